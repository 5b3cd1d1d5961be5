// A rig with some deformer parameters changed: the level-of-detail rigs of a variant
// build (fewer morph targets, fewer influences) derived from one rig file.
#pragma once
#include <cstdint>
#include <map>
#include <string>

#include "rig/rig.h"

namespace sg {

// `rig` with `params` set. Uniform arrays sized by a changed parameter are resized; with
// morph_targets: 0 the per-target attributes and the uniforms sized by morph_targets are
// dropped (a rig without targets carries no deltas). Throws InputError at `at` for a
// parameter the rig does not define or a negative value, and whatever checkRig rejects.
Rig rigWithParameters(const Rig& rig, const std::map<std::string, int64_t>& params, const SourceLoc& at);

}  // namespace sg

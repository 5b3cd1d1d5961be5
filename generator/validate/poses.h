// Uniform values for validation: the standard pose fields as semantic values, values drawn
// by declared kind for any other uniform a rig provides, and pose files (`validate
// --save-poses` / `--poses FILE`) that replay a run exactly. docs/validation.md, "Poses".
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "rig/rig.h"
#include "rules/rules.h"
#include "runtime/mesh.h"
#include "validate/interpreter.h"

namespace sg {

// True for the uniforms rt::Pose holds in named fields (skin.bones, camera.view, ...).
bool isStandardUniform(const std::string& semantic);

// For every uniform of the rig that is neither standard nor defined by a formula, and that a
// pose does not already carry in Pose::uniforms, draws a value by the semantic's `kind`
// (seeded by the pose index and the semantic's name: deterministic). Throws InputError
// (at the rig's uniform) for a uniform with neither kind nor definition.
void drawDeclaredUniforms(std::vector<rt::Pose>& poses, const Rig& rig, const RuleSet& rules);

// The values of the rig's uniforms in `pose`, by semantic, before definitions are applied.
UniformValues poseUniforms(const Rig& rig, const rt::Pose& pose);
// The pose's values of the uniforms that the definitions of the rig's uniforms read (through
// other definitions too) and the rig does not declare: those it holds in named fields, the
// values a rig declaring them would get. For the reference only (the GPU reads the rig's
// uniforms): a rig giving camera.view_projection (= camera.projection * camera.view) and no
// projection then has, in the reference, the projection and view its view_projection is the
// product of, so that clip.position, defined from them, is checked.
UniformValues definitionInputs(const Rig& rig, const RuleSet& rules, const rt::Pose& pose);

// Pose files (YAML). Floats are written with 9 significant digits and doubles with 17, so
// reading a file back and writing it again gives the same bytes.
std::string formatPoseFile(const std::vector<rt::Pose>& poses);
// Throws InputError (file:line:col) for malformed files.
std::vector<rt::Pose> parsePoseFile(const std::string& text, const std::string& fileName);
std::vector<rt::Pose> readPoseFile(const std::string& path);

}  // namespace sg

// Commands over a whole glTF model (MODEL.glb#*, docs/gltf.md#whole-models): one run per
// primitive, each failure reported with its primitive named, and the command fails (writing
// nothing) if any primitive fails.
#pragma once
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rig/gltf_import.h"

namespace sg {

// The primitives of `rigPath` when it ends in "#*"; nullopt otherwise. Throws InputError for
// "#*" after a rig that is not a glTF model and for a model without primitives.
std::optional<std::vector<GltfPart>> wholeModelParts(const std::string& rigPath);

// The animation belongs to the model, not to a primitive: an unknown name is refused once,
// before the primitives run, instead of once per primitive. ("" = the first: nothing to check.)
void checkWholeModelAnimation(const std::vector<GltfPart>& parts, const std::string& animation);

// Runs `body`; if it throws (InputError or any std::exception), prints `headline` as an error at
// `at`, then the error (and up to 20 related diagnostics), and returns false.
bool runReportingFailure(const SourceLoc& at, const std::string& headline, const std::function<void()>& body);

// Runs `body` on every part. A part that throws (InputError or any std::exception) is
// reported on standard error, its primitive named, and the next part still runs. Returns the
// names of the parts that failed, in order.
std::vector<std::string> forEachPart(const std::vector<GltfPart>& parts,
                                     const std::function<void(const GltfPart&)>& body);

// Throws the InputError that ends a whole-model command when parts failed:
// "MODEL.glb#*: 2 of 19 primitives failed (m2p1-Head, m3p0-Foot.R); nothing was written".
void failIfPartsFailed(const std::string& rigPath, size_t partCount, const std::vector<std::string>& failed,
                       const std::string& consequence = "nothing was written");

// The index of a whole-model output directory (index.json): the model, then one entry per
// part with its name, mesh, primitive and reference; `entries[i]` is merged into part i's
// entry (its files, plan cost, ...). Fixed key order and formatting: deterministic bytes.
std::string wholeModelIndex(const std::string& command, const std::string& rigPath, const std::vector<GltfPart>& parts,
                            const std::vector<nlohmann::ordered_json>& entries);

}  // namespace sg

#include "cli/whole_model.h"

#include <fmt/format.h>

#include <iostream>

#include "cli/commands.h"
#include "common/diagnostics.h"
#include "validate/gltf_scene.h"

namespace sg {

std::optional<std::vector<GltfPart>> wholeModelParts(const std::string& rigPath) {
  if (!isWholeModelRef(rigPath)) return std::nullopt;
  if (!isGltfPath(rigPath))
    throw InputError(SourceLoc{rigPath.substr(0, rigPath.size() - 2), 0, 0},
                     fmt::format("'#*' selects every primitive of a glTF model (.gltf, .glb); '{}' is not one",
                                 rigPath.substr(0, rigPath.size() - 2)));
  return gltfParts(parseGltfRef(rigPath, true).file);
}

void checkWholeModelAnimation(const std::vector<GltfPart>& parts, const std::string& animation) {
  if (animation.empty() || parts.empty()) return;
  std::optional<GltfImport> first;
  try {
    first = importGltfRef(parts.front().ref);
  } catch (const InputError&) {
    return;  // that primitive's own failure is reported with the others
  }
  findGltfAnimation(first->data, animation);
}

bool runReportingFailure(const SourceLoc& at, const std::string& headline, const std::function<void()>& body) {
  std::vector<std::string> messages;
  try {
    body();
    return true;
  } catch (const InputError& e) {
    messages.push_back(renderDiagnostic(e.diagnostic()));
    size_t shown = 0;
    for (const auto& d : e.related)
      if (++shown <= 20) messages.push_back(renderDiagnostic(d));
  } catch (const std::exception& e) {
    messages.push_back(fmt::format("shadergen: error: {}", e.what()));
  }
  std::cerr << formatDiagnostic(Diagnostic{Severity::Error, at, headline}) << "\n";
  for (const auto& m : messages) std::cerr << m << "\n";
  return false;
}

std::vector<std::string> forEachPart(const std::vector<GltfPart>& parts,
                                     const std::function<void(const GltfPart&)>& body) {
  std::vector<std::string> failed;
  for (const auto& part : parts)
    if (!runReportingFailure(SourceLoc{part.ref, 0, 0}, fmt::format("primitive {} failed:", part.name), [&] { body(part); }))
      failed.push_back(part.name);
  return failed;
}

void failIfPartsFailed(const std::string& rigPath, size_t partCount, const std::vector<std::string>& failed,
                       const std::string& consequence) {
  if (failed.empty()) return;
  std::string names;
  for (const auto& n : failed) names += (names.empty() ? "" : ", ") + n;
  throw InputError(SourceLoc{rigPath, 0, 0}, fmt::format("{} of {} primitive(s) failed ({}); {}", failed.size(),
                                                         partCount, names, consequence));
}

std::string wholeModelIndex(const std::string& command, const std::string& rigPath, const std::vector<GltfPart>& parts,
                            const std::vector<nlohmann::ordered_json>& entries) {
  nlohmann::ordered_json index;
  index["shadergen"] = shadergenVersionString();
  index["command"] = command;
  index["model"] = parseGltfRef(rigPath, true).file;
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  for (size_t i = 0; i < parts.size(); ++i) {
    nlohmann::ordered_json e;
    e["name"] = parts[i].name;
    e["mesh"] = parts[i].mesh;
    e["mesh_name"] = parts[i].meshName;
    e["primitive"] = parts[i].primitive;
    e["rig"] = parts[i].ref;
    if (i < entries.size())
      for (const auto& [k, v] : entries[i].items()) e[k] = v;
    list.push_back(std::move(e));
  }
  index["primitives"] = std::move(list);
  // Paths are bytes on Linux: invalid UTF-8 in one is replaced (U+FFFD), not an exception.
  return index.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + "\n";
}

}  // namespace sg

#include "rig/rig_lod.h"

#include <fmt/format.h>

#include <algorithm>

namespace sg {

Rig rigWithParameters(const Rig& rig, const std::map<std::string, int64_t>& params, const SourceLoc& at) {
  Rig out = rig;
  for (const auto& [key, value] : params) {
    // uniform_scale is documented as optional (default 0): a rig that omits it may set it.
    if (!rig.params.count(key) && key != "uniform_scale")
      throw InputError(at, fmt::format("rig '{}' has no deformer parameter '{}' to set", rig.name, key));
    if (value < 0) throw InputError(at, fmt::format("deformer parameter '{}' cannot be {}", key, value));
    out.params[key] = value;
  }
  if (out.morphTargets() == 0) {
    std::erase_if(out.attributes, [](const RigAttribute& a) { return a.perMorphTarget; });
    std::erase_if(out.uniforms, [](const RigUniform& u) { return u.arraySizeParam == "morph_targets"; });
    out.morphedAttributes.clear();
  }
  for (auto& u : out.uniforms)
    if (!u.arraySizeParam.empty()) u.arraySize = static_cast<int>(out.param(u.arraySizeParam));
  try {
    checkRig(out);
  } catch (const InputError& e) {
    InputError wrapped(at, fmt::format("rig '{}' with these parameters is inconsistent: {}", rig.name,
                                       e.diagnostic().message));
    wrapped.related.push_back(e.diagnostic());
    throw wrapped;
  }
  return out;
}

}  // namespace sg

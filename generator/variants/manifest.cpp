#include "variants/manifest.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>

#include "common/yaml_util.h"
#include "rig/gltf_import.h"
#include "rig/vertex_encoding.h"
#include "variants/cache_store.h"

namespace sg {
namespace {

namespace fs = std::filesystem;

// Paths in a manifest are relative to the manifest's folder. Rig paths may carry a glTF
// selector ("model.glb#0/0"), which stays as it is.
std::string resolvePath(const std::string& manifestFile, const std::string& p) {
  if (p.empty() || fs::path(p).is_absolute()) return p;
  fs::path base = fs::path(manifestFile).parent_path();
  return (base / p).lexically_normal().string();
}

std::vector<std::string> scalarOrList(const YamlCtx& y, const YAML::Node& n, const char* what) {
  std::vector<std::string> out;
  if (n.IsScalar()) {
    out.push_back(y.scalar(n, what));
    return out;
  }
  y.expectSeq(n, what);
  for (const auto& v : n) out.push_back(y.scalar(v, what));
  return out;
}

bool safeStem(const std::string& s) {
  if (s.empty() || s[0] == '.' || s.size() > 200) return false;
  for (char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.')) return false;
  return true;
}

double finiteNonNegative(const YamlCtx& y, const YAML::Node& n, const char* what) {
  const std::string text = y.scalar(n, what);
  size_t used = 0;
  double v = 0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || !std::isfinite(v) || v < 0)
    y.fail(n, fmt::format("{} '{}' is not a finite non-negative number", what, text));
  return v;
}

// `validate: true`, or a map of the `validate` command's options.
ManifestValidation parseValidation(const YamlCtx& y, const YAML::Node& n) {
  ManifestValidation v;
  v.loc = locOf(n, y.file);
  if (n.IsScalar()) {
    v.enabled = y.boolean(n, "'validate' (true, false or a map of settings)");
    return v;
  }
  y.expectMap(n, "'validate' (true, false or a map of settings)");
  y.checkKeys(n, {"mesh", "seed", "poses", "time", "animation", "morph_weight", "tolerance_abs", "tolerance_rel",
                  "cross_check", "strict", "float_check", "validation_layers", "device"});
  v.enabled = true;
  if (n["mesh"]) {
    v.mesh = y.scalar(n["mesh"], "'mesh'");
    if (v.mesh != "head" && v.mesh != "limb" && v.mesh != "dawn")
      y.fail(n["mesh"], fmt::format("unknown mesh '{}' (head, limb, dawn)", v.mesh));
  }
  if (n["seed"]) {
    long long s = y.integer(n["seed"], "'seed'");
    if (s < 0 || s > 0xffffffffll) y.fail(n["seed"], "'seed' is 0..4294967295");
    v.seed = static_cast<uint32_t>(s);
  }
  if (n["poses"]) {
    long long p = y.integer(n["poses"], "'poses'");
    if (p < 1 || p > 100) y.fail(n["poses"], "a count of poses is 1..100");
    v.poses = static_cast<int>(p);
  }
  if (n["time"] && n["time"].IsSequence())
    for (const auto& t : n["time"]) v.times.push_back(finiteNonNegative(y, t, "a time"));
  else if (n["time"])
    v.times.push_back(finiteNonNegative(y, n["time"], "a time"));
  if (n["animation"]) v.animation = y.scalar(n["animation"], "'animation'");
  if (n["morph_weight"]) v.morphWeight = finiteNonNegative(y, n["morph_weight"], "'morph_weight'");
  if (n["tolerance_abs"]) v.toleranceAbs = finiteNonNegative(y, n["tolerance_abs"], "'tolerance_abs'");
  if (n["tolerance_rel"]) v.toleranceRel = finiteNonNegative(y, n["tolerance_rel"], "'tolerance_rel'");
  if (n["cross_check"]) v.crossCheck = y.boolean(n["cross_check"], "'cross_check'");
  if (n["strict"]) v.strict = y.boolean(n["strict"], "'strict'");
  if (n["float_check"]) v.floatCheck = y.boolean(n["float_check"], "'float_check'");
  if (n["validation_layers"]) v.validationLayers = y.boolean(n["validation_layers"], "'validation_layers'");
  if (n["device"]) v.device = y.scalar(n["device"], "'device'");
  return v;
}

}  // namespace

bool Manifest::emits(const std::string& kind) const { return std::find(emit.begin(), emit.end(), kind) != emit.end(); }

Manifest loadManifest(const std::string& path) { return loadManifestText(readInputFile(path), path); }

Manifest loadManifestText(const std::string& text, const std::string& file) {
  Manifest m;
  m.file = file;
  YamlCtx y{file};
  YAML::Node root = parseYaml(text, file);
  y.expectMap(root, "a manifest");
  y.checkKeys(root, {"output", "rules", "templates", "target_env", "optimize", "heuristic", "emit", "rigs", "passes",
                     "axes", "exclude", "name", "device_profile", "max_error", "hlsl_shader_model", "msl_version",
                     "msl_platform", "validate", "cache_url", "mesh", "pins"});
  m.outputDir = resolvePath(file, root["output"] ? y.scalar(root["output"], "'output'") : "shaders");
  // Optional: the command line may name every rules file (-r, the CMake function's RULES: a
  // manifest cannot reach an installed library by a relative path); `build` checks for none.
  if (root["rules"])
    for (const auto& r : scalarOrList(y, root["rules"], "'rules'")) m.rules.push_back(resolvePath(file, r));
  if (root["templates"]) m.templates = resolvePath(file, y.scalar(root["templates"], "'templates'"));
  if (root["target_env"]) {
    std::string env = y.scalar(root["target_env"], "'target_env'");
    if (!parseTargetEnv(env, m.targetEnv))
      y.fail(root["target_env"], fmt::format("unknown target_env '{}' (vulkan1.0, vulkan1.1, vulkan1.2, vulkan1.3)", env));
  }
  if (root["device_profile"]) {  // one profile, or a list: the portable plan across them
    std::vector<std::string> profiles = scalarOrList(y, root["device_profile"], "'device_profile'");
    if (profiles.empty()) y.fail(root["device_profile"], "'device_profile' is an empty list (leave it out for instruction slots)");
    for (size_t i = 0; i < profiles.size(); ++i) {
      profiles[i] = resolvePath(file, profiles[i]);
      for (size_t j = 0; j < i; ++j)
        if (profiles[j] == profiles[i])
          y.fail(root["device_profile"][i], fmt::format("device profile '{}' is listed twice", profiles[i]));
    }
    m.deviceProfile = profiles.front();
    m.portableProfiles.assign(profiles.begin() + 1, profiles.end());
  }
  if (root["mesh"]) {  // the procedural mesh YAML rigs' programs draw (their workload)
    m.mesh = y.scalar(root["mesh"], "'mesh'");
    if (m.mesh != "head" && m.mesh != "limb" && m.mesh != "dawn")
      y.fail(root["mesh"], fmt::format("unknown mesh '{}' (head, limb, dawn)", m.mesh));
  }
  if (root["max_error"]) {  // { vertex.normal: 0.1deg, vertex.position: 1e-4 }, as --max-error
    y.expectMap(root["max_error"], "'max_error'");
    for (const auto& kv : root["max_error"]) {
      const std::string semantic = y.scalar(kv.first, "a semantic");
      std::string why;
      const std::optional<double> budget = parseErrorBudget(semantic, y.scalar(kv.second, "an error budget"), why);
      if (!budget) y.fail(encodingsOf(semantic).empty() ? kv.first : kv.second, why);
      m.maxError[semantic] = *budget;
    }
  }
  if (root["optimize"]) m.optimize = y.boolean(root["optimize"], "'optimize'");
  if (root["heuristic"]) {
    m.heuristic = y.scalar(root["heuristic"], "'heuristic'");
    if (m.heuristic != "lmcut" && m.heuristic != "hmax" && m.heuristic != "blind")
      y.fail(root["heuristic"], fmt::format("unknown heuristic '{}' (lmcut, hmax, blind)", m.heuristic));
  }
  if (root["emit"]) {
    m.emit = scalarOrList(y, root["emit"], "'emit'");
    static const std::set<std::string> kinds{"glsl", "spv", "reflection", "hlsl", "msl"};
    for (const auto& k : m.emit)
      if (!kinds.count(k)) y.fail(root["emit"], fmt::format("unknown emit kind '{}' (glsl, spv, reflection, hlsl, msl)", k));
    if (m.emit.empty()) y.fail(root["emit"], "'emit' is empty: nothing to write");
  }
  // Translation options apply only to what is emitted (like generate's flags).
  auto translation = [&](const char* key, const char* kind) -> std::string {
    if (!root[key]) return "";
    const std::string what = fmt::format("'{}'", key);
    std::string v = y.scalar(root[key], what.c_str());
    if (!m.emits(kind)) y.fail(root[key], fmt::format("'{}' does not apply: 'emit' has no {}", key, kind));
    return v;
  };
  if (std::string v = translation("hlsl_shader_model", "hlsl"); !v.empty() && !parseShaderModel(v, m.hlsl.shaderModel))
    y.fail(root["hlsl_shader_model"], fmt::format("unsupported shader model '{}' (supported: {})", v, kShaderModels));
  if (std::string v = translation("msl_version", "msl"); !v.empty() && !parseMslVersion(v, m.msl))
    y.fail(root["msl_version"], fmt::format("unsupported Metal Shading Language version '{}' (supported: {})", v, kMslVersions));
  if (std::string v = translation("msl_platform", "msl"); !v.empty() && !parseMslPlatform(v, m.msl.platform))
    y.fail(root["msl_platform"], fmt::format("unknown Metal platform '{}' (macos, ios)", v));

  if (root["validate"]) m.validate = parseValidation(y, root["validate"]);
  if (root["cache_url"]) {
    m.cacheUrl = y.scalar(root["cache_url"], "'cache_url'");
    // A manifest is a file in the repository. The error gives the line in its text, not as a
    // location: a located error quotes the line, and with it the secret, into the log.
    if (redactUrl(m.cacheUrl) != m.cacheUrl)
      throw InputError(SourceLoc{file, 0, 0},
                       fmt::format("line {}: 'cache_url' '{}' holds credentials; they come only from the environment "
                                   "(SHADERGEN_CACHE_AUTH=user:password, or the URL in SHADERGEN_CACHE_URL)",
                                   locOf(root["cache_url"], file).line, redactUrl(m.cacheUrl)));
  }

  std::map<std::string, std::vector<std::string>> wholeModels;  // rig name -> its primitives' rig names
  if (!root["rigs"]) y.fail(root, "the manifest needs 'rigs' (name: rig file, or name: { path: rig file, ban: [...] })");
  y.expectMap(root["rigs"], "'rigs'");
  for (const auto& kv : root["rigs"]) {
    ManifestRig r;
    r.name = y.scalar(kv.first, "a rig name");
    r.loc = locOf(kv.first, file);
    if (kv.second.IsMap()) {  // { path: RIG, ban: [rule, ...] }
      y.checkKeys(kv.second, {"path", "ban"});
      if (!kv.second["path"]) y.fail(kv.second, fmt::format("rig '{}' needs 'path'", r.name));
      r.path = resolvePath(file, y.scalar(kv.second["path"], "'path'"));
      if (kv.second["ban"]) {
        r.bans = scalarOrList(y, kv.second["ban"], "a rule name or a list of them");
        r.banLoc = locOf(kv.second["ban"], file);
      }
    } else {
      r.path = resolvePath(file, y.scalar(kv.second, "a rig file"));
    }
    if (!safeStem(r.name)) y.fail(kv.first, fmt::format("rig name '{}' must be letters, digits, '-', '_' or '.'", r.name));
    if (!isWholeModelRef(r.path)) {
      m.rigs.push_back(r);
      continue;
    }
    // A whole model (MODEL.glb#*): one rig per primitive, "<name>.<part name>".
    if (!isGltfPath(r.path))
      y.fail(kv.second, fmt::format("'#*' selects every primitive of a glTF model (.gltf, .glb); '{}' is not one",
                                    r.path.substr(0, r.path.size() - 2)));
    std::vector<GltfPart> parts;
    try {
      const std::string model = parseGltfRef(r.path, true).file;
      parts = gltfParts(model);
      m.wholeModelFiles.push_back(model);
    } catch (const InputError& e) {
      y.fail(kv.second, fmt::format("rig '{}': {}: {}", r.name, e.diagnostic().loc.file, e.diagnostic().message));
    }
    std::vector<std::string>& members = wholeModels[r.name];
    for (const auto& part : parts) {
      ManifestRig pr = r;
      pr.name = r.name + "." + part.name;
      pr.path = part.ref;
      members.push_back(pr.name);
      m.rigs.push_back(pr);
    }
  }
  if (!root["passes"]) y.fail(root, "the manifest needs 'passes' (name: fragment shader)");
  y.expectMap(root["passes"], "'passes'");
  for (const auto& kv : root["passes"]) {
    ManifestPass p;
    p.name = y.scalar(kv.first, "a pass name");
    p.loc = locOf(kv.first, file);
    if (!safeStem(p.name)) y.fail(kv.first, fmt::format("pass name '{}' must be letters, digits, '-', '_' or '.'", p.name));
    if (kv.second.IsMap()) {
      y.checkKeys(kv.second, {"fragment", "map", "conventions"});
      if (!kv.second["fragment"]) y.fail(kv.second, fmt::format("pass '{}' needs 'fragment'", p.name));
      p.fragment = resolvePath(file, y.scalar(kv.second["fragment"], "'fragment'"));
      if (kv.second["map"]) {
        y.expectMap(kv.second["map"], "'map'");
        for (const auto& mk : kv.second["map"]) {
          VaryingOverride ov;
          ov.name = y.scalar(mk.first, "a fragment input name");
          ov.semantics = scalarOrList(y, mk.second, "a semantic or a list of semantics");
          p.maps.push_back(ov);
        }
      }
      if (kv.second["conventions"]) p.conventions = scalarOrList(y, kv.second["conventions"], "a convention or a list");
    } else {
      p.fragment = resolvePath(file, y.scalar(kv.second, "a fragment shader"));
    }
    m.passes.push_back(p);
  }
  if (m.rigs.empty()) y.fail(root["rigs"], "'rigs' is empty");
  if (m.passes.empty()) y.fail(root["passes"], "'passes' is empty");

  std::set<std::string> axisNames;
  if (root["axes"]) {
    y.expectMap(root["axes"], "'axes' (axis: [values])");
    for (const auto& kv : root["axes"]) {
      ManifestAxis a;
      a.name = y.scalar(kv.first, "an axis name");
      a.loc = locOf(kv.first, file);
      a.values = scalarOrList(y, kv.second, "axis values");
      if (a.name == "rig") {  // a whole model's name stands for each of its primitives
        std::vector<std::string> values;
        for (const auto& v : a.values) {
          auto whole = wholeModels.find(v);
          if (whole == wholeModels.end())
            values.push_back(v);
          else
            values.insert(values.end(), whole->second.begin(), whole->second.end());
        }
        a.values = values;
      }
      if (a.values.empty()) y.fail(kv.second, fmt::format("axis '{}' has no values", a.name));
      std::set<std::string> seen;
      for (size_t i = 0; i < a.values.size(); ++i)
        if (!seen.insert(a.values[i]).second)
          y.fail(kv.second[i], fmt::format("axis '{}' lists '{}' twice", a.name, a.values[i]));
      if (!axisNames.insert(a.name).second) y.fail(kv.first, fmt::format("axis '{}' is given twice", a.name));
      m.axes.push_back(a);
    }
  }
  // Without a rig (pass) axis, every rig (pass) is made.
  auto implicitAxis = [&](const char* name, std::vector<std::string> values, const SourceLoc& loc, size_t at) {
    if (axisNames.count(name)) return;
    m.axes.insert(m.axes.begin() + static_cast<long>(std::min(at, m.axes.size())), ManifestAxis{name, values, loc});
  };
  std::vector<std::string> rigNames, passNames;
  for (const auto& r : m.rigs) rigNames.push_back(r.name);
  for (const auto& p : m.passes) passNames.push_back(p.name);
  implicitAxis("rig", rigNames, locOf(root["rigs"], file), 0);
  implicitAxis("pass", passNames, locOf(root["passes"], file), 1);

  if (root["exclude"]) {
    y.expectSeq(root["exclude"], "'exclude' (a list of {axis: value} maps)");
    for (const auto& e : root["exclude"]) {
      y.expectMap(e, "an exclusion ({axis: value, ...})");
      ManifestExclusion ex;
      ex.loc = locOf(e, file);
      for (const auto& kv : e) {
        std::string axis = y.scalar(kv.first, "an axis name");
        auto it = std::find_if(m.axes.begin(), m.axes.end(), [&](const ManifestAxis& a) { return a.name == axis; });
        if (it == m.axes.end()) y.fail(kv.first, fmt::format("exclusion names unknown axis '{}'", axis));
        std::string value = y.scalar(kv.second, "an axis value");
        if (std::find(it->values.begin(), it->values.end(), value) == it->values.end())
          y.fail(kv.second, fmt::format("axis '{}' has no value '{}'", axis, value));
        ex.match[axis] = value;
      }
      m.exclude.push_back(ex);
    }
  }
  if (root["name"]) {
    m.nameFormat = y.scalar(root["name"], "'name'");
    for (size_t i = m.nameFormat.find('{'); i != std::string::npos; i = m.nameFormat.find('{', i + 1)) {
      size_t close = m.nameFormat.find('}', i);
      if (close == std::string::npos) y.fail(root["name"], "unterminated '{' in 'name'");
      std::string axis = m.nameFormat.substr(i + 1, close - i - 1);
      if (!std::any_of(m.axes.begin(), m.axes.end(), [&](const ManifestAxis& a) { return a.name == axis; }))
        y.fail(root["name"], fmt::format("'name' uses unknown axis '{{{}}}'", axis));
    }
  }
  if (root["pins"] && root["pins"].IsScalar()) {  // a directory: <variant>.pin.yaml where one exists
    m.pinsDir = resolvePath(file, y.scalar(root["pins"], "'pins'"));
    std::error_code ec;
    // Not there yet: no variant is pinned (the first bench --manifest --pin-out makes it).
    if (fs::exists(m.pinsDir, ec) && !fs::is_directory(m.pinsDir, ec))
      y.fail(root["pins"], fmt::format("'pins' names '{}', which is not a directory (a map names one pin file per variant)", m.pinsDir));
    for (const Variant& v : expandVariants(m))
      if (const std::string f = (fs::path(m.pinsDir) / (v.name + ".pin.yaml")).string(); fs::is_regular_file(f, ec))
        m.pins.emplace(v.name, loadPin(f));
  } else if (root["pins"]) {  // { variant: pin file }: checked against the variants' names
    y.expectMap(root["pins"], "'pins' (a directory, or variant name: pin file)");
    const std::vector<Variant> variants = expandVariants(m);
    for (const auto& kv : root["pins"]) {
      const std::string name = y.scalar(kv.first, "a variant name");
      if (std::none_of(variants.begin(), variants.end(), [&](const Variant& v) { return v.name == name; }))
        y.fail(kv.first, fmt::format("'pins' names '{}', which is no variant of this manifest", name));
      m.pins.emplace(name, loadPin(resolvePath(file, y.scalar(kv.second, "a pin file"))));
    }
  }
  return m;
}

std::vector<Variant> expandVariants(const Manifest& m) {
  std::vector<Variant> out;
  std::map<std::string, const Variant*> byName;
  std::vector<size_t> idx(m.axes.size(), 0);
  if (m.axes.empty()) return out;
  for (;;) {
    Variant v;
    for (size_t a = 0; a < m.axes.size(); ++a) v.axes.emplace_back(m.axes[a].name, m.axes[a].values[idx[a]]);
    bool excluded = std::any_of(m.exclude.begin(), m.exclude.end(), [&](const ManifestExclusion& ex) {
      for (const auto& [axis, value] : ex.match)
        if (std::find(v.axes.begin(), v.axes.end(), std::make_pair(axis, value)) == v.axes.end()) return false;
      return true;
    });
    if (!excluded) {
      for (size_t a = 0; a < m.axes.size(); ++a) {
        const ManifestAxis& axis = m.axes[a];
        const std::string& value = axis.values[idx[a]];
        if (axis.name == "rig") {
          for (const auto& r : m.rigs)
            if (r.name == value) v.rig = &r;
          if (!v.rig) throw InputError(axis.loc, fmt::format("axis 'rig': no rig named '{}' in 'rigs'", value));
        } else if (axis.name == "pass") {
          for (const auto& p : m.passes)
            if (p.name == value) v.pass = &p;
          if (!v.pass) throw InputError(axis.loc, fmt::format("axis 'pass': no pass named '{}' in 'passes'", value));
        } else {
          size_t used = 0;
          long long n = 0;
          try {
            n = std::stoll(value, &used);
          } catch (const std::exception&) {
            used = 0;
          }
          if (used != value.size() || n < 0)
            throw InputError(axis.loc, fmt::format("axis '{}' sets a rig parameter: '{}' is not a non-negative integer",
                                                   axis.name, value));
          v.params[axis.name] = n;
        }
      }
      if (m.nameFormat.empty()) {
        for (const auto& [axis, value] : v.axes)
          v.name += (v.name.empty() ? "" : "-") + (axis == "rig" || axis == "pass" ? value : axis + value);
      } else {
        v.name = m.nameFormat;
        for (const auto& [axis, value] : v.axes)
          for (size_t p; (p = v.name.find("{" + axis + "}")) != std::string::npos;)
            v.name.replace(p, axis.size() + 2, value);
      }
      if (!safeStem(v.name))
        throw InputError(m.axes.front().loc,
                         fmt::format("variant name '{}' is not a safe file name (letters, digits, '-', '_', '.')", v.name));
      out.push_back(std::move(v));
    }
    // Next combination: the last axis varies fastest.
    size_t a = m.axes.size();
    while (a > 0) {
      --a;
      if (++idx[a] < m.axes[a].values.size()) break;
      idx[a] = 0;
      if (a == 0) goto done;
    }
  }
done:
  for (const auto& v : out)
    if (!byName.emplace(v.name, &v).second)
      throw InputError(SourceLoc{m.file, 0, 0},
                       fmt::format("two variants are both named '{}': put every axis in 'name'", v.name));
  if (out.empty()) throw InputError(SourceLoc{m.file, 0, 0}, "the exclusions leave no variant to build");
  return out;
}

}  // namespace sg

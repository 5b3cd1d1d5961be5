#include "variants/builder.h"

#include <fmt/format.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <thread>
#include <tuple>

#include "common/input_file.h"
#include "emit/depfile.h"
#include "emit/reflection.h"
#include "pipeline/generate.h"
#include "rig/rig_lod.h"
#include "common/content_hash.h"

namespace sg {
namespace {

namespace fs = std::filesystem;

// Bumped whenever the entry layout or what a key covers changes.
constexpr const char* kCacheFormat = "shadergen-variant-cache 3";  // 2: glTF buffer files keyed; 3: hlsl, msl

// Every file a build reads, loaded once and shared (read-only) by all workers.
struct SharedInputs {
  RuleSet rules;
  TemplateSet templates;
  std::map<std::string, Rig> rigs;                     // by manifest path
  std::map<std::string, FragmentInterface> fragments;  // by path
  std::map<std::string, std::string> digests;          // file -> SHA-256 of its bytes (cache keys)
  std::optional<DeviceProfile> profile;                // the manifest's device_profile
  std::vector<DeviceProfile> portable;                 // the rest of its list (a portable plan)
};

SharedInputs loadShared(const Manifest& m, const std::vector<Variant>& variants, const GltfReadOptions& gltf,
                        std::vector<Diagnostic>& warnings) {
  SharedInputs s;
  s.rules = loadRulesStage(m.rules);
  s.templates = loadTemplatesStage(m.templates);
  for (const ManifestRig& r : m.rigs)  // a misspelt ban would otherwise change nothing silently
    for (const auto& b : r.bans)
      if (!s.rules.findRule(b))
        throw InputError(r.banLoc, fmt::format("rig '{}' bans '{}': no rule of that name in the rules files", r.name, b));
  for (const auto& v : variants) {
    if (!s.rigs.count(v.rig->path)) {
      try {
        Rig& rig = s.rigs.emplace(v.rig->path, loadRigStage(v.rig->path, gltf)).first->second;
        // Printed once per rig, not once per variant (prepareInputs would pass them on).
        warnings.insert(warnings.end(), rig.importDiagnostics.begin(), rig.importDiagnostics.end());
        rig.importDiagnostics.clear();
      } catch (const InputError& e) {
        InputError out(e.diagnostic());
        out.related = e.related;
        out.related.push_back(Diagnostic{Severity::Note, v.rig->loc, fmt::format("rig '{}' is named here", v.rig->name)});
        throw out;
      }
    }
    if (!s.fragments.count(v.pass->fragment)) s.fragments.emplace(v.pass->fragment, loadFragmentStage(v.pass->fragment, m.targetEnv));
  }
  // Each file is hashed once; a variant's key hashes the digests of its files.
  auto keep = [&](const std::string& f) {
    if (!s.digests.count(f)) s.digests.emplace(f, sha256Hex(readInputFile(f)));
  };
  for (const auto& f : s.rules.files) keep(f);
  keep(s.templates.file());
  for (const auto& [path, rig] : s.rigs)
    for (const auto& f : rig.sourceFiles) keep(f);
  for (const auto& [path, frag] : s.fragments) keep(frag.file);
  if (!m.deviceProfile.empty()) {
    s.profile = loadDeviceProfileStage(m.deviceProfile);
    keep(m.deviceProfile);
  }
  for (const auto& p : m.portableProfiles) {
    s.portable.push_back(loadDeviceProfileStage(p));
    keep(p);
  }
  for (const auto& [name, pin] : m.pins) keep(pin.file);
  return s;
}

std::vector<std::string> inputsOf(const Manifest& m, const SharedInputs& s, const Variant& v) {
  std::vector<std::string> files = s.rigs.at(v.rig->path).sourceFiles;
  files.push_back(s.fragments.at(v.pass->fragment).file);
  files.insert(files.end(), s.rules.files.begin(), s.rules.files.end());
  files.push_back(s.templates.file());
  if (s.profile) files.push_back(s.profile->file);  // an input, so part of the cache key and the depfile
  for (const auto& d : s.portable) files.push_back(d.file);
  if (auto pin = m.pins.find(v.name); pin != m.pins.end()) files.push_back(pin->second.file);  // as a profile is
  return files;
}

// Every byte that can change a variant's outputs: the tool, the options, the variant's
// parameters and mappings, and each input file's path (outputs name them) and contents
// (through the SHA-256 of the file; left out with contents = false: the settings alone).
std::string cacheKey(const Manifest& m, const SharedInputs& s, const Variant& v, const std::vector<std::string>& inputs,
                     const Workload* workload, bool contents = true) {
  Sha256 h;
  h.field(kCacheFormat).field(shadergenVersion()).field(targetEnvName(m.targetEnv)).field(m.heuristic);
  h.field(m.optimize ? "optimize" : "no-optimize");
  if (m.emits("hlsl")) h.field("hlsl").field(shaderModelName(m.hlsl.shaderModel));
  if (m.emits("msl")) h.field("msl").field(mslVersionName(m.msl)).field(mslPlatformName(m.msl.platform));
  h.field(v.rig->path).field(v.pass->fragment);
  if (!v.rig->bans.empty()) {  // absent without bans: the keys of manifests before them stay
    h.field("bans");
    for (const auto& b : v.rig->bans) h.field(b);
  }
  for (const auto& [k, val] : v.params) h.field(k).field(std::to_string(val));
  h.field("maps");
  for (const auto& ov : v.pass->maps) {
    h.field(ov.name);
    for (const auto& sem : ov.semantics) h.field(sem);
  }
  if (!m.maxError.empty()) {  // only then: earlier manifests keep their cache keys
    h.field("max_error");
    for (const auto& [semantic, budget] : m.maxError) h.field(semantic).field(fmt::format("{:.17g}", budget));
  }
  if (!v.pass->conventions.empty()) {  // only then: earlier manifests keep their cache keys
    h.field("conventions");
    for (const auto& c : v.pass->conventions) h.field(c);
  }
  if (workload && workload->known()) {  // only then: earlier manifests keep their cache keys
    h.field("workload").field(fmt::format("{:.17g} {:.17g} {:.17g} {:.17g}", workload->verticesPerDraw, workload->jointsPerWarp,
                                          workload->activeMorphTargets, workload->invocationsPerVertex));
    if (workload->fragmentsPerVertex > 0) h.field(fmt::format("{:.17g}", workload->fragmentsPerVertex));
    if (workload->paletteEntriesPerWarp > 0) h.field("palette").field(fmt::format("{:.17g}", workload->paletteEntriesPerWarp));
    h.field(workload->source);
  }
  if (const std::string& w = s.rigs.at(v.rig->path).skinWeights; !w.empty())  // the reflection records it
    h.field("skin_weights").field(w);
  h.field("inputs");
  for (const auto& f : inputs) h.field(f).field(contents ? s.digests.at(f) : "");
  return h.hex();
}

// ---- cache entries (cache_store.h seals, stores and verifies them) ---------------------

std::string generatedBody(const BuiltVariant& v) {
  std::string rules;
  for (const auto& r : v.rules) rules += " " + r;
  return fmt::format("{}\ncost {}\nrules{}\nglsl {}\n{}spirv {}\n{}reflection {}\n{}hlsl {}\n{}msl {}\n{}", kCacheFormat,
                     v.cost, rules, v.glsl.size(), v.glsl, v.spirv.size(), v.spirv, v.reflection.size(),
                     v.reflection, v.hlsl.size(), v.hlsl, v.msl.size(), v.msl);
}

bool parseGenerated(const std::string& body, BuiltVariant& out) {
  std::istringstream in(body);
  std::string line;
  if (!std::getline(in, line) || line != kCacheFormat) return false;
  if (!std::getline(in, line) || line.rfind("cost ", 0) != 0) return false;
  try {
    out.cost = std::stoll(line.substr(5));
  } catch (const std::exception&) {
    return false;
  }
  if (!std::getline(in, line) || line.rfind("rules", 0) != 0) return false;
  std::istringstream rules(line.substr(5));
  out.rules.clear();
  for (std::string r; rules >> r;) out.rules.push_back(r);
  for (std::string* blob : {&out.glsl, &out.spirv, &out.reflection, &out.hlsl, &out.msl}) {
    if (!std::getline(in, line)) return false;
    size_t n = 0;
    try {
      n = std::stoull(line.substr(line.find(' ') + 1));
    } catch (const std::exception&) {
      return false;
    }
    if (n > body.size()) return false;
    blob->assign(n, '\0');
    if (!in.read(blob->data(), static_cast<std::streamsize>(n))) return false;
  }
  return in.peek() == std::char_traits<char>::eof() && out.spirv.size() % 4 == 0;
}

// A passing validation result (failures are never cached: the next build runs them again).
constexpr const char* kValidationFormat = "shadergen-validation 1";

std::string validationBody(const ValidationResult& r) {
  return fmt::format("{}\ndevice {}\ndriver {}\ntool {}\nmade {}\nruns {}\nworst {}\nmax_abs_error {:.17g}\n"
                     "max_rel_error {:.17g}\n",
                     kValidationFormat, r.device, r.driver, r.tool, r.made, r.runs, r.worstOutput, r.maxAbsError,
                     r.maxRelError);
}

std::optional<ValidationResult> parseValidation(const std::string& body) {
  std::istringstream in(body);
  std::string line;
  if (!std::getline(in, line) || line != kValidationFormat) return std::nullopt;
  ValidationResult r;
  r.pass = true;
  std::map<std::string, std::string> fields;
  while (std::getline(in, line)) {
    size_t sp = line.find(' ');
    fields[line.substr(0, sp)] = sp == std::string::npos ? "" : line.substr(sp + 1);
  }
  for (const char* k : {"device", "driver", "tool", "made", "runs", "worst", "max_abs_error", "max_rel_error"})
    if (!fields.count(k)) return std::nullopt;
  try {
    r.runs = std::stoul(fields["runs"]);
    r.maxAbsError = std::stod(fields["max_abs_error"]);
    r.maxRelError = std::stod(fields["max_rel_error"]);
  } catch (const std::exception&) {
    return std::nullopt;
  }
  r.device = fields["device"];
  r.driver = fields["driver"];
  r.tool = fields["tool"];
  r.made = fields["made"];
  r.worstOutput = fields["worst"];
  return r;
}

}  // namespace

GenerateOptions generateOptionsOf(const Manifest& m, const Variant& v, const BuildOptions& opts) {
  GenerateOptions o;
  if (auto w = opts.workloads.find(v.name); w != opts.workloads.end()) o.workload = w->second;
  o.gltf = opts.gltf;
  o.rigPath = v.rig->path;
  o.fragmentPath = v.pass->fragment;
  o.rulesPaths = m.rules;
  o.overrides = v.pass->maps;
  o.conventions = v.pass->conventions;
  o.rigParams = v.params;
  o.bannedRules = v.rig->bans;
  if (auto pin = m.pins.find(v.name); pin != m.pins.end()) o.pin = pin->second;
  o.maxError = m.maxError;
  o.heuristic = m.heuristic;
  o.templateDir = m.templates;
  o.targetEnv = m.targetEnv;
  o.optimize = m.optimize;
  o.deviceProfilePath = m.deviceProfile;
  o.portableProfilePaths = m.portableProfiles;
  o.outputName = (fs::path(m.outputDir) / (v.name + ".vert")).string();
  return o;
}

namespace {

// ---- one variant ------------------------------------------------------------------------

void generateVariant(const Manifest& m, const SharedInputs& s, const Variant& v, const BuildOptions& opts, BuiltVariant& out) {
  const Rig& base = s.rigs.at(v.rig->path);
  SourceLoc paramsAt{m.file, 0, 0};
  for (const auto& a : m.axes)
    if (v.params.count(a.name)) {
      paramsAt = a.loc;
      break;
    }
  Rig rig = v.params.empty() ? base : rigWithParameters(base, v.params, paramsAt);
  GenerateOptions o = generateOptionsOf(m, v, opts);
  if (m.emits("hlsl")) o.hlsl = m.hlsl;
  if (m.emits("msl")) o.msl = m.msl;
  LoadedInputs in = prepareInputs(std::move(rig), s.rules, s.fragments.at(v.pass->fragment), o, s.profile, s.portable);
  GenerateResult r = generateWith(std::move(in), s.templates, o);
  out.cost = r.plan.cost;
  for (int a : r.plan.actions) out.rules.push_back(r.in.problem.actions[a].name);
  out.glsl = r.glsl.text;
  out.spirv.assign(reinterpret_cast<const char*>(r.spirv.words.data()), r.spirv.words.size() * 4);
  out.reflection = reflectionOf(r);
  if (r.hlsl) out.hlsl = r.hlsl->text;
  if (r.msl) out.msl = r.msl->text;
}

void buildOne(const Manifest& m, const SharedInputs& s, const BuildOptions& opts, CacheStore& store,
              const std::string& validatorIdentity, BuiltVariant& out) {
  const Variant& v = *out.variant;
  out.inputs = inputsOf(m, s, v);
  out.skinWeights = s.rigs.at(v.rig->path).skinWeights;
  auto w = opts.workloads.find(v.name);
  const Workload* workload = w == opts.workloads.end() ? nullptr : &w->second;
  out.key = cacheKey(m, s, v, out.inputs, workload);
  BuiltVariant fromCache;  // read into its own record, so nothing leaks from a damaged entry
  std::optional<std::string> body = store.enabled() ? store.get(out.key) : std::nullopt;
  if (body && parseGenerated(*body, fromCache)) {
    out.cost = fromCache.cost;
    out.rules = std::move(fromCache.rules);
    out.glsl = std::move(fromCache.glsl);
    out.spirv = std::move(fromCache.spirv);
    out.reflection = std::move(fromCache.reflection);
    out.hlsl = std::move(fromCache.hlsl);
    out.msl = std::move(fromCache.msl);
    out.ok = out.cached = true;
  } else {
    try {
      generateVariant(m, s, v, opts, out);
      out.ok = true;
      if (store.enabled()) store.put(out.key, generatedBody(out));
    } catch (const InputError& e) {
      out.errors.push_back(e.diagnostic());
      out.errors.insert(out.errors.end(), e.related.begin(), e.related.end());
    } catch (const std::exception& e) {
      out.errors.push_back(Diagnostic{Severity::Error, SourceLoc{m.file, 0, 0}, e.what()});
    }
  }
  if (out.ok) out.spirvHash = sha256Hex(out.spirv);
  if (!out.ok || !opts.validator) return;
  // The result's key: the outputs' key, the validation settings, the device and driver.
  const std::string key = Sha256().field(kValidationFormat).field(out.key).field(validatorIdentity).hex();
  if (auto cached = store.enabled() ? store.get(key) : std::nullopt) {
    if (auto r = parseValidation(*cached)) {
      out.validation = std::move(r);
      out.validationCached = true;
      return;
    }
  }
  try {
    out.validation = opts.validator->validate(v, generateOptionsOf(m, v, opts));  // as it was generated
  } catch (const InputError& e) {
    out.validation = ValidationResult{};
    out.validation->errors.push_back(e.diagnostic());
    out.validation->errors.insert(out.validation->errors.end(), e.related.begin(), e.related.end());
  } catch (const std::exception& e) {
    out.validation = ValidationResult{};
    out.validation->errors.push_back(Diagnostic{Severity::Error, SourceLoc{m.file, 0, 0}, e.what()});
  }
  if (out.validation->pass) {
    if (store.enabled()) store.put(key, validationBody(*out.validation));
    return;
  }
  // A variant that does not validate fails the build: its outputs are not written.
  out.ok = false;
  out.errors.push_back(Diagnostic{Severity::Error, m.validate.loc.file.empty() ? SourceLoc{m.file, 0, 0} : m.validate.loc,
                                  fmt::format("variant '{}' does not validate{}", v.name,
                                              out.validation->device.empty() ? "" : " on " + out.validation->device)});
  out.errors.insert(out.errors.end(), out.validation->errors.begin(), out.validation->errors.end());
}

// ---- the index --------------------------------------------------------------------------

std::string jsonString(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\t': out += "\\t"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) out += fmt::format("\\u{:04x}", static_cast<int>(c));
        else out += c;
    }
  }
  return out + "\"";
}

// ["a", "b"]: the index's lists of names and paths.
std::string jsonStringArray(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& item : items) out += (out.empty() ? "" : ", ") + jsonString(item);
  return "[" + out + "]";
}

std::string relativeTo(const std::string& dir, const std::string& path) {
  return fs::path(path).lexically_relative(dir).generic_string();
}

// index.json: the build's settings, then each variant's entry (indexEntry), in manifest order.
std::string indexJson(const Manifest& m, const std::vector<std::string>& entries) {
  std::string out = "{\n";
  out += fmt::format("  \"shadergen\": {},\n", jsonString(shadergenVersion()));
  out += fmt::format("  \"target_env\": {},\n", jsonString(targetEnvName(m.targetEnv)));
  out += fmt::format("  \"optimize\": {},\n", m.optimize ? "true" : "false");
  if (m.emits("hlsl")) out += fmt::format("  \"hlsl_shader_model\": {},\n", jsonString(shaderModelName(m.hlsl.shaderModel)));
  if (m.emits("msl"))
    out += fmt::format("  \"msl_version\": {},\n  \"msl_platform\": {},\n", jsonString(mslVersionName(m.msl)),
                       jsonString(mslPlatformName(m.msl.platform)));
  if (!m.deviceProfile.empty() && m.portableProfiles.empty())  // then "cost" is femtoseconds per vertex on that device
    out += fmt::format("  \"device_profile\": {},\n", jsonString(m.deviceProfile));
  if (!m.portableProfiles.empty()) {  // then "cost" is the worst-case regret: predicted time over the device's best, times 10^9
    std::vector<std::string> profiles{m.deviceProfile};
    profiles.insert(profiles.end(), m.portableProfiles.begin(), m.portableProfiles.end());
    out += fmt::format("  \"device_profiles\": {},\n", jsonStringArray(profiles));
  }
  if (!m.maxError.empty()) {  // in each encoding's unit (degrees, or a fraction of the bounds diagonal)
    std::string budgets;
    for (const auto& [semantic, budget] : m.maxError)
      budgets += fmt::format("{}{}: {:.17g}", budgets.empty() ? "" : ", ", jsonString(semantic), budget);
    out += fmt::format("  \"max_error\": {{{}}},\n", budgets);
  }
  out += fmt::format("  \"rules\": {},\n", jsonStringArray(m.rules));
  out += fmt::format("  \"variants\": [\n");
  for (size_t i = 0; i < entries.size(); ++i) out += entries[i] + (i + 1 < entries.size() ? ",\n" : "\n");
  out += "  ]\n}\n";
  return out;
}

// One element of index.json's "variants" (no trailing comma or newline).
std::string indexEntry(const Manifest& m, const BuiltVariant& b) {
  const Variant& v = *b.variant;
  std::string out = "    {\n";
  out += fmt::format("      \"name\": {},\n", jsonString(v.name));
  out += fmt::format("      \"rig\": {},\n", jsonString(v.rig->name));
  out += fmt::format("      \"rig_file\": {},\n", jsonString(v.rig->path));
  if (!b.skinWeights.empty())  // the weights the host must feed (docs/gltf.md#import-diagnostics-and-weights)
    out += fmt::format("      \"skin_weights\": {},\n", jsonString(b.skinWeights));
  out += fmt::format("      \"pass\": {},\n", jsonString(v.pass->name));
  out += fmt::format("      \"fragment_file\": {},\n", jsonString(v.pass->fragment));
  std::string params;
  for (const auto& [k, val] : v.params) params += fmt::format("{}{}: {}", params.empty() ? "" : ", ", jsonString(k), val);
  out += fmt::format("      \"parameters\": {{{}}},\n", params);
  out += fmt::format("      \"cost\": {},\n", b.cost);
  out += fmt::format("      \"rules\": {},\n", jsonStringArray(b.rules));
  if (!v.rig->bans.empty())  // a pinned plan (docs/variants.md): what its search left out
    out += fmt::format("      \"bans\": {},\n", jsonStringArray(v.rig->bans));
  if (auto pin = m.pins.find(v.name); pin != m.pins.end())  // a measured choice: where it was timed fastest
    out += fmt::format("      \"pin\": {{\"file\": {}, \"device\": {}, \"plan\": {}}},\n", jsonString(pin->second.file),
                       jsonString(pin->second.deviceNames()), jsonString(pin->second.label));
  out += fmt::format("      \"spirv_sha256\": {},\n", jsonString(b.spirvHash));
  out += fmt::format("      \"validated\": {},\n", b.validation ? "true" : "false");
  if (const auto& val = b.validation)  // where and when the result was made (cached with it)
    out += fmt::format("      \"validation\": {{\"device\": {}, \"driver\": {}, \"shadergen\": {}, \"made\": {}, "
                       "\"runs\": {}, \"worst_output\": {}, \"max_abs_error\": {:.17g}, \"max_rel_error\": {:.17g}}},\n",
                       jsonString(val->device), jsonString(val->driver), jsonString(val->tool), jsonString(val->made),
                       val->runs, jsonString(val->worstOutput), val->maxAbsError, val->maxRelError);
  std::string outputs;
  for (const auto& [kind, path] : b.outputs)
    outputs += fmt::format("{}{}: {}", outputs.empty() ? "" : ", ", jsonString(kind),
                           jsonString(relativeTo(m.outputDir, path)));
  out += fmt::format("      \"outputs\": {{{}}}\n", outputs);
  return out + "    }";
}

// index.json and its depfile (every input of every variant, and the manifest).
std::vector<OutputFile> indexFiles(const Manifest& m, const std::vector<std::string>& entries,
                                   const std::set<std::string>& inputs) {
  std::string index = (fs::path(m.outputDir) / "index.json").string();
  return {{index, indexJson(m, entries)},
          {index + ".d", makeDepfile({index}, std::vector<std::string>(inputs.begin(), inputs.end()))}};
}

// The outputs named after the variant (the SPIR-V is named by its content).
std::map<std::string, std::string> namedOutputs(const Manifest& m, const Variant& v) {
  std::map<std::string, std::string> out;
  for (auto [kind, suffix] : {std::pair{"glsl", ".vert"}, std::pair{"reflection", ".json"}, std::pair{"hlsl", ".hlsl"},
                              std::pair{"msl", ".metal"}})
    if (m.emits(kind)) out[kind] = (fs::path(m.outputDir) / (v.name + suffix)).string();
  return out;
}

// A variant's entry file: its index element and its inputs, for joinIndex.
constexpr const char* kIndexEntryFormat = "shadergen-variant-entry 1";

std::string entryText(const BuiltVariant& b) {
  std::string out = fmt::format("{}\ninputs {}\n", kIndexEntryFormat, b.inputs.size());
  for (const auto& f : b.inputs) out += f + "\n";  // makeDepfile has refused paths with a newline
  return out + fmt::format("entry {}\n{}", b.entry.size(), b.entry);
}

bool parseEntry(const std::string& text, std::string& entry, std::vector<std::string>& inputs) {
  std::istringstream in(text);
  std::string line;
  if (!std::getline(in, line) || line != kIndexEntryFormat) return false;
  if (!std::getline(in, line) || line.rfind("inputs ", 0) != 0) return false;
  size_t n = 0, size = 0;
  try {
    n = std::stoull(line.substr(7));
    for (size_t i = 0; i < n && std::getline(in, line); ++i) inputs.push_back(line);
    if (inputs.size() != n || !std::getline(in, line) || line.rfind("entry ", 0) != 0) return false;
    size = std::stoull(line.substr(6));
  } catch (const std::exception&) {
    return false;
  }
  auto at = static_cast<size_t>(in.tellg());
  if (at > text.size() || text.size() - at != size) return false;
  entry = text.substr(at);
  return true;
}

}  // namespace

BuildReport buildVariants(const Manifest& m, const std::vector<Variant>& variants, const BuildOptions& opts) {
  BuildReport report;
  SharedInputs shared = loadShared(m, variants, opts.gltf, report.warnings);
  // A pin measured with other bytes still gives its plan (generation checks); the build says so,
  // as generate --pin does. Its digest covers the files but the profiles and the pin.
  for (const Variant& v : variants)
    if (auto pin = m.pins.find(v.name); pin != m.pins.end()) {
      std::vector<std::string> files;
      for (const auto& f : inputsOf(m, shared, v))
        if (f != pin->second.file && f != m.deviceProfile &&
            std::find(m.portableProfiles.begin(), m.portableProfiles.end(), f) == m.portableProfiles.end())
          files.push_back(f);
      if (auto changed = pinInputsChanged(pin->second, sha256OfFiles(files))) {
        changed->message = fmt::format("variant '{}': {}", v.name, changed->message);
        report.warnings.push_back(*changed);
      }
    }
  CacheStore store({opts.cacheDir, opts.cacheUrl, opts.cacheAuth, 1500, 20000, opts.warn});
  const std::string identity = opts.validator ? opts.validator->identity() : "";
  report.variants.resize(variants.size());
  for (size_t i = 0; i < variants.size(); ++i) report.variants[i].variant = &variants[i];

  // Workers take the next variant; results land in their own slot, so the order of the
  // outputs never depends on the scheduling.
  std::atomic<size_t> next{0};
  std::mutex progressLock;
  size_t done = 0;
  auto work = [&] {
    for (size_t i; (i = next++) < variants.size();) {
      buildOne(m, shared, opts, store, identity, report.variants[i]);
      if (opts.progress) {
        std::lock_guard<std::mutex> lock(progressLock);
        opts.progress(++done, variants.size(), variants[i].name, report.variants[i].cached);
      }
    }
  };
  unsigned jobs = opts.jobs ? opts.jobs : std::max(1u, std::thread::hardware_concurrency());
  jobs = static_cast<unsigned>(std::min<size_t>(jobs, variants.size()));
  std::vector<std::thread> threads;
  for (unsigned t = 1; t < jobs; ++t) threads.emplace_back(work);
  work();
  for (auto& t : threads) t.join();

  // Outputs, identical SPIR-V once (content-addressed), a depfile per variant, the index.
  std::set<std::string> spirvWritten;
  std::set<std::string> allInputs{m.file};
  report.cache = store.stats();
  for (auto& b : report.variants) {
    if (b.validation && b.validation->pass) ++(b.validationCached ? report.validationsCached : report.validated);
    if (!b.ok) {
      ++report.failed;
      continue;
    }
    ++(b.cached ? report.cached : report.generated);
    const Variant& v = *b.variant;
    b.outputs = namedOutputs(m, v);
    const std::map<std::string, const std::string*> text{
        {"glsl", &b.glsl}, {"reflection", &b.reflection}, {"hlsl", &b.hlsl}, {"msl", &b.msl}};
    std::vector<std::string> targets;
    // In the order of the depfile's targets: GLSL, SPIR-V, reflection, HLSL, MSL.
    for (const char* kind : {"glsl", "spv", "reflection", "hlsl", "msl"}) {
      if (!m.emits(kind)) continue;
      if (std::string(kind) == "spv") {
        b.outputs["spv"] = (fs::path(m.outputDir) / "spirv" / (b.spirvHash.substr(0, 16) + ".spv")).string();
        if (spirvWritten.insert(b.spirvHash).second) report.files.push_back({b.outputs["spv"], b.spirv});
        else ++report.sharedSpirv;
      } else {
        report.files.push_back({b.outputs[kind], *text.at(kind)});
      }
      targets.push_back(b.outputs[kind]);
    }
    std::vector<std::string> deps{m.file};
    deps.insert(deps.end(), b.inputs.begin(), b.inputs.end());
    report.files.push_back({(fs::path(m.outputDir) / (v.name + ".d")).string(), makeDepfile(targets, deps)});
    allInputs.insert(b.inputs.begin(), b.inputs.end());
    b.entry = indexEntry(m, b);
    if (!opts.index) {
      VariantEntryFiles ef = entryFiles(m, v);
      report.files.push_back({ef.entry, entryText(b)});
      report.files.push_back({ef.depfile, makeDepfile(ef.entry, b.inputs)});  // the manifest: PlannedVariant::stamp
    }
  }
  if (report.failed == 0 && opts.index) {
    std::vector<std::string> entries;
    for (const auto& b : report.variants) entries.push_back(b.entry);
    for (auto& f : indexFiles(m, entries, allInputs)) report.files.push_back(std::move(f));
    report.indexPath = (fs::path(m.outputDir) / "index.json").string();
  }
  return report;
}

VariantEntryFiles entryFiles(const Manifest& m, const Variant& v) {
  std::string entry = (fs::path(m.outputDir) / ".shadergen-variants" / (v.name + ".entry")).string();
  return {entry, entry + ".d"};
}

std::vector<OutputFile> joinIndex(const Manifest& m, const std::vector<Variant>& variants) {
  std::vector<std::string> entries;
  std::set<std::string> inputs{m.file};
  for (const auto& v : variants) {
    const std::string file = entryFiles(m, v).entry;
    std::string text, entry;
    std::vector<std::string> files;
    std::ifstream in(file, std::ios::binary);
    if (!in)
      throw InputError(SourceLoc{m.file, 0, 0},
                       fmt::format("variant '{}' has not been built: no '{}' (`shadergen build {} --variant {}` makes it)",
                                   v.name, file, m.file, v.name));
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    if (!parseEntry(text, entry, files))
      throw InputError(SourceLoc{file, 0, 0},
                       fmt::format("not an entry of variant '{}' (damaged, or from another shadergen version): "
                                   "build the variant again",
                                   v.name));
    entries.push_back(std::move(entry));
    inputs.insert(files.begin(), files.end());
  }
  return indexFiles(m, entries, inputs);
}

std::vector<PlannedVariant> planVariants(const Manifest& m, const std::vector<Variant>& variants) {
  std::vector<Diagnostic> warnings;  // the build that follows reports them
  SharedInputs shared = loadShared(m, variants, GltfReadOptions{}, warnings);
  std::vector<PlannedVariant> out;
  for (const auto& v : variants) {
    PlannedVariant p{inputsOf(m, shared, v), namedOutputs(m, v), ""};
    Sha256 h;
    h.field(cacheKey(m, shared, v, p.inputs, nullptr, false)).field(v.name).field(v.rig->name).field(v.pass->name).field(m.outputDir);
    for (const auto& kind : m.emit) h.field(kind);
    p.stamp = h.hex();
    out.push_back(std::move(p));
  }
  return out;
}

}  // namespace sg

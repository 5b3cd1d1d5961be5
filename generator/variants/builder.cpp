#include "variants/builder.h"

#include <fmt/format.h>
#include <unistd.h>

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
#include "variants/content_hash.h"

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
};

SharedInputs loadShared(const Manifest& m, const std::vector<Variant>& variants) {
  SharedInputs s;
  s.rules = loadRulesStage(m.rules);
  s.templates = loadTemplatesStage(m.templates);
  for (const auto& v : variants) {
    if (!s.rigs.count(v.rig->path)) {
      try {
        s.rigs.emplace(v.rig->path, loadRigStage(v.rig->path));
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
  return s;
}

std::vector<std::string> inputsOf(const SharedInputs& s, const Variant& v) {
  std::vector<std::string> files = s.rigs.at(v.rig->path).sourceFiles;
  files.push_back(s.fragments.at(v.pass->fragment).file);
  files.insert(files.end(), s.rules.files.begin(), s.rules.files.end());
  files.push_back(s.templates.file());
  if (s.profile) files.push_back(s.profile->file);  // an input, so part of the cache key and the depfile
  return files;
}

// Every byte that can change a variant's outputs: the tool, the options, the variant's
// parameters and mappings, and each input file's path (outputs name them) and contents
// (through the SHA-256 of the file; left out with contents = false: the settings alone).
std::string cacheKey(const Manifest& m, const SharedInputs& s, const Variant& v, const std::vector<std::string>& inputs,
                     bool contents = true) {
  Sha256 h;
  h.field(kCacheFormat).field(shadergenVersion()).field(targetEnvName(m.targetEnv)).field(m.heuristic);
  h.field(m.optimize ? "optimize" : "no-optimize");
  if (m.emits("hlsl")) h.field("hlsl").field(shaderModelName(m.hlsl.shaderModel));
  if (m.emits("msl")) h.field("msl").field(mslVersionName(m.msl)).field(mslPlatformName(m.msl.platform));
  h.field(v.rig->path).field(v.pass->fragment);
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
  h.field("inputs");
  for (const auto& f : inputs) h.field(f).field(contents ? s.digests.at(f) : "");
  return h.hex();
}

// ---- the cache: one file per key, written to a temporary and renamed into place ---------

std::string entryPath(const std::string& dir, const std::string& key) {
  return (fs::path(dir) / key.substr(0, 2) / key).string();
}

bool readEntry(const std::string& path, BuiltVariant& out) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
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
    if (n > (64u << 20)) return false;
    blob->assign(n, '\0');
    if (!in.read(blob->data(), static_cast<std::streamsize>(n))) return false;
  }
  return in.peek() == std::char_traits<char>::eof() && out.spirv.size() % 4 == 0;
}

void writeEntry(const std::string& path, const BuiltVariant& v) {
  std::string rules;
  for (const auto& r : v.rules) rules += " " + r;
  std::string text = fmt::format("{}\ncost {}\nrules{}\nglsl {}\n{}spirv {}\n{}reflection {}\n{}hlsl {}\n{}msl {}\n{}",
                                 kCacheFormat, v.cost, rules, v.glsl.size(), v.glsl, v.spirv.size(), v.spirv,
                                 v.reflection.size(), v.reflection, v.hlsl.size(), v.hlsl, v.msl.size(), v.msl);
  static std::atomic<unsigned> counter{0};
  std::error_code ec;
  fs::create_directories(fs::path(path).parent_path(), ec);
  // Unique per process and write: two builds sharing the cache never see a partial entry.
  std::string tmp = fmt::format("{}.tmp.{}.{}", path, static_cast<int>(getpid()), counter++);
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) return;  // a read-only cache only costs speed
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    if (!out) {
      out.close();
      fs::remove(tmp, ec);
      return;
    }
  }
  fs::rename(tmp, path, ec);
  if (ec) fs::remove(tmp, ec);
}

// ---- one variant ------------------------------------------------------------------------

void generateVariant(const Manifest& m, const SharedInputs& s, const Variant& v, BuiltVariant& out) {
  const Rig& base = s.rigs.at(v.rig->path);
  SourceLoc paramsAt{m.file, 0, 0};
  for (const auto& a : m.axes)
    if (v.params.count(a.name)) {
      paramsAt = a.loc;
      break;
    }
  Rig rig = v.params.empty() ? base : rigWithParameters(base, v.params, paramsAt);
  GenerateOptions o;
  o.overrides = v.pass->maps;
  o.conventions = v.pass->conventions;
  o.maxError = m.maxError;
  LoadedInputs in = prepareInputs(std::move(rig), s.rules, s.fragments.at(v.pass->fragment), o, s.profile);
  o.heuristic = m.heuristic;
  o.targetEnv = m.targetEnv;
  o.optimize = m.optimize;
  o.outputName = (fs::path(m.outputDir) / (v.name + ".vert")).string();
  if (m.emits("hlsl")) o.hlsl = m.hlsl;
  if (m.emits("msl")) o.msl = m.msl;
  GenerateResult r = generateWith(std::move(in), s.templates, o);
  out.cost = r.plan.cost;
  for (int a : r.plan.actions) out.rules.push_back(r.in.problem.actions[a].name);
  out.glsl = r.glsl.text;
  out.spirv.assign(reinterpret_cast<const char*>(r.spirv.words.data()), r.spirv.words.size() * 4);
  out.reflection = reflectionOf(r);
  if (r.hlsl) out.hlsl = r.hlsl->text;
  if (r.msl) out.msl = r.msl->text;
}

void buildOne(const Manifest& m, const SharedInputs& s, const BuildOptions& opts, BuiltVariant& out) {
  const Variant& v = *out.variant;
  out.inputs = inputsOf(s, v);
  out.key = cacheKey(m, s, v, out.inputs);
  std::string entry = opts.cacheDir.empty() ? "" : entryPath(opts.cacheDir, out.key);
  BuiltVariant fromCache;
  if (!entry.empty() && readEntry(entry, fromCache)) {
    out.cost = fromCache.cost;
    out.rules = std::move(fromCache.rules);
    out.glsl = std::move(fromCache.glsl);
    out.spirv = std::move(fromCache.spirv);
    out.reflection = std::move(fromCache.reflection);
    out.hlsl = std::move(fromCache.hlsl);
    out.msl = std::move(fromCache.msl);
    out.ok = out.cached = true;
  } else {  // a miss, or a damaged entry (read into its own record, so nothing leaks from it)
    try {
      generateVariant(m, s, v, out);
      out.ok = true;
      if (!entry.empty()) writeEntry(entry, out);
    } catch (const InputError& e) {
      out.errors.push_back(e.diagnostic());
      out.errors.insert(out.errors.end(), e.related.begin(), e.related.end());
    } catch (const std::exception& e) {
      out.errors.push_back(Diagnostic{Severity::Error, SourceLoc{m.file, 0, 0}, e.what()});
    }
  }
  if (out.ok) out.spirvHash = sha256Hex(out.spirv);
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
  if (!m.deviceProfile.empty())  // then "cost" is femtoseconds per vertex on that device
    out += fmt::format("  \"device_profile\": {},\n", jsonString(m.deviceProfile));
  if (!m.maxError.empty()) {  // in each encoding's unit (degrees, or a fraction of the bounds diagonal)
    std::string budgets;
    for (const auto& [semantic, budget] : m.maxError)
      budgets += fmt::format("{}{}: {:.17g}", budgets.empty() ? "" : ", ", jsonString(semantic), budget);
    out += fmt::format("  \"max_error\": {{{}}},\n", budgets);
  }
  std::string rules;
  for (const auto& f : m.rules) rules += (rules.empty() ? "" : ", ") + jsonString(f);
  out += fmt::format("  \"rules\": [{}],\n", rules);
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
  out += fmt::format("      \"pass\": {},\n", jsonString(v.pass->name));
  out += fmt::format("      \"fragment_file\": {},\n", jsonString(v.pass->fragment));
  std::string params;
  for (const auto& [k, val] : v.params) params += fmt::format("{}{}: {}", params.empty() ? "" : ", ", jsonString(k), val);
  out += fmt::format("      \"parameters\": {{{}}},\n", params);
  out += fmt::format("      \"cost\": {},\n", b.cost);
  std::string rules;
  for (const auto& rule : b.rules) rules += (rules.empty() ? "" : ", ") + jsonString(rule);
  out += fmt::format("      \"rules\": [{}],\n", rules);
  out += fmt::format("      \"spirv_sha256\": {},\n", jsonString(b.spirvHash));
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
constexpr const char* kEntryFormat = "shadergen-variant-entry 1";

std::string entryText(const BuiltVariant& b) {
  std::string out = fmt::format("{}\ninputs {}\n", kEntryFormat, b.inputs.size());
  for (const auto& f : b.inputs) out += f + "\n";  // makeDepfile has refused paths with a newline
  return out + fmt::format("entry {}\n{}", b.entry.size(), b.entry);
}

bool parseEntry(const std::string& text, std::string& entry, std::vector<std::string>& inputs) {
  std::istringstream in(text);
  std::string line;
  if (!std::getline(in, line) || line != kEntryFormat) return false;
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
  SharedInputs shared = loadShared(m, variants);
  BuildReport report;
  report.variants.resize(variants.size());
  for (size_t i = 0; i < variants.size(); ++i) report.variants[i].variant = &variants[i];

  // Workers take the next variant; results land in their own slot, so the order of the
  // outputs never depends on the scheduling.
  std::atomic<size_t> next{0};
  std::mutex progressLock;
  size_t done = 0;
  auto work = [&] {
    for (size_t i; (i = next++) < variants.size();) {
      buildOne(m, shared, opts, report.variants[i]);
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
  for (auto& b : report.variants) {
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
  SharedInputs shared = loadShared(m, variants);
  std::vector<PlannedVariant> out;
  for (const auto& v : variants) {
    PlannedVariant p{inputsOf(shared, v), namedOutputs(m, v), ""};
    Sha256 h;
    h.field(cacheKey(m, shared, v, p.inputs, false)).field(v.name).field(v.rig->name).field(v.pass->name).field(m.outputDir);
    for (const auto& kind : m.emit) h.field(kind);
    p.stamp = h.hex();
    out.push_back(std::move(p));
  }
  return out;
}

}  // namespace sg

// `shadergen build MANIFEST.yaml`: every variant of a manifest in one process
// (generator/variants/builder.h, docs/variants.md).
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>
#include <sstream>

#include "cli/commands.h"
#include "cli/output_files.h"
#include "validate/variant_validation.h"
#include "measure/workload.h"
#include "variants/builder.h"

namespace sg {
namespace {

bool sameContents(const std::string& path, const std::string& contents) {
  std::error_code ec;
  if (std::filesystem::file_size(path, ec) != contents.size() || ec) return false;
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::ostringstream s;
  s << in.rdbuf();
  return s.str() == contents;
}

// `--list-cmake`: the variants as CMake set() commands, for shadergen_add_shader_variants()
// (cmake/ShadergenFunctions.cmake), which gives each variant its own build edge. Paths are
// absolute (CMake resolves relative ones against the source directory, not ours).
std::string cmakeListing(const Manifest& m, const std::vector<Variant>& variants,
                         const std::vector<PlannedVariant>& planned) {
  auto quote = [&](const std::string& path) {
    std::string p = std::filesystem::absolute(path).lexically_normal().string();
    if (p.find_first_of(";\n\r") != std::string::npos)
      throw InputError(SourceLoc{m.file, 0, 0}, fmt::format("cannot list '{}' for CMake: the path contains ';' or a newline", p));
    std::string eq;
    while ((p + "]" + eq + "]").find("]" + eq + "]") < p.size()) eq += "=";  // no early end of the bracket
    return fmt::format(" [{}[{}]{}]", eq, p, eq);
  };
  std::string out = fmt::format("# `shadergen build {} --list-cmake`: one build edge per variant\n", m.file);
  out += "set(SHADERGEN_LIST_CONFIGURE_DEPENDS" + quote(m.file);  // what the list itself depends on
  for (const auto& f : m.wholeModelFiles) out += quote(f);
  // `pins: DIR`: a pin written for a variant that had none changes which files a variant reads
  // (its depfile names only the pins it had); the directory's time changes when one is written.
  if (std::error_code ec; !m.pinsDir.empty() && std::filesystem::is_directory(m.pinsDir, ec)) out += quote(m.pinsDir);
  out += ")\nset(SHADERGEN_LIST_VARIANTS";
  for (const auto& v : variants) out += " " + v.name;  // safe file stems
  out += ")\n";
  for (size_t i = 0; i < variants.size(); ++i) {
    const std::string var = "SHADERGEN_LIST_" + variants[i].name;
    VariantEntryFiles ef = entryFiles(m, variants[i]);
    out += fmt::format("set({}_ENTRY{})\nset({}_DEPFILE{})\nset({}_OUTPUTS", var, quote(ef.entry), var, quote(ef.depfile), var);
    for (const auto& [kind, path] : planned[i].outputs) out += quote(path);
    out += fmt::format(")\nset({}_STAMP {})\nset({}_INPUTS", var, planned[i].stamp, var);
    for (const auto& f : planned[i].inputs) out += quote(f);
    out += ")\n";
  }
  return out;
}

struct BuildCommand {
  std::string manifest;
  std::string output;
  std::string cacheDir;
  std::vector<std::string> rules;
  std::vector<std::string> deviceProfiles;
  bool noCache = false;
  unsigned jobs = 0;
  bool quiet = false;
  bool progress = false;
  bool list = false;
  bool validate = false;
  std::string cacheUrl;
  GltfReadOptions gltf;
  bool listCmake = false;
  std::vector<std::string> only;  // --variant
  bool join = false;

  int run() {
    if (noCache && !cacheDir.empty())
      throw CLI::ValidationError("--cache-dir", "does not apply with --no-cache");
    if (quiet && progress) throw CLI::ValidationError("--progress", "does not apply with --quiet");
    auto start = std::chrono::steady_clock::now();
    Manifest m = loadManifest(manifest);
    if (!output.empty()) m.outputDir = output;
    m.rules.insert(m.rules.begin(), rules.begin(), rules.end());
    if (m.rules.empty())
      throw InputError(SourceLoc{m.file, 1, 1}, "no rules: the manifest needs 'rules' (a rules file or a list of "
                                                  "them), or the command line -r FILE");
    if (!deviceProfiles.empty()) {
      m.deviceProfile = deviceProfiles.front();
      m.portableProfiles.assign(deviceProfiles.begin() + 1, deviceProfiles.end());
    }
    std::vector<Variant> variants = expandVariants(m);
    if (list) {  // for build systems: the variants and their name-derived outputs
      for (const auto& v : variants) std::cout << v.name << "\n";
      return 0;
    }
    if (listCmake) {
      std::cout << cmakeListing(m, variants, planVariants(m, variants));
      return 0;
    }
    if (join) {  // the final edge after one `--variant` edge per variant
      std::vector<PendingFile> index;
      for (auto& f : joinIndex(m, variants)) index.push_back({f.path, f.contents});
      writeFilesAtomically(index);
      return 0;
    }
    std::set<std::string> always;  // rewritten even when unchanged: a build edge's outputs
    if (!only.empty()) {           // one build edge per variant: its outputs and its index entry
      std::vector<Variant> picked;
      for (const auto& name : only) {
        auto it = std::find_if(variants.begin(), variants.end(), [&](const Variant& v) { return v.name == name; });
        if (it == variants.end())
          throw InputError(SourceLoc{m.file, 0, 0},
                           fmt::format("no variant named '{}' (`shadergen build {} --list` lists them)", name, m.file));
        VariantEntryFiles ef = entryFiles(m, *it);
        if (always.count(ef.entry)) continue;  // named twice
        always.insert({ef.entry, ef.depfile});
        picked.push_back(*it);
        std::error_code ec;  // a failing variant leaves no entry for --join to take
        std::filesystem::remove(ef.entry, ec);
      }
      variants = std::move(picked);
    }
    BuildOptions bo;
    bo.jobs = jobs;
    if (!noCache) {
      bo.cacheDir = cacheDir.empty() ? (std::filesystem::path(m.outputDir) / ".shadergen-cache").string() : cacheDir;
      try {
        bo.cacheUrl = chooseCacheUrl(cacheUrl, m.cacheUrl);
      } catch (const std::invalid_argument& e) {
        throw CLI::ValidationError("--cache-url", e.what());
      }
      if (const char* auth = std::getenv("SHADERGEN_CACHE_AUTH")) bo.cacheAuth = auth;
    } else if (!cacheUrl.empty()) {
      throw CLI::ValidationError("--cache-url", "does not apply with --no-cache");
    }
    bo.warn = [](const std::string& w) { std::cerr << "shadergen: warning: " << w << "\n"; };
    // Validation opens the device once (its name and driver are part of every result's key).
    std::unique_ptr<DeviceVariantValidator> validator;
    if (validate || m.validate.enabled) {
      try {
        validator = std::make_unique<DeviceVariantValidator>(m.validate);
      } catch (const std::runtime_error& e) {
        throw InputError(m.validate.loc.file.empty() ? SourceLoc{m.file, 0, 0} : m.validate.loc,
                         fmt::format("cannot validate: {}", e.what()));
      }
      bo.validator = validator.get();
    }
    // With a device profile each variant is priced for the workload of its mesh: a glTF rig's
    // own, the manifest's `mesh:` for YAML rigs (measure/workload.h); measured once per rig
    // and parameters.
    if (!m.deviceProfile.empty()) {
      std::map<std::pair<std::string, std::map<std::string, int64_t>>, Workload> measured;
      for (const auto& v : variants) {
        auto key = std::make_pair(v.rig->path, v.params);
        auto it = measured.find(key);
        if (it == measured.end()) {
          try {
            it = measured.emplace(key, rigWorkload(v.rig->path, v.params, isGltfPath(v.rig->path) ? "" : m.mesh)).first;
          } catch (const InputError&) {
            continue;  // the variant's own generation reports what is wrong with its rig
          }
        }
        bo.workloads[v.name] = it->second;
      }
    }
    bo.gltf = gltf;
    bo.index = only.empty();
    // Progress on a terminal, quiet in CI and in logs.
    bool showProgress = progress || (!quiet && isatty(STDERR_FILENO) && !std::getenv("CI"));
    if (showProgress)
      bo.progress = [](size_t done, size_t total, const std::string& name, bool cached) {
        std::cerr << fmt::format("\r\033[K[{}/{}] {}{}", done, total, name, cached ? " (cached)" : "") << std::flush;
        if (done == total) std::cerr << "\n";
      };
    BuildReport r = buildVariants(m, variants, bo);
    for (const auto& d : r.warnings) std::cerr << formatDiagnostic(d) << "\n";
    for (const auto& b : r.variants) {
      if (b.ok) continue;
      std::cerr << fmt::format("{}: error: variant '{}' failed:\n", m.file, b.variant->name);
      for (const auto& d : b.errors) std::cerr << renderDiagnostic(d) << "\n";
    }
    // No output may be an input (a rig called NAME.json beside its variant's reflection).
    std::vector<InputFile> inputs{{m.file, "the manifest"}};
    for (const auto& b : r.variants)
      for (const auto& f : b.inputs) inputs.push_back({f, fmt::format("an input of variant '{}'", b.variant->name)});
    std::vector<std::string> outputs;
    for (const auto& f : r.files) outputs.push_back(f.path);
    refuseClobbering(outputs, inputs);
    // Unchanged outputs are left alone (their timestamps too, so dependents do not rebuild);
    // the index is always rewritten: it is the build step's output, newer than its inputs.
    std::vector<PendingFile> changed;
    for (const auto& f : r.files)
      if (f.path == r.indexPath || f.path == r.indexPath + ".d" || always.count(f.path) || !sameContents(f.path, f.contents))
        changed.push_back({f.path, f.contents});
    if (!changed.empty()) writeFilesAtomically(changed);
    if (r.failed) {  // an index left from an earlier build must not vouch for this one's outputs
      std::error_code ec;
      const std::string index = (std::filesystem::path(m.outputDir) / "index.json").string();
      std::filesystem::remove(index, ec);
      std::filesystem::remove(index + ".d", ec);
    }
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!quiet)
      std::cout << fmt::format("{} variants: {} generated, {} from the cache, {} failed; {} share another's SPIR-V; "
                               "{} files written ({:.2f} s)\n",
                               r.variants.size(), r.generated, r.cached, r.failed, r.sharedSpirv, changed.size(),
                               seconds);
    if (!quiet && bo.validator)
      std::cout << fmt::format("validated on {}: {} run, {} from the cache\n", validator->deviceName(), r.validated,
                               r.validationsCached);
    if (!quiet && !bo.cacheUrl.empty())
      std::cout << fmt::format("remote cache {}: {} hits, {} stored, {} entries rejected{}\n", redactUrl(bo.cacheUrl),
                               r.cache.remoteHits, r.cache.remoteStores, r.cache.rejected,
                               r.cache.remoteFailed ? " (unreachable: built without it)" : "");
    else if (!quiet && r.cache.rejected)
      std::cout << fmt::format("cache: {} entries rejected (corrupt), rebuilt\n", r.cache.rejected);
    return r.failed ? 1 : 0;
  }
};

}  // namespace

void registerBuild(CLI::App& app, CliState& state) {
  auto cmd = std::make_shared<BuildCommand>();
  CLI::App* sub = app.add_subcommand("build", "Build every variant of a manifest (one process, all cores, cached)");
  sub->add_option("manifest", cmd->manifest, "Variant manifest (YAML, docs/variants.md)")->required();
  sub->add_option("-o,--output", cmd->output, "Output directory (default: the manifest's 'output')");
  sub->add_option("-r,--rules", cmd->rules, "Rules file read before the manifest's own (repeatable)");
  sub->add_option("--device-profile", cmd->deviceProfiles,
                  "Device profile (YAML, docs/device-profiles.md) for every variant, in place of the manifest's "
                  "'device_profile'. Given several times: the portable plan across them, as generate's");
  sub->add_option("--cache-dir", cmd->cacheDir, "Cache directory (default: <output>/.shadergen-cache)");
  sub->add_flag("--no-cache", cmd->noCache, "Neither read nor write the cache");
  sub->add_option("-j,--jobs", cmd->jobs, "Worker threads (default: every hardware thread)");
  sub->add_flag("-q,--quiet", cmd->quiet, "No progress and no summary");
  sub->add_flag("--progress", cmd->progress, "Show progress even when standard error is not a terminal");
  sub->add_flag("--list", cmd->list, "Print the variant names (one a line) and build nothing");
  sub->add_flag("--validate", cmd->validate,
                "Validate every variant on a Vulkan device (lavapipe by default) with the manifest's 'validate' "
                "settings; results are cached");
  sub->add_option("--cache-url", cmd->cacheUrl,
                  "Shared cache server (HTTP GET/PUT, e.g. nginx WebDAV) over the local cache (default: "
                  "$SHADERGEN_CACHE_URL, then the manifest's 'cache_url'); credentials only from the environment "
                  "(SHADERGEN_CACHE_AUTH=user:password)");
  addGltfReadOptions(*sub, cmd->gltf);
  sub->add_option("--variant", cmd->only,
                  "Build only this variant (repeatable), leaving its index entry for --join instead of the index "
                  "(one build edge per variant)");
  sub->add_flag("--join", cmd->join, "Write index.json from the entries the --variant builds left; build nothing")
      ->excludes("--variant");
  sub->add_flag("--list-cmake", cmd->listCmake,
                "Print each variant's outputs and input files as CMake set() commands (for "
                "shadergen_add_shader_variants) and build nothing")
      ->excludes("--variant")
      ->excludes("--join")
      ->excludes("--list");
  sub->callback([cmd, &state] { state.run = [cmd] { return cmd->run(); }; });
}

}  // namespace sg

// `shadergen build MANIFEST.yaml`: every variant of a manifest in one process
// (generator/variants/builder.h, docs/variants.md).
#include <fmt/format.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "cli/commands.h"
#include "cli/output_files.h"
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

struct BuildCommand {
  std::string manifest;
  std::string output;
  std::string cacheDir;
  std::vector<std::string> rules;
  std::string deviceProfile;
  bool noCache = false;
  unsigned jobs = 0;
  bool quiet = false;
  bool progress = false;
  bool list = false;
  GltfReadOptions gltf;

  int run() {
    if (noCache && !cacheDir.empty())
      throw CLI::ValidationError("--cache-dir", "does not apply with --no-cache");
    if (quiet && progress) throw CLI::ValidationError("--progress", "does not apply with --quiet");
    auto start = std::chrono::steady_clock::now();
    Manifest m = loadManifest(manifest);
    if (!output.empty()) m.outputDir = output;
    m.rules.insert(m.rules.begin(), rules.begin(), rules.end());
    if (!deviceProfile.empty()) m.deviceProfile = deviceProfile;
    std::vector<Variant> variants = expandVariants(m);
    if (list) {  // for build systems: the variants and their name-derived outputs
      for (const auto& v : variants) std::cout << v.name << "\n";
      return 0;
    }
    BuildOptions bo;
    bo.jobs = jobs;
    bo.gltf = gltf;
    if (!noCache) bo.cacheDir = cacheDir.empty() ? (std::filesystem::path(m.outputDir) / ".shadergen-cache").string() : cacheDir;
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
    // Unchanged outputs are left alone (their timestamps too, so dependents do not rebuild);
    // the index is always rewritten: it is the build step's output, newer than its inputs.
    std::vector<PendingFile> changed;
    for (const auto& f : r.files)
      if (f.path == r.indexPath || f.path == r.indexPath + ".d" || !sameContents(f.path, f.contents))
        changed.push_back({f.path, f.contents});
    if (!changed.empty()) writeFilesAtomically(changed);
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!quiet)
      std::cout << fmt::format("{} variants: {} generated, {} from the cache, {} failed; {} share another's SPIR-V; "
                               "{} files written ({:.2f} s)\n",
                               r.variants.size(), r.generated, r.cached, r.failed, r.sharedSpirv, changed.size(),
                               seconds);
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
  sub->add_option("--device-profile", cmd->deviceProfile,
                  "Device profile (YAML, docs/device-profiles.md) for every variant, in place of the manifest's "
                  "'device_profile'");
  sub->add_option("--cache-dir", cmd->cacheDir, "Cache directory (default: <output>/.shadergen-cache)");
  sub->add_flag("--no-cache", cmd->noCache, "Neither read nor write the cache");
  sub->add_option("-j,--jobs", cmd->jobs, "Worker threads (default: every hardware thread)");
  sub->add_flag("-q,--quiet", cmd->quiet, "No progress and no summary");
  sub->add_flag("--progress", cmd->progress, "Show progress even when standard error is not a terminal");
  sub->add_flag("--list", cmd->list, "Print the variant names (one a line) and build nothing");
  addGltfReadOptions(*sub, cmd->gltf);
  sub->callback([cmd, &state] { state.run = [cmd] { return cmd->run(); }; });
}

}  // namespace sg

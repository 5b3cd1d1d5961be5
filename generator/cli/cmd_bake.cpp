// `shadergen bake occlusion MODEL.glb -o OUT.glb [options]`: per-vertex occlusion of a glTF
// model, base shape and morph targets, stored as _OCCLUSION attributes; `shadergen bake
// tangents MODEL.glb -o OUT.glb`: TANGENT frames from normals and UVs (docs/bake.md).
#include <fmt/format.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <iostream>
#include <optional>

#include "bake/gltf_bake.h"
#include "cli/commands.h"
#include "cli/output_files.h"

namespace sg {
namespace {

std::string lowerExtension(const std::string& path) {
  std::string e = std::filesystem::path(path).extension().string();
  for (auto& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return e;
}

// True for a .glb output, false for .gltf; anything else is a usage error. Refuses an output
// that names the model (before baking; its buffer files are known after: writeBaked).
bool binaryOutput(const std::string& model, const std::string& output) {
  std::string ext = lowerExtension(output);
  if (ext != ".glb" && ext != ".gltf")
    throw CLI::ValidationError("--output", fmt::format("'{}' must end in .glb or .gltf", output));
  refuseClobbering({output}, {{model, "the glTF model"}});
  return ext == ".glb";
}

// Writes the baked model unless `output` is the model or one of its buffer files (`inputs`).
void writeBaked(const std::string& model, const std::string& output, const std::string& bytes,
                const std::vector<std::string>& inputs) {
  std::vector<InputFile> files;
  for (const auto& in : inputs) files.push_back({in, in == model ? "the glTF model" : "a buffer file of the model"});
  refuseClobbering({output}, files);
  writeFilesAtomically({PendingFile{output, bytes}});
}

struct BakeOcclusionCommand {
  std::string model;
  std::string output;
  int rays = 256;
  std::string distribution = "uniform";
  double maxDistance = -1;  // <0: unlimited
  double offset = -1;       // <0: automatic
  uint64_t seed = 1;
  int threads = 0;
  std::optional<double> time;
  std::string animation;
  bool quiet = false;

  int run() {
    if (!animation.empty() && !time) throw CLI::ValidationError("--animation", "needs --time");
    const bool binary = binaryOutput(model, output);  // before the (long) bake
    bake::GltfBakeOptions o;
    o.occlusion.rays = rays;
    o.occlusion.distribution = distribution == "cosine" ? bake::Distribution::Cosine : bake::Distribution::Uniform;
    if (maxDistance >= 0) o.occlusion.maxDistance = maxDistance;
    o.occlusion.offset = offset;
    o.occlusion.seed = seed;
    o.occlusion.threads = threads;
    o.time = time;
    o.animation = animation;
    o.binary = binary;
    bool tty = !quiet && isatty(STDERR_FILENO);
    if (tty)
      o.progress = [](int pass, int passes, const std::string& what, size_t done, size_t total) {
        std::cerr << fmt::format("\r\033[K[{}/{}] {}: {}%", pass, passes, what, total ? done * 100 / total : 100)
                  << std::flush;
      };
    auto start = std::chrono::steady_clock::now();
    bake::GltfBakeResult r = bake::bakeGltfOcclusion(model, o);
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (tty) std::cerr << "\r\033[K" << std::flush;
    writeBaked(model, output, r.bytes, r.inputs);
    if (!quiet) {
      for (const auto& n : r.notes) std::cerr << fmt::format("{}: warning: {}\n", model, n);
      size_t vertices = 0;
      for (const auto& p : r.primitives) {
        vertices += p.vertices;
        std::string t;
        for (size_t k = 0; k < p.meanAbsTargetDelta.size(); ++k)
          t += fmt::format("{}{:.3f}", k ? ", " : "; mean |delta| per target: ", p.meanAbsTargetDelta[k]);
        std::cout << fmt::format("mesh {} '{}' primitive {}: {} vertices, mean occlusion {:.3f}{}\n", p.mesh,
                                 p.meshName, p.primitive, p.vertices, p.meanOcclusion, t);
      }
      std::cout << fmt::format("{}: {} vertices, {} triangles, {} pass(es), {} rays ({} per vertex, {}) in {:.2f} s "
                               "({:.1f} Mrays/s); wrote {}\n",
                               model, vertices, r.triangles, r.passes, r.rays, rays, distribution, seconds,
                               seconds > 0 ? static_cast<double>(r.rays) / seconds * 1e-6 : 0.0, output);
    }
    return 0;
  }
};

struct BakeTangentsCommand {
  std::string model;
  std::string output;
  bool quiet = false;

  int run() {
    bake::GltfTangentResult r = bake::bakeGltfTangents(model, binaryOutput(model, output));
    writeBaked(model, output, r.bytes, r.inputs);
    if (!quiet) {
      for (const auto& n : r.notes) std::cerr << fmt::format("{}: warning: {}\n", model, n);
      for (const auto& p : r.primitives)
        std::cout << fmt::format("mesh {} '{}' primitive {}: {} vertices, {} target(s), {} without a texture direction\n",
                                 p.mesh, p.meshName, p.primitive, p.vertices, p.targets, p.fallbacks);
      std::cout << fmt::format("{}: tangents for {} primitive(s); wrote {}\n", model, r.primitives.size(), output);
    }
    return 0;
  }
};

}  // namespace

void registerBake(CLI::App& app, CliState& state) {
  CLI::App* bake = app.add_subcommand("bake", "Bake per-vertex data into glTF models");
  bake->require_subcommand(1);
  auto cmd = std::make_shared<BakeOcclusionCommand>();
  CLI::App* occ = bake->add_subcommand(
      "occlusion", "Per-vertex hemisphere occlusion of every primitive and morph target (_OCCLUSION attributes)");
  occ->add_option("model", cmd->model, "glTF model (.gltf or .glb)")->required();
  occ->add_option("-o,--output", cmd->output, "Output model (.glb, or .gltf with embedded buffers)")->required();
  occ->add_option("--rays", cmd->rays, "Rays per vertex (default 256)")->check(CLI::Range(1, 1 << 20));
  occ->add_option("--distribution", cmd->distribution,
                  "uniform (default): blocked fraction of the hemisphere's solid angle, as Dawn; "
                  "cosine: blocked fraction of cosine-weighted sky light (ambient occlusion)")
      ->check(CLI::IsMember({"uniform", "cosine"}));
  occ->add_option("--max-distance", cmd->maxDistance, "Hits farther than this do not block (default: unlimited)")
      ->check(finiteNumber(true));
  occ->add_option("--offset", cmd->offset,
                  "Ray origins move this far along the normal (default: 1e-5 of the scene's diagonal)")
      ->check(finiteNumber(false));
  occ->add_option("--seed", cmd->seed, "Random seed (default 1); the result does not depend on --threads");
  occ->add_option("--threads", cmd->threads, "Worker threads (default: all cores)")->check(CLI::Range(1, 1024));
  occ->add_option("--time", cmd->time, "Pose at this animation time in seconds (default: bind pose)")
      ->check(finiteNumber(false));
  occ->add_option("--animation", cmd->animation, "With --time: animation name or index (default: the first)");
  occ->add_flag("-q,--quiet", cmd->quiet, "No progress, summary or warnings");
  occ->callback([cmd, &state] { state.run = [cmd] { return cmd->run(); }; });

  auto tan = std::make_shared<BakeTangentsCommand>();
  CLI::App* tc = bake->add_subcommand(
      "tangents", "TANGENT frames from normals and TEXCOORD_0 for primitives without them, morph targets included");
  tc->add_option("model", tan->model, "glTF model (.gltf or .glb)")->required();
  tc->add_option("-o,--output", tan->output, "Output model (.glb, or .gltf with embedded buffers)")->required();
  tc->add_flag("-q,--quiet", tan->quiet, "No summary or warnings");
  tc->callback([tan, &state] { state.run = [tan] { return tan->run(); }; });
}

}  // namespace sg

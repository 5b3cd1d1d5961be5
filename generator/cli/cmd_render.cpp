// `shadergen render`: generate, then draw the rig with the generated vertex shader and the
// fragment shader into a PNG (docs/render.md).
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <set>

#include "cli/commands.h"
#include "cli/fresh_process.h"
#include "cli/whole_model.h"
#include "measure/gpu_bench.h"
#include "pipeline/pin.h"
#include "render/render.h"
#include "variants/builder.h"
#include "variants/manifest.h"

namespace sg {
namespace {

// "x,y,z" → vec3 (finite numbers only).
glm::vec3 parseVec3(const std::string& option, const std::string& text) {
  glm::vec3 v(0.0f);
  size_t start = 0;
  for (int i = 0; i < 3; ++i) {
    size_t comma = text.find(',', start);
    if ((i < 2) == (comma == std::string::npos))
      throw CLI::ValidationError(option, "expected x,y,z, got '" + text + "'");
    std::string part = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    size_t used = 0;
    float f = 0;
    try {
      f = std::stof(part, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (part.empty() || used != part.size() || !std::isfinite(f))
      throw CLI::ValidationError(option, "expected three finite numbers x,y,z, got '" + text + "'");
    v[i] = f;
    start = comma + 1;
  }
  return v;
}

// The files the options name, for an output to be checked against before anything runs: the
// rig (and a glTF model's buffer files: `-o M.bin` beside M.gltf), the fragment shader, the
// rules and the device profiles.
std::vector<InputFile> optionInputs(const GenerateOptions& gen) {
  auto parts = wholeModelParts(gen.rigPath);
  std::vector<InputFile> inputs{{parts ? parseGltfRef(gen.rigPath, true).file : gen.rigPath, "the rig"},
                                {gen.fragmentPath, "the fragment shader"}};
  for (const auto& r : gen.rulesPaths) inputs.push_back({r, "a rules file"});
  if (!gen.deviceProfilePath.empty()) inputs.push_back({gen.deviceProfilePath, "a device profile"});
  for (const auto& d : gen.portableProfilePaths) inputs.push_back({d, "a device profile"});
  if (isGltfPath(gen.rigPath))
    for (const auto& f : importGltfRef(parts ? parts->front().ref : gen.rigPath, gen.gltf).rig.sourceFiles)
      inputs.push_back({f, "the rig"});
  return inputs;
}

struct RenderCommand {
  GenerateArgs args;
  RenderOptions ro;
  std::string output;
  std::string size = "512x512";
  std::string light, rim;
  bool noLayers = false;
  std::optional<double> morphWeight;

  // MODEL.glb#*: every primitive generated and posed first (a failure names its primitive
  // and nothing is drawn or written), then drawn under one camera.
  RenderResult renderModel(RenderSession& session, const std::vector<GltfPart>& parts) {
    checkWholeModelAnimation(parts, ro.animation);
    std::vector<ModelPart> programs;
    std::vector<std::string> failed =
        forEachPart(parts, [&](const GltfPart& part) {
          RenderOptions o = ro;
          o.gen = partOptions(ro.gen, part.ref);
          programs.push_back(modelPart(o, part));
        });
    failIfPartsFailed(ro.gen.rigPath, parts.size(), failed);
    for (const auto& p : programs)
      for (const auto& n : p.notes) std::cerr << fmt::format("{}: warning: {}: {}\n", ro.gen.rigPath, p.name, n);
    frameModel(programs, ro.camera, float(ro.width) / float(ro.height));
    FragmentProgram frag = compileFragmentFile(ro.gen.fragmentPath, ro.gen.targetEnv);
    RenderResult r = session.renderModel(programs, frag, texturesFor(frag, ro.lighting), ro);
    for (const auto& p : programs) r.notes.insert(r.notes.end(), p.gen.in.notes.begin(), p.gen.in.notes.end());
    return r;
  }

  int run() {
    ro.gen = args.resolve();
    // Priced for the model's own mesh under a profile, as generate prices it.
    if (!ro.gen.deviceProfilePath.empty() && isGltfPath(ro.gen.rigPath) && !wholeModelParts(ro.gen.rigPath))
      measureWorkloadOf(ro.gen, "");
    ro.limits = {!ro.device.empty(), args.maxAttributes->count() > 0, args.maxUniformBytes->count() > 0};
    ro.validationLayers = !noLayers;
    if (morphWeight) {
      ro.morphWeight = static_cast<float>(*morphWeight);
      ro.gltfMorphWeight = morphWeight;
    }
    unsigned w = 0, h = 0;
    char tail = 0;
    if (std::sscanf(size.c_str(), "%ux%u%c", &w, &h, &tail) != 2 || w == 0 || h == 0 || w > 8192 || h > 8192)
      throw CLI::ValidationError("--size", "expected WIDTHxHEIGHT with each in 1..8192, got '" + size + "'");
    ro.width = w;
    ro.height = h;
    if (!light.empty()) ro.lighting.keyDirection = parseVec3("--light", light);
    if (!rim.empty()) ro.lighting.rimDirection = parseVec3("--rim-light", rim);
    if (glm::length(ro.lighting.keyDirection) == 0.0f || glm::length(ro.lighting.rimDirection) == 0.0f)
      throw CLI::ValidationError("--light", "a light direction must not be zero");

    auto parts = wholeModelParts(ro.gen.rigPath);
    refuseClobbering({output}, optionInputs(ro.gen));

    RenderSession session(ro.device, ro.validationLayers);
    RenderResult r = parts ? renderModel(session, *parts) : session.render(ro);
    for (const auto& n : r.notes) std::cerr << formatDiagnostic(n) << "\n";
    std::string png = encodePng(r.image);
    writeFilesAtomically({{output, png}});
    size_t covered = 0;
    for (float d : r.image.depth) covered += d < 1.0f;
    if (!r.limits.empty()) std::cout << r.limits << "\n";
    std::cout << fmt::format("{}: {}x{} on {}, plan cost {}, {} of {} pixels covered\n", output, r.image.width,
                             r.image.height, r.device, r.planCost, covered, r.image.depth.size());
    for (const auto& m : r.validationMessages) std::cerr << "shadergen: warning: validation layer: " << m << "\n";
    return r.validationMessages.empty() ? 0 : 1;
  }
};

struct BenchCommand {
  CLI::App* cmd = nullptr;
  GenerateArgs args;
  GpuBenchOptions bo;
  std::string size = "256x256";
  std::string raster = "both";
  bool noLayers = false;
  bool noAlternatives = false, noFloor = false;
  bool oneProcess = false;  // --one-process: every part of MODEL.glb#* timed in this process
  // A fresh process timing one part for its parent (cli/fresh_process.h): the part and where its
  // report goes. Hidden options; the parent adds them to its own command line.
  std::string timePart, reportPath;
  std::vector<std::string> commandLine;
  std::string pinOut;  // --pin-out: the fastest validated plan, pinned (pipeline/pin.h)
  // --manifest: every variant (or each --variant) timed in place of --rig/-f/-r, each in a fresh
  // process (--time-variant in the child); --pin-out is then a directory of <variant>.pin.yaml,
  // what the manifest's `pins: DIR` reads.
  std::string manifestPath, timeVariant;
  std::vector<std::string> variantNames;
  uint32_t processes = 1;  // --processes: fresh processes per rig, part or variant, their rounds merged
  // --max-candidates: how far --candidates K widens where the timed plans do not rank as the
  // objective does (0: 3K, at most 64); --time-candidates: a fresh child's count, the parent's.
  size_t maxCandidates = 0, timeCandidates = 0;

  // A rig, part or variant timed in this process, or in --processes fresh ones (`fresh`; the
  // child told by `childArgs`). With --candidates K, timed once more with the --max-candidates
  // cheapest where the K do not rank as the objective ranks them (rankCandidates): the measured
  // choice then looks past a short list its profile cannot order.
  GpuBenchReport timeOne(GpuBenchOptions one, bool fresh, const std::vector<std::string>& childArgs,
                         const std::string& what) const {
    auto time = [&](size_t candidates) {
      one.candidates = candidates;
      if (!fresh) return runGpuBench(one);
      std::vector<std::string> child = childArgs;
      if (candidates > 0) child.insert(child.end(), {"--time-candidates", std::to_string(candidates)});
      return benchInFreshProcesses(commandLine, child, what, false, processes);
    };
    const size_t first = one.candidates;
    const size_t widest = maxCandidates > 0 ? maxCandidates : std::min<size_t>(64, 3 * first);
    GpuBenchReport rep = time(first);
    if (first == 0 || widest <= first) return rep;
    size_t plans = 0;
    for (const auto& row : rep.rows) {
      if (row.validation.rfind("FAIL", 0) == 0) return rep;  // no pin from this run: nothing to widen for
      plans += row.hasCost;
    }
    if (plans < first) return rep;  // every plan there is was timed
    const CandidateRanking ranking = rankCandidates(rep);
    if (!ranking.cannotRank) return rep;
    GpuBenchReport wide = time(widest);
    wide.notes.push_back(Diagnostic{
        Severity::Note, SourceLoc{what, 0, 0},
        fmt::format("the search's objective puts the {} cheapest plans {:.3g} % apart and the device measured {:.3g} %: it "
                    "cannot rank them here, so the {} cheapest were timed (--max-candidates)",
                    ranking.plans, 100 * ranking.predictedSpread, 100 * ranking.measuredSpread, widest)});
    return wide;
  }

  int run() {
    if (timeCandidates > 0) bo.candidates = timeCandidates;
    if (maxCandidates > 0 && bo.candidates == 0) throw CLI::ValidationError("--max-candidates", "needs --candidates");
    if (maxCandidates > 0 && maxCandidates < bo.candidates)
      throw CLI::ValidationError("--max-candidates", fmt::format("{} is fewer than --candidates {}", maxCandidates, bo.candidates));
    if (!manifestPath.empty()) return runManifest();
    for (const char* o : {"--rig", "--fragment", "--rules"})
      if (cmd->count(o) == 0) throw CLI::RequiredError(std::string(o) + " (or --manifest)");
    if (!variantNames.empty()) throw CLI::ValidationError("--variant", "needs --manifest");
    bo.render.gen = args.resolve();
    return runRig();
  }

  // The render and measuring options every mode shares, from the command line.
  void resolveMeasuring() {
    bo.render.limits = {!bo.render.device.empty(), args.maxAttributes->count() > 0, args.maxUniformBytes->count() > 0};
    bo.render.validationLayers = !noLayers;
    unsigned w = 0, h = 0;
    char tail = 0;
    if (std::sscanf(size.c_str(), "%ux%u%c", &w, &h, &tail) != 2 || w == 0 || h == 0 || w > 8192 || h > 8192)
      throw CLI::ValidationError("--size", "expected WIDTHxHEIGHT with each in 1..8192, got '" + size + "'");
    bo.render.width = w;
    bo.render.height = h;
    bo.rasterOn = raster != "off";
    bo.rasterOff = raster != "on";
    bo.alternatives = !noAlternatives;
    bo.floor = !noFloor;
  }

  int runRig() {
    if (isGltfPath(bo.render.gen.rigPath))
      refuseOption(*cmd, "--mesh", "to a glTF rig (" + bo.render.gen.rigPath + "): it is timed on its own mesh");
    resolveMeasuring();
    if (!pinOut.empty()) {
      if (wholeModelParts(bo.render.gen.rigPath))
        throw CLI::ValidationError("--pin-out", "pins one rig's plan: name one primitive (MODEL.glb#m/p), not the whole model");
      std::vector<InputFile> inputs = optionInputs(bo.render.gen);
      if (!bo.handPortPath.empty()) inputs.push_back({bo.handPortPath, "the hand port"});
      refuseClobbering({pinOut}, inputs);
    }
    if (!timePart.empty()) {  // the child of a whole-model bench: one part, its report to the parent
      if (reportPath.empty()) throw CLI::ValidationError("--time-part", "needs --child-report");
      bo.render.gen.rigPath = timePart;
      writeFreshProcessReport(reportPath, [&] { return runGpuBench(bo); });
      return 0;
    }
    // MODEL.glb#*: every primitive timed on its own mesh (its vertices, its index order), one
    // table each, each in a fresh process unless --one-process; a primitive that cannot be
    // generated is reported and the others still run.
    if (auto parts = wholeModelParts(bo.render.gen.rigPath)) {
      if (!bo.handPortPath.empty())
        throw CLI::ValidationError("--hand-port", "does not apply to a whole model: one hand port cannot stand in for every primitive");
      const std::string model = bo.render.gen.rigPath;
      int failed = 0;
      std::vector<std::string> broken = forEachPart(*parts, [&](const GltfPart& part) {
        GpuBenchOptions one = bo;
        one.render.gen.rigPath = part.ref;
        GpuBenchReport rep = timeOne(one, !oneProcess, {"--time-part", part.ref}, part.ref);
        std::cout << fmt::format("## {} ({})\n\n", part.name, part.ref);
        failed += report(rep);
        std::cout << "\n";
      });
      failIfPartsFailed(model, parts->size(), broken, "the others were timed");
      return failed ? 1 : 0;
    }
    const GpuBenchReport rep = timeOne(bo, processes > 1, {"--time-part", bo.render.gen.rigPath}, bo.render.gen.rigPath);
    if (report(rep)) return 1;  // no pin from a run where a program failed on the device
    if (!pinOut.empty()) writePin(rep, pinOut);
    return 0;
  }

  // bench --manifest: each variant as `build` generates it (variants/builder.h generateOptionsOf),
  // without its old pin; a YAML rig on --mesh, else the manifest's `mesh:`, else dawn; a glTF rig
  // on its own mesh. A variant that fails is reported and the others still run.
  int runManifest() {
    const std::string why = "with --manifest: each variant's inputs and options are the manifest's";
    for (const CLI::Option* o : args.generateOptions)
      if (o->get_name() != "--device-profile") refuseOption(*cmd, o->get_name(), why);
    for (const char* o : {"--hand-port", "--time-part"}) refuseOption(*cmd, o, why);
    const GenerateOptions given = args.resolve();  // --device-profile, in place of the manifest's
    Manifest m = loadManifest(manifestPath);
    if (!given.deviceProfilePath.empty()) {
      m.deviceProfile = given.deviceProfilePath;
      m.portableProfiles = given.portableProfilePaths;
    }
    const std::vector<Variant> all = expandVariants(m);
    auto named = [&](const std::string& name, const char* option) {
      auto v = std::find_if(all.begin(), all.end(), [&](const Variant& x) { return x.name == name; });
      if (v == all.end()) throw CLI::ValidationError(option, fmt::format("'{}' is no variant of {}", name, manifestPath));
      return *v;
    };
    std::vector<Variant> variants;
    for (const auto& name : variantNames) variants.push_back(named(name, "--variant"));
    if (variantNames.empty()) variants = all;
    resolveMeasuring();
    const std::string mesh = cmd->count("--mesh") ? bo.render.mesh : m.mesh.empty() ? bo.render.mesh : m.mesh;
    auto optionsOf = [&](const Variant& v) {
      GpuBenchOptions one = bo;
      one.render.gen = generateOptionsOf(m, v, BuildOptions{});
      one.render.gen.gltf = given.gltf;
      one.render.gen.pin.reset();  // the candidates are the profile's, not an earlier measurement's
      one.render.mesh = mesh;
      return one;
    };
    if (!timeVariant.empty()) {  // the child: one variant, its report to the parent
      if (reportPath.empty()) throw CLI::ValidationError("--time-variant", "needs --child-report");
      writeFreshProcessReport(reportPath, [&] { return runGpuBench(optionsOf(named(timeVariant, "--time-variant"))); });
      return 0;
    }
    if (!pinOut.empty()) std::filesystem::create_directories(pinOut);
    int failed = 0;
    std::vector<std::string> broken;
    for (const Variant& v : variants)
      if (!runReportingFailure(SourceLoc{m.file, 0, 0}, fmt::format("variant {} failed:", v.name), [&] {
            GpuBenchReport rep = timeOne(optionsOf(v), !oneProcess, {"--time-variant", v.name}, v.name);
            std::cout << fmt::format("## {}\n\n", v.name);
            const int f = report(rep);
            failed += f;
            if (!pinOut.empty() && f == 0) writePin(rep, (std::filesystem::path(pinOut) / (v.name + ".pin.yaml")).string());
            std::cout << "\n";
          }))
        broken.push_back(v.name);
    if (!broken.empty())
      throw InputError(SourceLoc{m.file, 0, 0}, fmt::format("{} of {} variant(s) failed ({}); the others were timed",
                                                            broken.size(), variants.size(), fmt::join(broken, ", ")));
    return failed ? 1 : 0;
  }

  // The fastest validated plan as a pin (pipeline/pin.h).
  void writePin(const GpuBenchReport& rep, const std::string& path) const {
    const int chosen = pinnedPlan(rep);
    if (chosen < 0) throw std::runtime_error("--pin-out: no plan was timed by " + rep.predictionClock);
    const GpuBenchRow& f = rep.rows[size_t(chosen)];
    auto sortedNames = [](const std::vector<std::string>& names) {
      const std::set<std::string> once(names.begin(), names.end());
      return std::vector<std::string>(once.begin(), once.end());
    };
    Pin pin;
    PinTiming timing;
    timing.device = rep.device;
    timing.driver = rep.driver;
    timing.clock = rep.predictionClock;
    timing.nsPerVertex = timing.fastestNsPerVertex = medianRound(f);
    timing.generatedNsPerVertex = medianRound(rep.rows.front());
    pin.devices = {timing};
    pin.label = f.label;
    pin.program = f.program;
    pin.rules = sortedNames(f.rules);
    pin.bans = sortedNames(f.pin);
    pin.inputs = rep.inputs;
    // Every plan weighed, for a choice over several devices (pin merge).
    for (const auto& row : rep.rows)
      if (weighedPlan(row)) {
        ++pin.candidates;
        pin.timed.push_back({row.label, row.program, sortedNames(row.rules), sortedNames(row.pin), medianRound(row)});
      }
    writeFilesAtomically({{path, formatPin(pin)}});
    std::cout << fmt::format("{}: pins {} (its median round {:.4f} ns per vertex; the generated plan's {:.4f})\n", path,
                             f.label, timing.nsPerVertex, timing.generatedNsPerVertex);
  }

  // Prints the report; returns how many programs failed on the device.
  static int report(const GpuBenchReport& rep) {
    for (const auto& n : rep.notes) std::cerr << formatDiagnostic(n) << "\n";
    std::cout << formatGpuBench(rep);
    int failed = 0;
    for (const auto& row : rep.rows)
      if (row.validation.rfind("FAIL", 0) == 0) {
        std::cerr << "shadergen: error: " << row.label << " fails on " << rep.device << " (not timed): " << row.validation << "\n";
        ++failed;
      }
    return failed;
  }
};

}  // namespace

void registerRender(CLI::App& app, CliState& state) {
  auto cmd = std::make_shared<RenderCommand>();
  CLI::App* sub = app.add_subcommand("render", "Draw the rig with the generated vertex shader and the fragment shader into a PNG");
  cmd->args.add(*sub);
  sub->add_option("-o,--output", cmd->output, "PNG file to write")->required();
  sub->add_option("--mesh", cmd->ro.mesh, "Procedural mesh: head (default), limb, dawn (180k vertices)")
      ->check(CLI::IsMember({"head", "limb", "dawn"}));
  sub->add_option("--size", cmd->size, "Image size WIDTHxHEIGHT (default 512x512)");
  sub->add_option("--device", cmd->ro.device,
                  "Vulkan device name (substring); default lavapipe. A named device's own limits constrain the search, "
                  "as in validate --device");
  sub->add_flag("--no-validation-layers", cmd->noLayers, "Run without the Khronos validation layer");
  sub->add_option("--time", cmd->ro.time, "glTF rig (MODEL.glb#m/p, or MODEL.glb#* for the whole model): animation time in seconds (default 0)")
      ->check(finiteNumber(false));
  sub->add_option("--animation", cmd->ro.animation, "glTF rig: animation name or index (default: the first)");
  sub->add_option("--pose-seed", cmd->ro.poseSeed, "0 (default): rest pose; N: the random pose of seed N");
  sub->add_option("--morph-weight", cmd->morphWeight,
                  "Weight of every morph target: in the rest pose (default 0.5), or for a glTF rig in place of the "
                  "animation's (default: the animation's)")
      ->check(finiteNumber(false))
      ->check(CLI::Range(0.0, 1000.0));  // far past 1, float32 outputs overflow (a length of 1e20 squares to inf)
  sub->add_option("--yaw", cmd->ro.camera.yawDegrees, "Camera yaw in degrees around +Y (0: the face)")
      ->check(CLI::Range(-360.0f, 360.0f));
  sub->add_option("--pitch", cmd->ro.camera.pitchDegrees, "Camera pitch in degrees")->check(CLI::Range(-89.0f, 89.0f));
  sub->add_option("--zoom", cmd->ro.camera.zoom, "Closer (> 1) or farther (< 1) than the framing distance")
      ->check(CLI::Range(0.1f, 10.0f));
  sub->add_option("--light", cmd->light, "Direction towards the key light, x,y,z (world space)");
  sub->add_option("--rim-light", cmd->rim, "Direction of the hilight cube map's rim light, x,y,z");
  sub->add_option("--texture-size", cmd->ro.lighting.textureSize,
                  "Side of listing 3-4's procedural 2D maps in texels (default 1024; mipmapped)")
      ->check(CLI::Range(1, 4096));
  sub->callback([cmd, &state] { state.run = [cmd] { return cmd->run(); }; });

  auto bench = std::make_shared<BenchCommand>();
  bench->bo.render.mesh = "dawn";
  CLI::App* b = app.add_subcommand("bench", "Time the generated vertex program, its forced alternatives, a hand-written "
                                            "port and a pass-through floor on the GPU (timestamp queries), each validated on that "
                                            "device first (one that fails is not timed; exit status 1)");
  bench->cmd = b;
  bench->args.add(*b, false);  // --manifest stands in for --rig, -f and -r
  b->add_option("--hand-port", bench->bo.handPortPath, "A hand-written vertex shader with the same interface "
                                                       "(a_<attribute>, u_<uniform>, gl_VertexIndex, the generated program's storage buffers "
                                                       "at their bindings), e.g. examples/dawn/listing-3-3.vert");
  b->add_option("--mesh", bench->bo.render.mesh, "Procedural mesh for a YAML rig: dawn (default, 180k vertices), head, limb "
                                                 "(a glTF rig, MODEL.glb#m/p or the whole MODEL.glb#*, draws its own mesh)")
      ->check(CLI::IsMember({"head", "limb", "dawn"}));
  b->add_option("--size", bench->size, "Render target WIDTHxHEIGHT with rasterization on (default 256x256)");
  b->add_option("--draws", bench->bo.drawsPerFrame, "Draws of the mesh between two timestamps (default 8)")
      ->check(CLI::Range(uint32_t(1), kMostDrawsPerFrame));
  b->add_option("--min-frame-vertices", bench->bo.minVerticesPerFrame,
                "A smaller mesh (a model's part) is drawn more often than --draws, so that each timed frame draws at least this "
                "many vertices (default 16000: the 2,009-vertex head at 8 draws; 0: exactly --draws)")
      ->check(CLI::Range(0, 100000000));
  addInputMemoryOption(*b, bench->bo.inputMemory);
  b->add_option("--frames", bench->bo.frames, "Timed frames; the median is reported (default 7)")->check(CLI::Range(1, 1000));
  b->add_option("--rounds", bench->bo.rounds, "Passes over every program, order rotated; the best counts (default 3)")
      ->check(CLI::Range(1, 100));
  b->add_option("--raster", bench->raster, "on, off (rasterizer discard + transform feedback) or both (default)")
      ->check(CLI::IsMember({"on", "off", "both"}));
  b->add_flag("--no-alternatives", bench->noAlternatives, "Only the generated plan (and the hand port and floor)");
  b->add_flag("--no-floor", bench->noFloor, "Leave out the pass-through floor");
  b->add_option("--candidates", bench->bo.candidates,
                "Time the K plans cheapest under the search's objective (the device profile's predicted time), the generated "
                "one first, instead of its forced alternatives: the candidates of a measured choice (--pin-out)")
      ->check(CLI::Range(1, 64));
  b->add_option("--max-candidates", bench->maxCandidates,
                "With --candidates K: where the device does not show the differences the objective predicts between the K "
                "(it predicts 5 % or more and the device shows under a tenth of that), time the M cheapest instead "
                "(default 3K, at most 64; K: never)")
      ->check(CLI::Range(1, 64));
  b->add_option("--time-candidates", bench->timeCandidates)->group("");  // a fresh child's --candidates
  b->add_option("--pin-out", bench->pinOut,
                "Write the fastest validated plan as a pin file (YAML): generate --pin writes that plan on any machine "
                "(docs/performance.md, \"A measured choice\")");
  b->add_option("--device", bench->bo.render.device,
                "Vulkan device name (substring); default lavapipe. A named device's own limits constrain the search, "
                "as in validate --device");
  b->add_flag("--no-validation-layers", bench->noLayers, "Run without the Khronos validation layer (use for timings)");
  addOneProcessFlag(*b, bench->oneProcess, "part or variant");
  addProcessesOption(*b, bench->processes, "rig, part or variant");
  b->add_option("--manifest", bench->manifestPath,
                "Time the variants of a build manifest (docs/variants.md) in place of --rig/-f/-r, each as `build` generates "
                "it, each in a fresh process unless --one-process; with --pin-out DIR, DIR/<variant>.pin.yaml each, what "
                "the manifest's `pins: DIR` reads");
  b->add_option("--variant", bench->variantNames, "With --manifest: only this variant (repeatable)");
  b->add_option("--time-part", bench->timePart)->group("");  // a fresh process's one part (cli/fresh_process.h)
  b->add_option("--child-report", bench->reportPath)->group("");
  b->add_option("--time-variant", bench->timeVariant)->group("");
  b->callback([bench, &state] {
    bench->commandLine = state.commandLine;
    state.run = [bench] { return bench->run(); };
  });
}

}  // namespace sg

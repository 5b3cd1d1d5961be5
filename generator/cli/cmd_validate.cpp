// `shadergen validate`: generate, run on lavapipe, compare with the GLM reference.
#include <fmt/format.h>

#include <filesystem>
#include <iostream>

#include "cli/commands.h"
#include "validate/gltf_scene.h"
#include "validate/poses.h"
#include "cli/output_files.h"
#include "cli/whole_model.h"
#include "validate/validate.h"
#include "validate/validation_files.h"

namespace sg {
namespace {

struct ValidateCommand {
  CLI::App* cmd = nullptr;
  GenerateArgs args;
  std::string mesh = "head";
  uint32_t seed = 1;
  std::string poses = "2";  // a count of random poses, or a pose file
  std::string savePoses;
  bool strict = false;
  bool crossCheck = false;
  std::string device;
  bool noLayers = false;
  bool noFloatCheck = false;
  Tolerance tol;
  std::vector<double> times;  // glTF rigs: animation times
  std::string animation;
  std::optional<double> morphWeight;  // glTF rigs: every target's weight instead of the animation's
  std::string via = "spirv";
  bool optimize = false;
  CrossArgs cross;
  std::string reportPath;  // --report FILE.json
  std::vector<std::string> modelFiles;  // the glTF model and its buffer files: inputs
  std::string saveOutputs;  // --save-outputs DIR

  // A glTF primitive at every instance and time: its section of the text report, and what
  // --report and --save-outputs write.
  ValidatedPart validatePrimitive(Validator& v, const GltfImport& model, const GenerateOptions& gen,
                                  const GltfSceneOptions& so, const std::string& name, GltfSceneInfo& info) {
    ValidationScene scene = gltfScene(model, so, &info);
    ValidatedPart part;
    part.name = name;
    part.rig = gen.rigPath;
    part.report = v.run(scene, gen);
    part.instances = info.instances;
    part.instanceNotes = info.notes;
    part.times = info.times;
    part.vertices = scene.mesh.vertexCount;
    part.mode = model.data.mode;
    part.indices = model.data.indices;
    return part;
  }

  // "instances: 84 checked, each at every time (node 10, node 21, ...)", a note per instance
  // left out, and a line per failing instance and time.
  static std::string formatInstances(const ValidatedPart& p) {
    // Past 6 (a GPU-instanced node has hundreds): the first 4, "...", the last; --report has all.
    const size_t n = p.instances.size();
    std::string names;
    for (size_t k = 0; k < n; ++k) {
      if (n > 6 && k >= 4 && k + 1 < n) continue;
      names += (k == 0 ? "" : n > 6 && k + 1 == n ? ", ..., " : ", ") + p.instances[k].name;
    }
    std::string s = fmt::format("instances: {} checked, each at every time ({})\n", p.instances.size(), names);
    for (const auto& n : p.instanceNotes) s += "note: " + n + "\n";
    const RunReport& run = p.report.runs.front();
    const size_t nt = std::max<size_t>(1, p.times.size());
    for (size_t k = 0; k < run.poseOutputs.size(); ++k)
      for (const auto& o : run.poseOutputs[k])
        if (!o.pass)
          s += fmt::format("  FAIL instance {} ({}) at t = {:g}: {} max rel {:.3e} at vertex {}\n", k / nt,
                           p.instances[k / nt].name, p.times[k % nt], o.name, o.maxRelError, o.worstVertex);
    return s;
  }

  // --report and --save-outputs, all files or none.
  void writeFiles(const ValidateOptions& vo, const std::vector<ValidatedPart>& parts) {
    if (reportPath.empty() && saveOutputs.empty()) return;
    ValidationContext ctx;
    ctx.model = vo.gen.rigPath;
    ctx.animation = animation;
    ctx.tolerance = vo.tolerance;
    ctx.strict = vo.strict;
    std::vector<PendingFile> files;
    if (!reportPath.empty()) files.push_back({reportPath, validationReportJson(ctx, parts)});
    if (!saveOutputs.empty())
      for (auto& [name, bytes] : savedOutputFiles(ctx, parts))
        files.push_back({(std::filesystem::path(saveOutputs) / name).string(), std::move(bytes)});
    std::vector<std::string> paths;
    for (const auto& f : files) paths.push_back(f.path);
    std::vector<InputFile> inputs{{parseGltfRef(vo.gen.rigPath, true).file, "the rig"},
                                  {vo.gen.fragmentPath, "the fragment shader"}};
    for (const auto& f : modelFiles) inputs.push_back({f, "the rig"});  // `--report M.bin` beside M.gltf
    for (const auto& r : vo.gen.rulesPaths) inputs.push_back({r, "a rules file"});
    refuseClobbering(paths, inputs);
    writeFilesAtomically(files);
  }

  int run() {
    ValidateOptions vo;
    vo.gen = args.resolve();
    vo.gen.optimize = optimize;
    vo.via = via == "hlsl" ? ValidateVia::Hlsl : ValidateVia::Spirv;
    cross.resolve(vo.via == ValidateVia::Hlsl, false, vo.gen);
    vo.crossCheck = crossCheck;
    vo.device = device;
    vo.limits = {!device.empty(), args.maxAttributes->count() > 0, args.maxUniformBytes->count() > 0};
    vo.validationLayers = !noLayers;
    vo.tolerance = tol;
    vo.checkFloatData = !noFloatCheck;
    vo.strict = strict;
    vo.keepOutputs = !saveOutputs.empty();
    // Under a device profile a glTF rig is priced for its own mesh, as `generate` prices it, so
    // the plan validated is the plan generated (a YAML rig: unknown, as generate without --mesh).
    if (!vo.gen.deviceProfilePath.empty() && isGltfPath(vo.gen.rigPath) && !wholeModelParts(vo.gen.rigPath))
      measureWorkloadOf(vo.gen, "");
    ValidationScene scene;
    std::string what;
    bool gltf = isGltfPath(vo.gen.rigPath);
    if (gltf)
      for (const char* o : {"--mesh", "--seed", "--poses"})
        refuseOption(*cmd, o, "to a glTF rig: the model's own mesh is posed by its animation (use --time, --animation)");
    if (!gltf)
      for (const char* o : {"--time", "--animation", "--morph-weight", "--report", "--save-outputs"})
        refuseOption(*cmd, o, "to a YAML rig: it is validated on a procedural mesh in random poses (--mesh, --seed, --poses)");
    if (auto parts = wholeModelParts(vo.gen.rigPath)) return runModel(vo, *parts);
    if (gltf) {  // a real model: its own mesh, posed by its animation
      GltfSceneOptions so;
      so.times = times;
      so.animation = animation;
      so.morphWeight = morphWeight;
      so.read = vo.gen.gltf;
      so.allInstances = true;
      const GltfRef ref = parseGltfRef(vo.gen.rigPath);
      GltfImport model = importGltfRef(vo.gen.rigPath, vo.gen.gltf);
      modelFiles = model.rig.sourceFiles;
      Validator v(vo);
      GltfSceneInfo info;
      std::vector<ValidatedPart> parts{validatePrimitive(v, model, vo.gen, so,
                                                         gltfPartName(ref.mesh, ref.primitive, model.data.meshName), info)};
      if (!savePoses.empty()) {
        std::vector<InputFile> inputs{{ref.file, "the rig"}};
        for (const auto& f : modelFiles) inputs.push_back({f, "the rig"});
        refuseClobbering({savePoses}, inputs);
        writeFilesAtomically({{savePoses, formatPoseFile(parts.front().report.poses)}});
      }
      std::string ts;
      for (double t : info.times) ts += fmt::format("{}{:g}", ts.empty() ? "" : ", ", t);
      std::cout << fmt::format("model '{}' ({} vertices), {}, t = {}\n", model.rig.name, model.data.vertexCount,
                               info.animation.empty() ? std::string("no animation (rest pose)")
                                                      : fmt::format("animation '{}' [{:g}, {:g}] s", info.animation,
                                                                    info.start, info.end),
                               ts);
      std::cout << formatReport(parts.front().report) << formatInstances(parts.front());
      writeFiles(vo, parts);
      return parts.front().report.pass ? 0 : 1;
    } else {
      bool count = !poses.empty() && poses.find_first_not_of("0123456789") == std::string::npos && poses.size() < 4;
      int n = count ? std::stoi(poses) : 1;
      if (count && (n < 1 || n > 100))  // a usage error (exit 2), like every other bad option value
        throw CLI::ValidationError("--poses", fmt::format("{}: a count is 1..100", poses));
      scene = proceduralScene(vo.gen.rigPath, vo.gen.rigParams, mesh, seed, n);
      if (count) {
        what = fmt::format("mesh '{}' ({} vertices), {} pose(s) from seed {}\n", scene.mesh.name,
                           scene.mesh.vertexCount, scene.poses.size(), seed);
      } else {
        scene.poses = readPoseFile(poses);
        what = fmt::format("mesh '{}' ({} vertices), {} pose(s) from {}\n", scene.mesh.name, scene.mesh.vertexCount,
                           scene.poses.size(), poses);
      }
    }
    Validator v(vo);
    ValidateReport report = v.run(scene);
    if (!savePoses.empty()) {
      refuseClobbering({savePoses}, {{vo.gen.rigPath, "the rig"}, {poses, "the pose file"}});
      writeFilesAtomically({{savePoses, formatPoseFile(report.poses)}});
    }
    std::cout << what;
    std::cout << formatReport(report);
    return report.pass ? 0 : 1;
  }

  // MODEL.glb#*: every primitive at every --time on one device, one report; a line per
  // primitive at the end. Fails if any primitive fails (or cannot be generated).
  int runModel(const ValidateOptions& vo, const std::vector<GltfPart>& parts) {
    if (!savePoses.empty())
      throw CLI::ValidationError("--save-poses", "does not apply to a whole model (" + vo.gen.rigPath + ")");
    GltfSceneOptions so;
    so.times = times;
    so.animation = animation;
    so.morphWeight = morphWeight;
    so.allInstances = true;
    checkWholeModelAnimation(parts, animation);
    Validator v(vo);
    std::vector<ValidatedPart> done(parts.size());
    std::vector<std::string> lines(parts.size());
    std::string header;
    size_t passed = 0;
    std::vector<std::string> failed = forEachPart(parts, [&](const GltfPart& part) {
      size_t i = static_cast<size_t>(&part - parts.data());
      lines[i] = fmt::format("  FAIL  {}  ({}): not run, see the error above", part.name, part.ref);
      done[i].name = part.name;
      done[i].rig = part.ref;
      done[i].error = "not run: see the diagnostics";
      GltfImport model = importGltfRef(part.ref, vo.gen.gltf);
      modelFiles = model.rig.sourceFiles;  // the same for every part
      GenerateOptions gen = partOptions(vo.gen, part.ref);
      GltfSceneInfo info;
      done[i] = validatePrimitive(v, model, gen, so, part.name, info);
      if (header.empty()) {
        std::string ts;
        for (double t : info.times) ts += fmt::format("{}{:g}", ts.empty() ? "" : ", ", t);
        header = fmt::format("model '{}' ({} primitives), {}, t = {}\n", model.data.file, parts.size(),
                             info.animation.empty() ? std::string("no animation (rest pose)")
                                                    : fmt::format("animation '{}' [{:g}, {:g}] s", info.animation,
                                                                  info.start, info.end),
                             ts);
        std::cout << header;
      }
      const ValidateReport& report = done[i].report;
      const size_t vertices = done[i].vertices;
      std::string kind = model.joints > 0 ? fmt::format("skinned ({} joints)", model.joints) : "rigid";
      if (model.morphTargets > 0) kind += fmt::format(", {} morph target(s)", model.morphTargets);
      std::cout << fmt::format("== {} ({}): {} vertices, {}\n", part.name, part.ref, vertices, kind);
      bool weighted = false;
      for (const auto& pose : report.poses)
        for (float w : pose.morphWeights) weighted = weighted || w != 0.0f;
      if (model.morphTargets > 0 && !weighted)
        std::cout << "note: every morph weight is 0 at these times, so the targets are not exercised (--morph-weight W "
                     "sets them)\n";
      std::cout << formatReport(report) << formatInstances(done[i]);
      lines[i] = fmt::format("  {}  {}  ({}): {} vertices, {}, {} instance(s), plan cost {}", report.pass ? "PASS" : "FAIL",
                             part.name, part.ref, vertices, kind, done[i].instances.size(), report.runs.front().planCost);
      if (!report.pass) throw InputError(SourceLoc{part.ref, 0, 0}, "outputs differ from their definitions (report above)");
      ++passed;
    });
    std::cout << fmt::format("{} of {} primitive(s) pass:\n", passed, parts.size());
    for (const auto& l : lines) std::cout << l << "\n";
    writeFiles(vo, done);  // the report and outputs of a failing model too: that is when they are needed
    failIfPartsFailed(vo.gen.rigPath, parts.size(), failed, "the model does not validate");
    return 0;
  }
};

}  // namespace

void registerValidate(CLI::App& app, CliState& state) {
  auto cmd = std::make_shared<ValidateCommand>();
  CLI::App* sub = app.add_subcommand("validate", "Generate, run on lavapipe and compare with the GLM reference");
  cmd->cmd = sub;
  cmd->args.add(*sub);
  sub->add_option("--mesh", cmd->mesh, "Procedural mesh: head (default), limb, dawn (180k vertices)")
      ->check(CLI::IsMember({"head", "limb", "dawn"}));
  sub->add_option("--seed", cmd->seed, "Seed of the random poses");
  sub->add_option("--poses", cmd->poses, "Number of random poses (1..100), or a pose file written by --save-poses")
      ->check([](const std::string& v) -> std::string {  // a count out of range is a usage error
        bool digits = !v.empty() && v.find_first_not_of("0123456789") == std::string::npos;
        if (digits && (v.size() > 3 || std::stoi(v) < 1 || std::stoi(v) > 100)) return "a count of poses is 1..100";
        return "";
      });
  sub->add_option("--save-poses", cmd->savePoses, "Write the poses run (with drawn uniforms) to FILE, for --poses FILE");
  sub->add_option("--report", cmd->reportPath,
                  "glTF rig: write a JSON report to FILE (per primitive, instance, time and output: pass, worst error "
                  "and where, tolerances, the plan, device and driver; docs/validation.md)");
  sub->add_option("--save-outputs", cmd->saveOutputs,
                  "glTF rig: write what the device computed to DIR (the posed world positions and normals as .glb, "
                  "every captured output as little-endian float32 .bin, described by DIR/outputs.json)");
  sub->add_flag("--strict", cmd->strict, "Fail outputs whose semantic has no definition (unchecked)");
  CLI::Validator finiteNonNegative = finiteNumber(false);  // no nan, inf or negative times and tolerances
  sub->add_option("--time", cmd->times, "glTF rig (MODEL.glb#m/p or MODEL.glb#*): animation time in seconds (repeatable)")
      ->check(finiteNonNegative);
  sub->add_option("--animation", cmd->animation, "glTF rig: animation name or index (default: the first)");
  sub->add_option("--morph-weight", cmd->morphWeight,
                  "glTF rig: every morph target at this weight in place of the animation's (an expression held "
                  "through the motion)")
      ->check(finiteNumber(false))
      ->check(CLI::Range(0.0, 1000.0));  // far past 1, float32 outputs overflow (a length of 1e20 squares to inf)
  sub->add_flag("--cross-check", cmd->crossCheck, "Also force and check every alternative derivation");
  sub->add_option("--via", cmd->via,
                  "What runs: spirv (default: the GLSL's SPIR-V), or hlsl (the HLSL `generate --emit hlsl` writes, "
                  "compiled back to SPIR-V by glslang's HLSL front end and bound by its semantics)")
      ->check(CLI::IsMember({"spirv", "hlsl"}));
  sub->add_flag("-O", cmd->optimize, "Validate the optimised SPIR-V (spirv-opt -O), as `generate -O` writes it");
  cmd->cross.add(*sub, false);
  sub->add_option("--device", cmd->device,
                  "Vulkan device name (substring); default lavapipe. A named device's own limits (maxVertexInputAttributes, "
                  "maxUniformBufferRange, storage buffers) constrain the search; --max-attributes and --max-uniform-bytes "
                  "lower them (a higher value is clamped to the device's)");
  sub->add_flag("--no-validation-layers", cmd->noLayers, "Run without the Khronos validation layer");
  sub->add_option("--tolerance-abs", cmd->tol.abs, "Absolute tolerance (see docs/validation.md)")
      ->check(finiteNonNegative);
  sub->add_option("--tolerance-rel", cmd->tol.rel, "Relative tolerance (see docs/validation.md)")
      ->check(finiteNonNegative);
  sub->add_flag("--no-float-check", cmd->noFloatCheck,
                "Skip the second check of a rig that stores encoded or quantized streams: the outputs against the "
                "reference on the original float data, within tolerances derived from the formats' and encodings' "
                "stated errors (docs/validation.md, \"Against the float data\")");
  sub->callback([cmd, &state] { state.run = [cmd] { return cmd->run(); }; });
}

}  // namespace sg

// `shadergen generate`: rig + fragment shader + rules → .vert / .spv / header / reflection.
#include <fmt/format.h>

#include <filesystem>
#include <iostream>
#include <algorithm>
#include <cmath>
#include <set>

#include "cli/commands.h"
#include "cli/output_files.h"
#include "cli/whole_model.h"
#include "common/content_hash.h"
#include "emit/reflection.h"
#include "measure/workload.h"
#include "rig/vertex_encoding.h"

namespace sg {

const char* shadergenVersionString() { return shadergenVersion(); }

void GenerateArgs::add(CLI::App& cmd, bool inputsRequired) {
  const size_t before = cmd.get_options().size();
  cmd.add_option("--rig", opts.rigPath, "Rig description (YAML)")->required(inputsRequired);
  cmd.add_option("--fragment,-f", opts.fragmentPath, "Fragment shader whose inputs must be fed (GLSL 450)")->required(inputsRequired);
  cmd.add_option("--rules,-r", opts.rulesPaths, "Rules file(s) (YAML)")->required(inputsRequired);
  cmd.add_option("--map", maps, "Map a fragment input to semantics: Name=sem or Name=s1,s2,... (packs)");
  cmd.add_option("--conventions", opts.conventions,
                 "Varying naming conventions to apply, earlier first (threejs, gltf-sample-viewer, filament, ...; "
                 "none). Default: every convention, where they agree")
      ->delimiter(',');
  cmd.add_option("--heuristic", opts.heuristic, "A* heuristic (either engine): lmcut (default), hmax, blind")
      ->check(CLI::IsMember({"lmcut", "hmax", "blind"}));
  cmd.add_option("--search", opts.searchEngine,
                 "Search engine: auto (default: regression A* on acyclic rule graphs, else forward A*), "
                 "regression, forward, ip (exact integer program, GLPK)")
      ->check(CLI::IsMember({"auto", "regression", "forward", "ip"}));
  cmd.add_option("--search-time-limit", opts.searchLimits.maxSeconds,
                 "Give up (error) when one search runs longer than this many seconds (0 = no limit)")
      ->check(finiteNumber(false));
  cmd.add_option("--max-expansions", opts.searchLimits.maxExpansions,
                 "Give up (error) after this many A* expansions")
      ->check(CLI::PositiveNumber);
  maxAttributes = cmd.add_option("--max-attributes", opts.maxAttributes,
                 "Vertex input attributes the plan may use (the device's maxVertexInputAttributes; default 16, "
                 "what every Vulkan device supports). A constraint of the search, not a cost")
      ->check(CLI::Range(1, 4096));
  maxUniformBytes = cmd.add_option("--max-uniform-bytes", opts.maxUniformBlockBytes,
                 "Bytes of the uniform block (the device's maxUniformBufferRange; default 16384)")
      ->check(CLI::Range(16, 1 << 30));
  cmd.add_option("--vertices", opts.maxVertices,
                 "The most vertices one draw has: per-vertex storage buffers that would exceed "
                 "maxStorageBufferRange (2^27 bytes) at that count are not used, and a device profile's per-draw "
                 "weights are spread over that many (default: unknown, all allowed; the profile's vertices_per_draw)")
      ->check(CLI::Range(int64_t{0}, int64_t{1} << 32));
  cmd.add_option("--device-profile", profiles,
                 "Device profile (YAML, docs/device-profiles.md): weights in ns per vertex of arithmetic, vertex "
                 "input locations, bytes fetched, buffer and indexed uniform loads, outputs. The plan becomes the "
                 "cheapest in predicted time on that device (default: instruction slots). Given several times: the "
                 "plan with the least worst-case regret across the devices (a portable plan)");
  cmd.add_option("--target-env", targetEnv, "vulkan1.0 (default), vulkan1.1, vulkan1.2, vulkan1.3")
      ->check(CLI::IsMember({"vulkan", "vulkan1.0", "vulkan1.1", "vulkan1.2", "vulkan1.3"}));
  cmd.add_option("--templates", opts.templateDir, "Directory with vertex.glsl templates");
  cmd.add_option("--ban", opts.bannedRules, "Exclude a rule from the search (force an alternative)");
  cmd.add_option("--pin", pin,
                 "A pin file (bench --pin-out): the plan a device timed fastest among the cheapest candidates, written "
                 "without the device or its profile; an error if these inputs no longer give that plan "
                 "(docs/performance.md, \"A measured choice\")");
  cmd.add_option("--set", sets, "Set a rig deformer parameter: NAME=VALUE (level-of-detail rigs: morph_targets=2)");
  cmd.add_option("--max-error", maxErrors,
                 "Error budget of an encoded vertex semantic: SEMANTIC=ERROR, an angle in deg or rad for a direction "
                 "(vertex.normal=0.1deg), a fraction of the bounds diagonal for a position (vertex.position=1e-4), of the "
                 "target's scale for a morph delta (morph.position=1e-4). Stored encodings that can err more are not offered to the search "
                 "(docs/rig-format.md, \"Encodings\")");
  const std::vector<CLI::Option*> all = cmd.get_options();
  generateOptions.assign(all.begin() + std::ptrdiff_t(before), all.end());
  addGltfReadOptions(cmd, opts.gltf);
}

GenerateOptions GenerateArgs::resolve() const {
  GenerateOptions o = opts;
  parseTargetEnv(targetEnv, o.targetEnv);
  if (!pin.empty()) o.pin = loadPin(pin);
  if (!profiles.empty()) {
    o.deviceProfilePath = profiles.front();
    o.portableProfilePaths.assign(profiles.begin() + 1, profiles.end());
  }
  for (const auto& m : maps) {
    auto eq = m.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == m.size())
      throw CLI::ValidationError("--map", "expected Name=semantic[,semantic...], got '" + m + "'");
    VaryingOverride ov;
    ov.name = m.substr(0, eq);
    std::string rest = m.substr(eq + 1);
    for (size_t start = 0;;) {
      size_t c = rest.find(',', start);
      ov.semantics.push_back(rest.substr(start, c == std::string::npos ? std::string::npos : c - start));
      if (c == std::string::npos) break;
      start = c + 1;
    }
    o.overrides.push_back(ov);
  }
  for (const auto& kv : sets) {
    auto eq = kv.find('=');
    size_t used = 0;
    long long value = -1;
    try {
      if (eq != std::string::npos) value = std::stoll(kv.substr(eq + 1), &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (eq == std::string::npos || eq == 0 || used == 0 || eq + 1 + used != kv.size() || value < 0)
      throw CLI::ValidationError("--set", "expected NAME=VALUE with a non-negative integer VALUE, got '" + kv + "'");
    o.rigParams[kv.substr(0, eq)] = value;
  }
  for (const auto& kv : maxErrors) {
    const auto eq = kv.find('=');
    std::string why = "expected SEMANTIC=ERROR (vertex.normal=0.1deg, vertex.position=1e-4)";
    const std::optional<double> value =
        eq == std::string::npos || eq == 0 ? std::nullopt : parseErrorBudget(kv.substr(0, eq), kv.substr(eq + 1), why);
    if (!value) throw CLI::ValidationError("--max-error", "'" + kv + "': " + why);
    o.maxError[kv.substr(0, eq)] = *value;
  }
  return o;
}

void CrossArgs::add(CLI::App& cmd, bool msl) {
  cmd.add_option("--hlsl-shader-model", shaderModel,
                 fmt::format("HLSL shader model: {} (default 5.0: compiles with FXC for Direct3D 11 and 12 and "
                             "with DXC as vs_6_x)",
                             kShaderModels));
  if (!msl) return;
  cmd.add_option("--msl-version", mslVersion, fmt::format("Metal Shading Language version: {} (default 2.0)", kMslVersions));
  cmd.add_option("--msl-platform", mslPlatform, "Metal platform: macos (default), ios");
}

void CrossArgs::resolve(bool hlsl, bool msl, GenerateOptions& o) const {
  if (!shaderModel.empty() && !hlsl) throw CLI::ValidationError("--hlsl-shader-model", "does not apply: nothing is translated to HLSL (generate: --emit hlsl; validate: --via hlsl)");
  if (!mslVersion.empty() && !msl) throw CLI::ValidationError("--msl-version", "does not apply: no MSL is made (add msl to --emit)");
  if (!mslPlatform.empty() && !msl) throw CLI::ValidationError("--msl-platform", "does not apply: no MSL is made (add msl to --emit)");
  if (hlsl) {
    o.hlsl = HlslOptions{};
    if (!shaderModel.empty() && !parseShaderModel(shaderModel, o.hlsl->shaderModel))
      throw CLI::ValidationError("--hlsl-shader-model",
                                 fmt::format("unsupported shader model '{}' (supported: {})", shaderModel, kShaderModels));
  }
  if (msl) {
    o.msl = MslOptions{};
    if (!mslVersion.empty() && !parseMslVersion(mslVersion, *o.msl))
      throw CLI::ValidationError("--msl-version",
                                 fmt::format("unsupported Metal Shading Language version '{}' (supported: {})", mslVersion, kMslVersions));
    if (!mslPlatform.empty() && !parseMslPlatform(mslPlatform, o.msl->platform))
      throw CLI::ValidationError("--msl-platform", fmt::format("unknown Metal platform '{}' (macos, ios)", mslPlatform));
  }
}

std::vector<InputFile> inputFiles(const LoadedInputs& in, const std::vector<std::string>& extra) {
  std::vector<InputFile> files{{in.fragment.file, "the fragment shader"}};
  for (const auto& f : in.rig.sourceFiles) files.push_back({f, "the rig"});
  for (const auto& f : in.rules.files) files.push_back({f, "a rules file"});
  for (const auto& f : extra) files.push_back({f, "an input"});
  return files;
}

void measureWorkloadOf(GenerateOptions& o, const std::string& mesh) {
  if (!mesh.empty() && isGltfPath(o.rigPath))
    throw CLI::ValidationError("--mesh", "does not apply to a glTF rig (" + o.rigPath + "): it is measured on its own mesh");
  o.workload = rigWorkload(o.rigPath, o.rigParams, mesh);
}

GenerateOptions partOptions(const GenerateOptions& base, const std::string& partRef) {
  GenerateOptions o = base;
  o.rigPath = partRef;
  if (!o.deviceProfilePath.empty()) measureWorkloadOf(o, "");
  return o;
}

namespace {

struct GenerateCommand {
  CLI::App* cmd = nullptr;
  GenerateArgs args;
  std::string output;
  std::vector<std::string> emit{"glsl", "spv"};
  bool optimize = false;
  bool depfile = false;
  std::string depfilePath;
  bool quiet = false;
  bool capture = false;
  bool stats = false;
  std::string mesh;
  CrossArgs cross;

  // The outputs of one generation: with one --emit kind and `exact`, `path` is that file
  // (like glslc -o); otherwise it is a stem and known suffixes are stripped, each kind getting
  // its own (.vert .spv .spv.h .json).
  static std::string stemOf(std::string path) {
    for (const char* suffix : {".spv.h", ".vert", ".spv", ".json", ".h", ".hlsl", ".metal"}) {
      std::string sfx(suffix);
      if (path.size() > sfx.size() && path.compare(path.size() - sfx.size(), sfx.size(), sfx) == 0) {
        path.resize(path.size() - sfx.size());
        break;
      }
    }
    return path;
  }
  std::vector<PendingFile> outputsOf(const GenerateResult& r, const std::set<std::string>& kinds, const std::string& path,
                                     bool exact) const {
    const std::string stem = stemOf(path);
    auto pathFor = [&](const std::string& kind) {
      if (exact) return path;
      if (kind == "glsl") return stem + ".vert";
      if (kind == "spv") return stem + ".spv";
      if (kind == "header") return stem + ".spv.h";
      if (kind == "hlsl") return stem + ".hlsl";
      if (kind == "msl") return stem + ".metal";
      return stem + ".json";
    };
    std::vector<PendingFile> files;
    if (kinds.count("glsl")) files.push_back({pathFor("glsl"), r.glsl.text});
    if (kinds.count("spv")) {
      std::string bytes(reinterpret_cast<const char*>(r.spirv.words.data()), r.spirv.words.size() * 4);
      files.push_back({pathFor("spv"), bytes});
    }
    if (kinds.count("header")) {
      // Symbol from the output stem: "out/face.spv.h" -> face_spv (+ face_spv_size).
      std::string sym = std::filesystem::path(stem).filename().string();
      for (auto& c : sym)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
      if (sym.empty() || std::isdigit(static_cast<unsigned char>(sym[0]))) sym = "sg_" + sym;
      files.push_back({pathFor("header"), spirvHeader(r.spirv.words, sym + "_spv") + vertexInputsHeader(r.in.rig, r.glsl, sym) +
                                                 buffersHeader(r.glsl, sym)});
    }
    if (kinds.count("hlsl")) files.push_back({pathFor("hlsl"), r.hlsl->text});
    if (kinds.count("msl")) files.push_back({pathFor("msl"), r.msl->text});
    if (kinds.count("reflection")) files.push_back({pathFor("reflection"), reflectionOf(r)});
    return files;
  }

  // Every output is a target of the depfile (first = the first output, as Ninja wants).
  void addDepfile(std::vector<PendingFile>& files, const std::vector<std::string>& inputsRead) const {
    if (!depfile && depfilePath.empty()) return;
    std::vector<std::string> targets;
    for (const auto& f : files) targets.push_back(f.path);
    std::string dpath = depfilePath.empty() ? files.front().path + ".d" : depfilePath;
    files.push_back({dpath, makeDepfile(targets, inputsRead)});
  }

  void printPlan(const GenerateResult& r) const {
    const std::string expanded = r.stats.heuristic.empty() ? "" : fmt::format(", {} expanded", r.stats.expanded);
    std::cout << fmt::format("plan for rig '{}' ({} rules, {}{}):\n", r.in.rig.name, r.plan.actions.size(),
                             searchMethod(r.stats), expanded);
    std::cout << describePlan(r.in.problem, r.plan);
    if (r.in.profile) std::cout << describePlanCost(r.plan, r.in.problem, *r.in.profile);
    for (const DeviceProfile& d : r.in.portable) std::cout << describePlanCost(r.plan, r.in.problem, d);
    if (r.in.profile && !r.in.portable.empty()) {
      std::vector<DeviceProfile> all{*r.in.profile};
      all.insert(all.end(), r.in.portable.begin(), r.in.portable.end());
      std::cout << describePortable(r.plan, r.in.problem, all, r.in.portableBest);
    }
  }

  int run() {
    GenerateOptions o = args.resolve();
    o.optimize = optimize;
    o.capture = capture;
    std::set<std::string> kinds(emit.begin(), emit.end());
    if (kinds.empty()) throw CLI::ValidationError("--emit", "nothing to emit");
    if (optimize && !kinds.count("spv") && !kinds.count("header") && !kinds.count("hlsl") && !kinds.count("msl"))
      throw CLI::ValidationError("-O", "does not apply: it optimises the SPIR-V, and --emit writes none (add spv or header)");
    cross.resolve(kinds.count("hlsl") > 0, kinds.count("msl") > 0, o);
    // The workload prices nothing without a profile: outputs stay those of the slot model.
    if (o.deviceProfilePath.empty())
      refuseOption(*cmd, "--mesh", "without --device-profile: the workload it measures prices nothing under instruction slots");
    if (auto parts = wholeModelParts(o.rigPath)) {
      if (o.pin) throw CLI::ValidationError("--pin", "pins one rig's plan: name one primitive (MODEL.glb#m/p), not the whole model");
      return runModel(o, kinds, *parts);
    }
    if (!o.deviceProfilePath.empty()) measureWorkloadOf(o, mesh);
    bool single = kinds.size() == 1 && !output.empty();
    std::string path = output.empty() ? std::filesystem::path(o.fragmentPath).stem().string() : output;
    o.outputName = single && kinds.count("glsl") ? output : stemOf(path) + ".vert";

    GenerateResult r = generate(o);

    std::vector<PendingFile> files = outputsOf(r, kinds, path, single);
    addDepfile(files, r.inputsRead);
    std::vector<std::string> outPaths;
    for (const auto& f : files) outPaths.push_back(f.path);
    refuseClobbering(outPaths, inputFiles(r.in, r.inputsRead));
    writeFilesAtomically(files);
    if (stats) std::cout << describeStats(r.stats);
    for (const auto& n : r.in.notes) std::cerr << formatDiagnostic(n) << "\n";
    if (o.pin)
      if (auto changed = pinInputsChanged(*o.pin, sha256OfFiles(r.pinnedInputs))) std::cerr << formatDiagnostic(*changed) << "\n";
    if (!quiet) {
      printPlan(r);
      for (const auto& f : files) std::cout << "wrote " << f.path << "\n";
    }
    return 0;
  }

  // MODEL.glb#*: -o is a directory; one set of outputs per primitive (named by
  // gltfPartName) and index.json. Every primitive is generated before anything is written.
  int runModel(const GenerateOptions& base, const std::set<std::string>& kinds, const std::vector<GltfPart>& parts) {
    if (output.empty())
      throw CLI::ValidationError("-o", "is required with a whole model (" + base.rigPath +
                                           "): it names the directory that gets one set of outputs per primitive");
    std::vector<PendingFile> files;
    std::vector<InputFile> inputs;
    std::vector<std::string> inputsRead;
    std::vector<nlohmann::ordered_json> entries(parts.size());
    std::vector<std::string> failed = forEachPart(parts, [&](const GltfPart& part) {
      GenerateOptions o = partOptions(base, part.ref);
      std::string stem = (std::filesystem::path(output) / part.name).string();
      o.outputName = stem + ".vert";
      GenerateResult r = generate(o);
      std::vector<PendingFile> out = outputsOf(r, kinds, stem, false);
      nlohmann::ordered_json& e = entries[static_cast<size_t>(&part - parts.data())];
      e["rig_name"] = r.in.rig.name;
      e["plan_cost"] = r.plan.cost;
      nlohmann::ordered_json names = nlohmann::ordered_json::array();
      for (const auto& f : out) names.push_back(std::filesystem::path(f.path).filename().string());
      e["files"] = names;
      for (const auto& f : inputFiles(r.in, r.inputsRead)) inputs.push_back(f);
      inputsRead.insert(inputsRead.end(), r.inputsRead.begin(), r.inputsRead.end());
      if (stats) std::cout << part.name << ": " << describeStats(r.stats);
      if (!quiet) {
        std::cout << part.name << ": ";
        printPlan(r);
      }
      files.insert(files.end(), out.begin(), out.end());
    });
    failIfPartsFailed(base.rigPath, parts.size(), failed);
    files.push_back({(std::filesystem::path(output) / "index.json").string(),
                     wholeModelIndex("generate", base.rigPath, parts, entries)});
    std::sort(inputsRead.begin(), inputsRead.end());
    inputsRead.erase(std::unique(inputsRead.begin(), inputsRead.end()), inputsRead.end());
    if (depfile && depfilePath.empty()) depfilePath = files.back().path + ".d";
    addDepfile(files, inputsRead);
    std::vector<std::string> outPaths;
    for (const auto& f : files) outPaths.push_back(f.path);
    refuseClobbering(outPaths, inputs);
    writeFilesAtomically(files);
    if (!quiet) std::cout << fmt::format("{}: {} primitive(s), {} files written to {}\n", base.rigPath, parts.size(),
                                         files.size(), output);
    return 0;
  }
};

}  // namespace

void registerGenerate(CLI::App& app, CliState& state) {
  auto cmd = std::make_shared<GenerateCommand>();
  CLI::App* sub = app.add_subcommand("generate", "Generate the cheapest vertex shader (GLSL + SPIR-V)");
  cmd->cmd = sub;
  cmd->args.add(*sub);
  sub->add_option("-o", cmd->output, "Output path (a file if one --emit kind, else the stem for all)");
  sub->add_option("--mesh", cmd->mesh,
                  "With --device-profile and a YAML rig: the procedural mesh the program will draw (head, limb, dawn), "
                  "whose workload the profile prices (docs/device-profiles.md, \"Workload\"); a glTF rig is measured on "
                  "its own mesh. Default: unknown, the profile's defaults")
      ->check(CLI::IsMember({"head", "limb", "dawn"}));
  sub->add_option("--emit", cmd->emit,
                   "What to write: glsl, spv, header, reflection, hlsl (Direct3D), msl (Metal) (comma-separated). "
                   "HLSL and MSL are translated from the SPIR-V by SPIRV-Cross; their bindings go into the "
                   "reflection (docs/hlsl-msl.md)")
      ->delimiter(',')
      ->check(CLI::IsMember({"glsl", "spv", "header", "reflection", "hlsl", "msl"}));
  cmd->cross.add(*sub, true);
  sub->add_flag("-O", cmd->optimize, "Optimise the SPIR-V (spirv-opt -O)");
  sub->add_flag("--MD", cmd->depfile,
                "-MD: write a Make/Ninja depfile (<first output>.d) listing every input read "
                "(rig, fragment shader, rules files and their includes, templates)");
  sub->add_option("--MF", cmd->depfilePath, "-MF FILE: depfile path (implies -MD)");
  sub->add_flag("-q,--quiet", cmd->quiet, "Do not print the plan");
  sub->add_flag("--stats", cmd->stats,
                "Print search statistics: engine, expansions, generated nodes, heuristic time, "
                "initial h against the final cost");
  sub->add_flag("--capture", cmd->capture,
                "Transform-feedback build: add xfb_buffer/xfb_offset/xfb_stride to gl_Position and every "
                "output so sg::rt::Harness can read them back (testing/validation, not for rendering)")
      ->group("Advanced");
  sub->callback([cmd, &state] { state.run = [cmd] { return cmd->run(); }; });
}


}  // namespace sg

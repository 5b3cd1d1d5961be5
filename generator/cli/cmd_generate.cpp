// `shadergen generate`: rig + fragment shader + rules → .vert / .spv / header / reflection.
#include <fmt/format.h>

#include <filesystem>
#include <iostream>
#include <set>

#include "cli/commands.h"
#include "cli/output_files.h"
#include "emit/reflection.h"

namespace sg {

const char* shadergenVersionString() { return shadergenVersion(); }

void GenerateArgs::add(CLI::App& cmd) {
  cmd.add_option("--rig", opts.rigPath, "Rig description (YAML)")->required();
  cmd.add_option("--fragment,-f", opts.fragmentPath, "Fragment shader whose inputs must be fed (GLSL 450)")->required();
  cmd.add_option("--rules,-r", opts.rulesPaths, "Rules file(s) (YAML)")->required();
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
                 "maxStorageBufferRange (2^27 bytes) at that count are not used (default: unknown, all allowed)")
      ->check(CLI::Range(int64_t{0}, int64_t{1} << 32));
  cmd.add_option("--device-profile", opts.deviceProfilePath,
                 "Device profile (YAML, docs/device-profiles.md): weights in ns per vertex of arithmetic, vertex "
                 "input locations, bytes fetched, buffer and indexed uniform loads, outputs. The plan becomes the "
                 "cheapest in predicted time on that device (default: instruction slots)");
  cmd.add_option("--target-env", targetEnv, "vulkan1.0 (default), vulkan1.1, vulkan1.2, vulkan1.3")
      ->check(CLI::IsMember({"vulkan", "vulkan1.0", "vulkan1.1", "vulkan1.2", "vulkan1.3"}));
  cmd.add_option("--templates", opts.templateDir, "Directory with vertex.glsl templates");
  cmd.add_option("--ban", opts.bannedRules, "Exclude a rule from the search (force an alternative)");
  cmd.add_option("--set", sets, "Set a rig deformer parameter: NAME=VALUE (level-of-detail rigs: morph_targets=2)");
}

GenerateOptions GenerateArgs::resolve() const {
  GenerateOptions o = opts;
  parseTargetEnv(targetEnv, o.targetEnv);
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
  return o;
}

std::vector<InputFile> inputFiles(const LoadedInputs& in, const std::vector<std::string>& extra) {
  std::vector<InputFile> files{{in.fragment.file, "the fragment shader"}};
  for (const auto& f : in.rig.sourceFiles) files.push_back({f, "the rig"});
  for (const auto& f : in.rules.files) files.push_back({f, "a rules file"});
  for (const auto& f : extra) files.push_back({f, "an input"});
  return files;
}

namespace {

struct GenerateCommand {
  GenerateArgs args;
  std::string output;
  std::vector<std::string> emit{"glsl", "spv"};
  bool optimize = false;
  bool depfile = false;
  std::string depfilePath;
  bool quiet = false;
  bool capture = false;
  bool stats = false;

  int run() {
    GenerateOptions o = args.resolve();
    o.optimize = optimize;
    o.capture = capture;
    std::set<std::string> kinds(emit.begin(), emit.end());
    if (kinds.empty()) throw CLI::ValidationError("--emit", "nothing to emit");
    if (optimize && !kinds.count("spv") && !kinds.count("header"))
      throw CLI::ValidationError("-O", "does not apply: it optimises the SPIR-V, and --emit writes none (add spv or header)");
    // With one --emit kind, -o names that file exactly (like glslc -o). Otherwise -o is a
    // stem: known suffixes are stripped and each kind gets its own (.vert .spv .spv.h .json).
    bool single = kinds.size() == 1 && !output.empty();
    std::string stem = output.empty() ? std::filesystem::path(o.fragmentPath).stem().string() : output;
    for (const char* suffix : {".spv.h", ".vert", ".spv", ".json", ".h"}) {
      std::string sfx(suffix);
      if (stem.size() > sfx.size() && stem.compare(stem.size() - sfx.size(), sfx.size(), sfx) == 0) {
        stem.resize(stem.size() - sfx.size());
        break;
      }
    }
    auto pathFor = [&](const std::string& kind) {
      if (single) return output;
      if (kind == "glsl") return stem + ".vert";
      if (kind == "spv") return stem + ".spv";
      if (kind == "header") return stem + ".spv.h";
      return stem + ".json";
    };
    o.outputName = single && kinds.count("glsl") ? output : stem + ".vert";

    GenerateResult r = generate(o);

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
      files.push_back({pathFor("header"), spirvHeader(r.spirv.words, sym + "_spv") + buffersHeader(r.glsl, sym)});
    }
    if (kinds.count("reflection")) files.push_back({pathFor("reflection"), reflectionOf(r)});
    if (depfile || !depfilePath.empty()) {
      // Every output is a target of the depfile (first = the first output, as Ninja wants).
      std::vector<std::string> targets;
      for (const auto& f : files) targets.push_back(f.path);
      std::string dpath = depfilePath.empty() ? files.front().path + ".d" : depfilePath;
      files.push_back({dpath, makeDepfile(targets, r.inputsRead)});
    }
    std::vector<std::string> outPaths;
    for (const auto& f : files) outPaths.push_back(f.path);
    refuseClobbering(outPaths, inputFiles(r.in, r.inputsRead));
    writeFilesAtomically(files);
    if (stats) std::cout << describeStats(r.stats);
    if (!quiet) {
      std::cout << fmt::format("plan for rig '{}' ({} rules, {} expanded, {} heuristic):\n", r.in.rig.name,
                               r.plan.actions.size(), r.stats.expanded, o.heuristic);
      std::cout << describePlan(r.in.problem, r.plan);
      if (r.in.profile) std::cout << describePlanCost(r.plan, r.in.problem, *r.in.profile);
      for (const auto& f : files) std::cout << "wrote " << f.path << "\n";
    }
    return 0;
  }
};

}  // namespace

void registerGenerate(CLI::App& app, CliState& state) {
  auto cmd = std::make_shared<GenerateCommand>();
  CLI::App* sub = app.add_subcommand("generate", "Generate the cheapest vertex shader (GLSL + SPIR-V)");
  cmd->args.add(*sub);
  sub->add_option("-o", cmd->output, "Output path (a file if one --emit kind, else the stem for all)");
  sub->add_option("--emit", cmd->emit, "What to write: glsl, spv, header, reflection (comma-separated)")
      ->delimiter(',')
      ->check(CLI::IsMember({"glsl", "spv", "header", "reflection"}));
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

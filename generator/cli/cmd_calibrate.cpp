// `shadergen calibrate`: measure a device's cost per term and write its device profile
// (docs/device-profiles.md).
#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <sstream>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "cli/fresh_process.h"
#include "common/input_file.h"
#include "cli/output_files.h"
#include "cli/whole_model.h"
#include "measure/calibrate.h"
#include "measure/corpus.h"
#include "measure/fit.h"

namespace sg {
namespace {

struct CalibrateCommand {
  CalibrationOptions co;
  std::string output;
  std::string meshes = "dawn,head";
  bool noLayers = false;
  bool noCheck = false;
  bool noProbes = false;
  std::string form = "additive";
  std::string outsidePipes;  // --outside-pipes, "" = the form's own
  std::vector<std::string> thresholdTerms;  // --threshold
  bool noFloors = false;                    // --no-floors
  std::vector<std::string> fromLogs, checkLogs;
  std::string evaluate;  // --evaluate PROFILE: the held-out check of an existing profile
  bool perPlan = false;  // --per-plan: every plan of the held-out figures too
  std::string writeCorpus;  // --write-corpus DIR: the corpus's files, no device
  bool oneProcess = false;  // --one-process: every rig timed in this process
  // A fresh process timing one rig for its parent (cli/fresh_process.h): the rig, as JSON, and
  // where its report goes. Hidden options; the parent adds them to its own command line.
  std::string timeRig, report;
  std::vector<std::string> commandLine;

  static std::string rigTimingJson(const RigTiming& t) {
    return nlohmann::json{{"rig", t.rig},         {"fragment", t.fragment}, {"mesh", t.mesh},
                          {"profile", t.profilePath}, {"fitted", t.fitted},     {"cpu_device", t.cpuDevice}}
        .dump();
  }
  static RigTiming rigTimingFrom(const std::string& text) {
    try {
      const nlohmann::json j = nlohmann::json::parse(text);
      return RigTiming{j.at("rig"), j.at("fragment"), j.at("mesh"), j.at("profile"), j.at("fitted"), j.at("cpu_device")};
    } catch (const nlohmann::json::exception& e) {
      throw CLI::ValidationError("--time-rig", std::string("not a rig timing this shadergen writes: ") + e.what());
    }
  }

  // Samples of earlier runs (the tables calibrate prints): the device line and its rows.
  static std::vector<CalibrationSample> readLogs(const std::vector<std::string>& files, std::string* device) {
    std::vector<CalibrationSample> all;
    for (const auto& f : files) {
      std::istringstream in(readInputFile(f));
      std::string first;
      std::getline(in, first);
      if (device && device->empty() && first.rfind("device: ", 0) == 0) {
        // "device: NAME (driver: DRIVER); clock: ...": a driver may hold parentheses of its own.
        const size_t driver = first.find(" (driver: ");
        size_t end = first.find("); clock: ", driver);
        if (end == std::string::npos) end = first.rfind(')');
        *device = driver == std::string::npos ? first.substr(8)
                                              : first.substr(8, driver - 8) + " (" + first.substr(driver + 10, end - driver - 10) + ")";
      }
      for (auto& s : parseCalibrationSamples(in, {{"dawn", 180000}, {"head", 2009}}, std::filesystem::path(f).filename().string()))
        all.push_back(std::move(s));
    }
    if (all.empty()) throw InputError(SourceLoc{files.front(), 0, 0}, "no calibration samples in these logs");
    return all;
  }

  // --per-plan: every plan of the report's leave-one-rig-out and held-out check ("" without it).
  std::string perPlanTables(const CalibrationReport& rep) const {
    if (!perPlan) return "";
    return formatHeldOutPlans(rep.heldOut, "leave-one-rig-out") + formatHeldOutPlans(rep.check, "held-out check");
  }

  int refit() {
    CalibrationReport rep;
    rep.samples = readLogs(fromLogs, &rep.device);
    rep.clock = "as recorded in";
    for (const auto& f : fromLogs) rep.clock += " " + std::filesystem::path(f).filename().string();
    rep.driver = "as recorded (see the device)";
    rep.nearBestPower = co.nearBestPower;
    rep.outsidePipes = co.fit.outsidePipes.value_or(outsidePipesOf(co.fit.form));
    rep.floors = co.fit.floors;
    rep.profile = fitDeviceProfile(rep.samples, rep.device, 180000, co.nearBestPower, co.fit);
    rep.fits = evaluateFit(rep.samples, rep.profile, {"dawn", "head"});
    rep.heldOut = leaveOneRigOut(rep.samples, rep.device, 180000, co.nearBestPower, co.fit);
    if (!checkLogs.empty()) rep.check = checkHeldOut(readLogs(checkLogs, nullptr), rep.profile);
    std::cout << formatCalibration(rep) << perPlanTables(rep);
    if (!output.empty()) {
      std::vector<InputFile> inputs;
      for (const auto& f : fromLogs) inputs.push_back({f, "a log"});
      for (const auto& f : checkLogs) inputs.push_back({f, "a log"});
      refuseClobbering({output}, inputs);
      writeFilesAtomically({{output, deviceProfileYaml(rep)}});
      std::cout << fmt::format("{}: device profile of {}\n", output, rep.device);
    }
    return 0;
  }

  // The random rigs and requests --corpus N --seed S would time, as files to generate, bench or
  // validate one by one (the held-out sets of docs/device-profiles.md are such seeds).
  int writeCorpusFiles() const {
    if (co.corpus == 0) throw CLI::ValidationError("--write-corpus", "needs --corpus N (how many random rigs)");
    std::vector<PendingFile> files;
    std::string listing;
    for (const CorpusCase& c : randomCorpus(co.corpus, co.corpusSeed)) {
      const std::filesystem::path stem = std::filesystem::path(writeCorpus) / c.name;
      files.push_back({stem.string() + ".rig.yaml", c.rigYaml});
      files.push_back({stem.string() + ".frag", c.fragment});
      listing += files[files.size() - 2].path + " " + files.back().path + "\n";
    }
    writeFilesAtomically(files);  // all of them or none
    std::cout << listing;
    return 0;
  }

  // --form, which CLI11 has checked against the three names.
  ProfileForm chosenForm() const {
    return form == "roofline" ? ProfileForm::Roofline : form == "raster" ? ProfileForm::Raster : ProfileForm::Additive;
  }

  // --outside-pipes: "none" or term names, each one a pipe of the form prices.
  void parseOutsidePipes() {
    if (outsidePipes.empty()) return;
    if (co.fit.form == ProfileForm::Additive)
      throw CLI::ValidationError("--outside-pipes", "needs --form roofline or raster (the additive form has no pipes)");
    std::vector<int> terms;
    if (outsidePipes != "none") {
      const DeviceProfile pipes = profileForm(co.fit.form);
      for (size_t start = 0; start <= outsidePipes.size();) {
        const size_t comma = std::min(outsidePipes.find(',', start), outsidePipes.size());
        const std::string name = outsidePipes.substr(start, comma - start);
        const int term = termByName(name);
        const bool piped = term >= 0 && std::any_of(pipes.pipes.begin(), pipes.pipes.end(), [&](const DeviceProfile::Pipe& pipe) {
                             return pipe.nanoseconds[size_t(term)] > 0;
                           });
        if (!piped)
          throw CLI::ValidationError("--outside-pipes", fmt::format("'{}' is not a term any pipe of the {} form prices", name, form));
        if (std::count(terms.begin(), terms.end(), term) == 0) terms.push_back(term);
        start = comma + 1;
      }
    }
    co.fit.outsidePipes = terms;
  }

  // --threshold TERM (repeatable): the terms the fit may price past a threshold.
  void parseThresholds() {
    for (const std::string& name : thresholdTerms) {
      const int term = termByName(name);
      if (term < 0 || term == kTermVertices) {
        std::string known;
        for (int t = 0; t < kTermCount; ++t)
          if (t != kTermVertices) known += fmt::format("{}{}", known.empty() ? "" : ", ", termName(t));
        throw CLI::ValidationError("--threshold", fmt::format("'{}' is not a term a threshold may price (known: {})", name, known));
      }
      if (kMaxProfileThresholds <= co.fit.thresholds.size())
        throw CLI::ValidationError("--threshold", fmt::format("at most {} terms (each doubles what the search weighs)", kMaxProfileThresholds));
      if (std::count(co.fit.thresholds.begin(), co.fit.thresholds.end(), term) == 0) co.fit.thresholds.push_back(term);
    }
  }

  int run() {
    co.fit.form = chosenForm();
    parseOutsidePipes();
    parseThresholds();
    co.fit.floors = !noFloors;
    if (co.fit.constantCache && co.fit.form == ProfileForm::Additive)
      throw CLI::ValidationError("--constant-cache", "needs --form roofline or raster (the cache's misses are priced in the constant pipe)");
    if (co.fit.pipeSumShare && co.fit.form == ProfileForm::Additive)
      throw CLI::ValidationError("--pipe-sum-share", "needs --form roofline or raster (the share is of the pipes a program does not wait for)");
    if (co.fit.drawSizes && co.fit.form != ProfileForm::Raster)
      throw CLI::ValidationError("--draw-sizes", "needs --form raster (the other forms price a draw's size by their per-draw weights)");
    if (!writeCorpus.empty()) return writeCorpusFiles();
    if (!fromLogs.empty()) return refit();
    if (!evaluate.empty()) {
      if (checkLogs.empty()) throw CLI::ValidationError("--evaluate", "needs --check-log (the samples to predict)");
      CalibrationReport rep;
      rep.profile = loadDeviceProfile(evaluate);
      // A log timed with --plans-under this profile holds the plan its search returned.
      rep.check = checkHeldOut(readLogs(checkLogs, nullptr), rep.profile, ownPlanLabels(evaluate));
      std::cout << formatHeldOutCheck(rep.check) << perPlanTables(rep);
      return 0;
    }
    co.validationLayers = !noLayers;
    co.meshes.clear();
    size_t start = 0;
    while (start <= meshes.size()) {
      size_t comma = meshes.find(',', start);
      std::string m = meshes.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
      if (m != "dawn" && m != "head" && m != "limb" && m != "small")
        throw CLI::ValidationError("--meshes", "expected a comma-separated list of dawn, head, limb, small; got '" + meshes + "'");
      co.meshes.push_back(m);
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    if (!co.rigs.empty() && (co.plans.fragmentPath.empty() || co.plans.rulesPaths.empty()))
      throw CLI::ValidationError("--rig", "plans need --rig, --fragment and --rules together");
    if (co.corpus > 0 && co.plans.rulesPaths.empty())
      throw CLI::ValidationError("--corpus", "needs --rules whose vocabulary the random requests use (examples/dawn/rules.yaml)");
    if (!co.plansUnder.empty() && co.rigs.empty() && co.corpus == 0)
      throw CLI::ValidationError("--plans-under", "needs --rig or --corpus (the rigs whose plans it times)");
    // A profile's error is the user's, before anything is timed (a corpus rig's error only leaves that rig out).
    for (const auto& p : co.plansUnder) loadDeviceProfile(p);
    // The child of a calibration: one rig, its report to the parent. Before the rigs are listed,
    // so a whole model is not read again for each of its parts.
    if (!timeRig.empty()) {
      if (report.empty()) throw CLI::ValidationError("--time-rig", "needs --child-report");
      const RigTiming t = rigTimingFrom(timeRig);
      writeFreshProcessReport(report, [&] { return runGpuBench(rigBenchOptions(co, t)); });
      return 0;
    }
    // MODEL.glb#*: each primitive is a rig of its own, timed on its own mesh.
    std::vector<std::string> rigs;
    for (const auto& r : co.rigs) {
      if (auto parts = wholeModelParts(r)) {
        for (const auto& p : *parts) rigs.push_back(p.ref);
      } else {
        rigs.push_back(r);
      }
    }
    co.rigs = rigs;
    if (!oneProcess)
      co.timeRig = [this](const RigTiming& t) {
        const std::string what = fmt::format("{} on '{}'", rigLabel(t.rig), t.mesh);
        return benchInFreshProcesses(commandLine, {"--time-rig", rigTimingJson(t)}, what, true, co.processes, co.stop);
      };
    co.check = !noCheck;
    co.probes = !noProbes;
    co.fit.form = chosenForm();
    if (!output.empty()) {
      std::vector<InputFile> inputs;
      for (const auto& r : co.rigs)  // a glTF model's buffer files too: `-o M.bin` beside M.gltf
        for (const auto& f : loadRig(r).sourceFiles) inputs.push_back({f, "a rig"});
      if (!co.rigs.empty()) inputs.push_back({co.plans.fragmentPath, "the fragment shader"});
      for (const auto& r : co.plans.rulesPaths) inputs.push_back({r, "a rules file"});
      refuseClobbering({output}, inputs);
    }
    // SIGINT (`timeout -s INT`, Ctrl-C) stops the timing and keeps what was timed; a second one
    // a second or more later ends the process at once. Not sooner: GNU timeout sends its signal
    // to the command and again to its process group, and ending on that copy lost every run
    // (two of three interrupted lavapipe runs wrote nothing, an H200 training run too).
    // The first signal's time is claimed by one compare-exchange, so two copies handled at once
    // on two threads agree on which came first.
    static std::atomic<bool> interrupted{false};
    static std::atomic<long long> firstInterruptNs{0};
    co.stop = &interrupted;
    std::signal(SIGINT, [](int) {
      timespec now{};
      clock_gettime(CLOCK_MONOTONIC, &now);  // async-signal-safe, as are lock-free atomics and _exit
      const long long ns = static_cast<long long>(now.tv_sec) * 1000000000LL + now.tv_nsec + 1;  // never 0
      long long first = 0;
      if (firstInterruptNs.compare_exchange_strong(first, ns)) {
        interrupted.store(true);
        return;
      }
      if (ns - first > 1000000000LL) _exit(130);
    });
    // The handler stays until exit: restoring the default here let timeout's second copy, 0.2 s
    // after the first, kill a run that had just stopped and was writing what it timed (exit 130
    // under the sanitizers, cli_device_profile). The profile is written atomically either way.
    CalibrationReport rep = calibrateDevice(co);
    std::cout << formatCalibration(rep) << perPlanTables(rep);
    size_t failed = 0;
    for (const auto& s : rep.samples) failed += !s.validated;
    if (!output.empty()) {
      writeFilesAtomically({{output, deviceProfileYaml(rep)}});
      std::cout << fmt::format("{}: device profile of {}\n", output, rep.device);
    }
    if (failed) std::cerr << fmt::format("shadergen: error: {} probe(s) disagreed with their expected outputs and were not timed\n", failed);
    return failed ? 1 : 0;
  }
};

}  // namespace

void registerCalibrate(CLI::App& app, CliState& state) {
  auto cmd = std::make_shared<CalibrateCommand>();
  CLI::App* sub = app.add_subcommand("calibrate", "Measure what a Vulkan device pays per term of the cost model and write "
                                                   "its device profile (docs/device-profiles.md)");
  sub->add_option("--device", cmd->co.device, "Vulkan device name (substring); default lavapipe");
  sub->add_option("-o,--output", cmd->output, "Device profile (YAML) to write");
  sub->add_option("--meshes", cmd->meshes, "Procedural meshes, comma-separated; all are fitted, meshes of two sizes give per-draw "
                                           "weights, the first one's size is the profile's vertices_per_draw "
                                           "(default dawn,head: 180,000 and 2,009 vertices; limb: 825, a small draw)");
  sub->add_option("--rig", cmd->co.rigs, "Also time the plan of this rig, its forced alternatives and bench's floors; "
                                         "repeat for several rigs (a packed layout beside the float one). A glTF rig "
                                         "(MODEL.glb#m/p, or MODEL.glb#* for every primitive) is timed on its own mesh");
  sub->add_option("--fragment,-f", cmd->co.plans.fragmentPath, "With --rig: the fragment shader");
  sub->add_option("--rules,-r", cmd->co.plans.rulesPaths, "With --rig: rules file(s)");
  sub->add_option("--max-attributes", cmd->co.plans.maxAttributes, "With --rig: vertex input attributes (default 16)")
      ->check(CLI::Range(1, 4096));
  sub->add_option("--templates", cmd->co.plans.templateDir, "With --rig: directory with vertex.glsl templates");
  sub->add_option("--draws", cmd->co.drawsPerFrame, "Draws of the mesh between two timestamps (default 16)")
      ->check(CLI::Range(1, 4096));
  sub->add_option("--min-frame-vertices", cmd->co.minVerticesPerFrame,
                  "A smaller mesh (a model's part) is drawn more often than --draws, so that each timed frame draws at least this "
                  "many vertices (default 16000: the 2,009-vertex head at 8 draws; 0: exactly --draws)")
      ->check(CLI::Range(0, 100000000));
  addInputMemoryOption(*sub, cmd->co.inputMemory);
  sub->add_option("--frames", cmd->co.frames, "Timed frames; the median counts (default 9)")->check(CLI::Range(1, 1000));
  sub->add_option("--rounds", cmd->co.rounds, "Timings per program; the best counts (default 2)")->check(CLI::Range(1, 100));
  sub->add_option("--refits", cmd->co.refits, "With --rig: fits again with the plans each profile chose (default 1)")
      ->check(CLI::Range(0, 10));
  sub->add_option("--near-best-weight", cmd->co.nearBestPower,
                  "With --rig: a plan's row in the fit weighs (its rig's fastest / its time)^P (default 4; 0: all alike)")
      ->check(CLI::Range(0.0, 16.0));
  sub->add_option("--corpus", cmd->co.corpus,
                  "Also time N random rigs, each with a random request (generator/measure/corpus.h), over --rules "
                  "(examples/dawn/rules.yaml has their vocabulary), as --rig does")
      ->check(CLI::Range(0, 1000));
  sub->add_option("--seed", cmd->co.corpusSeed, "The corpus's seed (default 1): the same seed, the same rigs");
  sub->add_option("--write-corpus", cmd->writeCorpus,
                  "Write the --corpus N --seed S rigs and requests to DIR (<name>.rig.yaml, <name>.frag; one line "
                  "per case) and exit; no device is opened");
  sub->add_option("--plans-under", cmd->co.plansUnder,
                  "With --rig or --corpus: also time each rig's plan under this device profile and its forced "
                  "alternatives (\"plan under NAME: ...\"), so a held-out log holds the plan that profile would choose; "
                  "repeat for several")
      ->check(CLI::ExistingFile);
  sub->add_flag("--no-check", cmd->noCheck, "With --rig: do not time the rigs' plans under the fitted profile afterwards");
  sub->add_option("--from-log", cmd->fromLogs,
                  "Fit the samples of earlier runs' logs (their tables) instead of measuring; no device is opened")
      ->check(CLI::ExistingFile);
  sub->add_option("--check-log", cmd->checkLogs,
                  "With --from-log: logs of rigs the fit must not see, predicted by the fitted profile (the held-out check)")
      ->check(CLI::ExistingFile);
  sub->add_option("--evaluate", cmd->evaluate,
                  "With --check-log: predict the logs' plans with this device profile (no fit, no device)")
      ->check(CLI::ExistingFile);
  sub->add_flag("--per-plan", cmd->perPlan,
                "Also list every plan of the leave-one-rig-out and held-out (--check-log) figures: predicted, measured, "
                "and their ratio over its pair's level (the error a choice turns on)");
  sub->add_flag("--no-probes", cmd->noProbes, "With --rig: time only the rigs' programs (samples for another fit)");
  sub->add_option("--form", cmd->form, "The model fitted: additive (default), roofline, or raster (the roofline with the fragments a draw covers priced instead of per-draw weights; docs/device-profiles.md)")
      ->check(CLI::IsMember({"additive", "roofline", "raster"}));
  sub->add_flag("--constant-cache", cmd->co.fit.constantCache,
                "With --form roofline or raster: fit the constant cache's capacity (palette entries per warp past which "
                "uniform loads at a per-vertex index miss) and its miss price; kept where it lowers the fit's error "
                "(docs/device-profiles.md)");
  sub->add_flag("--draw-sizes", cmd->co.fit.drawSizes,
                "With --form raster: fit one set of weights per mesh size the samples were timed at (vertices per "
                "draw), a draw between two sizes priced by their weights interpolated in log(vertices); kept where it "
                "lowers the fit's error (docs/device-profiles.md, \"Draw sizes\")");
  sub->add_flag("--pipe-sum-share", cmd->co.fit.pipeSumShare,
                "With --form roofline or raster: fit how imperfectly the pipes overlap, a program paying besides its "
                "slowest pipe a share of the others (pipe_sum_share, 0 to 1; docs/device-profiles.md, "
                "\"Pipes overlap imperfectly\")");
  sub->add_option("--outside-pipes", cmd->outsidePipes,
                  "With --form roofline or raster: the terms priced in the additive part as well as in their pipe (the "
                  "share of their cost the device does not overlap), comma-separated term names, or none. Default: "
                  "locations,buffer_loads,buffer_vec4_loads for raster, none for roofline (docs/device-profiles.md, "
                  "\"Inputs outside the overlap\")");
  sub->add_option("--threshold", cmd->thresholdTerms,
                  "Fit a price per unit of this term past a threshold, the threshold chosen by the fit among the amounts the "
                  "samples part, kept where it lowers the fit's error; repeat for up to 3 terms (docs/device-profiles.md, "
                  "\"A price past a threshold\": lavapipe's inputs past the 15th)");
  sub->add_flag("--no-floors", cmd->noFloors,
                "Fit the probes and the rigs' plans, not bench's floors (which read every input and sum it at once: on "
                "lavapipe they price an input as no plan pays it; docs/device-profiles.md)");
  sub->add_flag("--no-validation-layers", cmd->noLayers, "Run without the Khronos validation layer (use for timings)");
  addOneProcessFlag(*sub, cmd->oneProcess, "rig");
  addProcessesOption(*sub, cmd->co.processes, "rig");
  sub->add_option("--time-rig", cmd->timeRig)->group("");  // a fresh process's one rig (cli/fresh_process.h)
  sub->add_option("--child-report", cmd->report)->group("");
  sub->callback([cmd, &state] {
    cmd->commandLine = state.commandLine;
    state.run = [cmd] { return cmd->run(); };
  });
}

}  // namespace sg

// Device calibration (shadergen calibrate, docs/device-profiles.md): measures what a device
// pays per vertex for each term of the cost model and fits a device profile.
//
// Probes are small vertex programs that vary one term at a time over the vertices and
// triangles of a procedural mesh: vertex input locations at fixed bytes, bytes at fixed
// locations, the length of a dependent arithmetic chain, storage-buffer loads, uniform
// palette loads indexed per vertex (against the same loads at a uniform index), and output
// components. Every probe is first run with its outputs captured and compared with the
// values it must compute (computed here on the CPU from the same data); only a probe that
// agrees is timed. Generated plans (each rig's plan and its forced alternatives, bench's
// rows) and bench's floors join the probes as samples. The weights are the non-negative
// least-squares fit (measure/fit.h, Ceres Solver) of ns per vertex on the terms' amounts, relative errors
// weighted equally; with meshes of different sizes, each term also gets a per-draw weight
// (the fit: ns per vertex = sum of (w + d / vertices per draw) x amount). Then each rig's
// plans under the fitted profile, which join the samples for a refit (the plans a profile
// chooses are where its errors cost time); the plans under the last profile are the check,
// timed and compared with its predictions, samples no fit saw.
#pragma once
#include <atomic>
#include <cmath>
#include <cstdint>
#include <functional>
#include <istream>
#include <map>
#include <string>
#include <vector>

#include "measure/gpu_bench.h"
#include "measure/fit.h"
#include "search/device_profile.h"

namespace sg {

// The mesh of a glTF rig's samples: the model's own primitive (its vertices and index
// order), not a procedural mesh.
inline constexpr const char* kOwnMesh = "own";
// The meshes a rig's plans are timed on: a glTF rig's own, a YAML rig's procedural ones.
std::vector<std::string> rigMeshes(const std::string& rig, const std::vector<std::string>& meshes);
// A rig as samples and reports name it: "face.rig.yaml", "Fox.glb#0/0".
std::string rigLabel(const std::string& rig);

// One rig's timing in a calibration: bench's programs for `rig` on `mesh`, generated under the
// profile at `profilePath` (the plans of a fit) or the slot model's (the first pass).
struct RigTiming {
  std::string rig;
  std::string fragment;  // "" = the options' own (a corpus rig has its own request)
  std::string mesh;
  std::string profilePath;
  bool fitted = true;  // the fit's samples (and the floors); false: the check's plans
  bool cpuDevice = false;  // timed by the host's clock, raster off (isCpuDevice)
};
struct CalibrationOptions;
// The bench options calibrate times a rig with.
GpuBenchOptions rigBenchOptions(const CalibrationOptions& opts, const RigTiming& t);

struct CalibrationOptions {
  std::string device;               // "" = lavapipe
  bool validationLayers = true;
  std::vector<std::string> meshes{"dawn", "head"};  // the first one's samples give the weights
  uint32_t drawsPerFrame = 16;
  uint32_t minVerticesPerFrame = 16000;  // a small mesh drawn more often (GpuBenchOptions)
  uint32_t frames = 9;              // + 1 warm-up frame
  uint32_t rounds = 2;              // best round counts
  uint32_t width = 256, height = 256;  // the target of every draw (bench's default)
  rt::InputMemory inputMemory = rt::InputMemory::DeviceLocal;  // of every timed program (GpuBenchOptions)
  bool probes = true;
  // For each rig: the generated plan and every forced alternative (bench's programs), with
  // plans' fragment shader, rules and limits, and bench's floors. A glTF rig (MODEL.glb#m/p)
  // is timed once, on its own mesh (kOwnMesh); a YAML rig on each of `meshes`.
  std::vector<std::string> rigs;
  GenerateOptions plans;
  // Random rigs and requests of the corpus (measure/corpus.h) added to `rigs`, each with its
  // own fragment shader, over plans.rulesPaths (examples/dawn/rules.yaml has the vocabulary).
  size_t corpus = 0;
  uint32_t corpusSeed = 1;
  // Device profiles under which each rig's plan is searched and timed too, with its forced
  // alternatives (labelled planUnderLabel(PATH)). The fit pass times the
  // instruction-slot plan's neighbourhood; a profile's own plan may lie outside it, and the
  // held-out check can only call "chosen" a plan that was timed (docs/device-profiles.md,
  // "The profile's own plan").
  std::vector<std::string> plansUnder;
  bool check = true;  // then the same rigs' plans under the fitted profile
  // Refits: each adds the plans the profile chose to the samples and fits again; the last
  // profile's plans are the check, which no fit saw.
  uint32_t refits = 1;
  // Each plan's and floor's row in the fit weighs (fastest of its rig and mesh / its time)^P:
  // the search only compares plans of one rig, and the ones near the fastest are where a
  // wrong order costs time (docs/device-profiles.md, "Where the fit looks"). 0: all alike.
  double nearBestPower = 4;
  // The model fitted and its optional terms (measure/fit.h): the constant cache's capacity and
  // draw sizes are kept only where they lower the fit's error; compare the leave-one-rig-out
  // tables with and without.
  FitOptions fit;
  // Set (by the CLI's SIGINT handler: a device call's time limit) to time nothing more: the
  // probe or rig being timed finishes, the rest are skipped, and what was timed is fitted and
  // reported, with a note saying so.
  const std::atomic<bool>* stop = nullptr;
  // How each rig is timed; empty: runGpuBench(rigBenchOptions(...)) in this process. Within one
  // process NVIDIA's timings depend on what it timed before, by up to 30 % per program and
  // reproducibly (bench/data/h100-order25), so the CLI times each rig in a fresh process of its own
  // (cli/fresh_process.h; docs/device-profiles.md, "One process per rig").
  std::function<GpuBenchReport(const RigTiming&)> timeRig;
  // How many processes timeRig times each rig in, their rounds merged (bench --processes,
  // measure/gpu_bench.h mergeProcessRuns): the clock line says it.
  uint32_t processes = 1;
};

struct CalibrationSample {
  std::string label;  // "locations 8 (float32x4)", "plan: generated", ...
  std::string mesh;
  double vertices = 0;  // per draw (the mesh's)
  std::string rig;      // the rig of a plan or floor ("" for a probe)
  // The request its plans answer, where one rig is timed under several (samples read from
  // several logs: the log's name; "" in a live run, which has one request per rig). Plans of
  // different requests are different choices, compared apart.
  std::string request;
  Workload workload;    // of the mesh and pose it was timed on (measure/workload.h); a probe's: its mesh's
  bool fitted = true;   // false: a plan of the check, which the fit did not see
  TermAmounts amounts{};
  bool validated = false;
  std::string failure;      // why it was not timed (its outputs disagreed, or it did not run)
  double measuredNs = -1;   // per vertex, raster on, timestamps: its best round
  double medianRoundNs = -1;  // its median round by the same clock (-1: not recorded): the sample's spread
  // Vertex shader invocations per vertex of one raster-on draw of its mesh (bench's
  // shadedVerticesPerVertex; -1: not counted); its fragments are workload.fragmentsPerVertex.
  double shadedPerVertex = -1;
  double predictedNs = -1;  // under the fitted profile
  // The timed SPIR-V's hash (GpuBenchRow::program; "" in logs before session 31): where the log
  // timed one program in several runs, the held-out check counts it at its best (predictRigs).
  std::string program;
  // What the driver compiled its vertex stage into (describeDriverStatistics; "" where the
  // device does not say, and in logs before session 32): read by analyses, not priced.
  std::string driverStatistics;
};

struct CalibrationFit {
  std::string mesh;
  size_t samples = 0;  // fitted ones
  double rmsRelativeError = 0, maxRelativeError = 0;
  double spearman = 0;  // predicted against measured, fitted samples (within 0.5 %: ties)
  size_t allSamples = 0;  // with the check's
  double spearmanAll = NAN;
};

// The check of one rig on one mesh: its plans under the fitted profile.
struct CalibrationCheck {
  std::string rig, mesh;
  size_t plans = 0;
  double spearman = NAN;            // predicted against measured over its plans
  double generatedOverFastest = NAN;  // the chosen plan's time over the fastest plan's
  RoundSpread byRound;                // the same ratio within each round (generatedOverFastestByRound)
};

// Leave-one-rig-out (docs/device-profiles.md, "Held-out error"): for each rig, the profile
// fitted without any of that rig's samples (fitDeviceProfile on the rest: the probes and the
// other rigs), predicting that rig's plans on each mesh it was timed on.
struct HeldOutRig {
  std::string rig, mesh;  // rig: "RIG (REQUEST)" where the rig was timed under several requests
  size_t plans = 0;                  // distinct validated plans (by their term amounts)
  std::vector<double> predicted, measured;  // ns per vertex, per plan
  // Per plan, of its first timing (plans of the same term amounts are one plan): its log label,
  // its program's hash ("" in logs before session 31) and how many timings it stands for.
  std::vector<std::string> labels, programs;
  std::vector<size_t> timings;
  // The plan counted as the choice (the own plan, or the slowest of a tie for the least prediction)
  // and its measured time. Where it is the own plan, its label and program are the own timing's.
  size_t chosen = 0;
  double chosenNs = NAN;
  size_t fastest = 0;  // the plan of the pair's fastest timing
  double spearman = NAN;             // predicted against measured (within 0.5 %: ties)
  double chosenOverFastest = NAN;    // measured time of the least-predicted plan / the fastest
  // Plans sharing the least predicted time (a roofline prices plans whose extra work hides under
  // the same slowest pipe alike). The search may return any of them, so chosenOverFastest counts
  // the slowest of them.
  size_t tiedForLeast = 0;
  // The profile's own plan, timed by calibrate --plans-under, is the one counted (checkHeldOut's
  // ownPlanLabels), not the slowest of a tie.
  bool ownPlan = false;
  bool ownPlanByNameOnly = false;  // its label had no fingerprint (ownPlanLabels' second)
  double rmsRelativeError = NAN;
  // The pair's level: the geometric mean of predicted over measured, and the RMS relative error
  // left with the predictions divided by it. A choice turns on the second alone (every plan of a
  // pair is scaled alike); on the GPUs most of the RMS error is the first (docs/device-profiles.md).
  double level = NAN;
  double rmsWithinPair = NAN;
};
struct LeaveOneRigOut {
  std::vector<HeldOutRig> rows;  // by rig, then mesh
  double medianSpearman = NAN, worstChosenOverFastest = NAN, medianRms = NAN, maxRms = NAN;
  double medianRmsWithinPair = NAN;  // of HeldOutRig::rmsWithinPair
  // Rows whose chosen plan is within 5 % and within 10 % of the fastest (issue 33's bars for a GPU
  // and for lavapipe): chosenOverFastest <= 1.05, <= 1.10.
  size_t within5Percent = 0, within10Percent = 0;
  size_t pairsWithATieForLeast = 0;  // rows whose least prediction several plans share (tie rule applied)
  size_t pairsWithOwnPlan = 0;       // rows counting the profile's own plan (HeldOutRig::ownPlan)
  size_t ownPlansByNameOnly = 0;     // of them, found by the name-only label of older logs
  // Rows whose log holds a plan under the profile's name that is not the least predicted (it was
  // searched under another profile of that name): the least predicted counted.
  size_t ownPlanNotLeast = 0;
};
LeaveOneRigOut leaveOneRigOut(const std::vector<CalibrationSample>& samples, const std::string& deviceName,
                              double workloadVertices, double nearBestPower, const FitOptions& fit = {});
std::string formatLeaveOneRigOut(const LeaveOneRigOut& loo);
// The held-out check: each (rig, mesh) of samples no fit saw, its plans predicted by `profile`
// (same figures as leave-one-rig-out). With `ownPlanLabels` (ownPlanLabels(PROFILE)), a pair
// whose log timed the plan the profile's search returned counts that plan, where it is among the
// least predicted.
LeaveOneRigOut checkHeldOut(const std::vector<CalibrationSample>& heldOut, const DeviceProfile& profile,
                            const std::vector<std::string>& ownPlanLabels = {});
// "plan under STEM@FINGERPRINT: ", the prefix of the labels of plans timed under a profile file
// (calibrate --plans-under): STEM the file's name without its directory and extension,
// FINGERPRINT the first digits of the SHA-256 of its bytes, so a log names the very profile
// its plans were searched under, not only a file name a later profile may take.
constexpr size_t kProfileFingerprintDigits = 12;
std::string planUnderLabel(const std::string& profilePath);
// The labels a log may give the profile's own plan: planUnderLabel(PATH) + "generated", then
// "plan under STEM: generated" as logs written before the fingerprint (session 28) have it;
// such a row may have been searched under an earlier profile of that name.
std::vector<std::string> ownPlanLabels(const std::string& profilePath);
std::string formatHeldOutCheck(const LeaveOneRigOut& check);
// Every plan of every pair (calibrate --per-plan): predicted and measured ns per vertex, their ratio,
// and that ratio over the pair's level, the part of the error a choice turns on; a pair's plans by
// predicted time, its chosen and fastest marked. `what` names the figures ("held-out check",
// "leave-one-rig-out").
std::string formatHeldOutPlans(const LeaveOneRigOut& check, const char* what = "held-out check");

struct CalibrationReport {
  std::string device, driver;
  std::string clock;  // what measured the samples: GPU timestamps, or host time on a CPU device
  std::vector<CalibrationSample> samples;
  double nearBestPower = 0;  // of the fit (CalibrationOptions)
  std::vector<int> outsidePipes;  // the terms the fit priced outside the pipes too (FitOptions::outsidePipes, resolved)
  bool floors = true;             // bench's floors were rows of the fit (FitOptions::floors)
  DeviceProfile profile;
  std::vector<CalibrationFit> fits;  // one per mesh
  std::vector<CalibrationCheck> checks;
  LeaveOneRigOut heldOut;  // with two rigs or more
  LeaveOneRigOut check;    // rigs no fit saw (calibrate --check-log)
  // Where each rig's timed inputs lived (inputMemoryLine), in timing order: "RIG on 'MESH', inputs: ...".
  std::vector<std::string> inputMemoryByRig;
  std::vector<std::string> notes;  // corpus cases left out, and why
};

CalibrationReport calibrateDevice(const CalibrationOptions& opts);

// The fit alone (exposed for tests): weights >= 0 minimising the relative error of
// predicted against measured ns per vertex over the validated, fitted samples, a rig's
// samples weighted by (its fastest on that mesh / their time)^nearBestPower; per-draw
// weights too when the samples' meshes differ in size. The profile prices draws of
// `workloadVertices`.
DeviceProfile fitDeviceProfile(const std::vector<CalibrationSample>& samples, const std::string& deviceName,
                               double workloadVertices, double nearBestPower = 0,
                               const FitOptions& fit = {});
// Fills predictedNs of every sample and the fit statistics per mesh.
std::vector<CalibrationFit> evaluateFit(std::vector<CalibrationSample>& samples, const DeviceProfile& profile,
                                        const std::vector<std::string>& meshes);

// The samples of formatCalibration's table read back (recorded logs, bench/data/*.log):
// rows whose mesh is in `meshVertices` (its vertices per draw). Rows "checked plan" are not
// fitted; a rig of "—" is a probe's. A log is one calibrate run, one request per rig: `request`
// names it (the log's file name), so the same rig in two logs is two choices.
std::vector<CalibrationSample> parseCalibrationSamples(std::istream& table, const std::map<std::string, double>& meshVertices,
                                                       const std::string& request = "");

// The report as text (samples table, weights, fit errors), and the profile as a documented
// YAML file that loadDeviceProfile reads back.
std::string formatCalibration(const CalibrationReport& report);
std::string deviceProfileYaml(const CalibrationReport& report);

}  // namespace sg

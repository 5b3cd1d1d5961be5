// GPU timing of vertex programs (shadergen bench): the generated plan, every forced
// alternative, a hand-written shader with the same interface (the port of listing 3-3),
// and a pass-through floor, each drawn over the same mesh many times per frame with
// Vulkan timestamp queries, with rasterization on (indexed triangles + the fragment
// shader) and off (rasterizer discard + transform feedback, so nothing is optimised
// away). Every program but the floors is first validated on the same device in the same
// run (Validator::runOne: its captured outputs against the reference, fed by the same
// programInputs); a program that fails is reported and not timed.
// docs/performance.md has the tables and what they say about the cost model.
#pragma once
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "render/render.h"
#include "search/device_profile.h"

namespace sg {

struct GpuBenchOptions {
  RenderOptions render;        // gen, device, limits, size, mesh ("dawn"), lighting
  std::string handPortPath;    // "" = none; GLSL with the generated shader's interface
  bool floor = true;           // the pass-through program
  bool alternatives = true;    // every forced alternative (as validate --cross-check)
  // 0: the alternatives above. K: instead, the K plans cheapest under the search's objective
  // (pipeline/generate.h cheapestPlans), the generated one first: the candidates a measured
  // choice (bench --pin-out) picks from.
  size_t candidates = 0;
  bool rasterOn = true, rasterOff = true;
  uint32_t drawsPerFrame = 8;
  // A mesh too small to keep the device busy over drawsPerFrame draws is drawn more often, so
  // that a frame draws at least this many vertices (0: exactly drawsPerFrame). On the H200 a
  // 302-vertex part timed over 8 draws read 0.07 ns per vertex for its floor (the timestamps
  // bracket almost nothing); the default is the 2,009-vertex head at 8 draws.
  uint32_t minVerticesPerFrame = 16000;
  uint32_t frames = 7;         // + 1 warm-up frame, not counted
  uint32_t rounds = 3;         // passes over every program; the best pass counts
  // Where the timed programs' inputs live (runtime/vk_program.h). Device-local, as an engine
  // keeps a mesh; mapped (host-visible, the harness's placement before session 24) to compare.
  rt::InputMemory inputMemory = rt::InputMemory::DeviceLocal;
};

struct GpuBenchRow {
  std::string label;               // "generated", "forced <rule> for <fact>", "hand port", "floor"
  std::vector<std::string> rules;  // plan rules (generated programs)
  // The rules to --ban, beside the options' own, that make generate write this program: a
  // forced alternative's are the other rules producing its fact ("generated": none).
  std::vector<std::string> bans;
  // The rules to --ban that leave this plan the only derivation of its facts, whatever the
  // costs it is searched under (pipeline/generate.h bansPinning, with the bans above and the
  // options' own): what bench --pin-out records. Empty for the hand port and the floors.
  std::vector<std::string> pin;
  bool hasCost = false;            // a plan of the search (planCost)
  bool hasAmounts = false;         // amounts known: the plans and the floors
  int64_t planCost = 0;
  size_t spirvInstructions = 0;    // of the render build
  // The render build's SPIR-V, hashed (SHA-256, first 16 hex digits): the same program timed in
  // two runs (a profile's plan among another plan's alternatives) is known as one.
  std::string program;
  // What the driver compiled the render build's vertex stage into (the capture build's without
  // raster on): registers, instructions, ... as the driver names them; empty where the device
  // does not offer VK_KHR_pipeline_executable_properties (lavapipe 22.3).
  std::vector<rt::ShaderStatistic> driverStatistics;
  // Validation on the device before timing: "pass", "FAIL: <output ...>" (then not timed),
  // or "" for the floors, which write constants on purpose.
  std::string validation;
  // What the plan pays per term (search/device_profile.h; generated programs), and the
  // predicted time per vertex under the generation's device profile (-1 = no profile).
  TermAmounts amounts{};
  double predictedNsPerVertex = -1;
  double rasterOnNsPerVertex = -1;   // median frame / (draws x vertices); -1 = not measured
  double rasterOffNsPerVertex = -1;
  double rasterOnWallNsPerVertex = -1;   // host submit-to-fence time (see rt::Timing::wallNs)
  double rasterOffCpuNsPerVertex = -1;   // this process's CPU time over it, raster off (rt::Timing::cpuNs): calibrate's clock on a CPU device
  double rasterOffWallNsPerVertex = -1;
  // The prediction clock's figure (GpuBenchReport::predictionClock) in each round, in round
  // order: a program's number above is its best; these say how far one round is from another.
  std::vector<double> roundNsPerVertex;
};

// A ratio's least and greatest over the rounds it was taken in (NaN, NaN: fewer than two).
struct RoundSpread {
  double least = NAN, most = NAN;
  size_t rounds = 0;
};

struct GpuBenchReport {
  std::string device, driver;
  std::string limits;  // the device limits the plans were searched under ("" = the flags)
  size_t vertices = 0, triangles = 0;
  Workload workload;  // of the mesh and pose timed; the plans are priced for it
  // Vertex shader invocations per vertex of one raster-on draw (rt::Renderer::statistics; its
  // fragments are workload.fragmentsPerVertex); -1 where the device cannot count.
  double shadedVerticesPerVertex = -1;
  uint32_t drawsPerFrame = 0, frames = 0, rounds = 0, width = 0, height = 0;
  uint32_t processes = 1;  // fresh processes whose rounds these are (mergeProcessRuns)
  std::vector<GpuBenchRow> rows;
  // Over the generated plan and its alternatives (rows with a cost): Pearson correlation of
  // plan cost with time per vertex, and Spearman (rank) correlation; NaN if < 3 rows.
  double pearsonOn = 0, spearmanOn = 0, pearsonOff = 0, spearmanOff = 0;
  double pearsonOffWall = 0, spearmanOffWall = 0;  // the same against host time, raster off
  // With a device profile: Spearman of predicted against measured time, and the generated
  // program's time over the fastest generated one's, by `predictionClock`: raster on,
  // timestamps on a GPU; on a CPU device the clock calibrate fits there (isCpuDevice).
  double spearmanPredictedOn = NAN;
  double generatedOverFastestOn = NAN;
  // The same ratio taken within each round by the prediction clock: its least and greatest
  // over the rounds, the spread a reader weighs the best-of-rounds ratio against.
  RoundSpread byRound;
  std::string predictionClock;
  std::string inputMemory;  // where the timed inputs lived: inputMemoryLine of the first timing
  // The validated plan (generated or forced) that `predictionClock` timed fastest: an index
  // into rows, -1 where none was timed by it. Its `bans` make generate write it.
  int fastestPlan = -1;
  double fastestOverGenerated = NAN;  // its time over the generated program's, by that clock
  std::vector<Diagnostic> notes;  // loading's (which stored form is read, what budgets removed)
  std::string inputs;  // the digest of the files the plans were generated from (pipeline/pin.h)
};

GpuBenchReport runGpuBench(const GpuBenchOptions& opts);

// The prediction clocks (GpuBenchReport::predictionClock): timestamps on a GPU, the process's
// CPU time or the host's wall time on a CPU device (isCpuDevice).
inline constexpr const char* kClockTimestamps = "raster on, timestamps";
inline constexpr const char* kClockCpuRasterOff = "raster off, process CPU time (a CPU device)";
inline constexpr const char* kClockCpuRasterOn = "raster on, host time (a CPU device)";

// Runs of the same bench in several fresh processes (bench --processes N) as one report: each
// program's rounds are all the processes' rounds (its figures the best of them), so the
// median round a pin is chosen by (pinnedPlan) is taken over every process. On lavapipe a
// program once ran 25 % slower in every round of one process out of seven, and the others
// not (docs/performance.md): a process is a sample, as a round is. Throws if the runs timed
// other programs (a different candidate list) or on another device.
GpuBenchReport mergeProcessRuns(const std::vector<GpuBenchReport>& runs);
// The summary figures of a report (correlations, the fastest plan, the by-round spread) from
// its rows; runGpuBench and mergeProcessRuns end with it.
void summarize(GpuBenchReport& rep);

// The plan a measured choice pins (bench --pin-out): of the validated plans the prediction clock
// timed, the one whose median round is the fastest (-1: none). Not the best round, which the
// report's "fastest" line uses: on lavapipe one round of one program once read 0.37x its other
// round and every other program's, and a best round pinned that. Not the slowest round either:
// one slow round of the fastest program (another process on the CPU) then pinned a slower one.
int pinnedPlan(const GpuBenchReport& r);
double medianRound(const GpuBenchRow& row);  // NaN: never timed
// A plan a measured choice weighs (pinnedPlan, rankCandidates, a pin's timed plans): a plan of the
// search, validated and timed in rounds.
bool weighedPlan(const GpuBenchRow& row);

// Whether the timed candidates rank as the search's objective ranks them (bench --candidates
// widens to --max-candidates where they do not): over the plans pinnedPlan weighs, the
// objective's spread (greatest plan cost over least, less 1) against the measured spread of
// their median rounds. The objective "cannot rank" them where it predicts at least
// kRankedSpread between them and the device shows less than kShownFraction of it: its
// differences are not what the device pays there, so the next plans it ranks lower are no
// likelier to be slower. Session 38's H100 run: RobotExpressive's hand (256 vertices, 250
// draws a frame) was predicted 24.8 % apart over its 4 cheapest plans and measured 0.24 %; its
// fastest plan was the 12th cheapest, 0.944x the others.
struct CandidateRanking {
  size_t plans = 0;               // validated plans timed by the prediction clock
  double predictedSpread = NAN;   // NaN: fewer than two, or a plan cost not above 0
  double measuredSpread = NAN;
  bool cannotRank = false;
};
inline constexpr double kRankedSpread = 0.05;
inline constexpr double kShownFraction = 0.1;
CandidateRanking rankCandidates(const GpuBenchReport& r);

// Draws per timed frame of a mesh of `vertices`: at least `draws`, and enough that the frame
// draws `minVertices` vertices, at most kMostDrawsPerFrame.
inline constexpr uint32_t kMostDrawsPerFrame = 100000;
uint32_t drawsPerFrame(uint32_t draws, uint32_t minVertices, size_t vertices);

// A CPU device (lavapipe): its timestamp queries miss work it defers (on the 2,009-vertex head
// they read 55 ns per vertex where submit-to-fence took 1,000), so bench and calibrate time it
// by the host: this process's CPU time with the rasterizer discarded, else wall time.
bool isCpuDevice(const std::string& deviceName);

// Before a device is opened for timing: lavapipe runs single-threaded (LP_NUM_THREADS=0) unless
// the environment already says otherwise. With its rasterizer threads on a 2-core machine, one
// program's process CPU time moved 64-86 ns per vertex between three runs and ratios within a run
// by up to 17 %; single-threaded, 60-62 and 2 % (bench/data/lavapipe-linear-blend). Other
// drivers ignore the variable.
void timeCpuDevicesSingleThreaded();

// Predicted against measured time by one clock (`clock`: &GpuBenchRow::rasterOnNsPerVertex,
// ...), over the rows with a plan cost that passed validation and were timed by it: how many,
// their Spearman within the run-to-run spread (rows with a prediction), and the generated
// program's time over the fastest's (NaN without predictions). Bench reports it for raster
// on, calibrate for its own clock.
struct PredictionCheck {
  size_t plans = 0;
  int fastest = -1;  // the row of the fastest plan counted (-1: none), with or without predictions
  double spearman = NAN;
  double generatedOverFastest = NAN;
};
PredictionCheck checkPredictions(const std::vector<GpuBenchRow>& rows, double GpuBenchRow::*clock);

// The generated program's time over the fastest plan's within each round (roundNsPerVertex of
// the rows checkPredictions counts, the generated program first): least and greatest over the
// rounds every such row was timed in; NaN, NaN with fewer than two such rounds.
RoundSpread generatedOverFastestByRound(const std::vector<GpuBenchRow>& rows);
// " (within one round: 1.087x to 1.121x over 6 rounds)", or "" without a spread: bench's and
// calibrate's summary lines.
std::string describeRoundSpread(const RoundSpread& spread);

// Markdown table + summary lines.
// "inputs: device-local (a staging copy), in <memory types>" or "inputs: mapped, in <...>": where a
// timing's inputs lived (rt::Timing::inputMemory), for the header of bench's and calibrate's tables.
std::string inputMemoryLine(rt::InputMemory placement, const std::string& memoryTypes);

std::string formatGpuBench(const GpuBenchReport& report);
// "Register Count=32; Binary Size=4096": a row's driver statistics on one line (calibrate's log);
// a statistic of a second compiled vertex executable is prefixed "<its name>: "; "" for none.
std::string describeDriverStatistics(const std::vector<rt::ShaderStatistic>& statistics);

// Correlations (exposed for tests): NaN if fewer than 3 points or no variance.
double pearson(const std::vector<double>& x, const std::vector<double>& y);
double spearman(const std::vector<double>& x, const std::vector<double>& y);
// Spearman where measured values `y` closer than `spread` (relative) to the smallest of their
// run of neighbours count as ties: differences inside the run-to-run spread rank nothing.
double spearmanWithinSpread(const std::vector<double>& x, const std::vector<double>& y, double spread);

// Adds transform-feedback qualifiers to a hand-written vertex shader whose outputs are
// `layout(location = N) out TYPE NAME;` lines, at the offsets of `capture` (a capture build
// with the same outputs), and redeclares gl_PerVertex. Throws InputError for an output the
// capture layout lacks.
std::string addCaptureQualifiers(const std::string& glsl, const std::string& path, const EmittedGlsl& capture);

// A hand-written vertex shader as a program that stands in for `like` (a generated one):
// its own SPIR-V and interface from its reflection (emitter naming: a_<attribute>[target],
// u_<uniform>; no storage buffers), `like`'s outputs and capture layout. Fed by
// programInputs and validated by Validator::runOne like a generated program; a capture
// build needs the text through addCaptureQualifiers first.
GenerateResult handWrittenProgram(const std::string& text, const std::string& path, const GenerateResult& like,
                                  TargetEnv env);

}  // namespace sg

// A device profile: what each term of the cost model costs on one device, in nanoseconds
// per vertex (docs/device-profiles.md). Loaded from YAML; turned into the integer weights
// of the search (femtoseconds, so A* stays exact over int64 costs).
//
// A term may also cost per draw (a fixed cost of each draw call, and output components
// interpolated over the pixels a draw covers): spread over a draw's vertices, a per-draw
// weight d adds d / verticesPerDraw to the per-vertex one. The profile states the workload
// it prices for; bench and calibrate price each mesh at its own vertex count.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "search/plan.h"
#include "search/problem.h"
#include "search/workload.h"

namespace sg {

// What a workload feature (search/workload.h) a term's weight may be multiplied by.
// joints_per_warp_squared is joints_per_warp's square (its workload value or its default).
enum WorkloadFeature {
  kFeatureNone = 0,
  kFeatureJointsPerWarp,
  kFeatureInvocationsPerVertex,
  kFeatureActiveMorphTargets,
  kFeatureJointsPerWarpSquared,
  kFeatureFragmentsPerVertex,
  kFeaturePaletteEntriesPerWarp,
  kFeatureCount
};
// "joints_per_warp", ...: the keys of a profile's `scaled_by:` values and `workload_defaults:`.
const char* featureName(int feature);

struct DeviceProfile {
  std::string device;  // "NVIDIA H200 (Vulkan 580.159.04)"
  std::string file;    // where it was loaded from ("" = built in code)
  std::array<double, kTermCount> nanoseconds{};  // per unit of each term, per vertex
  std::array<double, kTermCount> drawNanoseconds{};  // per unit of each term, per draw
  double verticesPerDraw = 0;  // the workload priced for; required when a draw weight is set
  // A roofline (docs/device-profiles.md, "Roofline profiles"): pipes the device overlaps, each
  // a weighted sum of terms (ns per unit per vertex); a program takes the additive part above
  // plus its slowest pipe. None: the additive model alone (every profile before issue 33).
  struct Pipe {
    std::string name;  // "fetch", "memory", ...
    std::array<double, kTermCount> nanoseconds{};
  };
  std::vector<Pipe> pipes;
  // How imperfectly the pipes overlap (docs/device-profiles.md, "Pipes overlap imperfectly"):
  // besides its slowest pipe a program pays this share of its other pipes, so it costs
  // additive + (1 - s) x slowest + s x (sum of the pipes). 0: a pure roofline (every profile
  // before session 24); 1: every pipe added. Still a max of weighted sums (profileComponents),
  // so the search stays exact.
  double pipeSumShare = 0;
  // Per term, the workload feature its weights (additive and in every pipe) are multiplied by:
  // an indexed uniform load costs per distinct address a warp reads (`joints_per_warp`).
  std::array<int, kTermCount> scaledBy{};
  // Feature values used where the workload does not say (none stated: 1).
  std::array<double, kFeatureCount> workloadDefaults{};
  // The constant cache's capacity (docs/device-profiles.md, "The constant cache's capacity"):
  // where a warp's palette footprint (palette_entries_per_warp) exceeds `constantCacheEntries`,
  // every weight scaled by joints_per_warp costs `constantCacheMissFactor` times as much (its
  // per-address reads miss). 0 entries: no such term (every profile before session 21).
  double constantCacheEntries = 0;
  double constantCacheMissFactor = 1;
  // Prices past a threshold (docs/device-profiles.md, "A price past a threshold"): past `at` units of
  // a term (times its workload feature) each unit costs `nanoseconds` more per vertex, a hinge
  // max(0, amount - at) x ns added to the cost. On lavapipe a vertex input past the 15th costs
  // about 9 ns more. A sum of hinges is a max of weighted sums (profileComponents), so the search
  // stays exact. None: every profile before session 29.
  struct Threshold {
    int term = 0;
    double at = 0;
    double nanoseconds = 0;
  };
  std::vector<Threshold> thresholds;  // one per term at most, in term order
  // The workload priced for (search/workload.h): set by whoever generates for a known mesh.
  Workload workload;
  // Weights fitted on meshes of several sizes (docs/device-profiles.md, "Draw sizes"): each
  // size's additive weights and pipes (the pipes named and ordered as `pipes`). A draw of V
  // vertices is priced by the two sizes around V, interpolated in log(V), or by the nearest
  // size outside them; `nanoseconds` and `pipes` hold the weights at `verticesPerDraw`.
  // Empty: the weights above at every size (every profile before session 22).
  struct DrawSize {
    double vertices = 0;
    std::array<double, kTermCount> nanoseconds{};
    std::vector<Pipe> pipes;
  };
  std::vector<DrawSize> drawSizes;  // ascending in vertices; none or two at least

  // This profile priced at draws of `vertices`: its draw sizes interpolated into `nanoseconds`
  // and `pipes` (and `verticesPerDraw` set), `drawSizes` kept. Without draw sizes: itself.
  DeviceProfile atDrawSize(double vertices) const;

  // ns per unit of `term` per vertex when a draw has `vertices`: nanoseconds + drawNanoseconds / vertices,
  // times the term's workload feature (with draw sizes: the weights at `vertices`).
  double perVertex(int term, double vertices) const;
  bool hasDrawWeights() const;
  // The value of a feature for this profile's workload (the workload's, else the stated
  // default, else 1); kFeatureNone is 1; joints_per_warp times constantCacheFactor().
  double feature(int f) const;
  // constantCacheMissFactor where the workload's palette footprint (else its default) is past
  // the constant cache's capacity; else 1.
  double constantCacheFactor() const;
  // Predicted ns per vertex of these amounts on a mesh drawn `vertices` at a time (unrounded
  // weights; the search's own figure is predictPlanCost's): the additive part, the slowest pipe
  // and what the thresholds add.
  double predictNanoseconds(const TermAmounts& amounts, double vertices) const;
};
// Where a draw of `vertices` falls among ascending draw sizes: the last size at or below it
// (the first where none is), the next, and the next's share, log(vertices / below) /
// log(above / below); outside the sizes, the nearest alone (share 0). DeviceProfile::atDrawSize
// and the fit (measure/fit.h) blend by it.
struct DrawSizeBlend {
  size_t below = 0, above = 0;
  double share = 0;
};
DrawSizeBlend blendDrawSizes(const std::vector<double>& sizes, double vertices);

// Largest workload a profile may state (vertices per draw), and largest draw weight (a
// millisecond per unit per draw).
constexpr double kMaxVerticesPerDraw = 1e9;
constexpr double kMaxProfileDrawWeightNs = 1e6;

// Most pipes a roofline profile may have, most thresholds (each doubles the search's components),
// and the largest workload default it may state.
constexpr size_t kMaxProfilePipes = 8;
constexpr size_t kMaxProfileThresholds = 3;
constexpr double kMaxWorkloadFeature = 1e6;

// Search cost units of a profile: femtoseconds (1e-6 ns); a weight is rounded to one.
constexpr int64_t kFemtosecondsPerNanosecond = 1'000'000;
// Largest weight a profile may state (a microsecond per unit: far above any device).
constexpr double kMaxProfileWeightNs = 1000;

// Throws InputError (file:line:col) for unreadable files, bad YAML, unknown keys, weights
// that are not numbers, negative, not finite or above kMaxProfileWeightNs (draw weights:
// kMaxProfileDrawWeightNs), and draw weights without vertices_per_draw.
DeviceProfile loadDeviceProfile(const std::string& path);
DeviceProfile parseDeviceProfile(const std::string& text, const std::string& file);
// Prices storage-buffer table reads (kTermBufferTableLoads, kTermBufferTableVec4Loads) as the
// profile prices buffer loads: what a profile means that was written, or fitted from logs written,
// before they were counted apart.
void priceTableReadsAsBufferLoads(DeviceProfile& prof);

// The profile's additive weights in femtoseconds per unit of each term, per vertex at its workload.
TermWeights profileWeights(const DeviceProfile& profile);
// The search's components (Problem::componentWeights): one per pipe k, each the additive
// weights plus (1 - s) x pipe k's plus s x every pipe's (s = pipeSumShare), whose largest is
// additive + (1 - s) x slowest + s x sum; the additive weights alone for a profile without pipes.
// With thresholds, each of those once per subset of the thresholds, the subset's hinges added as
// their lines (ns per unit on the term, less ns x at on the fixed `vertices`): the largest is the
// sum of the hinges above zero.
std::vector<TermWeights> profileComponents(const DeviceProfile& profile);
// Prices the problem's actions, inputs and fixed terms under the profile (priceProblem, or
// priceProblemByMax for a roofline).
void applyDeviceProfile(Problem& p, const DeviceProfile& profile);
// A portable choice (docs/device-profiles.md, "Portable plans"): prices the problem so a plan
// costs its worst regret over the devices, max over d of (its predicted time on d) / best[d],
// in parts per kRegretScale; `best` is each device's optimum in its own femtoseconds.
constexpr int64_t kRegretScale = 1'000'000'000;
void applyPortableProfiles(Problem& p, const std::vector<DeviceProfile>& profiles, const std::vector<int64_t>& best);

// What a plan pays, term by term: its rules' terms, each input it reads once, and the
// fixed terms. Plain data for explain, generate's report and bench's "predicted" column.
struct PlanCostPrediction {
  TermAmounts amounts{};
  std::array<double, kTermCount> nanoseconds{};  // rounded additive weight x amount, per term
  std::vector<double> pipeNanoseconds;           // per pipe of a roofline profile
  int slowestPipe = -1;                          // the pipe that bounds the program (-1: none)
  std::vector<double> thresholdNanoseconds;      // per threshold: what its hinge adds (0 at or below it)
  // What the other pipes add beside the slowest: pipeSumShare x their sum (0 in a pure roofline).
  double otherPipesNanoseconds = 0;
  double totalNanoseconds = 0;                   // equals plan cost / kFemtosecondsPerNanosecond
};
TermAmounts planTermAmounts(const Plan& plan, const Problem& p);
PlanCostPrediction predictPlanCost(const Plan& plan, const Problem& p, const DeviceProfile& profile);
// The prediction as a table: term, amount, ns per unit, ns; then the total per vertex.
std::string describePlanCost(const Plan& plan, const Problem& p, const DeviceProfile& profile);
// A portable plan's regret per device: its predicted time, the device's best (`best`, fs per
// vertex, from a search under that device alone) and their ratio; then the worst.
std::string describePortable(const Plan& plan, const Problem& p, const std::vector<DeviceProfile>& devices,
                             const std::vector<int64_t>& best);

}  // namespace sg

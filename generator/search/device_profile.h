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

#include "search/plan.h"
#include "search/problem.h"

namespace sg {

struct DeviceProfile {
  std::string device;  // "NVIDIA H200 (Vulkan 580.159.04)"
  std::string file;    // where it was loaded from ("" = built in code)
  std::array<double, kTermCount> nanoseconds{};  // per unit of each term, per vertex
  std::array<double, kTermCount> drawNanoseconds{};  // per unit of each term, per draw
  double verticesPerDraw = 0;  // the workload priced for; required when a draw weight is set
  // ns per unit of `term` per vertex when a draw has `vertices`: nanoseconds + drawNanoseconds / vertices.
  double perVertex(int term, double vertices) const;
  bool hasDrawWeights() const;
  // Predicted ns per vertex of these amounts on a mesh drawn `vertices` at a time (unrounded
  // weights; the search's own figure is predictPlanCost's).
  double predictNanoseconds(const TermAmounts& amounts, double vertices) const;
};
// Largest workload a profile may state (vertices per draw), and largest draw weight (a
// millisecond per unit per draw).
constexpr double kMaxVerticesPerDraw = 1e9;
constexpr double kMaxProfileDrawWeightNs = 1e6;

// Search cost units of a profile: femtoseconds (1e-6 ns); a weight is rounded to one.
constexpr int64_t kFemtosecondsPerNanosecond = 1'000'000;
// Largest weight a profile may state (a microsecond per unit: far above any device).
constexpr double kMaxProfileWeightNs = 1000;

// Throws InputError (file:line:col) for unreadable files, bad YAML, unknown keys, weights
// that are not numbers, negative, not finite or above kMaxProfileWeightNs (draw weights:
// kMaxProfileDrawWeightNs), and draw weights without vertices_per_draw.
DeviceProfile loadDeviceProfile(const std::string& path);
DeviceProfile parseDeviceProfile(const std::string& text, const std::string& file);

// The profile's weights in femtoseconds per unit of each term, per vertex at its workload.
TermWeights profileWeights(const DeviceProfile& profile);
// Prices the problem's actions, inputs and fixed terms under the profile (priceProblem).
void applyDeviceProfile(Problem& p, const DeviceProfile& profile);

// What a plan pays, term by term: its rules' terms, each input it reads once, and the
// fixed terms. Plain data for explain, generate's report and bench's "predicted" column.
struct PlanCostPrediction {
  TermAmounts amounts{};
  std::array<double, kTermCount> nanoseconds{};  // rounded weight x amount, per term
  double totalNanoseconds = 0;                   // equals plan cost / kFemtosecondsPerNanosecond
};
TermAmounts planTermAmounts(const Plan& plan, const Problem& p);
PlanCostPrediction predictPlanCost(const Plan& plan, const Problem& p, const DeviceProfile& profile);
// The prediction as a table: term, amount, ns per unit, ns; then the total per vertex.
std::string describePlanCost(const Plan& plan, const Problem& p, const DeviceProfile& profile);

}  // namespace sg

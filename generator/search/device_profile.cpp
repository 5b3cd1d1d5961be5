#include "search/device_profile.h"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>

#include "common/input_file.h"
#include "common/yaml_util.h"

namespace sg {

DeviceProfile loadDeviceProfile(const std::string& path) { return parseDeviceProfile(readInputFile(path), path); }

namespace {

// A finite number in [min, max], else a located error naming `what` ("weight 'locations'");
// `unit` names the number ("nanoseconds"), `symbol` abbreviates it. Below a minimum of 0 is
// a negative cost, which would let the search buy time by reading more.
double parseNumber(const YamlCtx& c, const YAML::Node& n, const std::string& what, const char* unit, const char* symbol,
                   double min, double max) {
  const std::string s = c.scalar(n, what.c_str());
  errno = 0;
  char* end = nullptr;
  double v = std::strtod(s.c_str(), &end);
  if (s.empty() || end != s.c_str() + s.size() || errno == ERANGE || !std::isfinite(v))
    c.fail(n, fmt::format("{} must be a number of {}, not '{}'", what, unit, s));
  if (v < min)
    c.fail(n, min == 0 ? fmt::format("{} is negative ({}): a term cannot save time", what, s)
                       : fmt::format("{} is {}: it must be at least {:g}", what, s, min));
  if (v > max) c.fail(n, fmt::format("{} is {} {}, above the {:g} {} a profile may state", what, s, symbol, max, symbol));
  return v;
}

// weights: or draw_weights: (term -> ns per unit).
// `what` names one weight in messages ("weight", "draw weight").
void parseTermWeights(const YamlCtx& c, const YAML::Node& w, const char* section, const char* what, double max,
                      std::array<double, kTermCount>& out) {
  c.expectMap(w, section);
  for (auto it = w.begin(); it != w.end(); ++it) {
    const std::string key = c.scalar(it->first, "weight name");
    int term = -1;
    for (int t = 0; t < kTermCount; ++t)
      if (key == termName(t)) term = t;
    if (term < 0) {
      std::string known;
      for (int t = 0; t < kTermCount; ++t) known += fmt::format("{}{}", t ? ", " : "", termName(t));
      c.fail(it->first, fmt::format("unknown cost term '{}' (known: {})", key, known));
    }
    out[static_cast<size_t>(term)] =
        parseNumber(c, it->second, fmt::format("{} '{}'", what, key), "nanoseconds", "ns", 0, max);
  }
}

}  // namespace

double DeviceProfile::perVertex(int term, double vertices) const {
  const size_t t = static_cast<size_t>(term);
  return nanoseconds[t] + (drawNanoseconds[t] > 0 ? drawNanoseconds[t] / vertices : 0.0);
}

bool DeviceProfile::hasDrawWeights() const {
  return std::any_of(drawNanoseconds.begin(), drawNanoseconds.end(), [](double d) { return d > 0; });
}

double DeviceProfile::predictNanoseconds(const TermAmounts& amounts, double vertices) const {
  double ns = 0;
  for (int t = 0; t < kTermCount; ++t) ns += perVertex(t, vertices) * double(amounts[static_cast<size_t>(t)]);
  return ns;
}

DeviceProfile parseDeviceProfile(const std::string& text, const std::string& file) {
  YamlCtx c{file};
  YAML::Node root = parseYaml(text, file);
  c.expectMap(root, "device profile");
  c.checkKeys(root, {"device", "unit", "weights", "draw_weights", "vertices_per_draw", "notes"});
  DeviceProfile prof;
  prof.file = file;
  if (!root["device"]) c.fail(root, "device profile: missing 'device' (the device it was measured on)");
  prof.device = c.scalar(root["device"], "device");
  if (root["unit"] && c.scalar(root["unit"], "unit") != "ns")
    c.fail(root["unit"], fmt::format("unit '{}' is not supported: weights are nanoseconds per vertex ('ns')",
                                     c.scalar(root["unit"], "unit")));
  if (root["notes"]) c.scalar(root["notes"], "notes");
  if (!root["weights"]) c.fail(root, "device profile: missing 'weights' (nanoseconds per unit of each term)");
  parseTermWeights(c, root["weights"], "weights", "weight", kMaxProfileWeightNs, prof.nanoseconds);
  if (root["vertices_per_draw"])
    prof.verticesPerDraw = parseNumber(c, root["vertices_per_draw"], "'vertices_per_draw'", "vertices", "vertices", 1, kMaxVerticesPerDraw);
  if (root["draw_weights"]) {
    parseTermWeights(c, root["draw_weights"], "draw_weights", "draw weight", kMaxProfileDrawWeightNs, prof.drawNanoseconds);
    if (!root["vertices_per_draw"])
      c.fail(root["draw_weights"], "device profile: 'draw_weights' needs 'vertices_per_draw' (the workload they are spread over)");
  }
  return prof;
}

TermWeights profileWeights(const DeviceProfile& profile) {
  TermWeights w{};
  for (int t = 0; t < kTermCount; ++t)
    w[static_cast<size_t>(t)] = std::llround(profile.perVertex(t, profile.verticesPerDraw) * kFemtosecondsPerNanosecond);
  return w;
}

void applyDeviceProfile(Problem& p, const DeviceProfile& profile) { priceProblem(p, profileWeights(profile)); }

TermAmounts planTermAmounts(const Plan& plan, const Problem& p) { return planAmounts(p, plan.actions); }

PlanCostPrediction predictPlanCost(const Plan& plan, const Problem& p, const DeviceProfile& profile) {
  PlanCostPrediction out;
  out.amounts = planTermAmounts(plan, p);
  const TermWeights w = profileWeights(profile);
  for (size_t t = 0; t < kTermCount; ++t) {
    out.nanoseconds[t] = static_cast<double>(w[t]) * static_cast<double>(out.amounts[t]) / kFemtosecondsPerNanosecond;
    out.totalNanoseconds += out.nanoseconds[t];
  }
  return out;
}

std::string describePlanCost(const Plan& plan, const Problem& p, const DeviceProfile& profile) {
  const PlanCostPrediction c = predictPlanCost(plan, p, profile);
  const TermWeights w = profileWeights(profile);
  std::string out = fmt::format("  predicted per vertex on '{}'{}{}:\n", profile.device,
                                profile.file.empty() ? "" : fmt::format(" ({})", profile.file),
                                profile.hasDrawWeights() ? fmt::format(" at {:g} vertices per draw", profile.verticesPerDraw) : "");
  out += fmt::format("    {:<22} {:>8} {:>10} {:>9}\n", "term", "amount", "ns/unit", "ns");
  for (size_t t = 0; t < kTermCount; ++t)
    out += fmt::format("    {:<22} {:>8} {:>10.6f} {:>9.3f}\n", termName(static_cast<int>(t)), c.amounts[t],
                       static_cast<double>(w[t]) / kFemtosecondsPerNanosecond, c.nanoseconds[t]);
  out += fmt::format("    {:<22} {:>8} {:>10} {:>9.3f}\n", "total", "", "", c.totalNanoseconds);
  return out;
}

}  // namespace sg

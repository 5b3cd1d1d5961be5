#include "search/device_profile.h"

#include <fmt/format.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>

#include "common/input_file.h"
#include "common/yaml_util.h"

namespace sg {

DeviceProfile loadDeviceProfile(const std::string& path) { return parseDeviceProfile(readInputFile(path), path); }

DeviceProfile parseDeviceProfile(const std::string& text, const std::string& file) {
  YamlCtx c{file};
  YAML::Node root = parseYaml(text, file);
  c.expectMap(root, "device profile");
  c.checkKeys(root, {"device", "unit", "weights", "notes"});
  DeviceProfile prof;
  prof.file = file;
  if (!root["device"]) c.fail(root, "device profile: missing 'device' (the device it was measured on)");
  prof.device = c.scalar(root["device"], "device");
  if (root["unit"] && c.scalar(root["unit"], "unit") != "ns")
    c.fail(root["unit"], fmt::format("unit '{}' is not supported: weights are nanoseconds per vertex ('ns')",
                                     c.scalar(root["unit"], "unit")));
  if (root["notes"]) c.scalar(root["notes"], "notes");
  if (!root["weights"]) c.fail(root, "device profile: missing 'weights' (nanoseconds per unit of each term)");
  const YAML::Node w = root["weights"];
  c.expectMap(w, "weights");
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
    const std::string s = c.scalar(it->second, key.c_str());
    errno = 0;
    char* end = nullptr;
    double v = std::strtod(s.c_str(), &end);
    if (s.empty() || end != s.c_str() + s.size() || errno == ERANGE || !std::isfinite(v))
      c.fail(it->second, fmt::format("weight '{}' must be a number of nanoseconds, not '{}'", key, s));
    if (v < 0) c.fail(it->second, fmt::format("weight '{}' is negative ({}): a term cannot save time", key, s));
    if (v > kMaxProfileWeightNs)
      c.fail(it->second, fmt::format("weight '{}' is {} ns, above the {} ns a profile may state", key, s,
                                     kMaxProfileWeightNs));
    prof.nanoseconds[static_cast<size_t>(term)] = v;
  }
  return prof;
}

TermWeights profileWeights(const DeviceProfile& profile) {
  TermWeights w{};
  for (int t = 0; t < kTermCount; ++t)
    w[static_cast<size_t>(t)] = std::llround(profile.nanoseconds[static_cast<size_t>(t)] * kFemtosecondsPerNanosecond);
  return w;
}

void applyDeviceProfile(Problem& p, const DeviceProfile& profile) { priceProblem(p, profileWeights(profile)); }

TermAmounts planTermAmounts(const Plan& plan, const Problem& p) {
  TermAmounts a = p.fixedTerms;
  auto add = [&](const TermAmounts& x) {
    for (int t = 0; t < kTermCount; ++t) a[static_cast<size_t>(t)] += x[static_cast<size_t>(t)];
  };
  for (int act : plan.actions) add(p.actions[static_cast<size_t>(act)].terms);
  for (int r : itemsRead(p, plan.actions)) add(p.resources[static_cast<size_t>(r)].terms);
  return a;
}

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
  std::string out = fmt::format("  predicted per vertex on '{}'{}:\n", profile.device,
                                profile.file.empty() ? "" : fmt::format(" ({})", profile.file));
  out += fmt::format("    {:<22} {:>8} {:>10} {:>9}\n", "term", "amount", "ns/unit", "ns");
  for (size_t t = 0; t < kTermCount; ++t)
    out += fmt::format("    {:<22} {:>8} {:>10.6f} {:>9.3f}\n", termName(static_cast<int>(t)), c.amounts[t],
                       static_cast<double>(w[t]) / kFemtosecondsPerNanosecond, c.nanoseconds[t]);
  out += fmt::format("    {:<22} {:>8} {:>10} {:>9.3f}\n", "total", "", "", c.totalNanoseconds);
  return out;
}

}  // namespace sg

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
// `what` names one weight in messages ("weight", "draw weight"); `named` marks each term stated.
void parseTermWeights(const YamlCtx& c, const YAML::Node& w, const char* section, const char* what, double max,
                      std::array<double, kTermCount>& out, std::array<bool, kTermCount>& named) {
  c.expectMap(w, section);
  for (auto it = w.begin(); it != w.end(); ++it) {
    const std::string key = c.scalar(it->first, "weight name");
    const int term = termByName(key);
    if (term < 0) {
      std::string known;
      for (int t = 0; t < kTermCount; ++t) known += fmt::format("{}{}", t ? ", " : "", termName(t));
      c.fail(it->first, fmt::format("unknown cost term '{}' (known: {})", key, known));
    }
    out[static_cast<size_t>(term)] =
        parseNumber(c, it->second, fmt::format("{} '{}'", what, key), "nanoseconds", "ns", 0, max);
    named[static_cast<size_t>(term)] = true;
  }
}

}  // namespace

const char* featureName(int feature) {
  static const char* const names[] = {"none", "joints_per_warp", "invocations_per_vertex", "active_morph_targets",
                                      "joints_per_warp_squared", "fragments_per_vertex",
                                      "palette_entries_per_warp"};
  return feature >= 0 && feature < kFeatureCount ? names[feature] : "?";
}

namespace {

// A feature's value as measured: the workload's, else the profile's stated default, else 1.
double stated(const DeviceProfile& p, int f) {
  const Workload& w = p.workload;
  double v = -1;
  switch (f) {
    case kFeatureJointsPerWarp: v = w.jointsPerWarp > 0 ? w.jointsPerWarp : -1; break;
    case kFeatureInvocationsPerVertex: v = w.invocationsPerVertex > 0 ? w.invocationsPerVertex : -1; break;
    case kFeatureActiveMorphTargets: v = w.activeMorphTargets; break;
    case kFeatureFragmentsPerVertex: v = w.fragmentsPerVertex > 0 ? w.fragmentsPerVertex : -1; break;
    case kFeaturePaletteEntriesPerWarp: v = w.paletteEntriesPerWarp > 0 ? w.paletteEntriesPerWarp : -1; break;
    default: break;
  }
  if (v >= 0) return v;
  const double d = p.workloadDefaults[static_cast<size_t>(f)];
  return d > 0 ? d : 1.0;
}

}  // namespace

double DeviceProfile::feature(int f) const {
  switch (f) {
    case kFeatureNone: return 1;
    // A warp's reads of distinct addresses, each priced as a miss past the cache's capacity.
    case kFeatureJointsPerWarp: return stated(*this, f) * constantCacheFactor();
    case kFeatureJointsPerWarpSquared: {
      const double j = stated(*this, kFeatureJointsPerWarp);
      return j * j;
    }
    default: return stated(*this, f);
  }
}

double DeviceProfile::constantCacheFactor() const {
  if (constantCacheEntries <= 0) return 1.0;
  return feature(kFeaturePaletteEntriesPerWarp) > constantCacheEntries ? constantCacheMissFactor : 1.0;
}

DrawSizeBlend blendDrawSizes(const std::vector<double>& sizes, double vertices) {
  DrawSizeBlend b;
  if (sizes.empty()) return b;
  while (b.below + 1 < sizes.size() && sizes[b.below + 1] <= vertices) ++b.below;
  b.above = std::min(b.below + 1, sizes.size() - 1);
  // A draw's cost changes over orders of magnitude of its size, so the share grows with log(vertices).
  if (b.above != b.below && vertices > sizes[b.below])
    b.share = std::log(vertices / sizes[b.below]) / std::log(sizes[b.above] / sizes[b.below]);
  return b;
}

DeviceProfile DeviceProfile::atDrawSize(double vertices) const {
  DeviceProfile p = *this;
  if (drawSizes.empty()) return p;
  if (vertices > 0) p.verticesPerDraw = vertices;
  vertices = p.verticesPerDraw;
  std::vector<double> sizes;
  for (const DrawSize& d : drawSizes) sizes.push_back(d.vertices);
  const DrawSizeBlend blend = blendDrawSizes(sizes, vertices);
  const DrawSize& a = drawSizes[blend.below];
  const DrawSize& b = drawSizes[blend.above];
  const double t = blend.share;
  for (size_t k = 0; k < kTermCount; ++k) p.nanoseconds[k] = (1 - t) * a.nanoseconds[k] + t * b.nanoseconds[k];
  p.pipes = a.pipes;
  for (size_t j = 0; j < p.pipes.size(); ++j)
    for (size_t k = 0; k < kTermCount; ++k) p.pipes[j].nanoseconds[k] = (1 - t) * a.pipes[j].nanoseconds[k] + t * b.pipes[j].nanoseconds[k];
  return p;
}

namespace {

// What pricing reads (`nanoseconds`, `pipes`): with draw sizes, the weights at a draw of
// `vertices` (0: the profile's own), resolved into `scratch`.
const DeviceProfile& pricedAt(const DeviceProfile& p, double vertices, DeviceProfile& scratch) {
  if (p.drawSizes.empty()) return p;
  scratch = p.atDrawSize(vertices);
  scratch.drawSizes.clear();
  return scratch;
}

}  // namespace

double DeviceProfile::perVertex(int term, double vertices) const {
  if (!drawSizes.empty()) {
    DeviceProfile scratch;
    return pricedAt(*this, vertices, scratch).perVertex(term, vertices);
  }
  const size_t t = static_cast<size_t>(term);
  return (nanoseconds[t] + (drawNanoseconds[t] > 0 ? drawNanoseconds[t] / vertices : 0.0)) * feature(scaledBy[t]);
}

bool DeviceProfile::hasDrawWeights() const {
  return std::any_of(drawNanoseconds.begin(), drawNanoseconds.end(), [](double d) { return d > 0; });
}

double DeviceProfile::predictNanoseconds(const TermAmounts& amounts, double vertices) const {
  if (!drawSizes.empty()) {
    DeviceProfile scratch;
    return pricedAt(*this, vertices, scratch).predictNanoseconds(amounts, vertices);
  }
  double ns = 0, slowest = 0, sum = 0;
  for (int t = 0; t < kTermCount; ++t) ns += perVertex(t, vertices) * double(amounts[static_cast<size_t>(t)]);
  for (const Pipe& pipe : pipes) {
    double x = 0;
    for (size_t t = 0; t < kTermCount; ++t) x += pipe.nanoseconds[t] * feature(scaledBy[t]) * double(amounts[t]);
    slowest = std::max(slowest, x);
    sum += x;
  }
  for (const Threshold& h : thresholds)
    ns += h.nanoseconds * std::max(0.0, feature(scaledBy[static_cast<size_t>(h.term)]) * double(amounts[static_cast<size_t>(h.term)]) - h.at);
  return ns + (1 - pipeSumShare) * slowest + pipeSumShare * sum;
}

DeviceProfile parseDeviceProfile(const std::string& text, const std::string& file) {
  YamlCtx c{file};
  YAML::Node root = parseYaml(text, file);
  c.expectMap(root, "device profile");
  c.checkKeys(root, {"device", "unit", "weights", "draw_weights", "vertices_per_draw", "pipes", "pipe_sum_share", "scaled_by",
                     "workload_defaults", "constant_cache", "thresholds", "draw_sizes", "notes"});
  DeviceProfile prof;
  prof.file = file;
  std::array<bool, kTermCount> named{};  // the terms the profile states anywhere
  if (!root["device"]) c.fail(root, "device profile: missing 'device' (the device it was measured on)");
  prof.device = c.scalar(root["device"], "device");
  if (root["unit"] && c.scalar(root["unit"], "unit") != "ns")
    c.fail(root["unit"], fmt::format("unit '{}' is not supported: weights are nanoseconds per vertex ('ns')",
                                     c.scalar(root["unit"], "unit")));
  if (root["notes"]) c.scalar(root["notes"], "notes");
  // weights: and pipes: of the profile, or of one of its draw sizes.
  auto parseWeightsAndPipes = [&](const YAML::Node& weights, const YAML::Node& pipes, std::array<double, kTermCount>& ns,
                                  std::vector<DeviceProfile::Pipe>& out) {
    parseTermWeights(c, weights, "weights", "weight", kMaxProfileWeightNs, ns, named);
    if (!pipes) return;
    c.expectMap(pipes, "pipes");
    for (auto it = pipes.begin(); it != pipes.end(); ++it) {
      DeviceProfile::Pipe pipe;
      pipe.name = c.scalar(it->first, "pipe name");
      parseTermWeights(c, it->second, "pipe", fmt::format("pipe '{}' weight", pipe.name).c_str(), kMaxProfileWeightNs,
                       pipe.nanoseconds, named);
      out.push_back(std::move(pipe));
    }
    if (out.size() > kMaxProfilePipes)
      c.fail(pipes, fmt::format("device profile: {} pipes, more than the {} a profile may have", out.size(), kMaxProfilePipes));
  };
  const YAML::Node sizes = root["draw_sizes"];
  if (sizes) {
    for (const char* key : {"weights", "pipes", "draw_weights"})
      if (root[key])
        c.fail(root[key], fmt::format("device profile: '{}' beside 'draw_sizes': a profile with draw sizes states its "
                                      "weights and pipes under each size",
                                      key));
    if (!root["vertices_per_draw"])
      c.fail(sizes, "device profile: 'draw_sizes' needs 'vertices_per_draw' (the draw priced where a generation's mesh is unknown)");
  } else if (!root["weights"]) {
    c.fail(root, "device profile: missing 'weights' (nanoseconds per unit of each term)");
  } else {
    parseWeightsAndPipes(root["weights"], root["pipes"], prof.nanoseconds, prof.pipes);
  }
  if (root["vertices_per_draw"])
    prof.verticesPerDraw = parseNumber(c, root["vertices_per_draw"], "'vertices_per_draw'", "vertices", "vertices", 1, kMaxVerticesPerDraw);
  if (root["draw_weights"]) {
    parseTermWeights(c, root["draw_weights"], "draw_weights", "draw weight", kMaxProfileDrawWeightNs, prof.drawNanoseconds, named);
    if (!root["vertices_per_draw"])
      c.fail(root["draw_weights"], "device profile: 'draw_weights' needs 'vertices_per_draw' (the workload they are spread over)");
  }
  if (sizes) {
    c.expectMap(sizes, "draw_sizes");
    for (auto it = sizes.begin(); it != sizes.end(); ++it) {
      DeviceProfile::DrawSize d;
      d.vertices = parseNumber(c, it->first, "a draw size", "vertices per draw", "vertices", 1, kMaxVerticesPerDraw);
      c.expectMap(it->second, "draw size");
      c.checkKeys(it->second, {"weights", "pipes"});
      if (!it->second["weights"])
        c.fail(it->second, fmt::format("draw size {:g}: missing 'weights' (nanoseconds per unit of each term at that size)", d.vertices));
      parseWeightsAndPipes(it->second["weights"], it->second["pipes"], d.nanoseconds, d.pipes);
      for (const DeviceProfile::DrawSize& e : prof.drawSizes)
        if (e.vertices == d.vertices) c.fail(it->first, fmt::format("draw size {:g} is stated twice", d.vertices));
      // Sizes are interpolated pipe by pipe: every size names the same pipes in the same order.
      if (!prof.drawSizes.empty()) {
        std::string want, got;
        for (const auto& q : prof.drawSizes.front().pipes) want += " " + q.name;
        for (const auto& q : d.pipes) got += " " + q.name;
        if (want != got)
          c.fail(it->first, fmt::format("draw size {:g} has the pipes [{} ] where the first size has [{} ]: every size "
                                        "names the same pipes in the same order",
                                        d.vertices, got, want));
      }
      prof.drawSizes.push_back(std::move(d));
    }
    if (prof.drawSizes.size() < 2)
      c.fail(sizes, "draw_sizes: one size is no interpolation; state its weights and pipes as 'weights' and 'pipes'");
    std::sort(prof.drawSizes.begin(), prof.drawSizes.end(),
              [](const DeviceProfile::DrawSize& a, const DeviceProfile::DrawSize& b) { return a.vertices < b.vertices; });
  }
  auto featureOf = [&](const YAML::Node& n) {
    const std::string name = c.scalar(n, "workload feature");
    for (int f = 1; f < kFeatureCount; ++f)
      if (name == featureName(f)) return f;
    std::string known;
    for (int f = 1; f < kFeatureCount; ++f) known += fmt::format("{}{}", f > 1 ? ", " : "", featureName(f));
    c.fail(n, fmt::format("unknown workload feature '{}' (known: {})", name, known));
    return 0;
  };
  if (const YAML::Node scaled = root["scaled_by"]) {
    c.expectMap(scaled, "scaled_by");
    for (auto it = scaled.begin(); it != scaled.end(); ++it) {
      const std::string key = c.scalar(it->first, "term name");
      const int term = termByName(key);
      if (term < 0) c.fail(it->first, fmt::format("scaled_by: unknown cost term '{}'", key));
      prof.scaledBy[static_cast<size_t>(term)] = featureOf(it->second);
      named[static_cast<size_t>(term)] = true;
    }
  }
  if (const YAML::Node defaults = root["workload_defaults"]) {
    c.expectMap(defaults, "workload_defaults");
    for (auto it = defaults.begin(); it != defaults.end(); ++it) {
      const int f = featureOf(it->first);
      prof.workloadDefaults[static_cast<size_t>(f)] =
          parseNumber(c, it->second, fmt::format("workload default '{}'", featureName(f)), "units", "", 0, kMaxWorkloadFeature);
    }
  }
  if (const YAML::Node share = root["pipe_sum_share"]) {
    prof.pipeSumShare = parseNumber(c, share, "'pipe_sum_share'", "share of the other pipes", "", 0, HUGE_VAL);
    if (prof.pipeSumShare > 1)
      c.fail(share, fmt::format("'pipe_sum_share' is {}: a share of the other pipes lies between 0 (a pure roofline) and 1 "
                                "(every pipe added)",
                                c.scalar(share, "pipe_sum_share")));
    if (prof.pipes.empty() && (prof.drawSizes.empty() || prof.drawSizes.front().pipes.empty()))
      c.fail(share, "device profile: 'pipe_sum_share' without 'pipes': the share is of the pipes a program does not wait for");
  }
  if (const YAML::Node cache = root["constant_cache"]) {
    c.expectMap(cache, "constant_cache");
    c.checkKeys(cache, {"entries", "miss_factor"});
    if (!cache["entries"] || !cache["miss_factor"])
      c.fail(cache, "constant_cache: needs 'entries' (the palette entries a warp's footprint may reach) and 'miss_factor' "
                    "(what a distinct address costs past them, times its price within)");
    prof.constantCacheEntries =
        parseNumber(c, cache["entries"], "constant_cache 'entries'", "palette entries", "entries", 1, kMaxWorkloadFeature);
    prof.constantCacheMissFactor = parseNumber(c, cache["miss_factor"], "constant_cache 'miss_factor'", "times", "x", 1, 1000);
    bool priced = false;
    for (int t = 0; t < kTermCount; ++t) priced |= prof.scaledBy[static_cast<size_t>(t)] == kFeatureJointsPerWarp;
    if (!priced)
      c.fail(cache, "constant_cache: no term is scaled_by joints_per_warp, so the cache's misses would price nothing");
  }
  if (const YAML::Node thresholds = root["thresholds"]) {
    c.expectMap(thresholds, "thresholds");
    for (auto it = thresholds.begin(); it != thresholds.end(); ++it) {
      const std::string key = c.scalar(it->first, "term name");
      const int term = termByName(key);
      if (term < 0) c.fail(it->first, fmt::format("thresholds: unknown cost term '{}'", key));
      if (term == kTermVertices)
        c.fail(it->first, "thresholds: 'vertices' is 1 in every program, so a threshold on it would be a constant");
      const YAML::Node h = it->second;  // a copy: the iterator's pair is a temporary
      c.expectMap(h, fmt::format("threshold '{}'", key).c_str());
      c.checkKeys(h, {"at", "ns"});
      if (!h["at"] || !h["ns"])
        c.fail(h, fmt::format("threshold '{}': needs 'at' (the units priced as the weights say) and 'ns' (what each unit "
                              "past them costs more)",
                              key));
      if (prof.thresholds.size() == kMaxProfileThresholds)
        c.fail(it->first, fmt::format("thresholds: '{}' is one more than the {} a profile may state (each doubles what the "
                                      "search weighs)",
                                      key, kMaxProfileThresholds));
      DeviceProfile::Threshold th;
      th.term = term;
      th.at = parseNumber(c, h["at"], fmt::format("threshold '{}' 'at'", key), "units", "", -HUGE_VAL, kMaxWorkloadFeature);
      if (th.at < 0) c.fail(h["at"], fmt::format("threshold '{}' 'at' is {:g}: it counts units of the term, 0 or more", key, th.at));
      th.nanoseconds = parseNumber(c, h["ns"], fmt::format("threshold '{}' 'ns'", key), "nanoseconds", "ns", 0, kMaxProfileWeightNs);
      prof.thresholds.push_back(th);
      named[static_cast<size_t>(term)] = true;
    }
    std::sort(prof.thresholds.begin(), prof.thresholds.end(),
              [](const DeviceProfile::Threshold& a, const DeviceProfile::Threshold& b) { return a.term < b.term; });
  }
  // A profile written before table reads were counted apart (it names neither table term) priced
  // them as buffer loads: so it still does.
  if (!named[kTermBufferTableLoads] && !named[kTermBufferTableVec4Loads]) priceTableReadsAsBufferLoads(prof);
  return prof.atDrawSize(prof.verticesPerDraw);
}

void priceTableReadsAsBufferLoads(DeviceProfile& prof) {
  auto asBufferLoads = [](auto& ns) {
    ns[kTermBufferTableLoads] = ns[kTermBufferLoads];
    ns[kTermBufferTableVec4Loads] = ns[kTermBufferVec4Loads];
  };
  asBufferLoads(prof.nanoseconds);
  asBufferLoads(prof.drawNanoseconds);
  asBufferLoads(prof.scaledBy);
  for (auto& pipe : prof.pipes) asBufferLoads(pipe.nanoseconds);
  for (auto& d : prof.drawSizes) {
    asBufferLoads(d.nanoseconds);
    for (auto& pipe : d.pipes) asBufferLoads(pipe.nanoseconds);
  }
}

TermWeights profileWeights(const DeviceProfile& priced) {
  DeviceProfile scratch;
  const DeviceProfile& profile = pricedAt(priced, priced.verticesPerDraw, scratch);
  TermWeights w{};
  for (int t = 0; t < kTermCount; ++t)
    w[static_cast<size_t>(t)] = std::llround(profile.perVertex(t, profile.verticesPerDraw) * kFemtosecondsPerNanosecond);
  return w;
}

namespace {

// A threshold's line in femtoseconds: its price per unit on the term, less price x at on the fixed
// `vertices` (1 in every program), so that above zero it is the hinge max(0, amount - at) x ns.
TermWeights thresholdLine(const DeviceProfile& profile, const DeviceProfile::Threshold& h) {
  TermWeights w{};
  w[static_cast<size_t>(h.term)] = std::llround(h.nanoseconds * profile.feature(profile.scaledBy[static_cast<size_t>(h.term)]) *
                                                kFemtosecondsPerNanosecond);
  w[kTermVertices] = -std::llround(h.nanoseconds * h.at * kFemtosecondsPerNanosecond);
  return w;
}

// The components without the thresholds: one per pipe (the additive weights alone without pipes).
std::vector<TermWeights> pipeComponents(const DeviceProfile& profile) {
  const TermWeights additive = profileWeights(profile);
  if (profile.pipes.empty()) return {additive};
  // max_k [(1 - s) P_k + s sum_j P_j] = (1 - s) max_k P_k + s sum_j P_j: the blend is a max of sums too.
  const double s = profile.pipeSumShare;
  std::array<double, kTermCount> sum{};
  for (const DeviceProfile::Pipe& pipe : profile.pipes)
    for (size_t t = 0; t < kTermCount; ++t) sum[t] += pipe.nanoseconds[t];
  std::vector<TermWeights> out;
  for (const DeviceProfile::Pipe& pipe : profile.pipes) {
    TermWeights w = additive;
    for (size_t t = 0; t < kTermCount; ++t)
      w[t] += std::llround(((1 - s) * pipe.nanoseconds[t] + s * sum[t]) * profile.feature(profile.scaledBy[t]) *
                           kFemtosecondsPerNanosecond);
    out.push_back(w);
  }
  return out;
}

}  // namespace

std::vector<TermWeights> profileComponents(const DeviceProfile& priced) {
  DeviceProfile scratch;
  const DeviceProfile& profile = pricedAt(priced, priced.verticesPerDraw, scratch);
  const std::vector<TermWeights> pipes = pipeComponents(profile);
  // sum over h of max(0, line_h) = max over subsets S of sum over h in S of line_h: each pipe's
  // component once per subset.
  std::vector<TermWeights> out;
  for (size_t subset = 0; subset < (size_t{1} << profile.thresholds.size()); ++subset)
    for (TermWeights w : pipes) {
      for (size_t h = 0; h < profile.thresholds.size(); ++h)
        if (subset & (size_t{1} << h)) {
          const TermWeights line = thresholdLine(profile, profile.thresholds[h]);
          for (size_t t = 0; t < kTermCount; ++t) w[t] += line[t];
        }
      out.push_back(w);
    }
  return out;
}

void applyDeviceProfile(Problem& p, const DeviceProfile& profile) { priceProblemByMax(p, profileComponents(profile)); }

void applyPortableProfiles(Problem& p, const std::vector<DeviceProfile>& profiles, const std::vector<int64_t>& best) {
  std::vector<TermWeights> all;
  for (size_t d = 0; d < profiles.size(); ++d) {
    // fs on device d over its best fs, in parts per kRegretScale: weights scale by S / best.
    const double scale = static_cast<double>(kRegretScale) / static_cast<double>(std::max<int64_t>(1, best[d]));
    for (const TermWeights& w : profileComponents(profiles[d])) {
      TermWeights r{};
      for (size_t t = 0; t < kTermCount; ++t) r[t] = std::llround(static_cast<double>(w[t]) * scale);
      all.push_back(r);
    }
  }
  priceProblemByMax(p, all);
}

TermAmounts planTermAmounts(const Plan& plan, const Problem& p) { return planAmounts(p, plan.actions); }

PlanCostPrediction predictPlanCost(const Plan& plan, const Problem& p, const DeviceProfile& priced) {
  DeviceProfile scratch;
  const DeviceProfile& profile = pricedAt(priced, priced.verticesPerDraw, scratch);
  PlanCostPrediction out;
  out.amounts = planTermAmounts(plan, p);
  const TermWeights w = profileWeights(profile);
  for (size_t t = 0; t < kTermCount; ++t) {
    out.nanoseconds[t] = static_cast<double>(w[t]) * static_cast<double>(out.amounts[t]) / kFemtosecondsPerNanosecond;
    out.totalNanoseconds += out.nanoseconds[t];
  }
  // Each hinge as the search weighs it (exact in femtoseconds), so the total is the plan's cost.
  for (const DeviceProfile::Threshold& h : profile.thresholds) {
    const double ns = static_cast<double>(std::max<int64_t>(0, weighTerms(thresholdLine(profile, h), out.amounts))) /
                      kFemtosecondsPerNanosecond;
    out.thresholdNanoseconds.push_back(ns);
    out.totalNanoseconds += ns;
  }
  if (profile.pipes.empty()) return out;
  // Each pipe's time: its component less the additive part (exact in femtoseconds), priced
  // with no share of the others; the total adds the largest component as the search prices it.
  DeviceProfile pure = profile;
  pure.pipeSumShare = 0;
  const std::vector<TermWeights> pipesAlone = pipeComponents(pure), comps = pipeComponents(profile);
  const int64_t additive = weighTerms(w, out.amounts);
  double slowest = 0;
  int64_t largest = 0;
  for (size_t k = 0; k < comps.size(); ++k) {
    const double ns = static_cast<double>(weighTerms(pipesAlone[k], out.amounts) - additive) / kFemtosecondsPerNanosecond;
    out.pipeNanoseconds.push_back(ns);
    if (out.slowestPipe < 0 || ns > slowest) {
      slowest = ns;
      out.slowestPipe = static_cast<int>(k);
    }
    largest = std::max(largest, weighTerms(comps[k], out.amounts) - additive);
  }
  const double pipesNs = static_cast<double>(largest) / kFemtosecondsPerNanosecond;
  out.otherPipesNanoseconds = profile.pipeSumShare > 0 ? pipesNs - slowest : 0;
  out.totalNanoseconds += pipesNs;
  return out;
}

std::string describePortable(const Plan& plan, const Problem& p, const std::vector<DeviceProfile>& devices,
                             const std::vector<int64_t>& best) {
  std::string out = "  portable plan: predicted per vertex on each device against its own best plan\n";
  double worst = 0;
  for (size_t d = 0; d < devices.size() && d < best.size(); ++d) {
    const double ns = predictPlanCost(plan, p, devices[d]).totalNanoseconds;
    const double bestNs = static_cast<double>(best[d]) / kFemtosecondsPerNanosecond;
    const double regret = bestNs > 0 ? ns / bestNs : 1.0;
    worst = std::max(worst, regret);
    out += fmt::format("    {:<40} {:>9.3f} ns  best {:>9.3f} ns  {:.3f}x\n", devices[d].device, ns, bestNs, regret);
  }
  out += fmt::format("    worst regret {:.3f}x\n", worst);
  return out;
}

std::string describePlanCost(const Plan& plan, const Problem& p, const DeviceProfile& priced) {
  DeviceProfile scratch;
  const DeviceProfile& profile = pricedAt(priced, priced.verticesPerDraw, scratch);
  const PlanCostPrediction c = predictPlanCost(plan, p, profile);
  const TermWeights w = profileWeights(profile);
  std::string sizes;
  for (const DeviceProfile::DrawSize& d : priced.drawSizes) sizes += fmt::format("{}{:g}", sizes.empty() ? "" : ", ", d.vertices);
  std::string out = fmt::format("  predicted per vertex on '{}'{}{}{}:\n", profile.device,
                                profile.file.empty() ? "" : fmt::format(" ({})", profile.file),
                                profile.hasDrawWeights() || !sizes.empty() ? fmt::format(" at {:g} vertices per draw", profile.verticesPerDraw) : "",
                                sizes.empty() ? "" : fmt::format(" (weights fitted at {} vertices per draw)", sizes));
  out += fmt::format("    {:<26} {:>8} {:>10} {:>9}\n", "term", "amount", "ns/unit", "ns");
  for (size_t t = 0; t < kTermCount; ++t) {
    out += fmt::format("    {:<26} {:>8} {:>10.6f} {:>9.3f}", termName(static_cast<int>(t)), c.amounts[t],
                       static_cast<double>(w[t]) / kFemtosecondsPerNanosecond, c.nanoseconds[t]);
    // A roofline's term is priced in its pipes: what it adds to each (summed in the pipe's line).
    for (const DeviceProfile::Pipe& pipe : profile.pipes)
      if (pipe.nanoseconds[t] > 0) {
        const double perUnit = pipe.nanoseconds[t] * profile.feature(profile.scaledBy[t]);
        out += fmt::format("  + {:.6f} x {} = {:.3f} in {}", perUnit, c.amounts[t], perUnit * double(c.amounts[t]), pipe.name);
      }
    out += "\n";
  }
  for (size_t k = 0; k < c.pipeNanoseconds.size(); ++k)
    out += fmt::format("    {:<26} {:>8} {:>10} {:>9.3f}{}\n", "pipe " + profile.pipes[k].name, "", "", c.pipeNanoseconds[k],
                       static_cast<int>(k) == c.slowestPipe ? "  (slowest: counted)" : "");
  if (profile.pipeSumShare > 0)
    out += fmt::format("    {:<26} {:>8} {:>10} {:>9.3f}\n", fmt::format("other pipes x {:g}", profile.pipeSumShare), "", "",
                       c.otherPipesNanoseconds);
  for (size_t h = 0; h < profile.thresholds.size(); ++h) {
    const DeviceProfile::Threshold& th = profile.thresholds[h];
    out += fmt::format("    {:<26} {:>8} {:>10.6f} {:>9.3f}\n", fmt::format("{} past {:g}", termName(th.term), th.at),
                       fmt::format("{:g}", std::max(0.0, profile.feature(profile.scaledBy[static_cast<size_t>(th.term)]) *
                                                              double(c.amounts[static_cast<size_t>(th.term)]) - th.at)),
                       th.nanoseconds, c.thresholdNanoseconds[h]);
  }
  if (profile.workload.known()) out += fmt::format("    workload: {}\n", describeWorkload(profile.workload));
  if (profile.constantCacheEntries > 0) {
    out += fmt::format("    constant cache: {:.1f} palette entries per warp{} against its {:g}: {}\n",
                       profile.feature(kFeaturePaletteEntriesPerWarp),
                       profile.workload.paletteEntriesPerWarp > 0 ? "" : " (the profile's default)", profile.constantCacheEntries,
                       profile.constantCacheFactor() > 1 ? fmt::format("past it, each address priced {:.3g}x", profile.constantCacheMissFactor)
                                                         : "within it");
  }
  out += fmt::format("    {:<26} {:>8} {:>10} {:>9.3f}\n", "total", "", "", c.totalNanoseconds);
  return out;
}

}  // namespace sg

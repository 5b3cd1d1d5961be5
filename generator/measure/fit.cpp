#include "measure/fit.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <stdexcept>

namespace sg {

const char* profileFormName(ProfileForm form) {
  return form == ProfileForm::Roofline ? "roofline" : form == ProfileForm::Raster ? "raster" : "additive";
}

DeviceProfile profileForm(ProfileForm form) {
  DeviceProfile p;
  // A uniform load at a per-vertex index is served once per distinct address a warp reads
  // (the constant cache serialises them), so its weight is per address: loads x joints per warp.
  p.scaledBy[kTermIndexedUniformLoads] = kFeatureJointsPerWarp;
  // Counted in vec4s too: the H200's palette probes cost about 0.04 ns per vec4 per joint a
  // warp reads, at 2.6 and at 12.2 joints per warp alike (docs/device-profiles.md).
  p.scaledBy[kTermIndexedUniformVec4Loads] = kFeatureJointsPerWarp;
  p.workloadDefaults[kFeatureJointsPerWarp] = 1;
  // The fragment shader's and rasterizer's work comes with each fragment a draw covers.
  if (form == ProfileForm::Raster) p.scaledBy[kTermFragments] = kFeatureFragmentsPerVertex;
  if (form != ProfileForm::Additive) {
    auto pipe = [&](const char* name, std::initializer_list<int> terms) {
      DeviceProfile::Pipe x;
      x.name = name;
      for (int t : terms) x.nanoseconds[static_cast<size_t>(t)] = 1;  // marks membership until fitted
      p.pipes.push_back(x);
    };
    pipe("fetch", {kTermLocations, kTermAttributeBytes});
    pipe("memory", {kTermBufferLoads, kTermBufferVec4Loads, kTermBufferBytes, kTermBufferTableLoads, kTermBufferTableVec4Loads});
    // Uniform loads at a per-vertex index go through the constant cache, a unit of its own:
    // in one pipe with storage-buffer loads, a palette's cost hid under the fetch it adds to,
    // and the 300-bone palette was chosen at 1.56x the fastest (docs/device-profiles.md).
    pipe("constant", {kTermIndexedUniformLoads, kTermIndexedUniformVec4Loads});
    pipe("alu", {kTermArithmetic});
    pipe("output", {kTermOutputs});
  }
  return p;
}

std::vector<int> outsidePipesOf(ProfileForm form) {
  if (form == ProfileForm::Raster) return {kTermLocations, kTermBufferLoads, kTermBufferVec4Loads};
  return {};
}

namespace {

// The parameters: a block of per-vertex additive weights (the additive form: every term but
// `fragments`; the roofline: `vertices` alone; the raster form: `vertices` and `fragments`),
// per-draw weights (every term, when draws differ; not in the raster form), then each pipe's
// terms; one such block per draw size (`sizes`, none: one block for every size).
struct Layout {
  std::vector<int> additive, perDraw;
  std::vector<std::pair<size_t, int>> pipeTerms;  // (pipe, term)
  size_t pipes = 0;
  std::vector<double> sizes;  // ascending vertices per draw, two at least, or none
  // With sizes: the parameters of a block every size shares, its first block's (a fragment's
  // price: a large draw covers too few fragments to price one of its own).
  std::vector<bool> shared;
  // After the blocks: the pipes' sum share (`share`), then the constant cache's miss factor
  // (`miss`) and the terms it multiplies, then one price per threshold (term, at), each row
  // paying it per unit of the term's scaled amount past `at`.
  bool share = false;
  bool miss = false;
  std::array<bool, kTermCount> missTerms{};
  std::vector<std::pair<int, double>> thresholds;
  size_t block() const { return additive.size() + perDraw.size() + pipeTerms.size(); }
  size_t blocks() const { return std::max<size_t>(1, sizes.size()); }
  size_t shareIndex() const { return block() * blocks(); }
  size_t missIndex() const { return shareIndex() + (share ? 1 : 0); }
  size_t thresholdIndex(size_t h) const { return missIndex() + (miss ? 1 : 0) + h; }
  size_t size() const { return thresholdIndex(thresholds.size()); }
};

// A row's units of a threshold's term past it (its amounts already scaled).
double pastThreshold(const std::array<double, kTermCount>& x, const std::pair<int, double>& threshold) {
  return std::max(0.0, x[static_cast<size_t>(threshold.first)] - threshold.second);
}

// `outside`: terms in the additive part besides their pipe (FitOptions::outsidePipes).
Layout layoutOf(const DeviceProfile& form, bool drawWeights, const std::vector<int>& outside) {
  Layout l;
  const bool raster = form.scaledBy[kTermFragments] == kFeatureFragmentsPerVertex;
  for (int t = 0; t < kTermCount; ++t)
    if (t == kTermFragments ? raster
                            : (form.pipes.empty() || t == kTermVertices || std::count(outside.begin(), outside.end(), t)))
      l.additive.push_back(t);
  // Outside the raster form a fragment is 1 per vertex, as `vertices` is: one per-draw weight for both.
  if (drawWeights && !raster)
    for (int t = 0; t < kTermCount; ++t)
      if (t != kTermFragments) l.perDraw.push_back(t);
  l.pipes = form.pipes.size();
  for (size_t p = 0; p < form.pipes.size(); ++p)
    for (int t = 0; t < kTermCount; ++t)
      if (form.pipes[p].nanoseconds[static_cast<size_t>(t)] > 0) l.pipeTerms.emplace_back(p, t);
  return l;
}

// A row's amounts as the model sees them: scaled by the form's workload features.
std::array<double, kTermCount> scaledAmounts(const DeviceProfile& form, const FitRow& row) {
  DeviceProfile at = form;
  at.workload = row.workload;
  std::array<double, kTermCount> x{};
  for (size_t t = 0; t < kTermCount; ++t) x[t] = double(row.amounts[t]) * at.feature(form.scaledBy[t]);
  return x;
}

// One row's weighted relative error and its (sub)gradient: the max picks the slowest pipe. With
// a constant cache (`missTerms` not empty, the last parameter the miss factor M), a row past
// the capacity pays M times its terms scaled by joints per warp. With draw sizes, the row's
// weights are its two sizes' blocks blended as the profile blends them.
class RowCost : public ceres::CostFunction {
 public:
  RowCost(const Layout& l, std::array<double, kTermCount> x, double vertices, double measured, double weight, bool past)
      : l_(l), x_(x), vertices_(vertices), measured_(measured), scale_(std::sqrt(weight) / measured), past_(past),
        blend_(blendDrawSizes(l.sizes, vertices)) {
    set_num_residuals(1);
    mutable_parameter_block_sizes()->push_back(static_cast<int32_t>(l.size()));
  }
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const size_t n = l_.block(), below = blend_.below * n, above = blend_.above * n;
    const double share = blend_.share;
    std::vector<double> w(n);
    for (size_t j = 0; j < n; ++j)
      w[j] = isShared(j) ? parameters[0][j] : (1 - share) * parameters[0][below + j] + share * parameters[0][above + j];
    std::vector<double> grad(n, 0.0);
    const bool miss = l_.miss && past_;
    const double m = miss ? parameters[0][l_.missIndex()] : 1.0;
    const double s = l_.share ? parameters[0][l_.shareIndex()] : 0.0;
    auto factor = [&](int t) { return miss && l_.missTerms[static_cast<size_t>(t)] ? m : 1.0; };
    double ns = 0, dm = 0;
    size_t i = 0;
    for (int t : l_.additive) {
      ns += w[i] * x_[t] * factor(t), grad[i] = x_[t] * factor(t);
      if (factor(t) != 1.0) dm += w[i] * x_[t];
      ++i;
    }
    for (int t : l_.perDraw) ns += w[i] * x_[t] / vertices_, grad[i] = x_[t] / vertices_, ++i;
    std::vector<double> pipe(l_.pipes, 0.0), pipeDm(l_.pipes, 0.0);
    const size_t pipeBegin = i;
    for (const auto& [p, t] : l_.pipeTerms) {
      pipe[p] += w[i] * x_[t] * factor(t);
      if (factor(t) != 1.0) pipeDm[p] += w[i] * x_[t];
      ++i;
    }
    double ds = 0;  // d ns / d share: the other pipes' sum
    if (l_.pipes) {
      const size_t slowest = static_cast<size_t>(std::max_element(pipe.begin(), pipe.end()) - pipe.begin());
      for (size_t p = 0; p < l_.pipes; ++p) {
        const double weight = p == slowest ? 1.0 : s;  // (1 - s) x slowest + s x every pipe
        ns += weight * pipe[p];
        dm += weight * pipeDm[p];
        if (p != slowest) ds += pipe[p];
      }
      i = pipeBegin;
      for (const auto& [p, t] : l_.pipeTerms) grad[i++] = (p == slowest ? 1.0 : s) * x_[t] * factor(t);
    }
    for (size_t h = 0; h < l_.thresholds.size(); ++h) ns += parameters[0][l_.thresholdIndex(h)] * pastThreshold(x_, l_.thresholds[h]);
    residuals[0] = scale_ * (ns - measured_);
    if (jacobians && jacobians[0]) {
      double* J = jacobians[0];
      std::fill(J, J + l_.size(), 0.0);
      for (size_t j = 0; j < n; ++j)
        if (isShared(j))
          J[j] += scale_ * grad[j];
        else
          J[below + j] += scale_ * (1 - share) * grad[j], J[above + j] += scale_ * share * grad[j];
      if (miss) J[l_.missIndex()] = scale_ * dm;
      if (l_.share) J[l_.shareIndex()] = scale_ * ds;
      for (size_t h = 0; h < l_.thresholds.size(); ++h) J[l_.thresholdIndex(h)] = scale_ * pastThreshold(x_, l_.thresholds[h]);
    }
    return true;
  }

 private:
  const Layout& l_;
  std::array<double, kTermCount> x_;
  double vertices_, measured_, scale_;
  bool past_;
  DrawSizeBlend blend_;
  bool isShared(size_t j) const { return j < l_.shared.size() && l_.shared[j]; }
};

DeviceProfile toProfile(const DeviceProfile& form, const Layout& l, const std::vector<double>& w, double vertices) {
  DeviceProfile p = form;
  for (auto& pipe : p.pipes) pipe.nanoseconds = {};
  for (size_t b = 0; b < l.blocks(); ++b) {
    std::vector<double> block(w.begin() + long(b * l.block()), w.begin() + long((b + 1) * l.block()));
    for (size_t j = 0; j < l.shared.size(); ++j)
      if (l.shared[j]) block[j] = w[j];
    size_t i = 0;
    for (int t : l.additive) p.nanoseconds[static_cast<size_t>(t)] = std::min(block[i++], kMaxProfileWeightNs);
    for (int t : l.perDraw) p.drawNanoseconds[static_cast<size_t>(t)] = std::min(block[i++], kMaxProfileDrawWeightNs);
    for (const auto& [pi, t] : l.pipeTerms) p.pipes[pi].nanoseconds[static_cast<size_t>(t)] = std::min(block[i++], kMaxProfileWeightNs);
    if (!l.sizes.empty()) p.drawSizes.push_back({l.sizes[b], p.nanoseconds, p.pipes});
  }
  // A share under kLeastPipeSumShare prices nothing a femtosecond weight can tell apart from none.
  if (l.share && w[l.shareIndex()] >= kLeastPipeSumShare) p.pipeSumShare = std::min(w[l.shareIndex()], 1.0);
  if (l.miss) p.constantCacheMissFactor = w[l.missIndex()];
  p.thresholds.clear();
  for (size_t h = 0; h < l.thresholds.size(); ++h)
    p.thresholds.push_back({l.thresholds[h].first, l.thresholds[h].second, std::min(w[l.thresholdIndex(h)], kMaxProfileWeightNs)});
  if (p.hasDrawWeights() || !p.drawSizes.empty()) p.verticesPerDraw = vertices;
  return p.atDrawSize(p.verticesPerDraw);
}

// The largest miss factor a fit may find (a miss costing 50x a hit is no cache at all).
constexpr double kMaxMissFactor = 50;

struct Solved {
  double cost = INFINITY;
  std::vector<double> w;
  bool converged = false;
};

// Ceres from three starts: each parameter at the share of a typical row it would explain
// alone, scaled by 0.1, 0.5 and 1; the best converged fit wins (the max makes the problem
// non-convex). `past[i]`: row i's palette footprint is past the constant cache's capacity.
Solved solve(const Layout& l, const std::vector<FitRow>& rows, const std::vector<std::array<double, kTermCount>>& xs,
             const std::vector<bool>& past) {
  std::vector<double> typical(l.size(), 0.0);
  {
    std::vector<double> measured;
    for (const FitRow& r : rows) measured.push_back(r.measuredNs);
    std::nth_element(measured.begin(), measured.begin() + static_cast<long>(measured.size() / 2), measured.end());
    const double median = measured[measured.size() / 2];
    auto meanAmount = [&](int t, bool perDraw) {
      double s = 0;
      for (size_t i = 0; i < rows.size(); ++i) s += xs[i][static_cast<size_t>(t)] / (perDraw ? rows[i].vertices : 1.0);
      return s / double(rows.size());
    };
    size_t i = 0;
    // Shared over one block's parameters and the miss factor (as many as without draw sizes).
    const double share = median / double(std::max<size_t>(1, l.block() + (l.miss ? 1 : 0) + (l.share ? 1 : 0) + l.thresholds.size()));
    for (int t : l.additive) typical[i++] = meanAmount(t, false) > 0 ? share / meanAmount(t, false) : 0;
    for (int t : l.perDraw) typical[i++] = meanAmount(t, true) > 0 ? share / meanAmount(t, true) : 0;
    for (const auto& [p, t] : l.pipeTerms) typical[i++] = meanAmount(t, false) > 0 ? share / meanAmount(t, false) : 0;
    for (size_t b = 1; b < l.blocks(); ++b) std::copy_n(typical.begin(), l.block(), typical.begin() + long(b * l.block()));
    for (size_t h = 0; h < l.thresholds.size(); ++h) {
      double past = 0;
      for (const auto& x : xs) past += pastThreshold(x, l.thresholds[h]);
      typical[l.thresholdIndex(h)] = past > 0 ? share * double(rows.size()) / past : 0;
    }
  }
  Solved best;
  for (double start : {0.1, 0.5, 1.0}) {
    std::vector<double> w(l.size());
    for (size_t j = 0; j < w.size(); ++j) w[j] = start * typical[j];
    if (l.miss) w[l.missIndex()] = 1.0 + start;  // a miss factor starts above 1: at 1 its gradient may vanish
    if (l.share) w[l.shareIndex()] = 0.1 * start;  // small: the pure roofline's neighbourhood
    ceres::Problem problem;
    for (size_t i = 0; i < rows.size(); ++i)
      problem.AddResidualBlock(new RowCost(l, xs[i], rows[i].vertices, rows[i].measuredNs, rows[i].weight, past[i]), nullptr,
                               w.data());
    for (size_t j = 0; j < w.size(); ++j) problem.SetParameterLowerBound(w.data(), static_cast<int>(j), 0.0);
    if (l.miss) {
      problem.SetParameterLowerBound(w.data(), static_cast<int>(l.missIndex()), 1.0);
      problem.SetParameterUpperBound(w.data(), static_cast<int>(l.missIndex()), kMaxMissFactor);
    }
    if (l.share) problem.SetParameterUpperBound(w.data(), static_cast<int>(l.shareIndex()), 1.0);
    ceres::Solver::Options o;
    o.linear_solver_type = ceres::DENSE_QR;
    o.max_num_iterations = 500;
    o.function_tolerance = 1e-12;
    o.gradient_tolerance = 1e-14;
    o.parameter_tolerance = 1e-12;
    o.num_threads = 1;  // deterministic
    o.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(o, &problem, &summary);
    if (summary.final_cost < best.cost) {
      best.cost = summary.final_cost;
      best.w = w;
      best.converged = summary.IsSolutionUsable();
    }
  }
  return best;
}

}  // namespace

double medianOf(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

namespace {

// The capacities tried: a threshold between each two consecutive distinct footprints of the
// rows that read a uniform at a per-vertex index (a term scaled by joints per warp), with
// kMinRowsPerSideOfCapacity footprints at least on each side. Each is the midpoint rounded to
// 0.01 (to more digits where that would leave the gap), so the profile states it exactly and it
// still parts the rows as tried.
std::vector<double> constantCacheCandidates(const std::vector<FitRow>& rows, const DeviceProfile& form) {
  std::vector<double> footprints;
  for (const FitRow& r : rows) {
    bool reads = false;
    for (size_t t = 0; t < kTermCount; ++t) reads |= form.scaledBy[t] == kFeatureJointsPerWarp && r.amounts[t] > 0;
    if (reads && r.workload.paletteEntriesPerWarp > 0) footprints.push_back(r.workload.paletteEntriesPerWarp);
  }
  std::sort(footprints.begin(), footprints.end());
  std::vector<double> out;
  for (size_t i = kMinRowsPerSideOfCapacity; i + kMinRowsPerSideOfCapacity <= footprints.size(); ++i) {
    const double below = footprints[i - 1], above = footprints[i];
    if (!(above > below * 1.001)) continue;
    double c = 0.5 * (below + above);
    for (double scale = 100; scale <= 1e9; scale *= 10)
      if (const double r = std::round(0.5 * (below + above) * scale) / scale; r >= below && r < above) {
        c = r;
        break;
      }
    out.push_back(c);
  }
  return out;
}

}  // namespace

FitResult fitProfile(const std::vector<FitRow>& rows, const FitOptions& options) {
  const ProfileForm form = options.form;
  if (rows.empty()) throw std::runtime_error("calibration: no validated timing to fit");
  std::set<double> sizes;
  for (const FitRow& r : rows) sizes.insert(r.vertices);
  DeviceProfile skeleton = profileForm(form);
  // Where a row's fragments were not counted, and where a generation's are unknown: the median
  // of the rows that were.
  std::vector<double> fragments, entries, joints;
  for (const FitRow& r : rows) {
    if (r.workload.fragmentsPerVertex > 0) fragments.push_back(r.workload.fragmentsPerVertex);
    if (r.workload.paletteEntriesPerWarp > 0) entries.push_back(r.workload.paletteEntriesPerWarp);
    if (r.workload.jointsPerWarp > 0) joints.push_back(r.workload.jointsPerWarp);
  }
  if (form == ProfileForm::Raster && !fragments.empty()) skeleton.workloadDefaults[kFeatureFragmentsPerVertex] = medianOf(fragments);
  Layout l = layoutOf(skeleton, sizes.size() > 1, options.outsidePipes.value_or(outsidePipesOf(form)));
  // Rows of logs written before table reads were counted apart have none (their table reads are
  // in the buffer loads): without the table terms' parameters the fit is the one it was then.
  bool tableReads = false;
  for (const FitRow& r : rows) tableReads |= r.amounts[kTermBufferTableLoads] > 0 || r.amounts[kTermBufferTableVec4Loads] > 0;
  if (!tableReads) {
    auto table = [](int t) { return t == kTermBufferTableLoads || t == kTermBufferTableVec4Loads; };
    std::erase_if(l.additive, table);
    std::erase_if(l.perDraw, table);
    std::erase_if(l.pipeTerms, [&](const std::pair<size_t, int>& pt) { return table(pt.second); });
  }
  // The pipes' sum share: how much of the pipes a program does not wait for still shows. One
  // parameter in [0, 1], fitted whenever asked (its gain on the training rows is small even
  // where it changes choices: docs/device-profiles.md, "Pipes overlap imperfectly").
  l.share = options.pipeSumShare && !skeleton.pipes.empty();
  std::vector<std::array<double, kTermCount>> xs;
  for (const FitRow& r : rows) xs.push_back(scaledAmounts(skeleton, r));

  const std::vector<bool> within(rows.size(), false);
  std::vector<bool> pastCapacity = within;  // each row past the constant cache's capacity (once one is kept)
  // A term is kept where it lowers the weighted squared error by kMinTermGain, and by more than
  // rounding: on rows a fit already prices exactly (both costs about 1e-28) either may be lower.
  const double negligible = kNegligibleRelativeError * kNegligibleRelativeError * double(rows.size());
  auto gains = [&](double with, double without) { return with < (1 - kMinTermGain) * without - negligible; };
  Solved best = solve(l, rows, xs, within);
  // Draw sizes (docs/device-profiles.md, "Draw sizes"): a block of weights per mesh size with
  // enough rows, kept where it explains kMinTermGain of the squared error.
  if (options.drawSizes && form == ProfileForm::Raster) {
    std::map<double, size_t> rowsPerSize;
    for (const FitRow& r : rows) ++rowsPerSize[r.vertices];
    Layout sized = l;
    for (const auto& [vertices, n] : rowsPerSize)
      if (n >= kMinRowsPerDrawSize) sized.sizes.push_back(vertices);
    sized.shared.assign(l.block(), false);
    for (size_t j = 0; j < l.additive.size(); ++j) sized.shared[j] = l.additive[j] == kTermFragments;
    if (sized.sizes.size() >= 2)
      if (Solved s = solve(sized, rows, xs, within); gains(s.cost, best.cost)) best = std::move(s), l = sized;
  }
  // The constant cache's capacity (docs/device-profiles.md, "The constant cache's capacity"):
  // each threshold between the footprints the rows read, with a miss factor fitted beside the
  // weights; the best threshold is kept where it explains kMinTermGain of the squared error.
  double capacity = 0;
  if (options.constantCache && !skeleton.pipes.empty()) {
    Layout withMiss = l;
    withMiss.miss = true;
    for (size_t t = 0; t < kTermCount; ++t) withMiss.missTerms[t] = skeleton.scaledBy[t] == kFeatureJointsPerWarp;
    double bestWithMiss = INFINITY;
    Solved chosen;
    std::vector<bool> chosenPast;
    // A row is past a capacity by the profile's own rule (a footprint not recorded: the default).
    DeviceProfile rule = skeleton;
    rule.workloadDefaults[kFeaturePaletteEntriesPerWarp] = medianOf(entries);
    rule.constantCacheMissFactor = 2;
    for (double c : constantCacheCandidates(rows, skeleton)) {
      rule.constantCacheEntries = c;
      std::vector<bool> past;
      for (const FitRow& r : rows) {
        rule.workload = r.workload;
        past.push_back(rule.constantCacheFactor() > 1);
      }
      Solved s = solve(withMiss, rows, xs, past);
      if (s.cost < bestWithMiss) bestWithMiss = s.cost, chosen = s, capacity = c, chosenPast = past;
    }
    if (capacity > 0 && gains(bestWithMiss, best.cost)) {
      best = chosen;
      l = withMiss;
      pastCapacity = chosenPast;
    } else {
      capacity = 0;
    }
  }
  // Prices past a threshold (docs/device-profiles.md, "A price past a threshold"): for each term
  // asked, in term order (the profile must not depend on the order of the flags), each threshold
  // between two distinct amounts of the rows (kMinRowsPerSideOfThreshold rows at least on each
  // side) with its price as one more parameter; the best is kept where it explains kMinTermGain of
  // the squared error.
  std::vector<int> thresholdTerms = options.thresholds;
  std::sort(thresholdTerms.begin(), thresholdTerms.end());
  for (int term : thresholdTerms) {
    std::vector<double> amounts;
    for (const auto& x : xs) amounts.push_back(x[static_cast<size_t>(term)]);
    std::sort(amounts.begin(), amounts.end());
    std::set<double> candidates;
    for (size_t i = kMinRowsPerSideOfThreshold; i + kMinRowsPerSideOfThreshold <= amounts.size(); ++i)
      if (amounts[i] > amounts[i - 1]) candidates.insert(amounts[i - 1]);  // rows at or below it pay nothing
    Solved bestWith;
    Layout chosen;
    for (double at : candidates) {
      Layout with = l;
      with.thresholds.emplace_back(term, at);
      if (Solved s = solve(with, rows, xs, pastCapacity); s.cost < bestWith.cost) bestWith = std::move(s), chosen = with;
    }
    if (!chosen.thresholds.empty() && gains(bestWith.cost, best.cost)) best = std::move(bestWith), l = chosen;
  }
  FitResult out;
  out.converged = best.converged;
  double workload = 0;
  for (const FitRow& r : rows) workload = std::max(workload, r.vertices);
  out.profile = toProfile(skeleton, l, best.w, workload);
  out.profile.constantCacheEntries = capacity;
  if (!tableReads) priceTableReadsAsBufferLoads(out.profile);
  // Where a generation's mesh is unknown, price it like the median mesh the fit saw.
  if (!joints.empty()) out.profile.workloadDefaults[kFeatureJointsPerWarp] = medianOf(joints);
  if (capacity > 0 && !entries.empty()) out.profile.workloadDefaults[kFeaturePaletteEntriesPerWarp] = medianOf(entries);
  double sq = 0;
  for (const FitRow& r : rows) {
    DeviceProfile at = out.profile;
    at.workload = r.workload;
    const double e = std::abs(at.predictNanoseconds(r.amounts, r.vertices) / r.measuredNs - 1);
    sq += e * e;
    out.maxRelativeError = std::max(out.maxRelativeError, e);
  }
  out.rmsRelativeError = std::sqrt(sq / double(rows.size()));
  return out;
}

}  // namespace sg

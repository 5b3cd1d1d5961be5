#include "measure/fit.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
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
    pipe("memory", {kTermBufferLoads, kTermBufferVec4Loads, kTermBufferBytes});
    // Uniform loads at a per-vertex index go through the constant cache, a unit of its own:
    // in one pipe with storage-buffer loads, a palette's cost hid under the fetch it adds to,
    // and the 300-bone palette was chosen at 1.56x the fastest (docs/device-profiles.md).
    pipe("constant", {kTermIndexedUniformLoads, kTermIndexedUniformVec4Loads});
    pipe("alu", {kTermArithmetic});
    pipe("output", {kTermOutputs});
  }
  return p;
}

namespace {

// The parameters: per-vertex additive weights (the additive form: every term but `fragments`;
// the roofline: `vertices` alone; the raster form: `vertices` and `fragments`), per-draw weights
// (every term, when draws differ; not in the raster form), then each pipe's terms.
struct Layout {
  std::vector<int> additive, perDraw;
  std::vector<std::pair<size_t, int>> pipeTerms;  // (pipe, term)
  size_t pipes = 0;
  size_t size() const { return additive.size() + perDraw.size() + pipeTerms.size(); }
};

Layout layoutOf(const DeviceProfile& form, bool drawWeights) {
  Layout l;
  const bool raster = form.scaledBy[kTermFragments] == kFeatureFragmentsPerVertex;
  for (int t = 0; t < kTermCount; ++t)
    if (t == kTermFragments ? raster : (form.pipes.empty() || t == kTermVertices)) l.additive.push_back(t);
  if (drawWeights && !raster)
    for (int t = 0; t < kTermCount; ++t) l.perDraw.push_back(t);
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

// One row's weighted relative error and its (sub)gradient: the max picks the slowest pipe.
class RowCost : public ceres::CostFunction {
 public:
  RowCost(const Layout& l, std::array<double, kTermCount> x, double vertices, double measured, double weight)
      : l_(l), x_(x), vertices_(vertices), measured_(measured), scale_(std::sqrt(weight) / measured) {
    set_num_residuals(1);
    mutable_parameter_block_sizes()->push_back(static_cast<int32_t>(l.size()));
  }
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const double* w = parameters[0];
    std::vector<double> grad(l_.size(), 0.0);
    double ns = 0;
    size_t i = 0;
    for (int t : l_.additive) ns += w[i] * x_[t], grad[i] = x_[t], ++i;
    for (int t : l_.perDraw) ns += w[i] * x_[t] / vertices_, grad[i] = x_[t] / vertices_, ++i;
    std::vector<double> pipe(l_.pipes, 0.0);
    const size_t pipeBegin = i;
    for (const auto& [p, t] : l_.pipeTerms) pipe[p] += w[i++] * x_[t];
    if (l_.pipes) {
      const size_t slowest = static_cast<size_t>(std::max_element(pipe.begin(), pipe.end()) - pipe.begin());
      ns += pipe[slowest];
      i = pipeBegin;
      for (const auto& [p, t] : l_.pipeTerms) grad[i++] = p == slowest ? x_[t] : 0.0;
    }
    residuals[0] = scale_ * (ns - measured_);
    if (jacobians && jacobians[0])
      for (size_t j = 0; j < l_.size(); ++j) jacobians[0][j] = scale_ * grad[j];
    return true;
  }

 private:
  const Layout& l_;
  std::array<double, kTermCount> x_;
  double vertices_, measured_, scale_;
};

DeviceProfile toProfile(const DeviceProfile& form, const Layout& l, const std::vector<double>& w, double vertices) {
  DeviceProfile p = form;
  for (auto& pipe : p.pipes) pipe.nanoseconds = {};
  size_t i = 0;
  for (int t : l.additive) p.nanoseconds[static_cast<size_t>(t)] = std::min(w[i++], kMaxProfileWeightNs);
  for (int t : l.perDraw) p.drawNanoseconds[static_cast<size_t>(t)] = std::min(w[i++], kMaxProfileDrawWeightNs);
  for (const auto& [pi, t] : l.pipeTerms) p.pipes[pi].nanoseconds[static_cast<size_t>(t)] = std::min(w[i++], kMaxProfileWeightNs);
  if (p.hasDrawWeights()) p.verticesPerDraw = vertices;
  return p;
}

}  // namespace

FitResult fitProfile(const std::vector<FitRow>& rows, ProfileForm form) {
  if (rows.empty()) throw std::runtime_error("calibration: no validated timing to fit");
  std::set<double> sizes;
  for (const FitRow& r : rows) sizes.insert(r.vertices);
  DeviceProfile skeleton = profileForm(form);
  // Where a row's fragments were not counted, and where a generation's are unknown: the median
  // of the rows that were.
  std::vector<double> fragments;
  for (const FitRow& r : rows)
    if (r.workload.fragmentsPerVertex > 0) fragments.push_back(r.workload.fragmentsPerVertex);
  if (form == ProfileForm::Raster && !fragments.empty()) {
    std::nth_element(fragments.begin(), fragments.begin() + static_cast<long>(fragments.size() / 2), fragments.end());
    skeleton.workloadDefaults[kFeatureFragmentsPerVertex] = fragments[fragments.size() / 2];
  }
  const Layout l = layoutOf(skeleton, sizes.size() > 1);
  std::vector<std::array<double, kTermCount>> xs;
  for (const FitRow& r : rows) xs.push_back(scaledAmounts(skeleton, r));

  // Starts: each parameter at the share of a typical row it would explain alone, scaled by
  // 0.1, 0.5 and 1; the best converged fit wins (the max makes the problem non-convex).
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
    const double share = median / double(std::max<size_t>(1, l.size()));
    for (int t : l.additive) typical[i++] = meanAmount(t, false) > 0 ? share / meanAmount(t, false) : 0;
    for (int t : l.perDraw) typical[i++] = meanAmount(t, true) > 0 ? share / meanAmount(t, true) : 0;
    for (const auto& [p, t] : l.pipeTerms) typical[i++] = meanAmount(t, false) > 0 ? share / meanAmount(t, false) : 0;
  }
  double bestCost = INFINITY;
  std::vector<double> best;
  bool converged = false;
  for (double start : {0.1, 0.5, 1.0}) {
    std::vector<double> w(l.size());
    for (size_t j = 0; j < w.size(); ++j) w[j] = start * typical[j];
    ceres::Problem problem;
    for (size_t i = 0; i < rows.size(); ++i)
      problem.AddResidualBlock(new RowCost(l, xs[i], rows[i].vertices, rows[i].measuredNs, rows[i].weight), nullptr, w.data());
    for (size_t j = 0; j < w.size(); ++j) problem.SetParameterLowerBound(w.data(), static_cast<int>(j), 0.0);
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
    if (summary.final_cost < bestCost) {
      bestCost = summary.final_cost;
      best = w;
      converged = summary.IsSolutionUsable();
    }
  }
  FitResult out;
  out.converged = converged;
  double workload = 0;
  for (const FitRow& r : rows) workload = std::max(workload, r.vertices);
  out.profile = toProfile(skeleton, l, best, workload);
  // Where a generation's mesh is unknown, price it like the median mesh the fit saw.
  std::vector<double> joints;
  for (const FitRow& r : rows)
    if (r.workload.jointsPerWarp > 0) joints.push_back(r.workload.jointsPerWarp);
  if (!joints.empty()) {
    std::nth_element(joints.begin(), joints.begin() + static_cast<long>(joints.size() / 2), joints.end());
    out.profile.workloadDefaults[kFeatureJointsPerWarp] = joints[joints.size() / 2];
  }
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

// Device calibration (docs/device-profiles.md): every probe computes what it claims on a
// real device (lavapipe), its amounts are what it was built to vary, the fit recovers known
// weights, and the written profile reads back. No timing is asserted.
#include <atomic>
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <random>

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "measure/calibrate.h"
#include "measure/gpu_bench.h"
#include "measure_test_util.h"

namespace sg {
namespace {

const CalibrationSample* find(const CalibrationReport& r, const std::string& label) {
  for (const auto& s : r.samples)
    if (s.label == label) return &s;
  return nullptr;
}

TEST(Calibrate, EveryProbeAgreesWithItsExpectedOutputsOnLavapipeAndVariesOneTerm) {
  CalibrationOptions o = testing::quickCalibration();
  CalibrationReport r = calibrateDevice(o);
  ASSERT_GE(r.samples.size(), 20u);
  for (const auto& s : r.samples) {
    EXPECT_TRUE(s.validated) << s.label << ": " << s.failure;
    EXPECT_GT(s.measuredNs, 0) << s.label;
    EXPECT_EQ(s.amounts[kTermVertices], 1) << s.label;
    // The workload of the probe mesh, whose skin (the Dawn face's) indexes the palette probes.
    EXPECT_EQ(s.workload.verticesPerDraw, s.vertices) << s.label;
    EXPECT_GE(s.workload.jointsPerWarp, 1.0) << s.label;
  }
  // Locations at fixed bytes and bytes at fixed locations, as built.
  const CalibrationSample* f16 = find(r, "locations 16 (float32x4 after the position)");
  const CalibrationSample* u8 = find(r, "locations 16 (unorm8x4 after the position)");
  ASSERT_TRUE(f16 && u8);
  EXPECT_EQ(f16->amounts[kTermLocations], 16);
  EXPECT_EQ(u8->amounts[kTermLocations], 16);
  EXPECT_EQ(f16->amounts[kTermAttributeBytes], 16 * 16);
  EXPECT_EQ(u8->amounts[kTermAttributeBytes], 16 + 15 * 4);
  // The chain's arithmetic grows by one slot per multiply-add (measured on its SPIR-V).
  const CalibrationSample* c0 = find(r, "arithmetic chain 0");
  const CalibrationSample* c64 = find(r, "arithmetic chain 64");
  ASSERT_TRUE(c0 && c64);
  EXPECT_EQ(c64->amounts[kTermArithmetic] - c0->amounts[kTermArithmetic], 64);
  EXPECT_EQ(c64->amounts[kTermLocations], c0->amounts[kTermLocations]);
  // Palette loads: the per-vertex index is charged, the uniform one is not; the rest is equal.
  const CalibrationSample* pv = find(r, "palette loads 4 at a per-vertex index");
  const CalibrationSample* pu = find(r, "palette loads 4 at a uniform index");
  ASSERT_TRUE(pv && pu);
  EXPECT_EQ(pv->amounts[kTermIndexedUniformLoads], 4);
  EXPECT_EQ(pu->amounts[kTermIndexedUniformLoads], 0);
  EXPECT_EQ(pv->amounts[kTermIndexedUniformVec4Loads], 16);  // a mat4 entry: 4 vec4 loads
  EXPECT_EQ(pu->amounts[kTermIndexedUniformVec4Loads], 0);
  // 16 loads: joints 0..3 of the skin, then shifted by 7 per group of four (validated above).
  const CalibrationSample* pv16 = find(r, "palette loads 16 at a per-vertex index");
  ASSERT_TRUE(pv16);
  EXPECT_EQ(pv16->amounts[kTermIndexedUniformLoads], 16);
  EXPECT_EQ(pv16->amounts[kTermIndexedUniformVec4Loads], 64);
  EXPECT_EQ(pv->amounts[kTermLocations], pu->amounts[kTermLocations]);
  // The palette in a storage buffer: a table's storage-buffer loads at the per-vertex joints,
  // counted apart from the per-vertex streams' loads, and no uniform load.
  const CalibrationSample* bv = find(r, "buffer palette loads 16 at a per-vertex index");
  ASSERT_TRUE(bv);
  EXPECT_EQ(bv->amounts[kTermBufferTableLoads], 16);
  EXPECT_EQ(bv->amounts[kTermBufferTableVec4Loads], 64);
  EXPECT_EQ(bv->amounts[kTermBufferLoads], 0);
  EXPECT_EQ(bv->amounts[kTermBufferVec4Loads], 0);
  EXPECT_EQ(bv->amounts[kTermBufferBytes], 16 * 64);
  EXPECT_EQ(bv->amounts[kTermIndexedUniformLoads], 0);
  EXPECT_EQ(bv->amounts[kTermLocations], pv->amounts[kTermLocations]);
  const CalibrationSample* b16 = find(r, "storage-buffer loads 16");
  ASSERT_TRUE(b16);
  EXPECT_EQ(b16->amounts[kTermBufferLoads], 16);
  EXPECT_EQ(b16->amounts[kTermBufferBytes], 256);
  const CalibrationSample* o15 = find(r, "outputs 15 x vec4");
  ASSERT_TRUE(o15);
  EXPECT_EQ(o15->amounts[kTermOutputs], 4 + 15 * 4);

  // The profile written reads back with the fitted weights (printed to 6 significant digits).
  DeviceProfile back = parseDeviceProfile(deviceProfileYaml(r), "calibrated.yaml");
  for (int t = 0; t < kTermCount; ++t) {
    EXPECT_GE(back.nanoseconds[size_t(t)], 0) << termName(t);
    EXPECT_NEAR(back.nanoseconds[size_t(t)], r.profile.nanoseconds[size_t(t)], 1e-5 * (1 + r.profile.nanoseconds[size_t(t)]))
        << termName(t);
  }
}

// Interrupted (the CLI's SIGINT handler sets the flag) before anything was timed: nothing is
// timed and the error says why there is nothing to fit.
TEST(Calibrate, AnInterruptionBeforeAnyTimingSaysSo) {
  std::atomic<bool> stop{true};
  CalibrationOptions o = testing::quickCalibration();
  o.stop = &stop;
  try {
    calibrateDevice(o);
    ADD_FAILURE() << "an interrupted calibration with nothing timed fitted a profile";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("interrupted before anything was timed"), std::string::npos) << e.what();
  }
}

TEST(Calibrate, TheFitRecoversKnownNonNegativeWeights) {
  // Samples timed by a known linear device: 0.5 ns per location, 0.01 per slot, 2 ns fixed,
  // nothing for the other terms. The fit must give those weights and predict exactly.
  double truth[kTermCount] = {};
  truth[kTermArithmetic] = 0.01;
  truth[kTermLocations] = 0.5;
  truth[kTermVertices] = 2.0;
  std::vector<CalibrationSample> samples;
  for (int locations = 1; locations <= 16; locations += 3)
    for (int slots : {0, 40, 200}) {
      CalibrationSample s;
      s.label = fmt::format("l{} a{}", locations, slots);
      s.mesh = "m";
      s.vertices = 1000;
      s.validated = true;
      s.amounts[kTermLocations] = locations;
      s.amounts[kTermAttributeBytes] = 16 * locations;
      s.amounts[kTermArithmetic] = slots;
      s.amounts[kTermOutputs] = 8;
      s.amounts[kTermVertices] = 1;
      s.measuredNs = 0;
      for (int t = 0; t < kTermCount; ++t) s.measuredNs += truth[t] * double(s.amounts[size_t(t)]);
      samples.push_back(s);
    }
  // A sample that failed validation is never fitted, however wrong its time.
  CalibrationSample bad = samples.front();
  bad.validated = false;
  bad.measuredNs = 1e6;
  samples.push_back(bad);
  DeviceProfile p = fitDeviceProfile(samples, "linear device", 1000);
  // One mesh size cannot tell a per-draw cost from a per-vertex one: none is fitted.
  EXPECT_FALSE(p.hasDrawWeights());
  // Bytes are 16 x locations here: only their sum is determined, so check predictions and
  // the terms the samples separate.
  std::vector<CalibrationFit> fits = evaluateFit(samples, p, {"m"});
  ASSERT_EQ(fits.size(), 1u);
  EXPECT_EQ(fits[0].samples, samples.size() - 1);
  EXPECT_LT(fits[0].rmsRelativeError, 1e-9);
  EXPECT_NEAR(p.nanoseconds[kTermArithmetic], 0.01, 1e-9);
  EXPECT_NEAR(p.nanoseconds[kTermLocations] + 16 * p.nanoseconds[kTermAttributeBytes], 0.5, 1e-9);
  EXPECT_NEAR(p.nanoseconds[kTermVertices] + 8 * p.nanoseconds[kTermOutputs], 2.0, 1e-9);
  EXPECT_DOUBLE_EQ(fits[0].spearman, 1.0);
}

TEST(Calibrate, TwoMeshSizesSeparatePerDrawFromPerVertexCosts) {
  // A device with a fixed 700 ns per draw and 150 ns per output component per draw (the
  // pixels a draw covers), beside per-vertex costs: on 2,000 vertices per draw those add
  // 0.35 + 0.075 x outputs ns per vertex, on 180,000 almost nothing. The fit must find both
  // parts, state the profile's workload, price each mesh at its own size, and read back.
  double perVertex[kTermCount] = {}, perDraw[kTermCount] = {};
  perVertex[kTermArithmetic] = 0.002;
  perVertex[kTermLocations] = 0.45;
  perVertex[kTermBufferLoads] = 0.13;
  perVertex[kTermOutputs] = 0.07;
  perDraw[kTermOutputs] = 150;
  perDraw[kTermVertices] = 700;
  std::vector<CalibrationSample> samples;
  for (double vertices : {180000.0, 2000.0})
    for (int locations = 1; locations <= 16; locations += 5)
      for (int outputs : {8, 24, 64})
        for (int loads : {0, 8})
          for (int slots : {20, 200}) {
            CalibrationSample s;
            s.label = fmt::format("l{} o{} b{} a{}", locations, outputs, loads, slots);
            s.mesh = vertices > 10000 ? "big" : "small";
            s.vertices = vertices;
            s.validated = true;
            s.amounts[kTermArithmetic] = slots;
            s.amounts[kTermLocations] = locations;
            s.amounts[kTermBufferLoads] = loads;
            s.amounts[kTermOutputs] = outputs;
            s.amounts[kTermVertices] = 1;
            // As calibrate counts it: 1 per vertex outside the raster form, so no per-draw weight of its own.
            s.amounts[kTermFragments] = 1;
            s.measuredNs = 0;
            for (int t = 0; t < kTermCount; ++t)
              s.measuredNs += (perVertex[t] + perDraw[t] / vertices) * double(s.amounts[size_t(t)]);
            samples.push_back(s);
          }
  DeviceProfile p = fitDeviceProfile(samples, "two-size device", 180000);
  ASSERT_TRUE(p.hasDrawWeights());
  EXPECT_EQ(p.verticesPerDraw, 180000);
  for (int t = 0; t < kTermCount; ++t) {
    // No sample reads a table from a storage buffer: the profile prices such reads as buffer loads.
    const int as = t == kTermBufferTableLoads ? kTermBufferLoads : t == kTermBufferTableVec4Loads ? kTermBufferVec4Loads : t;
    EXPECT_NEAR(p.nanoseconds[size_t(t)], perVertex[as], 1e-6) << termName(t);
    EXPECT_NEAR(p.drawNanoseconds[size_t(t)], perDraw[as], 1e-3) << termName(t);
  }
  std::vector<CalibrationFit> fits = evaluateFit(samples, p, {"big", "small"});
  ASSERT_EQ(fits.size(), 2u);
  for (const auto& f : fits) EXPECT_LT(f.rmsRelativeError, 1e-6) << f.mesh;
  // The search's weights price the profile's workload: per-vertex + per-draw / 180,000.
  const TermWeights w = profileWeights(p);
  EXPECT_EQ(w[kTermOutputs], std::llround((0.07 + 150.0 / 180000) * kFemtosecondsPerNanosecond));
  // Written and read back, draw weights and workload included.
  CalibrationReport r;
  r.profile = p;
  DeviceProfile back = parseDeviceProfile(deviceProfileYaml(r), "calibrated.yaml");
  EXPECT_EQ(back.verticesPerDraw, 180000);
  for (int t = 0; t < kTermCount; ++t)
    EXPECT_NEAR(back.drawNanoseconds[size_t(t)], p.drawNanoseconds[size_t(t)], 1e-5 * (1 + p.drawNanoseconds[size_t(t)]));
}

// The samples an H200 calibration measured (bench/data/h200-calibrate-alike.log, fitted with every row alike: probes, floors and
// both Dawn layouts' plans at Dawn scale and on the cached head, each validated before it was
// timed): data the fit was not designed around. Rows "checked plan" are never fitted.
std::vector<CalibrationSample> h200Samples() {
  std::ifstream in(std::string(SG_SOURCE_DIR) + "/bench/data/h200-calibrate-alike.log");
  return parseCalibrationSamples(in, {{"dawn", 180000}, {"head", 2009}});  // the log's meshes
}

// Of a rig's measured plans on a mesh, the one the profile predicts fastest, over the fastest.
double pickedOverFastest(const std::vector<CalibrationSample>& samples, const DeviceProfile& p, const std::string& rig,
                         const std::string& mesh) {
  double fastest = INFINITY, picked = 0, best = INFINITY;
  for (const auto& s : samples)
    if (s.rig == rig && s.mesh == mesh && s.label.find("plan") != std::string::npos) {
      fastest = std::min(fastest, s.measuredNs);
      const double predicted = p.predictNanoseconds(s.amounts, s.vertices);
      if (predicted < best) best = predicted, picked = s.measuredNs;
    }
  return picked / fastest;
}

TEST(Calibrate, WeightingThePlansNearTheFastestOrdersTheH200PlansTheSearchCompares) {
  const std::vector<CalibrationSample> samples = h200Samples();
  ASSERT_EQ(samples.size(), 240u) << "the log's table changed";
  // Fitted alike, the plans with 16 locations, whose palette loads the H200 hides under the
  // fetch, pull the indexed-load weight down: on the head the float face's cheapest-looking
  // plan (4 locations, the uniform palette at per-vertex joints) takes 1.41x the fastest
  // (6 locations, the palette from a buffer). Weighted towards each rig's fastest, the fit
  // orders them; no layout or mesh gets worse than 1 % over its fastest.
  const DeviceProfile alike = fitDeviceProfile(samples, "H200", 180000, 0);
  EXPECT_GT(pickedOverFastest(samples, alike, "face.rig.yaml", "head"), 1.3);
  const DeviceProfile nearBest = fitDeviceProfile(samples, "H200", 180000, CalibrationOptions{}.nearBestPower);
  for (const char* rig : {"face.rig.yaml", "face-packed.rig.yaml"})
    for (const char* mesh : {"dawn", "head"})
      EXPECT_LT(pickedOverFastest(samples, nearBest, rig, mesh), 1.01) << rig << " on " << mesh;
  // The probes still weigh 1, so the terms they isolate stay fitted: the predictions over
  // all programs still rank with the measurements on both meshes.
  std::vector<CalibrationSample> all = samples;
  for (const auto& f : evaluateFit(all, nearBest, {"dawn", "head"})) EXPECT_GT(f.spearmanAll, 0.85) << f.mesh;
}

// A device that overlaps its pipes (fetch, memory, alu, output: the slowest wins) on top of a
// per-vertex and a per-draw fixed cost, whose palette loads cost per distinct joint a warp
// reads. Rows are drawn at random over two draw sizes and several meshes' joints per warp;
// the roofline fit must predict rows it never saw, and the additive form cannot.
// RMS relative error of `p`'s predictions over `rows`, each priced at its own workload (its
// fragments unknown, priced at the profile's default, unless `fragmentsKnown`).
double rmsRelativeError(const DeviceProfile& p, const std::vector<CalibrationSample>& rows, bool fragmentsKnown = true) {
  double sq = 0;
  for (const auto& s : rows) {
    DeviceProfile at = p;
    at.workload = s.workload;
    if (!fragmentsKnown) at.workload.fragmentsPerVertex = 0;
    const double e = at.predictNanoseconds(s.amounts, s.vertices) / s.measuredNs - 1;
    sq += e * e;
  }
  return std::sqrt(sq / double(rows.size()));
}

namespace roofline {
struct Device {
  double vertexNs = 0.3, drawNs = 400;
  double location = 0.35, byte = 0.002, load = 0.07, address = 0.2, slot = 0.002, output = 0.04;
  double ns(const TermAmounts& a, double vertices, double jointsPerWarp) const {
    const double fetch = location * double(a[kTermLocations]) + byte * double(a[kTermAttributeBytes]);
    // Storage-buffer and constant-cache loads overlap each other, as the H200's do.
    const double memory = load * double(a[kTermBufferLoads]);
    const double constant = address * jointsPerWarp * double(a[kTermIndexedUniformLoads]);
    const double alu = slot * double(a[kTermArithmetic]), out = output * double(a[kTermOutputs]);
    return vertexNs + drawNs / vertices + std::max({fetch, memory, constant, alu, out});
  }
};
std::vector<CalibrationSample> rows(uint32_t seed, int n) {
  std::mt19937 rng(seed);
  auto pick = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
  Device d;
  std::vector<CalibrationSample> out;
  for (int i = 0; i < n; ++i) {
    CalibrationSample s;
    s.label = fmt::format("row {}", i);
    s.vertices = pick(0, 1) ? 180000 : 2009;
    s.mesh = s.vertices > 10000 ? "dawn" : "head";
    s.validated = true;
    s.amounts[kTermLocations] = pick(1, 16);
    s.amounts[kTermAttributeBytes] = s.amounts[kTermLocations] * 4 * pick(1, 4);
    s.amounts[kTermBufferLoads] = pick(0, 2) ? 0 : pick(1, 40);
    s.amounts[kTermIndexedUniformLoads] = pick(0, 2) ? 0 : 4 * pick(1, 4);
    s.amounts[kTermArithmetic] = pick(20, 600);
    s.amounts[kTermOutputs] = 4 * pick(1, 12);
    s.amounts[kTermVertices] = 1;
    s.workload.jointsPerWarp = 1 + pick(0, 28) / 4.0;
    s.measuredNs = d.ns(s.amounts, s.vertices, s.workload.jointsPerWarp);
    out.push_back(s);
  }
  return out;
}
}  // namespace roofline

TEST(Calibrate, TheRooflineFitPredictsRowsItNeverSawWhereTheAdditiveCannot) {
  const std::vector<CalibrationSample> train = roofline::rows(1, 160), test = roofline::rows(2, 80);
  auto heldOutRms = [&](const DeviceProfile& p) { return rmsRelativeError(p, test); };
  const DeviceProfile roof = fitDeviceProfile(train, "roofline device", 180000, 0, ProfileForm::Roofline);
  const DeviceProfile sum = fitDeviceProfile(train, "roofline device", 180000, 0, ProfileForm::Additive);
  ASSERT_EQ(roof.pipes.size(), 5u);
  EXPECT_EQ(roof.scaledBy[kTermIndexedUniformLoads], kFeatureJointsPerWarp);
  EXPECT_EQ(roof.scaledBy[kTermIndexedUniformVec4Loads], kFeatureJointsPerWarp);
  EXPECT_LT(heldOutRms(roof), 0.01);
  EXPECT_GT(heldOutRms(sum), 0.05);
  // The weights themselves: each pipe's, the per-vertex and the per-draw fixed costs.
  const roofline::Device d;
  EXPECT_NEAR(roof.pipes[0].nanoseconds[kTermLocations], d.location, 0.02);
  EXPECT_NEAR(roof.pipes[1].nanoseconds[kTermBufferLoads], d.load, 0.01);
  EXPECT_NEAR(roof.pipes[2].nanoseconds[kTermIndexedUniformLoads], d.address, 0.02);
  EXPECT_NEAR(roof.pipes[4].nanoseconds[kTermOutputs], d.output, 0.005);
  EXPECT_NEAR(roof.nanoseconds[kTermVertices], d.vertexNs, 0.05);
  EXPECT_NEAR(roof.drawNanoseconds[kTermVertices], d.drawNs, 40);
  // Written and read back, it predicts the same (pipes, scaling and defaults included).
  CalibrationReport r;
  r.profile = roof;
  DeviceProfile back = parseDeviceProfile(deviceProfileYaml(r), "roofline.yaml");
  for (const auto& s : test) {
    DeviceProfile a = roof, b = back;
    a.workload = b.workload = s.workload;
    EXPECT_NEAR(b.predictNanoseconds(s.amounts, s.vertices), a.predictNanoseconds(s.amounts, s.vertices),
                1e-5 * s.measuredNs);
  }
}

// A device whose pipes overlap imperfectly: besides the slowest a row pays `share` of the others
// (DeviceProfile::pipeSumShare). The fit with the share finds it and the weights and predicts
// rows it never saw; the pure roofline cannot. On a pure roofline's rows the share is not kept.
std::vector<CalibrationSample> sharedRows(uint32_t seed, int n, double share) {
  std::vector<CalibrationSample> out = roofline::rows(seed, n);
  const roofline::Device d;
  for (auto& s : out) {
    const TermAmounts& a = s.amounts;
    const double pipes[5] = {d.location * double(a[kTermLocations]) + d.byte * double(a[kTermAttributeBytes]),
                             d.load * double(a[kTermBufferLoads]),
                             d.address * s.workload.jointsPerWarp * double(a[kTermIndexedUniformLoads]),
                             d.slot * double(a[kTermArithmetic]), d.output * double(a[kTermOutputs])};
    double sum = 0, slowest = 0;
    for (double p : pipes) sum += p, slowest = std::max(slowest, p);
    s.measuredNs = d.vertexNs + d.drawNs / s.vertices + slowest + share * (sum - slowest);
  }
  return out;
}

TEST(Calibrate, TheFitFindsHowMuchOfTheOtherPipesShows) {
  const double share = 0.15;
  const std::vector<CalibrationSample> train = sharedRows(1, 160, share), test = sharedRows(2, 80, share);
  const FitOptions withShare(ProfileForm::Roofline, false, false, true);
  const DeviceProfile fitted = fitDeviceProfile(train, "shared device", 180000, 0, withShare);
  const DeviceProfile pure = fitDeviceProfile(train, "shared device", 180000, 0, ProfileForm::Roofline);
  EXPECT_NEAR(fitted.pipeSumShare, share, 0.02);
  EXPECT_EQ(pure.pipeSumShare, 0);
  EXPECT_LT(rmsRelativeError(fitted, test), 0.01);
  EXPECT_GT(rmsRelativeError(pure, test), 2 * rmsRelativeError(fitted, test));
  EXPECT_NEAR(fitted.pipes[0].nanoseconds[kTermLocations], roofline::Device{}.location, 0.02);
  // Written and read back, it predicts the same.
  CalibrationReport r;
  r.profile = fitted;
  const std::string yaml = deviceProfileYaml(r);
  EXPECT_NE(yaml.find("pipe_sum_share: "), std::string::npos) << yaml;
  const DeviceProfile back = parseDeviceProfile(yaml, "shared.yaml");
  EXPECT_NEAR(back.pipeSumShare, fitted.pipeSumShare, 1e-4);
  // A pure roofline's rows: the fitted share is nothing, and the profile states none.
  const DeviceProfile onPure = fitDeviceProfile(roofline::rows(1, 160), "roofline device", 180000, 0, withShare);
  EXPECT_EQ(onPure.pipeSumShare, 0);
  CalibrationReport none;
  none.profile = onPure;
  EXPECT_EQ(deviceProfileYaml(none).find("pipe_sum_share"), std::string::npos);
}

// The same pipes, no per-draw cost, and a price per fragment a draw covers (the H200's raster-on
// clock: docs/device-profiles.md, "The rasterizer's share"). Fragments per vertex vary from mesh
// to mesh independently of its size, so the raster form fits them and the roofline's per-draw
// weights cannot stand in for them.
std::vector<CalibrationSample> rasterRows(uint32_t seed, int n, double fragmentNs) {
  std::vector<CalibrationSample> out = roofline::rows(seed, n);
  std::mt19937 rng(seed + 100);
  roofline::Device d;
  d.drawNs = 0;
  for (auto& s : out) {
    s.amounts[kTermFragments] = 1;
    s.workload.fragmentsPerVertex = std::uniform_real_distribution<double>(0.2, 150)(rng);
    s.measuredNs = d.ns(s.amounts, s.vertices, s.workload.jointsPerWarp) + fragmentNs * s.workload.fragmentsPerVertex;
  }
  return out;
}

TEST(Calibrate, TheRasterFitPricesTheFragmentsADrawCovers) {
  const double fragmentNs = 0.05;
  const std::vector<CalibrationSample> train = rasterRows(1, 160, fragmentNs), test = rasterRows(2, 80, fragmentNs);
  auto heldOutRms = [&](const DeviceProfile& p, bool fragmentsKnown) { return rmsRelativeError(p, test, fragmentsKnown); };
  const DeviceProfile raster = fitDeviceProfile(train, "raster device", 180000, 0, ProfileForm::Raster);
  const DeviceProfile roof = fitDeviceProfile(train, "raster device", 180000, 0, ProfileForm::Roofline);
  EXPECT_FALSE(raster.hasDrawWeights());
  EXPECT_EQ(raster.scaledBy[kTermFragments], kFeatureFragmentsPerVertex);
  EXPECT_NEAR(raster.nanoseconds[kTermFragments], fragmentNs, 0.002);
  EXPECT_NEAR(raster.nanoseconds[kTermVertices], roofline::Device{}.vertexNs, 0.05);
  EXPECT_LT(heldOutRms(raster, true), 0.01);
  EXPECT_GT(heldOutRms(roof, true), 0.05);
  // Where a mesh's fragments are unknown the profile prices the median the fit saw.
  std::vector<double> seen;
  for (const auto& s : train) seen.push_back(s.workload.fragmentsPerVertex);
  std::nth_element(seen.begin(), seen.begin() + static_cast<long>(seen.size() / 2), seen.end());
  EXPECT_EQ(raster.workloadDefaults[kFeatureFragmentsPerVertex], seen[seen.size() / 2]);
  EXPECT_GT(heldOutRms(raster, false), heldOutRms(raster, true));
  // Written and read back, it predicts the same.
  CalibrationReport r;
  r.profile = raster;
  const std::string yaml = deviceProfileYaml(r);
  EXPECT_NE(yaml.find("# form: raster"), std::string::npos);
  DeviceProfile back = parseDeviceProfile(yaml, "raster.yaml");
  for (const auto& s : test) {
    DeviceProfile a = raster, b = back;
    a.workload = b.workload = s.workload;
    EXPECT_NEAR(b.predictNanoseconds(s.amounts, s.vertices), a.predictNanoseconds(s.amounts, s.vertices), 1e-5 * s.measuredNs);
  }
}

// A device with a constant cache of `capacity` palette entries: a warp whose footprint is larger
// pays `miss` times the constant pipe's per-address price (an LRU cache under a warp's cyclic
// reuse misses every time). Footprints vary independently of joints per warp, as the head's do.
// A device that overlaps its pipes except for a share of each input location and storage-buffer
// load, paid by every vertex beside the slowest pipe (as the H200's and H100's logs fit:
// docs/device-profiles.md, "Inputs outside the overlap").
constexpr double kLocationOutside = 0.12, kLoadOutside = 0.03;
std::vector<CalibrationSample> outsideRows(uint32_t seed, int n) {
  std::vector<CalibrationSample> out = rasterRows(seed, n, 0.05);
  for (auto& s : out)
    s.measuredNs += kLocationOutside * double(s.amounts[kTermLocations]) + kLoadOutside * double(s.amounts[kTermBufferLoads]);
  return out;
}

TEST(Calibrate, TheRasterFitPricesTheShareOfInputsThePipesDoNotOverlap) {
  const std::vector<CalibrationSample> train = outsideRows(1, 200), test = outsideRows(2, 80);
  const DeviceProfile raster = fitDeviceProfile(train, "outside device", 180000, 0, ProfileForm::Raster);
  const roofline::Device d;
  EXPECT_NEAR(raster.nanoseconds[kTermLocations], kLocationOutside, 0.01);
  EXPECT_NEAR(raster.nanoseconds[kTermBufferLoads], kLoadOutside, 0.005);
  EXPECT_NEAR(raster.pipes[0].nanoseconds[kTermLocations], d.location, 0.02);
  EXPECT_NEAR(raster.pipes[1].nanoseconds[kTermBufferLoads], d.load, 0.01);
  EXPECT_LT(rmsRelativeError(raster, test), 0.01);
  // Every term inside its pipe (--outside-pipes none, the raster form before session 28) cannot say it.
  FitOptions inside(ProfileForm::Raster);
  inside.outsidePipes = std::vector<int>{};
  const DeviceProfile pure = fitDeviceProfile(train, "outside device", 180000, 0, inside);
  EXPECT_EQ(pure.nanoseconds[kTermLocations], 0);
  EXPECT_GT(rmsRelativeError(pure, test), 0.02);
  // A choice that turns on it, on one mesh: 8 locations, against 6 and 20 buffer loads. The device
  // pays 0.3 + 0.96 + 2.8 = 4.06 ns for the first and 0.3 + 0.72 + 0.6 + max(2.1, 1.4) = 3.72 for
  // the second.
  TermAmounts attributes{}, buffered{};
  attributes[kTermVertices] = buffered[kTermVertices] = 1;
  attributes[kTermLocations] = 8, buffered[kTermLocations] = 6, buffered[kTermBufferLoads] = 20;
  DeviceProfile at = raster;
  at.workload.fragmentsPerVertex = 0;
  EXPECT_NEAR(at.predictNanoseconds(attributes, 180000), 4.06, 0.04);
  EXPECT_NEAR(at.predictNanoseconds(buffered, 180000), 3.72, 0.04);
  // The profile says how it was fitted.
  CalibrationReport r;
  r.profile = raster;
  r.outsidePipes = outsidePipesOf(ProfileForm::Raster);
  EXPECT_NE(deviceProfileYaml(r).find("# form: raster (outside the pipes too: locations, buffer_loads, buffer_vec4_loads)\n"),
            std::string::npos)
      << deviceProfileYaml(r);
  // The default raster form on a device that overlaps everything (rasterRows) finds no share.
  const DeviceProfile overlapped = fitDeviceProfile(rasterRows(1, 200, 0.05), "raster device", 180000, 0, ProfileForm::Raster);
  EXPECT_LT(overlapped.nanoseconds[kTermLocations], 0.005);
  EXPECT_LT(overlapped.nanoseconds[kTermBufferLoads], 0.001);
}

std::vector<CalibrationSample> cacheRows(uint32_t seed, int n, double capacity, double miss) {
  std::vector<CalibrationSample> out = rasterRows(seed, n, 0.05);
  std::mt19937 rng(seed + 200);
  roofline::Device d;
  d.drawNs = 0;
  for (auto& s : out) {
    s.workload.paletteEntriesPerWarp = s.workload.jointsPerWarp * std::uniform_real_distribution<double>(1, 6)(rng);
    const double j = s.workload.jointsPerWarp * (s.workload.paletteEntriesPerWarp > capacity ? miss : 1.0);
    s.measuredNs = d.ns(s.amounts, s.vertices, j) + 0.05 * s.workload.fragmentsPerVertex;
  }
  return out;
}

TEST(Calibrate, TheFitFindsTheConstantCachesCapacityAndItsMissPrice) {
  const double capacity = 30, miss = 2.5;
  const std::vector<CalibrationSample> train = cacheRows(1, 200, capacity, miss);
  std::vector<CalibrationSample> test = cacheRows(2, 80, capacity, miss);
  auto heldOutRms = [&](const DeviceProfile& p) { return rmsRelativeError(p, test); };
  // What the rows can tell: the capacity lies between the largest footprint within it and the
  // smallest past it, among the rows that read the palette at a per-vertex index.
  double within = 0, past = 1e9;
  for (const auto& s : train)
    if (s.amounts[kTermIndexedUniformLoads] > 0) {
      const double e = s.workload.paletteEntriesPerWarp;
      if (e <= capacity) within = std::max(within, e);
      else past = std::min(past, e);
    }
  ASSERT_LT(within, past);
  // Held-out rows in that gap are priced by where the fit put the threshold: not checked.
  test.erase(std::remove_if(test.begin(), test.end(),
                            [&](const CalibrationSample& s) {
                              return s.workload.paletteEntriesPerWarp > within && s.workload.paletteEntriesPerWarp <= past;
                            }),
             test.end());
  ASSERT_GT(test.size(), 70u);
  const DeviceProfile raster = fitDeviceProfile(train, "cached device", 180000, 0, FitOptions(ProfileForm::Raster, true));
  EXPECT_GE(raster.constantCacheEntries, within);
  EXPECT_LT(raster.constantCacheEntries, past);
  EXPECT_NEAR(raster.constantCacheMissFactor, miss, 0.05);
  EXPECT_NEAR(raster.pipes[2].nanoseconds[kTermIndexedUniformLoads], roofline::Device{}.address, 0.01);
  EXPECT_LT(heldOutRms(raster), 0.01);
  // Without the footprints the fit cannot see the cache, and prices every warp alike.
  std::vector<CalibrationSample> blind = train;
  for (auto& s : blind) s.workload.paletteEntriesPerWarp = 0;
  const DeviceProfile without = fitDeviceProfile(blind, "cached device", 180000, 0, FitOptions(ProfileForm::Raster, true));
  EXPECT_EQ(without.constantCacheEntries, 0);
  EXPECT_GT(heldOutRms(without), 0.05);
  // Not asked for, the fit has none; a device without the cliff gets none from the same footprints.
  EXPECT_EQ(fitDeviceProfile(train, "cached device", 180000, 0, ProfileForm::Raster).constantCacheEntries, 0);
  const DeviceProfile flat = fitDeviceProfile(cacheRows(1, 200, capacity, 1.0), "flat device", 180000, 0, FitOptions(ProfileForm::Raster, true));
  EXPECT_EQ(flat.constantCacheEntries, 0);
  // A capacity needs kMinRowsPerSideOfCapacity footprints past it: the first 120 rows hold one
  // (the 200, four), and a fit on them keeps no cache rather than a cliff one row says.
  const std::vector<CalibrationSample> fewer = cacheRows(1, 120, capacity, miss);
  ASSERT_EQ(std::count_if(fewer.begin(), fewer.end(),
                          [&](const CalibrationSample& s) {
                            return s.amounts[kTermIndexedUniformLoads] > 0 && s.workload.paletteEntriesPerWarp > capacity;
                          }),
            1);
  EXPECT_EQ(fitDeviceProfile(fewer, "cached device", 180000, 0, FitOptions(ProfileForm::Raster, true)).constantCacheEntries, 0);
  // Written and read back, it predicts the same; past the capacity a warp costs miss x as much.
  CalibrationReport r;
  r.profile = raster;
  const std::string yaml = deviceProfileYaml(r);
  EXPECT_NE(yaml.find("constant_cache:"), std::string::npos);
  const DeviceProfile back = parseDeviceProfile(yaml, "cached.yaml");
  EXPECT_EQ(back.constantCacheEntries, raster.constantCacheEntries);
  for (const auto& s : test) {
    DeviceProfile a = raster, b = back;
    a.workload = b.workload = s.workload;
    EXPECT_NEAR(b.predictNanoseconds(s.amounts, s.vertices), a.predictNanoseconds(s.amounts, s.vertices), 1e-5 * s.measuredNs);
  }
  DeviceProfile at = back;
  at.workload.jointsPerWarp = 10;
  at.workload.paletteEntriesPerWarp = back.constantCacheEntries - 1;
  const double hit = at.feature(kFeatureJointsPerWarp);
  at.workload.paletteEntriesPerWarp = back.constantCacheEntries + 1;
  EXPECT_DOUBLE_EQ(at.feature(kFeatureJointsPerWarp), hit * back.constantCacheMissFactor);
  EXPECT_DOUBLE_EQ(hit, 10);
}

// A CPU device whose vertex inputs cost more past the 14th (lavapipe's, docs/device-profiles.md, "A
// price past a threshold"), one mesh size: 4 ns a vertex, 0.3 per location and 4 more per location
// past 14, 1.2 per storage-buffer vec4 load, 0.3 per slot, 1 per output component. A rig's floor
// ("floor + every input fetched") reads every input and sums it at once: it pays no more past 14.
namespace past14 {
constexpr double kVertex = 4, kLocation = 0.3, kPast = 4, kVec4 = 1.2, kSlot = 0.3, kOutput = 1;
double ns(const TermAmounts& a, bool floor) {
  const double past = floor ? 0 : std::max(0.0, double(a[kTermLocations]) - 14);
  return kVertex + kLocation * double(a[kTermLocations]) + kPast * past + kVec4 * double(a[kTermBufferVec4Loads]) +
         kSlot * double(a[kTermArithmetic]) + kOutput * double(a[kTermOutputs]);
}
// vec4PastNs: a second step, each storage-buffer vec4 load past 12 costing that much more (lavapipe's
// loads past 18, session 30).
std::vector<CalibrationSample> rows(uint32_t seed, int n, double pastNs = kPast, double vec4PastNs = 0) {
  std::mt19937 rng(seed);
  auto pick = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
  std::vector<CalibrationSample> out;
  for (int i = 0; i < n; ++i) {
    CalibrationSample s;
    s.mesh = "dawn";
    s.vertices = 180000;
    s.validated = true;
    s.rig = fmt::format("rig{}", i / 4);
    const bool floor = i % 4 == 3;
    s.label = floor ? "floor + every input fetched" : fmt::format("plan: forced {}", i);
    s.amounts[kTermLocations] = pick(1, 24);
    s.amounts[kTermAttributeBytes] = 16 * s.amounts[kTermLocations];
    s.amounts[kTermBufferVec4Loads] = floor || pick(0, 1) ? 0 : pick(1, 20);
    s.amounts[kTermArithmetic] = floor ? s.amounts[kTermLocations] : pick(20, 200);
    s.amounts[kTermOutputs] = 4 * pick(1, 8);
    s.amounts[kTermVertices] = 1;
    s.measuredNs = ns(s.amounts, floor) + (floor ? 0 : (pastNs - kPast) * std::max(0.0, double(s.amounts[kTermLocations]) - 14)) +
                   vec4PastNs * std::max(0.0, double(s.amounts[kTermBufferVec4Loads]) - 12);
    out.push_back(s);
  }
  return out;
}
}  // namespace past14

// The fit finds where an input starts to cost more and what it costs past there, from the plans (the
// floors, which do not pay it, left out); the form without a threshold cannot say it and chooses
// the wrong plan; and a device without such a step gets no threshold.
TEST(Calibrate, TheFitFindsWhereAVertexInputStartsToCostMore) {
  const std::vector<CalibrationSample> train = past14::rows(1, 240), test = past14::rows(2, 80);
  std::vector<CalibrationSample> testPlans = test;
  std::erase_if(testPlans, [](const CalibrationSample& s) { return s.label.find("floor") != std::string::npos; });
  FitOptions opts;
  opts.thresholds = {kTermLocations};
  opts.floors = false;
  const DeviceProfile p = fitDeviceProfile(train, "past-14 device", 180000, 0, opts);
  ASSERT_EQ(p.thresholds.size(), 1u);
  EXPECT_EQ(p.thresholds[0].term, kTermLocations);
  EXPECT_EQ(p.thresholds[0].at, 14);
  EXPECT_NEAR(p.thresholds[0].nanoseconds, past14::kPast, 0.01);
  EXPECT_NEAR(p.nanoseconds[kTermLocations] + 16 * p.nanoseconds[kTermAttributeBytes], past14::kLocation, 0.01);
  EXPECT_NEAR(p.nanoseconds[kTermBufferVec4Loads], past14::kVec4, 0.01);
  EXPECT_LT(rmsRelativeError(p, testPlans), 0.001);
  // The Dawn face's choice: 16 locations, against 14 with the skin's two from a storage buffer (2 vec4
  // loads, 8 slots more). The device: 4.8 + 8 = 12.8 ns against 4.2 + 2.4 + 2.4 = 9.0 (the rest alike).
  TermAmounts attributes{}, buffered{};
  attributes[kTermVertices] = buffered[kTermVertices] = 1;
  attributes[kTermLocations] = 16, attributes[kTermAttributeBytes] = 256, attributes[kTermArithmetic] = 100;
  buffered[kTermLocations] = 14, buffered[kTermAttributeBytes] = 224, buffered[kTermArithmetic] = 108;
  buffered[kTermBufferVec4Loads] = 2;
  EXPECT_NEAR(p.predictNanoseconds(attributes, 180000) - p.predictNanoseconds(buffered, 180000), 12.8 - 9.0, 0.05);
  // Without a threshold the fit spreads the step over every location and keeps the attributes.
  const DeviceProfile plain = fitDeviceProfile(train, "past-14 device", 180000, 0, FitOptions{});
  EXPECT_TRUE(plain.thresholds.empty());
  EXPECT_LT(plain.predictNanoseconds(attributes, 180000), plain.predictNanoseconds(buffered, 180000));
  EXPECT_GT(rmsRelativeError(plain, testPlans), 0.02);
  // With the floors in the fit, whose inputs past 14 cost nothing more, no price fits both: the
  // plans are predicted worse.
  FitOptions withFloors = opts;
  withFloors.floors = true;
  const DeviceProfile floored = fitDeviceProfile(train, "past-14 device", 180000, 0, withFloors);
  EXPECT_GT(rmsRelativeError(floored, testPlans), 0.02);
  // A device without the step: no threshold kept.
  const DeviceProfile flat = fitDeviceProfile(past14::rows(1, 240, 0), "flat device", 180000, 0, opts);
  EXPECT_TRUE(flat.thresholds.empty());
  // Written and read back, the profile prices as fitted.
  CalibrationReport r;
  r.profile = p;
  r.floors = false;
  const std::string yaml = deviceProfileYaml(r);
  EXPECT_NE(yaml.find("not the floors'"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("thresholds:"), std::string::npos) << yaml;
  const DeviceProfile back = parseDeviceProfile(yaml, "past14.yaml");
  for (const auto& s : testPlans) EXPECT_NEAR(back.predictNanoseconds(s.amounts, 180000), p.predictNanoseconds(s.amounts, 180000), 1e-4);
}

// Two steps at once, on two terms (lavapipe's inputs past the 15th and buffer vec4 loads past the 18th):
// the fit finds both where each is and what each costs; with only the first, the second's price is
// spread over every load and the plans are predicted worse.
TEST(Calibrate, TwoThresholdsAreFittedTogether) {
  constexpr double kVec4Past = 2;
  const std::vector<CalibrationSample> train = past14::rows(3, 320, past14::kPast, kVec4Past);
  std::vector<CalibrationSample> testPlans = past14::rows(4, 80, past14::kPast, kVec4Past);
  std::erase_if(testPlans, [](const CalibrationSample& s) { return s.label.find("floor") != std::string::npos; });
  FitOptions opts;
  opts.thresholds = {kTermBufferVec4Loads, kTermLocations};  // in any order: the profile keeps term order
  opts.floors = false;
  const DeviceProfile p = fitDeviceProfile(train, "two-step device", 180000, 0, opts);
  ASSERT_EQ(p.thresholds.size(), 2u);
  EXPECT_EQ(p.thresholds[0].term, kTermLocations);
  EXPECT_EQ(p.thresholds[0].at, 14);
  EXPECT_NEAR(p.thresholds[0].nanoseconds, past14::kPast, 0.01);
  EXPECT_EQ(p.thresholds[1].term, kTermBufferVec4Loads);
  EXPECT_EQ(p.thresholds[1].at, 12);
  EXPECT_NEAR(p.thresholds[1].nanoseconds, kVec4Past, 0.01);
  EXPECT_NEAR(p.nanoseconds[kTermBufferVec4Loads], past14::kVec4, 0.01);
  EXPECT_LT(rmsRelativeError(p, testPlans), 0.001);
  FitOptions one = opts;
  one.thresholds = {kTermLocations};
  const DeviceProfile onlyInputs = fitDeviceProfile(train, "two-step device", 180000, 0, one);
  ASSERT_EQ(onlyInputs.thresholds.size(), 1u);
  EXPECT_GT(rmsRelativeError(onlyInputs, testPlans), 0.01);
  // Twenty vec4 loads against twelve: the device pays 8 x (1.2 + 2) = 25.6 ns more, each load past 12 at
  // its price and the step's; the one-threshold fit prices the eight well below that.
  TermAmounts many{}, few{};
  many[kTermVertices] = few[kTermVertices] = 1;
  many[kTermBufferVec4Loads] = 20, few[kTermBufferVec4Loads] = 12;
  EXPECT_NEAR(p.predictNanoseconds(many, 180000) - p.predictNanoseconds(few, 180000), 8 * (past14::kVec4 + kVec4Past), 0.1);
  EXPECT_LT(onlyInputs.predictNanoseconds(many, 180000) - onlyInputs.predictNanoseconds(few, 180000), 8 * (past14::kVec4 + kVec4Past) - 1);
}

// A device whose large draws pay more per location and per vertex than its small ones (its
// attributes stream from memory instead of a cache), with one price per fragment at every size.
std::vector<CalibrationSample> twoSizeRows(uint32_t seed, int n) {
  std::vector<CalibrationSample> out = rasterRows(seed, n, 0.05);
  for (auto& s : out) {
    roofline::Device d;
    d.drawNs = 0;
    if (s.vertices > 10000) d.location = 0.5, d.vertexNs = 0.5;
    else d.location = 0.25, d.vertexNs = 0.3;
    s.measuredNs = d.ns(s.amounts, s.vertices, s.workload.jointsPerWarp) + 0.05 * s.workload.fragmentsPerVertex;
  }
  return out;
}

TEST(Calibrate, DrawSizesFitEachMeshSizesWeightsAndBlendThemInLogVertices) {
  const std::vector<CalibrationSample> train = twoSizeRows(1, 200), test = twoSizeRows(2, 80);
  const DeviceProfile sized = fitDeviceProfile(train, "two-size device", 180000, 0, FitOptions(ProfileForm::Raster, false, true));
  const DeviceProfile plain = fitDeviceProfile(train, "two-size device", 180000, 0, ProfileForm::Raster);
  ASSERT_EQ(sized.drawSizes.size(), 2u);
  EXPECT_TRUE(plain.drawSizes.empty());
  EXPECT_EQ(sized.drawSizes[0].vertices, 2009);
  EXPECT_EQ(sized.drawSizes[1].vertices, 180000);
  EXPECT_NEAR(sized.drawSizes[0].pipes[0].nanoseconds[kTermLocations], 0.25, 0.01);
  EXPECT_NEAR(sized.drawSizes[1].pipes[0].nanoseconds[kTermLocations], 0.5, 0.01);
  EXPECT_NEAR(sized.drawSizes[0].nanoseconds[kTermVertices], 0.3, 0.03);
  EXPECT_NEAR(sized.drawSizes[1].nanoseconds[kTermVertices], 0.5, 0.03);
  // A fragment's price is one at every size (a large draw covers too few to price its own).
  EXPECT_EQ(sized.drawSizes[0].nanoseconds[kTermFragments], sized.drawSizes[1].nanoseconds[kTermFragments]);
  EXPECT_NEAR(sized.drawSizes[0].nanoseconds[kTermFragments], 0.05, 0.002);
  EXPECT_LT(rmsRelativeError(sized, test), 0.01);
  EXPECT_GT(rmsRelativeError(plain, test), 0.05);
  // Between the sizes a weight is the log-vertices blend of the two; outside, the nearest size's.
  const double t = std::log(18000.0 / 2009) / std::log(180000.0 / 2009);
  const DeviceProfile mid = sized.atDrawSize(18000);
  EXPECT_EQ(mid.verticesPerDraw, 18000);
  for (int k : {kTermVertices, kTermFragments})
    EXPECT_NEAR(mid.nanoseconds[size_t(k)], (1 - t) * sized.drawSizes[0].nanoseconds[size_t(k)] + t * sized.drawSizes[1].nanoseconds[size_t(k)], 1e-12);
  EXPECT_NEAR(mid.pipes[0].nanoseconds[kTermLocations],
              (1 - t) * sized.drawSizes[0].pipes[0].nanoseconds[kTermLocations] + t * sized.drawSizes[1].pipes[0].nanoseconds[kTermLocations], 1e-12);
  EXPECT_EQ(sized.atDrawSize(500).pipes[0].nanoseconds[kTermLocations], sized.drawSizes[0].pipes[0].nanoseconds[kTermLocations]);
  EXPECT_EQ(sized.atDrawSize(1e6).pipes[0].nanoseconds[kTermLocations], sized.drawSizes[1].pipes[0].nanoseconds[kTermLocations]);
  // The search prices a generation at its draw's size: the components are that size's weights.
  const std::vector<TermWeights> small = profileComponents(sized.atDrawSize(2009));
  EXPECT_EQ(small[0][kTermLocations], std::llround(sized.drawSizes[0].pipes[0].nanoseconds[kTermLocations] * kFemtosecondsPerNanosecond));
  // Written and read back, it predicts the same at every size, the blend included.
  CalibrationReport r;
  r.profile = sized;
  const std::string yaml = deviceProfileYaml(r);
  EXPECT_NE(yaml.find("draw_sizes:"), std::string::npos);
  const DeviceProfile back = parseDeviceProfile(yaml, "sized.yaml");
  ASSERT_EQ(back.drawSizes.size(), 2u);
  EXPECT_EQ(back.verticesPerDraw, 180000);
  for (const auto& s : test)
    for (double v : {s.vertices, 18000.0}) {
      DeviceProfile a = sized, b = back;
      a.workload = b.workload = s.workload;
      EXPECT_NEAR(b.predictNanoseconds(s.amounts, v), a.predictNanoseconds(s.amounts, v), 1e-5 * s.measuredNs);
    }
  // One mesh size has nothing to blend: no draw sizes.
  std::vector<CalibrationSample> one;
  for (const auto& s : train)
    if (s.vertices == 2009) one.push_back(s);
  EXPECT_TRUE(fitDeviceProfile(one, "one size", 2009, 0, FitOptions(ProfileForm::Raster, false, true)).drawSizes.empty());
}

TEST(Calibrate, AProfileWithoutPerDrawWeightsKeepsItsScalingWhenWritten) {
  // One mesh size fits no per-draw weight; the profile's workload scaling (a uniform load at a
  // per-vertex index costs per joint a warp reads) and its default must still be written, or
  // the file read back prices those loads 4x cheaper here (before session 17 they were lost).
  DeviceProfile p = profileForm(ProfileForm::Additive);
  p.device = "one size";
  p.nanoseconds[kTermVertices] = 2;
  p.nanoseconds[kTermIndexedUniformLoads] = 0.1;
  p.workloadDefaults[kFeatureJointsPerWarp] = 4;
  ASSERT_FALSE(p.hasDrawWeights());
  CalibrationReport r;
  r.profile = p;
  const DeviceProfile back = parseDeviceProfile(deviceProfileYaml(r), "one-size.yaml");
  EXPECT_EQ(back.scaledBy[kTermIndexedUniformLoads], kFeatureJointsPerWarp);
  TermAmounts a{};
  a[kTermVertices] = 1;
  a[kTermIndexedUniformLoads] = 16;
  EXPECT_DOUBLE_EQ(p.predictNanoseconds(a, 1000), 2 + 16 * 0.1 * 4);
  EXPECT_DOUBLE_EQ(back.predictNanoseconds(a, 1000), p.predictNanoseconds(a, 1000));
}

TEST(Calibrate, SpearmanTreatsTimesWithinTheSpreadAsTies) {
  // Measured 1.000 and 1.004 are one tie at a 0.5 % spread: ranks (1.5, 1.5, 3) against the
  // predictions' (1, 2, 3) correlate at sqrt(3)/2 (Pearson of the ranks), not 1.
  std::vector<double> predicted{1, 2, 3}, measured{1.0, 1.004, 2.0};
  EXPECT_DOUBLE_EQ(spearman(predicted, measured), 1.0);
  EXPECT_NEAR(spearmanWithinSpread(predicted, measured, 0.005), std::sqrt(3.0) / 2, 1e-12);
  EXPECT_DOUBLE_EQ(spearmanWithinSpread(predicted, measured, 0.001), 1.0);
}

}  // namespace
}  // namespace sg

// calibrate times the plans the device's limits allow, as bench --device does: lavapipe's
// 64 KiB uniform block holds the 300-bone palette (19,200 bytes), which the portable 16 KiB
// default does not, so a plan reading it from the uniform block at a per-vertex index is timed.
namespace sg {
TEST(Calibrate, TimesThePlansTheDevicesLimitsAllow) {
  CalibrationOptions o = testing::quickCalibration();
  o.probes = false;
  o.check = false;
  o.validationLayers = false;
  o.rigs = {std::string(SG_SOURCE_DIR) + "/tests/validate/data/limb8_palette300.rig.yaml"};
  o.plans.fragmentPath = std::string(SG_SOURCE_DIR) + "/tests/validate/data/world.frag";
  o.plans.rulesPaths = {std::string(SG_SOURCE_DIR) + "/rules/standard.yaml"};
  const CalibrationReport r = calibrateDevice(o);
  size_t uniformPalette = 0;
  for (const auto& s : r.samples) {
    EXPECT_TRUE(s.validated) << s.label << ": " << s.failure;
    uniformPalette += s.amounts[kTermIndexedUniformLoads] > 0;
  }
  EXPECT_GT(uniformPalette, 0u);
}

TEST(Calibrate, TheCheckStatesTheChosenPlansRatioWithinEachRound) {
  // Two rounds: each check line gives the chosen plan over the fastest within each round too,
  // the figures generatedOverFastestByRound takes from that rig's bench.
  CalibrationOptions o = testing::quickCalibration();
  o.rounds = 2;
  o.probes = false;
  o.validationLayers = false;
  o.rigs = {std::string(SG_SOURCE_DIR) + "/tests/validate/data/limb16.rig.yaml"};
  o.plans.fragmentPath = std::string(SG_SOURCE_DIR) + "/tests/validate/data/world.frag";
  o.plans.rulesPaths = {std::string(SG_SOURCE_DIR) + "/rules/standard.yaml"};
  CalibrationReport r = calibrateDevice(o);
  ASSERT_FALSE(r.checks.empty());
  // What a driver names of what it compiled is logged with the sample (lavapipe 22.3 names none).
  const std::string statistics = "Register Count=40; VS fast: Binary Size=4096";
  for (auto& s : r.samples) {
    if (s.validated) {
      s.driverStatistics = statistics;
      break;
    }
  }
  const std::string text = formatCalibration(r);
  // Each timed sample records its median round too, at or above its best; the log keeps it.
  std::istringstream log(text);
  const std::vector<CalibrationSample> back = parseCalibrationSamples(log, {}, "");
  ASSERT_FALSE(back.empty());
  size_t timed = 0;
  for (const auto& s : r.samples) {
    if (!s.validated) continue;
    ++timed;
    EXPECT_GE(s.medianRoundNs, s.measuredNs) << s.label;
  }
  EXPECT_EQ(back.size(), timed);
  for (const auto& s : back) EXPECT_GE(s.medianRoundNs, s.measuredNs) << s.label;
  // And the program each row timed (its SPIR-V's hash), for the held-out check to match across runs.
  std::vector<std::string> programs;
  for (const auto& s : r.samples)
    if (s.validated) programs.push_back(s.program);
  for (size_t i = 0; i < back.size() && i < programs.size(); ++i) {
    EXPECT_EQ(back[i].program, programs[i]) << back[i].label;
    EXPECT_EQ(back[i].program.size(), 16u) << back[i].label;
  }
  size_t withStatistics = 0;
  for (const auto& s : back) withStatistics += s.driverStatistics == statistics;
  EXPECT_EQ(withStatistics, 1u);
  for (const auto& c : r.checks) {
    ASSERT_GT(c.plans, 1u) << c.rig;
    EXPECT_EQ(c.byRound.rounds, 2u) << c.rig;
    EXPECT_LE(c.byRound.least, c.byRound.most) << c.rig;
    EXPECT_GE(c.byRound.least, 1.0) << c.rig;  // no plan is faster than the fastest within a round
    EXPECT_NE(text.find(fmt::format("(within one round: {:.3f}x to {:.3f}x over 2 rounds)", c.byRound.least, c.byRound.most)),
              std::string::npos);
  }
}

TEST(Calibrate, TheLimbMeshTimesProbesAndPlansAtTheLimbsSize) {
  // A small draw beside Dawn scale and the head: probes and plans alike at 825 vertices, so the
  // per-draw weights see one size; every probe and plan still validated first.
  CalibrationOptions o = testing::quickCalibration();
  o.meshes = {"limb"};
  o.check = false;
  o.validationLayers = false;
  o.rigs = {std::string(SG_SOURCE_DIR) + "/tests/validate/data/limb16.rig.yaml"};
  o.plans.fragmentPath = std::string(SG_SOURCE_DIR) + "/tests/validate/data/world.frag";
  o.plans.rulesPaths = {std::string(SG_SOURCE_DIR) + "/rules/standard.yaml"};
  const CalibrationReport r = calibrateDevice(o);
  size_t probes = 0, plans = 0;
  for (const auto& s : r.samples) {
    EXPECT_TRUE(s.validated) << s.label << ": " << s.failure;
    EXPECT_EQ(s.mesh, "limb") << s.label;
    EXPECT_EQ(s.vertices, 825) << s.label;
    (s.rig.empty() ? probes : plans) += 1;
  }
  EXPECT_GT(probes, 5u);
  EXPECT_GT(plans, 2u);
  // What one raster-on draw of the limb made the device shade: every vertex is referenced, so
  // shaded at least once, and at most once per triangle of the limb's grid that holds it (6);
  // the limb covers pixels. The log keeps both figures.
  for (const auto& s : r.samples) {
    EXPECT_GE(s.shadedPerVertex, 1.0) << s.label;
    EXPECT_LE(s.shadedPerVertex, 6.0) << s.label;
    EXPECT_GT(s.workload.fragmentsPerVertex, 0.0) << s.label;
  }
  std::istringstream log(formatCalibration(r));
  const std::vector<CalibrationSample> back = parseCalibrationSamples(log, {}, "");
  ASSERT_EQ(back.size(), r.samples.size());
  size_t wider = 0;  // samples whose warps read more palette entries over all slots than in one
  for (size_t i = 0; i < back.size(); ++i) {
    EXPECT_NEAR(back[i].shadedPerVertex, r.samples[i].shadedPerVertex, 1e-4) << back[i].label;
    EXPECT_NEAR(back[i].workload.fragmentsPerVertex, r.samples[i].workload.fragmentsPerVertex, 1e-4) << back[i].label;
    // The palette footprint is logged with the timing (a later fit's feature), and no smaller
    // than the joints one slot reads.
    EXPECT_NEAR(back[i].workload.paletteEntriesPerWarp, r.samples[i].workload.paletteEntriesPerWarp, 1e-4) << back[i].label;
    EXPECT_GE(r.samples[i].workload.paletteEntriesPerWarp, r.samples[i].workload.jointsPerWarp) << back[i].label;
    wider += r.samples[i].workload.paletteEntriesPerWarp > r.samples[i].workload.jointsPerWarp + 0.5;
  }
  EXPECT_GT(wider, 0u);  // the 16-influence limb: its slots index different joints
  // The log says how it was timed.
  EXPECT_NE(formatCalibration(r).find("over 1 draws per frame (a smaller mesh more: at least 0 vertices), median of 1 frames"),
            std::string::npos);
}
}  // namespace sg

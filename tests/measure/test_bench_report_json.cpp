// A bench report handed from a fresh process to its parent (measure/bench_report_json.h): every
// field comes back as it was written, NaN included, and an input error comes back as that error.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "measure/bench_report_json.h"

namespace sg {
namespace {

// Equal, or both NaN.
void same(double a, double b, const char* what) {
  if (std::isnan(a)) {
    EXPECT_TRUE(std::isnan(b)) << what;
  } else {
    EXPECT_EQ(a, b) << what;  // bit-exact: the JSON writer gives the shortest text that reads back the same double
  }
}

GpuBenchReport everyFieldSet() {
  GpuBenchReport r;
  r.device = "NVIDIA H100 80GB HBM3";
  r.driver = "NVIDIA 580.159.04 (\"quoted\")";
  r.limits = "limits of the device: 16 attributes";
  r.vertices = 3273;
  r.triangles = 4672;
  r.workload = {3273, 3.4809, 2, 2.8967, "model 'CesiumMan.glb#0/0'", 30.5775, 6.5825};
  r.shadedVerticesPerVertex = 2.8967;
  r.drawsPerFrame = 20;
  r.frames = 7;
  r.rounds = 2;
  r.width = 256;
  r.height = 128;
  for (int i = 0; i < 3; ++i) {
    GpuBenchRow row;
    row.label = i == 0 ? "generated" : "forced skin_matrix_blend_buffer_palette for skin.matrix";
    row.rules = {"skin_matrix_blend", "object_position_skinned"};
    row.bans = i == 0 ? std::vector<std::string>{} : std::vector<std::string>{"skin_matrix_blend"};
    row.hasCost = i < 2;
    row.hasAmounts = true;
    row.planCost = 97 + i;
    row.spirvInstructions = 412;
    row.program = i == 0 ? "9fff1df2c2f42099" : "";
    // As a driver may give them: a second vertex executable, a fraction, a 64-bit count.
    if (i == 0) row.driverStatistics = {{"VS", "Register Count", 40}, {"VS, fast path", "Register Count", 0.5}, {"VS", "Instructions", 9007199254740993.0}};
    row.validation = i == 2 ? "FAIL: output 3 differs" : "pass";
    for (size_t t = 0; t < row.amounts.size(); ++t) row.amounts[t] = int64_t(t * 7 + i) - 3;
    row.predictedNsPerVertex = i == 1 ? -1 : 0.1 + 0.2;  // 0.30000000000000004: no decimal rounding
    row.rasterOnNsPerVertex = 6.1872 + i;
    row.rasterOffNsPerVertex = -1;
    row.rasterOnWallNsPerVertex = 1e-300;
    row.rasterOffCpuNsPerVertex = std::numeric_limits<double>::max();
    row.rasterOffWallNsPerVertex = 3.0 / 7.0;
    row.roundNsPerVertex = {6.19, 6.2, 1.0 / 3.0};
    r.rows.push_back(row);
  }
  r.pearsonOn = 0.91;
  r.spearmanOn = NAN;
  r.pearsonOff = -0.5;
  r.spearmanOff = 1;
  r.pearsonOffWall = NAN;
  r.spearmanOffWall = 0.25;
  r.spearmanPredictedOn = NAN;
  r.generatedOverFastestOn = 1.2341234123412341;
  r.byRound = {1.087, NAN, 6};
  r.predictionClock = "raster on, GPU timestamps";
  r.inputMemory = "inputs: device-local (a staging copy), in type 1";
  r.fastestPlan = 1;
  r.fastestOverGenerated = 0.8;
  r.notes = {{Severity::Warning, {"RobotExpressive.glb", 0, 0}, "weights renormalised", "ACCESSOR_WEIGHTS_NON_NORMALIZED"},
             {Severity::Note, {"rig.yaml", 12, 3}, "the plan reads vertex.tangent_octahedral", ""}};
  return r;
}

TEST(BenchReportJson, EveryFieldComesBackAsWritten) {
  const GpuBenchReport a = everyFieldSet();
  const GpuBenchReport b = benchReportFromJson(benchReportJson(a));
  EXPECT_EQ(a.device, b.device);
  EXPECT_EQ(a.driver, b.driver);
  EXPECT_EQ(a.limits, b.limits);
  EXPECT_EQ(a.vertices, b.vertices);
  EXPECT_EQ(a.triangles, b.triangles);
  same(a.workload.verticesPerDraw, b.workload.verticesPerDraw, "verticesPerDraw");
  same(a.workload.jointsPerWarp, b.workload.jointsPerWarp, "jointsPerWarp");
  same(a.workload.activeMorphTargets, b.workload.activeMorphTargets, "activeMorphTargets");
  same(a.workload.invocationsPerVertex, b.workload.invocationsPerVertex, "invocationsPerVertex");
  EXPECT_EQ(a.workload.source, b.workload.source);
  same(a.workload.fragmentsPerVertex, b.workload.fragmentsPerVertex, "fragmentsPerVertex");
  same(a.workload.paletteEntriesPerWarp, b.workload.paletteEntriesPerWarp, "paletteEntriesPerWarp");
  same(a.shadedVerticesPerVertex, b.shadedVerticesPerVertex, "shadedVerticesPerVertex");
  EXPECT_EQ(a.drawsPerFrame, b.drawsPerFrame);
  EXPECT_EQ(a.frames, b.frames);
  EXPECT_EQ(a.rounds, b.rounds);
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  ASSERT_EQ(a.rows.size(), b.rows.size());
  for (size_t i = 0; i < a.rows.size(); ++i) {
    const GpuBenchRow &x = a.rows[i], &y = b.rows[i];
    EXPECT_EQ(x.label, y.label);
    EXPECT_EQ(x.rules, y.rules);
    EXPECT_EQ(x.bans, y.bans);
    EXPECT_EQ(x.hasCost, y.hasCost);
    EXPECT_EQ(x.hasAmounts, y.hasAmounts);
    EXPECT_EQ(x.planCost, y.planCost);
    EXPECT_EQ(x.spirvInstructions, y.spirvInstructions);
    EXPECT_EQ(x.program, y.program);
    ASSERT_EQ(x.driverStatistics.size(), y.driverStatistics.size());
    for (size_t k = 0; k < x.driverStatistics.size(); ++k) {
      EXPECT_EQ(x.driverStatistics[k].executable, y.driverStatistics[k].executable);
      EXPECT_EQ(x.driverStatistics[k].name, y.driverStatistics[k].name);
      same(x.driverStatistics[k].value, y.driverStatistics[k].value, "driver statistic");
    }
    EXPECT_EQ(x.validation, y.validation);
    EXPECT_EQ(x.amounts, y.amounts);
    same(x.predictedNsPerVertex, y.predictedNsPerVertex, "predicted");
    same(x.rasterOnNsPerVertex, y.rasterOnNsPerVertex, "raster on");
    same(x.rasterOffNsPerVertex, y.rasterOffNsPerVertex, "raster off");
    same(x.rasterOnWallNsPerVertex, y.rasterOnWallNsPerVertex, "raster on, wall");
    same(x.rasterOffCpuNsPerVertex, y.rasterOffCpuNsPerVertex, "raster off, CPU");
    same(x.rasterOffWallNsPerVertex, y.rasterOffWallNsPerVertex, "raster off, wall");
    EXPECT_EQ(x.roundNsPerVertex, y.roundNsPerVertex);
  }
  same(a.pearsonOn, b.pearsonOn, "pearsonOn");
  same(a.spearmanOn, b.spearmanOn, "spearmanOn");
  same(a.pearsonOff, b.pearsonOff, "pearsonOff");
  same(a.spearmanOff, b.spearmanOff, "spearmanOff");
  same(a.pearsonOffWall, b.pearsonOffWall, "pearsonOffWall");
  same(a.spearmanOffWall, b.spearmanOffWall, "spearmanOffWall");
  same(a.spearmanPredictedOn, b.spearmanPredictedOn, "spearmanPredictedOn");
  same(a.generatedOverFastestOn, b.generatedOverFastestOn, "generatedOverFastestOn");
  same(a.byRound.least, b.byRound.least, "byRound.least");
  same(a.byRound.most, b.byRound.most, "byRound.most");
  EXPECT_EQ(a.byRound.rounds, b.byRound.rounds);
  EXPECT_EQ(a.predictionClock, b.predictionClock);
  EXPECT_EQ(a.inputMemory, b.inputMemory);
  EXPECT_EQ(a.fastestPlan, b.fastestPlan);
  same(a.fastestOverGenerated, b.fastestOverGenerated, "fastestOverGenerated");
  ASSERT_EQ(a.notes.size(), b.notes.size());
  for (size_t i = 0; i < a.notes.size(); ++i) EXPECT_EQ(formatDiagnostic(a.notes[i]), formatDiagnostic(b.notes[i]));
  // The same report, the same text: what a fresh process writes is deterministic.
  EXPECT_EQ(benchReportJson(a), benchReportJson(b));
}

TEST(BenchReportJson, AnInputErrorComesBackAsThatError) {
  InputError e(SourceLoc{"limb.rig.yaml", 4, 9}, "unknown semantic 'skin.wieghts'");
  e.related.push_back({Severity::Note, {"rules.yaml", 30, 1}, "did you mean 'skin.weights'?", ""});
  try {
    benchReportFromJson(inputErrorJson(e));
    FAIL() << "no error thrown";
  } catch (const InputError& back) {
    EXPECT_EQ(formatDiagnostic(back.diagnostic()), "limb.rig.yaml:4:9: error: unknown semantic 'skin.wieghts'");
    ASSERT_EQ(back.related.size(), 1u);
    EXPECT_EQ(formatDiagnostic(back.related[0]), formatDiagnostic(e.related[0]));
  }
}

TEST(BenchReportJson, TextThatIsNoReportIsRefused) {
  for (const char* text : {"", "{", "[]", "{\"device\": \"x\"}", "{\"input_error\": {\"severity\": 9}}"})
    EXPECT_THROW(benchReportFromJson(text), std::runtime_error) << text;
}

}  // namespace
}  // namespace sg

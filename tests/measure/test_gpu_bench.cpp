// shadergen bench's parts that decide what its numbers mean: the correlations against
// independent textbook values, and the hand port's capture build, whose outputs on lavapipe
// must equal the generated shader's (otherwise the hand port row times something else).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <regex>
#include <set>

#include "common/input_file.h"
#include "measure/gpu_bench.h"
#include "pipeline/generate.h"
#include "runtime/procedural.h"
#include "test_util.h"

namespace {

using namespace sgtest;

TEST(GpuBench, CorrelationsMatchHandComputedValues) {
  // x = 1..5, y = 2, 4, 5, 4, 5: Pearson r = 6 / sqrt(10 * 6) = 0.7746 (by hand).
  EXPECT_NEAR(sg::pearson({1, 2, 3, 4, 5}, {2, 4, 5, 4, 5}), 6.0 / std::sqrt(60.0), 1e-12);
  // Spearman with ties: ranks of y are 0, 1.5, 3.5, 1.5, 3.5 (mean ranks).
  EXPECT_NEAR(sg::spearman({1, 2, 3, 4, 5}, {2, 4, 5, 4, 5}), sg::pearson({0, 1, 2, 3, 4}, {0, 1.5, 3.5, 1.5, 3.5}), 1e-12);
  EXPECT_NEAR(sg::spearman({1, 2, 3, 4}, {1, 8, 27, 64}), 1.0, 1e-12);  // monotone, not linear
  EXPECT_LT(sg::pearson({1, 2, 3, 4}, {1, 8, 27, 64}), 1.0);
  EXPECT_NEAR(sg::pearson({1, 2, 3}, {3, 2, 1}), -1.0, 1e-12);
  EXPECT_TRUE(std::isnan(sg::pearson({1, 2}, {1, 2})));        // too few points
  EXPECT_TRUE(std::isnan(sg::pearson({1, 1, 1}, {1, 2, 3})));  // no variance
}

TEST(GpuBench, PredictionsAreCheckedByTheClockAsked) {
  // Three plans (the generated one first), a floor, a plan that failed validation and one not
  // timed by the second clock; each clock sees only the plans it timed that passed.
  auto row = [](const char* label, bool cost, const char* validation, double predicted, double on, double cpu) {
    sg::GpuBenchRow r;
    r.label = label;
    r.hasCost = cost;
    r.validation = validation;
    r.predictedNsPerVertex = predicted;
    r.rasterOnNsPerVertex = on;
    r.rasterOffCpuNsPerVertex = cpu;
    return r;
  };
  const std::vector<sg::GpuBenchRow> rows = {
      row("generated", true, "pass", 1.5, 2.0, 1.0), row("a", true, "pass", 1.0, 1.0, 2.0),
      row("b", true, "pass", 3.0, 3.0, 3.0),         row("floor", false, "", 0.1, 0.1, 0.1),
      row("failed", true, "FAIL: x", 0.1, 0.1, 0.1), row("c", true, "pass", 9.0, 9.0, -1)};
  // Raster on: predictions rank like the times (1, 2, 3, 9); the generated takes 2 / 1.
  const sg::PredictionCheck on = sg::checkPredictions(rows, &sg::GpuBenchRow::rasterOnNsPerVertex);
  EXPECT_EQ(on.plans, 4u);
  EXPECT_DOUBLE_EQ(on.spearman, 1.0);
  EXPECT_DOUBLE_EQ(on.generatedOverFastest, 2.0);
  // CPU time (c untimed): predicted ranks (1, 0, 2) against measured (0, 1, 2): Pearson of
  // the ranks = 1 / 2 by hand; the generated program is the fastest.
  const sg::PredictionCheck cpu = sg::checkPredictions(rows, &sg::GpuBenchRow::rasterOffCpuNsPerVertex);
  EXPECT_EQ(cpu.plans, 3u);
  EXPECT_NEAR(cpu.spearman, 0.5, 1e-12);
  EXPECT_DOUBLE_EQ(cpu.generatedOverFastest, 1.0);
}

// A row as the round checks see it: a plan (cost) or not, its validation, its time in each round.
sg::GpuBenchRow roundsRow(const char* label, bool cost, const char* validation, std::vector<double> rounds) {
  sg::GpuBenchRow r;
  r.label = label;
  r.hasCost = cost;
  r.validation = validation;
  r.roundNsPerVertex = std::move(rounds);
  return r;
}

TEST(GpuBench, TheGeneratedOverTheFastestIsAlsoTakenWithinEachRound) {
  // Three rounds; within each, the generated program's time over the fastest passing plan's:
  // round 0: 10 / 8 = 1.25 (b fastest); round 1: 9 / 9 = 1 (itself); round 2: 12 / 10 = 1.2.
  // A floor and a failed plan are not plans to beat; neither is a row timed in fewer rounds
  // (then the rounds every plan has count: here all three).
  std::vector<sg::GpuBenchRow> rows = {
      roundsRow("generated", true, "pass", {10, 9, 12}), roundsRow("a", true, "pass", {11, 9.5, 10}),
      roundsRow("b", true, "pass", {8, 10, 13}), roundsRow("floor", false, "", {1, 1, 1}),
      roundsRow("failed", true, "FAIL: x", {1, 1, 1})};
  sg::RoundSpread s = sg::generatedOverFastestByRound(rows);
  EXPECT_EQ(s.rounds, 3u);
  EXPECT_DOUBLE_EQ(s.least, 1.0);
  EXPECT_DOUBLE_EQ(s.most, 1.25);
  rows[1].roundNsPerVertex.pop_back();  // a timed in two rounds: round 2 is not compared
  s = sg::generatedOverFastestByRound(rows);
  EXPECT_EQ(s.rounds, 2u);
  EXPECT_DOUBLE_EQ(s.most, 1.25);
  rows[1].roundNsPerVertex = {7};  // one round: no spread to state
  s = sg::generatedOverFastestByRound(rows);
  EXPECT_TRUE(std::isnan(s.least) && std::isnan(s.most));
}

TEST(GpuBench, APinTakesThePlanWhoseMedianRoundIsFastest) {
  // Medians: generated 10, a 9.5 (one round read far low: best round 3), b 9 (one slow round:
  // slowest 20), c 9.8. The best round would pin a, the slowest round c; the median pins b.
  // Floors, failed plans and plans never timed are not pinned.
  sg::GpuBenchReport rep;
  rep.rows = {roundsRow("generated", true, "pass", {10, 10, 10}), roundsRow("a", true, "pass", {3, 9.5, 9.6}),
              roundsRow("b", true, "pass", {9, 20, 8.9}),         roundsRow("c", true, "pass", {9.8, 9.8, 9.9}),
              roundsRow("floor", false, "", {1, 1, 1}),           roundsRow("failed", true, "FAIL: x", {1, 1, 1}),
              roundsRow("untimed", true, "pass", {})};
  EXPECT_EQ(sg::pinnedPlan(rep), 2);
  EXPECT_DOUBLE_EQ(sg::medianRound(rep.rows[2]), 9.0);
  EXPECT_TRUE(std::isnan(sg::medianRound(rep.rows[6])));
  rep.rows.resize(1);
  EXPECT_EQ(sg::pinnedPlan(rep), 0);  // alone, the generated plan is its own pin
  rep.rows[0].validation = "FAIL: y";
  EXPECT_EQ(sg::pinnedPlan(rep), -1);
}

TEST(GpuBench, ProcessesMergeTheirRoundsSoOneSlowProcessDoesNotPick) {
  // What lavapipe did (docs/performance.md, --processes): one process of three ran the fastest
  // plan, b, 25 % slower in every round. Alone, that process pins a; the three merged pin b
  // (its median round over 9 is 8, a's 9). Each figure is the best over every process.
  auto run = [](std::vector<double> a, std::vector<double> b) {
    sg::GpuBenchReport r;
    r.device = "llvmpipe";
    r.predictionClock = sg::kClockCpuRasterOff;
    r.rounds = 3;
    r.rows = {roundsRow("a", true, "pass", a), roundsRow("b", true, "pass", b)};
    for (auto& row : r.rows) {
      row.program = row.label == "a" ? "aaaa" : "bbbb";
      row.rasterOffCpuNsPerVertex = *std::min_element(row.roundNsPerVertex.begin(), row.roundNsPerVertex.end());
    }
    return r;
  };
  const sg::GpuBenchReport slow = run({9, 9, 9.1}, {10, 10, 10.1});
  EXPECT_EQ(sg::pinnedPlan(slow), 0);
  const sg::GpuBenchReport merged = sg::mergeProcessRuns({slow, run({9, 8.9, 9}, {8, 8.1, 8}), run({9.2, 9, 9}, {8, 7.9, 8})});
  EXPECT_EQ(sg::pinnedPlan(merged), 1);
  EXPECT_EQ(merged.processes, 3u);
  EXPECT_EQ(merged.rounds, 9u);
  ASSERT_EQ(merged.rows[1].roundNsPerVertex.size(), 9u);
  EXPECT_DOUBLE_EQ(sg::medianRound(merged.rows[1]), 8.0);
  EXPECT_DOUBLE_EQ(merged.rows[1].rasterOffCpuNsPerVertex, 7.9);
  EXPECT_DOUBLE_EQ(merged.rows[0].rasterOffCpuNsPerVertex, 8.9);
  EXPECT_EQ(merged.fastestPlan, 1);  // the summary is taken again over the merged rows
  // A failure in any process is the row's; runs of other programs are not merged.
  sg::GpuBenchReport failed = run({9, 9, 9}, {8, 8, 8});
  failed.rows[0].validation = "FAIL: out";
  EXPECT_EQ(sg::mergeProcessRuns({slow, failed}).rows[0].validation, "FAIL: out");
  sg::GpuBenchReport other = run({9, 9, 9}, {8, 8, 8});
  other.rows[1].program = "cccc";
  EXPECT_THROW(sg::mergeProcessRuns({slow, other}), std::runtime_error);
  other.rows.pop_back();
  EXPECT_THROW(sg::mergeProcessRuns({slow, other}), std::runtime_error);
}

TEST(GpuBench, CandidatesTheObjectiveCannotRankAreThoseItsDifferencesDoNotShowIn) {
  // Session 38's H100 hand, the 4 cheapest: plan costs 4.389, 4.967, 5.312, 5.476 (24.8 %
  // apart) and its check run's times 5.2265..5.2395 ns (0.25 % apart): the device shows under a tenth of
  // what the objective predicts, so it cannot rank them. Floors and failed plans do not count.
  auto row = [](const char* label, int64_t cost, double ns) {
    sg::GpuBenchRow r = roundsRow(label, true, "pass", {ns, ns * 1.01, ns * 0.99});
    r.planCost = cost;
    return r;
  };
  sg::GpuBenchReport hand;
  hand.rows = {row("generated", 4388891, 5.2305), row("#2", 4966655, 5.2265), row("#3", 5311831, 5.2395),
               row("#4", 5476447, 5.2335), roundsRow("floor", false, "", {1, 1, 1})};
  hand.rows.push_back(row("failed", 100, 1));
  hand.rows.back().validation = "FAIL: out";
  sg::CandidateRanking c = sg::rankCandidates(hand);
  EXPECT_EQ(c.plans, 4u);
  EXPECT_NEAR(c.predictedSpread, 5476447.0 / 4388891.0 - 1, 1e-12);
  EXPECT_NEAR(c.measuredSpread, 5.2395 / 5.2265 - 1, 1e-12);
  EXPECT_TRUE(c.cannotRank);
  // The device showing a tenth of the predicted spread (or more) ranks them: 24.8 % predicted, 2.5 % measured.
  hand.rows[3].roundNsPerVertex = {5.2265 * (1 + 0.1 * c.predictedSpread) * 1.0001};
  EXPECT_FALSE(sg::rankCandidates(hand).cannotRank);
  // Predicted within 5 %: nothing to rank, whatever the device shows.
  sg::GpuBenchReport close;
  close.rows = {row("generated", 1000, 5.0), row("#2", 1049, 5.0)};
  EXPECT_NEAR(sg::rankCandidates(close).predictedSpread, 0.049, 1e-12);
  EXPECT_FALSE(sg::rankCandidates(close).cannotRank);
  close.rows[1].planCost = 1050;
  EXPECT_TRUE(sg::rankCandidates(close).cannotRank);
  // One plan, or a cost of 0 (a profile that prices nothing here): no spread to judge.
  close.rows.pop_back();
  EXPECT_TRUE(std::isnan(sg::rankCandidates(close).predictedSpread));
  EXPECT_FALSE(sg::rankCandidates(close).cannotRank);
  close.rows = {row("generated", 0, 5.0), row("#2", 100, 5.0)};
  EXPECT_FALSE(sg::rankCandidates(close).cannotRank);
}

TEST(GpuBench, CaptureQualifiersGoOnEveryOutputAndUnknownOutputsAreErrors) {
  sg::EmittedGlsl capture;
  capture.captureStride = 32;
  auto output = [](const char* name, int location, uint32_t offset) {
    sg::EmittedOutput o;
    o.name = name;
    o.location = location;
    o.captureOffset = offset;
    return o;
  };
  capture.outputs = {output("gl_Position", -1, 0), output("A", 0, 16), output("B", 1, 28)};
  std::string text = "#version 450\nlayout(location = 0) out vec3 A;\nlayout(location=1) flat out float B;\nvoid main() {}\n";
  std::string out = sg::addCaptureQualifiers(text, "h.vert", capture);
  EXPECT_NE(out.find("layout(location = 0, xfb_buffer = 0, xfb_offset = 16, xfb_stride = 32) out vec3 A;"), std::string::npos) << out;
  EXPECT_NE(out.find("layout(location = 1, xfb_buffer = 0, xfb_offset = 28, xfb_stride = 32) flat out float B;"), std::string::npos) << out;
  EXPECT_NE(out.find("xfb_offset = 0, xfb_stride = 32) vec4 gl_Position;"), std::string::npos) << out;
  try {
    sg::addCaptureQualifiers("#version 450\n\nlayout(location = 2) out vec4 C;\nvoid main() {}\n", "h.vert", capture);
    ADD_FAILURE() << "no error";
  } catch (const sg::InputError& e) {
    EXPECT_EQ(e.diagnostic().loc.line, 3);
  }
}

sg::GpuBenchOptions quickBench(const std::string& rules) {
  sg::GpuBenchOptions b;
  b.render.gen.rigPath = sourcePath("examples/dawn/face.rig.yaml");
  b.render.gen.fragmentPath = sourcePath("examples/dawn/face.frag");
  b.render.gen.rulesPaths = {rules};
  b.render.mesh = "head";
  b.render.width = b.render.height = 32;
  b.drawsPerFrame = 1;
  b.minVerticesPerFrame = 0;
  b.frames = 1;
  b.rounds = 1;
  b.floor = false;
  return b;
}

TEST(GpuBench, ASmallMeshIsDrawnOftenEnoughThatEachFrameDrawsTheMinimum) {
  EXPECT_EQ(sg::drawsPerFrame(8, 16000, 180000), 8u);   // Dawn scale: --draws as given
  EXPECT_EQ(sg::drawsPerFrame(8, 16000, 2009), 8u);     // the head: 16,072 vertices at 8
  EXPECT_EQ(sg::drawsPerFrame(8, 16000, 2000), 8u);     // exactly 16,000
  EXPECT_EQ(sg::drawsPerFrame(8, 16000, 1999), 9u);
  EXPECT_EQ(sg::drawsPerFrame(8, 16000, 302), 53u);     // RobotExpressive's 302-vertex part
  EXPECT_EQ(sg::drawsPerFrame(8, 0, 302), 8u);          // 0: exactly --draws
  EXPECT_EQ(sg::drawsPerFrame(8, 100000000, 1), sg::kMostDrawsPerFrame);
  EXPECT_EQ(sg::drawsPerFrame(0, 0, 0), 1u);

  // The report states the draws a frame took, and the time per vertex divides by them: the
  // head drawn once (no minimum) and 8 times (the minimum) costs about the same per vertex.
  sg::GpuBenchOptions b = quickBench(sourcePath("examples/dawn/rules.yaml"));
  b.alternatives = false;
  b.rasterOff = false;
  b.frames = 3;
  sg::GpuBenchReport once = sg::runGpuBench(b);
  b.minVerticesPerFrame = 16000;
  sg::GpuBenchReport many = sg::runGpuBench(b);
  EXPECT_EQ(once.drawsPerFrame, 1u);
  EXPECT_EQ(many.drawsPerFrame, 8u);
  EXPECT_NE(sg::formatGpuBench(many).find("8 draws per frame"), std::string::npos);
  ASSERT_GT(once.rows[0].rasterOnWallNsPerVertex, 0);
  const double ratio = many.rows[0].rasterOnWallNsPerVertex / once.rows[0].rasterOnWallNsPerVertex;
  // Host time is a submit overhead o plus d per draw: (o + 8d) / 8(o + d) <= 1 when divided by the
  // 8 draws taken, (o + 8d) / (o + d) when not, above 2 wherever a draw costs a sixth of the
  // overhead (lavapipe's head draw costs more than the submit). The margin is for a busy machine:
  // a sanitized run beside a build measured 1.51.
  EXPECT_LT(ratio, 2.0) << "per-vertex time not divided by the draws taken";
}

TEST(GpuBench, BufferFedAlternativesAreValidatedAndTimed) {
  sg::GpuBenchOptions b = quickBench(sourcePath("examples/dawn/rules.yaml"));
  b.render.gen.maxAttributes = 8;
  sg::GpuBenchReport rep = sg::runGpuBench(b);
  size_t bufferRows = 0;
  for (const auto& row : rep.rows) {
    bool buffers = std::any_of(row.rules.begin(), row.rules.end(), [](const std::string& n) { return n.find("buffer") != std::string::npos; });
    bufferRows += buffers;
    EXPECT_EQ(row.validation, "pass") << row.label;
    EXPECT_GT(row.rasterOnNsPerVertex, 0) << row.label;
    EXPECT_GT(row.rasterOffNsPerVertex, 0) << row.label;
  }
  EXPECT_GE(bufferRows, 3u);
  // Each row names its SPIR-V (16 hex digits of its SHA-256), and every row is another program.
  std::set<std::string> programs;
  for (const auto& row : rep.rows) {
    EXPECT_TRUE(std::regex_match(row.program, std::regex("[0-9a-f]{16}"))) << row.label << ": " << row.program;
    programs.insert(row.program);
  }
  EXPECT_EQ(programs.size(), rep.rows.size());
}

TEST(GpuBench, CandidatesAreTheCheapestPlansEachPinnedAndTimed) {
  // --candidates 4: the generated plan and the next three by predicted time, in that order,
  // each validated and timed; each row's pin, searched under another profile, is its plan.
  sg::GpuBenchOptions b = quickBench(sourcePath("examples/dawn/rules.yaml"));
  b.render.gen.deviceProfilePath = sourcePath("devices/llvmpipe-2core.yaml");
  b.candidates = 4;
  b.floor = false;
  const sg::GpuBenchReport rep = sg::runGpuBench(b);
  ASSERT_EQ(rep.rows.size(), 4u);
  EXPECT_EQ(rep.rows[0].label, "generated");
  for (size_t i = 0; i < rep.rows.size(); ++i) {
    const sg::GpuBenchRow& row = rep.rows[i];
    EXPECT_EQ(row.validation, "pass") << row.label;
    EXPECT_GT(row.rasterOnNsPerVertex, 0) << row.label;
    if (i > 0) {
      EXPECT_EQ(row.label, "cheapest plan #" + std::to_string(i + 1));
      EXPECT_LE(rep.rows[i - 1].predictedNsPerVertex, row.predictedNsPerVertex) << row.label;
    }
    sg::GenerateOptions o = b.render.gen;
    o.deviceProfilePath = sourcePath("devices/nvidia-h200-raster.yaml");
    o.bannedRules = row.pin;
    const sg::GenerateResult g = sg::generate(o);
    std::vector<std::string> rules;
    for (int a : g.plan.actions) rules.push_back(g.in.problem.actions[size_t(a)].name);
    std::vector<std::string> want = row.rules;
    std::sort(rules.begin(), rules.end());
    std::sort(want.begin(), want.end());
    EXPECT_EQ(rules, want) << row.label << ": its pin gives another plan under another profile";
  }
  EXPECT_EQ(rep.inputs.size(), 64u);
}

TEST(GpuBench, AProgramHasTheSameNameInEveryRun) {
  // calibrate's held-out check matches one program timed in two runs by it (HeldOut,
  // AProgramTimedInTwoRunsCountsAtItsBestTiming): the same inputs name the same programs.
  sg::GpuBenchOptions b = quickBench(sourcePath("examples/dawn/rules.yaml"));
  b.alternatives = false;
  b.floor = true;
  const sg::GpuBenchReport first = sg::runGpuBench(b), second = sg::runGpuBench(b);
  ASSERT_EQ(first.rows.size(), 3u);  // the plan and the two floors
  ASSERT_EQ(second.rows.size(), first.rows.size());
  for (size_t i = 0; i < first.rows.size(); ++i) {
    EXPECT_EQ(first.rows[i].label, second.rows[i].label);
    EXPECT_EQ(first.rows[i].program, second.rows[i].program) << first.rows[i].label;
  }
  EXPECT_NE(first.rows[0].program, first.rows[1].program);
  // Another plan of the same rig is another program: the influences read from a storage buffer.
  b.render.gen.bannedRules = {"skin_matrix_blend"};
  const sg::GpuBenchReport banned = sg::runGpuBench(b);
  EXPECT_NE(banned.rows[0].program, first.rows[0].program);
}

TEST(GpuBench, APortableChoicesAlternativesArePricedByRegretAgainstTheUnbannedOptima) {
  // The face's two-device plan on the head: its plan cost is its worst predicted regret, the least
  // over every plan the search may return. Each forced alternative is such a plan, so its regret,
  // taken against the same optima, is no less. Searched under its bans with optima of their own
  // (before session 31), an alternative read 1.337 x 10^9 against the chosen plan's 1.492 x 10^9.
  sg::GpuBenchOptions b = quickBench(sourcePath("examples/dawn/rules.yaml"));
  b.render.gen.deviceProfilePath = sourcePath("devices/nvidia-h200-roofline.yaml");
  b.render.gen.portableProfilePaths = {sourcePath("devices/llvmpipe-2core.yaml")};
  b.rasterOff = false;
  const sg::GpuBenchReport rep = sg::runGpuBench(b);
  ASSERT_GT(rep.rows.size(), 3u);
  const sg::GpuBenchRow& chosen = rep.rows.front();
  ASSERT_TRUE(chosen.hasCost);
  EXPECT_GT(chosen.planCost, 1000000000);  // a regret above 1, in units of 10^-9
  for (const auto& row : rep.rows)
    if (row.hasCost) EXPECT_GE(row.planCost, chosen.planCost) << row.label;
}

TEST(GpuBench, TheDriversStatisticsAreTabledPerProgramWhereItGivesThem) {
  // A driver names its own statistics (VK_KHR_pipeline_executable_properties): bench tables them
  // by name in the order first given, "—" where a program's driver said nothing of one, and
  // writes no table where no program has any (lavapipe 22.3 offers none).
  sg::GpuBenchReport rep;
  rep.rows.resize(3);
  rep.rows[0].label = "generated";
  rep.rows[0].driverStatistics = {{"VS", "Register Count", 40}, {"VS", "Binary Size", 4096}};
  rep.rows[1].label = "forced a for b";
  rep.rows[1].driverStatistics = {{"VS", "Binary Size", 5120}, {"VS", "Spill|Fill", 1.5}, {"VS", "Register Count", 32}};
  rep.rows[2].label = "floor";
  const std::string text = sg::formatGpuBench(rep);
  EXPECT_NE(text.find("| program | Register Count | Binary Size | Spill/Fill |\n|---|---:|---:|---:|\n"
                      "| generated | 40 | 4096 | — |\n| forced a for b | 32 | 5120 | 1.5 |\n| floor | — | — | — |\n"),
            std::string::npos)
      << text;
  // calibrate's log holds them on one line in the driver's order; a second executable's are named
  // by it, and the log's separators never appear inside a name.
  EXPECT_EQ(sg::describeDriverStatistics(rep.rows[1].driverStatistics), "Binary Size=5120; Spill/Fill=1.5; Register Count=32");
  EXPECT_EQ(sg::describeDriverStatistics({{"VS", "Registers", 24}, {"VS fast", "Registers; used", 16}, {"VS", "a=b", 2}}),
            "Registers=24; VS fast: Registers, used=16; a-b=2");
  EXPECT_EQ(sg::describeDriverStatistics({}), "");
  for (auto& row : rep.rows) row.driverStatistics.clear();
  EXPECT_EQ(sg::formatGpuBench(rep).find("driver's statistics"), std::string::npos);
}

TEST(GpuBench, AProgramThatFailsOnTheDeviceIsReportedAndNotTimed) {
  // Eye direction reversed: the plan compiles and runs but computes the wrong outputs.
  RulesCopy rules("bench_eye");
  ASSERT_TRUE(rules.edit("view.yaml", "normalize(${world.position} - ${camera.position})",
                         "normalize(${camera.position} - ${world.position})"));
  sg::GpuBenchOptions b = quickBench(rules.dawnRules().string());
  b.alternatives = false;
  b.floor = true;
  sg::GpuBenchReport rep = sg::runGpuBench(b);
  ASSERT_EQ(rep.rows.size(), 3u);
  const sg::GpuBenchRow& gen = rep.rows[0];
  EXPECT_EQ(gen.validation.rfind("FAIL", 0), 0u) << gen.validation;
  EXPECT_EQ(gen.rasterOnNsPerVertex, -1);
  EXPECT_EQ(gen.rasterOffNsPerVertex, -1);
  EXPECT_EQ(rep.rows[1].validation, "");  // the floors are timed without a reference
  EXPECT_GT(rep.rows[1].rasterOnNsPerVertex, 0);
  EXPECT_NE(sg::formatGpuBench(rep).find("| generated | FAIL"), std::string::npos);
}

TEST(GpuBench, FloorsReadThePositionInEitherLayoutAndArePredicted) {
  // The pass-through floor reads the stored position, float, bounds-relative or unpacked from a
  // bit-packed attribute's words (it once read nothing for the packed face, then raw words for the
  // bit-packed one); the other floor reads every input of the generated plan.
  // Under a profile both are predicted from their amounts, at the bench mesh's vertex count.
  for (const char* rig : {"examples/dawn/face.rig.yaml", "examples/dawn/face-packed.rig.yaml", "examples/dawn/face-bitpacked.rig.yaml"}) {
    sg::GpuBenchOptions b = quickBench(sourcePath("examples/dawn/rules.yaml"));
    b.render.gen.rigPath = sourcePath(rig);
    b.render.gen.deviceProfilePath = sourcePath("devices/nvidia-h200.yaml");
    b.alternatives = false;
    b.floor = true;
    b.rasterOff = false;
    sg::GpuBenchReport rep = sg::runGpuBench(b);
    ASSERT_EQ(rep.rows.size(), 3u) << rig;
    const sg::GpuBenchRow &gen = rep.rows[0], &pass = rep.rows[1], &all = rep.rows[2];
    ASSERT_TRUE(pass.hasAmounts && all.hasAmounts) << rig;
    EXPECT_FALSE(pass.hasCost) << rig;
    EXPECT_EQ(pass.amounts[sg::kTermLocations], 1) << rig;
    EXPECT_EQ(all.amounts[sg::kTermLocations], gen.amounts[sg::kTermLocations]) << rig;
    EXPECT_EQ(all.amounts[sg::kTermAttributeBytes], gen.amounts[sg::kTermAttributeBytes]) << rig;
    EXPECT_EQ(pass.amounts[sg::kTermOutputs], gen.amounts[sg::kTermOutputs]) << rig;
    EXPECT_GT(all.amounts[sg::kTermArithmetic], pass.amounts[sg::kTermArithmetic]) << rig;
    // Predicted with the profile's weights at the head's 2,009 vertices (+1), not at its 180,000.
    sg::DeviceProfile prof = sg::loadDeviceProfile(sourcePath("devices/nvidia-h200.yaml"));
    EXPECT_NEAR(pass.predictedNsPerVertex, prof.predictNanoseconds(pass.amounts, double(rep.vertices + 1)), 1e-9) << rig;
    EXPECT_GT(pass.predictedNsPerVertex, prof.predictNanoseconds(pass.amounts, prof.verticesPerDraw)) << rig;
  }
}

// The fragments one draw covers are counted before the search and priced by a profile that has
// a fragments weight: every row's prediction uses the count, not the profile's default.
TEST(GpuBench, PlansArePricedForTheFragmentsTheDeviceCounts) {
  const std::string profile = ::testing::TempDir() + "fragments.yaml";
  writeText(profile, "device: test\nweights:\n  vertices: 1\n  fragments: 0.01\n"
                         "scaled_by:\n  fragments: fragments_per_vertex\nworkload_defaults:\n  fragments_per_vertex: 1000\n");
  double previous = 0;
  for (uint32_t size : {64u, 128u}) {
    sg::GpuBenchOptions b = quickBench(sourcePath("examples/dawn/rules.yaml"));
    b.render.gen.deviceProfilePath = profile;
    b.render.width = b.render.height = size;
    b.alternatives = false;
    b.floor = true;
    b.rasterOff = false;
    const sg::GpuBenchReport rep = sg::runGpuBench(b);
    const double fragments = rep.workload.fragmentsPerVertex;
    ASSERT_GT(fragments, 0) << size;
    EXPECT_GE(rep.shadedVerticesPerVertex, 1.0) << size;  // every vertex of the head is drawn
    for (const auto& row : rep.rows) EXPECT_NEAR(row.predictedNsPerVertex, 1 + 0.01 * fragments, 1e-6) << row.label;
    EXPECT_NE(sg::formatGpuBench(rep).find(fmt::format("{:.2f} fragments per vertex", fragments)), std::string::npos);
    // More pixels, more fragments; less than 4x on lavapipe, which counts whole blocks of
    // invocations around the head's small triangles (the H200 counts 16.0x for 16x the pixels:
    // bench/data/h200-draw-counts18/exp1.txt).
    if (previous > 0) {
      EXPECT_GT(fragments / previous, 1.5);
      EXPECT_LT(fragments / previous, 4.5);
    }
    previous = fragments;
  }
}

// On a CPU device (lavapipe, the tests' device) the prediction check uses the clock calibrate
// fits there, this process's CPU time with the rasterizer discarded, not lavapipe's timestamps
// (which miss deferred work): the generated program over the fastest passing plan by that clock.
TEST(GpuBench, ACpuDeviceIsCheckedByTheClockItsProfileWasFittedOn) {
  sg::GpuBenchOptions b = quickBench(sourcePath("examples/dawn/rules.yaml"));
  b.render.gen.deviceProfilePath = sourcePath("devices/llvmpipe-2core.yaml");
  b.rounds = 2;
  sg::GpuBenchReport rep = sg::runGpuBench(b);
  ASSERT_TRUE(sg::isCpuDevice(rep.device)) << rep.device;
  EXPECT_EQ(rep.predictionClock, "raster off, process CPU time (a CPU device)");
  ASSERT_FALSE(rep.rows.empty());
  ASSERT_EQ(rep.rows.front().label, "generated");
  double fastest = INFINITY;
  for (const auto& row : rep.rows)
    if (row.hasCost && row.validation == "pass") {
      ASSERT_GT(row.rasterOffCpuNsPerVertex, 0) << row.label;
      fastest = std::min(fastest, row.rasterOffCpuNsPerVertex);
      // Each round's figure by that clock is kept; the row's number is the best of them.
      ASSERT_EQ(row.roundNsPerVertex.size(), 2u) << row.label;
      EXPECT_DOUBLE_EQ(row.rasterOffCpuNsPerVertex, std::min(row.roundNsPerVertex[0], row.roundNsPerVertex[1])) << row.label;
    }
  EXPECT_DOUBLE_EQ(rep.generatedOverFastestOn, rep.rows.front().rasterOffCpuNsPerVertex / fastest);
  const sg::RoundSpread spread = sg::generatedOverFastestByRound(rep.rows);
  EXPECT_EQ(rep.byRound.rounds, 2u);
  EXPECT_DOUBLE_EQ(rep.byRound.least, spread.least);
  EXPECT_DOUBLE_EQ(rep.byRound.most, spread.most);
  EXPECT_GE(spread.most, spread.least);
  const std::string text = sg::formatGpuBench(rep);
  EXPECT_NE(text.find("predicted vs measured (raster off, process CPU time (a CPU device);"), std::string::npos);
  EXPECT_NE(text.find(fmt::format("(within one round: {:.3f}x to {:.3f}x over 2 rounds)", spread.least, spread.most)), std::string::npos);
  // The CPU clock has its column, the generated program's figure first in it.
  EXPECT_NE(text.find("| raster off, process CPU |"), std::string::npos);
  EXPECT_NE(text.find(fmt::format(" {:.4f} (1.00x) |\n", rep.rows.front().rasterOffCpuNsPerVertex)), std::string::npos);

  // The fastest validated plan by that clock is named, with the bans that make generate write
  // it: generate with them gives that plan's rules (checked for it and the first forced row).
  int fastestRow = -1;
  for (size_t k = 0; k < rep.rows.size(); ++k)
    if (rep.rows[k].hasCost && rep.rows[k].validation == "pass" &&
        (fastestRow < 0 || rep.rows[k].rasterOffCpuNsPerVertex < rep.rows[size_t(fastestRow)].rasterOffCpuNsPerVertex))
      fastestRow = static_cast<int>(k);
  ASSERT_EQ(rep.fastestPlan, fastestRow);
  EXPECT_DOUBLE_EQ(rep.fastestOverGenerated, rep.rows[size_t(fastestRow)].rasterOffCpuNsPerVertex / rep.rows.front().rasterOffCpuNsPerVertex);
  EXPECT_TRUE(rep.rows.front().bans.empty());
  ASSERT_GT(rep.rows.size(), 2u);
  for (size_t k : {size_t(1), size_t(fastestRow)}) {
    const sg::GpuBenchRow& row = rep.rows[k];
    if (row.label == "generated") continue;
    SCOPED_TRACE(row.label);
    ASSERT_FALSE(row.bans.empty());
    sg::GenerateOptions g = b.render.gen;
    g.bannedRules.insert(g.bannedRules.end(), row.bans.begin(), row.bans.end());
    const sg::GenerateResult r = sg::generate(g);
    std::vector<std::string> rules;
    for (int a : r.plan.actions) rules.push_back(r.in.problem.actions[a].name);
    EXPECT_EQ(rules, row.rules);
  }
  const size_t line = text.find("fastest validated plan (raster off, process CPU time (a CPU device)): ");
  ASSERT_NE(line, std::string::npos) << text;
  if (fastestRow == 0) {
    EXPECT_NE(text.find("): the generated one\n", line), std::string::npos);
  } else {
    for (const auto& ban : rep.rows[size_t(fastestRow)].bans) EXPECT_NE(text.find(" --ban " + ban, line), std::string::npos) << ban;
  }
}

// What `program` writes for every vertex of the mesh, captured with the generated program's layout.
std::vector<uint8_t> captured(sg::rt::Harness& harness, const sg::GenerateResult& program, const sg::GenerateResult& gen,
                              const sg::rt::Mesh& mesh, const sg::rt::Pose& pose) {
  sg::rt::RunRequest r;
  static_cast<sg::rt::ProgramInputs&>(r) = sg::programInputs(program, mesh, pose);
  r.spirv = program.spirv.words;
  r.capture.strideBytes = gen.glsl.captureStride;
  return harness.run(r).captured;
}

TEST(GpuBench, HandPortOfListing33ComputesWhatTheGeneratedShaderComputes) {
  sg::GenerateOptions g;
  g.rigPath = sourcePath("examples/dawn/face.rig.yaml");
  g.fragmentPath = sourcePath("examples/dawn/face.frag");
  g.rulesPaths = {sourcePath("examples/dawn/rules.yaml")};
  g.capture = true;
  sg::GenerateResult gen = sg::generate(g);
  sg::ValidationScene scene = sg::proceduralScene(gen.in.rig, "head", 3, 1);
  sg::rt::Mesh mesh = sg::quantizeForRig(gen.in.rig, scene.mesh);
  const sg::rt::Pose& pose = scene.poses.front();
  const std::string path = sourcePath("examples/dawn/listing-3-3.vert");
  sg::GenerateResult hand = sg::handWrittenProgram(
      sg::addCaptureQualifiers(sg::readInputFile(path), path, gen.glsl), path, gen, g.targetEnv);
  EXPECT_NE(hand.spirv.words, gen.spirv.words);

  sg::rt::Harness harness;
  std::vector<uint8_t> ga = captured(harness, gen, gen, mesh, pose), gb = captured(harness, hand, gen, mesh, pose);
  ASSERT_EQ(ga.size(), gb.size());
  EXPECT_TRUE(harness.validationMessages().empty()) << harness.validationMessages().front();
  // Same values up to float rounding (the two programs order their arithmetic differently).
  size_t floats = ga.size() / 4, differ = 0;
  double worst = 0;
  for (size_t i = 0; i < floats; ++i) {
    float x, y;
    std::memcpy(&x, &ga[i * 4], 4);
    std::memcpy(&y, &gb[i * 4], 4);
    double d = std::abs(double(x) - double(y)) / std::max(1.0, std::abs(double(x)));
    worst = std::max(worst, d);
    differ += d > 1e-4;
  }
  EXPECT_EQ(differ, 0u) << "worst relative difference " << worst;
}

// A hand port of a buffer-fed program (16 influences and the palette from storage buffers, read
// at gl_VertexIndex) is fed the generated program's buffers at their bindings and computes what it
// computes; a storage buffer the generated program does not read is a located error.
TEST(GpuBench, HandPortOfABufferFedProgramReadsTheGeneratedProgramsStorageBuffers) {
  sg::GenerateOptions g;
  g.rigPath = sourcePath("tests/validate/data/limb16.rig.yaml");
  g.fragmentPath = sourcePath("tests/validate/data/world.frag");
  g.rulesPaths = {sourcePath("rules/standard.yaml")};
  g.bannedRules = {"skin_matrix_blend", "skin_matrix_blend_buffered_influences", "skin_matrix_blend_buffer_palette",
                   "world_position_linear_blend", "world_normal_linear_blend", "world_tangent_linear_blend"};
  sg::GenerateResult plain = sg::generate(g);  // the hand port's text: no capture qualifiers of its own
  g.capture = true;
  sg::GenerateResult gen = sg::generate(g);
  ASSERT_EQ(gen.glsl.buffers.size(), 3u);  // joints, weights, palette
  sg::ValidationScene scene = sg::proceduralScene(gen.in.rig, "limb", 3, 1);
  sg::rt::Mesh mesh = sg::quantizeForRig(gen.in.rig, scene.mesh);
  const sg::rt::Pose& pose = scene.poses.front();
  sg::GenerateResult hand = sg::handWrittenProgram(sg::addCaptureQualifiers(plain.glsl.text, "hand.vert", gen.glsl),
                                                   "hand.vert", gen, g.targetEnv);
  ASSERT_EQ(hand.glsl.buffers.size(), 3u);
  for (size_t i = 0; i < 3; ++i) EXPECT_EQ(hand.glsl.buffers[i].semantic, gen.glsl.buffers[i].semantic);

  sg::rt::Harness harness;
  std::vector<uint8_t> ga = captured(harness, gen, gen, mesh, pose), gb = captured(harness, hand, gen, mesh, pose);
  ASSERT_EQ(ga.size(), gb.size());
  EXPECT_TRUE(harness.validationMessages().empty()) << harness.validationMessages().front();
  EXPECT_EQ(ga, gb);

  g.bannedRules.push_back("skin_matrix_blend_buffered_influences_buffer_palette");
  g.bannedRules.erase(g.bannedRules.begin());  // the uniform palette and attribute influences: no buffers
  sg::GenerateResult noBuffers = sg::generate(g);
  ASSERT_TRUE(noBuffers.glsl.buffers.empty());
  try {
    sg::handWrittenProgram(plain.glsl.text, "hand.vert", noBuffers, g.targetEnv);
    ADD_FAILURE() << "no error";
  } catch (const sg::InputError& e) {
    EXPECT_EQ(e.diagnostic().loc.file, "hand.vert");
    EXPECT_NE(e.diagnostic().message.find("is not one the generated program reads"), std::string::npos) << e.diagnostic().message;
  }
}

}  // namespace

// Timing on lavapipe turns its rasterizer threads off, unless the user chose a thread count.
TEST(GpuBenchCpuDevice, TimesLavapipeSingleThreadedUnlessTheEnvironmentSaysOtherwise) {
  const char* before = std::getenv("LP_NUM_THREADS");
  const std::string saved = before ? before : "";
  unsetenv("LP_NUM_THREADS");
  sg::timeCpuDevicesSingleThreaded();
  ASSERT_NE(std::getenv("LP_NUM_THREADS"), nullptr);
  EXPECT_STREQ(std::getenv("LP_NUM_THREADS"), "0");
  setenv("LP_NUM_THREADS", "3", 1);
  sg::timeCpuDevicesSingleThreaded();
  EXPECT_STREQ(std::getenv("LP_NUM_THREADS"), "3");
  if (before) setenv("LP_NUM_THREADS", saved.c_str(), 1); else unsetenv("LP_NUM_THREADS");
}

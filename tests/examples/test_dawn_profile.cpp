// Device profiles on the Dawn face (issue 21, docs/device-profiles.md): without a profile
// the plan, its cost and the reflection are the instruction-slot model's; the term amounts
// of that plan are the rig's (16 input locations, 220 attribute bytes per vertex); under a
// profile where input locations are dear the search moves to buffer-fed forms that read
// fewer locations, and its plan is the cheapest under that profile by every engine.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "pipeline/generate.h"
#include "pipeline/stages.h"
#include "search/device_profile.h"
#include "search/ip_oracle.h"

namespace sg {
namespace {

const std::string kDawn = std::string(SG_SOURCE_DIR) + "/examples/dawn/";

GenerateOptions faceOptions(const std::string& profile = "") {
  GenerateOptions o;
  o.rigPath = kDawn + "face.rig.yaml";
  o.fragmentPath = kDawn + "face.frag";
  o.rulesPaths = {kDawn + "rules.yaml"};
  o.templateDir = std::string(SG_SOURCE_DIR) + "/templates";
  o.deviceProfilePath = profile;
  return o;
}

std::string writeProfile(const std::string& name, const std::string& text) {
  auto path = std::filesystem::temp_directory_path() / ("sg_" + name + ".device.yaml");
  std::ofstream(path) << text;
  return path.string();
}

std::vector<std::string> ruleNames(const GenerateResult& r) {
  std::vector<std::string> names;
  for (int a : r.plan.actions) names.push_back(r.in.problem.actions[a].name);
  return names;
}

TEST(DawnProfile, WithoutAProfileTheSlotModelIsUnchanged) {
  GenerateResult r = generate(faceOptions());
  EXPECT_FALSE(r.in.profile);
  EXPECT_EQ(r.in.problem.weights, kSlotWeights);
  EXPECT_EQ(r.plan.cost, 97);  // docs/comparison.md: the Dawn face plan with the branchless tangent fallback
  EXPECT_EQ(r.in.problem.fixedCost, 0);
  for (const auto& item : r.in.problem.resources) EXPECT_EQ(item.cost, 0) << item.name;
  EXPECT_EQ(reflectionOf(r).find("predicted_cost"), std::string::npos);
  // The rig's streams: coord (12 B), normal, tangent (16), 5 x coord_morph (12), 5 x
  // normal_morph (16), bone_weight (16), bone_index (uint8x4: 4), skin_uvst (16).
  TermAmounts a = planTermAmounts(r.plan, r.in.problem);
  EXPECT_EQ(a[kTermLocations], 16);
  EXPECT_EQ(a[kTermAttributeBytes], 12 + 16 + 16 + 5 * 12 + 5 * 16 + 16 + 4 + 16);
  EXPECT_EQ(a[kTermArithmetic], 97);
  EXPECT_EQ(a[kTermVertices], 1);
}

// A profile that charges one femtosecond per slot and nothing else is the slot model in
// other units: same plan, cost 97 fs.
TEST(DawnProfile, ASlotsOnlyProfileKeepsThePlan) {
  GenerateResult slots = generate(faceOptions());
  GenerateResult r = generate(faceOptions(writeProfile("slots", "device: slots\nweights:\n  arithmetic: 0.000001\n")));
  ASSERT_TRUE(r.in.profile);
  EXPECT_EQ(ruleNames(r), ruleNames(slots));
  EXPECT_EQ(r.plan.cost, 97);
  EXPECT_EQ(r.glsl.text, slots.glsl.text);
}

TEST(DawnProfile, ExpensiveLocationsMoveThePlanToBuffers) {
  GenerateResult slots = generate(faceOptions());
  GenerateResult r = generate(faceOptions(std::string(SG_SOURCE_DIR) + "/devices/example.yaml"));
  ASSERT_TRUE(r.in.profile);
  const Problem& p = r.in.problem;
  const PlanCostPrediction c = predictPlanCost(r.plan, p, *r.in.profile);
  EXPECT_LT(c.amounts[kTermLocations], 16);
  EXPECT_GT(c.amounts[kTermBufferLoads], 0);
  EXPECT_NE(ruleNames(r), ruleNames(slots));
  // The plan's cost is its prediction in femtoseconds, and the slot model's plan costs more
  // under this profile (the actions are the same instances in both problems).
  EXPECT_EQ(r.plan.cost, std::llround(c.totalNanoseconds * kFemtosecondsPerNanosecond));
  const Plan slotPlanPriced = tidyPlan(p, slots.plan.actions);
  EXPECT_GT(slotPlanPriced.cost, r.plan.cost);
  const PlanCostPrediction old = predictPlanCost(slotPlanPriced, p, *r.in.profile);
  EXPECT_EQ(old.amounts[kTermLocations], 16);
  // Every engine agrees on the optimum.
  for (const char* engine : {"regression", "ip", "forward"}) {
    SearchOptions o;
    o.engine = engine;
    auto plan = findPlan(p, o);
    ASSERT_TRUE(plan) << engine;
    EXPECT_EQ(plan->cost, r.plan.cost) << engine;
  }
  std::string json = reflectionOf(r);
  EXPECT_NE(json.find("\"predicted_cost\""), std::string::npos);
  EXPECT_NE(json.find("\"locations\": {\"amount\": " + std::to_string(c.amounts[kTermLocations])), std::string::npos);
}

// The profile measured on an NVIDIA H200 (devices/nvidia-h200.yaml, `shadergen calibrate`,
// docs/device-profiles.md) reads back and chooses a plan of at most 6 input locations (the
// bench there timed it at 0.37x the hand port of listing 3-3: bench/data/h200-calibrate.log);
// the IP oracle agrees it is the optimum under that profile, at its own workload (Dawn
// scale) and at the cached head's 2,009 vertices per draw, where its per-draw weights weigh
// 90 times more per vertex.
TEST(DawnProfile, TheMeasuredH200ProfileReadsFewLocations) {
  for (int64_t vertices : {int64_t{0}, int64_t{2010}}) {
    GenerateOptions g = faceOptions(std::string(SG_SOURCE_DIR) + "/devices/nvidia-h200.yaml");
    g.maxVertices = vertices;
    GenerateResult r = generate(g);
    ASSERT_TRUE(r.in.profile);
    EXPECT_NE(r.in.profile->device.find("H200"), std::string::npos);
    ASSERT_TRUE(r.in.profile->hasDrawWeights());
    EXPECT_EQ(r.in.profile->verticesPerDraw, vertices ? double(vertices) : 180000.0);
    const PlanCostPrediction c = predictPlanCost(r.plan, r.in.problem, *r.in.profile);
    EXPECT_LE(c.amounts[kTermLocations], 6);
    SearchOptions o;
    o.engine = "ip";
    auto plan = findPlan(r.in.problem, o);
    ASSERT_TRUE(plan);
    EXPECT_EQ(plan->cost, r.plan.cost) << vertices;
  }
}

// A profile with draw sizes (docs/device-profiles.md, "Draw sizes") prices each generation at
// its draw's size: at each stated size the plan and its cost are those of a plain profile with
// that size's weights; the sizes here disagree on locations against storage-buffer loads, so the
// face's plan moves; between them the blend is searched exactly (the IP oracle agrees).
TEST(DawnProfile, DrawSizesPriceEachGenerationAtItsDrawsSize) {
  const std::string sized = writeProfile("sized",
                                         "device: d\nvertices_per_draw: 200000\ndraw_sizes:\n"
                                         "  2000:\n    weights: {arithmetic: 0.01, locations: 1, buffer_loads: 0.001}\n"
                                         "  200000:\n    weights: {arithmetic: 0.01, locations: 0.001, buffer_loads: 1}\n");
  const std::string small = writeProfile("small", "device: d\nweights: {arithmetic: 0.01, locations: 1, buffer_loads: 0.001}\n");
  const std::string large = writeProfile("large", "device: d\nweights: {arithmetic: 0.01, locations: 0.001, buffer_loads: 1}\n");
  auto at = [&](const std::string& profile, double vertices) {
    GenerateOptions g = faceOptions(profile);
    g.workload.verticesPerDraw = vertices;
    return generate(g);
  };
  const GenerateResult s = at(sized, 2000), l = at(sized, 0), unsized = at(small, 0), unsizedLarge = at(large, 0);
  EXPECT_EQ(ruleNames(s), ruleNames(unsized));
  EXPECT_EQ(s.plan.cost, unsized.plan.cost);
  EXPECT_EQ(ruleNames(l), ruleNames(unsizedLarge));  // unknown: the profile's 200,000
  EXPECT_EQ(l.plan.cost, unsizedLarge.plan.cost);
  EXPECT_NE(ruleNames(s), ruleNames(l));
  EXPECT_LT(planTermAmounts(s.plan, s.in.problem)[kTermLocations], planTermAmounts(l.plan, l.in.problem)[kTermLocations]);
  const GenerateResult mid = at(sized, 20000);
  EXPECT_EQ(mid.in.profile->verticesPerDraw, 20000);
  SearchOptions o;
  o.engine = "ip";
  auto plan = findPlan(mid.in.problem, o);
  ASSERT_TRUE(plan);
  EXPECT_EQ(plan->cost, mid.plan.cost);
}

// The face's palette (skin.bones in the uniform block) priced by `profile` for a mesh of
// `jointsPerWarp` (0: unknown), inputs prepared as `build` prepares each variant: its resource
// item carries the loads its readers make at a per-vertex index (shareIndexedUniformLoads).
ResourceItem facePaletteItem(const DeviceProfile& profile, double jointsPerWarp) {
  static const Rig rig = loadRigStage(kDawn + "face.rig.yaml");
  static const RuleSet rules = loadRulesStage({kDawn + "rules.yaml"});
  static const FragmentInterface fragment = loadFragmentStage(kDawn + "face.frag", TargetEnv::Vulkan1_0);
  GenerateOptions o;
  o.workload.jointsPerWarp = jointsPerWarp;
  const LoadedInputs in = prepareInputs(rig, rules, fragment, o, profile);
  const int f = in.problem.findFact("skin.bones");
  EXPECT_GE(f, 0);
  const int item = f < 0 ? -1 : in.problem.facts[static_cast<size_t>(f)].resource;
  EXPECT_GE(item, 0);
  return item < 0 ? ResourceItem{} : in.problem.resources[static_cast<size_t>(item)];
}

// The workload reaches the prices on every path that prepares inputs: `build` loads a profile
// once and prepares each variant from it (prepareInputs), as generate does after loading. A
// profile that prices indexed uniform loads per joint a warp reads must make the palette three
// times dearer on a mesh with three joints per warp than on one with one.
TEST(DawnProfile, PreparedInputsArePricedForTheirWorkload) {
  const DeviceProfile profile = parseDeviceProfile(
      "device: d\nweights:\n  indexed_uniform_loads: 1\nscaled_by:\n  indexed_uniform_loads: joints_per_warp\n",
      "per-joint.yaml");
  const int64_t one = facePaletteItem(profile, 1).cost, three = facePaletteItem(profile, 3).cost;
  ASSERT_GT(one, 0) << "skin_matrix_blend reads the palette at a per-vertex index";
  EXPECT_EQ(three, 3 * one);
}

// The vec4 loads of the palette (4 per mat4 entry, 16 for the face's 4 influences) priced by
// joints_per_warp_squared: 9 times dearer at three joints per warp than at one, and where the
// mesh is unknown, the square of the stated joints_per_warp default.
TEST(DawnProfile, PaletteVec4LoadsArePricedByTheSquareOfJointsPerWarp) {
  const DeviceProfile profile = parseDeviceProfile(
      "device: d\nweights:\n  indexed_uniform_vec4_loads: 1\nscaled_by:\n  indexed_uniform_vec4_loads: joints_per_warp_squared\n"
      "workload_defaults:\n  joints_per_warp: 2\n",
      "squared.yaml");
  EXPECT_EQ(facePaletteItem(profile, 1).terms[kTermIndexedUniformVec4Loads], 16);
  const int64_t one = facePaletteItem(profile, 1).cost;
  EXPECT_EQ(one, 16 * kFemtosecondsPerNanosecond);
  EXPECT_EQ(facePaletteItem(profile, 3).cost, 9 * one);
  EXPECT_EQ(facePaletteItem(profile, 0).cost, 4 * one);  // unknown: the default, 2, squared
}

// Table reads from storage buffers (the palette in a buffer) are counted apart from the
// per-vertex streams' loads since session 27. A profile that does not name them prices them as
// buffer loads, so it means what it meant; one that prices them at nothing moves Dawn's body
// depth pass at Dawn scale (2.62 joints per warp) to the palette in a buffer, the fastest plan the
// H100 and the H200 timed for it (docs/device-profiles.md, "Table reads").
TEST(DawnProfile, TableReadsArePricedAsBufferLoadsByAProfileThatDoesNotNameThem) {
  // TABLE: lines of the memory pipe a newer profile adds.
  auto profile = [](const std::string& table) {
    return "device: d\nweights:\n  vertices: 0.4\npipes:\n  fetch:\n    locations: 0.5\n  memory:\n"
           "    buffer_loads: 0.18\n    buffer_vec4_loads: 0.023\n" +
           table +
           "  constant:\n    indexed_uniform_loads: 0.06\n    indexed_uniform_vec4_loads: 0.015\n"
           "scaled_by:\n  indexed_uniform_loads: joints_per_warp\n  indexed_uniform_vec4_loads: joints_per_warp\n";
  };
  const std::string before = profile(""), free = profile("    buffer_table_loads: 0\n    buffer_table_vec4_loads: 0\n");
  const DeviceProfile old = parseDeviceProfile(before, "before.yaml");
  TermAmounts table{}, streamed{};
  table[kTermVertices] = streamed[kTermVertices] = 1;
  table[kTermLocations] = streamed[kTermLocations] = 1;
  table[kTermBufferLoads] = 2, table[kTermBufferVec4Loads] = 2;  // the influences
  table[kTermBufferTableLoads] = 4, table[kTermBufferTableVec4Loads] = 16;  // the palette
  streamed[kTermBufferLoads] = 6, streamed[kTermBufferVec4Loads] = 18;  // all counted as buffer loads
  EXPECT_DOUBLE_EQ(old.predictNanoseconds(table, 180000), old.predictNanoseconds(streamed, 180000));
  EXPECT_DOUBLE_EQ(old.predictNanoseconds(table, 180000), 0.4 + 6 * 0.18 + 18 * 0.023);  // the memory pipe, slowest
  const DeviceProfile named = parseDeviceProfile(free, "named.yaml");
  // The memory pipe reads the influences alone (0.406 ns): the fetch pipe's location is the slowest.
  EXPECT_DOUBLE_EQ(named.predictNanoseconds(table, 180000), 0.4 + 0.5);

  auto bodySkin = [&](const std::string& profileText, const char* name) {
    GenerateOptions o;
    o.rigPath = kDawn + "body.rig.yaml";
    o.fragmentPath = kDawn + "depth.frag";
    o.rulesPaths = {kDawn + "rules.yaml"};
    o.templateDir = std::string(SG_SOURCE_DIR) + "/templates";
    o.deviceProfilePath = writeProfile(name, profileText);
    o.maxAttributes = 32, o.maxUniformBlockBytes = 65536;  // an H200's limits
    o.workload.jointsPerWarp = 2.62;                       // the 'dawn' mesh's
    const GenerateResult r = generate(o);
    for (const std::string& rule : ruleNames(r))
      if (rule.rfind("skin_matrix", 0) == 0) return rule;
    return std::string("none");
  };
  EXPECT_EQ(bodySkin(before, "body-before"), "skin_matrix_blend_buffered_influences");
  EXPECT_EQ(bodySkin(free, "body-table"),
            "skin_matrix_blend_buffered_influences_buffer_palette");
}

}  // namespace
}  // namespace sg

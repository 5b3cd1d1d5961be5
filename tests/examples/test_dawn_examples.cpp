// The Dawn examples: the plan choices that depend on the rig, the size of the generated
// face shader against a hand port of listing 3-3, and validation of every example on
// lavapipe with the cross-check of alternatives.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/yaml_util.h"
#include "emit/spirv.h"
#include "pipeline/generate.h"
#include "validate/validate.h"

namespace sg {
namespace {

const std::string kDawn = std::string(SG_SOURCE_DIR) + "/examples/dawn/";

GenerateOptions dawnOptions(const std::string& rig, const std::string& frag) {
  GenerateOptions o;
  o.rigPath = rig;
  o.fragmentPath = kDawn + frag;
  o.rulesPaths = {kDawn + "rules.yaml"};
  o.templateDir = std::string(SG_SOURCE_DIR) + "/templates";
  return o;
}

std::vector<std::string> planRules(const GenerateResult& r) {
  std::vector<std::string> names;
  for (int a : r.plan.actions) names.push_back(r.in.problem.actions[a].name);
  return names;
}

bool has(const std::vector<std::string>& v, const std::string& s) { return std::find(v.begin(), v.end(), s) != v.end(); }

// The face rig with one textual change, written to a temp file.
std::string faceRigWith(const std::string& from, const std::string& to, const std::string& name) {
  std::string text = readInputFile(kDawn + "face.rig.yaml");
  auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  text.replace(at, from.size(), to);
  auto path = std::filesystem::temp_directory_path() / ("sg_" + name + ".rig.yaml");
  std::ofstream(path) << text;
  return path.string();
}

TEST(DawnExamples, FaceBlendsTheMatrixOnceAndTakesNdotVInWorldSpace) {
  GenerateResult r = generate(dawnOptions(kDawn + "face.rig.yaml", "face.frag"));
  auto rules = planRules(r);
  EXPECT_TRUE(has(rules, "skin_matrix_blend"));
  EXPECT_TRUE(has(rules, "world_normal_from_matrix"));
  EXPECT_TRUE(has(rules, "ndotv_world_space"));
  EXPECT_TRUE(has(rules, "normal_occlusion_morphed"));
  EXPECT_FALSE(has(rules, "eye_normal"));
  EXPECT_FALSE(has(rules, "world_normal_linear_blend"));
}

TEST(DawnExamples, OneInfluenceSwitchesToRigidSkinning) {
  GenerateResult r = generate(dawnOptions(faceRigWith("influences: 4", "influences: 1", "rigid"), "face.frag"));
  auto rules = planRules(r);
  EXPECT_TRUE(has(rules, "skin_matrix_rigid"));
  EXPECT_FALSE(has(rules, "skin_matrix_blend"));
  EXPECT_FALSE(has(rules, "world_position_linear_blend"));
}

TEST(DawnExamples, NoMorphTargetsSkipsMorphing) {
  std::string rig = faceRigWith("morph_targets: 5\n  morphs: [position, normal]", "morph_targets: 0", "nomorph");
  // Drop the per-target streams and weights: the rig checker rejects them without targets.
  std::string text = readInputFile(rig);
  std::stringstream in(text);
  std::string line, kept;
  while (std::getline(in, line))
    if (line.find("per_target") == std::string::npos && line.find("morph_weight") == std::string::npos) kept += line + "\n";
  std::ofstream(rig) << kept;
  GenerateResult r = generate(dawnOptions(rig, "face.frag"));
  auto rules = planRules(r);
  EXPECT_TRUE(has(rules, "object_position_unmorphed"));
  EXPECT_TRUE(has(rules, "object_normal_unmorphed"));
  EXPECT_TRUE(has(rules, "object_occlusion_unmorphed"));
  EXPECT_FALSE(has(rules, "object_position_morphed"));
  EXPECT_LT(r.plan.cost, generate(dawnOptions(kDawn + "face.rig.yaml", "face.frag")).plan.cost);
}

TEST(DawnExamples, ViewProjectionUniformReplacesTheEyeSpacePosition) {
  std::string rig = faceRigWith("  proj_xf:", "  view_proj_xf:   { type: mat4, semantic: camera.view_projection }\n  proj_xf:", "vp");
  GenerateResult r = generate(dawnOptions(rig, "face.frag"));
  auto rules = planRules(r);
  EXPECT_TRUE(has(rules, "clip_from_view_projection"));
  EXPECT_FALSE(has(rules, "eye_position"));
  EXPECT_FALSE(has(rules, "clip_from_eye"));
}

TEST(DawnExamples, DepthOnlyComputesNoNormalsOrTangents) {
  GenerateResult r = generate(dawnOptions(kDawn + "face.rig.yaml", "depth.frag"));
  for (int a : r.plan.actions) {
    const std::string& f = r.in.problem.facts[r.in.problem.actions[a].add].name;
    EXPECT_EQ(f.find("normal"), std::string::npos) << f;
    EXPECT_EQ(f.find("tangent"), std::string::npos) << f;
  }
  EXPECT_EQ(r.glsl.text.find("a_normal"), std::string::npos);
  EXPECT_EQ(r.glsl.text.find("a_tangent"), std::string::npos);
  // Position only: blending the point per bone beats blending the matrix first.
  EXPECT_TRUE(has(planRules(r), "world_position_linear_blend"));
}

// Issue 23: with the degenerate-tangent fallback, at most 0.8 of the hand port (docs/comparison.md).
TEST(DawnExamples, GeneratedFaceIsAtMostFourFifthsOfTheHandPortAfterOptimisation) {
  GenerateOptions o = dawnOptions(kDawn + "face.rig.yaml", "face.frag");
  o.optimize = true;
  GenerateResult r = generate(o);
  GlslUnit hand{Stage::Vertex, readInputFile(kDawn + "listing-3-3.vert"), kDawn + "listing-3-3.vert", {}};
  CompileResult c = compileGlsl(hand, TargetEnv::Vulkan1_0);
  ASSERT_TRUE(c.ok);
  size_t handCount = countInstructions(optimizeSpirv(c.spirv, TargetEnv::Vulkan1_0));
  size_t genCount = countInstructions(r.spirv.words);
  EXPECT_LE(genCount * 10, handCount * 8) << genCount << " instructions against the hand port's " << handCount;
  EXPECT_TRUE(has(planRules(r), "object_tangent_gram_schmidt"));  // the fallback is in the plan
  EXPECT_GT(genCount, 100u);  // a real shader, not an empty one
}

class DawnValidation : public ::testing::TestWithParam<std::pair<const char*, const char*>> {};

TEST_P(DawnValidation, ValidatesWithCrossCheckOnLavapipe) {
  auto [rig, frag] = GetParam();
  ValidateOptions vo;
  vo.gen = dawnOptions(kDawn + rig, frag);
  vo.crossCheck = true;
  Validator v(vo);
  ValidationScene scene = proceduralScene(loadRigFile(vo.gen.rigPath), "head", 7, 2);
  ValidateReport report = v.run(scene);
  EXPECT_TRUE(report.pass) << formatReport(report);
  EXPECT_TRUE(report.validationLayers);
  for (const auto& run : report.runs) EXPECT_TRUE(run.validationMessages.empty());
  if (std::string(frag) == "face.frag") EXPECT_GE(report.runs.size(), 4u) << formatReport(report);
  // The packed face stores encoded and quantized streams: every run is also checked against
  // the float data (docs/validation.md, "Against the float data").
  if (std::string(rig) == "face-packed.rig.yaml" || std::string(rig) == "face-bitpacked.rig.yaml")
    for (const auto& run : report.runs)
      for (const auto& o : run.outputs) EXPECT_TRUE(o.floatCheck.ran && o.floatCheck.pass) << run.label << " " << o.name;
}

// A portable choice's alternatives are searched for the least regret against the unbanned
// optima, as bench times them (GpuBench.APortableChoicesAlternativesArePricedByRegretAgainstTheUnbannedOptima):
// each is one of the plans the chosen one is the least of, so its plan cost is no less.
TEST(DawnValidationPortable, CrossCheckedAlternativesAreNoCheaperThanTheChosenPlan) {
  ValidateOptions vo;
  vo.gen = dawnOptions(kDawn + "face.rig.yaml", "face.frag");
  vo.gen.deviceProfilePath = std::string(SG_SOURCE_DIR) + "/devices/nvidia-h200-roofline.yaml";
  vo.gen.portableProfilePaths = {std::string(SG_SOURCE_DIR) + "/devices/llvmpipe-2core.yaml"};
  vo.crossCheck = true;
  Validator v(vo);
  const ValidateReport report = v.run(proceduralScene(loadRigFile(vo.gen.rigPath), "head", 7, 2));
  EXPECT_TRUE(report.pass) << formatReport(report);
  ASSERT_GE(report.runs.size(), 3u) << formatReport(report);
  EXPECT_GT(report.runs[0].planCost, 1000000000);  // a regret above 1, in units of 10^-9
  for (const auto& run : report.runs) EXPECT_GE(run.planCost, report.runs[0].planCost) << run.label;
}

INSTANTIATE_TEST_SUITE_P(Examples, DawnValidation,
                         ::testing::Values(std::make_pair("face.rig.yaml", "face.frag"),
                                           std::make_pair("face-packed.rig.yaml", "face.frag"),  // encoded, halves, bytes
                                           std::make_pair("face-bitpacked.rig.yaml", "face.frag"),  // the same in uint32x4 words
                                           std::make_pair("body.rig.yaml", "face.frag"),
                                           std::make_pair("face.rig.yaml", "depth.frag")));

}  // namespace
}  // namespace sg

namespace sg {
namespace {

TEST(RulesLibrary, StoredBinormalGivesTheHandednessAndValidates) {
  const std::string data = std::string(SG_SOURCE_DIR) + "/tests/examples/data/";
  ValidateOptions vo;
  vo.gen.rigPath = data + "binormal.rig.yaml";
  vo.gen.fragmentPath = data + "frame_color.frag";
  vo.gen.rulesPaths = {std::string(SG_SOURCE_DIR) + "/rules/standard.yaml"};
  vo.gen.templateDir = std::string(SG_SOURCE_DIR) + "/templates";
  vo.crossCheck = true;
  GenerateResult r = generate(vo.gen);
  auto rules = planRules(r);
  EXPECT_TRUE(has(rules, "world_handedness_from_binormal"));
  EXPECT_TRUE(has(rules, "clip_from_view_projection"));
  Validator v(vo);
  ValidateReport report = v.run(proceduralScene(r.in.rig, "limb", 3, 2));
  EXPECT_TRUE(report.pass) << formatReport(report);
}

}  // namespace
}  // namespace sg

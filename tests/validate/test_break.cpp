// Break tests: a copy of the rules library with one rule broken on purpose must fail
// validation, and the failure must be reported against exactly the outputs that depend on
// the broken value. The Dawn face (examples/dawn) on the procedural head, 2 poses.
//
// Dependencies in the Dawn face's chosen plan (see `shadergen generate` for the plan):
//   gl_Position       <- clip.position <- eye.position <- world.position <- skin.matrix, object.position
//   WorldTanMatrix*   <- world.tangent, world.binormal, world.normal
//                        (world.tangent <- object.tangent <- object.normal, skin.matrix)
//   WorldEyeDir       <- world.position, camera.position
//   SkinUVST          <- vertex.texcoord0/1 (pass-through)
//   SkinSilhouetteVec <- object.occlusion, view.ndotv (ndotv_world_space: world.normal,
//                        world.eye_dir), dapple.normal_z (world.normal)
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <iostream>

#include "test_util.h"
#include "validate/validate.h"

namespace {

using namespace sgtest;
using Set = std::set<std::string>;

const Set kAll = {"gl_Position", "WorldTanMatrixX", "WorldTanMatrixY", "WorldTanMatrixZ",
                  "WorldEyeDir", "SkinUVST",        "SkinSilhouetteVec"};

sg::ValidateReport validateDawn(const RulesCopy& rules, bool crossCheck = false) {
  sg::ValidateOptions vo;
  vo.gen.rigPath = sourcePath("examples/dawn/face.rig.yaml");
  vo.gen.fragmentPath = sourcePath("examples/dawn/face.frag");
  vo.gen.rulesPaths = {rules.dawnRules().string()};
  vo.crossCheck = crossCheck;
  sg::Rig rig = sg::loadRigFile(vo.gen.rigPath);
  sg::ValidationScene scene = sg::proceduralScene(rig, "head", 1, 2);
  sg::Validator v(vo);
  sg::ValidateReport rep = v.run(scene);
  std::cout << sg::formatReport(rep);
  return rep;
}

const sg::OutputReport* output(const sg::RunReport& run, const std::string& name) {
  for (const auto& o : run.outputs)
    if (o.name == name) return &o;
  return nullptr;
}

// The chosen plan of a broken library: it still uses `rule` (breaking a rule's body does not
// change its cost), fails, and fails on exactly `expected`; no validation-layer messages.
void expectBroken(const sg::ValidateReport& rep, const std::string& rule, const Set& expected) {
  ASSERT_EQ(rep.runs.size(), 1u);
  const sg::RunReport& run = rep.runs[0];
  EXPECT_TRUE(planHas(run, rule)) << rule << " is not in the plan";
  EXPECT_EQ(allOutputs(run), kAll);
  EXPECT_FALSE(rep.pass);
  EXPECT_FALSE(run.pass);
  EXPECT_EQ(failingOutputs(run), expected);
  EXPECT_TRUE(run.validationMessages.empty());
  // A broken rule is off by far more than the tolerance, not by rounding.
  for (const auto& o : run.outputs) {
    if (!o.pass) EXPECT_GT(o.maxRelError, 1e-3) << o.name;
  }
}

TEST(BreakRules, UnbrokenCopyPasses) {
  RulesCopy rules("unbroken");
  sg::ValidateReport rep = validateDawn(rules);
  ASSERT_EQ(rep.runs.size(), 1u);
  EXPECT_TRUE(rep.pass);
  EXPECT_EQ(allOutputs(rep.runs[0]), kAll);
  EXPECT_EQ(failingOutputs(rep.runs[0]), Set{});
  EXPECT_TRUE(rep.runs[0].validationMessages.empty());
}

// Wrong sign: vertex -> eye instead of eye -> vertex. view.ndotv takes abs(dot(N, E)), so
// the silhouette terms do not see the sign: only WorldEyeDir fails.
TEST(BreakRules, EyeDirWrongSign) {
  RulesCopy rules("eye_sign");
  ASSERT_TRUE(rules.edit("view.yaml", "normalize(${world.position} - ${camera.position})",
                         "normalize(${camera.position} - ${world.position})"));
  expectBroken(validateDawn(rules), "world_eye_dir", {"WorldEyeDir"});
}

// Swapped index: target i's position delta weighted by target i+1's weight. object.position
// feeds world.position: the clip position, the eye direction and (through ndotv_world_space)
// the silhouette terms; the tangent frame does not depend on the position.
TEST(BreakRules, MorphWeightWrongIndex) {
  RulesCopy rules("morph_index");
  ASSERT_TRUE(rules.edit("morph.yaml", "${out} += ${morph.weights}[${i}] * ${morph.position[i]};",
                         "${out} += ${morph.weights}[${(i + 1) % morph_targets}] * ${morph.position[i]};"));
  sg::ValidateReport rep = validateDawn(rules);
  expectBroken(rep, "object_position_morphed", {"gl_Position", "WorldEyeDir", "SkinSilhouetteVec"});
  // Within SkinSilhouetteVec only the N.V terms (components 1, 2) are wrong.
  const sg::OutputReport* sil = output(rep.runs[0], "SkinSilhouetteVec");
  ASSERT_NE(sil, nullptr);
  EXPECT_TRUE(sil->worstComponent == 1 || sil->worstComponent == 2) << sil->worstComponent;
}

// Swapped index: influence k's weight applied to influence k-1's joint (within the group of four). skin.matrix moves
// every world-space value; only the pass-through SkinUVST survives.
TEST(BreakRules, SkinJointWrongComponent) {
  RulesCopy rules("skin_joint");
  ASSERT_TRUE(rules.edit("skinning.yaml", "mat4 b${k}_ = ${skin.bones}[${skin.joints[k / 4]}[${k % 4}]];",
                         "mat4 b${k}_ = ${skin.bones}[${skin.joints[k / 4]}[${(k + 3) % 4}]];"));
  Set expected = kAll;
  expected.erase("SkinUVST");
  expectBroken(validateDawn(rules), "skin_matrix_blend", expected);
}

// Missing normalize on the morphed object normal. world_normal_from_matrix renormalises, so
// world.normal (hence ndotv and the dapple term) is still right; but Gram-Schmidt with a
// non-unit normal gives a wrong object.tangent, so the tangent frame rows fail.
TEST(BreakRules, ObjectNormalNotNormalized) {
  RulesCopy rules("object_normal");
  ASSERT_TRUE(rules.edit("morph.yaml", "${out} = normalize(${morph.normal_occlusion}.xyz);",
                         "${out} = ${morph.normal_occlusion}.xyz;"));
  expectBroken(validateDawn(rules), "object_normal_from_normal_occlusion",
               {"WorldTanMatrixX", "WorldTanMatrixY", "WorldTanMatrixZ"});
}

// Missing normalize on the skinned world normal (blended, scaled bones): the frame rows
// (their N column), and the silhouette terms (ndotv, dapple.normal_z) fail; positions don't.
TEST(BreakRules, WorldNormalNotNormalized) {
  RulesCopy rules("world_normal");
  ASSERT_TRUE(rules.edit("skinning.yaml", "${out} = normalize(mat3(${skin.matrix}) * ${object.normal});",
                         "${out} = mat3(${skin.matrix}) * ${object.normal};"));
  expectBroken(validateDawn(rules), "world_normal_from_matrix",
               {"WorldTanMatrixX", "WorldTanMatrixY", "WorldTanMatrixZ", "SkinSilhouetteVec"});
}

// Wrong matrix: the eye-space position multiplied by the view instead of the projection.
// Only gl_Position uses clip.position.
TEST(BreakRules, ClipWrongMatrix) {
  RulesCopy rules("clip_matrix");
  ASSERT_TRUE(rules.edit("projection.yaml", "needs: [eye.position, camera.projection]",
                         "needs: [eye.position, camera.projection, camera.view]"));
  ASSERT_TRUE(rules.edit("projection.yaml", "${out} = ${camera.projection} * ${eye.position};",
                         "${out} = ${camera.view} * ${eye.position};"));
  expectBroken(validateDawn(rules), "clip_from_eye", {"gl_Position"});
}

// A rig giving only camera.view_projection (no view, no projection): gl_Position is compared
// all the same, with clip.position from the projection and view of the pose whose product
// the rig's view_projection is. The copy passes; the clip rule with the transposed matrix
// fails on gl_Position alone.
sg::ValidateReport validateViewProjectionOnly(const RulesCopy& rules) {
  sg::ValidateOptions vo;
  vo.gen.rigPath = dataPath("view_projection_only.rig.yaml");
  vo.gen.fragmentPath = dataPath("basic.frag");
  vo.gen.rulesPaths = {rules.rulesFile("standard.yaml").string()};
  sg::Validator v(vo);
  sg::ValidateReport rep = v.run(sg::proceduralScene(sg::loadRigFile(vo.gen.rigPath), "limb", 1, 2));
  std::cout << sg::formatReport(rep);
  return rep;
}

TEST(BreakRules, ClipFromViewProjectionIsCheckedWithoutAProjection) {
  RulesCopy rules("view_projection");
  const sg::ValidateReport good = validateViewProjectionOnly(rules);
  ASSERT_EQ(good.runs.size(), 1u);
  EXPECT_TRUE(good.pass);
  EXPECT_TRUE(planHas(good.runs[0], "clip_from_view_projection"));
  const sg::OutputReport* clip = output(good.runs[0], "gl_Position");
  ASSERT_NE(clip, nullptr);
  EXPECT_FALSE(clip->unchecked) << clip->uncheckedReason;
  EXPECT_EQ(sg::formatReport(good).find("unchecked"), std::string::npos);

  ASSERT_TRUE(rules.edit("projection.yaml", "${out} = ${camera.view_projection} * vec4(${world.position}, 1.0);",
                         "${out} = transpose(${camera.view_projection}) * vec4(${world.position}, 1.0);"));
  const sg::ValidateReport broken = validateViewProjectionOnly(rules);
  ASSERT_EQ(broken.runs.size(), 1u);
  EXPECT_TRUE(planHas(broken.runs[0], "clip_from_view_projection"));
  EXPECT_FALSE(broken.pass);
  EXPECT_EQ(failingOutputs(broken.runs[0]), Set{"gl_Position"});
  EXPECT_TRUE(broken.runs[0].validationMessages.empty());
}

// The dapple term with the matrix's third column instead of its third row (the transpose,
// i.e. the inverse rotation): only SkinSilhouetteVec.w is wrong.
TEST(BreakRules, DappleColumnInsteadOfRow) {
  RulesCopy rules("dapple");
  ASSERT_TRUE(rules.edit("view.yaml", "dot(vec3(${dapple.matrix}[0].z, ${dapple.matrix}[1].z, ${dapple.matrix}[2].z)",
                         "dot(vec3(${dapple.matrix}[2].x, ${dapple.matrix}[2].y, ${dapple.matrix}[2].z)"));
  sg::ValidateReport rep = validateDawn(rules);
  expectBroken(rep, "dapple_normal_z_row", {"SkinSilhouetteVec"});
  const sg::OutputReport* sil = output(rep.runs[0], "SkinSilhouetteVec");
  ASSERT_NE(sil, nullptr);
  EXPECT_EQ(sil->worstComponent, 3);
}

// A broken alternative the chosen plan does not use is caught by the cross-check only: the
// chosen plan passes and exactly the run forcing the broken rule fails.
TEST(BreakRules, CrossCheckCatchesBrokenAlternative) {
  RulesCopy rules("alternative");
  ASSERT_TRUE(rules.edit("view.yaml", "abs(dot(normalize(-${eye.position}.xyz), ${eye.normal}))",
                         "abs(dot(-${eye.position}.xyz, ${eye.normal}))"));
  sg::ValidateReport rep = validateDawn(rules, /*crossCheck=*/true);
  ASSERT_GT(rep.runs.size(), 1u);
  EXPECT_FALSE(rep.pass);
  EXPECT_TRUE(rep.runs[0].pass);
  EXPECT_FALSE(planHas(rep.runs[0], "ndotv_eye_space"));
  int failed = 0;
  for (const auto& run : rep.runs) {
    EXPECT_TRUE(run.validationMessages.empty()) << run.label;
    if (run.pass) continue;
    ++failed;
    EXPECT_EQ(run.label, "forced ndotv_eye_space for view.ndotv");
    EXPECT_TRUE(planHas(run, "ndotv_eye_space"));
    EXPECT_EQ(failingOutputs(run), Set{"SkinSilhouetteVec"});
  }
  EXPECT_EQ(failed, 1);
}

// The CLI exits 1 on a mismatch and 0 when the shader is right.
int runCli(const RulesCopy& rules, const std::string& logName, std::string& log) {
  fs::path logPath = rules.root() / logName;
  std::string cmd = std::string("'") + SG_CLI + "' validate --rig '" + sourcePath("examples/dawn/face.rig.yaml") +
                    "' -f '" + sourcePath("examples/dawn/face.frag") + "' -r '" + rules.dawnRules().string() +
                    "' --poses 1 > '" + logPath.string() + "' 2>&1";
  int status = std::system(cmd.c_str());
  log = readText(logPath);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(BreakRules, CliExitStatus) {
  RulesCopy rules("cli");
  std::string log;
  EXPECT_EQ(runCli(rules, "good.log", log), 0) << log;
  EXPECT_NE(log.find("PASS: 1 run(s)"), std::string::npos) << log;

  ASSERT_TRUE(rules.edit("view.yaml", "normalize(${world.position} - ${camera.position})",
                         "normalize(${camera.position} - ${world.position})"));
  EXPECT_EQ(runCli(rules, "broken.log", log), 1) << log;
  EXPECT_NE(log.find("FAIL WorldEyeDir"), std::string::npos) << log;
  EXPECT_NE(log.find("FAIL: 1 run(s)"), std::string::npos) << log;
}

}  // namespace

// Fragment shaders written with the varying names of three.js, the glTF Sample Viewer and
// Filament go through generate with no --map (rules/conventions.yaml) and validate on
// lavapipe against the GLM reference, the mat3 TBN of the Sample Viewer included.
#include <gtest/gtest.h>

#include <iostream>
#include <map>

#include "validate/validate.h"

namespace {

const std::string kSrc = SG_SOURCE_DIR;

sg::ValidateReport validateStyle(const std::string& fragment) {
  sg::ValidateOptions vo;
  vo.gen.rigPath = kSrc + "/examples/dawn/face.rig.yaml";
  vo.gen.fragmentPath = kSrc + "/tests/validate/data/conventions/" + fragment;
  vo.gen.rulesPaths = {kSrc + "/rules/standard.yaml"};  // no overrides, no varyings: names only
  sg::ValidationScene scene = sg::proceduralScene(sg::loadRigFile(vo.gen.rigPath), "head", 7, 2);
  sg::Validator v(vo);
  sg::ValidateReport rep = v.run(scene);
  std::cout << sg::formatReport(rep);
  return rep;
}

// Every output passed, with the semantics the convention gives it.
void expectOutputs(const sg::ValidateReport& rep, const std::map<std::string, std::vector<std::string>>& want) {
  ASSERT_EQ(rep.runs.size(), 1u);
  EXPECT_TRUE(rep.pass);
  EXPECT_TRUE(rep.runs[0].validationMessages.empty());
  std::map<std::string, std::vector<std::string>> got;
  for (const auto& o : rep.runs[0].outputs) {
    EXPECT_TRUE(o.pass) << o.name << " max abs " << o.maxAbsError;
    if (o.name != "gl_Position") got[o.name] = o.semantics;
  }
  EXPECT_EQ(got, want);
}

TEST(Conventions, ThreeJsNamesValidate) {
  expectOutputs(validateStyle("threejs.frag"), {{"vNormal", {"eye.normal"}},
                                               {"vWorldPosition", {"world.position"}},
                                               {"vUv", {"vertex.texcoord0"}},
                                               {"vUv1", {"vertex.texcoord1"}}});
}

TEST(Conventions, GltfSampleViewerNamesAndMat3TbnValidate) {
  expectOutputs(validateStyle("gltf_sample_viewer.frag"),
                {{"v_Position", {"world.position"}},
                 {"v_Normal", {"world.normal"}},
                 {"v_TBN", {"world.tangent", "world.binormal", "world.normal"}},
                 {"v_texcoord_0", {"vertex.texcoord0"}},
                 {"v_texcoord_1", {"vertex.texcoord1"}}});
}

TEST(Conventions, FilamentNamesValidate) {
  expectOutputs(validateStyle("filament.frag"), {{"vertex_worldPosition", {"world.position"}},
                                                {"vertex_worldNormal", {"world.normal"}},
                                                {"vertex_worldTangent", {"world.tangent", "world.handedness"}},
                                                {"vertex_uv01", {"vertex.texcoord0", "vertex.texcoord1"}}});
}

// A swapped matrix column is caught: the GPU's mat3 is compared column by column with the
// reference of each semantic, so a mat3 built (normal, binormal, tangent) against the
// declared (tangent, binormal, normal) order fails.
TEST(Conventions, Mat3ColumnsAreComparedInOrder) {
  sg::ValidateOptions vo;
  vo.gen.rigPath = kSrc + "/examples/dawn/face.rig.yaml";
  vo.gen.fragmentPath = kSrc + "/tests/validate/data/conventions/gltf_sample_viewer.frag";
  vo.gen.rulesPaths = {kSrc + "/rules/standard.yaml"};
  vo.gen.capture = true;
  sg::GenerateResult r = sg::generate(vo.gen);
  sg::ValidationScene scene = sg::proceduralScene(r.in.rig, "head", 7, 1);
  sg::Validator v(vo);
  // Swap the first and last column in the emitted GLSL and recompile through the stages.
  std::string& text = r.glsl.text;
  const std::string good = "mat3(t_world_tangent, t_world_binormal, t_world_normal)";
  size_t at = text.find(good);
  ASSERT_NE(at, std::string::npos) << text;
  text.replace(at, good.size(), "mat3(t_world_normal, t_world_binormal, t_world_tangent)");
  sg::CompiledVertexShader c = sg::compileStage(r.in, r.plan, r.glsl, "swapped.vert", vo.gen.targetEnv);
  r.spirv = c.module;
  sg::RunReport bad = v.runOne(r, scene, "swapped columns");
  std::map<std::string, bool> pass;
  for (const auto& o : bad.outputs) pass[o.name] = o.pass;
  EXPECT_FALSE(pass["v_TBN"]);
  EXPECT_TRUE(pass["v_Normal"]);
  EXPECT_TRUE(pass["v_Position"]);
}

}  // namespace

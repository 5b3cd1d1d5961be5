// Fragment shaders written with the varying names of three.js, the glTF Sample Viewer and
// Filament go through generate with no --map (rules/conventions.yaml) and validate on
// lavapipe against the GLM reference, the mat3 TBN of the Sample Viewer included.
#include <gtest/gtest.h>

#include <filesystem>
#include <iostream>
#include <map>

#include "test_util.h"
#include "validate/gltf_scene.h"
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

// Generates with the standard rules (capture build); `failing(good, bad)` replaces `good` by
// `bad` in the emitted GLSL, recompiles through the stages, runs it and returns the outputs
// that fail (an empty `good` runs the shader as generated).
struct Planted {
  sg::ValidateOptions vo;
  sg::GenerateResult r;
  sg::ValidationScene scene;
  Planted(const std::string& rig, const std::string& fragment, uint32_t seed, int poses) {
    vo.gen.rigPath = rig;
    vo.gen.fragmentPath = fragment;
    vo.gen.rulesPaths = {kSrc + "/rules/standard.yaml"};
    vo.gen.capture = true;
    r = sg::generate(vo.gen);
    scene = sg::proceduralScene(r.in.rig, "head", seed, poses);
  }
  std::set<std::string> failing(const std::string& good, const std::string& bad) {
    sg::GenerateResult p = r;
    if (!good.empty()) {
      size_t at = p.glsl.text.find(good);
      EXPECT_NE(at, std::string::npos) << p.glsl.text;
      if (at == std::string::npos) return {"(not planted)"};
      p.glsl.text.replace(at, good.size(), bad);
      p.spirv = sg::compileStage(p.in, p.plan, p.glsl, "planted.vert", vo.gen.targetEnv).module;
    }
    return sgtest::failingOutputs(sg::Validator(vo).runOne(p, scene, "planted"));
  }
};

// A swapped matrix column is caught: the GPU's mat3 is compared column by column with the
// reference of each semantic, so a mat3 built (normal, binormal, tangent) against the
// declared (tangent, binormal, normal) order fails.
TEST(Conventions, Mat3ColumnsAreComparedInOrder) {
  Planted p(kSrc + "/examples/dawn/face.rig.yaml", kSrc + "/tests/validate/data/conventions/gltf_sample_viewer.frag", 7, 1);
  EXPECT_EQ(p.failing("mat3(world_tangent, world_binormal, world_normal)",
                      "mat3(world_normal, world_binormal, world_tangent)"),
            std::set<std::string>{"v_TBN"});
}

// three.js's MeshStandardMaterial varyings (issue 24): view-space position as three.js
// writes it (vViewPosition = -mvPosition.xyz), view-space normal, tangent and bitangent, uv.
// Every name maps through the 'threejs' convention; no --map, no user rules.

const std::string kShared = SG_SHARED_DIR;

sg::ValidateReport validateThree(const std::string& rig, const std::string& fragment, const sg::ValidationScene& scene,
                                 bool crossCheck) {
  sg::ValidateOptions vo;
  vo.gen.rigPath = rig;
  vo.gen.fragmentPath = fragment;
  vo.gen.rulesPaths = {kSrc + "/rules/standard.yaml"};
  vo.crossCheck = crossCheck;
  sg::Validator v(vo);
  sg::ValidateReport rep = v.run(scene);
  std::cout << sg::formatReport(rep);
  return rep;
}

void expectAllPass(const sg::ValidateReport& rep, const std::map<std::string, std::string>& want) {
  ASSERT_FALSE(rep.runs.empty());
  EXPECT_TRUE(rep.pass);
  for (const auto& run : rep.runs) {
    std::map<std::string, std::string> got;
    for (const auto& o : run.outputs) {
      EXPECT_TRUE(o.pass) << run.label << ": " << o.name << " max abs " << o.maxAbsError;
      ASSERT_EQ(o.semantics.size(), 1u) << o.name;
      if (o.name != "gl_Position") got[o.name] = o.semantics[0];
    }
    EXPECT_EQ(got, want) << run.label;
  }
}

const std::map<std::string, std::string> kStandardTbn = {{"vViewPosition", "eye.to_camera"},
                                                         {"vNormal", "eye.normal"},
                                                         {"vTangent", "eye.tangent"},
                                                         {"vBitangent", "eye.binormal"},
                                                         {"vUv", "vertex.texcoord0"}};

// A mesh with three.js's own uniforms (modelViewMatrix, normalMatrix): the plan reads them,
// and every alternative (through the view matrix instead) validates too, under the default
// hostile poses, whose model matrix scales per axis (the normal matrix must be the inverse
// transpose).
TEST(ThreeJs, StandardMaterialOnAThreeJsMesh) {
  const std::string rig = kSrc + "/examples/threejs/mesh.rig.yaml";
  sg::ValidationScene scene = sg::proceduralScene(sg::loadRigFile(rig), "head", 3, 2);
  sg::ValidateReport rep = validateThree(rig, kSrc + "/examples/threejs/standard_normalmap.frag", scene, true);
  expectAllPass(rep, kStandardTbn);
  ASSERT_GE(rep.runs.size(), 4u);  // the chosen plan and the forced alternatives
  const sg::RunReport& chosen = rep.runs[0];
  EXPECT_TRUE(sgtest::planHas(chosen, "eye_position_model_view"));
  EXPECT_TRUE(sgtest::planHas(chosen, "eye_normal_normal_matrix"));
  EXPECT_TRUE(sgtest::planHas(chosen, "eye_tangent_model_view"));
  bool viewPath = false;
  for (const auto& run : rep.runs) viewPath = viewPath || sgtest::planHas(run, "eye_normal");
  EXPECT_TRUE(viewPath) << "the alternative through world.normal and viewMatrix was not forced";
}

// Skinning and morphs (the Dawn face rig: 4 influences, 5 morph targets moving position and
// normal): three.js's skinnormal/morphnormal come first, then view space.
TEST(ThreeJs, StandardMaterialOnASkinnedMorphedRig) {
  const std::string rig = kSrc + "/examples/dawn/face.rig.yaml";
  sg::ValidationScene scene = sg::proceduralScene(sg::loadRigFile(rig), "head", 5, 2);
  expectAllPass(validateThree(rig, kSrc + "/examples/threejs/standard_normalmap.frag", scene, true), kStandardTbn);
}

bool haveSharedModels() { return std::filesystem::exists(kShared + "/models/README.md"); }

sg::ValidateReport validateModel(const std::string& model, const std::string& fragment, std::vector<double> times) {
  const std::string path = kShared + "/models/" + model;
  sg::GltfSceneOptions so;
  so.times = std::move(times);
  return validateThree(path, fragment, sg::gltfScene(path, so), true);
}

// The shared Fox is skinned and has no normals: MeshStandardMaterial's flatShading path
// (normals from the derivatives of vViewPosition) mid-animation.
TEST(ThreeJs, FlatShadedStandardMaterialOnTheSkinnedFox) {
  if (!haveSharedModels()) GTEST_SKIP() << "no shared models at " << kShared;
  expectAllPass(validateModel("Fox/Fox.glb", kSrc + "/examples/threejs/standard_flat.frag", {0.5, 1.7}),
                {{"vViewPosition", "eye.to_camera"}, {"vUv", "vertex.texcoord0"}});
}

// Morphed models: 8 targets moving position and normal (with UVs), and a sphere whose 2
// targets move position, normal and tangent (three.js's morphnormal + USE_TANGENT).
TEST(ThreeJs, StandardMaterialOnMorphedModels) {
  if (!haveSharedModels()) GTEST_SKIP() << "no shared models at " << kShared;
  expectAllPass(validateModel("MorphStressTest/MorphStressTest.gltf", kSrc + "/examples/threejs/standard.frag", {0.5, 2.0}),
                {{"vViewPosition", "eye.to_camera"}, {"vNormal", "eye.normal"}, {"vUv", "vertex.texcoord0"}});
  expectAllPass(validateModel("AnimatedMorphSphere/AnimatedMorphSphere.gltf",
                              kSrc + "/tests/validate/data/conventions/threejs_tbn.frag", {0.3, 1.1}),
                {{"vViewPosition", "eye.to_camera"},
                 {"vNormal", "eye.normal"},
                 {"vTangent", "eye.tangent"},
                 {"vBitangent", "eye.binormal"}});
}

// Planted errors are caught: vViewPosition without three.js's minus, and a normal matrix
// that is mat3(modelViewMatrix) instead of its inverse transpose (wrong under the per-axis
// model scale of the default poses).
TEST(ThreeJs, PlantedErrorsFail) {
  Planted p(kSrc + "/examples/threejs/mesh.rig.yaml", kSrc + "/examples/threejs/standard_normalmap.frag", 3, 2);
  EXPECT_EQ(p.failing("", ""), std::set<std::string>{});
  EXPECT_EQ(p.failing("= -eye_position.xyz;", "= eye_position.xyz;"), std::set<std::string>{"vViewPosition"});
  // The normal feeds the bitangent's cross product, so both go wrong.
  EXPECT_EQ(p.failing("normalize(u_normalMatrix * object_normal)", "normalize(mat3(u_modelViewMatrix) * object_normal)"),
            (std::set<std::string>{"vNormal", "vBitangent"}));
}

}  // namespace

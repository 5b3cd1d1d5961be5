// Every skinned or morphing model of ../shared/models: import, generate for a fragment shader
// asking for what the model can feed, and validate on lavapipe (validation layers on, zero
// messages) at two or more animation times, every alternative derivation included. Each
// run also has a negative control: the same shader with the pose wired wrongly (neighbouring
// joint matrix, halved morph weights, or a scaled node transform) must fail the comparison.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>

#include <sys/wait.h>

#include "gltf_test_util.h"
#include "validate/gltf_scene.h"
#include "validate/validate.h"

namespace sg {
namespace {

using test::dataPath;
using test::modelPath;

struct Case {
  const char* label;
  const char* model;  // relative to ../shared/models, with #mesh/primitive; "tiny:..." = synthetic
  const char* fragment;
  const char* animation;
  std::vector<double> times;
  std::vector<float> extraWeights;  // models without animations: a second pose with these weights
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.label; }

const std::vector<Case>& cases() {
  static const std::vector<Case> all{
      {"Fox_Survey", "Fox/Fox.glb#0/0", "uv.frag", "Survey", {0.5, 1.7, 3.0}, {}},
      {"Fox_Run", "Fox/Fox.glb#0/0", "uv.frag", "Run", {0.25, 0.8}, {}},
      {"SimpleSkin", "SimpleSkin/SimpleSkin.gltf#0/0", "minimal.frag", "", {1.0, 3.3}, {}},
      {"MorphStressTest_p0", "MorphStressTest/MorphStressTest.gltf#0/0", "lit_uv2.frag", "TheWave", {0.4, 1.3}, {}},
      {"MorphStressTest_p1", "MorphStressTest/MorphStressTest.gltf#0/1", "lit_uv2.frag", "TheWave", {0.4, 1.3}, {}},
      {"MorphStressTest_p1_Individuals", "MorphStressTest/MorphStressTest.gltf#0/1", "lit_uv2.frag", "Individuals",
       {1.1, 5.6}, {}},
      {"AnimatedMorphSphere", "AnimatedMorphSphere/AnimatedMorphSphere.gltf#0/0", "frame.frag", "", {1.2, 3.9}, {}},
      {"MorphPrimitivesTest_p0", "MorphPrimitivesTest/MorphPrimitivesTest.gltf#0/0", "lit_uv.frag", "", {0.0}, {1.0f}},
      {"MorphPrimitivesTest_p1", "MorphPrimitivesTest/MorphPrimitivesTest.gltf#0/1", "lit_uv.frag", "", {0.0}, {1.0f}},
      {"SimpleMorph", "SimpleMorph/SimpleMorph.gltf#0/0", "minimal.frag", "", {1.0, 2.5}, {}},
      // Synthetic models (gltf_test_util.h) for what the samples lack: uint8 joints, unorm8
      // weights, unorm16 colours, sparse morph deltas, skinning + morphing, CUBICSPLINE and
      // STEP channels; non-zero normal/tangent deltas under an animated node hierarchy.
      {"Tiny_skinned_morphing", "tiny:skinned", "color_uv.frag", "", {0.7, 2.0}, {}},
      {"Tiny_morphed_frame", "tiny:frame", "frame.frag", "", {0.4, 1.3, 2.6}, {}},
  };
  return all;
}

// Replaces every occurrence of `from` in the body of main() (not the declarations); returns
// how many.
int replaceAll(std::string& s, const std::string& from, const std::string& to) {
  int n = 0;
  size_t body = s.find("void main()");
  if (body == std::string::npos) return 0;
  for (size_t p = s.find(from, body); p != std::string::npos; p = s.find(from, p + to.size())) {
    s.replace(p, from.size(), to);
    ++n;
  }
  return n;
}

class GltfValidate : public ::testing::TestWithParam<Case> {};

TEST_P(GltfValidate, PassesAtEveryTimeAndCatchesAWrongPose) {
  const Case& c = GetParam();
  std::string modelRef = modelPath(c.model);
  if (std::string(c.model).rfind("tiny:", 0) == 0) {  // synthetic: a self-contained .gltf in the temp dir
    std::string kind = std::string(c.model).substr(5);
    modelRef = (std::filesystem::temp_directory_path() / fmt::format("sg_tiny_{}.gltf", kind)).string();
    std::ofstream(modelRef) << (kind == "skinned" ? test::tinySkinnedModel() : test::tinyMorphFrameModel());
  }
  GltfRef ref = parseGltfRef(modelRef);
  GltfImportOptions io;
  io.mesh = ref.mesh;
  io.primitive = ref.primitive;
  GltfImport model = importGltf(ref.file, io);
  const bool skinned = model.rig.param("influences") > 0;
  const bool morphing = model.rig.morphTargets() > 0;
  ASSERT_TRUE(skinned || morphing);

  GltfSceneOptions so;
  so.times = c.times;
  so.animation = c.animation;
  GltfSceneInfo info;
  ValidationScene scene = gltfScene(model, so, &info);
  if (!c.extraWeights.empty()) {  // no animation: pose the morph weights by hand as well
    ASSERT_TRUE(info.animation.empty());
    rt::Pose p = scene.poses.front();
    p.morphWeights = c.extraWeights;
    scene.poses.push_back(p);
  } else {
    ASSERT_FALSE(info.animation.empty());
  }
  ASSERT_GE(scene.poses.size(), 2u);
  // The poses differ: the animation moves the model between the times.
  bool differ = false;
  for (size_t i = 1; i < scene.poses.size(); ++i)
    differ = differ || scene.poses[i].bones != scene.poses[0].bones ||
             scene.poses[i].morphWeights != scene.poses[0].morphWeights;
  EXPECT_TRUE(differ);

  ValidateOptions vo;
  vo.gen.rigPath = modelRef;
  vo.gen.fragmentPath = dataPath(c.fragment);
  vo.gen.rulesPaths = {test::sourcePath("rules/standard.yaml")};
  vo.validationLayers = true;
  vo.crossCheck = true;  // every alternative derivation, too
  Validator v(vo);
  ValidateReport report = v.run(scene);
  std::string times;
  for (double t : info.times) times += fmt::format(" {:g}", t);
  std::cout << fmt::format("{} ({} vertices), animation '{}', t ={}\n", model.rig.name, scene.mesh.vertexCount,
                           info.animation, times)
            << formatReport(report);
  EXPECT_TRUE(report.validationLayers);
  EXPECT_TRUE(report.pass);
  ASSERT_FALSE(report.runs.empty());
  for (const auto& run : report.runs) {
    EXPECT_TRUE(run.pass) << run.label;
    EXPECT_TRUE(run.validationMessages.empty()) << run.label;
    EXPECT_EQ(run.vertices, model.data.vertexCount);
  }

  // Negative control: the chosen shader with the pose wired wrongly.
  GenerateOptions g = vo.gen;
  g.capture = true;
  GenerateResult good = generate(g);
  GenerateResult bad = good;
  // MorphStressTest's first primitive (the base cube) has targets whose deltas are all zero:
  // there the weights move nothing, so the node transform is perturbed instead.
  bool deltasMove = false;
  for (const auto& [sem, values] : model.data.streams)
    if (sem.rfind("morph.", 0) == 0)
      for (const auto& v : values) deltasMove = deltasMove || v[0] != 0 || v[1] != 0 || v[2] != 0;
  int edits = skinned      ? replaceAll(bad.glsl.text, "u_bones[", "u_bones[1u ^ ")  // the neighbouring joint's matrix
              : deltasMove ? replaceAll(bad.glsl.text, "u_morph_weights[", "0.5 * u_morph_weights[")  // half the weights
                           : replaceAll(bad.glsl.text, "u_model", "(1.5 * u_model)");  // a scaled node transform
  ASSERT_GT(edits, 0) << good.glsl.text;
  bad.spirv = compileVertexShader(bad.glsl, "perturbed.vert", TargetEnv::Vulkan1_0);
  RunReport control = v.runOne(bad, scene, "negative control");
  EXPECT_FALSE(control.pass) << "a wrongly posed shader passed";
  EXPECT_TRUE(control.validationMessages.empty());
  bool positionCaught = false;
  for (const auto& o : control.outputs)
    if (o.name == "world_position" || o.name == "gl_Position") positionCaught = positionCaught || !o.pass;
  EXPECT_TRUE(positionCaught);
  ValidateReport controlReport = report;
  controlReport.runs = {control};
  controlReport.pass = control.pass;
  std::cout << formatReport(controlReport);
}

INSTANTIATE_TEST_SUITE_P(Models, GltfValidate, ::testing::ValuesIn(cases()),
                         [](const ::testing::TestParamInfo<Case>& i) { return std::string(i.param.label); });

// The CLI: `rig import` writes YAML that loads; `validate --rig MODEL#m/p --time` passes.
TEST(GltfCli, ImportWritesLoadableYamlAndValidateTakesModels) {
  std::string out = (std::filesystem::temp_directory_path() / "sg_gltf_fox.rig.yaml").string();
  std::filesystem::remove(out);
  std::string cmd = fmt::format("\"{}\" rig import \"{}\" -o \"{}\"", SG_CLI, modelPath("Fox/Fox.glb"), out);
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  Rig rig = loadRigFile(out);
  EXPECT_EQ(rig.name, "Fox/fox1/0");
  EXPECT_EQ(rig.param("bones"), 24);
  std::filesystem::remove(out);

  cmd = fmt::format("XDG_RUNTIME_DIR=/tmp \"{}\" validate --rig \"{}\" -f \"{}\" -r \"{}\" --time 0.5 --time 1.7 > /dev/null",
                    SG_CLI, modelPath("Fox/Fox.glb#0/0"), dataPath("uv.frag"), test::sourcePath("rules/standard.yaml"));
  EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
  // Asking the Fox for normals fails with status 1 (input error), not a crash.
  cmd = fmt::format("\"{}\" validate --rig \"{}\" -f \"{}\" -r \"{}\" --time 0.5 2> /dev/null", SG_CLI,
                    modelPath("Fox/Fox.glb#0/0"), dataPath("uv_normal.frag"), test::sourcePath("rules/standard.yaml"));
  int status = std::system(cmd.c_str());
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 1) << status;
}

}  // namespace
}  // namespace sg

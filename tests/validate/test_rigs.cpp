// Validation of real requests: the Dawn face with the cross-check, and small test rigs
// (tests/validate/data) covering 2/4/8 influences with quantized joint/weight formats,
// rigid skinning, and unskinned meshes with and without a model matrix. Every run has the
// Khronos validation layer on and must leave it silent.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>

#include "runtime/reference.h"
#include "test_util.h"
#include "validate/program_inputs.h"
#include "validate/validate.h"

namespace {

using namespace sgtest;

struct Request {
  std::string rig, fragment, rules, mesh;
};

sg::ValidateReport validate(const Request& r, bool crossCheck, int poses = 2) {
  sg::ValidateOptions vo;
  vo.gen.rigPath = r.rig;
  vo.gen.fragmentPath = r.fragment;
  vo.gen.rulesPaths = {r.rules};
  vo.crossCheck = crossCheck;
  sg::Rig rig = sg::loadRigFile(vo.gen.rigPath);
  sg::ValidationScene scene = sg::proceduralScene(rig, r.mesh, 1, poses);
  sg::Validator v(vo);
  sg::ValidateReport rep = v.run(scene);
  std::cout << sg::formatReport(rep);
  ErrorMax m = maxErrors(rep);
  std::cout << "max abs error " << m.abs << " (" << m.absAt << "), max rel error " << m.rel << " (" << m.relAt
            << ")\n";
  return rep;
}

// Every run passes with the validation layer on and silent.
void expectAllPass(const sg::ValidateReport& rep) {
  EXPECT_TRUE(rep.validationLayers) << "VK_LAYER_KHRONOS_validation was not enabled";
  EXPECT_NE(rep.device.find("llvmpipe"), std::string::npos) << rep.device;
  EXPECT_TRUE(rep.pass);
  for (const auto& run : rep.runs) {
    EXPECT_TRUE(run.pass) << run.label;
    EXPECT_TRUE(run.validationMessages.empty()) << run.label << ": " << run.validationMessages.size() << " messages";
    EXPECT_GT(run.vertices, 0u);
    for (const auto& o : run.outputs) EXPECT_TRUE(o.pass) << run.label << ": " << o.name;
  }
}

// "forced <rule> for <semantic>" -> rule
std::string forcedRule(const std::string& label) {
  const std::string prefix = "forced ";
  if (label.rfind(prefix, 0) != 0) return "";
  return label.substr(prefix.size(), label.find(" for ") - prefix.size());
}

std::vector<std::string> forcedRules(const sg::ValidateReport& rep) {
  std::vector<std::string> out;
  for (size_t i = 1; i < rep.runs.size(); ++i) out.push_back(forcedRule(rep.runs[i].label));
  return out;
}

bool contains(const std::vector<std::string>& v, const std::string& s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}

TEST(DawnFace, CrossCheckForcesEveryAlternative) {
  sg::ValidateReport rep = validate({sourcePath("examples/dawn/face.rig.yaml"), sourcePath("examples/dawn/face.frag"),
                                     sourcePath("examples/dawn/rules.yaml"), "head"},
                                    /*crossCheck=*/true);
  expectAllPass(rep);
  ASSERT_GT(rep.runs.size(), 4u);
  const sg::RunReport& chosen = rep.runs[0];
  EXPECT_EQ(chosen.label, "chosen plan");
  EXPECT_EQ(chosen.vertices, 41u * 49u);
  for (size_t i = 1; i < rep.runs.size(); ++i) {
    const sg::RunReport& run = rep.runs[i];
    std::string rule = forcedRule(run.label);
    ASSERT_FALSE(rule.empty()) << run.label;
    EXPECT_TRUE(planHas(run, rule)) << run.label;
    EXPECT_FALSE(planHas(chosen, rule)) << run.label;
    EXPECT_NE(run.rules, chosen.rules) << run.label;
    EXPECT_GE(run.planCost, chosen.planCost) << run.label;  // the chosen plan is the cheapest
    for (size_t j = 1; j < i; ++j) EXPECT_NE(run.rules, rep.runs[j].rules) << run.label;
  }
  // Every alternative derivation the library has for a value of the Dawn plan.
  std::vector<std::string> forced = forcedRules(rep);
  for (const char* rule : {"object_normal_morphed", "world_normal_linear_blend", "world_tangent_linear_blend",
                           "world_position_linear_blend", "ndotv_eye_space", "dapple_normal_z_full",
                           "object_occlusion_morphed"})
    EXPECT_TRUE(contains(forced, rule)) << rule;
}

struct RigCase {
  const char* name;
  const char* rig;
  const char* fragment;
  const char* mesh;
  std::vector<std::string> chosenRules;  // must be in the chosen plan
  std::vector<std::string> forced;       // alternatives the cross-check must run
};

void PrintTo(const RigCase& c, std::ostream* os) { *os << c.name; }

class TestRigs : public ::testing::TestWithParam<RigCase> {};

TEST_P(TestRigs, ValidatesWithCrossCheck) {
  const RigCase& c = GetParam();
  sg::ValidateReport rep =
      validate({dataPath(c.rig), dataPath(c.fragment), sourcePath("rules/standard.yaml"), c.mesh}, true);
  expectAllPass(rep);
  ASSERT_FALSE(rep.runs.empty());
  for (const auto& r : c.chosenRules) EXPECT_TRUE(planHas(rep.runs[0], r)) << r;
  std::vector<std::string> forced = forcedRules(rep);
  for (const auto& r : c.forced) EXPECT_TRUE(contains(forced, r)) << r;
  for (size_t i = 1; i < rep.runs.size(); ++i) EXPECT_NE(rep.runs[i].rules, rep.runs[0].rules);
}

// The test rigs do not declare uniform_scale: their normals need the inverse transpose, so
// world_normal_linear_blend (= mat3(M)) is not an alternative (docs/rig-format.md).
const std::vector<std::string> kLinearBlends = {"world_position_linear_blend", "world_tangent_linear_blend"};

INSTANTIATE_TEST_SUITE_P(
    Validate, TestRigs,
    ::testing::Values(
        RigCase{"limb2", "limb2.rig.yaml", "world.frag", "limb", {"skin_matrix_blend"}, kLinearBlends},
        RigCase{"limb8", "limb8.rig.yaml", "world.frag", "limb", {"skin_matrix_blend"}, kLinearBlends},
        // Five influences (a last group of one) and uniform scale: every linear blend, the
        // normal's too, through vector_blend's partial-group path.
        RigCase{"limb5_uniform", "limb5_uniform.rig.yaml", "world.frag", "limb", {"skin_matrix_blend"},
                {"world_position_linear_blend", "world_normal_linear_blend", "world_tangent_linear_blend"}},
        RigCase{"limb4_unorm8", "limb4_unorm8.rig.yaml", "world.frag", "limb", {"skin_matrix_blend"}, kLinearBlends},
        // Every packed vertex format, read back on the device as the reference assumes.
        RigCase{"formats_a", "formats_a.rig.yaml", "formats.frag", "limb", {"skin_matrix_blend"}, kLinearBlends},
        RigCase{"formats_b", "formats_b.rig.yaml", "formats.frag", "limb", {"skin_matrix_blend"}, kLinearBlends},
        RigCase{"formats_rgb", "formats_rgb.rig.yaml", "formats.frag", "limb", {"skin_matrix_blend"}, kLinearBlends},
        RigCase{"formats_rg", "formats_rg.rig.yaml", "formats.frag", "limb", {"skin_matrix_blend"}, kLinearBlends},
        RigCase{"rigid1", "rigid1.rig.yaml", "eye.frag", "limb",
                {"skin_matrix_rigid", "eye_position", "eye_normal"}, {"dapple_normal_z_full"}},
        RigCase{"rigid1_world", "rigid1.rig.yaml", "world.frag", "limb",
                {"skin_matrix_rigid", "clip_from_view_projection"}, {"ndotv_eye_space"}},
        RigCase{"unskinned_model", "unskinned_model.rig.yaml", "eye.frag", "limb", {"skin_matrix_model"},
                {"dapple_normal_z_full"}},
        RigCase{"unskinned_model_head", "unskinned_model.rig.yaml", "world.frag", "head",
                {"skin_matrix_model", "clip_from_eye"}, {"ndotv_eye_space"}},
        RigCase{"unskinned_identity", "unskinned_identity.rig.yaml", "basic.frag", "limb",
                {"skin_matrix_identity", "clip_from_view_projection"}, {}}),
    [](const ::testing::TestParamInfo<RigCase>& p) { return std::string(p.param.name); });

// A float32x3 colour read as a vec4 (shader_type): the device supplies w = 1, so the reference
// must too, whatever alpha the mesh holds; the stored components stay as they are.
TEST(Quantization, WidenedColourReadsAlphaOne) {
  sg::Rig rig = sg::loadRigFile(dataPath("formats_rgb.rig.yaml"));
  sg::ValidationScene scene = sg::proceduralScene(rig, "limb", 1, 1);
  auto& drawn = scene.mesh.streams.at("vertex.color0");
  for (size_t v = 0; v < drawn.size(); ++v) drawn[v].w = 0.25f + 0.001f * static_cast<float>(v % 7);  // not 1
  const sg::rt::Mesh quantized = sg::quantizeForRig(rig, scene.mesh);
  const auto& read = quantized.streams.at("vertex.color0");
  ASSERT_EQ(read.size(), drawn.size());
  for (size_t v = 0; v < read.size(); ++v) {
    EXPECT_EQ(read[v], glm::vec4(glm::vec3(drawn[v]), 1.0f)) << "vertex " << v;
    if (HasFailure()) break;
  }
}

// A unorm8 RG colour read as a vec4: blue and alpha are the device's fill (0, 1) in the
// float data too, not the mesh's (its blue is (u + v) / 2): both checks pass, the second
// comparing every component, for the fill is exact and the stored red and green within
// their format's error.
TEST(Quantization, WidenedColourFillIsTheFloatDataToo) {
  const std::string rigPath = dataPath("formats_rg.rig.yaml");
  sg::ValidateReport rep = validate({rigPath, dataPath("formats.frag"), sourcePath("rules/standard.yaml"), "limb"}, false);
  expectAllPass(rep);
  bool colour = false;
  for (const auto& o : rep.runs.at(0).outputs) {
    EXPECT_TRUE(o.floatCheck.ran) << o.name;
    EXPECT_EQ(o.floatCheck.notCompared, 0u) << o.name;
    colour = colour || o.name == "vertex_color0";
  }
  EXPECT_TRUE(colour);
  // The mesh's blue is not what the device reads, so the fill is what the second check saw.
  const sg::Rig rig = sg::loadRigFile(rigPath);
  const sg::ValidationScene scene = sg::proceduralScene(rig, "limb", 1, 1);
  size_t blue = 0;
  for (const auto& c : scene.mesh.at("vertex.color0")) blue += c.z != 0.0f;
  EXPECT_GT(blue, scene.mesh.vertexCount / 2);
  double fillBound = 0;  // the fill is exact: no storage error to tolerate there
  for (const auto& b : sg::quantizationErrorBounds(rig, scene.mesh))
    if (b.semantic == "vertex.color0")
      for (const auto& v : b.bound) fillBound = std::max({fillBound, v.z, v.w});
  EXPECT_EQ(fillBound, 0.0);
}

// 16 vec4 varyings, 64 components (the least maxVertexOutputComponents Vulkan guarantees),
// each mapped to eye.position: with gl_Position the capture record is 68 components, past
// glslang's OpenGL default of 64 interleaved components but within the device's
// transform-feedback limits, which are the ones that apply.
sg::ValidateOptions outputs64(const std::string& rig) {
  sg::ValidateOptions vo;
  vo.gen.rigPath = rig;
  vo.gen.fragmentPath = dataPath("outputs64.frag");
  vo.gen.rulesPaths = {sourcePath("rules/standard.yaml")};
  for (int i = 0; i < 16; ++i) vo.gen.overrides.push_back({"e" + std::to_string(i), {"eye.position"}});
  return vo;
}

TEST(Capture, SixtyFourOutputComponentsValidate) {
  const sg::ValidateOptions vo = outputs64(dataPath("unskinned_model.rig.yaml"));
  sg::Validator v(vo);
  const sg::ValidateReport rep = v.run(sg::proceduralScene(sg::loadRigFile(vo.gen.rigPath), "limb", 1, 2));
  std::cout << sg::formatReport(rep);
  expectAllPass(rep);
  const sg::RunReport& run = rep.runs.at(0);
  ASSERT_EQ(run.outputs.size(), 17u);  // gl_Position and e0..e15
  for (const auto& o : run.outputs) EXPECT_FALSE(o.unchecked) << o.name << ": " << o.uncheckedReason;
}

// A device capturing fewer bytes a vertex than the record: a located error at the fragment
// input whose output crosses the limit, naming the Vulkan limits, before anything compiles.
TEST(Capture, ARecordPastTheDevicesLimitIsALocatedError) {
  sg::GenerateOptions gen = outputs64(dataPath("unskinned_model.rig.yaml")).gen;
  gen.capture = true;
  gen.maxCaptureBytes = 256;  // gl_Position and e0..e14; e15 is past it
  const std::string frag = readText(gen.fragmentPath);
  const int e15Line = 1 + static_cast<int>(std::count(frag.begin(), frag.begin() + static_cast<long>(frag.find("vec4 e15;")), '\n'));
  try {
    sg::generate(gen);
    FAIL() << "generated a capture record past the device's limit";
  } catch (const sg::InputError& e) {
    const sg::Diagnostic& d = e.diagnostic();
    EXPECT_EQ(d.loc.file, gen.fragmentPath);
    EXPECT_EQ(d.loc.line, e15Line);
    EXPECT_NE(d.message.find("maxTransformFeedbackBufferDataStride"), std::string::npos) << d.message;
    EXPECT_NE(d.message.find("'e15'"), std::string::npos) << d.message;
  }
  gen.maxCaptureBytes = 272;  // exactly the record
  EXPECT_NO_THROW(sg::generate(gen));
}

// The quantization path matters: with unorm8 weights, the reference fed the raw float weights
// is off by far more than the tolerance, so the unorm8 rig above only passes because the
// validator gives the reference the values the GPU reads.
TEST(Quantization, Unorm8WeightsChangeTheResultBeyondTolerance) {
  sg::Rig rig = sg::loadRigFile(dataPath("limb4_unorm8.rig.yaml"));
  sg::ValidationScene scene = sg::proceduralScene(rig, "limb", 1, 1);
  sg::rt::Mesh quantized = scene.mesh;
  for (auto& w : quantized.streams.at("skin.weights[0]"))
    for (int c = 0; c < 4; ++c) w[c] = std::round(std::clamp(w[c], 0.0f, 1.0f) * 255.0f) / 255.0f;
  auto raw = sg::rt::referenceValues("world.position", scene.mesh, scene.poses[0], scene.shape);
  auto q = sg::rt::referenceValues("world.position", quantized, scene.poses[0], scene.shape);
  double maxDiff = 0;
  for (size_t v = 0; v < raw.size(); ++v)
    for (int c = 0; c < 3; ++c) maxDiff = std::max(maxDiff, static_cast<double>(std::abs(raw[v][c] - q[v][c])));
  std::cout << "unorm8 weight quantization moves world.position by up to " << maxDiff << "\n";
  EXPECT_GT(maxDiff, 1e-4);  // 10x the largest tolerance (abs 1e-6 + rel 1e-5 * |p| with |p| < ~3)
}

// The unorm16 and uint16 paths are exercised: the limb's weights are not all representable
// in unorm16, so the stream the GPU reads differs from the float weights.
TEST(Quantization, Unorm16WeightsAreRounded) {
  sg::Rig rig = sg::loadRigFile(dataPath("limb2.rig.yaml"));
  sg::ValidationScene scene = sg::proceduralScene(rig, "limb", 1, 1);
  size_t changed = 0;
  for (const auto& w : scene.mesh.at("skin.weights[0]"))
    for (int c = 0; c < 4; ++c)
      if (std::round(w[c] * 65535.0f) / 65535.0f != w[c]) ++changed;
  EXPECT_GT(changed, scene.mesh.vertexCount);  // most vertices have 2 unrepresentable weights
  // How far the rounding moves world.position (docs/validation.md): about the tolerance.
  sg::rt::Mesh quantized = scene.mesh;
  for (auto& w : quantized.streams.at("skin.weights[0]"))
    for (int c = 0; c < 4; ++c) w[c] = std::round(std::clamp(w[c], 0.0f, 1.0f) * 65535.0f) / 65535.0f;
  auto raw = sg::rt::referenceValues("world.position", scene.mesh, scene.poses[0], scene.shape);
  auto q = sg::rt::referenceValues("world.position", quantized, scene.poses[0], scene.shape);
  double maxDiff = 0;
  for (size_t v = 0; v < raw.size(); ++v)
    for (int c = 0; c < 3; ++c) maxDiff = std::max(maxDiff, static_cast<double>(std::abs(raw[v][c] - q[v][c])));
  std::cout << "unorm16 weight quantization moves world.position by up to " << maxDiff << "\n";
  EXPECT_GT(maxDiff, 0.0);
  float maxJoint = 0;
  for (const auto& j : scene.mesh.at("skin.joints[0]")) maxJoint = std::max({maxJoint, j.x, j.y});
  EXPECT_EQ(maxJoint, 5.0f);  // joints span the 6-bone palette
}

}  // namespace

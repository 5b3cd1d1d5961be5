// Semantic definitions (rules/definition.h) and the reference interpreter
// (validate/interpreter.h): located errors for bad formulas; agreement with the
// hand-written GLM reference (runtime/reference.cpp) on every procedural mesh shape and the
// shared glTF models under hostile poses; pose files; a user's rules file with new
// semantics and uniforms validated on lavapipe, each planted sign error caught; break tests
// for the normal matrix and clamped morph weights.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <iostream>

#include "../gltf/gltf_test_util.h"
#include "rig/gltf_import.h"
#include "rules/instantiate.h"
#include "runtime/procedural.h"
#include "runtime/reference.h"
#include "test_util.h"
#include "validate/gltf_scene.h"
#include "validate/interpreter.h"
#include "validate/poses.h"
#include "validate/validate.h"

namespace {

namespace fs = std::filesystem;
namespace rt = sg::rt;
using sgtest::RulesCopy;
using sgtest::sourcePath;
using sgtest::writeText;

using sgtest::standardRules;

// The first error of loading `text` (the vocabulary plus it), or "" if it loads.
std::string loadError(const std::string& text) {
  sg::RuleSet set = sg::loadRules({sourcePath("rules/vocabulary.yaml")});
  try {
    sg::loadRulesText(set, text, "user.yaml");
    sg::checkDefinitions(set);
  } catch (const sg::InputError& e) {
    return sg::formatDiagnostic(e.diagnostic());
  }
  return "";
}

TEST(Definitions, BadFormulasAreLocated) {
  EXPECT_EQ(loadError("semantics:\n  a.b: { type: vec3, definition: \"world.normal +\" }\n"),
            "user.yaml:2:49: error: definition ends too early");
  EXPECT_EQ(loadError("semantics:\n  a.b: { type: vec3, definition: \"normalize(world.normul)\" }\n"),
            "user.yaml:2:45: error: unknown semantic 'world.normul' (did you mean 'world.normal'?)");
  EXPECT_EQ(loadError("semantics:\n  a.b: { type: vec3, definition: \"world.normal + camera.view\" }\n"),
            "user.yaml:2:48: error: cannot apply '+' to vec3 and mat4");
  EXPECT_EQ(loadError("semantics:\n  a.b: { type: float, definition: \"world.normal\" }\n"),
            "user.yaml:2:36: error: the definition of 'a.b' is a vec3, but 'a.b' is declared float");
  EXPECT_EQ(loadError("semantics:\n  a.b: { type: vec3, definition: \"morph.position + world.normal\" }\n"),
            "user.yaml:2:35: error: 'morph.position' is an indexed family: index it ('morph.position[i]')");
  EXPECT_EQ(loadError("semantics:\n  a.b: { type: vec3, definition: \"world.normal.xyzw\" }\n"),
            "user.yaml:2:48: error: '.xyzw' reaches past the end of a vec3");
  EXPECT_EQ(loadError("semantics:\n  a.b: { type: float, definition: \"frobnicate(1)\" }\n").substr(0, 57),
            "user.yaml:2:36: error: unknown function 'frobnicate' (dot");
  EXPECT_EQ(loadError("semantics:\n  a.b: { type: vec3, definition: \"c.d\" }\n  c.d: { type: vec3, definition: \"a.b * 2\" }\n"),
            "user.yaml:2:35: error: definitions form a cycle: a.b -> c.d -> a.b");
  EXPECT_EQ(loadError("semantics:\n  a.b: { type: float, kind: wobbly }\n"),
            "user.yaml:2:29: error: unknown kind 'wobbly' (rigid, affine, projection, unit, point, weight, int)");
  EXPECT_EQ(loadError("semantics:\n  a.b: { type: float, definition: \"(((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((1)))))))))))))))))))))))))))))))))))))))))))))))))))))))))))))))))\" }\n"),
            "user.yaml:2:68: error: definition is nested deeper than 64 levels");
  EXPECT_EQ(loadError("semantics:\n  a.b: { type: vec3, definition: \"let n = world.normal; n * view.ndotv\" }\n"), "");
  // A folded block: the error is located on its own source line.
  EXPECT_EQ(loadError("semantics:\n  a.b:\n    type: vec3\n    definition: >-\n      let n = world.normal;\n      n * camera.view\n"),
            "user.yaml:6:9: error: cannot apply '*' to vec3 and mat4");
  EXPECT_EQ(loadError("semantics:\n  a.b: { type: float, definition: \"let n = world.normal; n.z + n.w\" }\n"),
            "user.yaml:2:66: error: '.w' reaches past the end of a vec3");
}

// The hand-written reference and the interpreter, on one mesh in one pose: every computed
// semantic either both evaluate (and agree to 1e-9 relative: both are double precision) or
// both refuse.
int compareOracle(const sg::Rig& rig, const rt::Mesh& mesh, const rt::Pose& pose, const rt::RigShape& rshape) {
  static const sg::RuleSet rules = standardRules();
  sg::RigShape shape = sg::shapeOfRig(rig, rules);
  sg::UniformValues uniforms = sg::poseUniforms(rig, pose);
  sg::Interpreter interp(rules, shape, mesh, uniforms);
  rt::ReferenceEvaluator ref(mesh, pose, rshape);
  int compared = 0;
  for (const char* sem : {"object.position", "object.normal", "object.occlusion", "object.tangent", "world.position",
                          "world.normal", "world.tangent", "world.handedness", "world.binormal", "frame.row_x",
                          "frame.row_y", "frame.row_z", "world.eye_dir", "eye.position", "eye.normal", "view.ndotv",
                          "view.one_minus_ndotv", "view.one_minus_ndotv_sq", "dapple.normal_z", "clip.position",
                          "eye.to_camera", "eye.tangent", "eye.binormal"}) {
    if (std::string(sem) == "dapple.normal_z" && !uniforms.count("dapple.matrix")) continue;
    std::vector<glm::vec4> expected;
    bool refOk = true;
    try {
      expected = ref.values(sem);
    } catch (const std::invalid_argument&) {
      refOk = false;
    }
    if (!interp.uncheckedReason(sem).empty()) {
      EXPECT_FALSE(refOk) << sem << " on " << mesh.name << ": the reference evaluates it, the interpreter does not: "
                          << interp.uncheckedReason(sem);
      continue;
    }
    EXPECT_TRUE(refOk) << sem << " on " << mesh.name;
    if (!refOk) continue;
    auto got = interp.evaluate({sem})[0];
    const int n = interp.components(sem);
    double worst = 0;
    for (size_t v = 0; v < mesh.vertexCount; ++v) {
      double scale = 1;
      for (int c = 0; c < n; ++c) scale = std::max(scale, std::abs(double(expected[v][c])));
      for (int c = 0; c < n; ++c)
        worst = std::max(worst, std::abs(got[v * n + c] - expected[v][c]) / scale);
    }
    // The reference rounds its result to float: half an ulp of the scale. eye.binormal is
    // written as three.js computes it (a cross product in view space) and defined as the
    // world binormal rotated: equal for an exact rotation, but the view matrix is a float
    // rotation, orthonormal to ~1e-7 only.
    EXPECT_LT(worst, std::string(sem) == "eye.binormal" ? 4e-7 : 1.2e-7) << sem << " on " << mesh.name;
    ++compared;
  }
  return compared;
}

TEST(Oracle, InterpreterAgreesWithReferenceOnProceduralMeshes) {
  int compared = 0;
  sgtest::forEachProceduralCase([&](const sgtest::ProceduralCase& c) {
    for (uint32_t seed : {3u, 4u}) {
      SCOPED_TRACE(::testing::Message() << "seed " << seed);
      compared += compareOracle(c.rig, c.mesh, rt::makeRandomPose(c.shape, seed, rt::hostilePoseOptions(c.uniformScale)), c.shape);
    }
  });
  EXPECT_GT(compared, 600);
}

TEST(Oracle, InterpreterAgreesWithReferenceOnModels) {
  int compared = 0;
  for (const char* model : {"Fox/Fox.glb", "SimpleSkin/SimpleSkin.gltf", "AnimatedMorphSphere/AnimatedMorphSphere.gltf",
                            "SimpleMorph/SimpleMorph.gltf", "MorphPrimitivesTest/MorphPrimitivesTest.gltf",
                            "MorphStressTest/MorphStressTest.gltf"}) {
    std::string path = sg::test::modelPath(model);
    sg::GltfImport imp = sg::importGltf(path);
    sg::GltfSceneOptions so;
    sg::ValidationScene scene = sg::gltfScene(imp, so);
    for (const auto& pose : scene.poses) {
      SCOPED_TRACE(model);
      compared += compareOracle(imp.rig, scene.mesh, pose, scene.shape);
    }
  }
  EXPECT_GT(compared, 20);
}

TEST(PoseFile, RoundTripIsByteIdentical) {
  rt::RigShape rs;
  rs.bones = 3;
  rs.morphTargets = 2;
  std::vector<rt::Pose> poses = {rt::makeRandomPose(rs, 7, rt::hostilePoseOptions(false)), rt::makeRestPose(rs)};
  poses[0].uniforms["skin.bones_prev"] = {0.1, -2.5e-7, 1.0 / 3.0};
  std::string text = sg::formatPoseFile(poses);
  std::vector<rt::Pose> back = sg::parsePoseFile(text, "p.yaml");
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[0].bones, poses[0].bones);
  EXPECT_EQ(back[0].morphWeights, poses[0].morphWeights);
  EXPECT_EQ(back[0].view, poses[0].view);
  EXPECT_EQ(back[0].uniforms, poses[0].uniforms);
  EXPECT_EQ(sg::formatPoseFile(back), text);
  auto err = [](const std::string& t) {
    try {
      sg::parsePoseFile(t, "p.yaml");
    } catch (const sg::InputError& e) {
      return sg::formatDiagnostic(e.diagnostic());
    }
    return std::string();
  };
  EXPECT_EQ(err("poses:\n  - view: [1, 2]\n"), "p.yaml:2:11: error: 'view' has 2 numbers, not 16");
  EXPECT_EQ(err("poses:\n  - morph_weights: [nan]\n"), "p.yaml:2:21: error: 'nan' is not a finite number");
  EXPECT_EQ(err("poses:\n  - camera: [1, 2, 3]\n").substr(0, 40), "p.yaml:2:5: error: unknown key 'camera' ");
  EXPECT_EQ(err("poses: []\n"), "p.yaml:1:8: error: 'poses' is empty");
}

// --- On lavapipe -------------------------------------------------------------------------

const char* kUserRules = R"Y(# A user's rules: new semantics with definitions, new uniforms with kinds.
include: [STANDARD]
semantics:
  view.position: { type: vec3, definition: "(camera.view * vec4(world.position, 1)).xyz" }
  view.normal_matrix: { type: mat3, definition: "transpose(inverse(mat3(camera.view * model.matrix)))" }
  view.normal: { type: vec3, definition: "normalize(view.normal_matrix * object.normal)" }
  skin.bones_prev: { type: mat4, array: bones, kind: affine }
  camera.view_projection_prev: { type: mat4, kind: projection }
  skin.matrix_prev:
    type: mat4
    definition: "sum(k, influences, skin.weights[k / 4][k % 4] * skin.bones_prev[skin.joints[k / 4][k % 4]])"
  clip.position_prev:
    type: vec4
    definition: "camera.view_projection_prev * skin.matrix_prev * vec4(object.position, 1)"
  motion.vector:
    type: vec2
    definition: "clip.position.xy / clip.position.w - clip.position_prev.xy / clip.position_prev.w"
  fresnel.term: float
varyings:
  ViewPosition: view.position
  ViewNormal: view.normal
  MotionVector: motion.vector
rules:
  - name: view_position
    produces: view.position
    needs: [world.position, camera.view]
    cost: 3
    glsl: |
      ${out} = (${camera.view} * vec4(${world.position}, 1.0)).xyz;
  - name: view_normal
    produces: view.normal
    needs: [view.normal_matrix, object.normal]
    cost: 6
    glsl: |
      ${out} = normalize(${view.normal_matrix} * ${object.normal});
  - name: skin_matrix_prev
    produces: skin.matrix_prev
    needs: [skin.bones_prev, "skin.joints[*]", "skin.weights[*]"]
    cost: 4 * influences
    glsl: |
      ${out} = ${skin.weights[0]}.x * ${skin.bones_prev}[${skin.joints[0]}.x];
      @for k in influences - 1
      ${out} += ${skin.weights[(k + 1) / 4]}[${(k + 1) % 4}] * ${skin.bones_prev}[${skin.joints[(k + 1) / 4]}[${(k + 1) % 4}]];
      @end
  - name: clip_position_prev
    produces: clip.position_prev
    needs: [camera.view_projection_prev, skin.matrix_prev, object.position]
    cost: 8
    glsl: |
      ${out} = ${camera.view_projection_prev} * (${skin.matrix_prev} * vec4(${object.position}, 1.0));
  - name: motion_vector
    produces: motion.vector
    needs: [clip.position, clip.position_prev]
    cost: 4
    glsl: |
      ${out} = ${clip.position}.xy / ${clip.position}.w - ${clip.position_prev}.xy / ${clip.position_prev}.w;
)Y";

const char* kUserRig = R"(rig: user
deformers:
  bones: 6
  influences: 2
  morph_targets: 0
attributes:
  position: { format: float32x3, provides: vertex.position }
  normal:   { format: float32x3, provides: vertex.normal }
  joints:   { format: uint16x4, provides: "skin.joints[0]" }
  weights:  { format: float32x4, provides: "skin.weights[0]" }
uniforms:
  bones:      { type: mat4, array: bones, semantic: skin.bones }
  bones_prev: { type: mat4, array: bones, semantic: skin.bones_prev }
  vp_prev:    { type: mat4, semantic: camera.view_projection_prev }
  normal_mat: { type: mat3, semantic: view.normal_matrix }
  model:      { type: mat4, semantic: model.matrix }
  view:       { type: mat4, semantic: camera.view }
  projection: { type: mat4, semantic: camera.projection }
)";

const char* kUserFrag = R"(#version 450
layout(location = 0) in vec3 ViewPosition;
layout(location = 1) in vec3 ViewNormal;
layout(location = 2) in vec2 MotionVector;
layout(location = 3) in float FresnelTerm;
layout(location = 0) out vec4 color;
void main() { color = vec4(ViewPosition + ViewNormal, MotionVector.x + FresnelTerm); }
)";

struct UserCase {
  fs::path dir;
  explicit UserCase(const std::string& tag) : dir(fs::temp_directory_path() / ("sg_defs_" + tag + "_" + std::to_string(::getpid()))) {
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  ~UserCase() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
  sg::ValidateReport run(const std::string& from = "", const std::string& to = "", bool fresnel = false, bool strict = false) {
    std::string rules = kUserRules;
    rules.replace(rules.find("STANDARD"), 8, sourcePath("rules/standard.yaml"));
    if (fresnel) rules.replace(rules.find("varyings:\n"), 10, "varyings:\n  FresnelTerm: fresnel.term\n");
    if (!from.empty()) EXPECT_TRUE(sgtest::replaceOnce(rules, from, to));
    if (fresnel)
      rules += "  - name: fresnel\n    produces: fresnel.term\n    needs: [view.normal]\n    cost: 1\n    glsl: |\n"
               "      ${out} = 1.0 - ${view.normal}.z;\n";
    std::string frag = kUserFrag;
    if (!fresnel) {
      sgtest::replaceOnce(frag, "layout(location = 3) in float FresnelTerm;\n", "");
      sgtest::replaceOnce(frag, " + FresnelTerm", "");
    }
    writeText(dir / "user.yaml", rules);
    writeText(dir / "user.rig.yaml", kUserRig);
    writeText(dir / "user.frag", frag);
    sg::ValidateOptions vo;
    vo.gen.rigPath = (dir / "user.rig.yaml").string();
    vo.gen.fragmentPath = (dir / "user.frag").string();
    vo.gen.rulesPaths = {(dir / "user.yaml").string()};
    vo.strict = strict;
    sg::ValidationScene scene = sg::proceduralScene(sg::loadRigFile(vo.gen.rigPath), "limb", 1, 2);
    sg::Validator v(vo);
    sg::ValidateReport rep = v.run(scene);
    std::cout << sg::formatReport(rep);
    return rep;
  }
};

std::set<std::string> failing(const sg::ValidateReport& rep) { return sgtest::failingOutputs(rep.runs.at(0)); }

TEST(UserRules, NewSemanticsAndUniformsValidate) {
  UserCase c("ok");
  sg::ValidateReport rep = c.run();
  ASSERT_EQ(rep.runs.size(), 1u);
  EXPECT_TRUE(rep.pass);
  EXPECT_EQ(sgtest::allOutputs(rep.runs[0]), (std::set<std::string>{"gl_Position", "ViewPosition", "ViewNormal", "MotionVector"}));
  for (const auto& o : rep.runs[0].outputs) EXPECT_FALSE(o.unchecked) << o.name;
  // The drawn uniforms are in the poses (for --save-poses): previous bones, one per bone.
  ASSERT_EQ(rep.poses.size(), 2u);
  EXPECT_EQ(rep.poses[0].uniforms.at("skin.bones_prev").size(), 6u * 16u);
  EXPECT_EQ(rep.poses[0].uniforms.at("camera.view_projection_prev").size(), 16u);
}

TEST(UserRules, PlantedSignErrorsAreCaught) {
  {
    UserCase c("view_pos");
    EXPECT_EQ(failing(c.run("${out} = (${camera.view} * vec4(${world.position}, 1.0)).xyz;",
                            "${out} = -(${camera.view} * vec4(${world.position}, 1.0)).xyz;")),
              std::set<std::string>{"ViewPosition"});
  }
  {
    UserCase c("view_normal");
    EXPECT_EQ(failing(c.run("${out} = normalize(${view.normal_matrix} * ${object.normal});",
                            "${out} = normalize(${view.normal_matrix} * -${object.normal});")),
              std::set<std::string>{"ViewNormal"});
  }
  {
    UserCase c("motion");
    EXPECT_EQ(failing(c.run("${clip.position}.xy / ${clip.position}.w - ${clip.position_prev}.xy",
                            "${clip.position_prev}.xy / ${clip.position_prev}.w - ${clip.position}.xy")),
              std::set<std::string>{"MotionVector"});
  }
}

TEST(UserRules, UndefinedSemanticIsUncheckedNotFailed) {
  UserCase c("fresnel");
  sg::ValidateReport rep = c.run("", "", /*fresnel=*/true);
  EXPECT_TRUE(rep.pass);
  int unchecked = 0;
  for (const auto& o : rep.runs.at(0).outputs)
    if (o.unchecked) {
      ++unchecked;
      EXPECT_EQ(o.name, "FresnelTerm");
      EXPECT_EQ(o.uncheckedReason, "'fresnel.term' has no definition and the rig does not provide it");
    }
  EXPECT_EQ(unchecked, 1);
  EXPECT_NE(sg::formatReport(rep).find("unchecked: 'fresnel.term' has no definition"), std::string::npos);
  sg::ValidateReport strict = c.run("", "", true, /*strict=*/true);
  EXPECT_FALSE(strict.pass);
  EXPECT_EQ(failing(strict), std::set<std::string>{"FresnelTerm"});
}

TEST(UserRules, NaNIsReportedWithSideAndInputs) {
  UserCase c("nan");
  sg::ValidateReport rep = c.run("${out} = normalize(${view.normal_matrix} * ${object.normal});",
                                 "${out} = normalize(${view.normal_matrix} * ${object.normal} * 0.0);");
  EXPECT_FALSE(rep.pass);
  const sg::OutputReport* vn = nullptr;
  for (const auto& o : rep.runs.at(0).outputs)
    if (o.name == "ViewNormal") vn = &o;
  ASSERT_NE(vn, nullptr);
  EXPECT_EQ(vn->nonFinite.rfind("GPU gives nan at vertex 0, output ViewNormal component 0", 0), 0u) << vn->nonFinite;
  EXPECT_NE(vn->nonFinite.find("inputs of view.normal:"), std::string::npos);
  EXPECT_NE(vn->nonFinite.find("vertex.normal = ("), std::string::npos);
  EXPECT_NE(vn->nonFinite.find("view.normal_matrix = ("), std::string::npos);
}

// --- Break tests that only hostile poses catch -------------------------------------------

sg::ValidateReport validateFace(const RulesCopy& rules, const std::string& rigText) {
  fs::path rig = rules.root() / "face.rig.yaml";
  writeText(rig, rigText);
  sg::ValidateOptions vo;
  vo.gen.rigPath = rig.string();
  vo.gen.fragmentPath = sourcePath("examples/dawn/face.frag");
  vo.gen.rulesPaths = {rules.dawnRules().string()};
  sg::ValidationScene scene = sg::proceduralScene(sg::loadRigFile(vo.gen.rigPath), "head", 1, 2);
  sg::Validator v(vo);
  sg::ValidateReport rep = v.run(scene);
  std::cout << sg::formatReport(rep);
  return rep;
}

std::string faceRig(bool uniformScale) {
  std::string text = sgtest::readText(sourcePath("examples/dawn/face.rig.yaml"));
  if (!uniformScale) {
    size_t at = text.find("  uniform_scale: 1");
    text.erase(at, text.find('\n', at) + 1 - at);
  }
  return text;
}

// mat3(M) as the normal matrix on a rig that may scale non-uniformly (the rule's `when`
// removed): the normal and everything built on it fail.
TEST(BreakDefinitions, Mat3NormalMatrixUnderNonUniformScale) {
  RulesCopy rules("mat3_normal");
  ASSERT_TRUE(rules.edit("skinning.yaml", "    when: uniform_scale\n    cost: 6", "    cost: 6"));
  sg::ValidateReport rep = validateFace(rules, faceRig(false));
  ASSERT_EQ(rep.runs.size(), 1u);
  EXPECT_TRUE(sgtest::planHas(rep.runs[0], "world_normal_from_matrix"));
  EXPECT_EQ(failing(rep), (std::set<std::string>{"WorldTanMatrixX", "WorldTanMatrixY", "WorldTanMatrixZ", "SkinSilhouetteVec"}));
  // The inverse transpose passes on the same rig.
  RulesCopy good("it_normal");
  sg::ValidateReport ok = validateFace(good, faceRig(false));
  EXPECT_TRUE(ok.pass);
  EXPECT_TRUE(sgtest::planHas(ok.runs.at(0), "world_normal_inverse_transpose"));
}

// Morph weights clamped to [0, 1]: default poses draw them in [-0.5, 1.5].
TEST(BreakDefinitions, ClampedMorphWeights) {
  RulesCopy rules("clamp_weights");
  ASSERT_TRUE(rules.edit("morph.yaml", "${out} += ${morph.weights}[${i}] * ${morph.position[i]};",
                         "${out} += clamp(${morph.weights}[${i}], 0.0, 1.0) * ${morph.position[i]};"));
  sg::ValidateReport rep = validateFace(rules, faceRig(true));
  EXPECT_EQ(failing(rep), (std::set<std::string>{"gl_Position", "WorldEyeDir", "SkinSilhouetteVec"}));
}

}  // namespace

namespace {

// docs/semantics.md's table of definitions is the vocabulary's, verbatim (blanks collapsed).
TEST(Docs, SemanticsListsEveryDefinition) {
  sg::RuleSet set = sg::loadRules({sourcePath("rules/vocabulary.yaml")});
  std::string table = "| semantic | type | definition |\n|---|---|---|\n";
  for (const auto& d : set.semantics) {
    if (!d.definition) continue;
    std::string text, word;
    std::istringstream in(d.definitionText);
    while (in >> word) text += (text.empty() ? "" : " ") + word;
    table += "| `" + d.name + "` | " + std::string(sg::glslName(d.type)) + " | `" + text + "` |\n";
  }
  std::string doc = sgtest::readText(sourcePath("docs/semantics.md"));
  const std::string begin = "<!-- definitions begin -->\n", end = "<!-- definitions end -->";
  size_t b = doc.find(begin), e = doc.find(end);
  ASSERT_NE(b, std::string::npos);
  ASSERT_NE(e, std::string::npos);
  EXPECT_EQ(doc.substr(b + begin.size(), e - b - begin.size()), table);
}

}  // namespace

namespace {

// tests/validate/data/parallel_tangents.gltf: a ramp under node scale (1, 4, 1) whose
// vertices 0, 4 and 8 have TANGENT parallel (or antiparallel) to NORMAL.
sg::ValidateReport validateRamp(const std::string& rulesPath) {
  sg::ValidateOptions vo;
  vo.gen.rigPath = sgtest::dataPath("parallel_tangents.gltf");
  vo.gen.fragmentPath = sgtest::dataPath("frame.frag");
  vo.gen.rulesPaths = {rulesPath};
  sg::ValidationScene scene = sg::gltfScene(vo.gen.rigPath, sg::GltfSceneOptions{});
  sg::Validator v(vo);
  sg::ValidateReport rep = v.run(scene);
  std::cout << sg::formatReport(rep);
  return rep;
}

TEST(Degenerate, ImportWarnsAndDerivesScale) {
  sg::GltfImport imp = sg::importGltf(sgtest::dataPath("parallel_tangents.gltf"));
  std::vector<std::string> warned;
  for (const auto& n : imp.notes)
    if (n.find("TANGENT") != std::string::npos) warned.push_back(n);
  ASSERT_EQ(warned.size(), 1u);
  EXPECT_EQ(warned[0].rfind("3 of 9 vertices have a TANGENT that is zero or parallel to the NORMAL", 0), 0u) << warned[0];
  EXPECT_EQ(imp.rig.param("uniform_scale"), 0);  // the node scales (1, 4, 1)
  // The Fox's skeleton scales uniformly: it may use mat3(M).
  EXPECT_EQ(sg::importGltf(sg::test::modelPath("Fox/Fox.glb")).rig.param("uniform_scale"), 1);
}

TEST(Degenerate, FallbackValidatesAndSkippingItIsCaught) {
  sg::ValidateReport ok = validateRamp(sourcePath("rules/standard.yaml"));
  EXPECT_TRUE(ok.pass);
  EXPECT_TRUE(sgtest::planHas(ok.runs.at(0), "world_normal_inverse_transpose"));
  // The fallback skipped: Gram-Schmidt normalizes a zero vector on the GPU.
  RulesCopy rules("no_fallback");
  ASSERT_TRUE(rules.edit("vocabulary.yaml", "bvec3(dot(g_, g_) > 1e-6 * dot(t_, t_))", "bvec3(true)"));
  sg::ValidateReport broken = validateRamp(rules.rulesFile("standard.yaml").string());
  EXPECT_FALSE(broken.pass);
  EXPECT_EQ(failing(broken), (std::set<std::string>{"world_tangent", "world_binormal"}));
  for (const auto& o : broken.runs.at(0).outputs)
    if (o.name == "world_tangent") {
      EXPECT_EQ(o.nonFinite.rfind("GPU gives nan at vertex 0, output world_tangent", 0), 0u) << o.nonFinite;
      EXPECT_NE(o.nonFinite.find("vertex.tangent = (0, 0, 1)"), std::string::npos) << o.nonFinite;
    }
}

}  // namespace

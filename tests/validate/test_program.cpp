// Compiled definitions (validate/definition_program.h) against the tree walker they replace
// (Interpreter::evaluateByTree, the oracle): the same values to 1e-12 relative and NaN or
// infinity exactly where the tree walker has them, on every procedural mesh shape, a subset
// of the Dawn-scale mesh, the shared glTF models, hostile poses, degenerate data and a few
// hundred random definitions; the same errors, thrown as the tree walker throws them; the
// same values on any number of threads; uniform-only work done while compiling, not per vertex.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <random>

#include "rig/gltf_import.h"
#include "rules/instantiate.h"
#include "runtime/procedural.h"
#include "test_util.h"
#include "validate/definition_program.h"
#include "validate/gltf_scene.h"
#include "validate/interpreter.h"
#include "validate/poses.h"

namespace {

namespace rt = sg::rt;
using sgtest::rigFor;
using sgtest::sourcePath;

using sgtest::standardRules;

// What one evaluation gives: values, or the error it threw.
struct Outcome {
  std::vector<std::vector<double>> values;
  std::string error;
};
Outcome outcome(const std::function<std::vector<std::vector<double>>()>& f) {
  try {
    return {f(), ""};
  } catch (const std::exception& e) {
    return {{}, e.what()};
  }
}

struct Agreement {
  size_t compared = 0, nonFinite = 0;
};

// Both threw the same message, or both gave the same values: |tree - compiled| <=
// 1e-12 max(1, |tree|), NaN where the tree walker has NaN, the same infinities.
Agreement expectSame(const Outcome& tree, const Outcome& compiled, const std::vector<std::string>& semantics) {
  Agreement a;
  EXPECT_EQ(tree.error, compiled.error);
  if (!tree.error.empty() || !compiled.error.empty()) return a;
  EXPECT_EQ(tree.values.size(), compiled.values.size());
  int reported = 0;
  for (size_t k = 0; k < tree.values.size() && k < compiled.values.size(); ++k) {
    EXPECT_EQ(tree.values[k].size(), compiled.values[k].size());
    for (size_t i = 0; i < tree.values[k].size() && i < compiled.values[k].size(); ++i) {
      const double t = tree.values[k][i], c = compiled.values[k][i];
      bool same = std::isnan(t) ? std::isnan(c) : std::isinf(t) ? t == c : std::abs(t - c) <= 1e-12 * std::max(1.0, std::abs(t));
      if (!same && reported++ < 5)
        ADD_FAILURE() << semantics[k] << " component " << i << ": tree " << t << ", compiled " << c;
      ++a.compared;
      a.nonFinite += !std::isfinite(t);
    }
  }
  return a;
}

// Every semantic of `rules` with a definition that evaluates on this mesh, all at once, both ways.
Agreement compareAll(const sg::RuleSet& rules, const sg::Rig& rig, const rt::Mesh& mesh, const sg::UniformValues& uniforms,
                     std::vector<std::string> extra = {}) {
  sg::RigShape shape = sg::shapeOfRig(rig, rules);
  sg::Interpreter interp(rules, shape, mesh, uniforms);
  std::vector<std::string> semantics = std::move(extra);
  for (const auto& d : rules.semantics)
    if (d.definition && interp.uncheckedReason(d.name).empty()) semantics.push_back(d.name);
  Outcome tree = outcome([&] { return interp.evaluateByTree(semantics); });
  Outcome compiled = outcome([&] { return interp.evaluate(semantics); });
  return expectSame(tree, compiled, semantics);
}

TEST(Program, AgreesWithTreeOnProceduralMeshes) {
  size_t compared = 0;
  sgtest::forEachProceduralCase([&](const sgtest::ProceduralCase& c) {
    rt::Pose pose = rt::makeRandomPose(c.shape, 5, rt::hostilePoseOptions(c.uniformScale));
    compared += compareAll(standardRules(), c.rig, c.mesh, sg::poseUniforms(c.rig, pose)).compared;
  });
  EXPECT_GT(compared, 500000u);
}

// Full scale only uninstrumented: cmake/dev.sh test runs it in the plain tree (full_scale_tests).
TEST(Program, AgreesWithTreeOnDawnSubset) {
  const sg::RuleSet rules = sg::loadRules({sourcePath("examples/dawn/rules.yaml")});
  sg::Rig rig = sg::loadRigFile(sourcePath("examples/dawn/face.rig.yaml"));
  // Every 61st of the 180,000 vertices (2,951 across the face); the 2,009-vertex head of the
  // same shape in the sanitizer build, where building the large mesh is the slow part.
  sg::ValidationScene scene = sg::proceduralScene(rig, sgtest::kSanitized ? "head" : "dawn", 1, 2);
  rt::Mesh mesh = sgtest::kSanitized ? sg::quantizeForRig(rig, scene.mesh) : rt::everyNthVertex(sg::quantizeForRig(rig, scene.mesh), 61);
  size_t compared = 0;
  for (const auto& pose : scene.poses) compared += compareAll(rules, rig, mesh, sg::poseUniforms(rig, pose)).compared;
  EXPECT_GT(compared, 200000u);
}

TEST(Program, AgreesWithTreeOnModels) {
  const char* env = std::getenv("SHADERGEN_SHARED_DIR");
  const std::string shared = env && *env ? env : SG_SHARED_DIR;
  if (!std::filesystem::exists(shared + "/models/README.md")) GTEST_SKIP() << "no shared models at " << shared;
  size_t compared = 0;
  for (const char* model : {"Fox/Fox.glb", "SimpleSkin/SimpleSkin.gltf", "AnimatedMorphSphere/AnimatedMorphSphere.gltf",
                            "SimpleMorph/SimpleMorph.gltf", "MorphPrimitivesTest/MorphPrimitivesTest.gltf",
                            "MorphStressTest/MorphStressTest.gltf", "RiggedFigure/RiggedFigure.gltf"}) {
    const std::string path = shared + "/models/" + model;
    if (!std::filesystem::exists(path)) continue;
    SCOPED_TRACE(model);
    sg::GltfImport imp = sg::importGltf(path);
    sg::ValidationScene scene = sg::gltfScene(imp, sg::GltfSceneOptions{});
    for (const auto& pose : scene.poses) compared += compareAll(standardRules(), imp.rig, scene.mesh, sg::poseUniforms(imp.rig, pose)).compared;
  }
  EXPECT_GT(compared, 10000u);
}

// Zero, parallel and antiparallel tangents, zero, tiny and huge normals, a singular bone,
// weights of 0 and below: the same NaNs and infinities on both sides.
TEST(Program, DegenerateDataGiveTheSameNonFiniteValues) {
  rt::MeshOptions mo;
  mo.influences = 4;
  mo.morphTargets = 3;
  mo.morphTangents = true;
  mo.bones = 6;
  rt::Mesh mesh = rt::makeHead(12, 16, mo);
  auto& n = mesh.streams.at("vertex.normal");
  auto& t = mesh.streams.at("vertex.tangent");
  n[0] = glm::vec4(0.0f);
  t[1] = n[1];
  t[2] = glm::vec4(0.0f);
  t[3] = -n[3];
  n[5] *= 1e30f;
  n[6] *= 1e-30f;
  for (int k = 0; k < 3; ++k) mesh.streams.at("morph.normal[" + std::to_string(k) + "]")[0] = glm::vec4(0.0f);
  mesh.streams.at("skin.joints[0]")[7] = glm::vec4(1, 0, 0, 0);  // vertex 7 follows the singular bone alone
  mesh.streams.at("skin.weights[0]")[7] = glm::vec4(1, 0, 0, 0);
  for (bool uniformScale : {false, true}) {
    sg::Rig rig = rigFor(mo, false, uniformScale);
    rt::Pose pose = rt::makeRandomPose(rt::rigShapeFor(mo), 9, rt::hostilePoseOptions(uniformScale));
    pose.bones[1] = glm::mat4(0.0f);  // singular: its inverse transpose is infinite
    pose.morphWeights = {0.0f, -1.0f, 1e-20f};
    SCOPED_TRACE(uniformScale);
    Agreement a = compareAll(standardRules(), rig, mesh, sg::poseUniforms(rig, pose));
    EXPECT_GT(a.compared, 10000u);
    EXPECT_GT(a.nonFinite, 20u);  // the NaN paths are exercised
  }
}

// A user's rules over the standard library, and a mesh with an integer stream.
struct UserCase {
  sg::RuleSet rules = standardRules();
  rt::MeshOptions mo;
  rt::Mesh mesh;
  sg::Rig rig;
  sg::UniformValues uniforms;
  explicit UserCase(const std::string& semantics) {
    sg::loadRulesText(rules, "semantics:\n" + semantics, "user.yaml");
    sg::checkDefinitions(rules);
    mo.influences = 4;
    mo.bones = 6;
    mesh = rt::makeHead(12, 16, mo);  // 221 vertices: 4 batches
    rig = rigFor(mo, false, true);
    uniforms = sg::poseUniforms(rig, rt::makeRandomPose(rt::rigShapeFor(mo), 2, rt::hostilePoseOptions(true)));
  }
  Outcome tree(const std::vector<std::string>& s) {
    const sg::RigShape shape = sg::shapeOfRig(rig, rules);
    sg::Interpreter i(rules, shape, mesh, uniforms);
    return outcome([&] { return i.evaluateByTree(s); });
  }
  Outcome compiled(const std::vector<std::string>& s) {
    const sg::RigShape shape = sg::shapeOfRig(rig, rules);
    sg::Interpreter i(rules, shape, mesh, uniforms);
    return outcome([&] { return i.evaluate(s); });
  }
  void expectSameOutcome(const std::vector<std::string>& s) { expectSame(tree(s), compiled(s), s); }
};

TEST(Program, ErrorsAreTheTreeWalkers) {
  UserCase c(
      "  test.guarded: { type: mat4, definition: \"skin.joints[0].x < 6 ? skin.bones[skin.joints[0].x] : mat4(1)\" }\n"
      "  test.undefined: vec3\n"
      "  test.untaken: { type: vec3, definition: \"vertex.position.x > 100 ? test.undefined : vertex.position\" }\n"
      "  test.taken: { type: vec3, definition: \"vertex.position.x > 0.2 ? test.undefined : vertex.position\" }\n"
      "  test.id: int\n"
      "  test.ratio: { type: float, definition: \"float(10 / test.id)\" }\n"
      "  test.param: { type: float, definition: \"float(no_such_param) * vertex.occlusion\" }\n"
      "  test.column: { type: vec4, definition: \"camera.view[skin.joints[0].x > 8 ? skin.joints[0].x : 0]\" }\n");
  // A joint past the palette (vertex 130, in the third batch): the same located error.
  c.mesh.streams.at("skin.joints[0]")[130].x = 9;
  Outcome tree = c.tree({"world.position"});
  EXPECT_NE(tree.error.find("index 9 is out of range of 'skin.bones' (6 elements)"), std::string::npos) << tree.error;
  EXPECT_NE(tree.error.find("vocabulary.yaml:"), std::string::npos) << tree.error;
  c.expectSameOutcome({"world.position"});
  c.expectSameOutcome({"world.normal", "world.position"});
  // Guarded by a per-vertex condition: no error, and the values agree.
  EXPECT_EQ(c.tree({"test.guarded"}).error, "");
  c.expectSameOutcome({"test.guarded"});
  // An undefined semantic in a branch no vertex takes is no error; in a taken one it is.
  EXPECT_EQ(c.tree({"test.untaken"}).error, "");
  c.expectSameOutcome({"test.untaken"});
  EXPECT_EQ(c.tree({"test.taken"}).error, "'test.undefined' has no definition and the rig does not provide it");
  c.expectSameOutcome({"test.taken"});
  // Integer division by a per-vertex zero, a missing rig parameter, a column past a mat4.
  std::vector<glm::vec4> ids(c.mesh.vertexCount, glm::vec4(2.0f));
  ids[200].x = 0;
  c.mesh.streams["test.id"] = ids;
  EXPECT_NE(c.tree({"test.ratio"}).error.find("integer division by zero in '/'"), std::string::npos);
  c.expectSameOutcome({"test.ratio"});
  EXPECT_NE(c.tree({"test.param"}).error.find("the rig has no parameter 'no_such_param'"), std::string::npos);
  c.expectSameOutcome({"test.param"});
  EXPECT_NE(c.tree({"test.column"}).error.find("index 9 is out of range of a mat4"), std::string::npos);
  c.expectSameOutcome({"test.column"});
  c.mesh.streams.at("skin.joints[0]")[130].x = 1;
  EXPECT_EQ(c.tree({"test.column"}).error, "");
  c.expectSameOutcome({"test.column", "test.ratio", "test.guarded"});
}

TEST(Program, ThreadsDoNotChangeValues) {
  const sg::RuleSet rules = sg::loadRules({sourcePath("examples/dawn/rules.yaml")});
  sg::Rig rig = sg::loadRigFile(sourcePath("examples/dawn/face.rig.yaml"));
  sg::ValidationScene scene = sg::proceduralScene(rig, "head", 1, 1);
  sg::UniformValues uniforms = sg::poseUniforms(rig, scene.poses[0]);
  const sg::RigShape shape = sg::shapeOfRig(rig, rules);
  sg::Interpreter interp(rules, shape, scene.mesh, uniforms);
  const std::vector<std::string> semantics = {"frame.row_x", "frame.row_y", "frame.row_z", "world.eye_dir", "clip.position",
                                              "view.one_minus_ndotv_sq", "dapple.normal_z"};
  interp.setThreads(1);
  auto one = interp.evaluate(semantics);
  for (unsigned threads : {2u, 3u, 8u}) {
    interp.setThreads(threads);
    auto many = interp.evaluate(semantics);
    ASSERT_EQ(one.size(), many.size());
    for (size_t k = 0; k < one.size(); ++k) {
      ASSERT_EQ(one[k].size(), many[k].size());
      EXPECT_EQ(std::memcmp(one[k].data(), many[k].data(), one[k].size() * sizeof(double)), 0) << semantics[k] << " on " << threads;
    }
  }
}

// Uniform-only subtrees cost nothing per vertex: a normal matrix computed from uniforms with
// an inverse compiles to as many instructions as a plain uniform matrix, with no per-vertex
// call; the per-vertex inverse of a blended bone matrix is one. Outputs share their parts.
TEST(Program, UniformWorkIsDoneWhileCompiling) {
  UserCase c(
      "  test.hoisted: { type: vec3, definition: \"normalize(transpose(inverse(mat3(camera.view * model.matrix))) * object.normal)\" }\n"
      "  test.plain: { type: vec3, definition: \"normalize(mat3(camera.view) * object.normal)\" }\n");
  c.uniforms["model.matrix"] = std::vector<double>(16, 0.5);
  for (int d : {0, 5, 10, 15}) c.uniforms["model.matrix"][static_cast<size_t>(d)] = 2.0;
  auto stats = [&](std::vector<std::string> names) {
    std::vector<int> idx;
    for (const auto& n : names)
      for (size_t i = 0; i < c.rules.semantics.size(); ++i)
        if (c.rules.semantics[i].name == n) idx.push_back(static_cast<int>(i));
    auto p = sg::DefinitionProgram::compile(c.rules, sg::shapeOfRig(c.rig, c.rules), c.mesh, c.uniforms, idx);
    EXPECT_NE(p, nullptr);
    return p ? p->stats() : sg::DefinitionProgram::Stats{};
  };
  const auto hoisted = stats({"test.hoisted"}), plain = stats({"test.plain"});
  EXPECT_EQ(hoisted.perVertexCalls, 0u);
  EXPECT_EQ(hoisted.instructions, plain.instructions);
  c.expectSameOutcome({"test.hoisted", "test.plain"});
  // Without uniform_scale the world normal inverts the blended bone matrix of each vertex.
  c.rig = rigFor(c.mo, false, false);
  EXPECT_EQ(stats({"world.normal"}).perVertexCalls, 1u);
  c.expectSameOutcome({"world.normal"});
  // world.position once for three outputs that read it.
  const size_t shared = stats({"world.position", "world.eye_dir", "clip.position"}).instructions;
  const size_t apart = stats({"world.position"}).instructions + stats({"world.eye_dir"}).instructions +
                       stats({"clip.position"}).instructions;
  EXPECT_LT(shared, apart - 2 * stats({"world.position"}).instructions + 4);
}

// --- Random definitions ------------------------------------------------------------------

// Well-typed random formulas over the vocabulary, the rig's parameters and every operation
// of the language, some with per-vertex branches, indexes and errors.
class RandomDefinition {
 public:
  explicit RandomDefinition(uint32_t seed) : rng_(seed) {}

  // Depth 4, or 3 if that grew past the length limit of a definition.
  std::string make(sg::DefType t) {
    std::string s = gen(t, 4);
    return s.size() < 4000 ? s : gen(t, 3);
  }

 private:
  using T = sg::DefType;
  size_t pick(size_t n) { return rng_() % n; }
  template <size_t N>
  const char* one(const char* const (&options)[N]) {
    return options[pick(N)];
  }
  // Expands {F} {I} {B} {2} {3} {4} {m} {M} (a float, int, bool, vec2, vec3, vec4, mat3, mat4)
  // and {new} / {last} (a fresh local name, and it again).
  std::string fill(const std::string& pattern, int depth) {
    std::string out, local;
    for (size_t i = 0; i < pattern.size(); ++i) {
      if (pattern[i] != '{') {
        out += pattern[i];
        continue;
      }
      const size_t end = pattern.find('}', i);
      const std::string key = pattern.substr(i + 1, end - i - 1);
      i = end;
      if (key == "new") out += local = "l" + std::to_string(locals_++);
      else if (key == "last") out += local;
      else out += gen(key == "F" ? T::Float : key == "I" ? T::Int : key == "B" ? T::Bool : key == "2" ? T::Vec2
                      : key == "3" ? T::Vec3 : key == "4" ? T::Vec4 : key == "m" ? T::Mat3 : T::Mat4, depth - 1);
    }
    return out;
  }
  std::string gen(T t, int depth) {
    if (depth <= 0 || pick(5) == 0) return leaf(t);
    switch (t) {
      case T::Float:
        return fill(one({"({F} + {F})", "({F} - {F})", "({F} * {F})", "({F} / {F})", "-{F}", "dot({3}, {3})", "dot({4}, {4})", "dot({2}, {2})", "length({3})",
                         "abs({F})", "sqrt({F})", "sign({F})", "min({F}, {F})", "max({F}, {F})", "clamp({F}, {F}, {F})", "determinant({m})",
                         "determinant({M})", "{3}.y", "{4}[2]", "{3}[1]", "({B} ? {F} : {F})", "sum(i, morph_targets, morph.weights[i] * {F})",
                         "(let {new} = {F}; {last} * {last} + {F})", "float({I})", "{4}.w"}),
                    depth);
      case T::Int: return fill(one({"({I} + {I})", "({I} * {I})", "({I} / 2)", "({I} % 3)", "({I} - 1)", "-{I}", "({B} ? {I} : {I})"}), depth);
      case T::Bool:
        return fill(one({"({F} < {F})", "({F} >= {F})", "({F} == {F})", "({F} != {F})", "!{B}", "({B} && {B})", "({B} || {B})", "({I} > 2)", "({I} <= {F})"}), depth);
      case T::Vec2: return fill(one({"({2} + {2})", "({F} * {2})", "{4}.xy", "vec2({F}, {F})", "normalize({2})", "min({2}, {F})", "{3}.zx", "abs({2})", "vec2({F})"}), depth);
      case T::Vec3:
        return fill(one({"({3} + {3})", "({3} - {3})", "({F} * {3})", "({3} / {F})", "({m} * {3})", "({3} * {m})", "cross({3}, {3})", "normalize({3})",
                         "({M} * {4}).xyz", "vec3({F}, {F}, {F})", "vec3({2}, {F})", "{4}.wzy", "{m}[1]", "abs({3})", "clamp({3}, 0.0, 1.0)",
                         "max({3}, {3})", "({B} ? {3} : {3})", "sum(i, morph_targets, morph.weights[i] * morph.position[i])",
                         "(let {new} = {3}; {last} * dot({last}, {last}))", "sign({3})", "sqrt({3})", "-{3}", "({3} * {3})", "({3} / {3})"}),
                    depth);
      case T::Vec4:
        return fill(one({"({4} + {4})", "({M} * {4})", "({4} * {M})", "vec4({3}, {F})", "({F} * {4})", "normalize({4})", "{M}[2]", "vec4({2}, {2})",
                         "({B} ? {4} : {4})", "min({4}, {4})"}),
                    depth);
      case T::Mat3:
        return fill(one({"mat3({M})", "({m} * {m})", "transpose({m})", "inverse({m})", "({F} * {m})", "({m} + {m})", "mat3({F})", "mat3({3}, {3}, {3})",
                         "-{m}", "({m} - {m})", "({m} / {F})"}),
                    depth);
      case T::Mat4:
        return fill(one({"({M} * {M})", "transpose({M})", "inverse({M})", "mat4({m})", "({F} * {M})", "mat4({4}, {4}, {4}, {4})", "({B} ? {M} : {M})",
                         "({M} + {M})", "mat4({F})"}),
                    depth);
    }
    return leaf(t);
  }
  std::string leaf(T t) {
    switch (t) {
      case T::Float:
        return one({"0.5", "vertex.occlusion", "vertex.handedness", "morph.weights[1]", "view.ndotv", "vertex.position.x",
                    "2.0", "0.0", "-1.5", "world.normal.z", "1"});
      case T::Int: return one({"influences", "1", "morph_targets", "bones", "0"});
      case T::Bool: return one({"(vertex.position.y > 0.0)", "has(vertex.tangent)", "(view.ndotv < 0.5)", "has(morph.tangent)"});
      case T::Vec2: return one({"vertex.texcoord0", "vertex.texcoord1"});
      case T::Vec3:
        return one({"vertex.position", "vertex.normal", "world.normal", "camera.position", "object.tangent", "morph.position[2]",
                    "world.position", "vertex.tangent", "vec3(0)"});
      case T::Vec4: return one({"vertex.color0", "skin.weights[0]", "skin.joints[0]", "eye.position"});
      case T::Mat3: return one({"mat3(camera.view)", "mat3(skin.matrix)", "mat3(skin.bones[skin.joints[0].y])"});
      case T::Mat4:
        return one({"camera.view", "skin.bones[skin.joints[0].y]", "skin.matrix", "dapple.matrix", "skin.bones[3]",
                    "(skin.joints[0].x < 2 ? skin.bones[skin.joints[0].x + 4] : camera.projection)",
                    "skin.bones[skin.joints[0].x + 4]"});
    }
    return "0";
  }

  std::mt19937 rng_;
  int locals_ = 0;
};

// Full scale only uninstrumented: cmake/dev.sh test runs it in the plain tree (full_scale_tests).
TEST(Program, AgreesWithTreeOnRandomDefinitions) {
  rt::MeshOptions mo;
  mo.influences = 4;
  mo.morphTargets = 3;
  mo.morphTangents = true;
  mo.bones = 6;
  rt::Mesh mesh = rt::makeHead(10, 13, mo);  // 154 vertices: 3 batches, the last one partial
  const sg::DefType types[] = {sg::DefType::Float, sg::DefType::Vec2, sg::DefType::Vec3, sg::DefType::Vec4,
                               sg::DefType::Mat3, sg::DefType::Mat4, sg::DefType::Int};
  const char* names[] = {"float", "vec2", "vec3", "vec4", "mat3", "mat4", "int"};
  size_t compared = 0, errors = 0, nonFinite = 0;
  const uint32_t definitions = sgtest::kSanitized ? 100 : 400;  // the tree walker is slow under ASan
  for (uint32_t seed = 0; seed < definitions; ++seed) {
    RandomDefinition gen(seed);
    const size_t k = seed % 7;
    const std::string text = gen.make(types[k]);
    SCOPED_TRACE(::testing::Message() << "seed " << seed << ": " << names[k] << " " << text);
    sg::RuleSet rules = standardRules();
    ASSERT_NO_THROW({
      sg::loadRulesText(rules, std::string("semantics:\n  test.random: { type: ") + names[k] + ", definition: \"" + text + "\" }\n",
                        "random.yaml");
      sg::checkDefinitions(rules);
    });
    sg::Rig rig = rigFor(mo, false, seed % 2 == 0);
    rt::Pose pose = rt::makeRandomPose(rt::rigShapeFor(mo), seed, rt::hostilePoseOptions(seed % 2 == 0));
    sg::UniformValues uniforms = sg::poseUniforms(rig, pose);
    const sg::RigShape shape = sg::shapeOfRig(rig, rules);
    sg::Interpreter interp(rules, shape, mesh, uniforms);
    Outcome tree = outcome([&] { return interp.evaluateByTree({"test.random"}); });
    Outcome compiled = outcome([&] { return interp.evaluate({"test.random"}); });
    Agreement a = expectSame(tree, compiled, {"test.random"});
    compared += a.compared;
    nonFinite += a.nonFinite;
    errors += !tree.error.empty();
  }
  // Most formulas evaluate; some meet an index past the palette or a NaN, as intended.
  EXPECT_GT(compared, definitions * 500u);
  EXPECT_GT(errors, definitions / 80);
  EXPECT_GT(nonFinite, definitions / 4);
}

}  // namespace

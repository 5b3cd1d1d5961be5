// The GLM reference (runtime/reference.h) against hand-computed values and the identities of
// docs/semantics.md, and the procedural meshes/poses (runtime/procedural.h) against their
// contracts.
#include "runtime/procedural.h"
#include "runtime/reference.h"

#include <glm/glm.hpp>
#include <glm/gtc/matrix_access.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using namespace sg::rt;

glm::vec3 v3(const glm::vec4& v) { return glm::vec3(v); }

void expectNear3(const glm::vec3& a, const glm::vec3& b, float tol, const std::string& what) {
  EXPECT_NEAR(a.x, b.x, tol) << what;
  EXPECT_NEAR(a.y, b.y, tol) << what;
  EXPECT_NEAR(a.z, b.z, tol) << what;
}

void expectNear4(const glm::vec4& a, const glm::vec4& b, float tol, const std::string& what) {
  EXPECT_NEAR(a.x, b.x, tol) << what;
  EXPECT_NEAR(a.y, b.y, tol) << what;
  EXPECT_NEAR(a.z, b.z, tol) << what;
  EXPECT_NEAR(a.w, b.w, tol) << what;
}

std::string messageOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "<no std::invalid_argument thrown>";
}

// One vertex with explicit streams, for hand computations.
Mesh oneVertex(glm::vec3 position, glm::vec4 joints, glm::vec4 weights) {
  Mesh m;
  m.name = "one";
  m.vertexCount = 1;
  m.streams["vertex.position"] = {glm::vec4(position, 0)};
  m.streams["vertex.normal"] = {glm::vec4(0, 0, 1, 0)};
  m.streams["vertex.tangent"] = {glm::vec4(1, 0, 0, 0)};
  m.streams["vertex.handedness"] = {glm::vec4(1, 0, 0, 0)};
  m.streams["skin.joints[0]"] = {joints};
  m.streams["skin.weights[0]"] = {weights};
  return m;
}

MeshOptions limbOptions(int targets = 3, int influences = 4) {
  MeshOptions o;
  o.morphTargets = targets;
  o.morphTangents = true;
  o.influences = influences;
  o.bones = 8;
  return o;
}

// ---------------------------------------------------------------------------------------------
// Skinning and morphing against hand-computed values

TEST(Reference, IdentityBonesAndZeroWeightsGiveBindPose) {
  MeshOptions o = limbOptions(3, 4);
  Mesh mesh = makeLimb(6, 8, o);
  RigShape shape = rigShapeFor(o);
  Pose pose = makeRestPose(shape);
  auto world = referenceValues("world.position", mesh, pose, shape);
  auto normal = referenceValues("world.normal", mesh, pose, shape);
  const auto& vp = mesh.at("vertex.position");
  const auto& vn = mesh.at("vertex.normal");
  ASSERT_EQ(world.size(), mesh.vertexCount);
  for (size_t v = 0; v < mesh.vertexCount; ++v) {
    expectNear3(v3(world[v]), v3(vp[v]), 1e-6f, "world.position at " + std::to_string(v));
    EXPECT_EQ(world[v].w, 0.0f);
    expectNear3(v3(normal[v]), glm::normalize(v3(vn[v])), 1e-6f, "world.normal at " + std::to_string(v));
  }
}

TEST(Reference, LinearBlendOfTwoBonesMatchesHandComputation) {
  // B0 = translate(1,0,0); B1 = rotate 90° about z. p = (1,2,3):
  // B0·p = (2,2,3), B1·p = (-2,1,3), blend 0.5/0.5 = (0,1.5,3).
  Mesh mesh = oneVertex({1, 2, 3}, {0, 1, 0, 0}, {0.5f, 0.5f, 0, 0});
  RigShape shape{2, 4, 0, false};
  Pose pose;
  pose.bones = {glm::translate(glm::mat4(1.0f), glm::vec3(1, 0, 0)),
                glm::rotate(glm::mat4(1.0f), glm::radians(90.0f), glm::vec3(0, 0, 1))};
  expectNear3(v3(referenceValues("world.position", mesh, pose, shape)[0]), {0.0f, 1.5f, 3.0f}, 1e-6f,
              "world.position");
  // Normal (0,0,1): both bones keep it → (0,0,1). Tangent (1,0,0): B0 → (1,0,0), B1 → (0,1,0);
  // blend (0.5,0.5,0) normalised.
  expectNear3(v3(referenceValues("world.normal", mesh, pose, shape)[0]), {0, 0, 1}, 1e-6f, "world.normal");
  const float h = std::sqrt(0.5f);
  expectNear3(v3(referenceValues("world.tangent", mesh, pose, shape)[0]), {h, h, 0}, 1e-6f, "world.tangent");
}

TEST(Reference, EightInfluencesUseTheSecondSet) {
  // Influence 5 (set 1, component 1) carries all the weight: result = B3·p.
  Mesh mesh = oneVertex({1, 0, 0}, {0, 1, 2, 0}, {0, 0, 0, 0});
  mesh.streams["skin.joints[1]"] = {glm::vec4(0, 3, 0, 0)};
  mesh.streams["skin.weights[1]"] = {glm::vec4(0, 1, 0, 0)};
  RigShape shape{4, 8, 0, false};
  Pose pose;
  pose.bones.assign(4, glm::mat4(1.0f));
  pose.bones[3] = glm::translate(glm::mat4(1.0f), glm::vec3(0, 5, 0));
  expectNear3(v3(referenceValues("world.position", mesh, pose, shape)[0]), {1, 5, 0}, 1e-6f, "K=8");
  // With K = 4 the second set is ignored: all weights zero → M = 0.
  RigShape four{4, 4, 0, false};
  expectNear3(v3(referenceValues("world.position", mesh, pose, four)[0]), {0, 0, 0}, 1e-6f, "K=4");
}

TEST(Reference, RigidSkinningIgnoresTheWeight) {
  Mesh mesh = oneVertex({1, 2, 3}, {1, 0, 0, 0}, {0.25f, 0, 0, 0});
  mesh.streams.erase("skin.weights[0]");  // K = 1 does not need weights at all
  RigShape shape{2, 1, 0, false};
  Pose pose;
  pose.bones = {glm::mat4(1.0f), glm::translate(glm::mat4(1.0f), glm::vec3(10, 0, 0))};
  expectNear3(v3(referenceValues("world.position", mesh, pose, shape)[0]), {11, 2, 3}, 1e-6f, "K=1");
}

TEST(Reference, UnskinnedUsesModelMatrixOnlyWhenProvided) {
  Mesh mesh = oneVertex({1, 2, 3}, {0, 0, 0, 0}, {0, 0, 0, 0});
  Pose pose;
  pose.model = glm::translate(glm::mat4(1.0f), glm::vec3(0, 0, -7));
  RigShape withModel{0, 0, 0, true};
  RigShape without{0, 0, 0, false};
  expectNear3(v3(referenceValues("world.position", mesh, pose, withModel)[0]), {1, 2, -4}, 1e-6f, "model");
  expectNear3(v3(referenceValues("world.position", mesh, pose, without)[0]), {1, 2, 3}, 1e-6f, "identity");
}

TEST(Reference, MorphWeightOneAddsExactlyThatDelta) {
  MeshOptions o = limbOptions(3, 4);
  Mesh mesh = makeLimb(5, 7, o);
  RigShape shape = rigShapeFor(o);
  Pose pose = makeRestPose(shape);
  pose.morphWeights = {0.0f, 1.0f, 0.0f};
  auto pos = referenceValues("object.position", mesh, pose, shape);
  auto world = referenceValues("world.position", mesh, pose, shape);
  auto occ = referenceValues("object.occlusion", mesh, pose, shape);
  auto nrm = referenceValues("object.normal", mesh, pose, shape);
  const auto& vp = mesh.at("vertex.position");
  const auto& dp = mesh.at("morph.position[1]");
  const auto& vo = mesh.at("vertex.occlusion");
  const auto& dO = mesh.at("morph.occlusion[1]");
  const auto& vn = mesh.at("vertex.normal");
  const auto& dn = mesh.at("morph.normal[1]");
  bool anyNonZeroDelta = false;
  for (size_t v = 0; v < mesh.vertexCount; ++v) {
    expectNear3(v3(pos[v]), v3(vp[v]) + v3(dp[v]), 1e-6f, "object.position");
    expectNear3(v3(world[v]), v3(vp[v]) + v3(dp[v]), 1e-6f, "world.position");
    EXPECT_NEAR(occ[v].x, vo[v].x + dO[v].x, 1e-6f);
    expectNear3(v3(nrm[v]), glm::normalize(v3(vn[v]) + v3(dn[v])), 1e-6f, "object.normal");
    anyNonZeroDelta = anyNonZeroDelta || glm::length(v3(dp[v])) > 1e-3f;
  }
  EXPECT_TRUE(anyNonZeroDelta) << "the morph target must actually move vertices";
}

TEST(Reference, MorphSumsOnlyTargetsWhoseStreamExists) {
  Mesh mesh = oneVertex({0, 0, 0}, {0, 0, 0, 0}, {1, 0, 0, 0});
  mesh.streams["morph.position[0]"] = {glm::vec4(1, 0, 0, 0)};
  mesh.streams["morph.position[2]"] = {glm::vec4(0, 0, 1, 0)};  // target 1 moves no position
  mesh.streams["morph.normal[1]"] = {glm::vec4(0, 1, 0, 0)};
  RigShape shape{1, 0, 3, false};
  Pose pose;
  pose.morphWeights = {0.5f, 1.0f, 2.0f};
  expectNear3(v3(referenceValues("object.position", mesh, pose, shape)[0]), {0.5f, 0, 2}, 1e-6f, "pos");
  expectNear3(v3(referenceValues("object.normal", mesh, pose, shape)[0]),
              glm::normalize(glm::vec3(0, 1, 1)), 1e-6f, "normal");
  // Targets beyond shape.morphTargets are not applied even if the mesh carries them.
  RigShape two{1, 0, 2, false};
  expectNear3(v3(referenceValues("object.position", mesh, pose, two)[0]), {0.5f, 0, 0}, 1e-6f, "T=2");
}

TEST(Reference, TangentIsGramSchmidtAgainstMorphedNormal) {
  Mesh mesh = oneVertex({0, 0, 0}, {0, 0, 0, 0}, {1, 0, 0, 0});
  mesh.streams["vertex.tangent"] = {glm::vec4(1, 0, 1, 0)};  // not orthogonal to N = z
  RigShape shape{1, 0, 0, false};
  Pose pose;
  expectNear3(v3(referenceValues("object.tangent", mesh, pose, shape)[0]), {1, 0, 0}, 1e-6f, "GS");
}

// ---------------------------------------------------------------------------------------------
// Frames and view terms in random poses

struct Posed {
  Mesh mesh;
  RigShape shape;
  Pose pose;
};

Posed posedLimb(int influences, uint32_t seed) {
  MeshOptions o = limbOptions(3, influences);
  Posed p{makeLimb(10, 12, o), rigShapeFor(o), {}};
  p.pose = makeRandomPose(p.shape, seed);
  return p;
}

TEST(Reference, WorldFrameIsUnitAndOrthogonalUnderRigidSkinning) {
  for (uint32_t seed : {1u, 2u, 3u}) {
    // K = 1: mat3(M) is a rotation times a uniform scale, so it preserves orthogonality.
    Posed p = posedLimb(1, seed);
    auto N = referenceValues("world.normal", p.mesh, p.pose, p.shape);
    auto T = referenceValues("world.tangent", p.mesh, p.pose, p.shape);
    for (size_t v = 0; v < p.mesh.vertexCount; ++v) {
      EXPECT_NEAR(glm::length(v3(N[v])), 1.0f, 1e-5f);
      EXPECT_NEAR(glm::length(v3(T[v])), 1.0f, 1e-5f);
      EXPECT_NEAR(glm::dot(v3(N[v]), v3(T[v])), 0.0f, 1e-5f) << "vertex " << v;
    }
  }
}

TEST(Reference, ObjectFrameOrthogonalAndWorldFrameUnitUnderBlendSkinning) {
  Posed p = posedLimb(4, 7);
  auto oN = referenceValues("object.normal", p.mesh, p.pose, p.shape);
  auto oT = referenceValues("object.tangent", p.mesh, p.pose, p.shape);
  auto N = referenceValues("world.normal", p.mesh, p.pose, p.shape);
  auto T = referenceValues("world.tangent", p.mesh, p.pose, p.shape);
  for (size_t v = 0; v < p.mesh.vertexCount; ++v) {
    EXPECT_NEAR(glm::dot(v3(oN[v]), v3(oT[v])), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::length(v3(oT[v])), 1.0f, 1e-5f);
    EXPECT_NEAR(glm::length(v3(N[v])), 1.0f, 1e-5f);
    EXPECT_NEAR(glm::length(v3(T[v])), 1.0f, 1e-5f);
  }
}

TEST(Reference, BinormalCarriesHandednessAndFrameRowsAreTransposeOfTBN) {
  Posed p = posedLimb(4, 11);
  auto N = referenceValues("world.normal", p.mesh, p.pose, p.shape);
  auto T = referenceValues("world.tangent", p.mesh, p.pose, p.shape);
  auto B = referenceValues("world.binormal", p.mesh, p.pose, p.shape);
  auto H = referenceValues("world.handedness", p.mesh, p.pose, p.shape);
  auto rx = referenceValues("frame.row_x", p.mesh, p.pose, p.shape);
  auto ry = referenceValues("frame.row_y", p.mesh, p.pose, p.shape);
  auto rz = referenceValues("frame.row_z", p.mesh, p.pose, p.shape);
  const auto& h = p.mesh.at("vertex.handedness");
  std::set<float> signs;
  for (size_t v = 0; v < p.mesh.vertexCount; ++v) {
    EXPECT_EQ(H[v].x, h[v].x);
    signs.insert(h[v].x);
    EXPECT_NEAR(glm::length(v3(B[v])), 1.0f, 1e-5f);
    float side = glm::dot(glm::cross(v3(N[v]), v3(T[v])), v3(B[v]));
    EXPECT_GT(side * h[v].x, 0.0f) << "binormal sign must follow handedness at vertex " << v;
    // frame rows: the rows of [T B N] (columns T, B, N).
    glm::mat3 tbn(v3(T[v]), v3(B[v]), v3(N[v]));
    glm::mat3 rows = glm::transpose(tbn);
    expectNear3(v3(rx[v]), rows[0], 1e-6f, "row_x");
    expectNear3(v3(ry[v]), rows[1], 1e-6f, "row_y");
    expectNear3(v3(rz[v]), rows[2], 1e-6f, "row_z");
  }
  EXPECT_EQ(signs, (std::set<float>{-1.0f, 1.0f}));
}

TEST(Reference, NdotVMatchesEyeSpaceFormForRigidView) {
  Posed p = posedLimb(4, 5);
  auto ndotv = referenceValues("view.ndotv", p.mesh, p.pose, p.shape);
  auto om = referenceValues("view.one_minus_ndotv", p.mesh, p.pose, p.shape);
  auto om2 = referenceValues("view.one_minus_ndotv_sq", p.mesh, p.pose, p.shape);
  auto W = referenceValues("world.position", p.mesh, p.pose, p.shape);
  auto N = referenceValues("world.normal", p.mesh, p.pose, p.shape);
  auto eyePos = referenceValues("eye.position", p.mesh, p.pose, p.shape);
  auto eyeN = referenceValues("eye.normal", p.mesh, p.pose, p.shape);
  auto eyeDir = referenceValues("world.eye_dir", p.mesh, p.pose, p.shape);
  auto dz = referenceValues("dapple.normal_z", p.mesh, p.pose, p.shape);
  for (size_t v = 0; v < p.mesh.vertexCount; ++v) {
    EXPECT_GE(ndotv[v].x, 0.0f);
    EXPECT_LE(ndotv[v].x, 1.0f);
    // Listing 3-3: eye space, eye at the origin.
    glm::vec4 e = p.pose.view * glm::vec4(v3(W[v]), 1.0f);
    glm::vec3 en = glm::mat3(p.pose.view) * v3(N[v]);
    float eyeSpace = std::abs(glm::dot(glm::normalize(-glm::vec3(e)), en));
    EXPECT_NEAR(ndotv[v].x, eyeSpace, 2e-5f) << "vertex " << v;
    EXPECT_NEAR(om[v].x, 1.0f - ndotv[v].x, 1e-6f);
    EXPECT_NEAR(om2[v].x, (1.0f - ndotv[v].x) * (1.0f - ndotv[v].x), 1e-6f);
    expectNear4(eyePos[v], e, 1e-5f, "eye.position");
    expectNear3(v3(eyeN[v]), en, 1e-5f, "eye.normal");
    expectNear3(v3(eyeDir[v]), glm::normalize(v3(W[v]) - p.pose.cameraPosition), 1e-5f, "world.eye_dir");
    EXPECT_NEAR(dz[v].x, (glm::mat3(p.pose.dapple) * v3(N[v])).z, 1e-5f);
  }
}

TEST(Reference, ClipPositionIsProjectionViewWorld) {
  Posed p = posedLimb(4, 9);
  auto clip = referenceValues("clip.position", p.mesh, p.pose, p.shape);
  auto W = referenceValues("world.position", p.mesh, p.pose, p.shape);
  for (size_t v = 0; v < p.mesh.vertexCount; ++v) {
    glm::vec4 expected = p.pose.projection * p.pose.view * glm::vec4(v3(W[v]), 1.0f);
    expectNear4(clip[v], expected, 1e-4f, "clip.position");
    EXPECT_GT(clip[v].w, 0.0f) << "the limb is in front of the camera";
  }
}

TEST(Reference, SkinnedWorldPositionAgreesWithPerBoneBlend) {
  // Independent formulation: Σ_k w_k·(B_k·p) (listing 3-3) equals (Σ_k w_k·B_k)·p.
  Posed p = posedLimb(4, 21);
  auto W = referenceValues("world.position", p.mesh, p.pose, p.shape);
  auto O = referenceValues("object.position", p.mesh, p.pose, p.shape);
  const auto& j = p.mesh.at("skin.joints[0]");
  const auto& w = p.mesh.at("skin.weights[0]");
  for (size_t v = 0; v < p.mesh.vertexCount; ++v) {
    glm::vec4 sum(0.0f);
    for (int k = 0; k < 4; ++k)
      sum += w[v][k] * (p.pose.bones[static_cast<size_t>(j[v][k])] * glm::vec4(v3(O[v]), 1.0f));
    expectNear3(v3(W[v]), glm::vec3(sum), 1e-5f, "world.position");
  }
}

// ---------------------------------------------------------------------------------------------
// Vocabulary, pass-through and errors

TEST(Reference, PassThroughStreams) {
  MeshOptions o = limbOptions(2, 4);
  Mesh mesh = makeLimb(3, 4, o);
  RigShape shape = rigShapeFor(o);
  Pose pose = makeRandomPose(shape, 3);
  EXPECT_EQ(referenceValues("vertex.texcoord0", mesh, pose, shape), mesh.at("vertex.texcoord0"));
  EXPECT_EQ(referenceValues("out.texcoord1", mesh, pose, shape), mesh.at("vertex.texcoord1"));
  EXPECT_EQ(referenceValues("morph.normal[1]", mesh, pose, shape), mesh.at("morph.normal[1]"));
  auto occ = referenceValues("object.occlusion", mesh, pose, shape);
  const auto& vo = mesh.at("vertex.occlusion");
  for (size_t v = 0; v < mesh.vertexCount; ++v) {
    float expected = vo[v].x + pose.morphWeights[0] * mesh.at("morph.occlusion[0]")[v].x +
                     pose.morphWeights[1] * mesh.at("morph.occlusion[1]")[v].x;
    EXPECT_NEAR(occ[v].x, expected, 1e-6f);
  }
}

TEST(Reference, VocabularyAndComponents) {
  EXPECT_EQ(referenceComponents("world.position"), 3);
  EXPECT_EQ(referenceComponents("clip.position"), 4);
  EXPECT_EQ(referenceComponents("eye.position"), 4);
  EXPECT_EQ(referenceComponents("view.ndotv"), 1);
  EXPECT_EQ(referenceComponents("object.occlusion"), 1);
  EXPECT_EQ(referenceComponents("vertex.texcoord0"), 2);
  EXPECT_EQ(referenceComponents("out.texcoord0"), 2);
  EXPECT_EQ(referenceComponents("skin.weights[1]"), 4);
  EXPECT_EQ(referenceComponents("frame.row_z"), 3);
  EXPECT_TRUE(isReferenceSemantic("dapple.normal_z"));
  EXPECT_FALSE(isReferenceSemantic("skin.matrix"));
  EXPECT_FALSE(isReferenceSemantic("camera.view"));
  EXPECT_FALSE(isReferenceSemantic("world.nromal"));
  EXPECT_FALSE(isReferenceSemantic("morph.position[x]"));
  EXPECT_THROW(referenceComponents("skin.matrix"), std::invalid_argument);
}

TEST(Reference, ErrorsNameTheSemanticAndTheMissingData) {
  MeshOptions o = limbOptions(0, 4);
  o.tangents = false;
  Mesh mesh = makeLimb(2, 4, o);
  mesh.name = "fox";
  RigShape shape = rigShapeFor(o);
  Pose pose = makeRandomPose(shape, 1);

  std::string unknown = messageOf([&] { referenceValues("world.nromal", mesh, pose, shape); });
  EXPECT_NE(unknown.find("world.nromal"), std::string::npos) << unknown;

  std::string missing = messageOf([&] { referenceValues("world.tangent", mesh, pose, shape); });
  EXPECT_EQ(missing, "world.tangent needs vertex.tangent, which mesh 'fox' does not have");

  mesh.streams.erase("vertex.normal");
  missing = messageOf([&] { referenceValues("world.normal", mesh, pose, shape); });
  EXPECT_EQ(missing, "world.normal needs vertex.normal, which mesh 'fox' does not have");

  std::string mat = messageOf([&] { referenceValues("skin.matrix", mesh, pose, shape); });
  EXPECT_NE(mat.find("skin.matrix"), std::string::npos) << mat;

  Pose fewBones = pose;
  fewBones.bones.resize(2);
  std::string range = messageOf([&] { referenceValues("world.position", mesh, fewBones, shape); });
  EXPECT_NE(range.find("joint index"), std::string::npos) << range;

  RigShape morphing = shape;
  morphing.morphTargets = 1;
  mesh.streams["morph.position[0]"] = mesh.at("vertex.position");
  std::string weights = messageOf([&] { referenceValues("object.position", mesh, pose, morphing); });
  EXPECT_NE(weights.find("morph.weights[0]"), std::string::npos) << weights;
}

TEST(Reference, EvaluatorReusesIntermediatesWithSameResults) {
  Posed p = posedLimb(4, 13);
  ReferenceEvaluator eval(p.mesh, p.pose, p.shape);
  for (const char* s : {"frame.row_x", "world.normal", "view.ndotv", "clip.position"})
    EXPECT_EQ(eval.values(s), referenceValues(s, p.mesh, p.pose, p.shape)) << s;
}

// ---------------------------------------------------------------------------------------------
// Procedural meshes

void checkMeshContract(const Mesh& mesh, const MeshOptions& o) {
  SCOPED_TRACE(mesh.name);
  const size_t n = mesh.vertexCount;
  for (const auto& [name, stream] : mesh.streams) EXPECT_EQ(stream.size(), n) << name;
  for (const char* s : {"vertex.position", "vertex.normal", "vertex.texcoord0", "vertex.texcoord1"})
    EXPECT_TRUE(mesh.has(s)) << s;
  EXPECT_EQ(mesh.has("vertex.occlusion"), o.occlusion);
  EXPECT_EQ(mesh.has("vertex.tangent"), o.tangents);
  EXPECT_EQ(mesh.has("vertex.handedness"), o.tangents);
  for (int i = 0; i < o.morphTargets + 1; ++i) {
    std::string idx = "[" + std::to_string(i) + "]";
    bool present = i < o.morphTargets;
    EXPECT_EQ(mesh.has("morph.position" + idx), present) << i;
    EXPECT_EQ(mesh.has("morph.normal" + idx), present && o.morphNormals) << i;
    EXPECT_EQ(mesh.has("morph.occlusion" + idx), present && o.morphNormals && o.occlusion) << i;
    EXPECT_EQ(mesh.has("morph.tangent" + idx), present && o.morphTangents && o.tangents) << i;
  }
  const int sets = (o.influences + 3) / 4;
  for (int s = 0; s < sets + 1; ++s) {
    std::string idx = "[" + std::to_string(s) + "]";
    EXPECT_EQ(mesh.has("skin.joints" + idx), s < sets);
    EXPECT_EQ(mesh.has("skin.weights" + idx), s < sets);
  }
  std::set<float> signs;
  for (size_t v = 0; v < n; ++v) {
    EXPECT_NEAR(glm::length(v3(mesh.at("vertex.normal")[v])), 1.0f, 1e-5f);
    if (o.occlusion) {
      EXPECT_GE(mesh.at("vertex.occlusion")[v].x, 0.0f);
      EXPECT_LE(mesh.at("vertex.occlusion")[v].x, 1.0f);
    }
    if (o.tangents) {
      glm::vec3 t = v3(mesh.at("vertex.tangent")[v]);
      EXPECT_NEAR(glm::length(t), 1.0f, 1e-5f);
      EXPECT_LT(std::abs(glm::dot(t, v3(mesh.at("vertex.normal")[v]))), 0.2f) << "orthogonal-ish";
      signs.insert(mesh.at("vertex.handedness")[v].x);
    }
    if (sets == 0) continue;
    float sum = 0.0f, previous = 2.0f;
    for (int k = 0; k < 4 * sets; ++k) {
      std::string idx = "[" + std::to_string(k / 4) + "]";
      float w = mesh.at("skin.weights" + idx)[v][k % 4];
      float j = mesh.at("skin.joints" + idx)[v][k % 4];
      EXPECT_GE(j, 0.0f);
      EXPECT_LT(j, static_cast<float>(o.bones));
      EXPECT_EQ(j, std::floor(j));
      EXPECT_GE(w, 0.0f);
      EXPECT_LE(w, previous) << "weights sorted";
      previous = w;
      if (k >= o.influences || k >= o.bones) {
        EXPECT_EQ(w, 0.0f);
        EXPECT_EQ(j, 0.0f);
      }
      sum += w;
    }
    EXPECT_NEAR(sum, 1.0f, 1e-5f) << "vertex " << v;
  }
  if (o.tangents) {
    EXPECT_EQ(signs, (std::set<float>{-1.0f, 1.0f}));
  }
}

TEST(Procedural, LimbAndHeadHonourTheirOptions) {
  std::vector<MeshOptions> variants(6);
  variants[1].morphTargets = 3;
  variants[1].morphTangents = true;
  variants[2].influences = 1;
  variants[2].occlusion = false;
  variants[3].influences = 0;
  variants[3].tangents = false;
  variants[4].influences = 8;
  variants[4].bones = 12;
  variants[4].morphTargets = 2;
  variants[4].morphNormals = false;
  variants[5].influences = 4;
  variants[5].bones = 2;  // fewer bones than influences: slots 2, 3 unused
  for (const MeshOptions& o : variants) {
    Mesh limb = makeLimb(7, 9, o);
    EXPECT_EQ(limb.vertexCount, 8u * 10u);
    checkMeshContract(limb, o);
    Mesh head = makeHead(9, 11, o);
    EXPECT_EQ(head.vertexCount, 10u * 12u);
    checkMeshContract(head, o);
  }
}

TEST(Procedural, BadArgumentsThrow) {
  EXPECT_THROW(makeLimb(0, 8, {}), std::invalid_argument);
  EXPECT_THROW(makeHead(4, 2, {}), std::invalid_argument);
  MeshOptions noBones;
  noBones.bones = 0;
  EXPECT_THROW(makeLimb(4, 8, noBones), std::invalid_argument);
}

TEST(Procedural, DawnScale) {
  Mesh dawn = makeDawnScale();
  EXPECT_GE(dawn.vertexCount, 180000u);
  EXPECT_EQ(dawn.name, "dawn");
  MeshOptions o;
  o.morphTargets = 5;
  o.bones = 98;
  o.influences = 4;
  for (int i = 0; i < 5; ++i) {
    EXPECT_TRUE(dawn.has("morph.position[" + std::to_string(i) + "]"));
    EXPECT_TRUE(dawn.has("morph.normal[" + std::to_string(i) + "]"));
    EXPECT_TRUE(dawn.has("morph.occlusion[" + std::to_string(i) + "]"));
  }
  EXPECT_FALSE(dawn.has("morph.position[5]"));
  std::set<float> used;
  float maxJoint = 0;
  for (size_t v = 0; v < dawn.vertexCount; ++v) {
    const glm::vec4 j = dawn.at("skin.joints[0]")[v];
    const glm::vec4 w = dawn.at("skin.weights[0]")[v];
    ASSERT_NEAR(w.x + w.y + w.z + w.w, 1.0f, 1e-5f);
    for (int k = 0; k < 4; ++k) {
      ASSERT_LT(j[k], 98.0f);
      used.insert(j[k]);
      maxJoint = std::max(maxJoint, j[k]);
    }
  }
  EXPECT_EQ(used.size(), 98u) << "every bone influences some vertex";
  RigShape shape = rigShapeFor(o);
  EXPECT_EQ(shape.bones, 98);
  EXPECT_EQ(shape.morphTargets, 5);
  EXPECT_EQ(shape.influences, 4);
  auto world = referenceValues("world.position", dawn, makeRandomPose(shape, 42), shape);
  EXPECT_EQ(world.size(), dawn.vertexCount);
}

// ---------------------------------------------------------------------------------------------
// Poses

bool samePose(const Pose& a, const Pose& b) {
  return a.bones == b.bones && a.morphWeights == b.morphWeights && a.cameraPosition == b.cameraPosition &&
         a.view == b.view && a.projection == b.projection && a.model == b.model && a.dapple == b.dapple;
}

bool isRotation(const glm::mat3& m, float tol) {
  glm::mat3 mtm = glm::transpose(m) * m;
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r)
      if (std::abs(mtm[c][r] - (c == r ? 1.0f : 0.0f)) > tol) return false;
  return std::abs(glm::determinant(m) - 1.0f) < tol;
}

TEST(Procedural, PosesAreDeterministicAndDifferAcrossSeeds) {
  RigShape shape{98, 4, 5, false};
  Pose a = makeRandomPose(shape, 1234), b = makeRandomPose(shape, 1234), c = makeRandomPose(shape, 1235);
  EXPECT_TRUE(samePose(a, b));
  EXPECT_FALSE(samePose(a, c));
  EXPECT_NE(a.bones[0], c.bones[0]);
  EXPECT_NE(a.cameraPosition, c.cameraPosition);
  // Golden first draw: the Rng derives floats from raw mt19937 output, which the standard
  // fixes (the first output for seed 1234 is 822569775), so this value is the same everywhere.
  std::mt19937 raw(1234);
  EXPECT_EQ(raw(), 822569775u);
  // Golden pose values: floats are top-24-bit fractions of the raw output, exact everywhere.
  Pose g = makeRandomPose(RigShape{4, 4, 2, false}, 1234);
  EXPECT_EQ(g.morphWeights[0], 0.117443383f);
  EXPECT_EQ(g.morphWeights[1], 0.933140099f);
  EXPECT_NEAR(g.cameraPosition.x, -2.11153841f, 1e-5f);
  EXPECT_NEAR(g.cameraPosition.y, 3.00929809f, 1e-5f);
  EXPECT_NEAR(g.cameraPosition.z, -0.939701557f, 1e-5f);
}

TEST(Procedural, PoseContents) {
  RigShape shape{16, 4, 5, false};
  for (uint32_t seed = 0; seed < 20; ++seed) {
    Pose p = makeRandomPose(shape, seed);
    ASSERT_EQ(p.bones.size(), 16u);
    ASSERT_EQ(p.morphWeights.size(), 5u);
    for (float w : p.morphWeights) {
      EXPECT_GE(w, 0.0f);
      EXPECT_LE(w, 1.0f);
    }
    float maxAngle = 0.0f;
    for (const glm::mat4& B : p.bones) {
      glm::mat3 m(B);
      float s = std::cbrt(glm::determinant(m));
      EXPECT_GT(s, 0.85f);
      EXPECT_LT(s, 1.15f);
      EXPECT_TRUE(isRotation(m / s, 1e-4f)) << "bones are rotation * uniform scale";
      EXPECT_EQ(glm::row(B, 3), glm::vec4(0, 0, 0, 1));
      float angle = std::acos(std::clamp((m[0][0] + m[1][1] + m[2][2]) / s * 0.5f - 0.5f, -1.0f, 1.0f));
      EXPECT_LE(angle, glm::radians(60.0f) + 1e-3f);
      maxAngle = std::max(maxAngle, angle);
    }
    EXPECT_GT(maxAngle, glm::radians(20.0f)) << "rotations are non-trivial";
    float dist = glm::length(p.cameraPosition);
    EXPECT_GE(dist, 3.0f - 1e-4f);
    EXPECT_LE(dist, 5.0f + 1e-4f);
    EXPECT_TRUE(isRotation(glm::mat3(p.view), 1e-4f)) << "view is rigid";
    glm::vec4 eyeOfCamera = p.view * glm::vec4(p.cameraPosition, 1.0f);
    EXPECT_LT(glm::length(glm::vec3(eyeOfCamera)), 1e-4f) << "camera.position is the eye";
    glm::vec4 origin = p.view * glm::vec4(0, 0, 0, 1);
    EXPECT_NEAR(origin.x, 0.0f, 1e-4f);
    EXPECT_NEAR(origin.y, 0.0f, 1e-4f);
    EXPECT_LT(origin.z, 0.0f) << "looking at the origin";
    EXPECT_TRUE(isRotation(glm::mat3(p.dapple), 1e-4f));
    EXPECT_TRUE(isRotation(glm::mat3(p.model), 1e-4f));
  }
}

TEST(Procedural, NonUniformScaleIsOptIn) {
  RigShape shape{32, 4, 0, false};
  PoseOptions o;
  o.nonUniformScaleFraction = 1.0f;
  Pose p = makeRandomPose(shape, 5, o);
  int nonUniform = 0;
  for (const glm::mat4& B : p.bones) {
    glm::mat3 m(B);
    float a = glm::length(m[0]), b = glm::length(m[1]), c = glm::length(m[2]);
    if (std::abs(a - b) > 1e-3f || std::abs(b - c) > 1e-3f) ++nonUniform;
  }
  EXPECT_GT(nonUniform, 0);
}

}  // namespace

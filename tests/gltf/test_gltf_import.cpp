// glTF → rig import: formats, joint/target counts of the shared sample models (see
// ../shared/models/README.md), YAML round trip, sparse accessors, normalized formats, limits,
// animation sampling and the skinning formula.
#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <filesystem>

#include <unistd.h>

#include "gltf_test_util.h"
#include "pipeline/generate.h"
#include "rig/gltf_import.h"
#include "validate/gltf_scene.h"

namespace sg {
namespace {

using test::GltfBuilder;
using test::tinySkinnedModel;
using test::modelPath;

const GltfAttributeInfo* attr(const GltfImport& imp, const std::string& name) {
  for (const auto& a : imp.attributes)
    if (a.gltfName == name) return &a;
  return nullptr;
}
const RigAttribute* rigAttr(const Rig& rig, const std::string& name) {
  for (const auto& a : rig.attributes)
    if (a.name == name) return &a;
  return nullptr;
}
const RigUniform* uniformFor(const Rig& rig, const std::string& semantic) {
  for (const auto& u : rig.uniforms)
    if (u.semantic == semantic) return &u;
  return nullptr;
}
GltfImport importAt(const std::string& rel, int mesh = 0, int prim = 0) {
  GltfImportOptions o;
  o.mesh = mesh;
  o.primitive = prim;
  return importGltf(modelPath(rel), o);
}
std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(GltfImport, FoxIsSkinnedWith24JointsAndNoNormals) {
  GltfImport imp = importAt("Fox/Fox.glb");
  EXPECT_EQ(imp.rig.name, "Fox/fox1/0");
  EXPECT_EQ(imp.data.vertexCount, 1728u);
  EXPECT_EQ(imp.joints, 24);
  EXPECT_EQ(imp.influences, 4);
  EXPECT_EQ(imp.morphTargets, 0);
  EXPECT_EQ(imp.rig.param("bones"), 24);
  EXPECT_EQ(imp.rig.param("influences"), 4);
  EXPECT_EQ(imp.rig.param("morph_targets"), 0);
  ASSERT_EQ(imp.attributes.size(), 4u);  // POSITION, TEXCOORD_0, JOINTS_0, WEIGHTS_0
  EXPECT_EQ(attr(imp, "NORMAL"), nullptr);
  const auto* j = attr(imp, "JOINTS_0");
  ASSERT_NE(j, nullptr);
  EXPECT_EQ(j->componentType, "unsigned short");
  EXPECT_EQ(j->type, "VEC4");
  EXPECT_FALSE(j->normalized);
  EXPECT_EQ(j->format, "uint16x4");
  EXPECT_EQ(j->rigAttribute, "joints0");
  const auto* w = attr(imp, "WEIGHTS_0");
  ASSERT_NE(w, nullptr);
  EXPECT_EQ(w->componentType, "float");
  EXPECT_EQ(w->format, "float32x4");
  EXPECT_EQ(attr(imp, "TEXCOORD_0")->format, "float32x2");
  EXPECT_EQ(attr(imp, "POSITION")->format, "float32x3");
  ASSERT_NE(rigAttr(imp.rig, "joints0"), nullptr);
  EXPECT_EQ(rigAttr(imp.rig, "joints0")->shaderType, Type::UVec4);
  EXPECT_EQ(rigAttr(imp.rig, "joints0")->provides[0].semantic, "skin.joints[0]");
  EXPECT_EQ(rigAttr(imp.rig, "normal"), nullptr);
  const RigUniform* bones = uniformFor(imp.rig, "skin.bones");
  ASSERT_NE(bones, nullptr);
  EXPECT_EQ(bones->arraySize, 24);
  EXPECT_EQ(uniformFor(imp.rig, "model.matrix"), nullptr);  // skinned: bones map to world
  EXPECT_EQ(uniformFor(imp.rig, "morph.weights"), nullptr);
  EXPECT_NE(uniformFor(imp.rig, "camera.position"), nullptr);
  EXPECT_NE(uniformFor(imp.rig, "camera.view"), nullptr);
  EXPECT_NE(uniformFor(imp.rig, "camera.projection"), nullptr);
  EXPECT_EQ(imp.data.animations.size(), 3u);
  EXPECT_EQ(imp.data.animations[0].name, "Survey");
  EXPECT_TRUE(imp.notes.empty());
}

TEST(GltfImport, SimpleSkinFromDataUris) {
  GltfImport imp = importAt("SimpleSkin/SimpleSkin.gltf");
  EXPECT_EQ(imp.rig.name, "SimpleSkin/0/0");  // unnamed mesh: its index
  EXPECT_EQ(imp.data.vertexCount, 10u);
  EXPECT_EQ(imp.joints, 2);
  EXPECT_EQ(imp.influences, 4);
  EXPECT_EQ(attr(imp, "JOINTS_0")->format, "uint16x4");
  EXPECT_EQ(attr(imp, "WEIGHTS_0")->format, "float32x4");
  EXPECT_EQ(uniformFor(imp.rig, "skin.bones")->arraySize, 2);
  EXPECT_EQ(imp.data.animations.size(), 1u);
}

TEST(GltfImport, MorphStressTestTwoPrimitivesEightTargets) {
  const size_t vertices[2] = {24, 1504};
  for (int p = 0; p < 2; ++p) {
    SCOPED_TRACE(p);
    GltfImport imp = importAt("MorphStressTest/MorphStressTest.gltf", 0, p);
    EXPECT_EQ(imp.rig.name, fmt::format("MorphStressTest/Cube.001/{}", p));
    EXPECT_EQ(imp.data.vertexCount, vertices[p]);
    EXPECT_EQ(imp.joints, 0);
    EXPECT_EQ(imp.influences, 0);
    EXPECT_EQ(imp.morphTargets, 8);
    ASSERT_EQ(imp.targetAttributes.size(), 8u);
    for (const auto& t : imp.targetAttributes) EXPECT_EQ(t, (std::vector<std::string>{"NORMAL", "POSITION"}));
    EXPECT_EQ(imp.rig.morphedAttributes, (std::vector<std::string>{"position", "normal"}));
    EXPECT_EQ(imp.rig.morphTargets(), 8);
    EXPECT_TRUE(rigAttr(imp.rig, "position_morph")->perMorphTarget);
    EXPECT_TRUE(rigAttr(imp.rig, "normal_morph")->perMorphTarget);
    EXPECT_EQ(rigAttr(imp.rig, "tangent_morph"), nullptr);
    EXPECT_EQ(attr(imp, "TEXCOORD_0")->format, "float32x2");
    EXPECT_EQ(attr(imp, "TEXCOORD_1")->format, "float32x2");
    EXPECT_EQ(uniformFor(imp.rig, "morph.weights")->arraySize, 8);
    EXPECT_NE(uniformFor(imp.rig, "model.matrix"), nullptr);
    EXPECT_EQ(uniformFor(imp.rig, "skin.bones"), nullptr);
    EXPECT_EQ(imp.data.animations.size(), 3u);
    EXPECT_EQ(imp.data.streams.count("morph.normal[7]"), 1u);
  }
}

TEST(GltfImport, AnimatedMorphSphereMovesPositionNormalTangent) {
  GltfImport imp = importAt("AnimatedMorphSphere/AnimatedMorphSphere.gltf");
  EXPECT_EQ(imp.rig.name, "AnimatedMorphSphere/Sphere/0");
  EXPECT_EQ(imp.data.vertexCount, 1876u);
  EXPECT_EQ(imp.morphTargets, 2);
  for (const auto& t : imp.targetAttributes)
    EXPECT_EQ(t, (std::vector<std::string>{"NORMAL", "POSITION", "TANGENT"}));
  EXPECT_EQ(imp.rig.morphedAttributes, (std::vector<std::string>{"position", "normal", "tangent"}));
  const RigAttribute* t = rigAttr(imp.rig, "tangent");
  ASSERT_NE(t, nullptr);
  EXPECT_EQ(t->format, VertexFormat::Float32x4);
  ASSERT_EQ(t->provides.size(), 2u);
  EXPECT_EQ(t->provides[0].semantic, "vertex.tangent");
  EXPECT_EQ(t->provides[0].swizzle, "xyz");
  EXPECT_EQ(t->provides[1].semantic, "vertex.handedness");
  EXPECT_EQ(t->provides[1].swizzle, "w");
  EXPECT_EQ(rigAttr(imp.rig, "tangent_morph")->format, VertexFormat::Float32x3);
  // Handedness is ±1.
  for (const auto& h : imp.data.streams.at("vertex.handedness")) EXPECT_EQ(std::abs(h[0]), 1.0f);
}

TEST(GltfImport, MorphPrimitivesTestOneTargetPerPrimitive) {
  const size_t vertices[2] = {21, 9};
  for (int p = 0; p < 2; ++p) {
    SCOPED_TRACE(p);
    GltfImport imp = importAt("MorphPrimitivesTest/MorphPrimitivesTest.gltf", 0, p);
    EXPECT_EQ(imp.data.vertexCount, vertices[p]);
    EXPECT_EQ(imp.morphTargets, 1);
    EXPECT_EQ(imp.targetAttributes[0], (std::vector<std::string>{"POSITION"}));
    EXPECT_EQ(imp.rig.morphedAttributes, (std::vector<std::string>{"position"}));
    EXPECT_EQ(imp.data.meshWeights, (std::vector<double>{0.5}));
    EXPECT_NE(rigAttr(imp.rig, "normal"), nullptr);
    EXPECT_EQ(rigAttr(imp.rig, "normal_morph"), nullptr);
    EXPECT_TRUE(imp.data.animations.empty());
  }
}

TEST(GltfImport, SimpleMorphTwoPositionTargets) {
  GltfImport imp = importAt("SimpleMorph/SimpleMorph.gltf");
  EXPECT_EQ(imp.data.vertexCount, 3u);
  EXPECT_EQ(imp.morphTargets, 2);
  EXPECT_EQ(imp.rig.morphedAttributes, (std::vector<std::string>{"position"}));
  EXPECT_EQ(imp.data.meshWeights, (std::vector<double>{0.5, 0.5}));
  EXPECT_EQ(imp.rig.attributes.size(), 2u);  // position, position_morph
}

// Every rig the models give, written as YAML, loads back to the same rig.
TEST(GltfImport, YamlRoundTripForEveryPrimitive) {
  struct M {
    const char* file;
    int primitives;
  };
  for (const M& m : {M{"Fox/Fox.glb", 1}, M{"SimpleSkin/SimpleSkin.gltf", 1}, M{"MorphStressTest/MorphStressTest.gltf", 2},
                     M{"AnimatedMorphSphere/AnimatedMorphSphere.gltf", 1},
                     M{"MorphPrimitivesTest/MorphPrimitivesTest.gltf", 2}, M{"SimpleMorph/SimpleMorph.gltf", 1}}) {
    for (int p = 0; p < m.primitives; ++p) {
      SCOPED_TRACE(fmt::format("{} primitive {}", m.file, p));
      GltfImport imp = importAt(m.file, 0, p);
      std::string yaml = rigToYaml(imp.rig, {"header comment", "with: colons"});
      Rig back;
      ASSERT_NO_THROW(back = loadRigText(yaml, "roundtrip.yaml")) << yaml;
      EXPECT_EQ(back.name, imp.rig.name);
      EXPECT_EQ(back.params, imp.rig.params);
      EXPECT_EQ(back.morphedAttributes, imp.rig.morphedAttributes);
      ASSERT_EQ(back.attributes.size(), imp.rig.attributes.size());
      for (size_t i = 0; i < back.attributes.size(); ++i) {
        const auto &a = back.attributes[i], &b = imp.rig.attributes[i];
        EXPECT_EQ(a.name, b.name);
        EXPECT_EQ(a.format, b.format);
        EXPECT_EQ(a.shaderType, b.shaderType);
        EXPECT_EQ(a.perMorphTarget, b.perMorphTarget);
        ASSERT_EQ(a.provides.size(), b.provides.size());
        for (size_t k = 0; k < a.provides.size(); ++k) {
          EXPECT_EQ(a.provides[k].semantic, b.provides[k].semantic);
          EXPECT_EQ(a.provides[k].swizzle, b.provides[k].swizzle);
        }
      }
      ASSERT_EQ(back.uniforms.size(), imp.rig.uniforms.size());
      for (size_t i = 0; i < back.uniforms.size(); ++i) {
        EXPECT_EQ(back.uniforms[i].name, imp.rig.uniforms[i].name);
        EXPECT_EQ(back.uniforms[i].semantic, imp.rig.uniforms[i].semantic);
        EXPECT_EQ(back.uniforms[i].type, imp.rig.uniforms[i].type);
        EXPECT_EQ(back.uniforms[i].arraySize, imp.rig.uniforms[i].arraySize);
      }
    }
  }
}

TEST(GltfImport, LoadRigDispatchesOnTheExtension) {
  Rig fox = loadRig(modelPath("Fox/Fox.glb#0/0"));
  EXPECT_EQ(fox.name, "Fox/fox1/0");
  EXPECT_EQ(fox.file, modelPath("Fox/Fox.glb"));
  EXPECT_EQ(loadRig(modelPath("Fox/Fox.glb")).name, "Fox/fox1/0");
  EXPECT_EQ(loadRig(modelPath("MorphStressTest/MorphStressTest.gltf#0/1")).name, "MorphStressTest/Cube.001/1");
  EXPECT_EQ(loadRig(test::sourcePath("examples/dawn/face.rig.yaml")).name, "dawn-face");
  EXPECT_TRUE(isGltfPath("a/Fox.GLB#0/0"));
  EXPECT_TRUE(isGltfPath("x.gltf"));
  EXPECT_FALSE(isGltfPath("rig.yaml"));
  std::string e = errorOf([] { loadRig(modelPath("Fox/Fox.glb#0/1")); });
  EXPECT_NE(e.find("mesh 'fox1' has 1 primitive(s); there is no primitive 1"), std::string::npos) << e;
  e = errorOf([] { loadRig(modelPath("Fox/Fox.glb#zero")); });
  EXPECT_NE(e.find("does not select a primitive"), std::string::npos) << e;
  e = errorOf([] { loadRig(modelPath("Fox/Missing.glb")); });
  EXPECT_NE(e.find("Missing.glb"), std::string::npos) << e;
}

// A binary model called .gltf is read by its magic, as viewers read it (it was "invalid JSON").
TEST(GltfImport, ABinaryModelIsKnownByItsMagicNotItsName) {
  const std::filesystem::path copy =
      std::filesystem::path(::testing::TempDir()) / ("fox-binary-" + std::to_string(::getpid()) + ".gltf");
  std::filesystem::copy_file(modelPath("Fox/Fox.glb"), copy, std::filesystem::copy_options::overwrite_existing);
  GltfImportOptions o;
  GltfImport imp = importGltf(copy.string(), o);
  std::filesystem::remove(copy);
  EXPECT_EQ(imp.data.vertexCount, 1728u);
  EXPECT_EQ(imp.joints, 24);
}

// The Fox has no normals: asking for world_normal names what is missing.
TEST(GltfImport, FoxWorldNormalRequestNamesVertexNormal) {
  GenerateOptions g;
  g.rigPath = modelPath("Fox/Fox.glb#0/0");
  g.fragmentPath = test::dataPath("uv_normal.frag");
  g.rulesPaths = {test::sourcePath("rules/standard.yaml")};
  std::string e = errorOf([&] { generate(g); });
  EXPECT_NE(e.find("rig 'Fox/fox1/0'"), std::string::npos) << e;
  EXPECT_NE(e.find("cannot produce 'world.normal'"), std::string::npos) << e;
  EXPECT_NE(e.find("vertex.normal"), std::string::npos) << e;
  EXPECT_NE(e.find("uv_normal.frag"), std::string::npos) << e;  // points at the request
  // Without the normal request the same rig generates.
  g.fragmentPath = test::dataPath("uv.frag");
  EXPECT_NO_THROW(generate(g));
}

TEST(GltfImport, NormalizedFormatsAreDequantizedAsTheGpuReadsThem) {
  GltfImport imp = importGltfText(tinySkinnedModel(), "tiny.gltf");
  EXPECT_EQ(imp.rig.name, "tiny/tri/0");
  EXPECT_EQ(attr(imp, "JOINTS_0")->format, "uint8x4");
  EXPECT_EQ(attr(imp, "WEIGHTS_0")->format, "unorm8x4");
  EXPECT_TRUE(attr(imp, "WEIGHTS_0")->normalized);
  EXPECT_EQ(attr(imp, "WEIGHTS_0")->componentType, "unsigned byte");
  EXPECT_EQ(attr(imp, "COLOR_0")->format, "unorm16x4");
  EXPECT_EQ(rigAttr(imp.rig, "weights0")->shaderType, Type::Vec4);
  EXPECT_EQ(rigAttr(imp.rig, "joints0")->shaderType, Type::UVec4);
  const auto& w = imp.data.streams.at("skin.weights[0]");
  EXPECT_EQ(w[1][0], 128.0f / 255.0f);
  EXPECT_EQ(w[1][1], 127.0f / 255.0f);
  EXPECT_EQ(w[2][1], 204.0f / 255.0f);
  const auto& j = imp.data.streams.at("skin.joints[0]");
  EXPECT_EQ(j[0][1], 1.0f);
  EXPECT_EQ(j[2][0], 1.0f);
  const auto& c = imp.data.streams.at("vertex.color0");
  EXPECT_EQ(c[0][2], 32768.0f / 65535.0f);
  EXPECT_EQ(c[1][3], 4.0f / 65535.0f);
  EXPECT_EQ(imp.joints, 2);
}

TEST(GltfImport, SparseAccessorsAreApplied) {
  GltfImport imp = importGltfText(tinySkinnedModel(), "tiny.gltf");
  // Morph target without a buffer view: zeros, then the sparse value at index 1.
  const auto& m = imp.data.streams.at("morph.position[0]");
  ASSERT_EQ(m.size(), 3u);
  EXPECT_EQ(m[0], (std::array<float, 4>{0, 0, 0, 0}));
  EXPECT_EQ(m[1], (std::array<float, 4>{0, 0.5f, 0, 0}));
  EXPECT_EQ(m[2], (std::array<float, 4>{0, 0, 0, 0}));
  // UVs: base buffer view with index 2 replaced.
  const auto& uv = imp.data.streams.at("vertex.texcoord0");
  EXPECT_EQ(uv[1], (std::array<float, 4>{1, 0, 0, 0}));
  EXPECT_EQ(uv[2], (std::array<float, 4>{0.25f, 0.75f, 0, 0}));
  EXPECT_TRUE(attr(imp, "TEXCOORD_0")->sparse);
  bool noted = false;
  for (const auto& n : imp.notes) noted = noted || n.find("TEXCOORD_0 is a sparse accessor") != std::string::npos;
  EXPECT_TRUE(noted);
  EXPECT_EQ(imp.rig.morphTargets(), 1);
  EXPECT_EQ(imp.data.meshWeights, (std::vector<double>{0.25}));
  // The written rig loads.
  EXPECT_NO_THROW(loadRigText(rigToYaml(imp.rig), "tiny.rig.yaml"));
}

// glTF names may hold control characters and be any length; the rig name, written into the
// YAML of `rig import` and read back, must be one printable line of at most kMaxRigNameBytes.
// Such a mesh made `rig import` fail at a line of the file it had not written.
TEST(GltfImport, AnyMeshNameGivesALoadableRigName) {
  std::string longName;
  for (int i = 0; i < 200; ++i) longName += "\u00e9";  // é: two bytes each in UTF-8
  for (const std::string& name : {std::string(R"(we\"ird\n\t*/ #: {x})"), longName}) {
    std::string text = tinySkinnedModel();
    const size_t at = text.find(R"("name":"tri")");
    ASSERT_NE(at, std::string::npos);
    text.replace(at, 12, R"("name":")" + name + "\"");
    GltfImport imp = importGltfText(text, "tiny.gltf");
    SCOPED_TRACE(imp.rig.name);
    EXPECT_LE(imp.rig.name.size(), kMaxRigNameBytes);
    EXPECT_EQ(imp.rig.name.substr(0, 5), "tiny/");
    EXPECT_EQ(imp.rig.name.substr(imp.rig.name.size() - 2), "/0");
    Rig back;
    ASSERT_NO_THROW(back = loadRigText(rigToYaml(imp.rig), "tiny.rig.yaml"));
    EXPECT_EQ(back.name, imp.rig.name);
  }
  EXPECT_EQ(importGltfText(tinySkinnedModel(), "tiny.gltf").rig.name, "tiny/tri/0");
}

TEST(GltfImport, MoreThanSixteenInfluencesIsRejected) {
  EXPECT_EQ(importGltfText(tinySkinnedModel(1), "tiny.gltf").rig.param("influences"), 8);
  // JOINTS_2/WEIGHTS_2 and JOINTS_3/WEIGHTS_3: 16 influences, every set imported.
  Rig r16 = importGltfText(tinySkinnedModel(3), "tiny.gltf").rig;
  EXPECT_EQ(r16.param("influences"), 16);
  int sets = 0;
  for (const auto& a : r16.attributes)
    for (const auto& part : a.provides) sets += part.semantic.rfind("skin.joints[", 0) == 0;
  EXPECT_EQ(sets, 4);
  EXPECT_NO_THROW(loadRigText(rigToYaml(r16), "tiny.rig.yaml"));
  std::string e = errorOf([] { importGltfText(tinySkinnedModel(4), "tiny.gltf"); });
  EXPECT_NE(e.find("tiny.gltf: error: mesh 'tri' primitive 0 has JOINTS_4 (20 influences per vertex); the rules serve "
                   "at most 16"),
            std::string::npos)
      << e;
}

TEST(GltfImport, TooManyJointsNamesModelMeshAndLimit) {
  // 1100 joints: nodes 1..1100, all children of the skinned node's sibling root.
  GltfBuilder b;
  int pos = b.accessor(b.view(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}), 5126, 3, "VEC3");
  int joints = b.accessor(b.view(std::vector<uint16_t>{0, 1, 2, 3, 299, 0, 0, 0, 5, 6, 7, 8}), 5123, 3, "VEC4");
  int weights = b.accessor(b.view(std::vector<float>{1, 0, 0, 0, 1, 0, 0, 0, 0.5f, 0.5f, 0, 0}), 5126, 3, "VEC4");
  std::string nodes = R"({"name":"body","mesh":0,"skin":0})", jointList;
  for (int i = 1; i <= 1100; ++i) {
    nodes += fmt::format(R"(,{{"name":"j{}","translation":[0,{},0]}})", i, i);
    jointList += (jointList.empty() ? "" : ",") + std::to_string(i);
  }
  std::string json = b.json(fmt::format(
      R"("meshes":[{{"name":"fox","primitives":[{{"attributes":{{"POSITION":{},"JOINTS_0":{},"WEIGHTS_0":{}}}}}]}}],)"
      R"("skins":[{{"joints":[{}]}}],"nodes":[{}],"scenes":[{{"nodes":[0]}}])",
      pos, joints, weights, jointList, nodes));
  std::string e = errorOf([&] { importGltfText(json, "models/Fox.glb"); });
  EXPECT_NE(e.find("Fox.glb: error: mesh 'fox' uses 1100 joints; the bone palette holds at most 1024 (kMaxBones)"),
            std::string::npos)
      << e;
  // The same limit, lowered, on the real Fox.
  GltfImportOptions o;
  o.maxBones = 16;
  e = errorOf([&] { importGltf(modelPath("Fox/Fox.glb"), o); });
  EXPECT_NE(e.find("Fox.glb: error: mesh 'fox1' uses 24 joints; the bone palette holds at most 16 (kMaxBones)"),
            std::string::npos)
      << e;
  o.maxBones = 24;
  EXPECT_NO_THROW(importGltf(modelPath("Fox/Fox.glb"), o));
}

TEST(GltfImport, UnsupportedOptionalAttributesAreLeftOutWithANote) {
  GltfBuilder b;
  int pos = b.accessor(b.view(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}), 5126, 3, "VEC3");
  int rgb = b.accessor(b.view(std::vector<float>{1, 0, 0, 0, 1, 0, 0, 0, 1}), 5126, 3, "VEC3");
  int quv = b.accessor(b.view(std::vector<uint16_t>{0, 0, 65535, 0, 0, 65535}), 5123, 3, "VEC2", R"("normalized":true)");
  std::string json = b.json(fmt::format(
      R"("meshes":[{{"primitives":[{{"attributes":{{"POSITION":{},"COLOR_0":{},"TEXCOORD_0":{},"_TEMPERATURE":{}}},"mode":0}}]}}],)"
      R"("nodes":[{{"mesh":0,"matrix":[2,0,0,0,0,2,0,0,0,0,2,0,1,2,3,1]}}])",
      pos, rgb, quv, pos));
  GltfImport imp = importGltfText(json, "points.gltf");
  EXPECT_EQ(imp.data.mode, 0);  // POINTS: fine, shaders run per vertex
  EXPECT_EQ(imp.rig.attributes.size(), 3u);  // position, the RGB colours, and the UVs as stored (unorm16x2)
  EXPECT_EQ(imp.notes.size(), 2u);
  std::string all;
  for (const auto& n : imp.notes) all += n + "\n";
  EXPECT_EQ(all.find("COLOR_0"), std::string::npos) << all;
  EXPECT_NE(all.find("TEXCOORD_0 is stored normalized unsigned short VEC2 (KHR_mesh_quantization): fed to the shader "
                     "as stored, unorm16x2"),
            std::string::npos)
      << all;
  EXPECT_EQ(imp.data.streams.at("vertex.texcoord0")[1][0], 1.0f);  // 65535 / 65535
  EXPECT_NE(all.find("_TEMPERATURE"), std::string::npos) << all;
  EXPECT_NE(uniformFor(imp.rig, "model.matrix"), nullptr);
  // Node matrix → model matrix.
  auto G = gltfNodeGlobals(imp.data, -1, 0.0);
  EXPECT_EQ(G[0][3], glm::dvec4(1, 2, 3, 1));
  EXPECT_EQ(G[0][0][0], 2.0);
}


// glTF's RGB vertex colours mean alpha 1 (the spec's COLOR_0 VEC3). Float ones are read as they are
// stored, 3 floats, into a vec4 the device completes with w = 1 (Vulkan's vertex input fills
// what the format lacks: 0, and 1 for w); normalized RGB integers are padded to 4 bytes per
// element, so no 3-component format reads them and they are left out with a note.
TEST(GltfImport, RgbColoursAreReadAsRgbaWithAlphaOne) {
  GltfBuilder b;
  int pos = b.accessor(b.view(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}), 5126, 3, "VEC3");
  int rgb = b.accessor(b.view(std::vector<float>{0.25f, 0.5f, 0.75f, 1, 0, 0, 0, 0, 1}), 5126, 3, "VEC3");
  std::string json = b.json(fmt::format(
      R"("meshes":[{{"primitives":[{{"attributes":{{"POSITION":{},"COLOR_0":{}}}}}]}}],"nodes":[{{"mesh":0}}])", pos, rgb));
  GltfImport imp = importGltfText(json, "rgb.gltf");
  const RigAttribute* c = rigAttr(imp.rig, "color0");
  ASSERT_NE(c, nullptr);
  EXPECT_EQ(c->format, VertexFormat::Float32x3);  // 12 bytes a vertex, as the file stores them
  EXPECT_EQ(c->shaderType, Type::Vec4);
  EXPECT_EQ(attr(imp, "COLOR_0")->format, "float32x3");
  const auto& v = imp.data.streams.at("vertex.color0");
  EXPECT_EQ(v[0], (std::array<float, 4>{0.25f, 0.5f, 0.75f, 1}));
  EXPECT_EQ(v[2], (std::array<float, 4>{0, 0, 1, 1}));
  // The rig's YAML says so, and reads back the same.
  std::string yaml = rigToYaml(imp.rig, {});
  EXPECT_NE(yaml.find("color0: { format: float32x3, shader_type: vec4, provides: \"vertex.color0\" }"), std::string::npos)
      << yaml;
  Rig back = loadRigText(yaml, "rgb.yaml");
  EXPECT_EQ(rigAttr(back, "color0")->shaderType, Type::Vec4);
  EXPECT_EQ(rigAttr(back, "color0")->format, VertexFormat::Float32x3);

  GltfBuilder q;
  pos = q.accessor(q.view(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}), 5126, 3, "VEC3");
  rgb = q.accessor(q.view(std::vector<uint8_t>{255, 0, 0, 0, 0, 255, 0, 0, 0, 0, 255, 0}), 5121, 3, "VEC3",
                   R"("normalized":true)");
  json = q.json(fmt::format(
      R"("meshes":[{{"primitives":[{{"attributes":{{"POSITION":{},"COLOR_0":{}}}}}]}}],"nodes":[{{"mesh":0}}])", pos, rgb));
  imp = importGltfText(json, "rgb8.gltf");
  EXPECT_EQ(rigAttr(imp.rig, "color0"), nullptr);
  std::string all;
  for (const auto& n : imp.notes) all += n + "\n";
  EXPECT_NE(all.find("COLOR_0 (normalized unsigned byte VEC3) is not carried"), std::string::npos) << all;
}

// --- animation sampling and the skinning formula ---

GltfChannel channel(GltfPath path, GltfInterpolation interp, std::vector<float> times, std::vector<float> values, int n) {
  GltfChannel c;
  c.node = 0;
  c.path = path;
  c.interpolation = interp;
  c.times = std::move(times);
  c.values = std::move(values);
  c.components = n;
  return c;
}

TEST(GltfAnimation, LinearStepAndClamping) {
  GltfChannel c = channel(GltfPath::Translation, GltfInterpolation::Linear, {1, 3}, {0, 0, 0, 2, 4, 6}, 3);
  EXPECT_EQ(sampleGltfChannel(c, 2.0), (std::vector<double>{1, 2, 3}));
  EXPECT_EQ(sampleGltfChannel(c, 0.0), (std::vector<double>{0, 0, 0}));   // before the first key
  EXPECT_EQ(sampleGltfChannel(c, 10.0), (std::vector<double>{2, 4, 6}));  // after the last key
  c.interpolation = GltfInterpolation::Step;
  EXPECT_EQ(sampleGltfChannel(c, 2.9), (std::vector<double>{0, 0, 0}));
  EXPECT_EQ(sampleGltfChannel(c, 3.0), (std::vector<double>{2, 4, 6}));
  GltfChannel w = channel(GltfPath::Weights, GltfInterpolation::Linear, {0, 1}, {0, 1, 1, 0}, 2);
  EXPECT_EQ(sampleGltfChannel(w, 0.25), (std::vector<double>{0.25, 0.75}));
}

TEST(GltfAnimation, RotationSlerpTakesTheShortArc) {
  float h = std::sqrt(0.5f);
  // identity → 90° about Z; the second key is stored negated (same rotation, long way round).
  GltfChannel c = channel(GltfPath::Rotation, GltfInterpolation::Linear, {0, 1}, {0, 0, 0, 1, 0, 0, -h, -h}, 4);
  std::vector<double> q = sampleGltfChannel(c, 0.5);
  double s = std::sin(glm::radians(22.5)), co = std::cos(glm::radians(22.5));
  EXPECT_NEAR(q[0], 0, 1e-7);
  EXPECT_NEAR(q[1], 0, 1e-7);
  EXPECT_NEAR(std::abs(q[2]), s, 1e-6);
  EXPECT_NEAR(std::abs(q[3]), co, 1e-6);
  EXPECT_GT(q[2] * q[3], 0);  // 45° about +Z, not -135°
}

TEST(GltfAnimation, CubicSplineIsTheSpecHermite) {
  // Tangents 0: p(s) = v0 + (v1 - v0)(3s² - 2s³).
  GltfChannel c = channel(GltfPath::Translation, GltfInterpolation::CubicSpline, {0, 2},
                          {9, 9, 9, 0, 0, 0, 0, 0, 0, /**/ 0, 0, 0, 4, 8, 0, 9, 9, 9}, 3);
  std::vector<double> p = sampleGltfChannel(c, 0.5);  // s = 0.25
  double f = 3 * 0.0625 - 2 * 0.015625;
  EXPECT_NEAR(p[0], 4 * f, 1e-12);
  EXPECT_NEAR(p[1], 8 * f, 1e-12);
  // Out-tangent b0 = (1, 0, 0), interval 2: adds h10(s)·2·b0.
  c.values[6] = 1;
  p = sampleGltfChannel(c, 0.5);
  double h10 = 0.015625 - 2 * 0.0625 + 0.25;
  EXPECT_NEAR(p[0], 4 * f + h10 * 2, 1e-12);
  // Keys: exactly the values (tangents of the ends are ignored).
  EXPECT_EQ(sampleGltfChannel(c, 2.0), (std::vector<double>{4, 8, 0}));
}

TEST(GltfAnimation, SkinPaletteFollowsTheHierarchy) {
  GltfImport imp = importGltfText(tinySkinnedModel(), "tiny.gltf");
  GltfSceneOptions so;
  so.times = {0.0, 1.0, 2.0};
  GltfSceneInfo info;
  ValidationScene scene = gltfScene(imp, so, &info);
  EXPECT_EQ(info.animation, "wave");
  EXPECT_EQ(info.end, 2.0);
  ASSERT_EQ(scene.poses.size(), 3u);
  EXPECT_EQ(scene.shape.bones, 2);
  EXPECT_EQ(scene.shape.influences, 4);
  EXPECT_FALSE(scene.shape.hasModelMatrix);
  // t = 0: root at the origin, tip at (1,0,0) with IBM translate(-1,0,0): identity palette
  // (the skinned node's own translation (5,5,5) is ignored, as the spec requires).
  for (const auto& B : scene.poses[0].bones)
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) EXPECT_NEAR(B[c][r], c == r ? 1.0 : 0.0, 1e-6);
  // t = 1 (s = 0.5 of a 2 s interval): the root moved along the Hermite curve,
  // y = h01·2 = 1 and x = h10·2·(out-tangent 1) = 0.25; the tip is still unrotated (STEP
  // holds the first key until t = 2), so both bones are that translation.
  glm::vec4 t0 = scene.poses[1].bones[0][3];
  EXPECT_NEAR(t0.x, 0.25, 1e-6);
  EXPECT_NEAR(t0.y, 1.0, 1e-6);
  EXPECT_NEAR(scene.poses[1].bones[1][3].y, 1.0, 1e-6);
  // t = 2: root at (0,2,0); tip rotated 90° about Z at (1,2,0): B1 = T(1,2,0)·Rz(90)·T(-1,0,0).
  glm::mat4 expect = glm::translate(glm::mat4(1), glm::vec3(1, 2, 0)) *
                     glm::rotate(glm::mat4(1), glm::radians(90.0f), glm::vec3(0, 0, 1)) *
                     glm::translate(glm::mat4(1), glm::vec3(-1, 0, 0));
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) EXPECT_NEAR(scene.poses[2].bones[1][c][r], expect[c][r], 1e-6) << c << "," << r;
  // Morph weights: the mesh default (no weights channel).
  EXPECT_EQ(scene.poses[2].morphWeights, (std::vector<float>{0.25f}));
}

TEST(GltfAnimation, SimpleSkinPaletteIsJointGlobalTimesInverseBind) {
  GltfImport imp = importAt("SimpleSkin/SimpleSkin.gltf");
  // Node 1 (joint 0) at (0,1,0), node 2 (joint 1) its child at the same place; both inverse
  // bind matrices of this copy are translate(-0.5,-1,0): without the animation both palette
  // entries are translate(-0.5,0,0).
  std::vector<glm::dmat4> G = gltfNodeGlobals(imp.data, -1, 0.0);
  const GltfSkin& skin = imp.data.skins[0];
  glm::dmat4 expect = glm::translate(glm::dmat4(1.0), glm::dvec3(-0.5, 0, 0));
  for (size_t j = 0; j < skin.joints.size(); ++j) {
    glm::dmat4 ibm;
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) ibm[c][r] = skin.inverseBind[j][static_cast<size_t>(c * 4 + r)];
    glm::dmat4 B = G[static_cast<size_t>(skin.joints[j])] * ibm;
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) EXPECT_NEAR(B[c][r], expect[c][r], 1e-6);
  }
  // The scene's palette is the same product (in float) at the start of the animation, whose
  // first key is the identity rotation.
  GltfSceneOptions so;
  so.times = {0.0};
  ValidationScene scene = gltfScene(imp, so);
  ASSERT_EQ(scene.poses[0].bones.size(), 2u);
  for (const auto& B : scene.poses[0].bones)
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) EXPECT_NEAR(B[c][r], expect[c][r], 1e-6);
}

TEST(GltfAnimation, MorphWeightsChannelDrivesTheWeights) {
  GltfImport imp = importAt("SimpleMorph/SimpleMorph.gltf");
  std::vector<double> w0, w1;
  gltfNodeGlobals(imp.data, 0, 0.0, &w0);
  gltfNodeGlobals(imp.data, 0, 2.0, &w1);
  ASSERT_EQ(w0.size(), 2u);
  EXPECT_NE(w0, w1);
  for (double w : w0) EXPECT_TRUE(w >= 0.0 && w <= 1.0);
  std::string e = errorOf([&] { findGltfAnimation(imp.data, "nope"); });
  EXPECT_NE(e.find("has no animation 'nope'"), std::string::npos) << e;
}

}  // namespace
}  // namespace sg

// Quantized and compressed glTF (docs/gltf.md#quantized-and-compressed-models):
// KHR_mesh_quantization's storage decoded with the glTF spec's formulas, gltfpack's outputs
// (tests/gltf/data/gltfpack, make.sh) against the float originals within the error gltfpack
// states, EXT_meshopt_compression decoding and its hostile cases, and extensionsRequired.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>

#include "../core/core_test_util.h"
#include "gltf_builder.h"
#include "gltf_test_util.h"
#include "rig/gltf_import.h"
#include "validate/gltf_scene.h"

namespace sg {
namespace {

using test::dataPath;
using test::GltfBuilder;
using test::modelPath;

// The error `f` throws as the user sees it ("file:line:col: error: ...").
std::string errorOf(const std::function<void()>& f) { return formatDiagnostic(sgtest::errorOf(f)); }
std::string packed(const std::string& name) { return dataPath("gltfpack/" + name); }

// --- KHR_mesh_quantization on hand-built accessors ---

TEST(GltfQuantized, StorageDecodesWithTheSpecFormulas) {
  GltfBuilder b;
  // POSITION as (non-normalized) signed shorts: the values themselves; the node's scale and
  // translation dequantize them, as in gltfpack's output.
  int pos = b.accessor(b.view(std::vector<int16_t>{-32768, 0, 32767, 1, 2, 3, 0, 0, 0}), 5122, 3, "VEC3");
  // NORMAL as normalized bytes: max(c / 127, -1), so -128 and -127 both give -1.
  int nrm = b.accessor(b.view(std::vector<int8_t>{-128, 0, 0, 0, -127, 0, 64, 0, 127}), 5120, 3, "VEC3",
                       R"("normalized":true)");
  // TANGENT as normalized shorts: max(c / 32767, -1).
  int tan = b.accessor(b.view(std::vector<int16_t>{32767, 0, 0, 32767, 0, 32767, 0, -32768, -16384, 0, 0, -32767}),
                       5122, 3, "VEC4", R"("normalized":true)");
  // TEXCOORD_0 as normalized unsigned bytes: c / 255; TEXCOORD_1 as unsigned shorts: c.
  int uv0 = b.accessor(b.view(std::vector<uint8_t>{255, 0, 128, 51, 0, 255}), 5121, 3, "VEC2", R"("normalized":true)");
  int uv1 = b.accessor(b.view(std::vector<uint16_t>{0, 65535, 4095, 1, 7, 9}), 5123, 3, "VEC2");
  // Morph target: POSITION deltas as bytes (not normalized), NORMAL deltas as normalized shorts.
  int dpos = b.accessor(b.view(std::vector<int8_t>{-128, 127, 5, 0, 0, 0, 1, -1, 0}), 5120, 3, "VEC3");
  int dnrm = b.accessor(b.view(std::vector<int16_t>{-32768, 16384, 0, 0, 0, 0, 0, 0, 32767}), 5122, 3, "VEC3",
                        R"("normalized":true)");
  std::string json = b.json(fmt::format(
      R"("extensionsUsed":["KHR_mesh_quantization"],"extensionsRequired":["KHR_mesh_quantization"],)"
      R"("meshes":[{{"primitives":[{{"attributes":{{"POSITION":{},"NORMAL":{},"TANGENT":{},"TEXCOORD_0":{},"TEXCOORD_1":{}}},)"
      R"("targets":[{{"POSITION":{},"NORMAL":{}}}]}}]}}],)"
      R"("nodes":[{{"mesh":0,"translation":[1,2,3],"scale":[0.5,0.5,0.5]}}])",
      pos, nrm, tan, uv0, uv1, dpos, dnrm));
  GltfImport imp = importGltfText(json, "q.gltf");
  const auto& s = imp.data.streams;
  auto at = [&](const char* sem, size_t v, size_t c) { return s.at(sem)[v][c]; };
  EXPECT_EQ(at("vertex.position", 0, 0), -32768.0f);
  EXPECT_EQ(at("vertex.position", 0, 2), 32767.0f);
  EXPECT_EQ(at("vertex.position", 1, 1), 2.0f);
  EXPECT_EQ(at("vertex.normal", 0, 0), -1.0f);
  EXPECT_EQ(at("vertex.normal", 1, 1), -1.0f);
  EXPECT_FLOAT_EQ(at("vertex.normal", 2, 0), 64.0f / 127.0f);
  EXPECT_EQ(at("vertex.normal", 2, 2), 1.0f);
  EXPECT_EQ(at("vertex.tangent", 0, 0), 1.0f);
  EXPECT_EQ(at("vertex.handedness", 0, 0), 1.0f);
  EXPECT_EQ(at("vertex.tangent", 1, 1), 1.0f);
  EXPECT_EQ(at("vertex.handedness", 1, 0), -1.0f);  // -32768 clamps to -1
  EXPECT_FLOAT_EQ(at("vertex.tangent", 2, 0), -16384.0f / 32767.0f);
  EXPECT_EQ(at("vertex.handedness", 2, 0), -1.0f);  // -32767 / 32767
  EXPECT_EQ(at("vertex.texcoord0", 0, 0), 1.0f);
  EXPECT_FLOAT_EQ(at("vertex.texcoord0", 1, 0), 128.0f / 255.0f);
  EXPECT_FLOAT_EQ(at("vertex.texcoord0", 1, 1), 51.0f / 255.0f);
  EXPECT_EQ(at("vertex.texcoord1", 0, 1), 65535.0f);
  EXPECT_EQ(at("vertex.texcoord1", 1, 0), 4095.0f);
  EXPECT_EQ(at("morph.position[0]", 0, 0), -128.0f);
  EXPECT_EQ(at("morph.position[0]", 0, 1), 127.0f);
  EXPECT_EQ(at("morph.position[0]", 2, 1), -1.0f);
  EXPECT_EQ(at("morph.normal[0]", 0, 0), -1.0f);
  EXPECT_FLOAT_EQ(at("morph.normal[0]", 0, 1), 16384.0f / 32767.0f);
  EXPECT_EQ(at("morph.normal[0]", 2, 2), 1.0f);
  // Normalized integers are fed as stored (a VEC3 in the x4 form, its w the padding); the
  // rest is expanded to float: positions and TEXCOORD_1 are integers read unnormalized.
  std::map<std::string, std::string> formats;
  for (const auto& a : imp.rig.attributes) formats[a.name] = formatName(a.format);
  EXPECT_EQ(formats["position"], "float32x3");
  EXPECT_EQ(formats["normal"], "snorm8x4");
  EXPECT_EQ(formats["tangent"], "snorm16x4");
  EXPECT_EQ(formats["texcoord0"], "unorm8x2");
  EXPECT_EQ(formats["texcoord1"], "float32x2");
  // Stored as read: re-encoding the dequantized values gives them back exactly.
  for (const auto& a : imp.rig.attributes)
    for (const auto& part : a.provides) {
      if (a.perMorphTarget) continue;  // deltas: float32, one stream per target
      const std::string swz = part.swizzle.empty() ? std::string("xyzw").substr(0, size_t(formatComponents(a.format)))
                                                   : part.swizzle;
      for (const auto& v : s.at(part.semantic))
        for (size_t k = 0; k < swz.size(); ++k)
          EXPECT_EQ(storedValue(a.format, int(std::string("xyzw").find(swz[k])), v[int(k)]), v[int(k)])
              << a.name << " " << part.semantic;
    }
  // The dequantization transform is the node's, as stored: the model matrix scales by 0.5.
  auto G = gltfNodeGlobals(imp.data, -1, 0.0);
  EXPECT_EQ(G[0] * glm::dvec4(2, 4, 6, 1), glm::dvec4(2, 4, 6, 1));  // 0.5 * (2,4,6) + (1,2,3)
}

TEST(GltfQuantized, StorageOutsideTheExtensionsTableIsRefusedOrLeftOut) {
  GltfBuilder b;
  int pos = b.accessor(b.view(std::vector<uint16_t>{0, 0, 0, 1, 0, 0, 0, 1, 0}), 5123, 3, "VEC3");
  int upos = b.accessor(b.view(std::vector<uint32_t>{0, 0, 0, 1, 0, 0, 0, 1, 0}), 5125, 3, "VEC3");
  int unrm = b.accessor(b.view(std::vector<uint8_t>{0, 0, 255, 0, 0, 255, 0, 0, 255}), 5121, 3, "VEC3",
                        R"("normalized":true)");
  int snrm = b.accessor(b.view(std::vector<int8_t>{0, 0, 127, 0, 0, 127, 0, 0, 127}), 5120, 3, "VEC3");
  auto model = [&](const std::string& attrs, const std::string& targets = "") {
    return b.json(fmt::format(R"("meshes":[{{"name":"q","primitives":[{{"attributes":{{{}}}{}}}]}}])", attrs,
                              targets.empty() ? "" : ",\"targets\":[{" + targets + "}]"));
  };
  // Unsigned int positions are not in the table.
  std::string e = errorOf([&] { importGltfText(model(fmt::format(R"("POSITION":{})", upos)), "q.gltf"); });
  EXPECT_NE(e.find("mesh 'q' primitive 0: POSITION is unsigned int VEC3; positions are VEC3 of float, or (unsigned) "
                   "byte or short, normalized or not (KHR_mesh_quantization)"),
            std::string::npos)
      << e;
  // Normals as unsigned or non-normalized bytes are not either: left out with a note.
  for (int n : {unrm, snrm}) {
    GltfImport imp = importGltfText(model(fmt::format(R"("POSITION":{},"NORMAL":{})", pos, n)), "q.gltf");
    EXPECT_EQ(imp.data.streams.count("vertex.normal"), 0u);
    std::string all;
    for (const auto& note : imp.notes) all += note + "\n";
    EXPECT_NE(all.find("normals are VEC3 of float, or normalized byte or short"), std::string::npos) << all;
  }
  // Morph position deltas are signed: unsigned shorts are refused.
  e = errorOf([&] { importGltfText(model(fmt::format(R"("POSITION":{})", pos), fmt::format(R"("POSITION":{})", pos)), "q.gltf"); });
  EXPECT_NE(e.find("morph target 0 POSITION is unsigned short VEC3; deltas are VEC3 of float, or byte or short"),
            std::string::npos)
      << e;
}

// --- extensionsRequired ---

TEST(GltfQuantized, ARequiredExtensionWeCannotReadIsNamedWithItsLocation) {
  GltfBuilder b;
  int pos = b.accessor(b.view(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}), 5126, 3, "VEC3");
  std::string json = b.json(fmt::format(
      "\"extensionsUsed\":[\"KHR_draco_mesh_compression\"],\n\"extensionsRequired\":[\n  \"KHR_mesh_quantization\", "
      "\"KHR_draco_mesh_compression\"],\n\"meshes\":[{{\"primitives\":[{{\"attributes\":{{\"POSITION\":{}}}}}]}}]",
      pos));
  std::string e = errorOf([&] { importGltfText(json, "draco.gltf"); });
  EXPECT_NE(e.find("draco.gltf:3:28: error: the model requires the extension KHR_draco_mesh_compression "
                   "(extensionsRequired), which shadergen cannot read"),
            std::string::npos)
      << e;
  // Merely used (not required), it is no error.
  json.replace(json.find("\"extensionsRequired\""), 20, "\"extensionsIgnoredX\"");
  EXPECT_NO_THROW(importGltfText(json, "draco.gltf"));
}

// --- gltfpack's outputs against the float originals ---

struct Packed {
  const char* file;      // in tests/gltf/data/gltfpack
  const char* original;  // in ../shared/models
  int primitive;
  double normalDegrees;  // gltfpack's 8-bit normals: component error 0.5/127 (≈0.4°); octahedral (-cc) ≈0.95° max
};
void PrintTo(const Packed& p, std::ostream* os) { *os << p.file << "#0/" << p.primitive; }

std::vector<Packed> packedModels() {
  return {{"SimpleSkin.glb", "SimpleSkin/SimpleSkin.gltf", 0, 0},
          {"SimpleSkin.meshopt.glb", "SimpleSkin/SimpleSkin.gltf", 0, 0},
          {"SimpleSkin.meshopt-cc.glb", "SimpleSkin/SimpleSkin.gltf", 0, 0},
          {"SimpleMorph.glb", "SimpleMorph/SimpleMorph.gltf", 0, 0},
          {"SimpleMorph.meshopt.glb", "SimpleMorph/SimpleMorph.gltf", 0, 0},
          {"MorphPrimitivesTest.glb", "MorphPrimitivesTest/MorphPrimitivesTest.gltf", 0, 0.41},
          {"MorphPrimitivesTest.glb", "MorphPrimitivesTest/MorphPrimitivesTest.gltf", 1, 0.41},
          {"MorphPrimitivesTest.meshopt.glb", "MorphPrimitivesTest/MorphPrimitivesTest.gltf", 0, 0.41},
          {"MorphPrimitivesTest.meshopt.glb", "MorphPrimitivesTest/MorphPrimitivesTest.gltf", 1, 0.41},
          {"AnimatedMorphSphere.meshopt-cc-kv.glb", "AnimatedMorphSphere/AnimatedMorphSphere.gltf", 0, 1.0}};
}

// World positions (rest pose, glTF's skinning or the mesh node's transform), world normals
// and world morph position deltas of every vertex.
struct WorldVertex {
  glm::dvec3 p, n;
  std::vector<glm::dvec3> d;
};
std::vector<WorldVertex> restWorld(const GltfImport& imp, double* step = nullptr) {
  const GltfModelData& m = imp.data;
  auto G = gltfNodeGlobals(m, -1, 0.0);
  std::vector<WorldVertex> out(m.vertexCount);
  double unit = 0;  // world length of one unit of the stored positions (the quantization step)
  for (size_t v = 0; v < m.vertexCount; ++v) {
    glm::dmat4 M(0.0);
    if (m.skin >= 0) {
      const GltfSkin& sk = m.skins[static_cast<size_t>(m.skin)];
      const auto& j = m.streams.at("skin.joints[0]")[v];
      const auto& w = m.streams.at("skin.weights[0]")[v];
      for (int k = 0; k < 4; ++k) {
        size_t joint = static_cast<size_t>(j[static_cast<size_t>(k)]);
        glm::dmat4 ib;
        for (int c = 0; c < 16; ++c) ib[c / 4][c % 4] = sk.inverseBind[joint][static_cast<size_t>(c)];
        M += double(w[static_cast<size_t>(k)]) * (G[static_cast<size_t>(sk.joints[joint])] * ib);
      }
    } else {
      M = m.meshNode >= 0 ? G[static_cast<size_t>(m.meshNode)] : glm::dmat4(1.0);
    }
    unit = std::max(unit, glm::length(glm::dvec3(M[0])));
    const auto& p = m.streams.at("vertex.position")[v];
    out[v].p = glm::dvec3(M * glm::dvec4(p[0], p[1], p[2], 1.0));
    if (auto n = m.streams.find("vertex.normal"); n != m.streams.end()) {
      const auto& q = n->second[v];
      out[v].n = glm::normalize(glm::transpose(glm::inverse(glm::dmat3(M))) * glm::dvec3(q[0], q[1], q[2]));
    }
    for (int t = 0; m.streams.count(fmt::format("morph.position[{}]", t)); ++t) {
      const auto& d = m.streams.at(fmt::format("morph.position[{}]", t))[v];
      out[v].d.push_back(glm::dmat3(M) * glm::dvec3(d[0], d[1], d[2]));
    }
  }
  if (step) *step = unit;
  return out;
}

class GltfPacked : public ::testing::TestWithParam<Packed> {};

TEST_P(GltfPacked, MatchesTheFloatOriginalWithinGltfpacksQuantization) {
  const Packed& c = GetParam();
  GltfImportOptions o;
  o.primitive = c.primitive;
  GltfImport q = importGltf(packed(c.file), o);
  GltfImport f = importGltf(modelPath(c.original), o);
  // The same rig: attributes (semantics, formats), deformers, uniforms; only the name differs,
  // and the formats of what the rig carries as stored: joints and weights (gltfpack: uint8x4,
  // unorm8x4), normals and tangents (snorm8x4: gltfpack's 8-bit default) and normalized UVs
  // (unorm16x2), a VEC3 as its x4 form read through "xyz".
  q.rig.name = f.rig.name;
  const std::map<std::string, std::vector<VertexFormat>> asStored = {
      {"joints", {VertexFormat::Uint8x4}}, {"weights", {VertexFormat::Unorm8x4}},
      {"normal", {VertexFormat::Snorm8x4, VertexFormat::Snorm16x4}},
      {"tangent", {VertexFormat::Snorm8x4, VertexFormat::Snorm16x4}},
      {"texcoord", {VertexFormat::Unorm16x2, VertexFormat::Unorm8x2, VertexFormat::Snorm16x2, VertexFormat::Snorm8x2}}};
  for (auto& a : q.rig.attributes) {
    if (formatIsFloat32(a.format)) continue;
    auto kind = std::find_if(asStored.begin(), asStored.end(), [&](const auto& k) { return a.name.rfind(k.first, 0) == 0; });
    ASSERT_NE(kind, asStored.end()) << a.name << " is " << formatName(a.format);
    EXPECT_NE(std::find(kind->second.begin(), kind->second.end(), a.format), kind->second.end())
        << a.name << " is " << formatName(a.format);
    for (const auto& b : f.rig.attributes)
      if (b.name == a.name) {
        a.format = b.format;
        a.shaderType = b.shaderType;
        a.provides = b.provides;
      }
  }
  EXPECT_EQ(rigToYaml(q.rig), rigToYaml(f.rig));
  EXPECT_EQ(q.morphTargets, f.morphTargets);
  EXPECT_EQ(q.joints, f.joints);

  double unit = 0;
  auto Q = restWorld(q, &unit);
  auto F = restWorld(f);
  double extent = 0;
  for (const auto& v : F) extent = std::max(extent, glm::length(v.p - F[0].p));
  // Positions are rounded to the 14-bit grid: at most half a step per axis.
  const double tol = 0.5 * std::sqrt(3.0) * unit * 1.001 + 1e-6 * extent;
  const double cosTol = std::cos(c.normalDegrees * M_PI / 180.0);
  // gltfpack reorders and welds vertices: each quantized vertex must match some original
  // vertex in every attribute, and each original vertex some quantized position.
  for (size_t i = 0; i < Q.size(); ++i) {
    bool found = false;
    double nearest = 1e300;
    for (const auto& v : F) {
      double dp = glm::length(Q[i].p - v.p);
      nearest = std::min(nearest, dp);
      if (dp > tol) continue;
      if (c.normalDegrees > 0 && glm::dot(Q[i].n, v.n) < cosTol) continue;
      bool deltas = Q[i].d.size() == v.d.size();
      for (size_t t = 0; deltas && t < v.d.size(); ++t) deltas = glm::length(Q[i].d[t] - v.d[t]) <= 2 * tol;
      if (deltas) found = true;
    }
    ASSERT_TRUE(found) << "vertex " << i << ": nearest original position " << nearest << " away (tolerance " << tol
                       << ")";
  }
  for (const auto& v : F) {
    double nearest = 1e300;
    for (const auto& w : Q) nearest = std::min(nearest, glm::length(w.p - v.p));
    ASSERT_LE(nearest, tol);
  }
  // The bound is tight enough to matter: one more step would exceed it.
  EXPECT_LT(tol, 2 * unit + 1e-6 * extent);
}

INSTANTIATE_TEST_SUITE_P(Gltfpack, GltfPacked, ::testing::ValuesIn(packedModels()),
                         [](const ::testing::TestParamInfo<Packed>& i) {
                           std::string s = fmt::format("{}_{}", i.param.file, i.param.primitive);
                           for (auto& ch : s)
                             if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           return s;
                         });

// `validate --rig MODEL.glb#m/p --time ...` on lavapipe, like the float originals
// (test_gltf_validate.cpp).
struct Validated {
  const char* ref;
  const char* fragment;
  const char* times;
};
void PrintTo(const Validated& v, std::ostream* os) { *os << v.ref; }
class GltfPackedValidate : public ::testing::TestWithParam<Validated> {};
TEST_P(GltfPackedValidate, PassesAtSeveralTimes) {
  const Validated& c = GetParam();
  std::string cmd = fmt::format("XDG_RUNTIME_DIR=/tmp \"{}\" validate --rig \"{}\" -f \"{}\" -r \"{}\" {} > /dev/null",
                                SG_CLI, packed(c.ref), dataPath(c.fragment), test::sourcePath("rules/standard.yaml"),
                                c.times);
  EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
}
INSTANTIATE_TEST_SUITE_P(
    Gltfpack, GltfPackedValidate,
    ::testing::Values(Validated{"SimpleSkin.glb#0/0", "minimal.frag", "--time 1.0 --time 3.3"},
                      Validated{"SimpleSkin.meshopt-cc.glb#0/0", "minimal.frag", "--time 1.0 --time 3.3"},
                      Validated{"SimpleMorph.glb#0/0", "minimal.frag", "--time 1.0 --time 2.5"},
                      Validated{"SimpleMorph.meshopt.glb#0/0", "minimal.frag", "--time 1.0 --time 2.5"},
                      Validated{"MorphPrimitivesTest.glb#0/1", "lit_uv.frag", "--time 0"},
                      Validated{"MorphPrimitivesTest.meshopt.glb#0/0", "lit_uv.frag", "--time 0"},
                      Validated{"AnimatedMorphSphere.meshopt-cc-kv.glb#0/0", "frame.frag", "--time 1.2 --time 3.9"}),
    [](const ::testing::TestParamInfo<Validated>& i) {
      std::string s = i.param.ref;
      for (auto& ch : s)
        if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
      return s;
    });

// --- EXT_meshopt_compression on hostile input ---

// SimpleSkin.meshopt.glb as .gltf text (BIN as a data URI), its JSON editable.
struct MeshoptText {
  nlohmann::json j;
  std::string text() const { return j.dump(); }
};
MeshoptText meshoptModel() {
  std::ifstream in(packed("SimpleSkin.meshopt.glb"), std::ios::binary);
  std::string b((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  uint32_t jsonLen, binLen;
  std::memcpy(&jsonLen, b.data() + 12, 4);
  std::memcpy(&binLen, b.data() + 20 + jsonLen, 4);
  MeshoptText m{nlohmann::json::parse(b.substr(20, jsonLen))};
  std::vector<uint8_t> bin(b.begin() + 28 + jsonLen, b.begin() + 28 + jsonLen + binLen);
  m.j["buffers"][0]["uri"] = "data:application/octet-stream;base64," + test::base64(bin);
  return m;
}

TEST(GltfMeshopt, DecodesLikeTheUncompressedOutput) {
  GltfImport plain = importGltf(packed("SimpleSkin.glb"));
  GltfImport text = importGltfText(meshoptModel().text(), "SimpleSkin.gltf");
  EXPECT_EQ(text.data.streams, plain.data.streams);
  EXPECT_EQ(text.data.indices, plain.data.indices);
  ASSERT_EQ(text.data.animations.size(), plain.data.animations.size());
  EXPECT_EQ(text.data.animations[0].channels[0].values, plain.data.animations[0].channels[0].values);
  // -cc: the QUATERNION filter on the rotation keys decodes to the same rotations (q or -q),
  // within its 12 bits.
  GltfImport cc = importGltf(packed("SimpleSkin.meshopt-cc.glb"));
  const auto& a = cc.data.animations[0].channels[0].values;
  const auto& b = plain.data.animations[0].channels[0].values;
  ASSERT_EQ(cc.data.animations[0].channels[0].path, GltfPath::Rotation);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i + 3 < a.size(); i += 4) {
    double dot = 0;
    for (size_t k = 0; k < 4; ++k) dot += double(a[i + k]) * b[i + k];
    EXPECT_GT(std::abs(dot), 0.9999) << "key " << i / 4;
  }
}

TEST(GltfMeshopt, HostileViewsGetClearErrors) {
  struct Edit {
    std::function<void(nlohmann::json&)> edit;
    const char* expected;
  };
  const std::vector<Edit> edits{
      // A fallback buffer claiming 16 GiB: refused before anything is allocated.
      {[](nlohmann::json& j) { j["buffers"][1]["byteLength"] = uint64_t{1} << 34; },
       "buffer 1: decompressing into its 17179869184 bytes would take the decoded data past this model's limit"},
      // Not a fallback buffer (the flag is no boolean): then it needs data of its own.
      {[](nlohmann::json& j) { j["buffers"][1]["extensions"]["EXT_meshopt_compression"]["fallback"] = "yes"; },
       "hostile.gltf: error: buffer file '' refused"},
      {[](nlohmann::json& j) { j["bufferViews"][0]["extensions"]["EXT_meshopt_compression"]["byteLength"] = 100000; },
       "buffer view 0: the compressed bytes 0..+100000 lie outside buffer 0"},
      {[](nlohmann::json& j) { j["bufferViews"][0]["extensions"]["EXT_meshopt_compression"]["buffer"] = 1; },
       "buffer view 0: the compressed data is in buffer 1, which is a fallback buffer without data"},
      {[](nlohmann::json& j) { j["bufferViews"][0]["extensions"]["EXT_meshopt_compression"]["count"] = 11; },
       "buffer view 0: 11 elements of 8 bytes do not fill the view's 80 bytes"},
      {[](nlohmann::json& j) { j["bufferViews"][0]["extensions"]["EXT_meshopt_compression"]["byteStride"] = 6; },
       "buffer view 0: byteStride 6 is not valid for mode ATTRIBUTES"},
      {[](nlohmann::json& j) { j["bufferViews"][0]["extensions"]["EXT_meshopt_compression"]["mode"] = "LINES"; },
       "buffer view 0: unknown EXT_meshopt_compression mode 'LINES'"},
      {[](nlohmann::json& j) { j["bufferViews"][0]["extensions"]["EXT_meshopt_compression"]["filter"] = "HALF"; },
       "buffer view 0: unknown EXT_meshopt_compression filter 'HALF'"},
      {[](nlohmann::json& j) { j["bufferViews"][3]["extensions"]["EXT_meshopt_compression"]["filter"] = "OCTAHEDRAL"; },
       "buffer view 3: filter OCTAHEDRAL applies to ATTRIBUTES only, not TRIANGLES"},
      {[](nlohmann::json& j) { j["bufferViews"][0]["extensions"]["EXT_meshopt_compression"]["count"] = -1; },
       "buffer view 0: EXT_meshopt_compression 'count' is not a non-negative integer"},
      // Truncated compressed data: meshoptimizer's decoder says so, nothing is read past it.
      {[](nlohmann::json& j) { j["bufferViews"][0]["extensions"]["EXT_meshopt_compression"]["byteLength"] = 20; },
       "buffer view 0: the ATTRIBUTES data (20 bytes) is malformed"},
  };
  for (const auto& e : edits) {
    MeshoptText m = meshoptModel();
    e.edit(m.j);
    std::string err = errorOf([&] { importGltfText(m.text(), "hostile.gltf"); });
    EXPECT_NE(err.find(e.expected), std::string::npos) << err;
  }
}

}  // namespace
}  // namespace sg

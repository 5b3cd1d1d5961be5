// Loaders and checks in front of the search: rig YAML, rules YAML, integer expressions,
// snippet templates, fragment-shader reflection and varying binding, problem building.
// Every error case asserts the exact file:line:col of the diagnostic and a key phrase.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <sys/stat.h>
#include <unistd.h>

#include <climits>

#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "common/diagnostics.h"
#include "common/input_file.h"
#include "core_test_util.h"
#include "common/types.h"
#include "interface/fragment_interface.h"
#include "rig/rig.h"
#include "rig/rig_lod.h"
#include "rules/expr.h"
#include "rules/rules.h"
#include "rules/snippet.h"
#include "search/problem.h"

namespace sgtest {


struct Pos {
  int line = 0;
  int col = 0;
};

// 1-based line/column of the `nth` occurrence (0-based) of `needle` in `text`.
Pos posOf(const std::string& text, const std::string& needle, int nth = 0) {
  size_t at = text.find(needle);
  for (int i = 0; i < nth && at != std::string::npos; ++i) at = text.find(needle, at + 1);
  if (at == std::string::npos) {
    ADD_FAILURE() << "test bug: '" << needle << "' not found in the test text";
    return {};
  }
  Pos p;
  p.line = 1;
  size_t lineStart = 0;
  for (size_t i = 0; i < at; ++i)
    if (text[i] == '\n') {
      ++p.line;
      lineStart = i + 1;
    }
  p.col = static_cast<int>(at - lineStart) + 1;
  return p;
}

std::string readText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}


}  // namespace sgtest

#define EXPECT_LOC(diag, file_, line_, col_)                     \
  do {                                                           \
    const sg::Diagnostic& d_ = (diag);                           \
    EXPECT_EQ(d_.loc.file, (file_)) << sg::formatDiagnostic(d_); \
    EXPECT_EQ(d_.loc.line, (line_)) << sg::formatDiagnostic(d_); \
    EXPECT_EQ(d_.loc.col, (col_)) << sg::formatDiagnostic(d_);   \
  } while (0)

#define EXPECT_MSG(diag, phrase)                                                   \
  EXPECT_NE((diag).message.find(phrase), std::string::npos) << "message lacks '" \
                                                             << (phrase) << "': " << sg::formatDiagnostic(diag)

namespace {

using namespace sgtest;

const std::string kSrc = SG_SOURCE_DIR;
const std::string kDawnRig = kSrc + "/examples/dawn/face.rig.yaml";
const std::string kDawnFrag = kSrc + "/examples/dawn/face.frag";
const std::string kDawnRules = kSrc + "/examples/dawn/rules.yaml";

// ---------------------------------------------------------------------------------------
// Rig loader
// ---------------------------------------------------------------------------------------

const sg::RigAttribute* findAttr(const sg::Rig& r, const std::string& name) {
  for (const auto& a : r.attributes)
    if (a.name == name) return &a;
  return nullptr;
}
const sg::RigUniform* findUniform(const sg::Rig& r, const std::string& name) {
  for (const auto& u : r.uniforms)
    if (u.name == name) return &u;
  return nullptr;
}

TEST(RigLoader, DawnFaceParameters) {
  sg::Rig rig = sg::loadRigFile(kDawnRig);
  EXPECT_EQ(rig.name, "dawn-face");
  EXPECT_EQ(rig.file, kDawnRig);
  EXPECT_EQ(rig.param("bones"), 98);
  EXPECT_EQ(rig.param("influences"), 4);
  EXPECT_EQ(rig.param("morph_targets"), 5);
  EXPECT_EQ(rig.morphTargets(), 5);
  EXPECT_EQ(rig.param("no_such_param", -7), -7);
  EXPECT_EQ(rig.morphedAttributes, (std::vector<std::string>{"position", "normal"}));
  // Parameter locations point at the values.
  std::string text = readText(kDawnRig);
  Pos bones = posOf(text, "bones: 98");
  bones.col += 7;
  ASSERT_TRUE(rig.paramLocs.count("bones"));
  EXPECT_EQ(rig.paramLocs.at("bones").line, bones.line);
  EXPECT_EQ(rig.paramLocs.at("bones").col, bones.col);
}

TEST(RigLoader, DawnFaceAttributes) {
  sg::Rig rig = sg::loadRigFile(kDawnRig);
  std::string text = readText(kDawnRig);
  ASSERT_EQ(rig.attributes.size(), 8u);
  std::vector<std::string> names;
  for (const auto& a : rig.attributes) names.push_back(a.name);
  EXPECT_EQ(names, (std::vector<std::string>{"coord", "normal", "tangent", "coord_morph", "normal_morph", "bone_weight",
                                             "bone_index", "skin_uvst"}));

  const sg::RigAttribute* coord = findAttr(rig, "coord");
  ASSERT_TRUE(coord);
  EXPECT_EQ(coord->format, sg::VertexFormat::Float32x3);
  EXPECT_EQ(coord->shaderType, sg::Type::Vec3);
  EXPECT_FALSE(coord->perMorphTarget);
  ASSERT_EQ(coord->provides.size(), 1u);
  EXPECT_EQ(coord->provides[0].semantic, "vertex.position");
  EXPECT_EQ(coord->provides[0].swizzle, "");
  Pos cp = posOf(text, "  coord:");
  EXPECT_EQ(coord->loc.file, kDawnRig);
  EXPECT_EQ(coord->loc.line, cp.line);
  EXPECT_EQ(coord->loc.col, cp.col + 2);

  const sg::RigAttribute* normal = findAttr(rig, "normal");
  ASSERT_TRUE(normal);
  EXPECT_EQ(normal->format, sg::VertexFormat::Float32x4);
  EXPECT_EQ(normal->shaderType, sg::Type::Vec4);
  ASSERT_EQ(normal->provides.size(), 2u);
  EXPECT_EQ(normal->provides[0].semantic, "vertex.normal");
  EXPECT_EQ(normal->provides[0].swizzle, "xyz");
  EXPECT_EQ(normal->provides[1].semantic, "vertex.occlusion");
  EXPECT_EQ(normal->provides[1].swizzle, "w");

  const sg::RigAttribute* nm = findAttr(rig, "normal_morph");
  ASSERT_TRUE(nm);
  EXPECT_TRUE(nm->perMorphTarget);
  ASSERT_EQ(nm->provides.size(), 2u);
  EXPECT_EQ(nm->provides[0].semantic, "morph.normal");
  EXPECT_EQ(nm->provides[1].semantic, "morph.occlusion");
  EXPECT_TRUE(findAttr(rig, "coord_morph")->perMorphTarget);

  const sg::RigAttribute* bi = findAttr(rig, "bone_index");
  ASSERT_TRUE(bi);
  EXPECT_EQ(bi->format, sg::VertexFormat::Uint8x4);
  EXPECT_EQ(bi->shaderType, sg::Type::UVec4);  // uint8x4 is read as uvec4
  EXPECT_EQ(bi->provides[0].semantic, "skin.joints[0]");
  EXPECT_EQ(findAttr(rig, "bone_weight")->provides[0].semantic, "skin.weights[0]");

  const sg::RigAttribute* uv = findAttr(rig, "skin_uvst");
  ASSERT_TRUE(uv);
  ASSERT_EQ(uv->provides.size(), 2u);
  EXPECT_EQ(uv->provides[0].semantic, "vertex.texcoord0");
  EXPECT_EQ(uv->provides[0].swizzle, "xy");
  EXPECT_EQ(uv->provides[1].semantic, "vertex.texcoord1");
  EXPECT_EQ(uv->provides[1].swizzle, "zw");
}

TEST(RigLoader, DawnFaceUniforms) {
  sg::Rig rig = sg::loadRigFile(kDawnRig);
  ASSERT_EQ(rig.uniforms.size(), 6u);
  const sg::RigUniform* bones = findUniform(rig, "bone_xf");
  ASSERT_TRUE(bones);
  EXPECT_EQ(bones->type, sg::Type::Mat4);
  EXPECT_EQ(bones->semantic, "skin.bones");
  EXPECT_EQ(bones->arraySizeParam, "bones");
  EXPECT_EQ(bones->arraySize, 98);
  const sg::RigUniform* mw = findUniform(rig, "morph_weight");
  ASSERT_TRUE(mw);
  EXPECT_EQ(mw->type, sg::Type::Float);
  EXPECT_EQ(mw->semantic, "morph.weights");
  EXPECT_EQ(mw->arraySize, 5);
  const sg::RigUniform* cam = findUniform(rig, "global_cam_pos");
  ASSERT_TRUE(cam);
  EXPECT_EQ(cam->type, sg::Type::Vec3);
  EXPECT_EQ(cam->semantic, "camera.position");
  EXPECT_EQ(cam->arraySize, 0);
  EXPECT_TRUE(cam->arraySizeParam.empty());
  EXPECT_EQ(findUniform(rig, "view_xf")->semantic, "camera.view");
  EXPECT_EQ(findUniform(rig, "proj_xf")->semantic, "camera.projection");
  EXPECT_EQ(findUniform(rig, "dapple_xf")->semantic, "dapple.matrix");
}

// What the device reads back from each stored format, against the Vulkan spec's
// conversions worked by hand ("Fixed-Point Data Conversions": unorm c / (2^b - 1), snorm
// max(c / (2^(b-1) - 1), -1), round to nearest; binary16 to the nearest, ties away from 0).
TEST(VertexFormats, StoredValuesFollowTheVulkanConversions) {
  using sg::VertexFormat;
  using sg::storedValue;
  EXPECT_FLOAT_EQ(storedValue(VertexFormat::Unorm8x4, 0, 0.5f), 128.0f / 255.0f);
  EXPECT_FLOAT_EQ(storedValue(VertexFormat::Unorm8x2, 1, 1.7f), 1.0f);  // clamped
  EXPECT_FLOAT_EQ(storedValue(VertexFormat::Unorm16x2, 0, 0.25f), 16384.0f / 65535.0f);
  EXPECT_FLOAT_EQ(storedValue(VertexFormat::Snorm8x4, 0, -1.0f), -1.0f);
  EXPECT_FLOAT_EQ(storedValue(VertexFormat::Snorm8x4, 2, -0.5f), -64.0f / 127.0f);  // -63.5 rounds away from 0
  EXPECT_FLOAT_EQ(storedValue(VertexFormat::Snorm8x2, 1, 0.3f), 38.0f / 127.0f);    // 38.1
  EXPECT_FLOAT_EQ(storedValue(VertexFormat::Snorm16x2, 0, -0.3f), -9830.0f / 32767.0f);  // -9830.1
  EXPECT_FLOAT_EQ(storedValue(VertexFormat::Snorm16x4, 3, -3.0f), -1.0f);
  // 10-10-10-2: x, y, z in 10 bits, w in 2.
  EXPECT_FLOAT_EQ(storedValue(VertexFormat::Unorm10_10_10_2, 0, 0.5f), 512.0f / 1023.0f);
  EXPECT_FLOAT_EQ(storedValue(VertexFormat::Unorm10_10_10_2, 3, 0.5f), 2.0f / 3.0f);  // 1.5 -> 2 of 3
  EXPECT_FLOAT_EQ(storedValue(VertexFormat::Snorm10_10_10_2, 1, 0.5f), 256.0f / 511.0f);  // 255.5 -> 256
  EXPECT_FLOAT_EQ(storedValue(VertexFormat::Snorm10_10_10_2, 3, -0.4f), 0.0f);  // 2-bit snorm: -1, 0, 1
  EXPECT_FLOAT_EQ(storedValue(VertexFormat::Snorm10_10_10_2, 3, -0.6f), -1.0f);
  // binary16 (10 fraction bits): 0.1 is 0x2E66 = 1638 / 16384; to the nearest, a tie (1 + 2^-11,
  // halfway between 1 and 1 + 2^-10) away from zero, as GLM's packHalf1x16 rounds.
  EXPECT_FLOAT_EQ(storedValue(VertexFormat::Float16x2, 0, 0.1f), 1638.0f / 16384.0f);
  EXPECT_FLOAT_EQ(storedValue(VertexFormat::Float16x4, 1, 1.0f + 0x1p-12f), 1.0f);
  EXPECT_FLOAT_EQ(storedValue(VertexFormat::Float16x4, 1, 1.0f + 0x1p-11f), 1.0f + 0x1p-10f);
  EXPECT_FLOAT_EQ(storedValue(VertexFormat::Float16x4, 2, -1.0f - 3 * 0x1p-12f), -1.0f - 0x1p-10f);
  EXPECT_EQ(storedValue(VertexFormat::Float16x2, 1, 1e5f), std::numeric_limits<float>::infinity());
  EXPECT_FLOAT_EQ(storedValue(VertexFormat::Uint8x2, 0, 300.0f), 255.0f);
  EXPECT_FLOAT_EQ(storedValue(VertexFormat::Uint16x2, 1, 2.5f), 3.0f);
  EXPECT_FLOAT_EQ(storedValue(VertexFormat::Float32x3, 2, 0.1f), 0.1f);
  // NaN stores as 0 in a fixed-point format, never as an undefined integer conversion.
  EXPECT_FLOAT_EQ(storedValue(VertexFormat::Snorm8x4, 0, std::nanf("")), 0.0f);
}

// The bytes of one element, as Vulkan reads A2B10G10R10 (one little-endian word, x in the
// low bits) and the byte-per-component formats.
TEST(VertexFormats, ElementBytes) {
  uint8_t b[16] = {};
  const float xyzw[4] = {1.0f, 0.0f, 0.0f, 1.0f};
  sg::encodeElement(sg::VertexFormat::Unorm10_10_10_2, xyzw, b);
  uint32_t word = 0;
  std::memcpy(&word, b, 4);
  EXPECT_EQ(word, 0xC00003FFu);
  const float neg[4] = {-1.0f, 0.0f, 1.0f, -1.0f};
  sg::encodeElement(sg::VertexFormat::Snorm10_10_10_2, neg, b);
  std::memcpy(&word, b, 4);
  // x = -511 (0x201 in 10 bits), z = 511 at bit 20, w = -1 (0b11) at bit 30.
  EXPECT_EQ(word, 0x201u | (0x1FFu << 20) | (0x3u << 30));
  const float s8[2] = {-0.5f, 1.0f};
  sg::encodeElement(sg::VertexFormat::Snorm8x2, s8, b);
  EXPECT_EQ(b[0], 0xC0);  // -64
  EXPECT_EQ(b[1], 0x7F);
  const float h[2] = {1.0f, -2.0f};
  sg::encodeElement(sg::VertexFormat::Float16x2, h, b);
  EXPECT_EQ(b[0] | (b[1] << 8), 0x3C00);
  EXPECT_EQ(b[2] | (b[3] << 8), 0xC000);
}

TEST(RigLoader, Formats) {
  struct F {
    const char* name;
    sg::VertexFormat f;
    int comps, bytes;
    bool integer;
  };
  for (const F& f : {F{"float32", sg::VertexFormat::Float32x1, 1, 4, false},
                     F{"float32x2", sg::VertexFormat::Float32x2, 2, 8, false},
                     F{"float32x3", sg::VertexFormat::Float32x3, 3, 12, false},
                     F{"float32x4", sg::VertexFormat::Float32x4, 4, 16, false},
                     F{"unorm8x4", sg::VertexFormat::Unorm8x4, 4, 4, false},
                     F{"uint8x4", sg::VertexFormat::Uint8x4, 4, 4, true},
                     F{"unorm16x4", sg::VertexFormat::Unorm16x4, 4, 8, false},
                     F{"uint16x4", sg::VertexFormat::Uint16x4, 4, 8, true},
                     F{"uint32x4", sg::VertexFormat::Uint32x4, 4, 16, true},
                     F{"float16x2", sg::VertexFormat::Float16x2, 2, 4, false},
                     F{"float16x4", sg::VertexFormat::Float16x4, 4, 8, false},
                     F{"snorm8x2", sg::VertexFormat::Snorm8x2, 2, 2, false},
                     F{"snorm8x4", sg::VertexFormat::Snorm8x4, 4, 4, false},
                     F{"snorm16x2", sg::VertexFormat::Snorm16x2, 2, 4, false},
                     F{"snorm16x4", sg::VertexFormat::Snorm16x4, 4, 8, false},
                     F{"unorm8x2", sg::VertexFormat::Unorm8x2, 2, 2, false},
                     F{"unorm16x2", sg::VertexFormat::Unorm16x2, 2, 4, false},
                     F{"unorm10-10-10-2", sg::VertexFormat::Unorm10_10_10_2, 4, 4, false},
                     F{"snorm10-10-10-2", sg::VertexFormat::Snorm10_10_10_2, 4, 4, false},
                     F{"uint8x2", sg::VertexFormat::Uint8x2, 2, 2, true},
                     F{"uint16x2", sg::VertexFormat::Uint16x2, 2, 4, true},
                     F{"uint32", sg::VertexFormat::Uint32x1, 1, 4, true},
                     F{"uint32x2", sg::VertexFormat::Uint32x2, 2, 8, true}}) {
    sg::VertexFormat out{};
    ASSERT_TRUE(sg::parseFormat(f.name, out)) << f.name;
    EXPECT_EQ(out, f.f) << f.name;
    EXPECT_STREQ(sg::formatName(out), f.name);
    EXPECT_EQ(sg::formatComponents(out), f.comps) << f.name;
    EXPECT_EQ(sg::formatBytes(out), f.bytes) << f.name;
    EXPECT_EQ(sg::formatIsInteger(out), f.integer) << f.name;
  }
  sg::VertexFormat out{};
  EXPECT_FALSE(sg::parseFormat("float64x3", out));
  // Shader types follow the format: unorm reads as vec4, uint16x4 as uvec4.
  sg::Rig rig = sg::loadRigText(
      "rig: t\n"
      "attributes:\n"
      "  c: { format: unorm8x4, provides: vertex.color0 }\n"
      "  j: { format: uint16x4, provides: \"skin.joints[0]\" }\n"
      "  s: { format: float32, provides: vertex.occlusion }\n",
      "t.rig.yaml");
  EXPECT_EQ(rig.attributes[0].shaderType, sg::Type::Vec4);
  EXPECT_EQ(rig.attributes[1].shaderType, sg::Type::UVec4);
  EXPECT_EQ(rig.attributes[2].shaderType, sg::Type::Float);
}

// --set (rigWithParameters) refuses a parameter the rig does not have (a typo), except
// uniform_scale, which rig-format.md documents as optional with a default of 0.
TEST(RigLoader, SetReachesTheOptionalUniformScaleButNoUnknownParameter) {
  const sg::Rig rig = sg::loadRigText(
      "rig: t\n"
      "deformers: { bones: 2, influences: 1 }\n"
      "attributes:\n"
      "  p: { format: float32x3, provides: vertex.position }\n"
      "  j: { format: uint8x4, provides: \"skin.joints[0]\" }\n",
      "t.rig.yaml");
  EXPECT_EQ(rig.param("uniform_scale"), 0);
  EXPECT_EQ(sg::rigWithParameters(rig, {{"uniform_scale", 1}}, sg::SourceLoc{}).param("uniform_scale"), 1);
  auto d = errorOf([&] { sg::rigWithParameters(rig, {{"uniform_scales", 1}}, sg::SourceLoc{}); });
  EXPECT_MSG(d, "rig 't' has no deformer parameter 'uniform_scales' to set");
}

// An unsigned normalized format clamps a normal's negative components to 0 (Vulkan's unorm
// conversion): the loader warns at the attribute; snorm, and unorm colours, get no warning.
TEST(RigLoader, AnUnsignedFormatForASignedValueIsWarned) {
  const std::string text =
      "rig: t\n"
      "attributes:\n"
      "  p: { format: float32x3, provides: vertex.position }\n"
      "  n: { format: unorm8x4, provides: { vertex.normal: xyz } }\n"
      "  t: { format: snorm8x4, provides: { vertex.tangent: xyz, vertex.handedness: w } }\n"
      "  c: { format: unorm8x4, provides: vertex.color0 }\n";
  const sg::Rig rig = sg::loadRigText(text, "t.rig.yaml");
  ASSERT_EQ(rig.importDiagnostics.size(), 1u);
  const sg::Diagnostic& d = rig.importDiagnostics[0];
  EXPECT_EQ(d.severity, sg::Severity::Warning);
  EXPECT_LOC(d, "t.rig.yaml", 4, 3);
  EXPECT_MSG(d, "attribute 'n' stores vertex.normal as unorm8x4, which clamps negative components to 0");
}

TEST(RigLoader, MalformedYaml) {
  const std::string text =
      "rig: bad\n"
      "deformers:\n"
      "  bones: 4\n"
      "   influences: 2\n";
  auto d = errorOf([&] { sg::loadRigText(text, "bad.rig.yaml"); });
  Pos p = posOf(text, ": 2");  // yaml-cpp: the ':' of the over-indented key is an illegal map value
  EXPECT_LOC(d, "bad.rig.yaml", p.line, p.col);
  EXPECT_MSG(d, "malformed YAML");
  EXPECT_EQ(sg::formatDiagnostic(d), "bad.rig.yaml:4:14: error: " + d.message);
}

// YAML allows document markers only at the start of a line, so they are found without a second
// parse (yaml-cpp's Load drops a second document silently; its LoadAll hung on fuzzed input).
TEST(RigLoader, OneDocumentPerFile) {
  const std::string rig = readText(kSrc + "/tests/bad-input/base/tiny.rig.yaml");
  for (const std::string& text : {"%YAML 1.2\n# a directive, then the one document\n---\n" + rig,
                                  "--- # the marker may carry a comment\n" + rig + "...\n# comments after its end\n\n",
                                  rig + "#---\n  # --- neither is a marker\n"})
    EXPECT_NO_THROW(sg::loadRigText(text, "one.rig.yaml")) << text;
  struct Case {
    std::string text, at, phrase;
  };
  for (const Case& c : {Case{rig + "---\nrig: second\n", "---", "a second YAML document starts here"},
                        Case{"---\n" + rig + "--- \t\n", "--- \t", "a second YAML document starts here"},
                        Case{rig + "...\n---\n", "---", "a second YAML document starts here"},
                        Case{rig + "...\n  rig: after\n", "rig: after", "content after the document's end marker"}}) {
    auto d = errorOf([&] { sg::loadRigText(c.text, "two.rig.yaml"); });
    Pos p = posOf(c.text, c.at);
    EXPECT_LOC(d, "two.rig.yaml", p.line, p.col);
    EXPECT_MSG(d, c.phrase);
  }
}

TEST(RigLoader, UnknownTopLevelKey) {
  const std::string text =
      "rig: bad\n"
      "attributes:\n"
      "  coord: { format: float32x3, provides: vertex.position }\n"
      "unifroms:\n"
      "  x: { type: mat4, semantic: camera.view }\n";
  auto d = errorOf([&] { sg::loadRigText(text, "bad.rig.yaml"); });
  EXPECT_LOC(d, "bad.rig.yaml", 4, 1);
  EXPECT_MSG(d, "unknown key 'unifroms'");
  EXPECT_EQ(sg::formatDiagnostic(d), "bad.rig.yaml:4:1: error: " + d.message);
}

TEST(RigLoader, UnknownFormat) {
  const std::string text =
      "rig: bad\n"
      "attributes:\n"
      "  coord: { format: float32x5, provides: vertex.position }\n";
  auto d = errorOf([&] { sg::loadRigText(text, "bad.rig.yaml"); });
  Pos p = posOf(text, "float32x5");
  EXPECT_LOC(d, "bad.rig.yaml", p.line, p.col);
  EXPECT_MSG(d, "unknown vertex format 'float32x5'");
}

TEST(RigLoader, BadSwizzleLetter) {
  const std::string text =
      "rig: bad\n"
      "attributes:\n"
      "  normal:\n"
      "    format: float32x4\n"
      "    provides: { vertex.normal: xyzq }\n";
  auto d = errorOf([&] { sg::loadRigText(text, "bad.rig.yaml"); });
  Pos p = posOf(text, "xyzq");
  EXPECT_LOC(d, "bad.rig.yaml", p.line, p.col);
  EXPECT_MSG(d, "'xyzq' is not a valid swizzle");
}

TEST(RigLoader, SwizzleBeyondComponents) {
  const std::string text =
      "rig: bad\n"
      "attributes:\n"
      "  normal: { format: float32x3, provides: { vertex.normal: xyz, vertex.occlusion: w } }\n";
  auto d = errorOf([&] { sg::loadRigText(text, "bad.rig.yaml"); });
  Pos p = posOf(text, "w }");
  EXPECT_LOC(d, "bad.rig.yaml", p.line, p.col);
  EXPECT_MSG(d, "3-component");
}

TEST(RigLoader, SemanticProvidedTwice) {
  const std::string text =
      "rig: bad\n"
      "attributes:\n"
      "  coord: { format: float32x3, provides: vertex.position }\n"
      "  pos2:  { format: float32x4, provides: { vertex.position: xyz } }\n";
  auto d = errorOf([&] { sg::loadRigText(text, "bad.rig.yaml"); });
  Pos p = posOf(text, "vertex.position", 1);
  EXPECT_LOC(d, "bad.rig.yaml", p.line, p.col);
  EXPECT_MSG(d, "semantic 'vertex.position' is provided twice");

  // Also across an attribute and a uniform.
  const std::string text2 =
      "rig: bad\n"
      "attributes:\n"
      "  coord: { format: float32x3, provides: vertex.position }\n"
      "uniforms:\n"
      "  cam: { type: vec3, semantic: vertex.position }\n";
  auto d2 = errorOf([&] { sg::loadRigText(text2, "bad.rig.yaml"); });
  Pos p2 = posOf(text2, "vertex.position", 1);
  EXPECT_LOC(d2, "bad.rig.yaml", p2.line, p2.col);
  EXPECT_MSG(d2, "provided twice");
}

TEST(RigLoader, PerTargetWithoutMorphTargets) {
  const std::string text =
      "rig: bad\n"
      "deformers:\n"
      "  morph_targets: 0\n"
      "attributes:\n"
      "  coord: { format: float32x3, provides: vertex.position }\n"
      "  coord_morph: { format: float32x3, per_target: true, provides: morph.position }\n";
  auto d = errorOf([&] { sg::loadRigText(text, "bad.rig.yaml"); });
  Pos p = posOf(text, "coord_morph");
  EXPECT_LOC(d, "bad.rig.yaml", p.line, p.col);
  EXPECT_MSG(d, "morph_targets: 0");
}

TEST(RigLoader, UniformArraySizedByUnknownParameter) {
  const std::string text =
      "rig: bad\n"
      "deformers:\n"
      "  bones: 3\n"
      "attributes:\n"
      "  coord: { format: float32x3, provides: vertex.position }\n"
      "uniforms:\n"
      "  bone_xf: { type: mat4, array: joints, semantic: skin.bones }\n";
  auto d = errorOf([&] { sg::loadRigText(text, "bad.rig.yaml"); });
  Pos p = posOf(text, "joints");
  EXPECT_LOC(d, "bad.rig.yaml", p.line, p.col);
  EXPECT_MSG(d, "array size 'joints' is not a deformer parameter");
}

TEST(RigLoader, MissingRigName) {
  const std::string text =
      "# a rig without its name\n"
      "deformers:\n"
      "  bones: 3\n"
      "attributes:\n"
      "  coord: { format: float32x3, provides: vertex.position }\n";
  auto d = errorOf([&] { sg::loadRigText(text, "bad.rig.yaml"); });
  EXPECT_LOC(d, "bad.rig.yaml", 2, 1);  // the top-level mapping starts at its first key
  EXPECT_MSG(d, "missing 'rig'");
}

TEST(RigLoader, MorphTargetsWithoutDeltaStreams) {
  const std::string text =
      "rig: bad\n"
      "deformers:\n"
      "  morph_targets: 2\n"
      "attributes:\n"
      "  coord: { format: float32x3, provides: vertex.position }\n";
  auto d = errorOf([&] { sg::loadRigText(text, "bad.rig.yaml"); });
  EXPECT_LOC(d, "bad.rig.yaml", 3, 18);
  EXPECT_MSG(d, "no per_target attribute");
}

TEST(Diagnostics, Format) {
  sg::Diagnostic d{sg::Severity::Error, sg::SourceLoc{"a/b.yaml", 12, 7}, "something is wrong"};
  EXPECT_EQ(sg::formatDiagnostic(d), "a/b.yaml:12:7: error: something is wrong");
  d.severity = sg::Severity::Warning;
  EXPECT_EQ(sg::formatDiagnostic(d), "a/b.yaml:12:7: warning: something is wrong");
  d.loc.col = 0;
  EXPECT_EQ(sg::formatDiagnostic(d), "a/b.yaml:12: warning: something is wrong");
  d.loc.line = 0;
  EXPECT_EQ(sg::formatDiagnostic(d), "a/b.yaml: warning: something is wrong");
  sg::InputError e(sg::SourceLoc{"x.frag", 3, 4}, "boom");
  EXPECT_STREQ(e.what(), "x.frag:3:4: error: boom");
}

TEST(Diagnostics, RenderQuotesLineWithCaret) {
  auto dir = freshDir("render");
  auto file = (dir / "r.yaml").string();
  writeText(file, "first line\n  second: line\n");
  sg::Diagnostic d{sg::Severity::Error, sg::SourceLoc{file, 2, 3}, "bad key"};
  EXPECT_EQ(sg::renderDiagnostic(d), file + ":2:3: error: bad key\n    second: line\n    ^");
  std::filesystem::remove_all(dir);
}

// ---------------------------------------------------------------------------------------
// Rules loader
// ---------------------------------------------------------------------------------------

const std::string kGoodRules =
    "# rules for the loader test\n"                                            // 1
    "semantics:\n"                                                             // 2
    "  vertex.position: vec3\n"                                                // 3
    "  morph.position: { type: vec3, count: morph_targets }\n"                 // 4
    "  morph.weights: { type: float, array: morph_targets, doc: weights }\n"   // 5
    "  object.position: vec3\n"                                                // 6
    "  view.a: float\n"                                                        // 7
    "  view.b: float\n"                                                        // 8
    "varyings:\n"                                                              // 9
    "  Packed: [view.a, view.b]\n"                                             // 10
    "  Pos: object.position\n"                                                 // 11
    "rules:\n"                                                                 // 12
    "  - name: object_position_morphed\n"                                      // 13
    "    doc: one multiply-add per target\n"                                   // 14
    "    produces: object.position\n"                                          // 15
    "    needs: [vertex.position, \"morph.position[*]\", morph.weights]\n"     // 16
    "    when: morph_targets > 0 && has(morph.position)\n"                     // 17
    "    cost: 2 * morph_targets + 1\n"                                        // 18
    "    glsl: |\n"                                                            // 19
    "      ${out} = ${vertex.position};\n"                                     // 20
    "      @for i in morph_targets\n"                                          // 21
    "        ${out} += ${morph.weights}[${i}] * ${morph.position[i]};\n"       // 22
    "      @end\n"                                                             // 23
    "  - name: view_a\n"                                                       // 24
    "    produces: view.a\n"                                                   // 25
    "    cost: 1\n"                                                            // 26
    "    glsl: \"${out} = 1.0;\"\n"                                            // 27
    "  - name: view_b\n"                                                       // 28
    "    produces: view.b\n"                                                   // 29
    "    needs: view.a\n"                                                      // 30
    "    cost: auto\n"                                                         // 31
    "    glsl: ${out} = ${view.a} * 2.0;\n";                                   // 32

sg::ExprEnv paramEnv(std::map<std::string, int64_t> params, std::vector<std::string> provided = {}) {
  sg::ExprEnv env;
  env.lookup = [params](const std::string& n, int64_t& v) {
    auto it = params.find(n);
    if (it == params.end()) return false;
    v = it->second;
    return true;
  };
  env.has = [provided](const std::string& s) {
    for (const auto& p : provided)
      if (p == s) return true;
    return false;
  };
  return env;
}

TEST(RulesLoader, GoodFile) {
  sg::RuleSet set;
  sg::loadRulesText(set, kGoodRules, "good.yaml");
  EXPECT_EQ(set.files, std::vector<std::string>{"good.yaml"});

  ASSERT_EQ(set.semantics.size(), 6u);
  const sg::SemanticDecl* mp = set.findSemantic("morph.position");
  ASSERT_TRUE(mp);
  EXPECT_EQ(mp->type, sg::Type::Vec3);
  EXPECT_FALSE(mp->count.empty());
  EXPECT_EQ(mp->count.text(), "morph_targets");
  EXPECT_EQ(mp->count.eval(paramEnv({{"morph_targets", 5}})), 5);
  EXPECT_EQ(mp->loc.line, 4);
  EXPECT_EQ(mp->loc.col, 3);
  const sg::SemanticDecl* mw = set.findSemantic("morph.weights");
  ASSERT_TRUE(mw);
  EXPECT_EQ(mw->type, sg::Type::Float);
  EXPECT_EQ(mw->arrayParam, "morph_targets");
  EXPECT_TRUE(mw->count.empty());
  EXPECT_EQ(mw->doc, "weights");
  EXPECT_TRUE(set.findSemantic("vertex.position")->count.empty());
  EXPECT_EQ(set.findSemantic("view.a")->type, sg::Type::Float);
  EXPECT_EQ(set.findSemantic("no.such"), nullptr);

  ASSERT_EQ(set.varyings.size(), 2u);
  const sg::VaryingMapping* packed = set.findVarying("Packed");
  ASSERT_TRUE(packed);
  EXPECT_EQ(packed->semantics, (std::vector<std::string>{"view.a", "view.b"}));
  EXPECT_EQ(packed->loc.line, 10);
  EXPECT_EQ(packed->loc.col, 3);
  EXPECT_EQ(set.findVarying("Pos")->semantics, std::vector<std::string>{"object.position"});

  ASSERT_EQ(set.rules.size(), 3u);
  const sg::Rule& r = set.rules[0];
  EXPECT_EQ(r.name, "object_position_morphed");
  EXPECT_EQ(r.doc, "one multiply-add per target");
  EXPECT_EQ(r.loc.line, 13);
  EXPECT_EQ(r.loc.col, 11);
  EXPECT_EQ(r.produces, "object.position");
  EXPECT_EQ(r.producesLoc.line, 15);
  EXPECT_EQ(r.producesLoc.col, 15);
  ASSERT_EQ(r.needs.size(), 3u);
  EXPECT_EQ(r.needs[0].name, "vertex.position");
  EXPECT_EQ(r.needs[0].index, "");
  EXPECT_EQ(r.needs[1].name, "morph.position");
  EXPECT_EQ(r.needs[1].index, "*");
  EXPECT_EQ(r.needs[1].loc.line, 16);
  EXPECT_EQ(r.needs[1].loc.col, posOf(kGoodRules, "\"morph.position[*]\"").col);
  EXPECT_EQ(r.needs[2].name, "morph.weights");

  ASSERT_FALSE(r.when.empty());
  EXPECT_EQ(r.when.text(), "morph_targets > 0 && has(morph.position)");
  EXPECT_EQ(r.when.eval(paramEnv({{"morph_targets", 3}}, {"morph.position"})), 1);
  EXPECT_EQ(r.when.eval(paramEnv({{"morph_targets", 3}}, {})), 0);
  EXPECT_EQ(r.when.eval(paramEnv({{"morph_targets", 0}}, {"morph.position"})), 0);
  EXPECT_FALSE(r.costAuto);
  EXPECT_EQ(r.cost.eval(paramEnv({{"morph_targets", 3}})), 7);
  EXPECT_EQ(r.cost.eval(paramEnv({{"morph_targets", 0}})), 1);

  // Block snippet: one TemplateLine per YAML line, located at its first character.
  ASSERT_EQ(r.glsl.size(), 4u);
  EXPECT_EQ(r.glsl[0].text, "${out} = ${vertex.position};");
  EXPECT_EQ(r.glsl[1].text, "@for i in morph_targets");
  EXPECT_EQ(r.glsl[2].text, "  ${out} += ${morph.weights}[${i}] * ${morph.position[i]};");
  EXPECT_EQ(r.glsl[3].text, "@end");
  for (size_t i = 0; i < r.glsl.size(); ++i) {
    EXPECT_EQ(r.glsl[i].loc.file, "good.yaml");
    EXPECT_EQ(r.glsl[i].loc.line, 20 + static_cast<int>(i)) << i;
    EXPECT_EQ(r.glsl[i].loc.col, 7) << i;
  }

  // Quoted one-line snippet: the column is the first character inside the quotes.
  const sg::Rule& a = set.rules[1];
  EXPECT_EQ(a.name, "view_a");
  EXPECT_TRUE(a.needs.empty());
  EXPECT_TRUE(a.when.empty());
  EXPECT_EQ(a.cost.eval(paramEnv({})), 1);
  ASSERT_EQ(a.glsl.size(), 1u);
  EXPECT_EQ(a.glsl[0].text, "${out} = 1.0;");
  EXPECT_EQ(a.glsl[0].loc.line, 27);
  EXPECT_EQ(a.glsl[0].loc.col, posOf(kGoodRules, "${out} = 1.0;").col);

  // Scalar 'needs', 'cost: auto', plain one-line snippet.
  const sg::Rule& b = set.rules[2];
  ASSERT_EQ(b.needs.size(), 1u);
  EXPECT_EQ(b.needs[0].name, "view.a");
  EXPECT_TRUE(b.costAuto);
  ASSERT_EQ(b.glsl.size(), 1u);
  EXPECT_EQ(b.glsl[0].text, "${out} = ${view.a} * 2.0;");
  EXPECT_EQ(b.glsl[0].loc.line, 32);
  EXPECT_EQ(b.glsl[0].loc.col, 11);
}

TEST(RulesLoader, StandardLibraryAndDawnIncludes) {
  sg::RuleSet set = sg::loadRules({kDawnRules});
  // Every include is read once, in load order, with normalised paths.
  ASSERT_GE(set.files.size(), 8u);
  EXPECT_EQ(set.files[0], kDawnRules);
  EXPECT_EQ(set.files[1], kSrc + "/rules/standard.yaml");
  EXPECT_EQ(set.files[2], kSrc + "/rules/vocabulary.yaml");
  std::set<std::string> unique(set.files.begin(), set.files.end());
  EXPECT_EQ(unique.size(), set.files.size());
  EXPECT_TRUE(set.findSemantic("world.normal"));
  EXPECT_EQ(set.findSemantic("skin.joints")->count.eval(paramEnv({{"influences", 5}})), 2);
  EXPECT_EQ(set.findSemantic("skin.bones")->arrayParam, "bones");
  ASSERT_TRUE(set.findVarying("SkinSilhouetteVec"));
  EXPECT_EQ(set.findVarying("SkinSilhouetteVec")->semantics.size(), 4u);
  // A rule from skinning.yaml: its snippet lines (palette_fetch, bone_blend) point into skinning.yaml.
  const sg::Rule* blend = nullptr;
  for (const auto& r : set.rules)
    if (r.name == "skin_matrix_blend") blend = &r;
  ASSERT_TRUE(blend);
  std::string skinning = readText(kSrc + "/rules/skinning.yaml");
  Pos first = posOf(skinning, "mat4 b${k}_ = ${skin.bones}[");
  ASSERT_GT(blend->glsl.size(), 3u);
  EXPECT_EQ(blend->glsl[2].text, "  mat4 b${k}_ = ${skin.bones}[${skin.joints[k / 4]}[${k % 4}]];");
  EXPECT_EQ(blend->glsl[2].loc.file, kSrc + "/rules/skinning.yaml");
  EXPECT_EQ(blend->glsl[2].loc.line, first.line);
  EXPECT_EQ(blend->glsl[2].loc.col, first.col - 2);  // the text keeps the indentation past the block's
  // Its `@use bone_blend()` is expanded at load: the shared snippet's lines, each at its own
  // place in skinning.yaml (one text for every fetch form).
  Pos last = posOf(skinning, "${out} = mat4(c0_, c1_, c2_, c3_);");
  auto line = std::find_if(blend->glsl.begin(), blend->glsl.end(),
                           [](const sg::TemplateLine& l) { return l.text == "${out} = mat4(c0_, c1_, c2_, c3_);"; });
  ASSERT_NE(line, blend->glsl.end());
  EXPECT_EQ(line->loc.line, last.line);
  for (const auto& l : blend->glsl) EXPECT_EQ(l.text.find("@use"), std::string::npos) << l.text;
  // Arguments replace the parameters: the sparse tangent rule's text reads its own sum.
  // (through tangent_orthonormal, which uses orthonormal_tangent_into: both in vocabulary.yaml)
  std::string vocabulary = readText(kSrc + "/rules/vocabulary.yaml");
  for (const auto& r : set.rules) {
    if (r.name != "object_tangent_morphed_sparse_gram_schmidt") continue;
    auto t = std::find_if(r.glsl.begin(), r.glsl.end(), [](const sg::TemplateLine& l) { return l.text == "  vec3 t_ = ${out};"; });
    ASSERT_NE(t, r.glsl.end());
    EXPECT_EQ(t->loc.file, kSrc + "/rules/vocabulary.yaml");
    EXPECT_EQ(t->loc.line, posOf(vocabulary, "vec3 t_ = ${t};").line);
  }
  // Loading the same file twice is a no-op.
  size_t nRules = set.rules.size();
  sg::loadRulesInto(set, kSrc + "/rules/morph.yaml");
  EXPECT_EQ(set.rules.size(), nRules);
}

TEST(RulesLoader, UnknownKeyInRule) {
  const std::string text =
      "semantics:\n"
      "  a.b: float\n"
      "rules:\n"
      "  - name: r1\n"
      "    produce: a.b\n"
      "    cost: 1\n"
      "    glsl: \"${out} = 1.0;\"\n";
  sg::RuleSet set;
  auto d = errorOf([&] { sg::loadRulesText(set, text, "bad.yaml"); });
  EXPECT_LOC(d, "bad.yaml", 5, 5);
  EXPECT_MSG(d, "unknown key 'produce'");
  EXPECT_MSG(d, "produces");  // the expected keys are listed
}

TEST(RulesLoader, MissingCost) {
  const std::string text =
      "semantics:\n"
      "  a.b: float\n"
      "rules:\n"
      "  - name: r1\n"
      "    produces: a.b\n"
      "    glsl: \"${out} = 1.0;\"\n";
  sg::RuleSet set;
  auto d = errorOf([&] { sg::loadRulesText(set, text, "bad.yaml"); });
  EXPECT_LOC(d, "bad.yaml", 4, 5);  // the rule's mapping
  EXPECT_MSG(d, "rule 'r1' has no 'cost'");
}

TEST(RulesLoader, UnknownType) {
  const std::string text =
      "semantics:\n"
      "  a.b: float\n"
      "  a.c: vec5\n"
      "  a.d: { type: float3 }\n";
  sg::RuleSet set;
  auto d = errorOf([&] { sg::loadRulesText(set, text, "bad.yaml"); });
  EXPECT_LOC(d, "bad.yaml", 3, 8);
  EXPECT_MSG(d, "unknown type 'vec5'");

  const std::string text2 = "semantics:\n  a.d: { type: float3 }\n";
  sg::RuleSet set2;
  auto d2 = errorOf([&] { sg::loadRulesText(set2, text2, "bad2.yaml"); });
  EXPECT_LOC(d2, "bad2.yaml", 2, 16);
  EXPECT_MSG(d2, "unknown type 'float3'");
}

TEST(RulesLoader, DuplicateRuleName) {
  const std::string text =
      "semantics:\n"
      "  a.b: float\n"
      "rules:\n"
      "  - name: r1\n"
      "    produces: a.b\n"
      "    cost: 1\n"
      "    glsl: \"${out} = 1.0;\"\n"
      "  - name: r1\n"
      "    produces: a.b\n"
      "    cost: 2\n"
      "    glsl: \"${out} = 2.0;\"\n";
  sg::RuleSet set;
  auto d = errorOf([&] { sg::loadRulesText(set, text, "bad.yaml"); });
  EXPECT_LOC(d, "bad.yaml", 8, 11);
  EXPECT_MSG(d, "rule 'r1' is defined twice (first at bad.yaml:4)");
}

TEST(RulesLoader, DuplicateSemantic) {
  const std::string text =
      "semantics:\n"
      "  a.b: float\n"
      "  a.c: vec3\n"
      "  a.b: vec4\n";
  sg::RuleSet set;
  auto d = errorOf([&] { sg::loadRulesText(set, text, "bad.yaml"); });
  EXPECT_LOC(d, "bad.yaml", 4, 3);
  // Within one mapping the YAML check answers first (yaml-cpp would keep the last silently).
  EXPECT_MSG(d, "duplicate key 'a.b' (first at line 2)");

  // Across files loaded into one set.
  sg::RuleSet two;
  sg::loadRulesText(two, "semantics:\n  a.b: float\n", "one.yaml");
  auto d2 = errorOf([&] { sg::loadRulesText(two, "# second\nsemantics:\n  x.y: vec2\n  a.b: float\n", "two.yaml"); });
  EXPECT_LOC(d2, "two.yaml", 4, 3);
  EXPECT_MSG(d2, "first at one.yaml:2");
}

TEST(RulesLoader, IncludeCycle) {
  auto dir = freshDir("cycle");
  writeText(dir / "a.yaml", "include: [b.yaml]\nsemantics:\n  x.a: float\n");
  writeText(dir / "b.yaml", "# b includes a back\ninclude: [c.yaml, a.yaml]\n");
  writeText(dir / "c.yaml", "semantics:\n  x.c: float\n");
  auto d = errorOf([&] { sg::loadRules({(dir / "a.yaml").string()}); });
  EXPECT_LOC(d, (dir / "b.yaml").string(), 2, 19);
  EXPECT_MSG(d, "include cycle");

  // A file that includes itself.
  writeText(dir / "self.yaml", "include:\n  - ./self.yaml\n");
  auto d2 = errorOf([&] { sg::loadRules({(dir / "self.yaml").string()}); });
  EXPECT_LOC(d2, (dir / "self.yaml").string(), 2, 5);
  EXPECT_MSG(d2, "include cycle");

  // A missing include is located too.
  writeText(dir / "m.yaml", "include: [nope.yaml]\n");
  auto d3 = errorOf([&] { sg::loadRules({(dir / "m.yaml").string()}); });
  EXPECT_LOC(d3, (dir / "m.yaml").string(), 1, 11);
  EXPECT_MSG(d3, "does not exist");
  std::filesystem::remove_all(dir);
}

TEST(RulesLoader, MalformedWhenExpression) {
  const std::string text =
      "semantics:\n"
      "  a.b: float\n"
      "rules:\n"
      "  - name: r1\n"
      "    produces: a.b\n"
      "    when: influences >= && 2\n"
      "    cost: 1\n"
      "    glsl: \"${out} = 1.0;\"\n";
  sg::RuleSet set;
  auto d = errorOf([&] { sg::loadRulesText(set, text, "bad.yaml"); });
  Pos p = posOf(text, "&&");
  EXPECT_LOC(d, "bad.yaml", p.line, p.col);
  EXPECT_MSG(d, "unexpected '&'");

  // Quoted expressions: the column still lands inside the expression.
  const std::string text2 =
      "semantics:\n"
      "  a.b: float\n"
      "rules:\n"
      "  - name: r1\n"
      "    produces: a.b\n"
      "    when: \"influences == 4)\"\n"
      "    cost: 1\n"
      "    glsl: \"${out} = 1.0;\"\n";
  sg::RuleSet set2;
  auto d2 = errorOf([&] { sg::loadRulesText(set2, text2, "bad.yaml"); });
  Pos p2 = posOf(text2, ")\"");
  EXPECT_LOC(d2, "bad.yaml", p2.line, p2.col);
  EXPECT_MSG(d2, "unexpected ')'");

  // And in the cost.
  const std::string text3 =
      "semantics:\n"
      "  a.b: float\n"
      "rules:\n"
      "  - name: r1\n"
      "    produces: a.b\n"
      "    cost: 4 * (influences + 1\n"
      "    glsl: \"${out} = 1.0;\"\n";
  sg::RuleSet set3;
  auto d3 = errorOf([&] { sg::loadRulesText(set3, text3, "bad.yaml"); });
  EXPECT_EQ(d3.loc.line, 6);
  EXPECT_EQ(d3.loc.col, 11 + 19);  // just past the end of "4 * (influences + 1" (value at column 11)
  EXPECT_MSG(d3, "expected ')'");
}

TEST(RulesLoader, OtherShapeErrors) {
  sg::RuleSet set;
  auto d = errorOf([&] { sg::loadRulesText(set, "rules:\n  - name: r1\n    produces: a.b\n    cost: 1\n", "bad.yaml"); });
  EXPECT_LOC(d, "bad.yaml", 2, 5);
  EXPECT_MSG(d, "no 'glsl'");
  sg::RuleSet set2;
  auto d2 = errorOf([&] { sg::loadRulesText(set2, "semantics:\n  a.b: float\nvaryings:\n  X: a.b\n  X: a.b\n", "bad.yaml"); });
  EXPECT_LOC(d2, "bad.yaml", 5, 3);
  EXPECT_MSG(d2, "duplicate key 'X' (first at line 4)");
  sg::RuleSet set3;
  auto d3 = errorOf([&] { sg::loadRulesText(set3, "rules: {}\n", "bad.yaml"); });
  EXPECT_LOC(d3, "bad.yaml", 1, 8);
  EXPECT_MSG(d3, "must be a sequence");
  sg::RuleSet set4;
  auto d4 = errorOf([&] { sg::loadRulesText(set4, "", "empty.yaml"); });
  EXPECT_LOC(d4, "empty.yaml", 1, 1);
  EXPECT_MSG(d4, "empty rules file");
}

// ---------------------------------------------------------------------------------------
// Expressions
// ---------------------------------------------------------------------------------------

int64_t ev(const std::string& text, const sg::ExprEnv& env = paramEnv({})) {
  return sg::Expr::parse(text, sg::SourceLoc{"e.yaml", 1, 1}).eval(env);
}

TEST(Expr, ArithmeticAndPrecedence) {
  EXPECT_EQ(ev("1 + 2 * 3"), 7);
  EXPECT_EQ(ev("(1 + 2) * 3"), 9);
  EXPECT_EQ(ev("10 - 4 - 3"), 3);  // left associative
  EXPECT_EQ(ev("7 / 2"), 3);       // integer division
  EXPECT_EQ(ev("-7 / 2"), -3);     // truncates toward zero
  EXPECT_EQ(ev("7 % 3"), 1);
  EXPECT_EQ(ev("2 * 3 % 4"), 2);
  EXPECT_EQ(ev("-3 + 5"), 2);
  EXPECT_EQ(ev("1 + 2 == 3"), 1);
  EXPECT_EQ(ev("2 < 1 + 2"), 1);
  EXPECT_EQ(ev("3 >= 4"), 0);
  EXPECT_EQ(ev("3 != 4"), 1);
  EXPECT_EQ(ev("  42  "), 42);
  EXPECT_EQ(ev("(influences + 3) / 4", paramEnv({{"influences", 5}})), 2);
  EXPECT_EQ(ev("(influences + 3) / 4", paramEnv({{"influences", 4}})), 1);
  EXPECT_EQ(ev("(influences + 3) / 4", paramEnv({{"influences", 0}})), 0);
}

TEST(Expr, Logic) {
  EXPECT_EQ(ev("1 && 0"), 0);
  EXPECT_EQ(ev("2 && 3"), 1);
  EXPECT_EQ(ev("0 || 2"), 1);
  EXPECT_EQ(ev("0 || 0"), 0);
  EXPECT_EQ(ev("!0"), 1);
  EXPECT_EQ(ev("!5"), 0);
  EXPECT_EQ(ev("!(1 < 2)"), 0);
  EXPECT_EQ(ev("1 || 0 && 0"), 1);  // && binds tighter than ||
  EXPECT_EQ(ev("true && !false"), 1);
  // Short-circuit: the unknown name on the dead side is never evaluated.
  EXPECT_EQ(ev("0 && nosuch"), 0);
  EXPECT_EQ(ev("1 || nosuch"), 1);
}

TEST(Expr, Has) {
  auto env = paramEnv({{"influences", 4}}, {"morph.position", "vertex.normal"});
  EXPECT_EQ(ev("has(morph.position)", env), 1);
  EXPECT_EQ(ev("has(morph.tangent)", env), 0);
  EXPECT_EQ(ev("!has(morph.tangent) && has( vertex.normal )", env), 1);
  EXPECT_EQ(ev("influences >= 2 && has(vertex.normal)", env), 1);
  // Without a has() callback nothing is provided.
  sg::ExprEnv bare;
  EXPECT_EQ(sg::Expr::parse("has(x.y)", {}).eval(bare), 0);
}

TEST(Expr, EmptyExpression) {
  sg::Expr e;
  EXPECT_TRUE(e.empty());
  EXPECT_EQ(e.eval(paramEnv({})), 0);
  EXPECT_FALSE(sg::Expr::parse("1", {}).empty());
}

TEST(Expr, UnknownIdentifierColumn) {
  sg::Expr e = sg::Expr::parse("2 * bones + joints", sg::SourceLoc{"r.yaml", 9, 11});
  auto d = errorOf([&] { e.eval(paramEnv({{"bones", 3}})); });
  EXPECT_LOC(d, "r.yaml", 9, 11 + 12);  // 'joints' is at offset 12
  EXPECT_MSG(d, "unknown name 'joints'");
  EXPECT_EQ(e.eval(paramEnv({{"bones", 3}, {"joints", 1}})), 7);
}

TEST(Expr, DivisionByZero) {
  auto d = errorOf([&] { sg::Expr::parse("8 / (2 - 2)", sg::SourceLoc{"r.yaml", 4, 9}).eval(paramEnv({})); });
  EXPECT_LOC(d, "r.yaml", 4, 9 + 2);  // the '/' operator
  EXPECT_MSG(d, "division by zero");
  auto d2 = errorOf([&] { sg::Expr::parse("n % 0", sg::SourceLoc{"r.yaml", 4, 9}).eval(paramEnv({{"n", 3}})); });
  EXPECT_LOC(d2, "r.yaml", 4, 9 + 2);
  EXPECT_MSG(d2, "division by zero");
}

// A failure no rig can avoid (check's error without a rig): a constant part that is always
// evaluated. A part with a name, or behind && / ||, may be some rig's business.
TEST(Expr, FailsForEveryRig) {
  auto every = [](const std::string& text) {
    return sg::Expr::parse(text, sg::SourceLoc{"r.yaml", 3, 9}).failsForEveryRig();
  };
  auto d = every("bones * (4611686018427387904 * 4)");
  ASSERT_TRUE(d);
  EXPECT_EQ(d->loc.col, 9 + 29);  // the inner '*'
  EXPECT_NE(d->message.find("integer overflow in expression (4611686018427387904 * 4)"), std::string::npos);
  EXPECT_TRUE(every("9223372036854775807 + 1"));
  EXPECT_TRUE(every("bones + 1 / 0"));
  EXPECT_TRUE(every("(1 / 0) && bones"));  // the left side is always evaluated
  EXPECT_FALSE(every("bones * 4611686018427387904 * 4"));  // fine for bones == 0
  EXPECT_FALSE(every("bones > 0 && 1 / 0"));               // only for rigs with bones
  EXPECT_FALSE(every("has(morph.position) || 1 / 0"));
  EXPECT_FALSE(every("0 && 1 / 0"));  // constant, and short-circuited: never fails
  EXPECT_TRUE(every("4611686018427387904 * 2 - 1"));  // 2^63 overflows before the - 1
  EXPECT_FALSE(every("(bones + 3) / 4 * 2 + 1"));
}

TEST(Expr, ParseErrors) {
  auto d = errorOf([&] { sg::Expr::parse("1 +", sg::SourceLoc{"r.yaml", 2, 5}); });
  EXPECT_LOC(d, "r.yaml", 2, 5 + 3);
  EXPECT_MSG(d, "ends too early");
  auto d2 = errorOf([&] { sg::Expr::parse("(1 + 2", sg::SourceLoc{"r.yaml", 2, 5}); });
  EXPECT_LOC(d2, "r.yaml", 2, 5 + 6);
  EXPECT_MSG(d2, "expected ')'");
  auto d3 = errorOf([&] { sg::Expr::parse("1 2", sg::SourceLoc{"r.yaml", 2, 5}); });
  EXPECT_LOC(d3, "r.yaml", 2, 5 + 2);
  EXPECT_MSG(d3, "unexpected '2'");
  auto d4 = errorOf([&] { sg::Expr::parse("has x", sg::SourceLoc{"r.yaml", 2, 5}); });
  EXPECT_MSG(d4, "expected '(' after has");
  auto d5 = errorOf([&] { sg::Expr::parse("99999999999999999999", sg::SourceLoc{"r.yaml", 2, 5}); });
  EXPECT_MSG(d5, "too large");
}

// ---------------------------------------------------------------------------------------
// Snippet expansion
// ---------------------------------------------------------------------------------------

// Template lines as if they sat at lines 10.. of t.yaml, column 7.
std::vector<sg::TemplateLine> tmpl(const std::vector<std::string>& lines, int firstLine = 10, int col = 7) {
  std::vector<sg::TemplateLine> out;
  for (size_t i = 0; i < lines.size(); ++i)
    out.push_back(sg::TemplateLine{lines[i], sg::SourceLoc{"t.yaml", firstLine + static_cast<int>(i), col}});
  return out;
}

sg::SnippetContext snippetCtx(std::map<std::string, int64_t> params = {{"morph_targets", 3}, {"influences", 2}}) {
  sg::SnippetContext ctx;
  ctx.rigEnv = paramEnv(params, {"morph.position"});
  ctx.outText = "OUT";
  ctx.semantic = [](const std::string& name, int64_t idx, const sg::SourceLoc& at, std::string& text) {
    if (name == "vertex.position" && idx < 0) {
      text = "VP";
      return true;
    }
    if (name == "morph.position" && idx >= 0) {
      if (idx >= 3) throw sg::InputError(at, "index out of range");
      text = "MP" + std::to_string(idx);
      return true;
    }
    if (name == "morph.weights" && idx < 0) {
      text = "W";
      return true;
    }
    return false;
  };
  return ctx;
}

std::vector<std::string> texts(const std::vector<sg::ExpandedLine>& v) {
  std::vector<std::string> out;
  for (const auto& l : v) out.push_back(l.text);
  return out;
}

TEST(Snippet, PlainSubstitution) {
  auto out = sg::expandSnippet(tmpl({"${out} = ${vertex.position} * ${ 2 * morph_targets };"}), snippetCtx());
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].text, "OUT = VP * 6;");
  EXPECT_EQ(out[0].loc.file, "t.yaml");
  EXPECT_EQ(out[0].loc.line, 10);
  EXPECT_EQ(out[0].loc.col, 7);
}

TEST(Snippet, ForUnrollsWithIndexAndIndexedSemantic) {
  auto out = sg::expandSnippet(tmpl({"${out} = ${vertex.position};", "@for i in morph_targets",
                                     "  ${out} += ${morph.weights}[${i}] * ${morph.position[i]};", "@end",
                                     "${out} *= 2.0;"}),
                               snippetCtx());
  EXPECT_EQ(texts(out), (std::vector<std::string>{"OUT = VP;", "  OUT += W[0] * MP0;", "  OUT += W[1] * MP1;",
                                                  "  OUT += W[2] * MP2;", "OUT *= 2.0;"}));
  // Each unrolled line keeps the location of its template line.
  std::vector<int> lines;
  for (const auto& l : out) lines.push_back(l.loc.line);
  EXPECT_EQ(lines, (std::vector<int>{10, 12, 12, 12, 14}));
}

TEST(Snippet, IndexExpressions) {
  auto out = sg::expandSnippet(tmpl({"@for k in influences", "x = ${morph.position[(k + 1) % 3]} + ${(k + 1) / 2};",
                                     "@end"}),
                               snippetCtx());
  EXPECT_EQ(texts(out), (std::vector<std::string>{"x = MP1 + 0;", "x = MP2 + 1;"}));
}

TEST(Snippet, NestedFor) {
  auto out = sg::expandSnippet(tmpl({"@for i in 3", "  @for j in i", "    p${i}${j};", "  @end", "@end"}), snippetCtx());
  EXPECT_EQ(texts(out), (std::vector<std::string>{"    p10;", "    p20;", "    p21;"}));
  // Inner loop variables shadow outer ones; the outer one is back after @end.
  auto out2 = sg::expandSnippet(tmpl({"@for i in 2", "@for i in 1", "a${i};", "@end", "b${i};", "@end"}), snippetCtx());
  EXPECT_EQ(texts(out2), (std::vector<std::string>{"a0;", "b0;", "a0;", "b1;"}));
}

TEST(Snippet, ZeroIterations) {
  auto out = sg::expandSnippet(tmpl({"a;", "@for i in morph_targets", "${morph.position[i]};", "@end", "b;"}),
                               snippetCtx({{"morph_targets", 0}}));
  EXPECT_EQ(texts(out), (std::vector<std::string>{"a;", "b;"}));
}

TEST(Snippet, IfElse) {
  std::vector<std::string> t{"@if morph_targets > 2", "A${morph_targets};", "@else", "B;", "@end", "C;"};
  EXPECT_EQ(texts(sg::expandSnippet(tmpl(t), snippetCtx({{"morph_targets", 3}}))),
            (std::vector<std::string>{"A3;", "C;"}));
  EXPECT_EQ(texts(sg::expandSnippet(tmpl(t), snippetCtx({{"morph_targets", 2}}))),
            (std::vector<std::string>{"B;", "C;"}));
  // Without @else; has() conditions; nested in @for.
  std::vector<std::string> t2{"@for i in 3", "@if i != 1 && has(morph.position)", "v${i};", "@end", "@end"};
  EXPECT_EQ(texts(sg::expandSnippet(tmpl(t2), snippetCtx())), (std::vector<std::string>{"v0;", "v2;"}));
  // The branch not taken is not expanded (it may use names that do not exist).
  std::vector<std::string> t3{"@if 0", "${nosuch} ${no.such.semantic};", "@for i in nosuch", "@end", "@end", "ok;"};
  EXPECT_EQ(texts(sg::expandSnippet(tmpl(t3), snippetCtx())), (std::vector<std::string>{"ok;"}));
}

TEST(Snippet, UnknownDirective) {
  auto d = errorOf([&] { sg::expandSnippet(tmpl({"a;", "  @foreach i in 3", "@end"}), snippetCtx()); });
  EXPECT_LOC(d, "t.yaml", 11, 7 + 2);
  EXPECT_MSG(d, "unknown directive '@foreach'");
}

TEST(Snippet, MissingEnd) {
  auto d = errorOf([&] { sg::expandSnippet(tmpl({"a;", "b;", "@for i in 2", "c${i};"}), snippetCtx()); });
  EXPECT_LOC(d, "t.yaml", 12, 7);
  EXPECT_MSG(d, "'@for' without '@end'");
  auto d2 = errorOf([&] { sg::expandSnippet(tmpl({"  @if 1", "c;", "@else", "d;"}), snippetCtx()); });
  EXPECT_LOC(d2, "t.yaml", 10, 9);
  EXPECT_MSG(d2, "'@if' without '@end'");
  auto d3 = errorOf([&] { sg::expandSnippet(tmpl({"a;", "@end"}), snippetCtx()); });
  EXPECT_LOC(d3, "t.yaml", 11, 7);
  EXPECT_MSG(d3, "without a matching");
  auto d4 = errorOf([&] { sg::expandSnippet(tmpl({"@for i in 2", "a;", "@else", "@end"}), snippetCtx()); });
  EXPECT_LOC(d4, "t.yaml", 12, 7);
  EXPECT_MSG(d4, "'@else' inside '@for'");
}

TEST(Snippet, ExpressionErrorsAreLocatedInsideTheLine) {
  // Unknown name in ${...}: the column of the name.
  auto d = errorOf([&] { sg::expandSnippet(tmpl({"x;", "y = ${ bones + 1 };"}), snippetCtx()); });
  EXPECT_LOC(d, "t.yaml", 11, 7 + 7);
  EXPECT_MSG(d, "unknown name 'bones'");
  // Unknown name in the @for count.
  auto d2 = errorOf([&] { sg::expandSnippet(tmpl({"@for i in targets", "@end"}), snippetCtx()); });
  EXPECT_LOC(d2, "t.yaml", 10, 7 + 10);
  EXPECT_MSG(d2, "unknown name 'targets'");
  // Malformed loop header.
  auto d3 = errorOf([&] { sg::expandSnippet(tmpl({"@for i 3", "@end"}), snippetCtx()); });
  EXPECT_LOC(d3, "t.yaml", 10, 7);
  EXPECT_MSG(d3, "expected '@for VAR in COUNT'");
  // Unterminated ${.
  auto d4 = errorOf([&] { sg::expandSnippet(tmpl({"a = ${out;"}), snippetCtx()); });
  EXPECT_LOC(d4, "t.yaml", 10, 7 + 4);
  EXPECT_MSG(d4, "unterminated");
  // The semantic callback's own errors (index out of range) come through located.
  auto d5 = errorOf([&] { sg::expandSnippet(tmpl({"@for i in 4", "  m = ${morph.position[i]};", "@end"}), snippetCtx()); });
  EXPECT_LOC(d5, "t.yaml", 11, 7 + 8);
  EXPECT_MSG(d5, "index out of range");
  // Unknown dotted name.
  auto d6 = errorOf([&] { sg::expandSnippet(tmpl({"m = ${world.nope};"}), snippetCtx()); });
  EXPECT_LOC(d6, "t.yaml", 10, 7 + 6);
  EXPECT_MSG(d6, "unknown semantic 'world.nope'");
}

// ---------------------------------------------------------------------------------------
// Fragment interface
// ---------------------------------------------------------------------------------------

TEST(Fragment, ReflectDawnFace) {
  sg::FragmentInterface fi = sg::reflectFragmentFile(kDawnFrag);
  EXPECT_EQ(fi.file, kDawnFrag);
  EXPECT_EQ(fi.source, readText(kDawnFrag));
  ASSERT_EQ(fi.inputs.size(), 6u);
  struct E {
    const char* name;
    sg::Type type;
  };
  const E expected[] = {{"WorldTanMatrixX", sg::Type::Vec3}, {"WorldTanMatrixY", sg::Type::Vec3},
                        {"WorldTanMatrixZ", sg::Type::Vec3}, {"WorldEyeDir", sg::Type::Vec3},
                        {"SkinUVST", sg::Type::Vec4},        {"SkinSilhouetteVec", sg::Type::Vec4}};
  std::string src = readText(kDawnFrag);
  for (int i = 0; i < 6; ++i) {
    SCOPED_TRACE(expected[i].name);
    EXPECT_EQ(fi.inputs[i].name, expected[i].name);
    EXPECT_EQ(fi.inputs[i].type, expected[i].type);
    EXPECT_EQ(fi.inputs[i].location, i);
    EXPECT_FALSE(fi.inputs[i].flat);
    Pos p = posOf(src, std::string(" ") + expected[i].name + ";");
    EXPECT_EQ(fi.inputs[i].loc.file, kDawnFrag);
    EXPECT_EQ(fi.inputs[i].loc.line, p.line);
    EXPECT_EQ(fi.inputs[i].loc.col, p.col + 1);
  }
}

TEST(Fragment, SortedByLocationAndFlat) {
  const std::string src =
      "#version 450\n"
      "layout(location = 2) in vec2 B;\n"
      "layout(location = 0) flat in uvec4 A;\n"
      "layout(location = 1) in float C;\n"
      "layout(location = 0) out vec4 color;\n"
      "void main() { color = vec4(vec2(A.xy) + B, C, 1.0); }\n";
  sg::FragmentInterface fi = sg::reflectFragmentSource(src, "s.frag");
  ASSERT_EQ(fi.inputs.size(), 3u);
  EXPECT_EQ(fi.inputs[0].name, "A");
  EXPECT_EQ(fi.inputs[0].type, sg::Type::UVec4);
  EXPECT_TRUE(fi.inputs[0].flat);
  EXPECT_EQ(fi.inputs[0].loc.line, 3);
  EXPECT_EQ(fi.inputs[1].name, "C");
  EXPECT_EQ(fi.inputs[1].type, sg::Type::Float);
  EXPECT_EQ(fi.inputs[2].name, "B");
  EXPECT_EQ(fi.inputs[2].location, 2);
  EXPECT_EQ(fi.inputs[2].loc.line, 2);
  EXPECT_EQ(fi.inputs[2].loc.col, 30);
}

TEST(Fragment, SyntaxErrorIsLocated) {
  const std::string src =
      "#version 450\n"
      "layout(location = 0) in vec3 N;\n"
      "layout(location = 0) out vec4 color;\n"
      "void main() {\n"
      "  color = vec4(N 1.0);\n"
      "}\n";
  auto d = errorOf([&] { sg::reflectFragmentSource(src, "broken.frag"); });
  EXPECT_EQ(d.loc.file, "broken.frag");
  EXPECT_EQ(d.loc.line, 5) << sg::formatDiagnostic(d);
  EXPECT_MSG(d, "syntax error");

  const std::string src2 =
      "#version 450\n"
      "layout(location = 0) in vec3 N;\n"
      "layout(location = 0) out vec4 color;\n"
      "void main() {\n"
      "  color = vec4(N, 1.0);\n"
      "  color.x += undeclared;\n"
      "}\n";
  auto d2 = errorOf([&] { sg::reflectFragmentSource(src2, "broken.frag"); });
  EXPECT_EQ(d2.loc.line, 6) << sg::formatDiagnostic(d2);
  EXPECT_MSG(d2, "undeclared");
}

// Some Windows editors start a UTF-8 file with a byte-order mark; glslang stopped at it
// ("'\xEF' : unexpected token" at line 1). The shader reads as it would without it, with
// line 2's columns unchanged.
TEST(Fragment, AUtf8ByteOrderMarkIsNotGlsl) {
  const std::string src =
      "\xEF\xBB\xBF#version 450\r\n"
      "layout(location = 0) in vec3 N;\r\n"
      "layout(location = 0) out vec4 color;\r\n"
      "void main() { color = vec4(N, 1.0); }\r\n";
  sg::FragmentInterface fi = sg::reflectFragmentSource(src, "bom.frag");
  ASSERT_EQ(fi.inputs.size(), 1u);
  EXPECT_EQ(fi.inputs[0].name, "N");
  EXPECT_EQ(fi.inputs[0].loc.line, 2);
  EXPECT_EQ(fi.inputs[0].loc.col, 30);
  // An error after it is still located in the file's own lines.
  auto d = errorOf([&] { sg::reflectFragmentSource("\xEF\xBB\xBF#version 450\nvoid main() { undeclared; }\n", "bom.frag"); });
  EXPECT_EQ(d.loc.line, 2) << sg::formatDiagnostic(d);
  EXPECT_MSG(d, "undeclared");
}

TEST(Fragment, InputWithoutLocation) {
  const std::string src =
      "#version 450\n"
      "layout(location = 0) in vec3 N;\n"
      "in vec2 uv;\n"
      "layout(location = 0) out vec4 color;\n"
      "void main() { color = vec4(N, uv.x); }\n";
  auto d = errorOf([&] { sg::reflectFragmentSource(src, "noloc.frag"); });
  EXPECT_EQ(d.loc.file, "noloc.frag");
  EXPECT_EQ(d.loc.line, 3) << sg::formatDiagnostic(d);
  EXPECT_MSG(d, "location");
}

TEST(Fragment, SharedLocation) {
  const std::string src =
      "#version 450\n"
      "layout(location = 1) in vec3 N;\n"
      "layout(location = 1) in vec3 T;\n"
      "layout(location = 0) out vec4 color;\n"
      "void main() { color = vec4(N + T, 1.0); }\n";
  try {
    sg::reflectFragmentSource(src, "shared.frag");
    FAIL() << "shared locations must be rejected";
  } catch (const sg::InputError& e) {
    EXPECT_EQ(e.diagnostic().loc.file, "shared.frag");
    EXPECT_GE(e.diagnostic().loc.line, 2);
    EXPECT_LE(e.diagnostic().loc.line, 3);
    EXPECT_NE(std::string(e.what()).find("location"), std::string::npos) << e.what();
  }
}

TEST(Fragment, BindDawnVaryingsThroughRulesMapping) {
  sg::RuleSet rules = sg::loadRules({kDawnRules});
  sg::FragmentInterface fi = sg::reflectFragmentFile(kDawnFrag);
  std::vector<sg::Varying> v = sg::bindVaryings(fi, rules, {});
  ASSERT_EQ(v.size(), 7u);
  EXPECT_EQ(v[0].name, "gl_Position");
  EXPECT_EQ(v[0].location, -1);
  EXPECT_EQ(v[0].type, sg::Type::Vec4);
  EXPECT_EQ(v[0].semantics, std::vector<std::string>{"clip.position"});
  EXPECT_EQ(v[1].name, "WorldTanMatrixX");
  EXPECT_EQ(v[1].semantics, std::vector<std::string>{"frame.row_x"});
  EXPECT_EQ(v[1].location, 0);
  EXPECT_EQ(v[4].name, "WorldEyeDir");
  EXPECT_EQ(v[4].semantics, std::vector<std::string>{"world.eye_dir"});
  EXPECT_EQ(v[5].name, "SkinUVST");
  EXPECT_EQ(v[5].semantics, (std::vector<std::string>{"vertex.texcoord0", "vertex.texcoord1"}));
  EXPECT_EQ(v[6].name, "SkinSilhouetteVec");
  EXPECT_EQ(v[6].type, sg::Type::Vec4);
  EXPECT_EQ(v[6].location, 5);
  EXPECT_EQ(v[6].semantics, (std::vector<std::string>{"object.occlusion", "view.one_minus_ndotv_sq",
                                                       "view.one_minus_ndotv", "dapple.normal_z"}));
  EXPECT_EQ(v[6].loc.line, fi.inputs[5].loc.line);
}

TEST(Fragment, MapOverridePacksScalars) {
  sg::RuleSet rules = sg::loadRules({kDawnRules});
  sg::FragmentInterface fi = sg::reflectFragmentFile(kDawnFrag);
  std::vector<sg::VaryingOverride> ov{
      {"SkinSilhouetteVec", {"view.ndotv", "view.one_minus_ndotv", "object.occlusion", "dapple.normal_z"}},
      {"WorldEyeDir", {"world.normal"}}};
  std::vector<sg::Varying> v = sg::bindVaryings(fi, rules, ov);
  ASSERT_EQ(v.size(), 7u);
  EXPECT_EQ(v[6].semantics, ov[0].semantics);  // the override wins over the rules' mapping
  EXPECT_EQ(v[4].semantics, std::vector<std::string>{"world.normal"});
  EXPECT_EQ(v[1].semantics, std::vector<std::string>{"frame.row_x"});  // others unchanged
}

TEST(Fragment, BindByInputName) {
  sg::RuleSet rules = sg::loadRules({kSrc + "/rules/standard.yaml"});
  const std::string src =
      "#version 450\n"
      "layout(location = 0) in vec3 world_normal;\n"
      "layout(location = 1) in vec3 world_eye_dir;\n"
      "layout(location = 2) in float view_one_minus_ndotv_sq;\n"
      "layout(location = 0) out vec4 color;\n"
      "void main() { color = vec4(world_normal + world_eye_dir, view_one_minus_ndotv_sq); }\n";
  sg::FragmentInterface fi = sg::reflectFragmentSource(src, "names.frag");
  std::vector<sg::Varying> v = sg::bindVaryings(fi, rules, {});
  ASSERT_EQ(v.size(), 4u);
  EXPECT_EQ(v[1].semantics, std::vector<std::string>{"world.normal"});
  EXPECT_EQ(v[2].semantics, std::vector<std::string>{"world.eye_dir"});
  EXPECT_EQ(v[3].semantics, std::vector<std::string>{"view.one_minus_ndotv_sq"});
}

TEST(Fragment, UnknownInputName) {
  sg::RuleSet rules = sg::loadRules({kDawnRules});
  const std::string src =
      "#version 450\n"
      "layout(location = 0) in vec3 WorldEyeDir;\n"
      "layout(location = 1)   in   vec3   Bogus;\n"
      "layout(location = 0) out vec4 color;\n"
      "void main() { color = vec4(WorldEyeDir + Bogus, 1.0); }\n";
  sg::FragmentInterface fi = sg::reflectFragmentSource(src, "bogus.frag");
  auto d = errorOf([&] { sg::bindVaryings(fi, rules, {}); });
  Pos p = posOf(src, "Bogus;");
  EXPECT_LOC(d, "bogus.frag", p.line, p.col);
  EXPECT_MSG(d, "fragment input 'Bogus' does not name a semantic");
  EXPECT_MSG(d, "--map Bogus=");
}

TEST(Fragment, TypeMismatch) {
  sg::RuleSet rules = sg::loadRules({kDawnRules});
  const std::string src =
      "#version 450\n"
      "layout(location = 0) in vec3 Foo;\n"
      "layout(location = 0) out vec4 color;\n"
      "void main() { color = vec4(Foo, 1.0); }\n";
  sg::FragmentInterface fi = sg::reflectFragmentSource(src, "mismatch.frag");
  auto d = errorOf([&] { sg::bindVaryings(fi, rules, {{"Foo", {"view.ndotv"}}}); });
  Pos p = posOf(src, "Foo;");
  EXPECT_LOC(d, "mismatch.frag", p.line, p.col);
  EXPECT_MSG(d, "fragment input 'Foo' is vec3 but semantic 'view.ndotv' is float");
  // Integer vs float kinds also mismatch.
  auto d2 = errorOf([&] { sg::bindVaryings(fi, rules, {{"Foo", {"skin.joints"}}}); });
  EXPECT_EQ(d2.loc.file, "mismatch.frag");
  // Unknown semantic in an override.
  auto d3 = errorOf([&] { sg::bindVaryings(fi, rules, {{"Foo", {"world.nowhere"}}}); });
  EXPECT_LOC(d3, "mismatch.frag", p.line, p.col);
  EXPECT_MSG(d3, "unknown semantic 'world.nowhere'");
  // Matrices cannot be varyings.
  auto d4 = errorOf([&] { sg::bindVaryings(fi, rules, {{"Foo", {"camera.view"}}}); });
  EXPECT_MSG(d4, "cannot be passed as a varying");
}

TEST(Fragment, PackWithWrongComponentCount) {
  sg::RuleSet rules = sg::loadRules({kDawnRules});
  sg::FragmentInterface fi = sg::reflectFragmentFile(kDawnFrag);
  auto d = errorOf(
      [&] { sg::bindVaryings(fi, rules, {{"SkinSilhouetteVec", {"object.occlusion", "view.ndotv", "dapple.normal_z"}}}); });
  EXPECT_LOC(d, kDawnFrag, fi.inputs[5].loc.line, fi.inputs[5].loc.col);
  EXPECT_MSG(d, "is vec4 (4 components) but its packed semantics have 3 components");
  // Too many components through the rules' own mapping.
  sg::RuleSet rules2 = sg::loadRules({kSrc + "/rules/standard.yaml"});
  sg::loadRulesText(rules2, "varyings:\n  SkinUVST: [vertex.texcoord0, vertex.texcoord1, view.ndotv]\n", "map.yaml");
  const std::string src =
      "#version 450\n"
      "layout(location = 4) in vec4 SkinUVST;\n"
      "layout(location = 0) out vec4 color;\n"
      "void main() { color = SkinUVST; }\n";
  sg::FragmentInterface fi2 = sg::reflectFragmentSource(src, "uv.frag");
  auto d2 = errorOf([&] { sg::bindVaryings(fi2, rules2, {}); });
  EXPECT_LOC(d2, "uv.frag", 2, 30);
  EXPECT_MSG(d2, "packed semantics have 5 components");
  EXPECT_MSG(d2, "map.yaml:2");
}

// ---------------------------------------------------------------------------------------
// Problem building
// ---------------------------------------------------------------------------------------

const std::string kTinyRules =
    "semantics:\n"
    "  vertex.position: vec3\n"
    "  vertex.normal: vec3\n"
    "  object.position: vec3\n"
    "  clip.position: vec4\n"
    "rules:\n"
    "  - name: object_position\n"
    "    produces: object.position\n"
    "    needs: [vertex.position]\n"
    "    cost: 1\n"
    "    glsl: |\n"
    "      ${out} = ${vertex.position};\n"
    "  - name: clip\n"
    "    produces: clip.position\n"
    "    needs: [object.position]\n"
    "    cost: 2\n"
    "    glsl: |\n"
    "      ${out} = vec4(${object.position}, 1.0);\n";

TEST(Problem, BuildsFactsActionsAndGoals) {
  sg::RuleSet rules;
  sg::loadRulesText(rules, kTinyRules, "tiny.yaml");
  sg::Rig rig = sg::loadRigText("rig: tiny\nattributes:\n  pos: { format: float32x3, provides: vertex.position }\n",
                                "tiny.rig.yaml");
  std::vector<sg::Varying> v(1);
  v[0].name = "gl_Position";
  v[0].semantics = {"clip.position"};
  sg::Problem p = sg::buildProblem(rig, rules, v);
  ASSERT_EQ(p.facts.size(), 4u);
  int vp = p.findFact("vertex.position");
  ASSERT_GE(vp, 0);
  EXPECT_EQ(p.facts[vp].source, sg::Fact::Source::Attribute);
  EXPECT_EQ(p.facts[vp].rigIndex, 0);
  EXPECT_EQ(p.init, std::vector<int>{vp});
  EXPECT_EQ(p.goals, std::vector<int>{p.findFact("clip.position")});
  ASSERT_EQ(p.actions.size(), 2u);
  EXPECT_EQ(p.actions[0].name, "object_position");
  EXPECT_EQ(p.actions[0].pre, std::vector<int>{vp});
  EXPECT_EQ(p.actions[0].add, p.findFact("object.position"));
  EXPECT_EQ(p.actions[0].cost, 1);
  ASSERT_EQ(p.actions[0].code.size(), 1u);
  EXPECT_EQ(p.actions[0].code[0].text, sg::factRef(p.actions[0].add) + " = " + sg::factRef(vp) + ";");
  EXPECT_EQ(p.actions[0].code[0].loc.line, 12);
  EXPECT_EQ(p.findFact("nope"), -1);
}

TEST(Problem, RigAttributeProvidesUndeclaredSemantic) {
  sg::RuleSet rules;
  sg::loadRulesText(rules, kTinyRules, "tiny.yaml");
  const std::string rigText =
      "rig: tiny\n"
      "attributes:\n"
      "  pos: { format: float32x3, provides: vertex.position }\n"
      "  wiggle: { format: float32x2, provides: vertex.wiggle }\n";
  sg::Rig rig = sg::loadRigText(rigText, "tiny.rig.yaml");
  auto d = errorOf([&] { sg::buildProblem(rig, rules, {}); });
  Pos p = posOf(rigText, "wiggle:");
  EXPECT_LOC(d, "tiny.rig.yaml", p.line, p.col);
  EXPECT_MSG(d, "attribute 'wiggle' provides unknown semantic 'vertex.wiggle'");
}

TEST(Problem, SnippetUsesSemanticNotInNeeds) {
  const std::string text =
      "semantics:\n"
      "  vertex.position: vec3\n"
      "  vertex.normal: vec3\n"
      "  object.position: vec3\n"
      "rules:\n"
      "  - name: sneaky\n"
      "    produces: object.position\n"
      "    needs: [vertex.position]\n"
      "    cost: 1\n"
      "    glsl: |\n"
      "      ${out} = ${vertex.position};\n"
      "      ${out} += 0.1 * ${vertex.normal};\n";
  sg::RuleSet rules;
  sg::loadRulesText(rules, text, "sneaky.yaml");
  sg::Rig rig = sg::loadRigText(
      "rig: r\nattributes:\n  pos: { format: float32x3, provides: vertex.position }\n"
      "  nrm: { format: float32x3, provides: vertex.normal }\n",
      "r.rig.yaml");
  auto d = errorOf([&] { sg::buildProblem(rig, rules, {}); });
  Pos p = posOf(text, "vertex.normal}");
  EXPECT_LOC(d, "sneaky.yaml", p.line, p.col);
  EXPECT_MSG(d, "rule 'sneaky' uses 'vertex.normal' but does not list it in 'needs'");
}

TEST(Problem, NeedsUndeclaredSemantic) {
  const std::string text =
      "semantics:\n"
      "  vertex.position: vec3\n"
      "  object.position: vec3\n"
      "rules:\n"
      "  - name: r\n"
      "    produces: object.position\n"
      "    needs: [vertex.position, vertex.bogus]\n"
      "    cost: 1\n"
      "    glsl: \"${out} = ${vertex.position};\"\n";
  sg::RuleSet rules;
  sg::loadRulesText(rules, text, "n.yaml");
  sg::Rig rig = sg::loadRigText("rig: r\nattributes:\n  pos: { format: float32x3, provides: vertex.position }\n", "r.rig.yaml");
  auto d = errorOf([&] { sg::buildProblem(rig, rules, {}); });
  Pos p = posOf(text, "vertex.bogus");
  EXPECT_LOC(d, "n.yaml", p.line, p.col);
  EXPECT_MSG(d, "unknown semantic 'vertex.bogus'");
}

TEST(Problem, AttributeTypeMismatch) {
  sg::RuleSet rules;
  sg::loadRulesText(rules, kTinyRules, "tiny.yaml");
  const std::string rigText =
      "rig: tiny\n"
      "attributes:\n"
      "  pos: { format: float32x3, provides: vertex.position }\n"
      "  nrm: { format: float32x4, provides: vertex.normal }\n";
  sg::Rig rig = sg::loadRigText(rigText, "tiny.rig.yaml");
  auto d = errorOf([&] { sg::buildProblem(rig, rules, {}); });
  Pos p = posOf(rigText, "nrm:");
  EXPECT_LOC(d, "tiny.rig.yaml", p.line, p.col);
  EXPECT_MSG(d, "'vertex.normal' is vec3 in the rules but the rig provides vec4");
  // The swizzle fixes it.
  sg::Rig ok = sg::loadRigText(
      "rig: tiny\nattributes:\n  pos: { format: float32x3, provides: vertex.position }\n"
      "  nrm: { format: float32x4, provides: { vertex.normal: xyz } }\n",
      "tiny.rig.yaml");
  sg::Problem prob = sg::buildProblem(ok, rules, {});
  int n = prob.findFact("vertex.normal");
  ASSERT_GE(n, 0);
  EXPECT_EQ(prob.facts[n].swizzle, "xyz");
}

TEST(Problem, IntegerAttributeSwizzleWithoutGlslType) {
  // uint8x4 read as uvec4; "xyz" would be a uvec3, which is not a type the generator has.
  // This must be a located input error, not a crash.
  const std::string rules =
      "semantics:\n"
      "  vertex.position: vec3\n"
      "  skin.joints: { type: uvec4, count: 1 }\n";
  sg::RuleSet set;
  sg::loadRulesText(set, rules, "j.yaml");
  const std::string rigText =
      "rig: j\n"
      "attributes:\n"
      "  pos: { format: float32x3, provides: vertex.position }\n"
      "  idx: { format: uint8x4, provides: { \"skin.joints[0]\": xyz } }\n";
  sg::Rig rig = sg::loadRigText(rigText, "j.rig.yaml");
  auto d = errorOf([&] { sg::buildProblem(rig, set, {}); });
  Pos p = posOf(rigText, "idx:");
  EXPECT_LOC(d, "j.rig.yaml", p.line, p.col);
  EXPECT_MSG(d, "skin.joints[0]");
  EXPECT_MSG(d, "swizzle 'xyz'");
}

TEST(Problem, UnknownRequestedSemanticAndWhenSkipping) {
  sg::RuleSet rules = sg::loadRules({kDawnRules});
  sg::Rig rig = sg::loadRigFile(kDawnRig);
  sg::FragmentInterface fi = sg::reflectFragmentFile(kDawnFrag);
  std::vector<sg::Varying> v = sg::bindVaryings(fi, rules, {});
  sg::Problem p = sg::buildProblem(rig, rules, v);
  // Indexed families are unrolled against the rig.
  EXPECT_GE(p.findFact("morph.position[4]"), 0);
  EXPECT_EQ(p.findFact("morph.position[5]"), -1);
  EXPECT_GE(p.findFact("skin.joints[0]"), 0);
  EXPECT_EQ(p.findFact("skin.joints[1]"), -1);
  EXPECT_EQ(p.facts[p.findFact("skin.bones")].arraySize, 98);
  EXPECT_EQ(p.facts[p.findFact("morph.normal[2]")].target, 2);
  EXPECT_EQ(p.facts[p.findFact("morph.occlusion[2]")].swizzle, "w");
  // Goals: clip.position + 3 frame rows + eye dir + 2 texcoords + 4 packed = 11 facts.
  EXPECT_EQ(p.goals.size(), 11u);
  // Rules whose `when` is false for Dawn are reported, not instantiated.
  bool skippedRigid = false;
  for (const auto& [r, why] : p.skippedRules)
    if (rules.rules[r].name == "skin_matrix_rigid") skippedRigid = why.find("when") != std::string::npos;
  EXPECT_TRUE(skippedRigid);
  for (const auto& a : p.actions) EXPECT_NE(a.name, "skin_matrix_rigid");
  // A varying naming an undeclared semantic fails at the varying.
  std::vector<sg::Varying> bad(1);
  bad[0].name = "X";
  bad[0].semantics = {"no.such"};
  bad[0].loc = sg::SourceLoc{"f.frag", 3, 4};
  auto d = errorOf([&] { sg::buildProblem(rig, rules, bad); });
  EXPECT_LOC(d, "f.frag", 3, 4);
  EXPECT_MSG(d, "unknown semantic 'no.such'");
}

// ---------------------------------------------------------------------------------------
// Hostile input (issue 10): every case below crashed, hung, overflowed or was accepted
// before; each asserts the located diagnostic that replaces it.
// ---------------------------------------------------------------------------------------

const std::string kMiniRig = "rig: mini\nattributes:\n  position: { format: float32x3, provides: vertex.position }\n";

TEST(Hostile, DuplicateYamlKeysAreRefused) {
  // yaml-cpp keeps the second `bones` silently; the loader must not.
  const std::string rig = "rig: mini\ndeformers:\n  bones: 2\n  bones: 3\n" + kMiniRig.substr(kMiniRig.find("attributes"));
  auto d = errorOf([&] { sg::loadRigText(rig, "r.yaml"); });
  EXPECT_LOC(d, "r.yaml", 4, 3);
  EXPECT_MSG(d, "duplicate key 'bones' (first at line 3)");
  sg::RuleSet set;
  const std::string rules = "semantics:\n  a.b: vec3\nrules:\n  - name: r\n    produces: a.b\n    cost: 1\n    cost: 2\n"
                            "    glsl: \"${out} = vec3(0);\"\n";
  auto d2 = errorOf([&] { sg::loadRulesText(set, rules, "s.yaml"); });
  EXPECT_LOC(d2, "s.yaml", 7, 5);
  EXPECT_MSG(d2, "duplicate key 'cost'");
}

TEST(Hostile, YamlDepthAndAliasBombsAreBounded) {
  std::string deep = "rig: mini\nattributes:\n";
  for (int i = 1; i < 40; ++i) deep += std::string(2 * i, ' ') + "k" + std::to_string(i) + ":\n";
  auto d = errorOf([&] { sg::loadRigText(deep, "deep.yaml"); });
  EXPECT_MSG(d, "nesting is deeper than 32 levels");
  EXPECT_EQ(d.loc.file, "deep.yaml");
  EXPECT_GT(d.loc.line, 30);
  // 100000 '[': yaml-cpp's own depth guard answers, located, instead of overflowing the stack.
  auto d2 = errorOf([&] { sg::loadRigText("rig: [" + std::string(100000, '[') + "\n", "flow.yaml"); });
  EXPECT_EQ(d2.loc.file, "flow.yaml");
  EXPECT_GE(d2.loc.line, 1);
  EXPECT_MSG(d2, "malformed YAML");
  // 10^9 nodes through aliases in a few hundred bytes.
  std::string bomb = "a: &a [x, x, x, x, x, x, x, x, x, x]\n";
  for (char c = 'b'; c <= 'i'; ++c) {
    char p = static_cast<char>(c - 1);
    bomb += std::string(1, c) + ": &" + c + " [";
    for (int k = 0; k < 10; ++k) bomb += std::string(k ? ", " : "") + "*" + p;
    bomb += "]\n";
  }
  auto d3 = errorOf([&] { sg::loadRigText(bomb + kMiniRig, "bomb.yaml"); });
  EXPECT_MSG(d3, "more than 1048576 nodes");
}

TEST(Hostile, RigNameCannotCarryControlCharacters) {
  auto d = errorOf([&] { sg::loadRigText("rig: \"x\\n#define main oops\"\n" + kMiniRig.substr(kMiniRig.find("attributes")), "r.yaml"); });
  EXPECT_LOC(d, "r.yaml", 1, 6);
  EXPECT_MSG(d, "control character 0x0a");
  auto d2 = errorOf([&] { sg::loadRigText("rig: " + std::string(300, 'n') + "\n" + kMiniRig.substr(kMiniRig.find("attributes")), "r.yaml"); });
  EXPECT_MSG(d2, "1..256 bytes of UTF-8");
}

TEST(Hostile, RigCountsAreLimited) {
  auto d = errorOf([&] { sg::loadRigText("rig: m\ndeformers:\n  morph_targets: 300\n" + kMiniRig.substr(kMiniRig.find("attributes")), "r.yaml"); });
  EXPECT_LOC(d, "r.yaml", 3, 18);
  EXPECT_MSG(d, "at most 256 morph targets");
  std::string many = "rig: m\nattributes:\n";
  for (int i = 0; i < 70; ++i) many += "  a" + std::to_string(i) + ": { format: float32, provides: s.v" + std::to_string(i) + " }\n";
  auto d2 = errorOf([&] { sg::loadRigText(many, "r.yaml"); });
  EXPECT_LOC(d2, "r.yaml", 2 + 65, 3);
  EXPECT_MSG(d2, "more than 64 attributes");
  auto d3 = errorOf([&] { sg::loadRigText("rig: m\ndeformers:\n  bones: 99999999999999999999\n" + kMiniRig.substr(kMiniRig.find("attributes")), "r.yaml"); });
  EXPECT_LOC(d3, "r.yaml", 3, 10);
  EXPECT_MSG(d3, "must be an integer");
}

TEST(Hostile, InputFilesMustBeRegularAndBounded) {
  auto dir = freshDir("files");
  auto d = errorOf([&] { sg::loadRigFile(dir.string()); });
  EXPECT_EQ(d.loc.file, dir.string());
  EXPECT_MSG(d, "is a directory");
  auto d2 = errorOf([&] { sg::loadRigFile("/dev/zero"); });
  EXPECT_MSG(d2, "is a device");
  // A FIFO without a writer: opening it must not block (the test would hang).
  std::string fifo = (dir / "rig.fifo").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  auto d3 = errorOf([&] { sg::loadRigFile(fifo); });
  EXPECT_MSG(d3, "is a FIFO");
  // Oversize (sparse, so the test writes nothing much).
  std::string big = (dir / "big.yaml").string();
  { std::ofstream(big) << "rig: x\n"; }
  std::filesystem::resize_file(big, sg::kMaxInputBytes + 1);
  auto d4 = errorOf([&] { sg::loadRigFile(big); });
  EXPECT_MSG(d4, "larger than the 16777216 byte limit");
  // The diagnostic printer re-reads lines with the same checks: a FIFO is not quoted, and
  // rendering returns (no block).
  sg::Diagnostic onFifo{sg::Severity::Error, sg::SourceLoc{fifo, 3, 1}, "m"};
  EXPECT_EQ(sg::renderDiagnostic(onFifo), fifo + ":3:1: error: m");
  sg::Diagnostic onZero{sg::Severity::Error, sg::SourceLoc{"/dev/zero", 1, 1}, "m"};
  EXPECT_EQ(sg::renderDiagnostic(onZero), "/dev/zero:1:1: error: m");
  std::filesystem::remove_all(dir);
}

TEST(Hostile, DiagnosticsShowControlBytesEscaped) {
  sg::Diagnostic d{sg::Severity::Error, sg::SourceLoc{"a\x1b[2Jb.yaml", 1, 2}, "name 'x\ry'\nsecond line"};
  EXPECT_EQ(sg::formatDiagnostic(d), "a\\x1b[2Jb.yaml:1:2: error: name 'x\\x0dy'\nsecond line");
}

TEST(Hostile, CheckedIntegerArithmetic) {
  auto at = sg::SourceLoc{"e.yaml", 2, 5};
  auto fails = [&](const std::string& text, const std::string& phrase, int col) {
    auto d = errorOf([&] { sg::Expr::parse(text, at).eval(paramEnv({{"big", INT64_MAX}, {"one", 1}})); });
    SCOPED_TRACE(text);
    EXPECT_LOC(d, "e.yaml", 2, 5 + col);
    EXPECT_MSG(d, phrase) << text;
  };
  fails("big + one", "integer overflow in expression (9223372036854775807 + 1)", 4);
  fails("0 - big - 2", "integer overflow", 8);
  fails("big * 2", "integer overflow", 4);
  fails("(0 - big - 1) / -1", "integer overflow in expression (-9223372036854775808 / -1)", 14);
  fails("-(0 - big - 1)", "(-INT64_MIN)", 0);
  // INT64_MIN % -1 is 0 mathematically (and SIGFPE on x86 if computed directly).
  EXPECT_EQ(ev("(0 - big - 1) % -1", paramEnv({{"big", INT64_MAX}})), 0);
  EXPECT_EQ(ev("big - 1 + one", paramEnv({{"big", INT64_MAX}, {"one", 1}})), INT64_MAX);
  EXPECT_EQ(ev("0 - big - 1", paramEnv({{"big", INT64_MAX}})), INT64_MIN);
}

TEST(Hostile, ExpressionDepthAndLengthAreLimited) {
  auto at = sg::SourceLoc{"e.yaml", 1, 1};
  for (const std::string& text : {std::string(2000, '(') + "1" + std::string(2000, ')'), std::string(4000, '!') + "0",
                                  std::string(4000, '-') + "1"}) {
    auto d = errorOf([&] { sg::Expr::parse(text, at); });
    EXPECT_MSG(d, "nested deeper than 64 levels");
  }
  std::string chain = "1";
  for (int i = 0; i < 100; ++i) chain += "+1";
  EXPECT_MSG(errorOf([&] { sg::Expr::parse(chain, at); }), "nested deeper than 64 levels");
  std::string padded(5000, ' ');  // (built in place: GCC's -Wstringop-overflow misreads a temporary + "1")
  padded += '1';
  auto d = errorOf([&] { sg::Expr::parse(padded, at); });
  EXPECT_MSG(d, "5001 characters long");
  // Just inside the limits still works.
  EXPECT_EQ(ev(std::string(60, '(') + "7" + std::string(60, ')')), 7);
  std::string ok = "1";
  for (int i = 0; i < 60; ++i) ok += "+1";
  EXPECT_EQ(ev(ok), 61);
}

TEST(Hostile, SnippetControlBytesAreRefusedAtLoad) {
  // \x01..\x02 is how the generator marks fact references internally; in a snippet it
  // used to be taken for one (an out-of-bounds write).
  sg::RuleSet set;
  const std::string rules = "semantics:\n  a.b: vec3\nrules:\n  - name: r\n    produces: a.b\n    cost: 1\n    glsl: |\n"
                            "      ${out} = vec3(\x01" "99999\x02);\n";
  auto d = errorOf([&] { sg::loadRulesText(set, rules, "s.yaml"); });
  EXPECT_LOC(d, "s.yaml", 8, 7 + 14);
  EXPECT_MSG(d, "control character 0x01 in a GLSL snippet");
}

TEST(Hostile, NestedForUnrollIsBounded) {
  auto d = errorOf([&] {
    sg::expandSnippet(tmpl({"@for i in 4096", "@for j in 4096", "@for k in 4096", "x;", "@end", "@end", "@end"}), snippetCtx());
  });
  EXPECT_LOC(d, "t.yaml", 13, 7);  // the line that would be emitted the 16385th time
  EXPECT_MSG(d, "more than 16384 lines");
  auto d2 = errorOf([&] { sg::expandSnippet(tmpl({"@for i in 200", "@for j in 200", "x;", "@end", "@end"}), snippetCtx()); });
  EXPECT_LOC(d2, "t.yaml", 12, 7);
  EXPECT_MSG(d2, "more than 16384 lines");
  // An empty body still counts iterations, so empty nested loops cannot spin for hours.
  auto d3 = errorOf([&] {
    sg::expandSnippet(tmpl({"@for i in 4096", "@for j in 4096", "@for k in 4096", "@end", "@end", "@end"}), snippetCtx());
  });
  EXPECT_LOC(d3, "t.yaml", 12, 7);  // the innermost loop
  EXPECT_MSG(d3, "unroll more than 1048576 iterations");
}

TEST(Hostile, AbsurdCostIsRefused) {
  sg::RuleSet set;
  const std::string rules = "semantics:\n  vertex.position: vec3\n  clip.position: vec4\nrules:\n  - name: r\n"
                            "    produces: clip.position\n    needs: vertex.position\n    cost: 1000000000000\n"
                            "    glsl: \"${out} = vec4(${vertex.position}, 1.0);\"\n";
  sg::loadRulesText(set, rules, "s.yaml");
  sg::Rig rig = sg::loadRigText(kMiniRig, "r.yaml");
  auto d = errorOf([&] { sg::buildProblem(rig, set, {}); });
  EXPECT_LOC(d, "s.yaml", 5, 11);
  EXPECT_MSG(d, "above the limit of 1000000000");
}

TEST(Hostile, FragmentLongLineIsScannedLinearly) {
  sg::RuleSet rules = sg::loadRules({kSrc + "/rules/standard.yaml"});
  // ~30 KB on one line made std::regex recurse until the stack overflowed.
  const std::string src = "#version 450\nlayout(location = 0) in " + std::string(30000, ' ') + "vec3 world_normal; // " +
                          std::string(30000, 'x') + "\nlayout(location = 1) in vec3 bogus_input;\n"
                          "layout(location = 0) out vec4 c;\nvoid main() { c = vec4(world_normal + bogus_input, 1); }\n";
  sg::FragmentInterface fi = sg::reflectFragmentSource(src, "long.frag");
  ASSERT_EQ(fi.inputs.size(), 2u);
  EXPECT_EQ(fi.inputs[0].loc.line, 2);
  EXPECT_EQ(fi.inputs[0].loc.col, 25 + 30000 + 5);
  auto d = errorOf([&] { sg::bindVaryings(fi, rules, {}); });
  EXPECT_LOC(d, "long.frag", 3, 30);
  EXPECT_MSG(d, "'bogus_input' does not name a semantic");
}

TEST(Hostile, FragmentDeclarationScannerSkipsCommentsAndFindsSplitDeclarations) {
  const std::string src = "#version 450\n// in vec3 world_normal;\n/* in vec3 world_normal; */ layout(location = 0)\n"
                          "  in\n  vec3 world_normal;\nlayout(location = 0) out vec4 c;\nvoid main() { c = vec4(world_normal, 1); }\n";
  sg::FragmentInterface fi = sg::reflectFragmentSource(src, "split.frag");
  ASSERT_EQ(fi.inputs.size(), 1u);
  EXPECT_EQ(fi.inputs[0].loc.line, 5);
  EXPECT_EQ(fi.inputs[0].loc.col, 8);
}

TEST(Hostile, FragmentInputsCannotUseGeneratedNames) {
  sg::RuleSet rules = sg::loadRules({kSrc + "/rules/standard.yaml"});
  for (const std::string name : {"a_position", "u_bones", "ShadergenUniforms"}) {
    const std::string src = "#version 450\nlayout(location = 0) in vec3 " + name +
                            ";\nlayout(location = 0) out vec4 c;\nvoid main() { c = vec4(" + name + ", 1); }\n";
    sg::FragmentInterface fi = sg::reflectFragmentSource(src, "n.frag");
    auto d = errorOf([&] { sg::bindVaryings(fi, rules, {{name, {"world.normal"}}}); });
    SCOPED_TRACE(name);
    EXPECT_LOC(d, "n.frag", 2, 30);
    EXPECT_MSG(d, "rename it") << name;
  }
}

TEST(Hostile, MapMustNameAnInput) {
  sg::RuleSet rules = sg::loadRules({kSrc + "/rules/standard.yaml"});
  const std::string src = "#version 450\nlayout(location = 0) in vec3 world_normal;\nlayout(location = 0) out vec4 c;\n"
                          "void main() { c = vec4(world_normal, 1); }\n";
  sg::FragmentInterface fi = sg::reflectFragmentSource(src, "m.frag");
  auto d = errorOf([&] { sg::bindVaryings(fi, rules, {{"WorldNormal", {"world.normal"}}}); });
  EXPECT_EQ(d.loc.file, "m.frag");
  EXPECT_MSG(d, "no input 'WorldNormal' (its inputs: world_normal)");
}

TEST(Hostile, FragmentCompileErrorsGetColumns) {
  const std::string src = "#version 450\nlayout(location = 0) out vec4 c;\nvoid main() {\n  c = vec4(no_such_thing);\n}\n";
  auto d = errorOf([&] { sg::reflectFragmentSource(src, "e.frag"); });
  EXPECT_LOC(d, "e.frag", 4, 12);
  EXPECT_MSG(d, "no_such_thing");
  // A 30 KB identifier in the message: parsed without std::regex (no deep recursion).
  const std::string longName(30000, 'q');
  const std::string src2 = "#version 450\nlayout(location = 0) out vec4 c;\nvoid main() { c = vec4(" + longName + "); }\n";
  auto d2 = errorOf([&] { sg::reflectFragmentSource(src2, "l.frag"); });
  EXPECT_EQ(d2.loc.file, "l.frag");
  EXPECT_EQ(d2.loc.line, 3);
}

}  // namespace

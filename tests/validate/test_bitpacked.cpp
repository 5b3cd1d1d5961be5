// Bit-packed attributes (rig/packed_fields.h, docs/rig-format.md "Bit-packed attributes"):
// the layout rule and the words checked against values computed by hand from the formats'
// definitions, the shader's unpack and its stated cost against the compiled program, a
// packed vertex validated on the device, planted wrong unpacks caught, the reflection and
// header, and the search weighing a packed attribute against separate ones per device.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <set>
#include <tuple>

#include <nlohmann/json.hpp>

#include "analysis/cost.h"
#include "common/glsl_compile.h"
#include "emit/reflection.h"
#include "pipeline/generate.h"
#include "pipeline/stages.h"
#include "rig/packed_fields.h"
#include "test_util.h"
#include "validate/pack.h"
#include "validate/validate.h"

namespace {

using sgtest::dataPath;
using sgtest::sourcePath;

sg::PackedField field(sg::VertexFormat f) {
  sg::PackedField p;
  p.format = f;
  return p;
}

std::vector<sg::PackedField> laidOut(std::initializer_list<sg::VertexFormat> formats, int words, bool* fits = nullptr) {
  std::vector<sg::PackedField> out;
  for (sg::VertexFormat f : formats) out.push_back(field(f));
  const bool ok = sg::layoutFields(out, words);
  if (fits) *fits = ok;
  return out;
}

// Fields in order, each at its component size's boundary (10-10-10-2 a whole word): an
// 8-bit pair at bit 0, a 16-bit pair after it at bit 16 (its y in word 1), a 10-10-10-2 at
// the next word boundary (word 2), bytes in word 3: 128 bits exactly.
TEST(BitPacked, FieldsArePlacedInOrderAlignedToTheirComponents) {
  bool fits = false;
  auto f = laidOut({sg::VertexFormat::Snorm8x2, sg::VertexFormat::Unorm16x2, sg::VertexFormat::Unorm10_10_10_2,
                    sg::VertexFormat::Unorm8x4},
                   4, &fits);
  EXPECT_TRUE(fits);
  EXPECT_EQ(f[0].word, 0);
  EXPECT_EQ(f[0].bit, 0);
  EXPECT_EQ(f[1].word, 0);
  EXPECT_EQ(f[1].bit, 16);
  EXPECT_EQ(sg::fieldComponentBit(f[1], 1), 32);
  EXPECT_EQ(f[2].word, 2);
  EXPECT_EQ(f[2].bit, 0);
  EXPECT_EQ(sg::fieldComponentBit(f[2], 1), 74);
  EXPECT_EQ(sg::fieldComponentBit(f[2], 3), 94);
  EXPECT_EQ(f[3].word, 3);
  EXPECT_EQ(sg::fieldComponentBit(f[3], 3), 120);
  // Bytes, halves, bytes, a float, bytes: 16 + 32 (at 16) + 16 (at 48) + 32 (at 64) + 16 (at
  // 96); a 16-bit pair more would end at bit 144.
  auto g = laidOut({sg::VertexFormat::Unorm8x2, sg::VertexFormat::Float16x2, sg::VertexFormat::Snorm8x2,
                    sg::VertexFormat::Float32x1, sg::VertexFormat::Unorm8x2},
                   4, &fits);
  EXPECT_TRUE(fits);
  EXPECT_EQ(g[1].bit, 16);
  EXPECT_EQ(g[2].word, 1);
  EXPECT_EQ(g[2].bit, 16);
  EXPECT_EQ(g[3].word, 2);
  EXPECT_EQ(g[4].word, 3);
  EXPECT_EQ(g[4].bit, 0);
  laidOut({sg::VertexFormat::Unorm8x2, sg::VertexFormat::Float16x2, sg::VertexFormat::Snorm8x2,
           sg::VertexFormat::Float32x1, sg::VertexFormat::Unorm8x2, sg::VertexFormat::Snorm16x2},
          4, &fits);
  EXPECT_FALSE(fits);
  // Two words (uint32x2): a 16-bit pair, then two byte pairs in word 1's halves.
  auto two = laidOut({sg::VertexFormat::Snorm16x2, sg::VertexFormat::Snorm8x2, sg::VertexFormat::Snorm8x2}, 2, &fits);
  EXPECT_TRUE(fits);
  EXPECT_EQ(two[1].word, 1);
  EXPECT_EQ(two[2].word, 1);
  EXPECT_EQ(two[2].bit, 16);
  // One word (uint32): two byte pairs fit, a third does not.
  laidOut({sg::VertexFormat::Unorm8x2, sg::VertexFormat::Unorm8x2}, 1, &fits);
  EXPECT_TRUE(fits);
  laidOut({sg::VertexFormat::Unorm8x2, sg::VertexFormat::Unorm8x2, sg::VertexFormat::Unorm8x2}, 1, &fits);
  EXPECT_FALSE(fits);
}

std::array<uint32_t, 4> words(const std::vector<sg::PackedField>& fields, const std::vector<std::vector<float>>& values) {
  std::array<uint8_t, 16> element{};
  for (size_t i = 0; i < fields.size(); ++i) sg::packField(fields[i], values[i].data(), element.data());
  std::array<uint32_t, 4> w{};
  std::memcpy(w.data(), element.data(), 16);  // little-endian words, as the device reads them
  return w;
}

// The words, from the formats' definitions (Vulkan "Fixed-Point Data Conversions": unorm
// c = round(v (2^b - 1)), snorm c = round(v (2^(b-1) - 1)) in two's complement; binary16):
//   snorm8 (-1, 0.5): 0x81, 0x40 (63.5 rounds to 64)    -> word 0 bits 0-15:  0x4081
//   unorm16 (1, 0.5): 0xffff, 0x8000 (32767.5 -> 32768) -> word 0 bits 16-31, word 1 bits 0-15
//   unorm10-10-10-2 (1, 0, 0.5, 1): 1023 | 0 << 10 | 512 << 20 | 3 << 30 = 0xe00003ff
//   unorm8 (0, 1, 0.2, 1): 0x00, 0xff, 0x33 (51), 0xff -> 0xff33ff00
//   float16 (1, -2): 0x3c00, 0xc000
TEST(BitPacked, WordsHoldEachFormatsCodeAtItsBits) {
  auto f = laidOut({sg::VertexFormat::Snorm8x2, sg::VertexFormat::Unorm16x2, sg::VertexFormat::Unorm10_10_10_2,
                    sg::VertexFormat::Unorm8x4},
                   4);
  auto w = words(f, {{-1.0f, 0.5f}, {1.0f, 0.5f}, {1.0f, 0.0f, 0.5f, 1.0f}, {0.0f, 1.0f, 0.2f, 1.0f}});
  EXPECT_EQ(w[0], 0xffff4081u);
  EXPECT_EQ(w[1], 0x00008000u);
  EXPECT_EQ(w[2], 0xe00003ffu);
  EXPECT_EQ(w[3], 0xff33ff00u);
  auto g = laidOut({sg::VertexFormat::Unorm8x2, sg::VertexFormat::Float16x2}, 4);
  auto h = words(g, {{0.0f, 0.0f}, {1.0f, -2.0f}});
  EXPECT_EQ(h[0], 0x3c000000u);
  EXPECT_EQ(h[1], 0x0000c000u);
}

struct UnpackCase {
  sg::VertexFormat format;
  int word;
  const char* swizzle;
  const char* glsl;
  int64_t slots;
};

// Each component read with the builtin of its format, consecutive lanes of one unpack kept
// together; the stated slots are what `cost: auto` measures on the compiled, optimised
// unpack (analysis/cost.h).
TEST(BitPacked, UnpackUsesTheBuiltinsAndCostsWhatItStates) {
  const UnpackCase cases[] = {
      {sg::VertexFormat::Unorm16x4, 0, "xyz", "vec3(unpackUnorm2x16(a.x), unpackUnorm2x16(a.y).x)", 4},
      {sg::VertexFormat::Unorm16x4, 0, "w", "unpackUnorm2x16(a.y).y", 1},
      {sg::VertexFormat::Snorm16x4, 2, "", "vec4(unpackSnorm2x16(a.z), unpackSnorm2x16(a.w))", 4},
      {sg::VertexFormat::Float16x4, 0, "xy", "unpackHalf2x16(a.x)", 1},
      {sg::VertexFormat::Snorm8x4, 1, "", "unpackSnorm4x8(a.y)", 1},
      {sg::VertexFormat::Unorm8x4, 3, "", "unpackUnorm4x8(a.w)", 1},
      {sg::VertexFormat::Uint8x4, 2, "", "(uvec4(a.z, a.z, a.z, a.z) >> uvec4(0u, 8u, 16u, 24u)) & 255u", 2},
      {sg::VertexFormat::Uint16x4, 0, "", "(uvec4(a.x, a.x, a.y, a.y) >> uvec4(0u, 16u, 0u, 16u)) & 65535u", 2},
      {sg::VertexFormat::Unorm10_10_10_2, 1, "x", "(float(bitfieldExtract(a.y, 0, 10)) / 1023.0)", 3},
      {sg::VertexFormat::Snorm10_10_10_2, 1, "w", "max(float(bitfieldExtract(int(a.y), 30, 2)), -1.0)", 3},
      {sg::VertexFormat::Snorm10_10_10_2, 1, "z", "max(float(bitfieldExtract(int(a.y), 20, 10)) / 511.0, -1.0)", 4},
      {sg::VertexFormat::Float32x1, 3, "", "uintBitsToFloat(a.w)", 0},
      {sg::VertexFormat::Unorm10_10_10_2, 0, "xyw",
       "vec3((float(bitfieldExtract(a.x, 0, 10)) / 1023.0), (float(bitfieldExtract(a.x, 10, 10)) / 1023.0), "
       "(float(bitfieldExtract(a.x, 30, 2)) / 3.0))",
       12},
      {sg::VertexFormat::Float32x4, 0, "xy", "vec2(uintBitsToFloat(a.x), uintBitsToFloat(a.y))", 2},
  };
  for (const UnpackCase& c : cases) {
    SCOPED_TRACE(c.glsl);
    sg::PackedField f = field(c.format);
    f.word = c.word;
    const sg::FieldUnpack u = sg::unpackField(f, c.swizzle, "a", 4);
    EXPECT_EQ(u.glsl, c.glsl);
    EXPECT_EQ(u.slots, c.slots);
    // Measured as `cost: auto` measures a rule: compiled, optimised, weighed.
    const int n = *c.swizzle ? static_cast<int>(std::strlen(c.swizzle)) : sg::formatComponents(c.format);
    const auto type = sg::vectorType(sg::formatIsInteger(c.format) ? sg::ScalarKind::UInt : sg::ScalarKind::Float, n);
    ASSERT_TRUE(type);
    sg::GlslUnit unit;
    unit.fileName = "unpack.vert";
    unit.text = "#version 450\nlayout(location = 0) in uvec4 a;\nlayout(location = 0) " +
                std::string(sg::formatIsInteger(c.format) ? "flat " : "") + "out " + std::string(sg::glslName(*type)) +
                " o;\nvoid main() {\n  o = " + u.glsl + ";\n}\n";
    const sg::CompileResult compiled = sg::compileGlsl(unit, sg::TargetEnv::Vulkan1_0);
    ASSERT_TRUE(compiled.ok) << unit.text;
    const sg::CostBreakdown b = sg::measureSpirv(sg::optimizeSpirv(compiled.spirv, sg::TargetEnv::Vulkan1_0));
    std::string items;
    for (const auto& i : b.items) items += i.what + " x" + std::to_string(i.count) + " = " + std::to_string(i.slots) + "\n";
    EXPECT_EQ(b.total, c.slots) << unit.text << items;
  }
}

std::string loaderError(const std::string& attributes) {
  try {
    sg::loadRigText("rig: t\nattributes:\n" + attributes, "t.yaml");
  } catch (const sg::InputError& e) {
    return e.what();
  }
  return "(loaded)";
}

// The loader's refusals, each at the offending line and column (more in tests/bad-input/rig/fields_*).
TEST(BitPacked, LoaderRefusesWithALocation) {
  EXPECT_NE(loaderError("  p: { format: uint32x4, fields: [ { format: unorm16x4, provides: { vertex.position: xyz } },\n"
                        "    { format: float32x3, provides: vertex.normal } ] }\n")
                .find("t.yaml:4:5: error: field 2 (float32x3) would take bits 64..159, past the 128 bits of uint32x4"),
            std::string::npos);
  EXPECT_NE(loaderError("  p: { format: uint16x4, fields: [ { format: unorm8x4, provides: vertex.color } ] }\n")
                .find("t.yaml:3:16: error: attribute 'p' has 'fields', so its format must be uint32x4, uint32x2 or uint32"),
            std::string::npos);
  EXPECT_NE(loaderError("  p: { format: uint32, fields: [ { format: snorm8x2, provides: { vertex.uv: xyz } } ] }\n")
                .find("t.yaml:3:77: error: 'xyz' is not a valid swizzle of a 2-component field (snorm8x2)"),
            std::string::npos);
  EXPECT_NE(loaderError("  p: { format: uint32x4, fields: [ { format: unorm16x2, provides: vertex.qtangent } ] }\n")
                .find("t.yaml:3:46: error: 'vertex.qtangent' (qtangent vertex.normal, vertex.tangent, vertex.handedness) "
                      "must be stored in"),
            std::string::npos);
  // A field's place is computed by the loader: words 2-3 for the second 64-bit field.
  const sg::Rig rig = sg::loadRigFile(dataPath("bitpacked.rig.yaml"));
  ASSERT_EQ(rig.attributes[0].fields.size(), 2u);
  EXPECT_EQ(rig.attributes[0].fields[1].word, 2);
  EXPECT_EQ(rig.attributes[1].fields[2].word, 3);
  EXPECT_EQ(rig.attributes[0].provides[2].field, 1);
  EXPECT_EQ(sg::partFormat(rig.attributes[0], rig.attributes[0].provides[2]), sg::VertexFormat::Snorm16x4);
}

sg::ValidateOptions limbOptions(const std::string& rig) {
  sg::ValidateOptions vo;
  vo.gen.rigPath = dataPath(rig);
  vo.gen.fragmentPath = dataPath("world.frag");
  vo.gen.rulesPaths = {sourcePath("rules/standard.yaml")};
  return vo;
}

// bounds.rig.yaml's vertex in two uint32x4 locations instead of five: every field unpacked
// on the device, the decodes after it, and the float data's check, pass.
TEST(BitPacked, PackedVertexValidatesOnTheDevice) {
  sg::ValidateOptions vo = limbOptions("bitpacked.rig.yaml");
  const sg::ValidationScene scene = sg::proceduralScene(sg::loadRigFile(vo.gen.rigPath), "limb", 1, 2);
  const sg::ValidateReport rep = sg::Validator(vo).run(scene);
  std::cout << sg::formatReport(rep);
  EXPECT_TRUE(rep.pass);
  ASSERT_FALSE(rep.runs.empty());
  EXPECT_TRUE(sgtest::planHas(rep.runs[0], "unpack_packed.vertex.position_in_bounds"));
  EXPECT_TRUE(sgtest::planHas(rep.runs[0], "unpack_skin.skin.joints[0]"));
  EXPECT_TRUE(sgtest::planHas(rep.runs[0], "vertex_normal_from_octahedral"));
}

// One- and two-word attributes (uint, uvec2 inputs): an snorm16 pair in word 0, two snorm8
// pairs in word 1's halves, halves and bytes each in a uint.
TEST(BitPacked, OneAndTwoWordAttributesValidateOnTheDevice) {
  sg::ValidateOptions vo = limbOptions("bitpacked_small.rig.yaml");
  const sg::GenerateResult g = sg::generate(vo.gen);
  for (const char* line : {"layout(location = 1) in uvec2 a_frame;", "layout(location = 2) in uint a_uv;",
                           "unpackSnorm4x8(a_frame.y).xy", "unpackSnorm4x8(a_frame.y).z;", "unpackHalf2x16(a_uv)",
                           "(uvec4(a_joints, a_joints, a_joints, a_joints) >> uvec4(0u, 8u, 16u, 24u)) & 255u"})
    EXPECT_NE(g.glsl.text.find(line), std::string::npos) << line << "\n" << g.glsl.text;
  const sg::ValidationScene scene = sg::proceduralScene(g.in.rig, "limb", 1, 2);
  const sg::ValidateReport rep = sg::Validator(vo).run(scene);
  EXPECT_TRUE(rep.pass) << sg::formatReport(rep);
}

// Wrong unpacks planted in the generated GLSL fail on the outputs that read them: the
// frame's snorm codes read as unorm (every negative component becomes large), the
// position's z read 16 bits off (from the empty w).
TEST(BitPacked, PlantedWrongUnpacksFailValidation) {
  sg::ValidateOptions vo = limbOptions("bitpacked.rig.yaml");
  vo.gen.capture = true;
  const sg::GenerateResult r = sg::generate(vo.gen);
  const sg::ValidationScene scene = sg::proceduralScene(r.in.rig, "limb", 1, 1);
  auto failing = [&](const std::string& good, const std::string& bad) {
    sg::GenerateResult p = r;
    const size_t at = p.glsl.text.find(good);
    EXPECT_NE(at, std::string::npos) << p.glsl.text;
    if (at == std::string::npos) return std::set<std::string>{"(not planted)"};
    p.glsl.text.replace(at, good.size(), bad);
    p.spirv = sg::compileStage(p.in, p.plan, p.glsl, "planted.vert", vo.gen.targetEnv).module;
    return sgtest::failingOutputs(sg::Validator(vo).runOne(p, scene, "planted"));
  };
  EXPECT_TRUE(failing("", "").empty());
  const std::set<std::string> signless = failing("unpackSnorm2x16(a_packed.z)", "unpackUnorm2x16(a_packed.z)");
  EXPECT_TRUE(signless.count("world_normal")) << ::testing::PrintToString(signless);
  EXPECT_FALSE(signless.count("world_position"));
  const std::set<std::string> shifted = failing("unpackUnorm2x16(a_packed.y).x", "unpackUnorm2x16(a_packed.y).y");
  EXPECT_TRUE(shifted.count("world_position")) << ::testing::PrintToString(shifted);
  EXPECT_FALSE(shifted.count("world_normal"));
}

// The packer writes each field's bytes exactly as a separate attribute of its format holds
// them: bounds.rig.yaml stores the same values in five ordinary streams.
TEST(BitPacked, PackedWordsHoldTheSeparateFormatsBytes) {
  auto pack = [](const std::string& rig) {
    sg::GenerateOptions o = limbOptions(rig).gen;
    const sg::GenerateResult r = sg::generate(o);
    const sg::ValidationScene scene = sg::proceduralScene(r.in.rig, "limb", 1, 1);
    sg::PackedVertices packed = sg::packVertices(r, scene.mesh);
    return std::make_pair(nlohmann::json::parse(packed.layoutJson), std::move(packed.bytes));
  };
  const auto [bitLayout, bitBytes] = pack("bitpacked.rig.yaml");
  const auto [sepLayout, sepBytes] = pack("bounds.rig.yaml");
  auto stream = [](const nlohmann::json& layout, const std::string& attribute) {
    for (const auto& s : layout["streams"])
      if (s["attribute"] == attribute) return s;
    ADD_FAILURE() << "no stream " << attribute;
    return nlohmann::json{};
  };
  const std::vector<std::tuple<std::string, size_t, std::string>> pairs{
      {"packed", 0, "position"}, {"packed", 1, "frame"}, {"skin", 0, "uv"}, {"skin", 1, "joints"}, {"skin", 2, "weights"}};
  size_t vertices = bitLayout["vertex_count"];
  ASSERT_EQ(vertices, sepLayout["vertex_count"].get<size_t>());
  for (const auto& [attribute, index, separate] : pairs) {
    SCOPED_TRACE(attribute + " field " + std::to_string(index) + " vs " + separate);
    const nlohmann::json s = stream(bitLayout, attribute), t = stream(sepLayout, separate);
    const nlohmann::json f = s["fields"][index];
    ASSERT_EQ(f["format"], t["format"]);
    const size_t at = 4 * f["word"].get<size_t>() + f["bit"].get<size_t>() / 8, n = t["stride"];
    size_t differing = 0;
    for (size_t v = 0; v < vertices; ++v)
      differing += std::memcmp(bitBytes.data() + s["offset"].get<size_t>() + v * s["stride"].get<size_t>() + at,
                               sepBytes.data() + t["offset"].get<size_t>() + v * n, n) != 0;
    EXPECT_EQ(differing, 0u);
  }
}

// The reflection and the C header say where every field sits, so that an engine fills the
// words without our code.
TEST(BitPacked, ReflectionAndHeaderDescribeEveryField) {
  const sg::GenerateResult r = sg::generate(limbOptions("bitpacked.rig.yaml").gen);
  const nlohmann::json j = nlohmann::json::parse(sg::reflectionJson(r.in.rig, r.glsl, r.spirv));
  ASSERT_EQ(j["inputs"].size(), 2u);
  const nlohmann::json& packed = j["inputs"][0];
  EXPECT_EQ(packed["format"], "uint32x4");
  EXPECT_EQ(packed["type"], "uvec4");
  ASSERT_EQ(packed["fields"].size(), 2u);
  EXPECT_EQ(packed["fields"][1]["format"], "snorm16x4");
  EXPECT_EQ(packed["fields"][1]["vk_format"], "VK_FORMAT_R16G16B16A16_SNORM");
  EXPECT_EQ(packed["fields"][1]["conversion"], "snorm");
  EXPECT_EQ(packed["fields"][1]["word"], 2);
  EXPECT_EQ(packed["fields"][1]["bit"], 0);
  EXPECT_EQ(packed["fields"][1]["bits_per_component"], nlohmann::json::array({16, 16, 16, 16}));
  EXPECT_EQ(packed["fields"][1]["component_bit"], nlohmann::json::array({64, 80, 96, 112}));
  EXPECT_EQ(packed["provides"][2]["semantic"], "vertex.tangent_octahedral");
  EXPECT_EQ(packed["provides"][2]["components"], "zw");
  EXPECT_EQ(packed["provides"][2]["field"], 1);
  EXPECT_EQ(j["inputs"][1]["fields"][2]["component_bit"], nlohmann::json::array({96, 104, 112, 120}));
  const std::string h = sg::vertexInputsHeader(r.in.rig, r.glsl, "limb");
  for (const char* line : {"#define LIMB_A_PACKED_FIELD_COUNT 2u", "#define LIMB_A_PACKED_FIELD1_FORMAT 92u",
                           "#define LIMB_A_PACKED_FIELD1_WORD 2u", "#define LIMB_A_PACKED_FIELD1_BIT 0u",
                           "#define LIMB_A_PACKED_FIELD1_BITS 16u", "#define LIMB_A_SKIN_FIELD2_WORD 3u",
                           "field 1: snorm16x4 (vertex.normal_octahedral.xy, vertex.tangent_octahedral.zw)"})
    EXPECT_NE(h.find(line), std::string::npos) << line << "\n" << h;
}

// Stored both ways, the position and frame as three float attributes or one bit-packed
// location to unpack and decode: instruction slots keep the floats, the H200 profile (a
// location costs 0.40 ns, a slot 0.0017 ns) reads the packed words. The integer program
// agrees with A* on each, and every choice validates.
TEST(BitPacked, TheSearchWeighsPackedAgainstSeparatePerDevice) {
  for (const std::string profile : {"", "nvidia-h200.yaml"}) {
    SCOPED_TRACE(profile.empty() ? "instruction slots" : profile);
    const bool h200 = !profile.empty();
    sg::ValidateOptions vo = limbOptions("bitpacked_or_separate.rig.yaml");
    if (h200) vo.gen.deviceProfilePath = sourcePath("devices/" + profile);
    const sg::GenerateResult g = sg::generate(vo.gen);
    std::set<std::string> read;
    for (const auto& in : g.glsl.inputs) read.insert(g.in.rig.attributes[static_cast<size_t>(in.attribute)].name);
    EXPECT_EQ(read.count("packed"), h200 ? 1u : 0u) << ::testing::PrintToString(read);
    EXPECT_EQ(read.count("normal"), h200 ? 0u : 1u) << ::testing::PrintToString(read);
    EXPECT_EQ(read.count("position"), h200 ? 0u : 1u) << ::testing::PrintToString(read);
    sg::GenerateOptions ip = vo.gen;
    ip.searchEngine = "ip";
    EXPECT_EQ(sg::generate(ip).plan.cost, g.plan.cost);
    const sg::ValidationScene scene = sg::proceduralScene(g.in.rig, "limb", 1, 1);
    const sg::ValidateReport rep = sg::Validator(vo).run(scene);
    EXPECT_TRUE(rep.pass) << sg::formatReport(rep);
  }
}

}  // namespace

// HLSL and MSL (issue 25, docs/hlsl-msl.md). The HLSL is proven by execution: what
// `generate --emit hlsl` writes is compiled back to SPIR-V by glslang's HLSL front end, bound
// by the semantics the reflection names, and validated on lavapipe against the definitions
// with the SPIR-V's tolerances, for the Dawn face, body and depth passes and the shared
// models; a swapped semantic or input location must fail. MSL cannot run here: its text is
// checked against its reflection (every attribute, user location and buffer index).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <regex>
#include <set>

#include <shadergen/shadergen.h>

#include "../gltf/gltf_test_util.h"
#include "emit/reflection.h"
#include "pipeline/generate.h"
#include "validate/gltf_scene.h"
#include "validate/validate.h"

namespace sg {
namespace {

const std::string kDawn = std::string(SG_SOURCE_DIR) + "/examples/dawn/";

GenerateOptions dawnOptions(const std::string& rig, const std::string& frag) {
  GenerateOptions o;
  o.rigPath = kDawn + rig;
  o.fragmentPath = kDawn + frag;
  o.rulesPaths = {kDawn + "rules.yaml"};
  o.templateDir = std::string(SG_SOURCE_DIR) + "/templates";
  o.hlsl = HlslOptions{};
  o.msl = MslOptions{};
  return o;
}

// The three Dawn passes of the issue: the face, the body (no morphs) and the depth pass.
const std::vector<std::pair<const char*, const char*>> kPasses{
    {"face.rig.yaml", "face.frag"}, {"body.rig.yaml", "face.frag"}, {"face.rig.yaml", "depth.frag"}};

int count(const std::string& text, const std::string& what) {
  int n = 0;
  for (size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
  return n;
}

// Swaps the first occurrences of two strings in `text` (both must occur after `from`).
std::string swapped(std::string text, const std::string& a, const std::string& b, const std::string& from) {
  size_t start = text.find(from);
  EXPECT_NE(start, std::string::npos) << from;
  size_t pa = text.find(a, start), pb = text.find(b, start);
  EXPECT_NE(pa, std::string::npos) << a;
  EXPECT_NE(pb, std::string::npos) << b;
  if (pa == std::string::npos || pb == std::string::npos) return text;
  const std::string marker = "\x01";
  text.replace(pa, a.size(), marker);
  pb = text.find(b, start);
  text.replace(pb, b.size(), a);
  text.replace(text.find(marker), marker.size(), b);
  return text;
}

ValidateReport validateViaHlsl(const GenerateOptions& gen, bool crossCheck) {
  ValidateOptions vo;
  vo.gen = gen;
  vo.via = ValidateVia::Hlsl;
  vo.crossCheck = crossCheck;
  Validator v(vo);
  return v.run(proceduralScene(loadRigFile(gen.rigPath), "head", 7, 2));
}

class DawnHlsl : public ::testing::TestWithParam<std::pair<const char*, const char*>> {};

// Same scene, poses and tolerances as DawnValidation (test_dawn_examples.cpp), through HLSL.
TEST_P(DawnHlsl, TheHlslRoundTripValidatesOnLavapipe) {
  auto [rig, frag] = GetParam();
  ValidateReport report = validateViaHlsl(dawnOptions(rig, frag), true);
  EXPECT_TRUE(report.pass) << formatReport(report);
  EXPECT_EQ(report.via, "HLSL 5.0 (compiled back by glslang)");
  EXPECT_TRUE(report.validationLayers);
  ASSERT_FALSE(report.runs.empty());
  for (const auto& run : report.runs) {
    EXPECT_TRUE(run.validationMessages.empty()) << run.label;
    size_t compared = 0;
    for (const auto& o : run.outputs) compared += o.unchecked ? 0 : 1;
    EXPECT_EQ(compared, run.outputs.size()) << run.label;  // every output compared, position included
  }
  if (std::string(frag) == "face.frag") EXPECT_GE(report.runs.size(), 4u) << formatReport(report);
}

// The HLSL that runs is the text `generate` writes, byte for byte: the validator translates
// the shipped build. (The GLSL capture build would translate to the same text too: its
// transform feedback qualifiers have no HLSL form, so SPIRV-Cross drops them.)
TEST_P(DawnHlsl, TheValidatedHlslIsTheEmittedText) {
  auto [rig, frag] = GetParam();
  GenerateResult shipped = generate(dawnOptions(rig, frag));
  GenerateOptions capture = dawnOptions(rig, frag);
  capture.capture = true;
  GenerateResult captured = generate(capture);
  ASSERT_TRUE(shipped.hlsl && captured.hlsl);
  EXPECT_NE(captured.glsl.text, shipped.glsl.text);
  EXPECT_EQ(captured.hlsl->text, shipped.hlsl->text);
  // The module the harness runs is compiled from shipped.hlsl; the capture is added to it.
  std::vector<uint32_t> words = hlslCaptureModule(shipped, TargetEnv::Vulkan1_0);
  EXPECT_EQ(validateSpirv(words, TargetEnv::Vulkan1_0), "");
}

TEST_P(DawnHlsl, OutputsAreByteIdenticalAcrossRuns) {
  auto [rig, frag] = GetParam();
  GenerateResult a = generate(dawnOptions(rig, frag));
  GenerateResult b = generate(dawnOptions(rig, frag));
  EXPECT_EQ(a.hlsl->text, b.hlsl->text);
  EXPECT_EQ(a.msl->text, b.msl->text);
  EXPECT_EQ(reflectionOf(a), reflectionOf(b));
}

// MSL cannot run here. Its text must declare exactly the interface the reflection gives:
// one [[attribute(n)]] per input at its location, one [[user(locnN)]] per output, the
// position, and one [[buffer(n)]] per resource, read back from SPIRV-Cross's own parse.
TEST_P(DawnHlsl, MslDeclaresExactlyTheReflectedInterface) {
  auto [rig, frag] = GetParam();
  GenerateResult r = generate(dawnOptions(rig, frag));
  const CrossShader& msl = *r.msl;
  EXPECT_EQ(msl.entryPoint, "main0");
  EXPECT_NE(msl.text.find("vertex main0_out main0("), std::string::npos) << msl.text;
  std::set<std::string> declared, reflected;
  static const std::regex attr(R"(\[\[(attribute\(\d+\)|user\(locn\d+\)|position|buffer\(\d+\))\]\])");
  for (auto it = std::sregex_iterator(msl.text.begin(), msl.text.end(), attr); it != std::sregex_iterator(); ++it)
    EXPECT_TRUE(declared.insert((*it)[1]).second) << (*it)[1] << " declared twice";
  ASSERT_EQ(msl.inputs.size(), r.glsl.inputs.size());
  for (size_t i = 0; i < msl.inputs.size(); ++i) {
    EXPECT_EQ(msl.inputs[i].binding, "attribute(" + std::to_string(r.glsl.inputs[i].location) + ")");
    reflected.insert(msl.inputs[i].binding);
  }
  for (const auto& o : msl.outputs) reflected.insert(o.binding);
  for (const auto& res : msl.resources) reflected.insert(res.slot);
  EXPECT_EQ(declared, reflected);
  EXPECT_TRUE(reflected.count("position"));
  EXPECT_TRUE(reflected.count("buffer(0)"));  // the uniform block
  EXPECT_EQ(msl.firstVertexBuffer, msl.resources.size());
}

INSTANTIATE_TEST_SUITE_P(Passes, DawnHlsl, ::testing::ValuesIn(kPasses),
                         [](const auto& info) {
                           return std::string(info.param.first).substr(0, 4) + "_" +
                                  std::string(info.param.second).substr(0, std::string(info.param.second).find('.'));
                         });

// A planted error in the HLSL path fails validation: two output semantics swapped (the
// pixel shader would read each value in the other's place), or two vertex input semantics
// swapped (the input layout would feed each stream to the other).
// The face through HLSL, one run at a time (runOne), for planting errors in its text.
struct FaceViaHlsl {
  GenerateOptions gen = dawnOptions("face.rig.yaml", "face.frag");
  Validator validator{ValidateOptions{gen, ValidateVia::Hlsl}};
  ValidationScene scene = proceduralScene(loadRigFile(gen.rigPath), "head", 7, 2);
  GenerateResult r = generate(gen);
  RunReport run(const std::string& label) { return validator.runOne(r, scene, label); }
};

TEST(HlslPlantedErrors, SwappedOutputSemanticsFailExactlyThoseOutputs) {
  FaceViaHlsl face;
  GenerateResult& r = face.r;
  ASSERT_TRUE(face.run("as emitted").pass);
  // WorldTanMatrixX (TEXCOORD0) and WorldEyeDir (TEXCOORD3) are both float3.
  ASSERT_NE(r.hlsl->text.find("float3 WorldTanMatrixX : TEXCOORD0;"), std::string::npos) << r.hlsl->text;
  ASSERT_NE(r.hlsl->text.find("float3 WorldEyeDir : TEXCOORD3;"), std::string::npos);
  r.hlsl->text = swapped(r.hlsl->text, "TEXCOORD0;", "TEXCOORD3;", "struct SPIRV_Cross_Output");
  RunReport bad = face.run("semantics swapped");
  EXPECT_FALSE(bad.pass);
  for (const auto& o : bad.outputs)
    EXPECT_EQ(o.pass, o.name != "WorldTanMatrixX" && o.name != "WorldEyeDir") << o.name;
}

TEST(HlslPlantedErrors, SwappedInputSemanticsFail) {
  FaceViaHlsl face;
  GenerateResult& r = face.r;
  // a_normal and a_tangent are both float4: swapping their semantics type-checks everywhere.
  ASSERT_NE(r.hlsl->text.find("float4 a_normal : TEXCOORD1;"), std::string::npos) << r.hlsl->text;
  ASSERT_NE(r.hlsl->text.find("float4 a_tangent : TEXCOORD2;"), std::string::npos);
  r.hlsl->text = swapped(r.hlsl->text, "TEXCOORD1;", "TEXCOORD2;", "struct SPIRV_Cross_Input");
  RunReport bad = face.run("input semantics swapped");
  EXPECT_FALSE(bad.pass);
  for (const auto& o : bad.outputs)
    if (o.name == "gl_Position" || o.name == "SkinUVST") EXPECT_TRUE(o.pass) << o.name;  // read neither
    else if (o.name == "WorldTanMatrixX" || o.name == "WorldTanMatrixZ") EXPECT_FALSE(o.pass) << o.name;
}

TEST(HlslPlantedErrors, ASemanticTheReflectionDoesNotNameIsAnError) {
  GenerateResult r = generate(dawnOptions("face.rig.yaml", "depth.frag"));
  std::string& text = r.hlsl->text;
  size_t at = text.find("TEXCOORD0;", text.find("struct SPIRV_Cross_Input"));
  ASSERT_NE(at, std::string::npos);
  text.replace(at, 10, "TEXCOORD9;");
  try {
    hlslCaptureModule(r, TargetEnv::Vulkan1_0);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("semantic 'TEXCOORD9' is not in the reflection"), std::string::npos) << e.what();
  }
}

// The one rewrite before glslang compiles the HLSL: a bit cast of an integer matrix becomes
// the float matrix of the bit casts of its rows (HLSL fills a matrix from vectors by rows,
// and asfloat works per component, so the value is the same). Nothing else changes.
TEST(HlslRoundTrip, IntegerMatrixBitCastsBecomeFloatMatricesOfBitCasts) {
  EXPECT_EQ(withoutIntegerMatrices("float4x4 m = asfloat(uint4x4(b.Load4(k * 64 + 0), b.Load4(k * 64 + 16), "
                                   "b.Load4(f(k, 2)), x));\nfloat4 v = asfloat(uint4(1, 2, 3, 4));"),
            "float4x4 m = float4x4(asfloat(b.Load4(k * 64 + 0)), asfloat(b.Load4(k * 64 + 16)), "
            "asfloat(b.Load4(f(k, 2))), asfloat(x));\nfloat4 v = asfloat(uint4(1, 2, 3, 4));");
  EXPECT_EQ(withoutIntegerMatrices("asfloat(uint3x3(a, b, c)).x"), "float3x3(asfloat(a), asfloat(b), asfloat(c)).x");
  const std::string untouched = "float4 a = asfloat(b.Load4(0)); uint4x4 m;";
  EXPECT_EQ(withoutIntegerMatrices(untouched), untouched);
}

// The reflection a host binds by: HLSL semantics per location, registers, MSL indices.
TEST(HlslMslReflection, RecordsSemanticsRegistersAndBufferIndices) {
  GenerateOptions o = dawnOptions("face.rig.yaml", "face.frag");
  o.hlsl->shaderModel = 60;
  o.msl = MslOptions{2, 1, MslPlatform::IOS};
  GenerateResult r = generate(o);
  std::string j = reflectionOf(r);
  EXPECT_NE(j.find("\"hlsl\": {\n    \"shader_model\": \"6.0\", \"profile\": \"vs_6_0\", \"entry_point\": \"main\""),
            std::string::npos)
      << j;
  EXPECT_NE(j.find("\"msl\": {\n    \"version\": \"2.1\", \"platform\": \"ios\", \"entry_point\": \"main0\""),
            std::string::npos);
  for (const auto& in : r.glsl.inputs)
    EXPECT_NE(j.find(fmt::format("{{\"name\": \"{}\", \"location\": {}, \"semantic\": \"TEXCOORD{}\"}}", in.name,
                                 in.location, in.location)),
              std::string::npos)
        << in.name;
  EXPECT_NE(j.find("{\"name\": \"gl_Position\", \"location\": -1, \"semantic\": \"SV_Position\"}"), std::string::npos);
  EXPECT_NE(j.find("{\"name\": \"ShadergenUniforms\", \"variable\": \"uniforms\", \"kind\": \"cbuffer\", "
                   "\"register\": \"b0\", \"space\": 0, \"set\": 0, \"binding\": 0}"),
            std::string::npos);
  EXPECT_NE(j.find("\"buffer\": 0, \"set\": 0, \"binding\": 0}"), std::string::npos);
  EXPECT_NE(r.msl->text.find("constant ShadergenUniforms& uniforms [[buffer(0)]]"), std::string::npos) << r.msl->text;
  // The platform is recorded (the Dawn text is the same for macOS and iOS).
  GenerateOptions mac = o;
  mac.msl->platform = MslPlatform::MacOS;
  EXPECT_NE(reflectionOf(generate(mac)).find("\"platform\": \"macos\""), std::string::npos);
  // From 5.1 on, registers name their space.
  EXPECT_NE(r.hlsl->text.find("cbuffer ShadergenUniforms : register(b0, space0)"), std::string::npos);
}

// A plan that reads storage buffers: their registers follow the uniform block's (t0, t1, ...)
// and the round trip binds them back to Vulkan bindings 1, 2, ...
TEST(HlslMslReflection, StorageBuffersTakeTRegistersAndRunThroughHlsl) {
  GenerateOptions o = dawnOptions("face.rig.yaml", "face.frag");
  o.rulesPaths.push_back(std::string(SG_SOURCE_DIR) + "/rules/buffers.yaml");
  o.maxAttributes = 6;  // too few locations for the morph streams: they move to storage buffers
  GenerateResult r;
  try {
    r = generate(o);
  } catch (const InputError& e) {
    GTEST_SKIP() << "no buffer plan for the face under 6 attributes: " << e.what();
  }
  ASSERT_FALSE(r.glsl.buffers.empty());
  for (size_t i = 0; i < r.glsl.buffers.size(); ++i) {
    const CrossResource& h = r.hlsl->resources[i + 1];
    EXPECT_EQ(h.slot, "t" + std::to_string(i));
    EXPECT_EQ(h.binding, static_cast<uint32_t>(r.glsl.buffers[i].binding));
    EXPECT_NE(r.hlsl->text.find("ByteAddressBuffer " + h.variable + " : register(" + h.slot + ")"), std::string::npos)
        << r.hlsl->text;
    EXPECT_EQ(r.msl->resources[i + 1].slot, "buffer(" + std::to_string(i + 1) + ")");
  }
  ValidateReport report = validateViaHlsl(o, false);
  EXPECT_TRUE(report.pass) << formatReport(report);
}

// A matrix varying (the glTF Sample Viewer's mat3 v_TBN) takes TEXCOORD2..4 and still
// validates through HLSL: its columns land where the GLSL capture puts them.
TEST(HlslMslReflection, AMatrixOutputTakesConsecutiveSemanticsAndValidates) {
  GenerateOptions o = dawnOptions("face.rig.yaml", "face.frag");
  o.fragmentPath = std::string(SG_SOURCE_DIR) + "/tests/validate/data/conventions/gltf_sample_viewer.frag";
  o.rulesPaths = {std::string(SG_SOURCE_DIR) + "/rules/standard.yaml"};
  GenerateResult r = generate(o);
  std::string j = reflectionOf(r);
  EXPECT_NE(j.find("{\"name\": \"v_TBN\", \"location\": 2, \"semantic\": \"TEXCOORD2\", \"semantic_count\": 3}"),
            std::string::npos)
      << j;
  EXPECT_NE(j.find("{\"name\": \"v_TBN\", \"location\": 2, \"attribute\": \"user(locn2)\", \"locations\": 3}"),
            std::string::npos);
  EXPECT_NE(r.hlsl->text.find("float3x3 v_TBN : TEXCOORD2;"), std::string::npos);
  ValidateReport report = validateViaHlsl(o, false);
  EXPECT_TRUE(report.pass) << formatReport(report);
}

// shadergen::core (api/shadergen.h) makes the same texts from strings, and refuses bad ones.
TEST(HlslMslLibrary, TheApiReturnsTheTranslationsAndRefusesUnsupportedOptions) {
  shadergen::Options o;
  o.rig = kDawn + "face.rig.yaml";
  o.fragment = kDawn + "depth.frag";
  o.rules = {kDawn + "rules.yaml"};
  o.templates = std::string(SG_SOURCE_DIR) + "/templates";
  o.hlslShaderModel = "5.1";
  o.mslVersion = "2.2";
  shadergen::Result r = shadergen::generate(o);
  ASSERT_TRUE(r.ok);
  GenerateOptions g = dawnOptions("face.rig.yaml", "depth.frag");
  g.hlsl->shaderModel = 51;
  g.msl->minor = 2;
  GenerateResult expected = generate(g);
  EXPECT_EQ(r.hlsl, expected.hlsl->text);
  EXPECT_EQ(r.msl, expected.msl->text);
  EXPECT_EQ(r.reflection, reflectionOf(expected));
  o.hlslShaderModel = "4.1";
  r = shadergen::generate(o);
  ASSERT_FALSE(r.ok);
  EXPECT_EQ(r.diagnostics.at(0).message, "unsupported shader model '4.1' (supported: 5.0, 5.1, 6.0 .. 6.7)");
  o.hlslShaderModel = "";
  o.mslPlatform = "visionos";
  EXPECT_FALSE(shadergen::generate(o).ok);
}

// The shared models (../shared/models) through HLSL, at animation times, as
// tests/gltf/test_gltf_validate.cpp validates their SPIR-V.
struct ModelCase {
  const char* label;
  const char* model;
  const char* fragment;
  const char* animation;
  std::vector<double> times;
};

class ModelHlsl : public ::testing::TestWithParam<ModelCase> {};

TEST_P(ModelHlsl, TheHlslRoundTripValidatesOnLavapipe) {
  const ModelCase& c = GetParam();
  ValidateOptions vo;
  vo.gen.rigPath = test::modelPath(c.model);
  vo.gen.fragmentPath = test::dataPath(c.fragment);
  vo.gen.rulesPaths = {test::sourcePath("rules/standard.yaml")};
  vo.via = ValidateVia::Hlsl;
  GltfSceneOptions so;
  so.times = c.times;
  so.animation = c.animation;
  ValidationScene scene = gltfScene(vo.gen.rigPath, so, nullptr);
  Validator v(vo);
  ValidateReport report = v.run(scene);
  EXPECT_TRUE(report.pass) << formatReport(report);
  EXPECT_TRUE(report.validationLayers);
  for (const auto& run : report.runs) EXPECT_TRUE(run.validationMessages.empty()) << run.label;
}

INSTANTIATE_TEST_SUITE_P(
    SharedModels, ModelHlsl,
    ::testing::Values(ModelCase{"Fox", "Fox/Fox.glb#0/0", "uv.frag", "Survey", {0.5, 1.7}},
                      ModelCase{"SimpleSkin", "SimpleSkin/SimpleSkin.gltf#0/0", "minimal.frag", "", {1.0, 3.3}},
                      ModelCase{"MorphStressTest", "MorphStressTest/MorphStressTest.gltf#0/1", "lit_uv2.frag",
                                "TheWave", {0.4, 1.3}},
                      ModelCase{"AnimatedMorphSphere", "AnimatedMorphSphere/AnimatedMorphSphere.gltf#0/0", "frame.frag",
                                "", {1.2, 3.9}}),
    [](const auto& info) { return std::string(info.param.label); });

}  // namespace
}  // namespace sg

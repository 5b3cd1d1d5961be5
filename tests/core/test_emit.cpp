// The whole generator through generate(): the Dawn face end to end (GLSL that compiles,
// SPIR-V that validates, an interface that links with the fragment shader), determinism,
// dead-code-free plans, GLSL errors mapped back to rules-file lines, unsatisfiable
// requests, and the transform-feedback capture build.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "common/diagnostics.h"
#include "core_test_util.h"
#include "common/glsl_compile.h"
#include "common/types.h"
#include "emit/glsl_emitter.h"
#include "emit/spirv.h"
#include "interface/fragment_interface.h"
#include "pipeline/generate.h"

namespace {

const std::string kSrc = SG_SOURCE_DIR;
const std::string kDawnRig = kSrc + "/examples/dawn/face.rig.yaml";
const std::string kDawnFrag = kSrc + "/examples/dawn/face.frag";
const std::string kDawnRules = kSrc + "/examples/dawn/rules.yaml";
const std::string kStandardRules = kSrc + "/rules/standard.yaml";

using sgtest::errorOf;

int lineOf(const std::string& text, const std::string& needle) {
  size_t at = text.find(needle);
  if (at == std::string::npos) {
    ADD_FAILURE() << "test bug: '" << needle << "' not in text";
    return 0;
  }
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(at), '\n'));
}

using sgtest::freshDir;
using sgtest::writeText;

sg::GenerateOptions dawnOptions() {
  sg::GenerateOptions o;
  o.rigPath = kDawnRig;
  o.fragmentPath = kDawnFrag;
  o.rulesPaths = {kDawnRules};
  o.templateDir = kSrc + "/templates";
  return o;
}

struct Decl {
  int location;
  std::string type;
  std::string name;
};

// `layout(location = N[, xfb...]) [flat ]out TYPE NAME;` declarations of the GLSL text.
std::vector<Decl> outputsOf(const std::string& glsl) {
  static const std::regex re(R"(layout\(location = (\d+)[^)]*\) (?:flat )?out (\w+) (\w+);)");
  std::vector<Decl> out;
  for (auto it = std::sregex_iterator(glsl.begin(), glsl.end(), re); it != std::sregex_iterator(); ++it)
    out.push_back(Decl{std::stoi((*it)[1]), (*it)[2], (*it)[3]});
  return out;
}

// `layout(location = N) in TYPE NAME;` declarations.
std::vector<Decl> inputsOf(const std::string& glsl) {
  static const std::regex re(R"(layout\(location = (\d+)\) in (\w+) (\w+);)");
  std::vector<Decl> out;
  for (auto it = std::sregex_iterator(glsl.begin(), glsl.end(), re); it != std::sregex_iterator(); ++it)
    out.push_back(Decl{std::stoi((*it)[1]), (*it)[2], (*it)[3]});
  return out;
}

// Names of the semantics the plan's actions produce.
std::set<std::string> producedBy(const sg::GenerateResult& r) {
  std::set<std::string> out;
  for (int a : r.plan.actions) out.insert(r.in.problem.facts[r.in.problem.actions[a].add].name);
  return out;
}

// The shared result of one Dawn generation (several tests inspect it).
const sg::GenerateResult& dawn() {
  static const sg::GenerateResult r = sg::generate(dawnOptions());
  return r;
}

TEST(GenerateDawn, CompilesValidatesAndLinks) {
  const sg::GenerateResult& r = dawn();
  ASSERT_FALSE(r.glsl.text.empty());
  EXPECT_EQ(r.glsl.text.rfind("#version 450\n", 0), 0u);
  // SPIR-V: a module with the right magic that passes spirv-val.
  ASSERT_GT(r.spirv.words.size(), 5u);
  EXPECT_EQ(r.spirv.words[0], 0x07230203u);
  EXPECT_EQ(sg::validateSpirv(r.spirv.words, sg::TargetEnv::Vulkan1_0), "");
  EXPECT_GT(sg::countInstructions(r.spirv.words), 50u);
  // The emitted text compiles on its own too (independently of generate()'s own compile).
  sg::GlslUnit unit{sg::Stage::Vertex, r.glsl.text, "dawn.vert", r.glsl.sourceFiles};
  sg::CompileResult c = sg::compileGlsl(unit, sg::TargetEnv::Vulkan1_0);
  EXPECT_TRUE(c.ok);
  for (const auto& d : c.diagnostics) ADD_FAILURE() << sg::formatDiagnostic(d);
  EXPECT_EQ(c.spirv, r.spirv.words);
  // Vertex and fragment link, location by location.
  sg::FragmentInterface frag = sg::reflectFragmentFile(kDawnFrag);
  EXPECT_NO_THROW(sg::checkLink(r.glsl, frag.source, kDawnFrag, sg::TargetEnv::Vulkan1_0));
  // The uniform block is laid out (98 bones + 5 weights + camera + 3 matrices).
  EXPECT_GE(r.spirv.uniformBlockSize, 98u * 64u + 5u * 16u + 16u + 3u * 64u);
  // Every input file is reported for depfiles.
  std::set<std::string> read(r.inputsRead.begin(), r.inputsRead.end());
  EXPECT_TRUE(read.count(kDawnRig));
  EXPECT_TRUE(read.count(kDawnFrag));
  EXPECT_TRUE(read.count(kDawnRules));
  EXPECT_TRUE(read.count(kSrc + "/rules/skinning.yaml"));
}

TEST(GenerateDawn, OutputsMatchTheFragmentInputs) {
  const sg::GenerateResult& r = dawn();
  sg::FragmentInterface frag = sg::reflectFragmentFile(kDawnFrag);
  ASSERT_EQ(frag.inputs.size(), 6u);
  std::vector<Decl> outs = outputsOf(r.glsl.text);
  ASSERT_EQ(outs.size(), frag.inputs.size()) << r.glsl.text;
  std::map<int, Decl> byLoc;
  for (const auto& o : outs) EXPECT_TRUE(byLoc.emplace(o.location, o).second) << "location used twice: " << o.location;
  for (const auto& in : frag.inputs) {
    SCOPED_TRACE(in.name);
    auto it = byLoc.find(in.location);
    ASSERT_NE(it, byLoc.end());
    EXPECT_EQ(it->second.name, in.name);
    EXPECT_EQ(it->second.type, std::string(sg::glslName(in.type)));
  }
  // The emitter's own record agrees: gl_Position first, then the outputs by location.
  ASSERT_EQ(r.glsl.outputs.size(), 7u);
  EXPECT_EQ(r.glsl.outputs[0].name, "gl_Position");
  EXPECT_EQ(r.glsl.outputs[0].location, -1);
  for (size_t i = 1; i < r.glsl.outputs.size(); ++i) {
    EXPECT_EQ(r.glsl.outputs[i].name, frag.inputs[i - 1].name);
    EXPECT_EQ(r.glsl.outputs[i].location, frag.inputs[i - 1].location);
    EXPECT_EQ(r.glsl.outputs[i].type, frag.inputs[i - 1].type);
  }
  // Every output and gl_Position is written.
  EXPECT_NE(r.glsl.text.find("gl_Position = "), std::string::npos);
  for (const auto& in : frag.inputs) EXPECT_NE(r.glsl.text.find("  " + in.name + " = "), std::string::npos) << in.name;
  // No transform-feedback qualifiers in the normal build.
  EXPECT_EQ(r.glsl.text.find("xfb_"), std::string::npos);
}

TEST(GenerateDawn, VertexInputsHaveUniqueLocationsBelow16) {
  const sg::GenerateResult& r = dawn();
  std::vector<Decl> ins = inputsOf(r.glsl.text);
  ASSERT_FALSE(ins.empty());
  ASSERT_EQ(ins.size(), r.glsl.inputs.size());
  std::set<int> locs;
  for (const auto& in : ins) {
    EXPECT_TRUE(locs.insert(in.location).second) << "duplicate input location " << in.location;
    EXPECT_GE(in.location, 0);
    EXPECT_LT(in.location, 16) << in.name;  // Vulkan guarantees 16 vertex attributes
  }
  std::set<std::string> names;
  for (size_t i = 0; i < ins.size(); ++i) {
    names.insert(ins[i].name);
    EXPECT_EQ(ins[i].name, r.glsl.inputs[i].name);
    EXPECT_EQ(ins[i].location, r.glsl.inputs[i].location);
    EXPECT_EQ(ins[i].type, std::string(sg::glslName(r.glsl.inputs[i].type)));
  }
  // Per-target streams are expanded, one per morph target; bone indices are uvec4.
  for (int t = 0; t < 5; ++t) EXPECT_TRUE(names.count("a_coord_morph" + std::to_string(t))) << t;
  EXPECT_FALSE(names.count("a_coord_morph5"));
  for (const auto& in : ins)
    if (in.name == "a_bone_index") EXPECT_EQ(in.type, "uvec4");
}

TEST(GenerateDawn, SnippetLinesCarryLineDirectivesIntoTheRules) {
  const sg::GenerateResult& r = dawn();
  // #line L S: S indexes sourceFiles; every source is a rules file that was read.
  std::set<std::string> rulesFiles(r.in.rules.files.begin(), r.in.rules.files.end());
  for (const auto& f : r.glsl.sourceFiles) EXPECT_TRUE(rulesFiles.count(f)) << f;
  static const std::regex re(R"(#line (\d+) (\d+))");
  int n = 0;
  for (auto it = std::sregex_iterator(r.glsl.text.begin(), r.glsl.text.end(), re); it != std::sregex_iterator(); ++it) {
    int src = std::stoi((*it)[2]);
    EXPECT_LE(src, static_cast<int>(r.glsl.sourceFiles.size()));
    ++n;
  }
  EXPECT_GT(n, 10);
}

TEST(GenerateDawn, Deterministic) {
  sg::GenerateResult a = sg::generate(dawnOptions());
  sg::GenerateResult b = sg::generate(dawnOptions());
  EXPECT_EQ(a.glsl.text, b.glsl.text);
  EXPECT_EQ(a.spirv.words, b.spirv.words);
  EXPECT_EQ(a.plan.actions, b.plan.actions);
  EXPECT_EQ(a.plan.cost, b.plan.cost);
  EXPECT_EQ(a.glsl.text, dawn().glsl.text);
}

TEST(GenerateDawn, HeuristicsAgreeOnTheOptimalCost) {
  sg::GenerateOptions o = dawnOptions();
  o.heuristic = "hmax";
  sg::GenerateResult h = sg::generate(o);
  EXPECT_EQ(h.plan.cost, dawn().plan.cost);
  EXPECT_GT(dawn().plan.cost, 0);
  o.heuristic = "no-such-heuristic";
  auto d = errorOf([&] { sg::generate(o); });
  EXPECT_NE(d.message.find("unknown heuristic"), std::string::npos) << d.message;
}

TEST(GenerateDawn, OptimisedSpirvValidates) {
  sg::GenerateOptions o = dawnOptions();
  o.optimize = true;
  sg::GenerateResult r = sg::generate(o);
  EXPECT_EQ(sg::validateSpirv(r.spirv.words, sg::TargetEnv::Vulkan1_0), "");
  EXPECT_EQ(r.glsl.text, dawn().glsl.text);  // only the SPIR-V changes
}

TEST(GenerateDepthOnly, PlanComputesNoNormalsOrTangents) {
  auto dir = freshDir("depth");
  auto frag = (dir / "depth.frag").string();
  writeText(frag,
            "#version 450\n"
            "layout(location = 0) out vec4 color;\n"
            "void main() { color = vec4(1.0, 0.5, 0.25, 1.0); }\n");
  sg::GenerateOptions o = dawnOptions();
  o.fragmentPath = frag;
  sg::GenerateResult r = sg::generate(o);
  std::set<std::string> produced = producedBy(r);
  EXPECT_TRUE(produced.count("clip.position"));
  for (const char* s : {"world.normal", "world.tangent", "object.normal", "object.tangent", "world.binormal",
                        "morph.normal_occlusion", "world.eye_dir"})
    EXPECT_FALSE(produced.count(s)) << s << " is computed but nothing needs it";
  // Only gl_Position is written; no normal/tangent/uv streams are declared.
  EXPECT_TRUE(outputsOf(r.glsl.text).empty());
  ASSERT_EQ(r.glsl.outputs.size(), 1u);
  std::set<std::string> inputs;
  for (const auto& d : inputsOf(r.glsl.text)) inputs.insert(d.name);
  EXPECT_TRUE(inputs.count("a_coord"));
  for (const auto& name : inputs) {
    EXPECT_EQ(name.find("normal"), std::string::npos) << name;
    EXPECT_EQ(name.find("tangent"), std::string::npos) << name;
    EXPECT_EQ(name.find("uvst"), std::string::npos) << name;
  }
  EXPECT_EQ(r.glsl.text.find("a_normal"), std::string::npos);
  EXPECT_EQ(r.glsl.text.find("a_tangent"), std::string::npos);
  EXPECT_EQ(r.glsl.text.find("u_dapple_xf"), std::string::npos);  // unused uniforms are not declared
  EXPECT_LT(r.plan.cost, dawn().plan.cost);
  EXPECT_EQ(sg::validateSpirv(r.spirv.words, sg::TargetEnv::Vulkan1_0), "");
  std::filesystem::remove_all(dir);
}

// A rig with positions only (no normals), unskinned, with a view-projection matrix.
const char* kPositionOnlyRig =
    "rig: positions-only\n"
    "attributes:\n"
    "  coord: { format: float32x3, provides: vertex.position }\n"
    "uniforms:\n"
    "  mvp: { type: mat4, semantic: camera.view_projection }\n";

TEST(GenerateErrors, GlslErrorInRuleSnippetPointsAtTheRulesLine) {
  auto dir = freshDir("glslerr");
  auto rules = (dir / "bad_rules.yaml").string();
  const std::string rulesText =
      "# A self-contained rules file whose snippet does not compile.\n"
      "semantics:\n"
      "  vertex.position: vec3\n"
      "  camera.view_projection: mat4\n"
      "  clip.position: vec4\n"
      "rules:\n"
      "  - name: clip_bad\n"
      "    produces: clip.position\n"
      "    needs: [vertex.position, camera.view_projection]\n"
      "    cost: 1\n"
      "    glsl: |\n"
      "      ${out} = ${camera.view_projection} * vec4(${vertex.position}, 1.0);\n"
      "      ${out}.x += undefined_thing;\n";
  writeText(rules, rulesText);
  writeText(dir / "r.rig.yaml", kPositionOnlyRig);
  writeText(dir / "depth.frag",
            "#version 450\nlayout(location = 0) out vec4 color;\nvoid main() { color = vec4(1.0); }\n");
  sg::GenerateOptions o;
  o.rigPath = (dir / "r.rig.yaml").string();
  o.fragmentPath = (dir / "depth.frag").string();
  o.rulesPaths = {rules};
  o.templateDir = kSrc + "/templates";
  auto d = errorOf([&] { sg::generate(o); });
  EXPECT_EQ(d.loc.file, rules) << sg::formatDiagnostic(d);
  EXPECT_EQ(d.loc.line, lineOf(rulesText, "undefined_thing")) << sg::formatDiagnostic(d);
  EXPECT_NE(d.message.find("undefined_thing"), std::string::npos) << d.message;

  // The same file without the bad line generates fine (the error is the snippet's).
  std::string good = rulesText.substr(0, rulesText.find("      ${out}.x += undefined_thing;"));
  writeText(rules, good);
  sg::GenerateResult r = sg::generate(o);
  EXPECT_EQ(producedBy(r), std::set<std::string>{"clip.position"});
  EXPECT_NE(r.glsl.text.find("u_mvp * vec4(a_coord, 1.0)"), std::string::npos) << r.glsl.text;
  std::filesystem::remove_all(dir);
}

TEST(GenerateErrors, UnsatisfiableRequestNamesTheMissingSemantic) {
  auto dir = freshDir("unsat");
  writeText(dir / "r.rig.yaml", kPositionOnlyRig);
  const std::string fragText =
      "#version 450\n"
      "layout(location = 0) in vec3 WorldNormal;\n"
      "layout(location = 0) out vec4 color;\n"
      "void main() { color = vec4(WorldNormal, 1.0); }\n";
  writeText(dir / "n.frag", fragText);
  sg::GenerateOptions o;
  o.rigPath = (dir / "r.rig.yaml").string();
  o.fragmentPath = (dir / "n.frag").string();
  o.rulesPaths = {kStandardRules};
  o.overrides = {{"WorldNormal", {"world.normal"}}};
  o.templateDir = kSrc + "/templates";
  auto d = errorOf([&] { sg::generate(o); });
  EXPECT_NE(d.message.find("vertex.normal"), std::string::npos) << sg::formatDiagnostic(d);
  EXPECT_NE(d.message.find("world.normal"), std::string::npos) << sg::formatDiagnostic(d);
  EXPECT_NE(d.message.find("positions-only"), std::string::npos) << sg::formatDiagnostic(d);
  // Located at the fragment input that cannot be fed.
  EXPECT_EQ(d.loc.file, o.fragmentPath);
  EXPECT_EQ(d.loc.line, 2);

  // The same rig can feed a position-only request (skin matrix = identity, no model matrix).
  const std::string okFrag =
      "#version 450\n"
      "layout(location = 0) in vec3 world_position;\n"
      "layout(location = 0) out vec4 color;\n"
      "void main() { color = vec4(world_position, 1.0); }\n";
  writeText(dir / "p.frag", okFrag);
  o.fragmentPath = (dir / "p.frag").string();
  o.overrides.clear();
  sg::GenerateResult r = sg::generate(o);
  std::set<std::string> produced = producedBy(r);
  EXPECT_TRUE(produced.count("world.position"));
  EXPECT_FALSE(produced.count("world.normal"));
  std::filesystem::remove_all(dir);
}

TEST(GenerateCapture, XfbQualifiersAndStride) {
  sg::GenerateOptions o = dawnOptions();
  o.capture = true;
  sg::GenerateResult r = sg::generate(o);
  EXPECT_NE(r.glsl.text.find("xfb_offset"), std::string::npos);
  EXPECT_NE(r.glsl.text.find("xfb_buffer = 0"), std::string::npos);
  // gl_Position (4) + 3 frame rows (3 each) + eye dir (3) + SkinUVST (4) + SkinSilhouetteVec (4).
  int components = 4;
  sg::FragmentInterface frag = sg::reflectFragmentFile(kDawnFrag);
  for (const auto& in : frag.inputs) components += sg::componentCount(in.type);
  EXPECT_EQ(components, 24);
  EXPECT_EQ(r.glsl.captureStride, 4u * static_cast<uint32_t>(components));
  EXPECT_NE(r.glsl.text.find("xfb_stride = " + std::to_string(r.glsl.captureStride)), std::string::npos);
  // Offsets are packed in order: gl_Position at 0, each output right after the previous one.
  uint32_t expect = 0;
  for (const auto& out : r.glsl.outputs) {
    EXPECT_EQ(out.captureOffset, expect) << out.name;
    if (out.location >= 0)
      EXPECT_NE(r.glsl.text.find("layout(location = " + std::to_string(out.location) +
                                 ", xfb_buffer = 0, xfb_offset = " + std::to_string(out.captureOffset)),
                std::string::npos)
          << out.name;
    expect += 4u * static_cast<uint32_t>(sg::componentCount(out.type));
  }
  EXPECT_EQ(expect, r.glsl.captureStride);
  // Still valid, still links; the computation is the same plan.
  EXPECT_EQ(sg::validateSpirv(r.spirv.words, sg::TargetEnv::Vulkan1_0), "");
  EXPECT_NO_THROW(sg::checkLink(r.glsl, frag.source, kDawnFrag, sg::TargetEnv::Vulkan1_0));
  EXPECT_EQ(r.plan.actions, dawn().plan.actions);
  EXPECT_EQ(outputsOf(r.glsl.text).size(), 6u);
}

// Hostile input (issue 10): names that reach the generated GLSL, and limits checked
// against the generated program.

TEST(GenerateHostile, CommentSafeText) {
  EXPECT_EQ(sg::commentSafe("face\n#error x"), "face?#error x");
  EXPECT_EQ(sg::commentSafe("dir\\"), "dir?");  // a trailing '\' would splice the next line
  EXPECT_EQ(sg::commentSafe("caf\xc3\xa9 ok"), "caf\xc3\xa9 ok");
}

TEST(GenerateHostile, FileNameWithNewlineCannotInjectCode) {
  auto dir = freshDir("inject");
  // The file name ends up in the generated header comment; a newline used to end the
  // comment and the rest compiled as code.
  const std::string name = "x\n#error injected\nfloat injected_decl;\\";
  std::filesystem::copy_file(kDawnFrag, dir / (name + ".frag"));
  sg::GenerateOptions o = dawnOptions();
  o.fragmentPath = (dir / (name + ".frag")).string();
  sg::GenerateResult r = sg::generate(o);
  EXPECT_EQ(r.glsl.text.find("\n#error"), std::string::npos) << r.glsl.text;
  EXPECT_EQ(r.glsl.text.find("\nfloat injected_decl"), std::string::npos) << r.glsl.text;
  EXPECT_NE(r.glsl.text.find("x?#error injected?float injected_decl;?.frag"), std::string::npos) << r.glsl.text;
  std::filesystem::remove_all(dir);
}

TEST(GenerateHostile, UniformBlockLargerThanTheVulkanGuaranteeIsRefused) {
  auto dir = freshDir("ubo");
  std::string rig = sgtest::readFile(kDawnRig);
  size_t at = rig.find("bones: 98");
  ASSERT_NE(at, std::string::npos);
  rig.replace(at, 9, "bones: 300");  // 300 mat4 = 19200 bytes > 16384
  writeText(dir / "big.rig.yaml", rig);
  sg::GenerateOptions o = dawnOptions();
  o.rigPath = (dir / "big.rig.yaml").string();
  // The uniform block is a constraint of the search (issue 14): the palette moves to a
  // storage buffer and the block stays within the limit.
  sg::GenerateResult viaBuffer = sg::generate(o);
  EXPECT_LE(viaBuffer.spirv.uniformBlockSize, 16384u);
  ASSERT_EQ(viaBuffer.glsl.buffers.size(), 1u);
  EXPECT_EQ(viaBuffer.glsl.buffers[0].semantic, "skin.bones_buffer");
  // Without the buffer rules no plan fits: the error names the limit at the palette.
  o.bannedRules = {"skin_matrix_blend_buffer_palette", "skin_matrix_blend_buffered_influences_buffer_palette"};
  auto d = errorOf([&] { sg::generate(o); });
  EXPECT_EQ(d.loc.file, o.rigPath);
  EXPECT_EQ(d.loc.line, lineOf(rig, "bone_xf:"));
  EXPECT_EQ(d.loc.col, 3);
  EXPECT_NE(d.message.find("above the limit of 16384 (maxUniformBufferRange)"), std::string::npos)
      << sg::formatDiagnostic(d);
  EXPECT_NE(d.message.find("uniform u_bone_xf 19200"), std::string::npos) << sg::formatDiagnostic(d);
  // A device with a larger limit accepts the same rig.
  o.maxUniformBlockBytes = 65536;
  EXPECT_GT(sg::generate(o).spirv.uniformBlockSize, 16384u);
  std::filesystem::remove_all(dir);
}

TEST(GenerateHostile, BanMustNameARule) {
  sg::GenerateOptions o = dawnOptions();
  o.bannedRules = {"no_such_rule"};
  auto d = errorOf([&] { sg::generate(o); });
  EXPECT_NE(d.message.find("--ban no_such_rule: no rule of that name"), std::string::npos) << sg::formatDiagnostic(d);
}

}  // namespace

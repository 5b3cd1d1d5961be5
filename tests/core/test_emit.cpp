// The whole generator through generate(): the Dawn face end to end (GLSL that compiles,
// SPIR-V that validates, an interface that links with the fragment shader), determinism,
// dead-code-free plans, GLSL errors mapped back to rules-file lines, unsatisfiable
// requests, and the transform-feedback capture build.
#include <fmt/format.h>
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
#include "pipeline/stages.h"

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

// ---- The generated GLSL reads like a person wrote it (issue 34) --------------------------

const char* const kGlslType = R"((?:float|double|int|uint|bool|[iubd]?vec[234]|mat[234](?:x[234])?))";

struct StyleFinding {
  int line = 0;
  std::string what;
};

// What a reviewer checks, read from the text alone: (1) no declaration in main() reuses the
// name of a global (input, output, uniform, buffer, function) or of a local in an enclosing
// scope; (2) each line of a rule's block is indented two spaces inside main() and two more
// per open brace, and a line continuing a statement more than the statement's first line;
// (3) each rule's block declares the local named for its semantic ("// r -> world.normal"
// declares world_normal, or world_normal_N where that name was taken).
std::vector<StyleFinding> styleFindings(const std::string& glsl) {
  static const std::regex global(std::string(R"(\b)") + kGlslType + R"(\s+(\w+)\s*(?:\[\d*\])?\s*[;(])");
  static const std::regex local(std::string(R"(^\s*)") + kGlslType + R"(\s+(\w+)\s*[=;])");
  static const std::regex rule(R"(^  // \S+ -> (\S+) \(cost \d+\)$)");
  std::vector<StyleFinding> out;
  std::istringstream in(glsl);
  std::string line;
  std::set<std::string> globals;
  std::vector<std::set<std::string>> scopes;  // inside main: one set per open brace
  bool inMain = false, continues = false;
  int n = 0, stmtIndent = 0, depth = 0;
  std::string expectLocal;  // after a rule comment: the semantic's local it declares
  while (std::getline(in, line)) {
    ++n;
    if (!inMain) {
      if (line == "void main() {") {
        inMain = true;
        scopes.emplace_back();
        continue;
      }
      if (line.rfind("//", 0) == 0 || line.rfind("#", 0) == 0) continue;
      for (auto it = std::sregex_iterator(line.begin(), line.end(), global); it != std::sregex_iterator(); ++it)
        globals.insert((*it)[1]);
      continue;
    }
    if (line.rfind("#line ", 0) == 0 || line.empty()) continue;
    if (line == "}" && scopes.size() == 1) break;  // the end of main
    const size_t b = line.find_first_not_of(' ');
    const int indent = static_cast<int>(b);
    std::string code = line.substr(b, line.find("//") == std::string::npos ? std::string::npos : line.find("//") - b);
    while (!code.empty() && code.back() == ' ') code.pop_back();
    // (2) indentation
    if (continues) {
      if (indent <= stmtIndent) out.push_back({n, "a continuation line not indented past its statement"});
    } else {
      const int want = 2 + 2 * std::max(0, depth - (!code.empty() && code[0] == '}' ? 1 : 0));
      if (indent != want) out.push_back({n, fmt::format("indented {} at brace depth {}, not {}", indent, depth, want)});
      stmtIndent = indent;
    }
    if (!code.empty()) continues = code.back() != ';' && code.back() != '{' && code.back() != '}';
    // (3) the rule's local
    std::smatch m;
    if (std::regex_match(line, m, rule)) {
      expectLocal = sg::semanticIdentifier(m[1]);
      continue;
    }
    // (1) declarations
    if (std::regex_search(line, m, local)) {
      const std::string name = m[1];
      if (globals.count(name)) out.push_back({n, "local '" + name + "' hides a global"});
      for (const auto& scope : scopes)
        if (scope.count(name)) out.push_back({n, "local '" + name + "' declared again in its scope or an inner one"});
      scopes.back().insert(name);
      if (!expectLocal.empty() && name != expectLocal && name.rfind(expectLocal + "_", 0) != 0)
        out.push_back({n, "rule block declares '" + name + "', not the local of its semantic ('" + expectLocal + "')"});
    }
    expectLocal.clear();
    for (char c : code) {
      if (c == '{') scopes.emplace_back(), ++depth;
      if (c == '}' && scopes.size() > 1) scopes.pop_back(), --depth;
    }
  }
  return out;
}

std::string describe(const std::vector<StyleFinding>& f, const std::string& glsl) {
  std::string s;
  for (const auto& x : f) s += fmt::format("line {}: {}\n", x.line, x.what);
  return s + glsl;
}

// The checks themselves catch what issue 34 found in the output of the time.
TEST(GeneratedGlslStyle, TheChecksCatchShadowingAndRaggedBlocks) {
  const std::string head = "#version 450\nlayout(location = 1) in vec4 a_normal;\nlayout(location = 0) out vec3 n;\n";
  EXPECT_TRUE(styleFindings(head + "void main() {\n  vec4 n4 = a_normal;\n  n = n4.xyz;\n}\n").empty());
  auto shadow = styleFindings(head + "void main() {\n  vec4 a_normal = a_normal;\n  n = a_normal.xyz;\n}\n");
  ASSERT_EQ(shadow.size(), 1u);
  EXPECT_EQ(shadow[0].line, 5);
  EXPECT_EQ(styleFindings(head + "void main() {\n  vec3 x_;\n  {\n    vec3 x_ = n;\n  }\n}\n").size(), 1u);
  // The skinning blend of the time: a shared snippet's lines at their own YAML indentation.
  const std::string ragged = "void main() {\n  // skin_matrix_blend -> skin.matrix (cost 16)\n  mat4 skin_matrix;\n  {\n"
                             "    vec4 w0_ = a_normal;\n  vec4 c0_ =\n    w0_;\n  }\n}\n";
  auto r = styleFindings(head + ragged);
  ASSERT_EQ(r.size(), 1u) << describe(r, ragged);
  EXPECT_EQ(r[0].line, 9);
  // A rule block whose local is not named for its semantic.
  EXPECT_EQ(styleFindings(head + "void main() {\n  // r -> world.normal (cost 1)\n  vec3 t_world_normal;\n}\n").size(), 1u);
}

// Every example rig and test rig (and the shared glTF models) with every example and test
// fragment shader it can serve: data not written for these checks.
TEST(GeneratedGlslStyle, EveryExampleRigAndRequestReadsCleanly) {
  namespace fs = std::filesystem;
  std::vector<std::string> rigs, frags;
  for (const char* dir : {"examples/dawn", "examples/threejs", "examples/cmake-consumer", "tests/validate/data",
                          "tests/examples/data"})
    for (const auto& e : fs::directory_iterator(kSrc + "/" + dir)) {
      const std::string p = e.path().string();
      if (p.size() > 9 && p.compare(p.size() - 9, 9, ".rig.yaml") == 0) rigs.push_back(p);
    }
  const std::string models = std::string(SG_SHARED_DIR) + "/models";
  for (const char* m : {"CesiumMan/CesiumMan.glb#0/0", "MorphStressTest/MorphStressTest.gltf#0/1",
                        "AnimatedMorphSphere/AnimatedMorphSphere.gltf#0/0", "RiggedFigure/RiggedFigure.glb#0/0"})
    if (fs::exists(models)) rigs.push_back(models + "/" + m);
  for (const char* dir : {"examples/dawn", "examples/threejs", "examples/render", "examples/cmake-consumer",
                          "tests/validate/data", "tests/gltf/data", "tests/examples/data", "tests/bake/data"})
    for (const auto& e : fs::directory_iterator(kSrc + "/" + dir))
      if (e.path().extension() == ".frag") frags.push_back(e.path().string());
  std::sort(rigs.begin(), rigs.end());
  std::sort(frags.begin(), frags.end());
  std::vector<std::vector<std::string>> ruleSets = {{kSrc + "/examples/dawn/rules.yaml"},
                                                    {kStandardRules, kSrc + "/examples/cmake-consumer/prop.rules.yaml"}};
#if defined(SG_SANITIZED)
  ruleSets.pop_back();  // several times slower there: the Dawn rules alone (about 560 pairs)
#endif
  const sg::TemplateSet templates = sg::loadTemplatesStage(kSrc + "/templates");
  std::map<std::string, sg::FragmentInterface> fragments;
  for (const auto& f : frags) fragments.emplace(f, sg::loadFragmentStage(f, sg::TargetEnv::Vulkan1_0));
  int generated = 0, withParts = 0, withBlocks = 0;
  for (const auto& rules : ruleSets) {
    const sg::RuleSet ruleSet = sg::loadRulesStage(rules);
    for (const auto& rigPath : rigs) {
      const sg::Rig rig = sg::loadRigStage(rigPath);
      for (const auto& [fragPath, fragment] : fragments) {
        sg::LoadedInputs in;
        sg::Plan plan;
        try {
          in = sg::instantiateStage(rig, ruleSet, fragment, {});
          plan = sg::searchStage(in, sg::SearchOptions{});
        } catch (const sg::InputError&) {
          continue;  // a request this rig cannot serve
        }
        const sg::EmittedGlsl glsl = sg::emitStage(in, plan, templates, sg::EmitOptions{});
        SCOPED_TRACE(rigPath + " x " + fragPath);
        const auto findings = styleFindings(glsl.text);
        EXPECT_TRUE(findings.empty()) << describe(findings, glsl.text);
        ++generated;
        withParts += glsl.text.find("// Attributes read in parts") != std::string::npos;
        withBlocks += glsl.text.find("\n  {\n") != std::string::npos;
      }
    }
  }
  // Enough pairs to mean something, including attributes read in parts and snippet blocks.
  EXPECT_GE(generated, 100);
  EXPECT_GE(withParts, 10);
  EXPECT_GE(withBlocks, 20);
  std::printf("%d rig x request x rules generations checked (%d with attributes read in parts, %d with blocks)\n",
              generated, withParts, withBlocks);
}

// A fragment shader whose inputs take the names the locals would have: the locals give way
// (world_normal_2), the program still compiles and validates, and nothing is hidden.
TEST(GeneratedGlslStyle, LocalsGiveWayToOutputsOfTheSameName) {
  auto dir = freshDir("names");
  const std::string frag = (dir / "names.frag").string();
  writeText(frag, "#version 450\nlayout(location = 0) in vec3 world_normal;\nlayout(location = 1) in vec3 object_normal;\n"
                  "layout(location = 2) in vec3 t_world_normal;\nlayout(location = 0) out vec4 c;\n"
                  "void main() { c = vec4(world_normal + object_normal + t_world_normal, 1.0); }\n");
  sg::GenerateOptions o = dawnOptions();
  o.fragmentPath = frag;
  o.overrides = {{"t_world_normal", {"world.normal"}}};
  sg::GenerateResult r = sg::generate(o);
  EXPECT_TRUE(styleFindings(r.glsl.text).empty()) << describe(styleFindings(r.glsl.text), r.glsl.text);
  EXPECT_NE(r.glsl.text.find("  world_normal = world_normal_2;\n"), std::string::npos) << r.glsl.text;
  EXPECT_NE(r.glsl.text.find("  object_normal = object_normal_2;\n"), std::string::npos) << r.glsl.text;
  EXPECT_NE(r.glsl.text.find("  t_world_normal = world_normal_2;\n"), std::string::npos) << r.glsl.text;
  std::filesystem::remove_all(dir);
}

}  // namespace

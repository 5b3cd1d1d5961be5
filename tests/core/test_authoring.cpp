// Authoring real shaders and rules (issue 17): every unmapped or unproducible fragment
// input in one run with suggestions, naming conventions, matrix and array varyings, rule
// overrides and the scoped check. Validation on lavapipe: tests/validate/test_conventions.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "analysis/check.h"
#include "core_test_util.h"
#include "interface/fragment_interface.h"
#include "interface/suggest.h"
#include "pipeline/generate.h"
#include "rules/rules.h"

namespace {

using namespace sgtest;
const std::string kSrc = SG_SOURCE_DIR;
const std::string kStandard = kSrc + "/rules/standard.yaml";
const std::string kFaceRig = kSrc + "/examples/dawn/face.rig.yaml";

std::string frag(const std::vector<std::string>& decls) {
  std::string s = "#version 450\n";
  for (const auto& d : decls) s += d + "\n";
  return s + "layout(location = 0) out vec4 c;\nvoid main() { c = vec4(1); }\n";
}

// Every diagnostic an InputError carries (primary first).
std::vector<sg::Diagnostic> allErrors(const std::function<void()>& f) {
  try {
    f();
  } catch (const sg::InputError& e) {
    std::vector<sg::Diagnostic> out{e.diagnostic()};
    out.insert(out.end(), e.related.begin(), e.related.end());
    return out;
  }
  ADD_FAILURE() << "expected sg::InputError";
  return {};
}

bool has(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

// ---- all problems in one run ------------------------------------------------------------

TEST(Authoring, FourUnmappedInputsFourLocatedErrorsWithSuggestions) {
  sg::RuleSet rules = sg::loadRules({kStandard});
  const std::string src = frag({"layout(location = 0) in vec3 vWorldPos;", "layout(location = 1) in vec3 v_nrm;",
                                "layout(location = 2) in vec2 v_tex_coord_0;", "layout(location = 3) in vec3 WorldNormalDir;",
                                "layout(location = 4) in vec3 world_normal;"});
  sg::FragmentInterface fi = sg::reflectFragmentSource(src, "four.frag");
  auto errs = allErrors([&] { sg::bindVaryings(fi, rules, {}, {"none"}); });
  ASSERT_EQ(errs.size(), 4u);  // world_normal binds by its name
  const std::vector<std::pair<std::string, std::string>> expect{{"vWorldPos", "did you mean world.position (vec3)"},
                                                                {"v_nrm", "did you mean world.normal (vec3)"},
                                                                {"v_tex_coord_0", "did you mean vertex.texcoord0 (vec2)"},
                                                                {"WorldNormalDir", "did you mean world.normal (vec3)"}};
  for (size_t i = 0; i < 4; ++i) {
    SCOPED_TRACE(expect[i].first);
    EXPECT_EQ(errs[i].loc.file, "four.frag");
    EXPECT_EQ(errs[i].loc.line, static_cast<int>(i) + 2);  // each at its own declaration
    EXPECT_EQ(errs[i].loc.col, 30);
    EXPECT_TRUE(has(errs[i].message, "'" + expect[i].first + "' does not name a semantic")) << errs[i].message;
    EXPECT_TRUE(has(errs[i].message, expect[i].second)) << errs[i].message;
  }
}

TEST(Authoring, UnmappedAndUnproducibleTogetherThroughTheInstantiateStage) {
  // vertex.color0 is mapped (by its name) but the face rig has no colour; Bogus maps to
  // nothing. Both come back at once, each at its declaration, the first with the missing input.
  const std::string src = frag({"layout(location = 0) in vec4 vertex_color0;", "layout(location = 1) in vec3 Bogus;",
                                "layout(location = 2) in vec3 world_normal;"});
  sg::FragmentInterface fi = sg::reflectFragmentSource(src, "two.frag");
  auto errs = allErrors([&] {
    sg::instantiateStage(sg::loadRigFile(kFaceRig), sg::loadRules({kStandard}), fi, {});
  });
  ASSERT_EQ(errs.size(), 2u);
  EXPECT_EQ(errs[0].loc.line, 2);
  EXPECT_TRUE(has(errs[0].message, "cannot produce 'vertex.color0' (requested by vertex_color0)")) << errs[0].message;
  EXPECT_TRUE(has(errs[0].message, "possible if the rig also provided {vertex.color0}")) << errs[0].message;
  EXPECT_EQ(errs[1].loc.line, 3);
  EXPECT_TRUE(has(errs[1].message, "'Bogus' does not name a semantic")) << errs[1].message;
}

TEST(Authoring, EveryUnproducibleInputIsReportedWithItsMissingRigInputs) {
  // Without the binormal rules every frame row is unproducible: three errors, one per input,
  // from the search stage (all inputs map).
  sg::RuleSet rules = sg::loadRules({kStandard});
  sg::loadRulesText(rules, "disable: [world_binormal_cross]\n", "user.yaml");
  const std::string src = frag({"layout(location = 0) in vec3 frame_row_x;", "layout(location = 1) in vec3 frame_row_y;",
                                "layout(location = 2) in vec3 world_eye_dir;", "layout(location = 3) in vec3 frame_row_z;"});
  sg::FragmentInterface fi = sg::reflectFragmentSource(src, "rows.frag");
  sg::LoadedInputs in = sg::instantiateStage(sg::loadRigFile(kFaceRig), rules, fi, {});
  auto errs = allErrors([&] { sg::searchStage(in, sg::SearchOptions{}); });
  ASSERT_EQ(errs.size(), 3u);
  std::vector<int> lines;
  for (const auto& e : errs) {
    lines.push_back(e.loc.line);
    EXPECT_TRUE(has(e.message, "possible if the rig also provided {world.binormal}")) << e.message;
  }
  EXPECT_EQ(lines, (std::vector<int>{2, 3, 5}));
}

// ---- suggestions ------------------------------------------------------------------------

TEST(Authoring, NameWordsOfEngineNames) {
  using W = std::vector<std::string>;
  EXPECT_EQ(sg::nameWords("vWorldPos", false), (W{"world", "position"}));
  EXPECT_EQ(sg::nameWords("v_texcoord_0", false), (W{"texcoord0"}));
  EXPECT_EQ(sg::nameWords("vertex_worldNormal", false), (W{"world", "normal"}));
  EXPECT_EQ(sg::nameWords("normalWS", false), (W{"normal", "world"}));
  EXPECT_EQ(sg::nameWords("TBNMatrix", false), (W{"tbn", "matrix"}));
  EXPECT_EQ(sg::nameWords("vNormalW", false), (W{"normal", "world"}));
  EXPECT_EQ(sg::nameWords("world.eye_dir", true), (W{"world", "eye", "dir"}));
}

TEST(Authoring, SuggestionsRespectTheScalarKind) {
  sg::RuleSet rules = sg::loadRules({kStandard});
  // A uvec4 'joints' input can only mean an integer semantic; a float one never does.
  EXPECT_TRUE(sg::closestSemantics(rules, "vJoints", sg::Type::UVec4).empty());  // skin.joints is an indexed family
  auto eye = sg::closestSemantics(rules, "v_eye_direction", sg::Type::Vec3);
  ASSERT_FALSE(eye.empty());
  EXPECT_EQ(eye[0], "world.eye_dir");
  EXPECT_TRUE(sg::closestSemantics(rules, "qqq", sg::Type::Vec3).empty());
}

// ---- naming conventions ------------------------------------------------------------------

TEST(Authoring, ConventionsMapEngineNamesByType) {
  sg::RuleSet rules = sg::loadRules({kStandard});
  const std::string src = frag({"layout(location = 0) in vec3 vNormal;", "layout(location = 1) in vec4 vertex_uv01;",
                                "layout(location = 2) in vec4 vertex_worldTangent;", "layout(location = 3) in mat3 v_TBN;",
                                "layout(location = 6) in vec2 v_texcoord_0;", "layout(location = 7) in vec3 worldEyeDir;"});
  sg::FragmentInterface fi = sg::reflectFragmentSource(src, "conv.frag");
  std::vector<sg::Varying> v = sg::bindVaryings(fi, rules, {});
  ASSERT_EQ(v.size(), 7u);
  using S = std::vector<std::string>;
  EXPECT_EQ(v[1].semantics, S{"eye.normal"});  // three.js: view space
  EXPECT_EQ(v[2].semantics, (S{"vertex.texcoord0", "vertex.texcoord1"}));  // Filament's vec4 form
  EXPECT_EQ(v[3].semantics, (S{"world.tangent", "world.handedness"}));
  EXPECT_EQ(v[4].semantics, (S{"world.tangent", "world.binormal", "world.normal"}));
  EXPECT_EQ(v[4].type, sg::Type::Mat3);
  EXPECT_EQ(v[5].semantics, S{"vertex.texcoord0"});
  EXPECT_EQ(v[6].semantics, S{"world.eye_dir"});  // this project's own name, camelCase
  EXPECT_EQ(v[6].via, "its name");
  EXPECT_TRUE(has(v[1].via, "threejs")) << v[1].via;
  // The vec2 form of vertex_uv01 is uv0 alone; a vec3 vColor matches no convention.
  sg::FragmentInterface f2 = sg::reflectFragmentSource(
      frag({"layout(location = 0) in vec2 vertex_uv01;", "layout(location = 1) in vec3 vColor;"}), "c2.frag");
  auto errs = allErrors([&] { sg::bindVaryings(f2, rules, {}); });
  ASSERT_EQ(errs.size(), 1u);
  EXPECT_TRUE(has(errs[0].message, "convention 'threejs' maps 'vColor' only as vec4")) << errs[0].message;
  sg::FragmentInterface f3 = sg::reflectFragmentSource(frag({"layout(location = 0) in vec2 vertex_uv01;"}), "c3.frag");
  EXPECT_EQ(sg::bindVaryings(f3, rules, {})[1].semantics, S{"vertex.texcoord0"});
}

TEST(Authoring, AmbiguousNamesNeedAChoiceAndChoicesHavePrecedence) {
  sg::RuleSet rules = sg::loadRules({kStandard});
  sg::loadRulesText(rules,
                    "conventions:\n"
                    "  mine:\n"
                    "    names:\n"
                    "      vNormal: world.normal\n",
                    "mine.yaml");
  sg::FragmentInterface fi = sg::reflectFragmentSource(frag({"layout(location = 0) in vec3 vNormal;"}), "n.frag");
  auto d = errorOf([&] { sg::bindVaryings(fi, rules, {}); });
  EXPECT_TRUE(has(d.message, "'vNormal' is ambiguous across naming conventions (eye.normal in 'threejs', "
                             "world.normal in 'mine')"))
      << d.message;
  EXPECT_EQ(sg::bindVaryings(fi, rules, {}, {"mine"})[1].semantics, std::vector<std::string>{"world.normal"});
  EXPECT_EQ(sg::bindVaryings(fi, rules, {}, {"threejs", "mine"})[1].semantics, std::vector<std::string>{"eye.normal"});
  EXPECT_EQ(sg::bindVaryings(fi, rules, {}, {"mine", "threejs"})[1].semantics, std::vector<std::string>{"world.normal"});
  // --map and the rules' varyings still win over every convention.
  EXPECT_EQ(sg::bindVaryings(fi, rules, {{"vNormal", {"object.normal"}}}, {"mine"})[1].semantics,
            std::vector<std::string>{"object.normal"});
  auto none = errorOf([&] { sg::bindVaryings(fi, rules, {}, {"none"}); });
  EXPECT_TRUE(has(none.message, "does not name a semantic")) << none.message;
  auto unknown = errorOf([&] { sg::bindVaryings(fi, rules, {}, {"threej"}); });
  EXPECT_TRUE(has(unknown.message, "--conventions threej: no convention of that name")) << unknown.message;
  EXPECT_TRUE(has(unknown.message, "threejs")) << unknown.message;
}

TEST(Authoring, ConventionErrorsAreLocated) {
  sg::RuleSet rules = sg::loadRules({kStandard});
  auto d = errorOf([&] { sg::loadRulesText(rules, "conventions:\n  threejs:\n    names: {a: world.normal}\n", "dup.yaml"); });
  EXPECT_EQ(d.loc.line, 2);
  EXPECT_TRUE(has(d.message, "convention 'threejs' is defined twice")) << d.message;
  sg::RuleSet r2 = sg::loadRules({kStandard});
  auto t = errorOf([&] { sg::loadRulesText(r2, "conventions:\n  x:\n    names:\n      a: { vec5: world.normal }\n", "t.yaml"); });
  EXPECT_EQ(t.loc.line, 4);
  EXPECT_EQ(t.loc.col, 12);
  EXPECT_TRUE(has(t.message, "unknown type 'vec5'")) << t.message;
  // An entry naming an unknown semantic fails where it is used, at the entry.
  sg::RuleSet r3 = sg::loadRules({kStandard});
  sg::loadRulesText(r3, "conventions:\n  x:\n    names:\n      vFoo: world.nope\n", "u.yaml");
  sg::FragmentInterface fi = sg::reflectFragmentSource(frag({"layout(location = 0) in vec3 vFoo;"}), "f.frag");
  auto u = errorOf([&] { sg::bindVaryings(fi, r3, {}); });
  EXPECT_EQ(u.loc.file, "u.yaml");
  EXPECT_EQ(u.loc.line, 4);
  EXPECT_TRUE(has(u.message, "unknown semantic 'world.nope'")) << u.message;
}

// ---- matrices and arrays ------------------------------------------------------------------

TEST(Authoring, MatrixAndArrayLocationsAndShapes) {
  sg::RuleSet rules = sg::loadRules({kStandard});
  // A mat3 takes three locations: a vec3 at location 2 overlaps it.
  auto d = errorOf([&] {
    sg::reflectFragmentSource(frag({"layout(location = 0) in mat3 v_TBN;", "layout(location = 2) in vec3 world_normal;"}),
                              "o.frag");
  });
  EXPECT_EQ(d.loc.line, 3);  // glslang finds it (our own range check backs it up)
  EXPECT_TRUE(has(d.message, "overlap")) << d.message;
  auto a = errorOf([&] {
    sg::reflectFragmentSource(frag({"layout(location = 0) in vec3 rows[3];", "layout(location = 3) in vec3 n;",
                                    "layout(location = 1) in float f;"}),
                              "a.frag");
  });
  EXPECT_EQ(a.loc.line, 4);
  EXPECT_TRUE(has(a.message, "overlap")) << a.message;
  // Arrays take one semantic per element of the element's type.
  sg::FragmentInterface fi = sg::reflectFragmentSource(frag({"layout(location = 0) in vec3 rows[3];"}), "r.frag");
  EXPECT_EQ(fi.inputs[0].arraySize, 3);
  auto few = errorOf([&] { sg::bindVaryings(fi, rules, {{"rows", {"frame.row_x", "frame.row_y"}}}); });
  EXPECT_TRUE(has(few.message, "is vec3[3]: map it to 3 semantics, one per element (got 2")) << few.message;
  auto kind = errorOf([&] { sg::bindVaryings(fi, rules, {{"rows", {"frame.row_x", "view.ndotv", "frame.row_z"}}}); });
  EXPECT_TRUE(has(kind.message, "each element takes one vec3 semantic, but 'view.ndotv' is float")) << kind.message;
  auto v = sg::bindVaryings(fi, rules, {{"rows", {"frame.row_x", "frame.row_y", "frame.row_z"}}});
  EXPECT_EQ(v[1].arraySize, 3);
  // A mat4 is filled by 16 components, column by column.
  sg::FragmentInterface m4 = sg::reflectFragmentSource(frag({"layout(location = 0) in mat4 M;"}), "m.frag");
  auto short4 = errorOf([&] { sg::bindVaryings(m4, rules, {{"M", {"eye.position", "eye.position", "eye.position"}}}); });
  EXPECT_TRUE(has(short4.message, "is mat4 (16 components, filled column by column) but its packed semantics have 12"))
      << short4.message;
}

TEST(Authoring, MatrixAndArrayVaryingsAreEmittedAndLinked) {
  sg::GenerateOptions o;
  o.rigPath = kFaceRig;
  o.rulesPaths = {kStandard};
  auto dir = freshDir("emit");
  writeText(dir / "m.frag", frag({"layout(location = 0) in mat3 v_TBN;", "layout(location = 3) in vec3 rows[3];",
                                  "layout(location = 6) in vec4 vertex_uv01;"}));
  o.fragmentPath = (dir / "m.frag").string();
  o.overrides = {{"rows", {"frame.row_x", "frame.row_y", "frame.row_z"}}};
  o.capture = true;
  sg::GenerateResult r = sg::generate(o);  // compiles, validates and link-checks with the fragment shader
  EXPECT_TRUE(has(r.glsl.text, "layout(location = 0, xfb_buffer = 0, xfb_offset = 16, xfb_stride = 104) out mat3 v_TBN;"))
      << r.glsl.text;
  EXPECT_TRUE(has(r.glsl.text, "out vec3 rows[3];")) << r.glsl.text;
  EXPECT_TRUE(has(r.glsl.text, "v_TBN = mat3(world_tangent, world_binormal, world_normal);")) << r.glsl.text;
  EXPECT_TRUE(has(r.glsl.text, "rows[2] = frame_row_z;")) << r.glsl.text;
  ASSERT_EQ(r.glsl.outputs.size(), 4u);
  EXPECT_EQ(r.glsl.outputs[2].captureOffset, 16u + 36u);  // after gl_Position and 9 floats
  EXPECT_EQ(r.glsl.outputs[3].captureOffset, 16u + 36u + 36u);
  EXPECT_EQ(r.glsl.captureStride, 16u + 36u + 36u + 16u);
}

// ---- overrides ------------------------------------------------------------------------------

const char* kOverride =
    "include: [standard.yaml]\n"
    "disable: [world_handedness_from_binormal]\n"
    "rules:\n"
    "  - name: world_eye_dir\n"
    "    override: true\n"
    "    produces: world.eye_dir\n"
    "    needs: [world.position, camera.position]\n"
    "    cost: 4\n"
    "    glsl: |\n"
    "      ${out} = normalize(${world.position} - ${camera.position});\n";

TEST(Authoring, OverrideReplacesInPlaceAndDisableRemoves) {
  auto dir = freshDir("ov");
  std::filesystem::copy(kSrc + "/rules", dir, std::filesystem::copy_options::recursive);
  writeText(dir / "user.yaml", kOverride);
  sg::RuleSet base = sg::loadRules({kStandard});
  sg::RuleSet rules = sg::loadRules({(dir / "user.yaml").string()});
  ASSERT_EQ(rules.rules.size(), base.rules.size() - 1);
  auto pos = [](const sg::RuleSet& s, const std::string& n) {
    for (size_t i = 0; i < s.rules.size(); ++i)
      if (s.rules[i].name == n) return static_cast<int>(i);
    return -1;
  };
  EXPECT_EQ(pos(rules, "world_handedness_from_binormal"), -1);
  int at = pos(rules, "world_eye_dir");
  ASSERT_GE(at, 0);
  EXPECT_EQ(rules.rules[at].loc.file, (dir / "user.yaml").string());
  EXPECT_EQ(rules.rules[at].loc.line, 4);
  // The replaced rule keeps its place (rules before it are unchanged, the disabled one aside).
  EXPECT_EQ(at, pos(base, "world_eye_dir") - (pos(base, "world_handedness_from_binormal") < pos(base, "world_eye_dir")));
  ASSERT_EQ(rules.changes.size(), 2u);
  EXPECT_TRUE(rules.changes[0].disabled);
  EXPECT_EQ(rules.changes[0].loc.line, 2);
  EXPECT_FALSE(rules.changes[1].disabled);
  EXPECT_TRUE(has(rules.changes[1].original.file, "view.yaml"));
  // The override's cost is the one the search pays.
  sg::FragmentInterface fi = sg::reflectFragmentSource(frag({"layout(location = 0) in vec3 world_eye_dir;"}), "e.frag");
  sg::LoadedInputs in = sg::instantiateStage(sg::loadRigFile(kFaceRig), rules, fi, {});
  sg::Plan p = sg::searchStage(in, sg::SearchOptions{});
  bool found = false;
  for (int a : p.actions)
    if (in.problem.actions[a].name == "world_eye_dir") found = in.problem.actions[a].cost == 4;
  EXPECT_TRUE(found);
}

TEST(Authoring, OverrideErrors) {
  auto dir = freshDir("ove");
  std::filesystem::copy(kSrc + "/rules", dir, std::filesystem::copy_options::recursive);
  auto load = [&](const std::string& text) {
    writeText(dir / "u.yaml", text);
    return errorOf([&] { sg::loadRules({(dir / "u.yaml").string()}); });
  };
  std::string rule = "    produces: world.eye_dir\n    needs: [world.position]\n    cost: 1\n    glsl: \"${out} = ${world.position};\"\n";
  auto twice = load("include: [view.yaml]\nrules:\n  - name: world_eye_dir\n" + rule);
  EXPECT_EQ(twice.loc.line, 3);
  EXPECT_TRUE(has(twice.message, "defined twice") && has(twice.message, "add 'override: true'")) << twice.message;
  auto nothing = load("include: [view.yaml]\nrules:\n  - name: no_such_rule\n    override: true\n" + rule);
  EXPECT_EQ(nothing.loc.line, 3);
  EXPECT_EQ(nothing.loc.col, 11);
  EXPECT_TRUE(has(nothing.message, "'override: true' but no file loaded before this one defines a rule 'no_such_rule'"))
      << nothing.message;
  auto disabled = load("include: [view.yaml]\ndisable: [world_eye_dir]\nrules:\n  - name: world_eye_dir\n    override: true\n" + rule);
  EXPECT_TRUE(has(disabled.message, "that rule was disabled at")) << disabled.message;
  auto unknown = load("include: [view.yaml]\ndisable: [world_eye_dri]\n");
  EXPECT_EQ(unknown.loc.line, 2);
  EXPECT_EQ(unknown.loc.col, 11);
  EXPECT_TRUE(has(unknown.message, "disable: no rule 'world_eye_dri'")) << unknown.message;
  auto own = load("rules:\n  - name: a\n" + rule + "  - name: a\n    override: true\n" + rule);
  EXPECT_TRUE(has(own.message, "overrides a rule of its own file")) << own.message;
  auto notBool = load("include: [view.yaml]\nrules:\n  - name: world_eye_dir\n    override: maybe\n" + rule);
  EXPECT_EQ(notBool.loc.line, 4);
}

// ---- the scoped check --------------------------------------------------------------------------

TEST(Authoring, CheckReportsOnTheNamedFilesOnly) {
  auto dir = freshDir("chk");
  std::filesystem::copy(kSrc + "/rules", dir, std::filesystem::copy_options::recursive);
  // A user file with one warning of its own (a stated cost far from the measured one) and
  // an override; the library's own cost warnings are in included files.
  writeText(dir / "user.yaml", std::string(kOverride) +
                                   "  - name: my_normal_twice\n    produces: world.normal\n    needs: [object.normal]\n"
                                   "    cost: 1\n    glsl: |\n      ${out} = normalize(normalize(normalize(${object.normal})));\n");
  sg::CheckOptions o;
  o.rulesPaths = {(dir / "user.yaml").string()};
  sg::CheckReport scoped = sg::checkRules(o);
  o.all = true;
  sg::CheckReport all = sg::checkRules(o);
  EXPECT_EQ(scoped.errors, 0) << sg::formatCheckReport(scoped);
  ASSERT_GT(all.findings.size(), scoped.findings.size());
  for (const auto& d : scoped.findings) EXPECT_EQ(d.loc.file, (dir / "user.yaml").string()) << d.message;
  EXPECT_EQ(scoped.hiddenWarnings, static_cast<int>(all.findings.size() - scoped.findings.size()));
  int notes = 0;
  for (const auto& d : scoped.findings) notes += d.severity == sg::Severity::Note;
  EXPECT_EQ(notes, 2);  // the override and the disable
  EXPECT_EQ(scoped.warnings, 1) << sg::formatCheckReport(scoped);
  std::string text = sg::formatCheckReport(scoped);
  EXPECT_TRUE(has(text, "warnings and notes in included files not shown (--all shows them)")) << text;
  // --Werror: the warning becomes an error.
  o.all = false;
  o.werror = true;
  sg::CheckReport strict = sg::checkRules(o);
  EXPECT_EQ(strict.errors, 1);
  EXPECT_EQ(strict.warnings, 0);
  EXPECT_TRUE(has(sg::formatCheckReport(strict), "-Werror")) << sg::formatCheckReport(strict);
}

TEST(Authoring, CheckGroupsWarningsByKind) {
  auto dir = freshDir("grp");
  std::filesystem::copy(kSrc + "/rules", dir, std::filesystem::copy_options::recursive);
  std::string text = "include: [standard.yaml]\nrules:\n";
  for (int i = 0; i < 3; ++i)
    text += "  - name: n" + std::to_string(i) + "\n    produces: world.normal\n    needs: [object.normal]\n    cost: 1\n"
            "    glsl: |\n      ${out} = normalize(normalize(normalize(${object.normal})));\n";
  writeText(dir / "g.yaml", text);
  sg::CheckOptions o;
  o.rulesPaths = {(dir / "g.yaml").string()};
  sg::CheckReport r = sg::checkRules(o);
  ASSERT_FALSE(r.groups.empty()) << sg::formatCheckReport(r);
  EXPECT_EQ(r.groups[0].count, 3) << sg::formatCheckReport(r);
  EXPECT_TRUE(has(r.groups[0].kind, "rule '\u2026' states cost 1")) << r.groups[0].kind;
}

TEST(Authoring, CheckValidatesConventionEntries) {
  auto dir = freshDir("conv");
  writeText(dir / "c.yaml",
            "semantics:\n  world.normal: vec3\n  world.handedness: float\n"
            "conventions:\n  mine:\n    names:\n      vNrm: world.nrmal\n"
            "      vTan: { vec3: [world.normal, world.handedness] }\n");
  sg::CheckOptions o;
  o.rulesPaths = {(dir / "c.yaml").string()};
  o.compileSnippets = false;
  sg::CheckReport r = sg::checkRules(o);
  ASSERT_EQ(r.errors, 2) << sg::formatCheckReport(r);
  EXPECT_EQ(r.findings[0].loc.line, 7);
  EXPECT_TRUE(has(r.findings[0].message, "unknown semantic 'world.nrmal'")) << r.findings[0].message;
  EXPECT_TRUE(has(r.findings[0].message, "world.normal")) << r.findings[0].message;  // did you mean
  EXPECT_EQ(r.findings[1].loc.line, 8);
  EXPECT_TRUE(has(r.findings[1].message, "maps vec3 'vTan' to 4 components; a vec3 has 3")) << r.findings[1].message;
}

}  // namespace

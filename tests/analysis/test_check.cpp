// `shadergen check` (generator/analysis/check.h): every kind of finding from a bad rules
// file, located at the exact line and column of the offending YAML; and snippet compile
// errors reported at the rule's YAML line through `shadergen generate`.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <string>

#include "analysis/check.h"
#include "analysis_test_util.h"
#include "common/diagnostics.h"

namespace sg {
namespace {

using sg::testing::lineColOf;
using sg::testing::runCli;
using sg::testing::scratchDir;
using sg::testing::writeFile;

// A small, clean vocabulary the bad files below start from.
const char* kSemantics = R"(semantics:
  vertex.position: vec3
  vertex.normal: vec3
  camera.view_projection: mat4
  morph.position: { type: vec3, count: morph_targets }
  morph.weights: { type: float, array: morph_targets }
  object.position: vec3
  world.normal: vec3
  clip.position: vec4
)";

const char* kGoodRules = R"(rules:
  - name: object_position
    produces: object.position
    needs: [vertex.position]
    cost: 0
    glsl: |
      ${out} = ${vertex.position};

  - name: world_normal
    produces: world.normal
    needs: [vertex.normal]
    cost: 3
    glsl: |
      ${out} = normalize(${vertex.normal});

  - name: clip
    produces: clip.position
    needs: [object.position, camera.view_projection]
    cost: 4
    glsl: |
      ${out} = ${camera.view_projection} * vec4(${object.position}, 1.0);
)";

const char* kTinyRig = R"(rig: tiny
attributes:
  position: { format: float32x3, provides: vertex.position }
uniforms:
  vp: { type: mat4, semantic: camera.view_projection }
)";

struct Fixture {
  std::string path;
  std::string text;
};

Fixture rulesFile(const std::string& test, const std::string& text) {
  auto dir = scratchDir(test);
  return Fixture{writeFile(dir / "rules.yaml", text), text};
}

CheckReport check(const Fixture& f, const std::string& rig = "") {
  CheckOptions o;
  o.rulesPaths = {f.path};
  o.rigPath = rig;
  return checkRules(o);
}

std::string dump(const CheckReport& r) {
  std::string s;
  for (const auto& d : r.findings) s += formatDiagnostic(d) + "\n";
  return s;
}

// The finding of `sev` at (line, col) of `f` whose message contains `text`.
::testing::AssertionResult hasFinding(const CheckReport& r, const Fixture& f, Severity sev, std::pair<int, int> at,
                                      const std::string& text) {
  for (const auto& d : r.findings)
    if (d.severity == sev && d.loc.file == f.path && d.loc.line == at.first && d.loc.col == at.second &&
        d.message.find(text) != std::string::npos)
      return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "no " << (sev == Severity::Error ? "error" : "warning") << " at " << f.path
                                       << ":" << at.first << ":" << at.second << " containing '" << text
                                       << "'; findings:\n"
                                       << dump(r);
}

// (line, col) of the n-th occurrence (1-based) of `needle` in `text`.
std::pair<int, int> nth(const std::string& text, const std::string& needle, int n) {
  int line = 1, col = 1, seen = 0;
  for (size_t i = 0; i < text.size(); ++i) {
    if (text.compare(i, needle.size(), needle) == 0 && ++seen == n) return {line, col};
    if (text[i] == '\n') {
      ++line;
      col = 1;
    } else {
      ++col;
    }
  }
  return {0, 0};
}

TEST(Check, CleanFileHasNoFindings) {
  Fixture f = rulesFile("clean", std::string(kSemantics) + kGoodRules);
  CheckReport r = check(f);
  EXPECT_EQ(r.errors, 0) << dump(r);
  EXPECT_EQ(r.warnings, 0) << dump(r);
  auto cli = runCli({"check", f.path});
  EXPECT_EQ(cli.status, 0) << cli.output;
  EXPECT_NE(cli.output.find("0 errors, 0 warnings"), std::string::npos) << cli.output;
}

TEST(Check, SchemaErrorIsReportedAndStops) {
  std::string text = std::string(kSemantics) + R"(rules:
  - name: object_position
    produces: object.position
    needs: [vertex.position]
    cots: 0
    glsl: |
      ${out} = ${vertex.position};
  - name: broken_too
    produces: nowhere
    needs: [vertex.positon]
    cost: 0
    glsl: "${out} = 1.0;"
)";
  Fixture f = rulesFile("schema", text);
  CheckReport r = check(f);
  EXPECT_TRUE(r.schemaError);
  ASSERT_EQ(r.findings.size(), 1u) << dump(r);  // the loader stops at the first
  EXPECT_TRUE(hasFinding(r, f, Severity::Error, lineColOf(text, "cots"), "cots"));
  auto cli = runCli({"check", f.path});
  EXPECT_EQ(cli.status, 1);
  auto [line, col] = lineColOf(text, "cots");
  EXPECT_NE(cli.output.find(fmt::format("rules.yaml:{}:{}: error:", line, col)), std::string::npos) << cli.output;
  EXPECT_NE(cli.output.find("    cots: 0\n"), std::string::npos) << "quotes the YAML line:\n" << cli.output;
}

TEST(Check, MissingCostIsASchemaError) {
  std::string text = std::string(kSemantics) + R"(rules:
  - name: no_cost
    produces: object.position
    needs: [vertex.position]
    glsl: |
      ${out} = ${vertex.position};
)";
  Fixture f = rulesFile("missing_cost", text);
  CheckReport r = check(f);
  ASSERT_EQ(r.errors, 1) << dump(r);
  EXPECT_TRUE(hasFinding(r, f, Severity::Error, lineColOf(text, "name: no_cost"), "has no 'cost'"));
}

TEST(Check, DuplicateRuleName) {
  std::string text = std::string(kSemantics) + kGoodRules + R"(
  - name: world_normal
    produces: world.normal
    needs: [vertex.normal]
    cost: 3
    glsl: |
      ${out} = normalize(${vertex.normal});
)";
  Fixture f = rulesFile("duplicate", text);
  CheckReport r = check(f);
  auto at = nth(text, "world_normal", 2);
  at.second += 0;
  EXPECT_TRUE(hasFinding(r, f, Severity::Error, at, "defined twice"));
}

TEST(Check, UnknownSemanticsWithSuggestions) {
  std::string text = std::string(kSemantics) + R"(rules:
  - name: object_position
    produces: object.positoin
    needs: [vertex.positon]
    cost: 0
    glsl: |
      ${out} = ${vertex.position};
  - name: world_normal
    produces: world.normal
    needs: [vertex.normal]
    when: has(vertex.normals)
    cost: 3
    glsl: |
      ${out} = normalize(${vertex.normal});
)";
  Fixture f = rulesFile("unknown", text);
  CheckReport r = check(f);
  EXPECT_TRUE(hasFinding(r, f, Severity::Error, lineColOf(text, "object.positoin"),
                         "produces unknown semantic 'object.positoin' (did you mean 'object.position'?)"));
  EXPECT_TRUE(hasFinding(r, f, Severity::Error, lineColOf(text, "vertex.positon"),
                         "needs unknown semantic 'vertex.positon' (did you mean 'vertex.position'?)"));
  EXPECT_TRUE(hasFinding(r, f, Severity::Error, lineColOf(text, "vertex.normals"), "has(vertex.normals)"));
  EXPECT_EQ(r.errors, 3) << dump(r);
}

TEST(Check, IndexedFamilyMistakes) {
  std::string text = std::string(kSemantics) + R"(rules:
  - name: object_position
    produces: object.position
    needs: [vertex.position, morph.position, morph.weights]
    cost: morph_targets
    glsl: |
      ${out} = ${vertex.position};
  - name: world_normal
    produces: world.normal
    needs: ["vertex.normal[0]"]
    cost: 3
    glsl: |
      ${out} = normalize(${vertex.normal});
  - name: family_product
    produces: morph.position
    needs: [vertex.position]
    cost: 0
    glsl: |
      ${out} = ${vertex.position};
)";
  Fixture f = rulesFile("family", text);
  CheckReport r = check(f);
  EXPECT_TRUE(hasFinding(r, f, Severity::Error, lineColOf(text, "morph.position, morph.weights"),
                         "'morph.position' is an indexed family"));
  EXPECT_TRUE(hasFinding(r, f, Severity::Error, lineColOf(text, "\"vertex.normal[0]\""),
                         "'vertex.normal' is not an indexed family"));
  EXPECT_TRUE(hasFinding(r, f, Severity::Error, nth(text, "morph.position", 3), "which is an indexed family"));
}

TEST(Check, VaryingMistakes) {
  std::string text = std::string(kSemantics) + kGoodRules + R"(varyings:
  Normal: world.normall
  Packed: [world.normal, object.position]
)";
  Fixture f = rulesFile("varyings", text);
  CheckReport r = check(f);
  EXPECT_TRUE(hasFinding(r, f, Severity::Error, lineColOf(text, "Normal:"),
                         "maps to unknown semantic 'world.normall' (did you mean 'world.normal'?)"));
  EXPECT_TRUE(hasFinding(r, f, Severity::Error, lineColOf(text, "Packed:"), "packs 6 components"));
}

// a.x and a.y only derive from each other: every derivation of either needs itself.
const char* kCycle = R"(  a.x: vec3
  a.y: vec3
  a.z: vec3
rules:
  - name: r_y
    produces: a.y
    needs: [a.x]
    cost: 1
    glsl: |
      ${out} = ${a.x};
  - name: r_x
    produces: a.x
    needs: [a.y]
    cost: 1
    glsl: |
      ${out} = ${a.y};
  - name: r_z
    produces: a.z
    needs: [a.x]
    cost: 1
    glsl: |
      ${out} = ${a.x};
)";

TEST(Check, CycleWithNoWayInIsAnError) {
  std::string text = std::string(kSemantics) + kCycle;
  Fixture f = rulesFile("cycle_error", text);
  CheckReport r = check(f);
  EXPECT_TRUE(hasFinding(r, f, Severity::Error, lineColOf(text, "r_y"),
                         "every derivation of 'a.x', 'a.y' needs one of these values itself ('a.x' -> rule 'r_y' -> "
                         "'a.y' -> rule 'r_x' -> 'a.x')"));
  // A rule downstream of the cycle can never fire.
  auto need = nth(text, "[a.x]", 2);
  need.second += 1;
  EXPECT_TRUE(hasFinding(r, f, Severity::Warning, need,
                         "rule 'r_z' can never fire: no derivation of 'a.x' exists (it is on a cycle with no way in)"));
  EXPECT_EQ(r.errors, 1) << dump(r);
}

TEST(Check, CycleWithAWayInIsAWarning) {
  std::string text = std::string(kSemantics) + kCycle + R"(  - name: r_x_from_vertex
    produces: a.x
    needs: [vertex.position]
    cost: 0
    glsl: |
      ${out} = ${vertex.position};
)";
  Fixture f = rulesFile("cycle_warning", text);
  CheckReport r = check(f);
  EXPECT_EQ(r.errors, 0) << dump(r);
  EXPECT_TRUE(hasFinding(r, f, Severity::Warning, lineColOf(text, "r_y"), "rules form a cycle ('a.x' -> rule 'r_y'"));
}

TEST(Check, RuleNeedingItsOwnProduct) {
  std::string text = std::string(kSemantics) + R"(rules:
  - name: selfish
    produces: world.normal
    needs: [vertex.normal, world.normal]
    cost: 1
    glsl: |
      ${out} = ${vertex.normal};
)";
  Fixture f = rulesFile("selfish", text);
  CheckReport r = check(f);
  EXPECT_TRUE(hasFinding(r, f, Severity::Error, lineColOf(text, "world.normal]"), "needs its own product"));
}

TEST(Check, RulesThatNeverFireForTheRig) {
  std::string text = std::string(kSemantics) + kGoodRules + R"(
  - name: rigid_only
    produces: object.position
    needs: [vertex.position]
    when: influences == 1
    cost: 0
    glsl: |
      ${out} = ${vertex.position};
)";
  Fixture f = rulesFile("never_fires", text);
  std::string rig = writeFile(scratchDir("never_fires_rig") / "tiny.rig.yaml", kTinyRig);
  // Without a rig neither finding exists: a rig could provide vertex.normal and have one influence.
  EXPECT_EQ(check(f).warnings, 0) << dump(check(f));
  CheckReport r = check(f, rig);
  EXPECT_TRUE(hasFinding(r, f, Severity::Warning, lineColOf(text, "influences == 1"),
                         "rule 'rigid_only' never fires for rig 'tiny': its 'when' (influences == 1) is false"));
  EXPECT_TRUE(hasFinding(r, f, Severity::Warning, lineColOf(text, "vertex.normal]"),
                         "rule 'world_normal' never fires for rig 'tiny': it needs 'vertex.normal', and the rig does "
                         "not provide it"));
  EXPECT_EQ(r.errors, 0) << dump(r);
}

TEST(Check, ProductsNoVaryingNeeds) {
  // With `varyings:`, world.normal reaches no output (clip.position is always requested).
  std::string text = std::string(kSemantics) + kGoodRules + "varyings:\n  Position: object.position\n";
  Fixture f = rulesFile("dead_product", text);
  CheckReport r = check(f);
  auto at = nth(text, "produces: world.normal", 1);
  at.second += 10;
  EXPECT_TRUE(hasFinding(r, f, Severity::Warning, at,
                         "rule 'world_normal' produces 'world.normal', which no varying needs"));
  EXPECT_EQ(r.warnings, 1) << dump(r);
}

TEST(Check, SnippetThatDoesNotCompile) {
  std::string text = std::string(kSemantics) + R"(rules:
  - name: world_normal
    produces: world.normal
    needs: [vertex.normal]
    cost: 3
    glsl: |
      vec3 n = ${vertex.normal};
      ${out} = normalise(n);
)";
  Fixture f = rulesFile("snippet_error", text);
  CheckReport r = check(f);
  EXPECT_TRUE(hasFinding(r, f, Severity::Error, lineColOf(text, "normalise"), "'normalise'"));
  EXPECT_EQ(r.errors, 1) << dump(r);
  auto cli = runCli({"check", f.path});
  EXPECT_EQ(cli.status, 1);
  auto [line, col] = lineColOf(text, "normalise");
  EXPECT_NE(cli.output.find(fmt::format("rules.yaml:{}:{}: error: 'normalise'", line, col)), std::string::npos)
      << cli.output;
  EXPECT_NE(cli.output.find("        ${out} = normalise(n);\n                 ^"), std::string::npos) << cli.output;
}

TEST(Check, SnippetTypeErrorAgainstTheDeclaredProduct) {
  std::string text = std::string(kSemantics) + R"(rules:
  - name: world_normal
    produces: world.normal
    needs: [vertex.normal]
    cost: 1
    glsl: |
      ${out} = vec4(${vertex.normal}, 0.0);
)";
  Fixture f = rulesFile("snippet_type", text);
  CheckReport r = check(f);
  // glslang quotes the '=' of the assignment.
  EXPECT_TRUE(hasFinding(r, f, Severity::Error, lineColOf(text, "= vec4"), "cannot convert"));
}

TEST(Check, SnippetUsesASemanticNotInNeeds) {
  std::string text = std::string(kSemantics) + R"(rules:
  - name: world_normal
    produces: world.normal
    needs: [vertex.normal]
    cost: 3
    glsl: |
      ${out} = normalize(${vertex.normal} + ${vertex.position});
)";
  Fixture f = rulesFile("snippet_needs", text);
  CheckReport r = check(f);
  EXPECT_TRUE(hasFinding(r, f, Severity::Error, lineColOf(text, "vertex.position}"),
                         "uses 'vertex.position' but does not list it in 'needs'"));
}

TEST(Check, SnippetThatNeverWritesItsProduct) {
  std::string text = std::string(kSemantics) + R"(rules:
  - name: world_normal
    produces: world.normal
    needs: [vertex.normal]
    cost: 3
    glsl: |
      vec3 n = normalize(${vertex.normal});
)";
  Fixture f = rulesFile("snippet_out", text);
  CheckReport r = check(f);
  EXPECT_TRUE(hasFinding(r, f, Severity::Error, lineColOf(text, "|"), "never writes its product"));
}

TEST(Check, StatedCostFarFromMeasured) {
  std::string text = std::string(kSemantics) + R"(rules:
  - name: world_normal
    produces: world.normal
    needs: [vertex.normal, vertex.position]
    cost: 1
    glsl: |
      ${out} = normalize(cross(${vertex.normal}, ${vertex.position}));
)";
  Fixture f = rulesFile("cost_disagrees", text);
  CheckReport r = check(f);
  // cross 2 + normalize 3 = 5 slots (docs/cost-model.md) against a stated 1.
  auto at = lineColOf(text, "cost: 1");
  at.second += 6;
  EXPECT_TRUE(hasFinding(r, f, Severity::Warning, at, "states cost 1 but its snippet measures 5"));
  ASSERT_EQ(r.costs.size(), 1u);
  EXPECT_EQ(r.costs[0].stated, 1);
  EXPECT_EQ(r.costs[0].measured, 5);
  EXPECT_TRUE(r.costs[0].disagrees);
  EXPECT_TRUE(costsDisagree(1, 5));
  EXPECT_FALSE(costsDisagree(3, 6));
  EXPECT_FALSE(costsDisagree(0, 1));
  EXPECT_TRUE(costsDisagree(0, 2));
}

TEST(Check, CostExpressionWithAnUnknownName) {
  std::string text = std::string(kSemantics) + R"(rules:
  - name: object_position
    produces: object.position
    needs: [vertex.position]
    cost: morph_target + 1
    glsl: |
      ${out} = ${vertex.position};
)";
  Fixture f = rulesFile("cost_unknown", text);
  // Without a rig it may be a parameter of some rig: a warning. With a rig: an error.
  CheckReport r = check(f);
  auto at = lineColOf(text, "cost: morph_target");
  at.second += 6;
  EXPECT_TRUE(hasFinding(r, f, Severity::Warning, at, "cannot evaluate 'cost'"));
  EXPECT_TRUE(hasFinding(r, f, Severity::Warning, at, "unknown name 'morph_target'"));
  EXPECT_EQ(r.errors, 0) << dump(r);
  std::string rig = writeFile(scratchDir("cost_unknown_rig") / "tiny.rig.yaml", kTinyRig);
  CheckReport withRig = check(f, rig);
  EXPECT_TRUE(hasFinding(withRig, f, Severity::Error, at, "cannot evaluate 'cost'"));
}

TEST(Check, AutoCostsAreMeasuredNotCompared) {
  std::string text = std::string(kSemantics) + R"(rules:
  - name: world_normal
    produces: world.normal
    needs: [vertex.normal]
    cost: auto
    glsl: |
      ${out} = normalize(${vertex.normal});
)";
  Fixture f = rulesFile("cost_auto", text);
  CheckReport r = check(f);
  EXPECT_EQ(r.errors + r.warnings, 0) << dump(r);
  ASSERT_EQ(r.costs.size(), 1u);
  EXPECT_TRUE(r.costs[0].isAuto);
  EXPECT_EQ(r.costs[0].measured, 3);
}

TEST(Check, WalkThroughDraft) {
  // docs/rules-authoring.md: the draft has a misspelt need and a missing ';'.
  Fixture f{sg::testing::sourceDir() + "/tests/analysis/data/fresnel_draft.yaml", ""};
  f.text = sg::testing::readFile(f.path);
  CheckReport r = check(f, sg::testing::sourceDir() + "/examples/dawn/face.rig.yaml");
  EXPECT_EQ(r.errors, 2) << dump(r);
  EXPECT_TRUE(hasFinding(r, f, Severity::Error, {16, 13}, "did you mean 'view.one_minus_ndotv'?"));
  // Just past the end of the snippet line that lacks its ';'.
  auto [line, col] = lineColOf(f.text, "${out} = ${view.one_minus_ndotv_sq}");
  std::string snippet = "${out} = ${view.one_minus_ndotv_sq} * ${view.one_minus_ndotv_sq} * ${view.one_minus_ndotv}";
  EXPECT_EQ(line, 27);
  EXPECT_TRUE(hasFinding(r, f, Severity::Error, {27, col + static_cast<int>(snippet.size())}, "syntax error"));
}

TEST(Check, StandardLibraryHasNoErrors) {
  CheckOptions o;
  o.rulesPaths = {sg::testing::sourceDir() + "/rules/standard.yaml"};
  CheckReport r = checkRules(o);
  EXPECT_EQ(r.errors, 0) << dump(r);
  o.rulesPaths = {sg::testing::sourceDir() + "/examples/dawn/rules.yaml"};
  o.rigPath = sg::testing::sourceDir() + "/examples/dawn/face.rig.yaml";
  r = checkRules(o);
  EXPECT_EQ(r.errors, 0) << dump(r);
}

// ---------------------------------------------------------------------------
// Snippet errors through `shadergen generate`: the emitted #line directives map
// glslang's messages back to the rule's YAML line; the column is the quoted token.

const char* kTinyFrag = R"(#version 450
layout(location = 0) in vec3 world_normal;
layout(location = 0) out vec4 color;
void main() { color = vec4(world_normal, 1.0); }
)";

TEST(SnippetErrors, GenerateReportsTheYamlLineAndColumn) {
  auto dir = scratchDir("generate_snippet_error");
  std::string text = R"(semantics:
  vertex.position: vec3
  camera.view_projection: mat4
  world.normal: vec3
  clip.position: vec4
rules:
  - name: clip
    produces: clip.position
    needs: [vertex.position, camera.view_projection]
    cost: 4
    glsl: |
      ${out} = ${camera.view_projection} * vec4(${vertex.position}, 1.0);
  - name: fake_normal
    produces: world.normal
    needs: [vertex.position]
    cost: 3
    glsl: |
      vec3 p = ${vertex.position};
      @for i in 2
      p = p * 0.5;
      @end
      ${out} = normalise(p);
)";
  std::string rules = writeFile(dir / "rules.yaml", text);
  std::string rig = writeFile(dir / "tiny.rig.yaml", kTinyRig);
  std::string frag = writeFile(dir / "tiny.frag", kTinyFrag);
  std::string out = (dir / "out").string();
  auto r = runCli({"generate", "--rig", rig, "-f", frag, "-r", rules, "-o", out});
  EXPECT_EQ(r.status, 1) << r.output;
  auto [line, col] = lineColOf(text, "normalise");
  EXPECT_EQ(line, 22);
  EXPECT_EQ(col, 16);
  EXPECT_NE(r.output.find(rules + ":22:16: error: 'normalise'"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("      ${out} = normalise(p);\n"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(out + ".spv"));
  EXPECT_FALSE(std::filesystem::exists(out + ".vert"));
}

TEST(SnippetErrors, BrokenStandardRuleInTheDawnPlan) {
  // A copy of the standard library with a typo in the N.V rule the Dawn plan uses.
  auto dir = scratchDir("generate_dawn_snippet_error");
  std::string src = sg::testing::sourceDir();
  for (const auto& e : std::filesystem::directory_iterator(src + "/rules"))
    std::filesystem::copy_file(e.path(), dir / "rules" / e.path().filename(),
                               (std::filesystem::create_directories(dir / "rules"),
                                std::filesystem::copy_options::overwrite_existing));
  std::string view = sg::testing::readFile(dir / "rules/view.yaml");
  const std::string good = "abs(dot(${world.normal}, ${world.eye_dir}))";
  auto at = view.find(good);
  if (at == std::string::npos) GTEST_SKIP() << "rules/view.yaml no longer has the world-space N.V snippet";
  view.replace(at, good.size(), "abs(dott(${world.normal}, ${world.eye_dir}))");
  std::string viewPath = writeFile(dir / "rules/view.yaml", view);
  std::string dawn = sg::testing::readFile(src + "/examples/dawn/rules.yaml");
  auto inc = dawn.find("../../rules/standard.yaml");
  ASSERT_NE(inc, std::string::npos);
  dawn.replace(inc, std::string("../../rules/standard.yaml").size(), "rules/standard.yaml");
  std::string rules = writeFile(dir / "dawn.yaml", dawn);
  auto r = runCli({"generate", "--rig", src + "/examples/dawn/face.rig.yaml", "-f", src + "/examples/dawn/face.frag",
                   "-r", rules, "-o", (dir / "face").string()});
  EXPECT_EQ(r.status, 1) << r.output;
  auto [line, col] = lineColOf(view, "dott(");
  EXPECT_NE(r.output.find(fmt::format("{}:{}:{}: error: 'dott'", viewPath, line, col)), std::string::npos)
      << r.output;
}

}  // namespace
}  // namespace sg

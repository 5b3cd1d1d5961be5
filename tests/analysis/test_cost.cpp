// `cost: auto` (generator/analysis/cost.h): the per-opcode weights of docs/cost-model.md
// on small snippets, agreement with the hand-written costs of the standard library, and
// auto costs resolved before instantiation so `generate` and `explain` use them.
#include <gtest/gtest.h>

#include <map>
#include <sstream>
#include <string>

#include "analysis/check.h"
#include "analysis/cost.h"
#include "analysis/explain.h"
#include "analysis/probe.h"
#include "common/glsl_compile.h"
#include "analysis_test_util.h"
#include "pipeline/generate.h"

namespace sg {
namespace {

using sg::testing::scratchDir;
using sg::testing::sourceDir;
using sg::testing::writeFile;

const char* kVocabulary = R"(semantics:
  a.v3: vec3
  b.v3: vec3
  a.v4: vec4
  a.f: float
  b.f: float
  a.m4: mat4
  skin.bones: { type: mat4, array: bones }
  skin.joints: { type: uvec4, count: 1 }
  morph.weights: { type: float, array: morph_targets }
  morph.deltas: { type: vec3, count: morph_targets }
  out.f: float
  out.v3: vec3
  out.v4: vec4
  out.m4: mat4
)";

// Measures one snippet producing `type` from `needs` on the default rig (morph_targets=2).
int64_t measure(const std::string& produces, const std::string& needs, const std::string& glsl) {
  static int counter = 0;
  auto dir = scratchDir("measure" + std::to_string(counter++));
  std::string text = std::string(kVocabulary) + "rules:\n  - name: probe\n    produces: " + produces +
                     "\n    needs: [" + needs + "]\n    cost: auto\n    glsl: |\n";
  std::istringstream lines(glsl);
  for (std::string l; std::getline(lines, l);) text += "      " + l + "\n";
  RuleSet rs = loadRules({writeFile(dir / "rules.yaml", text)});
  AutoCost c = measureRuleCost(rs, 0, defaultProbeRigs(rs).front());
  EXPECT_TRUE(c.ok) << (c.diagnostics.empty() ? "" : formatDiagnostic(c.diagnostics.front()));
  return c.cost;
}

TEST(AutoCost, WeightsPerOpcodeClass) {
  // Moves and swizzles are free.
  EXPECT_EQ(measure("out.v3", "a.v3", "${out} = ${a.v3}.zyx;"), 0);
  // Arithmetic: one slot per vector instruction.
  EXPECT_EQ(measure("out.v3", "a.v3, b.v3", "${out} = ${a.v3} + ${b.v3};"), 1);
  EXPECT_EQ(measure("out.v3", "a.v3, a.f", "${out} = ${a.f} * ${a.v3};"), 1);
  // A multiply feeding an add is one multiply-add.
  EXPECT_EQ(measure("out.v3", "a.v3, b.v3, a.f", "${out} = ${a.v3} + ${a.f} * ${b.v3};"), 1);
  // GLSL.std.450: dot 1, normalize 3 (DP3, RSQ, MUL), cross 2, length 3, pow 3.
  EXPECT_EQ(measure("out.f", "a.v3, b.v3", "${out} = dot(${a.v3}, ${b.v3});"), 1);
  EXPECT_EQ(measure("out.v3", "a.v3", "${out} = normalize(${a.v3});"), 3);
  EXPECT_EQ(measure("out.v3", "a.v3, b.v3", "${out} = cross(${a.v3}, ${b.v3});"), 2);
  EXPECT_EQ(measure("out.f", "a.v3", "${out} = length(${a.v3});"), 3);
  EXPECT_EQ(measure("out.f", "a.f", "${out} = pow(${a.f}, 5.0);"), 3);
  EXPECT_EQ(measure("out.f", "a.f, b.f", "${out} = ${a.f} / ${b.f};"), 2);
  // Matrices: one slot per column.
  EXPECT_EQ(measure("out.v4", "a.m4, a.v4", "${out} = ${a.m4} * ${a.v4};"), 4);
  EXPECT_EQ(measure("out.v3", "a.m4, a.v3", "${out} = mat3(${a.m4}) * ${a.v3};"), 3);
  // Gathering components of three registers: one write-masked move each.
  EXPECT_EQ(measure("out.v3", "a.m4", "${out} = vec3(${a.m4}[0].z, ${a.m4}[1].z, ${a.m4}[2].z);"), 3);
  // vec4(v, 1.0): one move (the constant comes from a constant register).
  EXPECT_EQ(measure("out.v4", "a.v3", "${out} = vec4(${a.v3}, 1.0);"), 1);
  // Indexing the bone palette by a vertex attribute: one address-register load.
  EXPECT_EQ(measure("out.m4", "skin.bones, \"skin.joints[0]\"", "${out} = ${skin.bones}[${skin.joints[0]}.x];"), 1);
  // Unrolled morph loop: one multiply-add per target (2 on the default rig).
  EXPECT_EQ(measure("out.v3", "a.v3, morph.weights, \"morph.deltas[*]\"",
                    "${out} = ${a.v3};\n@for i in morph_targets\n${out} += ${morph.weights}[${i}] * "
                    "${morph.deltas[i]};\n@end"),
            2);
}

TEST(AutoCost, AgreesWithTheHandWrittenStandardCosts) {
  // Most hand-written costs of the standard library are reproduced exactly on the Dawn rig;
  // none disagree by more than a factor of two except where the snippet's data layout
  // is the point (listed in docs/cost-model.md).
  RuleSet rs = loadRules({sourceDir() + "/examples/dawn/rules.yaml"});
  Rig rig = loadRigFile(sourceDir() + "/examples/dawn/face.rig.yaml");
  ProbeRig pr = probeRigFromRig(rig, rs);
  ExprEnv env = probeEnv(pr);
  std::map<std::string, std::pair<int64_t, int64_t>> got;  // rule -> (stated, measured)
  for (size_t i = 0; i < rs.rules.size(); ++i) {
    const Rule& r = rs.rules[i];
    if (r.costAuto || (!r.when.empty() && r.when.eval(env) == 0)) continue;
    AutoCost c = measureRuleCost(rs, static_cast<int>(i), pr);
    ASSERT_TRUE(c.ok) << r.name;
    got[r.name] = {r.cost.eval(env), c.cost};
  }
  for (const char* exact : {"object_position_morphed", "object_normal_from_normal_occlusion", "normal_occlusion_morphed",
                            "world_normal_from_matrix", "world_tangent_from_matrix", "world_binormal_cross",
                            "frame_row_x", "world_eye_dir", "ndotv_world_space", "one_minus_ndotv", "clip_from_eye"}) {
    ASSERT_TRUE(got.count(exact)) << exact;
    EXPECT_EQ(got[exact].first, got[exact].second) << exact;
  }
  int disagreements = 0;
  for (const auto& [name, c] : got) disagreements += costsDisagree(c.first, c.second) ? 1 : 0;
  EXPECT_LE(disagreements, 1);  // dapple_normal_z_row: a row of a column-major matrix is 3 moves
}

TEST(AutoCost, ResolvedBeforeInstantiation) {
  RuleSet rs = loadRules({sourceDir() + "/tests/analysis/data/fresnel.yaml"});
  Rig rig = loadRigFile(sourceDir() + "/examples/dawn/face.rig.yaml");
  int pow = -1, square = -1;
  for (size_t i = 0; i < rs.rules.size(); ++i) {
    if (rs.rules[i].name == "fresnel_pow") pow = static_cast<int>(i);
    if (rs.rules[i].name == "fresnel_from_square") square = static_cast<int>(i);
  }
  ASSERT_GE(pow, 0);
  ASSERT_GE(square, 0);
  EXPECT_TRUE(rs.rules[pow].cost.empty());
  resolveAutoCosts(rs, rig);
  ExprEnv env = probeEnv(probeRigFromRig(rig, rs));
  EXPECT_EQ(rs.rules[pow].cost.eval(env), 3);     // LG2, MUL, EX2
  EXPECT_EQ(rs.rules[square].cost.eval(env), 2);  // two multiplies
  EXPECT_TRUE(rs.rules[pow].costAuto);
}

TEST(AutoCost, GenerateUsesMeasuredCosts) {
  GenerateOptions o;
  o.rigPath = sourceDir() + "/examples/dawn/face.rig.yaml";
  o.fragmentPath = sourceDir() + "/examples/dawn/face.frag";
  o.rulesPaths = {sourceDir() + "/tests/analysis/data/fresnel.yaml"};
  GenerateResult r = generate(o);
  bool found = false;
  for (int a : r.plan.actions) {
    const Action& act = r.in.problem.actions[a];
    if (act.name == "fresnel_from_square") {
      found = true;
      EXPECT_EQ(act.cost, 2);
    }
    EXPECT_NE(act.name, "fresnel_pow");
  }
  EXPECT_TRUE(found);
  // Banning the winner picks pow at one slot more.
  GenerateOptions banned = o;
  banned.bannedRules = {"fresnel_from_square"};
  EXPECT_EQ(generate(banned).plan.cost, r.plan.cost + 1);
}

TEST(AutoCost, UnmeasurableSnippetIsALocatedError) {
  auto dir = scratchDir("auto_error");
  std::string text = std::string(kVocabulary) + R"(rules:
  - name: broken
    produces: out.v3
    needs: [a.v3]
    cost: auto
    glsl: |
      ${out} = nrmalize(${a.v3});
)";
  std::string path = writeFile(dir / "rules.yaml", text);
  RuleSet rs = loadRules({path});
  Rig rig = loadRigText("rig: r\nattributes:\n  p: { format: float32x3, provides: a.v3 }\n", (dir / "r.yaml").string());
  try {
    resolveAutoCosts(rs, rig);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.diagnostic().loc.file, path);
    auto [line, col] = sg::testing::lineColOf(text, "nrmalize");
    EXPECT_EQ(e.diagnostic().loc.line, line);
    EXPECT_EQ(e.diagnostic().loc.col, col);
  }
}

}  // namespace
}  // namespace sg

namespace sg {
namespace {

// The access terms of one rule of `rs`, measured on `pr`.
RuleAccesses accessesOf(const RuleSet& rs, const std::string& rule, const ProbeRig& pr) {
  for (size_t i = 0; i < rs.rules.size(); ++i)
    if (rs.rules[i].name == rule) {
      RuleAccesses a = measureRuleAccesses(rs, static_cast<int>(i), pr);
      EXPECT_TRUE(a.ok) << rule << (a.diagnostics.empty() ? "" : ": " + formatDiagnostic(a.diagnostics.front()));
      return a;
    }
  ADD_FAILURE() << "no rule " << rule;
  return RuleAccesses{};
}

// The memory terms of the device cost model (docs/device-profiles.md), counted on the
// Dawn face's rules: one element fetch per target of a constant-trip loop (unrolled), one
// palette matrix per influence, each buffer element once however many components are read,
// and none for constant-indexed uniform arrays; and the same fetches in loads of at most 16
// bytes (a vec4): a mat4 is 4, a vec3 or a uvec4 1.
TEST(AccessTerms, CountedOnTheDawnRules) {
  RuleSet rs = loadRules({sourceDir() + "/examples/dawn/rules.yaml"});
  Rig rig = loadRigFile(sourceDir() + "/examples/dawn/face.rig.yaml");
  ProbeRig pr = probeRigFromRig(rig, rs);
  auto accesses = [&](const std::string& rule) { return accessesOf(rs, rule, pr); };
  using Loads = std::map<std::string, int64_t>;
  // 5 targets: a GLSL loop over the deltas buffer, morph weights indexed by the loop counter.
  // A vec3 delta is one element and one load.
  RuleAccesses morph = accesses("object_position_morphed_buffer");
  EXPECT_EQ(morph.bufferLoads, (Loads{{"morph.position_deltas", 5}}));
  EXPECT_EQ(morph.bufferVec4Loads, (Loads{{"morph.position_deltas", 5}}));
  EXPECT_EQ(morph.indexedUniformLoads, 0);  // unrolled: u_morph_weight[0..4] are constant indices
  // The attribute form reads streams and constant-indexed weights only.
  RuleAccesses attr = accesses("object_position_morphed");
  EXPECT_TRUE(attr.bufferLoads.empty());
  EXPECT_EQ(attr.indexedUniformLoads, 0);
  // 4 influences: one mat4 palette entry each (64 bytes: 4 loads), at a joint index read per vertex.
  RuleAccesses skin = accesses("skin_matrix_blend");
  EXPECT_TRUE(skin.bufferLoads.empty());
  EXPECT_EQ(skin.indexedUniformLoads, 4);
  EXPECT_EQ(skin.indexedUniformVec4Loads, 4 * 4);
  // Joints and weights of 4 influences are one uvec4 and one vec4 element: 1 fetch each,
  // although every component is read separately.
  RuleAccesses buffered = accesses("skin_matrix_blend_buffered_influences");
  EXPECT_EQ(buffered.bufferLoads, (Loads{{"skin.joints_buffer", 1}, {"skin.weights_buffer", 1}}));
  EXPECT_EQ(buffered.bufferVec4Loads, (Loads{{"skin.joints_buffer", 1}, {"skin.weights_buffer", 1}}));
  EXPECT_EQ(buffered.indexedUniformLoads, 4);
  EXPECT_EQ(buffered.indexedUniformVec4Loads, 4 * 4);
  // The palette itself from a buffer: 4 matrices fetched from it (16 loads), no indexed uniform load.
  RuleAccesses palette = accesses("skin_matrix_blend_buffer_palette");
  EXPECT_EQ(palette.bufferLoads, (Loads{{"skin.bones_buffer", 4}}));
  EXPECT_EQ(palette.bufferVec4Loads, (Loads{{"skin.bones_buffer", 16}}));
  EXPECT_EQ(palette.indexedUniformLoads, 0);
  // Both from buffers, each bone column loaded where it is summed (bone_blend_columns): still one
  // element per matrix and 4 vec4 loads of it, and the joints' and weights' one element each.
  RuleAccesses both = accesses("skin_matrix_blend_buffered_influences_buffer_palette");
  EXPECT_EQ(both.bufferLoads, (Loads{{"skin.bones_buffer", 4}, {"skin.joints_buffer", 1}, {"skin.weights_buffer", 1}}));
  EXPECT_EQ(both.bufferVec4Loads, (Loads{{"skin.bones_buffer", 16}, {"skin.joints_buffer", 1}, {"skin.weights_buffer", 1}}));
  EXPECT_EQ(both.indexedUniformLoads, 0);
}

}  // namespace
}  // namespace sg

// A palette read at the per-vertex joints by the skin matrix and by a linear blend of the
// position is loaded once (the device's compiler reuses the loads): a plan with both pays
// 4 influences x 4 vec4 loads of a mat4 entry, as a plan with one of them does, not twice.
namespace sg {
namespace {
TEST(AccessTerms, APaletteReadByTwoRulesIsLoadedOnce) {
  GenerateOptions o;
  o.rigPath = sourceDir() + "/examples/dawn/face.rig.yaml";
  o.fragmentPath = sourceDir() + "/examples/dawn/face.frag";
  o.rulesPaths = {sourceDir() + "/examples/dawn/rules.yaml"};
  o.deviceProfilePath = sourceDir() + "/devices/nvidia-h200-roofline.yaml";
  LoadedInputs in = loadInputs(o);
  const Problem& p = in.problem;
  auto action = [&](const std::string& rule) {
    for (size_t i = 0; i < p.actions.size(); ++i)
      if (p.actions[i].name == rule) return static_cast<int>(i);
    ADD_FAILURE() << "no action " << rule;
    return 0;
  };
  const int skin = action("skin_matrix_blend"), blend = action("world_position_linear_blend"),
            buffered = action("skin_matrix_blend_buffered_influences"), bufferPalette = action("skin_matrix_blend_buffer_palette");
  auto vec4Loads = [&](std::vector<int> actions) { return planAmounts(p, actions)[kTermIndexedUniformVec4Loads]; };
  auto elements = [&](std::vector<int> actions) { return planAmounts(p, actions)[kTermIndexedUniformLoads]; };
  EXPECT_EQ(vec4Loads({skin}), 16);
  EXPECT_EQ(vec4Loads({blend}), 16);
  EXPECT_EQ(vec4Loads({skin, blend}), 16);
  EXPECT_EQ(elements({skin, blend}), 4);
  EXPECT_EQ(vec4Loads({buffered}), 16);  // influences from a buffer, the palette still uniform
  // The palette from a storage buffer: no uniform load at all, and its 4 mat4 entries are a
  // table's loads (read at the joints), apart from the influences' per-vertex stream loads.
  EXPECT_EQ(vec4Loads({bufferPalette}), 0);
  EXPECT_EQ(planAmounts(p, {bufferPalette})[kTermBufferTableLoads], 4);
  EXPECT_EQ(planAmounts(p, {bufferPalette})[kTermBufferTableVec4Loads], 16);
  EXPECT_EQ(planAmounts(p, {bufferPalette})[kTermBufferVec4Loads], 0);
  // Influences from buffers: per-vertex stream loads (joints and weights, one vec4 each), no table.
  EXPECT_EQ(planAmounts(p, {buffered})[kTermBufferLoads], 2);
  EXPECT_EQ(planAmounts(p, {buffered})[kTermBufferTableLoads], 0);
  const int both = action("skin_matrix_blend_buffered_influences_buffer_palette");
  EXPECT_EQ(planAmounts(p, {both})[kTermBufferLoads], 2);
  EXPECT_EQ(planAmounts(p, {both})[kTermBufferTableLoads], 4);
  EXPECT_EQ(planAmounts(p, {both})[kTermBufferTableVec4Loads], 16);
}
}  // namespace
}  // namespace sg

// The sparse-morph loop runs min(morph.active_count, max_active_targets) times, a count the
// vocabulary bounds (`bound: max_active_targets`): its loads count once per iteration at that
// bound, as a constant-trip loop's do. Its uniform reads are indexed by the active list, the
// same for every vertex of a draw: one address per warp, as a constant index reads, so they
// are not per-vertex indexed loads.
namespace sg {
namespace {
TEST(AccessTerms, ABoundedLoopCountsEveryIterationAndWarpUniformIndicesAreNotPerVertex) {
  RuleSet rs = loadRules({sourceDir() + "/rules/standard.yaml"});
  Rig rig = loadRigFile(sourceDir() + "/tests/validate/data/face52_sparse.rig.yaml");
  ProbeRig pr = probeRigFromRig(rig, rs);
  ASSERT_EQ(pr.params.at("max_active_targets"), 6);
  auto accesses = [&](const std::string& rule, const ProbeRig& at) { return accessesOf(rs, rule, at); };
  using Loads = std::map<std::string, int64_t>;
  // 6 active targets at most: 6 delta elements, one per iteration.
  RuleAccesses sparse = accesses("object_position_morphed_sparse", pr);
  EXPECT_EQ(sparse.bufferLoads, (Loads{{"morph.position_deltas", 6}}));
  EXPECT_EQ(sparse.indexedUniformLoads, 0);  // morph.weights[active[k]]: one address per warp
  EXPECT_EQ(sparse.indexedUniformVec4Loads, 0);
  RuleAccesses normals = accesses("normal_occlusion_morphed_sparse", pr);
  EXPECT_EQ(normals.bufferLoads, (Loads{{"morph.normal_occlusion_deltas", 6}}));
  // The bound follows the rig's parameter.
  ProbeRig two = pr;
  two.params["max_active_targets"] = 2;
  EXPECT_EQ(accesses("object_position_morphed_sparse", two).bufferLoads, (Loads{{"morph.position_deltas", 2}}));
  // A rig may state up to 65,535 active targets; the loop also stops at the list's size (52).
  ProbeRig most = pr;
  most.params["max_active_targets"] = 65535;
  EXPECT_EQ(accesses("object_position_morphed_sparse", most).bufferLoads, (Loads{{"morph.position_deltas", 52}}));
  // The palette at the per-vertex joints stays a per-vertex indexed load (4 influences), also
  // where the joints are another rule's product (unpacked from a bit-packed attribute): the
  // probe reads such a value as a vertex input, not as a uniform.
  EXPECT_EQ(accesses("skin_matrix_blend", pr).indexedUniformLoads, 4);
  Rig packed = loadRigFile(sourceDir() + "/tests/validate/data/bitpacked.rig.yaml");
  ASSERT_EQ(probeRigFromRig(packed, rs).streams.count("skin.joints[0]"), 0u);
  EXPECT_EQ(accesses("skin_matrix_blend", probeRigFromRig(packed, rs)).indexedUniformLoads, 4);
}

// measureAccesses on hand-written programs: a uniform array read at an index from a vertex
// input, or from a storage buffer read at gl_VertexIndex, or through a local variable holding
// one, is per-vertex; at an index computed from uniforms alone it is not.
TEST(AccessTerms, PerVertexIndicesAreFollowedThroughLoadsLocalsAndArithmetic) {
  auto count = [](const std::string& body) {
    const std::string text = "#version 450\n"
                             "layout(location = 0) in uvec4 joint;\n"
                             "layout(std140, binding = 0) uniform U { mat4 palette[64]; uvec4 base; } u;\n"
                             "layout(std430, binding = 1) readonly buffer B { uvec4 j[]; } b;\n"
                             "layout(location = 0) out vec4 o;\n"
                             "void main() {\n" + body + "}\n";
    CompileResult c = compileGlsl(GlslUnit{Stage::Vertex, text, "accesses.vert", {}}, TargetEnv::Vulkan1_0);
    EXPECT_TRUE(c.ok) << (c.diagnostics.empty() ? "" : formatDiagnostic(c.diagnostics.front()));
    return c.ok ? measureAccesses(optimizeSpirv(c.spirv, TargetEnv::Vulkan1_0)).indexedUniformLoads : -1;
  };
  EXPECT_EQ(count("  o = u.palette[joint.x][0];\n"), 1);
  EXPECT_EQ(count("  o = u.palette[b.j[gl_VertexIndex].y][1];\n"), 1);
  EXPECT_EQ(count("  o = u.palette[(joint.z + u.base.x) & 63u][2];\n"), 1);
  EXPECT_EQ(count("  uint k = u.base.y;\n  if (joint.w > 3u) k = joint.w;\n  o = u.palette[k & 63u][3];\n"), 1);
  EXPECT_EQ(count("  o = u.palette[u.base.x & 63u][0];\n"), 0);
  EXPECT_EQ(count("  o = u.palette[(u.base.x * 3u + u.base.y) & 63u][0] + u.palette[b.j[u.base.z].x & 63u][1];\n"), 0);
  EXPECT_EQ(count("  vec4 s = vec4(0.0);\n  for (uint k = 0u; k < u.base.w; ++k) s += u.palette[k & 63u][0];\n  o = s;\n"), 0);
}

// One rule looping to a count declared with `bound: BOUND`, reading the palette at an index
// that varies per vertex (a.f is neither a rig uniform nor an array).
std::string boundedLoopRules(const std::string& bound) {
  return std::string(kVocabulary) + "  a.count: { type: uint, bound: " + bound + " }\n" + R"(rules:
  - name: looped
    produces: out.m4
    needs: [a.count, a.f, skin.bones]
    cost: 1
    glsl: |
      ${out} = mat4(0.0);
      for (uint k = 0u; k < ${a.count}; ++k) ${out} += ${skin.bones}[(uint(${a.f}) + k) & 3u];
)";
}

// A loop to a count whose bound is larger than any family (a user's rule, no other clamp) is
// counted at most 256 times, so a large bound cannot make the probe unroll for minutes.
TEST(AccessTerms, ALargeBoundIsCountedAtMost256Times) {
  auto dir = scratchDir("bound_cap");
  const std::string text = boundedLoopRules("100000");
  RuleSet rs = loadRules({writeFile(dir / "rules.yaml", text)});
  RuleAccesses a = measureRuleAccesses(rs, 0, defaultProbeRigs(rs).front());
  ASSERT_TRUE(a.ok) << (a.diagnostics.empty() ? "" : formatDiagnostic(a.diagnostics.front()));
  EXPECT_EQ(a.indexedUniformLoads, 256);  // a.f varies per vertex: every iteration's index does
}

// `bound:` names the most a count can be; anything but an integer scalar is refused where it
// is written.
TEST(AccessTerms, ABoundOnANonCountIsALocatedError) {
  auto dir = scratchDir("bound_error");
  const std::string text = "semantics:\n  a.n: { type: uint, bound: max_active_targets }\n  a.f: { type: float, bound: 4 }\n";
  const std::string path = writeFile(dir / "rules.yaml", text);
  try {
    loadRules({path});
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(formatDiagnostic(e.diagnostic()), path + ":3:30: error: semantic 'a.f': 'bound' is for a count (a uint or int scalar), not a float");
  }
  // A bound naming no rig parameter is reported at the name when a rule's accesses are measured.
  const std::string misspelt = boundedLoopRules("mroph_targets");
  const std::string misspeltPath = writeFile(dir / "misspelt.yaml", misspelt);
  RuleSet rs = loadRules({misspeltPath});
  RuleAccesses a = measureRuleAccesses(rs, 0, defaultProbeRigs(rs).front());
  ASSERT_FALSE(a.ok);
  ASSERT_FALSE(a.diagnostics.empty());
  auto [line, col] = sg::testing::lineColOf(misspelt, "mroph_targets");
  EXPECT_EQ(a.diagnostics.front().loc.file, misspeltPath);
  EXPECT_EQ(a.diagnostics.front().loc.line, line);
  EXPECT_EQ(a.diagnostics.front().loc.col, col);
  EXPECT_NE(a.diagnostics.front().message.find("mroph_targets"), std::string::npos);
}
}  // namespace
}  // namespace sg

// Rule-level checking (validate/rule_check.h, `shadergen check --rig`): every rule of the
// standard library run alone on lavapipe against its semantic's definition, on hostile
// inputs, for several rigs; and the drift of issue 23 (a tangent rule without the
// degenerate-tangent fallback) caught and located at the rule, for each tangent rule.
#include <gtest/gtest.h>

#include <filesystem>
#include <map>

#include "test_util.h"
#include "validate/rule_check.h"

namespace sg {
namespace {

using sgtest::RulesCopy;
using sgtest::dataPath;
using sgtest::sourcePath;
using Status = RuleCheckResult::Status;

const std::vector<std::string> kTangentRules = {
    "object_tangent_gram_schmidt", "object_tangent_morphed_gram_schmidt",
    "object_tangent_morphed_buffer_gram_schmidt", "object_tangent_morphed_sparse_gram_schmidt"};

RuleCheckReport checkOn(const std::string& rig, const std::string& rules, std::vector<std::string> only = {}) {
  RuleCheckOptions o;
  o.rigPath = rig;
  o.rulesPaths = {rules};
  o.only = std::move(only);
  return checkRulesOnDevice(o);
}

const RuleCheckResult* find(const RuleCheckReport& r, const std::string& rule) {
  for (const auto& x : r.results)
    if (x.rule == rule) return &x;
  return nullptr;
}

std::string errorsOf(const RuleCheckReport& r) {
  std::string s;
  for (const auto& d : r.errors) s += formatDiagnostic(d) + "\n";
  return s + formatRuleCheckSummary(r);
}

// Every rule is accounted for: it agrees, or it says why it is unchecked or not applicable.
void expectAllAccountedFor(const RuleCheckReport& r) {
  for (const auto& x : r.results) {
    EXPECT_NE(x.status, Status::Disagrees) << x.detail;
    if (x.status != Status::Agrees) EXPECT_FALSE(x.detail.empty()) << x.rule;
  }
}

TEST(RuleCheck, StandardLibraryAgreesForTheDawnFaceIncludingEveryTangentRule) {
  RuleCheckReport r = checkOn(sourcePath("examples/dawn/face.rig.yaml"), sourcePath("rules/standard.yaml"));
  EXPECT_TRUE(r.errors.empty()) << errorsOf(r);
  expectAllAccountedFor(r);
  // The whole library is listed, and the rules the Dawn plan uses really ran.
  EXPECT_GT(r.results.size(), 40u);
  for (const char* rule : {"normal_occlusion_morphed", "object_normal_from_normal_occlusion", "skin_matrix_blend",
                           "world_normal_from_matrix", "world_binormal_cross", "frame_row_x", "ndotv_world_space",
                           "dapple_normal_z_row", "clip_from_eye", "object_position_morphed_buffer",
                           "skin_matrix_blend_buffer_palette", "object_position_morphed_sparse"}) {
    const RuleCheckResult* x = find(r, rule);
    ASSERT_NE(x, nullptr) << rule;
    EXPECT_EQ(x->status, Status::Agrees) << rule << ": " << x->detail;
  }
  // The face's targets do not move its tangents: the morphed forms run on the rig with
  // morphed tangents added, the sparse one with an active-target list too.
  for (const auto& rule : kTangentRules) {
    const RuleCheckResult* x = find(r, rule);
    ASSERT_NE(x, nullptr) << rule;
    EXPECT_EQ(x->status, Status::Agrees) << rule << ": " << x->detail;
  }
  EXPECT_EQ(find(r, "object_tangent_gram_schmidt")->rig, "dawn-face");
  EXPECT_EQ(find(r, "object_tangent_morphed_buffer_gram_schmidt")->rig, "dawn-face + morph.tangent");
  // The tangent rules read object.normal fed from its definition.
  EXPECT_EQ(find(r, "object_tangent_gram_schmidt")->fed, std::vector<std::string>{"object.normal"});
  // Unmorphed forms cannot apply to a morphed face.
  EXPECT_EQ(find(r, "object_position_unmorphed")->status, Status::NotApplicable);
  EXPECT_NE(find(r, "object_position_unmorphed")->detail.find("has(morph.position)"), std::string::npos);
}

// Several rigs: none disagrees, and together they check every rule of the standard
// library (or list it as unchecked, with why): no rule is left untried.
TEST(RuleCheck, StandardLibraryOverSeveralRigsChecksEveryRule) {
  // 16 rigs through every rule: 42 s under ASan, and what it covers beyond the rig-by-rig
  // tests here is the rules library's, not memory safety's. The plain suite runs it (cmake/dev.sh).
  if (sgtest::kSanitized) GTEST_SKIP() << "every rule over 16 rigs: run by the plain suite";
  const std::vector<std::string> rigs = {
      sourcePath("examples/dawn/face.rig.yaml"),         sourcePath("examples/dawn/body.rig.yaml"),
      dataPath("limb8.rig.yaml"),                        dataPath("face52_sparse.rig.yaml"),  // buffer-fed
      dataPath("limb8_palette300.rig.yaml"),             dataPath("rigid1.rig.yaml"),
      dataPath("unskinned_model.rig.yaml"),              dataPath("unskinned_identity.rig.yaml"),
      sourcePath("tests/examples/data/binormal.rig.yaml"), dataPath("bounds.rig.yaml"),  // encoded position and frame
      dataPath("qtangent.rig.yaml"), dataPath("morph_scaled.rig.yaml"),  // the frame as a QTangent, scaled deltas
      dataPath("pbr_character.rig.yaml"),  // view, projection and their product: clip_from_view_projection
      sourcePath("examples/threejs/mesh.rig.yaml"),  // a model-view and a normal matrix: the eye_* forms
      // An snorm8 normal beside a float16 tangent: the hostile antiparallel frame must stay
      // exactly antiparallel as stored, or float32 Gram-Schmidt "disagrees" by 3e-5.
      dataPath("formats_b.rig.yaml"),
      std::string(SG_SHARED_DIR) + "/models/SimpleSkin/SimpleSkin.gltf#0/0"};
  std::map<std::string, Status> best;  // Agrees < Disagrees < Unchecked < NotApplicable < InNoPlan
  for (const auto& rig : rigs) {
    if (rig.find("SimpleSkin") != std::string::npos && !std::filesystem::exists(std::string(SG_SHARED_DIR) + "/models"))
      continue;
    SCOPED_TRACE(rig);
    RuleCheckReport r = checkOn(rig, sourcePath("rules/standard.yaml"));
    for (const auto& x : r.results) {
      // Including world_handedness_from_binormal at the hostile mesh's tangents parallel to
      // the normal, once the sign of a zero determinant (docs/rules-authoring.md).
      EXPECT_NE(x.status, Status::Disagrees) << x.detail;
      if (x.status != Status::Agrees) EXPECT_FALSE(x.detail.empty()) << x.rule;
    }
    for (const auto& x : r.results) {
      auto it = best.find(x.rule);
      if (it == best.end() || x.status < it->second) best[x.rule] = x.status;
    }
  }
  EXPECT_GT(best.size(), 40u);
  for (const auto& [rule, status] : best)
    EXPECT_EQ(status, Status::Agrees) << rule << " is never checked";
}

// Issue 34: a glTF-style PBR character (40 bones, 2 influences, 8 targets moving position
// and normal, no occlusion attribute). The rules reading an occlusion can be in no plan
// for it; run alone they were fed an occlusion the rig does not have (the procedural
// head's), and object_occlusion_from_normal_occlusion "disagreed" (0.734 against 0.725: the
// fed morph.normal_occlusion summed the head's occlusion deltas, which object.occlusion's
// definition leaves out for a rig without morph.occlusion). They are skipped, with why;
// the rules the rig's plans can contain still run.
TEST(RuleCheck, ARigWithoutOcclusionChecksOnlyTheRulesItsPlansCanContain) {
  const std::vector<std::string> rules = {"object_occlusion_from_normal_occlusion", "object_normal_from_normal_occlusion",
                                          "object_visibility", "object_normal_morphed", "object_position_morphed",
                                          "skin_matrix_blend"};
  RuleCheckReport r = checkOn(dataPath("pbr_character.rig.yaml"), sourcePath("rules/standard.yaml"), rules);
  EXPECT_TRUE(r.errors.empty()) << errorsOf(r);
  ASSERT_EQ(r.results.size(), rules.size());
  for (const char* rule : {"object_occlusion_from_normal_occlusion", "object_normal_from_normal_occlusion"}) {
    EXPECT_EQ(find(r, rule)->status, Status::InNoPlan) << rule;
    EXPECT_EQ(find(r, rule)->detail, "needs 'morph.normal_occlusion', which the rig neither provides nor derives");
  }
  // A need behind another: the inputs that would make it derivable are named.
  EXPECT_EQ(find(r, "object_visibility")->status, Status::InNoPlan);
  EXPECT_NE(find(r, "object_visibility")->detail.find("needs 'object.occlusion'"), std::string::npos);
  EXPECT_NE(find(r, "object_visibility")->detail.find("a rig providing {vertex.occlusion} or {morph.normal_occlusion} could"),
            std::string::npos)
      << find(r, "object_visibility")->detail;
  for (const char* rule : {"object_normal_morphed", "object_position_morphed", "skin_matrix_blend"})
    EXPECT_EQ(find(r, rule)->status, Status::Agrees) << rule << ": " << find(r, rule)->detail;
  const std::string summary = formatRuleCheckSummary(r);
  EXPECT_NE(summary.find(": 3 agree, 0 disagree; 3 skipped: in no plan for the rig\n"), std::string::npos) << summary;
  EXPECT_NE(summary.find("skipped, in no plan for the rig:\n  object_normal_from_normal_occlusion: needs"), std::string::npos)
      << summary;
}

// The skip is the rig's, not the rule's: a wrong rule the rig can use still fails, and
// the same wrong rule the rig cannot use fails for a rig that can (the Dawn face stores its
// occlusion in normal.w).
TEST(RuleCheck, APlantedWrongRuleFailsWhereTheRigCanUseIt) {
  const std::string planted = dataPath("planted_wrong.rules.yaml");
  const std::vector<std::string> rules = {"object_normal_morphed", "object_occlusion_from_normal_occlusion"};
  RuleCheckReport pbr = checkOn(dataPath("pbr_character.rig.yaml"), planted, rules);
  ASSERT_EQ(pbr.errors.size(), 1u) << errorsOf(pbr);
  EXPECT_EQ(pbr.errors[0].loc.file, planted);
  EXPECT_EQ(pbr.errors[0].loc.line, 8);  // the overriding rule's name
  EXPECT_NE(pbr.errors[0].message.find("rule 'object_normal_morphed' disagrees with the definition of 'object.normal'"),
            std::string::npos)
      << pbr.errors[0].message;
  EXPECT_EQ(find(pbr, "object_occlusion_from_normal_occlusion")->status, Status::InNoPlan);

  RuleCheckReport dawn = checkOn(sourcePath("examples/dawn/face.rig.yaml"), planted, rules);
  EXPECT_EQ(dawn.errors.size(), 2u) << errorsOf(dawn);
  for (const auto& rule : rules) EXPECT_EQ(find(dawn, rule)->status, Status::Disagrees) << rule;
}

// The drift of issue 23: one tangent rule computing Gram-Schmidt without the fallback
// (its own copy of the text instead of the shared snippet). The check names that rule,
// at its line, with the degenerate input; the others still agree.
TEST(RuleCheck, EachTangentRuleWithoutTheFallbackIsCaughtAtTheRule) {
  for (const auto& rule : kTangentRules) {
    SCOPED_TRACE(rule);
    RulesCopy copy("rulecheck_" + rule);
    const std::string file = rule == "object_tangent_gram_schmidt" || rule == "object_tangent_morphed_gram_schmidt"
                                 ? "morph.yaml"
                                 : "buffers.yaml";
    const std::string input = rule == "object_tangent_gram_schmidt" ? "${vertex.tangent}" : "${out}";
    std::string text = sgtest::readText(copy.rulesFile(file));
    // The rule's own `@use` line: the one after its name.
    const size_t at = text.find("@use tangent_orthonormal(" + input + ", ${object.normal})", text.find("name: " + rule + "\n"));
    ASSERT_NE(at, std::string::npos);
    const std::string line = "@use tangent_orthonormal(" + input + ", ${object.normal})";
    text.replace(at, line.size(),
                 "${out} = normalize(" + input + " - dot(" + input + ", ${object.normal}) * ${object.normal});");
    sgtest::writeText(copy.rulesFile(file), text);

    RuleCheckReport r = checkOn(sourcePath("examples/dawn/face.rig.yaml"), copy.rulesFile("standard.yaml").string(),
                                kTangentRules);
    ASSERT_EQ(r.errors.size(), 1u) << errorsOf(r);
    const Diagnostic& d = r.errors[0];
    EXPECT_EQ(d.loc.file, copy.rulesFile(file).string());
    EXPECT_GT(d.loc.line, 0);
    const std::string msg = formatDiagnostic(d);
    EXPECT_NE(msg.find("error: rule '" + rule + "' disagrees with the definition of 'object.tangent'"), std::string::npos) << msg;
    // The input that shows it: a degenerate tangent of the hostile mesh, and what was read.
    EXPECT_NE(msg.find("vertex 0 of the hostile mesh"), std::string::npos) << msg;
    EXPECT_NE(msg.find("the GPU gives (nan, nan, nan)"), std::string::npos) << msg;
    EXPECT_NE(msg.find(" at input "), std::string::npos) << msg;
    EXPECT_NE(msg.find("vertex.tangent = (0, 0, 0)"), std::string::npos) << msg;
    EXPECT_NE(msg.find("object.normal = ("), std::string::npos) << msg;
    for (const auto& other : kTangentRules)
      if (other != rule) EXPECT_EQ(find(r, other)->status, Status::Agrees) << other;
  }
}

// One text, several fetch forms: a fix (or a break) of the shared snippet lands in every
// tangent rule at once.
TEST(RuleCheck, TheSharedTangentSnippetReachesEveryForm) {
  RulesCopy copy("rulecheck_shared");
  ASSERT_TRUE(copy.edit("vocabulary.yaml", "bvec3(dot(g_, g_) > 1e-6 * dot(t_, t_))", "bvec3(true)"));
  RuleCheckReport r = checkOn(sourcePath("examples/dawn/face.rig.yaml"), copy.rulesFile("standard.yaml").string(),
                              kTangentRules);
  EXPECT_EQ(r.errors.size(), kTangentRules.size()) << errorsOf(r);
  for (const auto& rule : kTangentRules) EXPECT_EQ(find(r, rule)->status, Status::Disagrees) << rule;
}

}  // namespace
}  // namespace sg

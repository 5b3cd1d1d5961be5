// The library's device-profile options (api/shadergen.h): an engine that passes several
// profiles, the workload `explain` prints and bans gets the program `shadergen generate` writes
// with --device-profile (several times), --mesh and --ban: the workload here is measured by the
// CLI's own measuring code (measure/workload.h) and handed over as plain figures.
#include <gtest/gtest.h>

#include <algorithm>

#include "api/shadergen.h"
#include "measure/workload.h"
#include "pipeline/generate.h"

namespace {

const std::string kSrc = SG_SOURCE_DIR;
const std::string kDawn = kSrc + "/examples/dawn/";

// The face under both shipped device profiles, a portable plan.
shadergen::Options faceOptions() {
  shadergen::Options o;
  o.rig = kDawn + "face.rig.yaml";
  o.fragment = kDawn + "face.frag";
  o.rules = {kDawn + "rules.yaml"};
  o.templates = kSrc + "/templates";
  o.deviceProfile = kSrc + "/devices/nvidia-h200-raster.yaml";
  o.portableProfiles = {kSrc + "/devices/llvmpipe-2core.yaml"};
  return o;
}

// What `generate --device-profile A --device-profile B --mesh MESH [--ban ...]` runs.
sg::GenerateResult cliGenerate(const shadergen::Options& lib, const std::string& mesh) {
  sg::GenerateOptions o;
  o.rigPath = lib.rig;
  o.fragmentPath = lib.fragment;
  o.rulesPaths = lib.rules;
  o.templateDir = lib.templates;
  o.deviceProfilePath = lib.deviceProfile;
  o.portableProfilePaths = lib.portableProfiles;
  o.bannedRules = lib.bannedRules;
  o.workload = sg::rigWorkload(o.rigPath, {}, mesh);
  return sg::generate(o);
}

shadergen::Workload figures(const sg::Workload& w) {
  return {w.verticesPerDraw, w.jointsPerWarp, w.activeMorphTargets, w.invocationsPerVertex, w.fragmentsPerVertex};
}

std::string skinBlend(const std::vector<std::string>& rules) {
  for (const auto& r : rules)
    if (r.rfind("skin_matrix_", 0) == 0) return r;
  return "";
}

TEST(ApiProfiles, SeveralProfilesAWorkloadAndBansGiveGeneratesProgram) {
  std::map<std::string, std::string> blendOn;
  for (const std::string mesh : {"head", "dawn"}) {
    shadergen::Options o = faceOptions();
    const sg::GenerateResult cli = cliGenerate(o, mesh);
    o.workload = figures(cli.in.workload);
    const shadergen::Result r = shadergen::generate(o);
    ASSERT_TRUE(r.ok) << (r.diagnostics.empty() ? "" : r.diagnostics[0].text());
    EXPECT_EQ(r.glsl, cli.glsl.text) << mesh;
    EXPECT_EQ(r.spirv, cli.spirv.words) << mesh;
    EXPECT_EQ(r.cost, cli.plan.cost) << mesh;
    EXPECT_GE(r.cost, 1'000'000'000);  // the worst regret times 10^9: at least 1
    blendOn[mesh] = skinBlend(r.rules);
  }
  // The workload reaches the pricing: the face's portable plan blends differently per mesh (under
  // the shipped profiles: the palette in the uniform block at Dawn scale, in a buffer on the head).
  EXPECT_NE(blendOn["dawn"], "");
  EXPECT_NE(blendOn["head"], "");
  EXPECT_NE(blendOn["dawn"], blendOn["head"]);

  // Without the second profile, the first device's own plan: not the portable one (at Dawn scale the
  // H200 alone reads the influences from a buffer).
  shadergen::Options one = faceOptions();
  one.portableProfiles.clear();
  one.workload = figures(sg::rigWorkload(one.rig, {}, "dawn"));
  const shadergen::Result alone = shadergen::generate(one);
  ASSERT_TRUE(alone.ok);
  EXPECT_NE(skinBlend(alone.rules), blendOn["dawn"]);

  // A ban pins another plan, as --ban does.
  shadergen::Options banned = faceOptions();
  banned.bannedRules = {"skin_matrix_blend"};
  const sg::GenerateResult cli = cliGenerate(banned, "dawn");
  banned.workload = figures(cli.in.workload);
  const shadergen::Result b = shadergen::generate(banned);
  ASSERT_TRUE(b.ok);
  EXPECT_EQ(b.glsl, cli.glsl.text);
  EXPECT_EQ(std::count(b.rules.begin(), b.rules.end(), "skin_matrix_blend"), 0);
  EXPECT_NE(skinBlend(b.rules), "");
}

TEST(ApiProfiles, MisusedOptionsAreDiagnosed) {
  shadergen::Options o = faceOptions();
  o.bannedRules = {"skin_matrix_blendd"};
  shadergen::Result r = shadergen::generate(o);
  ASSERT_FALSE(r.ok);
  ASSERT_FALSE(r.diagnostics.empty());
  EXPECT_NE(r.diagnostics[0].message.find("skin_matrix_blendd"), std::string::npos) << r.diagnostics[0].text();

  o = faceOptions();
  o.deviceProfile.clear();  // more profiles, but no first one
  r = shadergen::generate(o);
  ASSERT_FALSE(r.ok);
  EXPECT_NE(r.diagnostics[0].message.find("portable choice needs at least two device profiles"), std::string::npos)
      << r.diagnostics[0].text();
}

}  // namespace

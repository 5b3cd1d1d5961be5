// The calibration corpus (measure/corpus.h): deterministic per seed, varied, and every random
// (rig, request) generates; a few validate on lavapipe against the reference.
#include <gtest/gtest.h>

#include <filesystem>
#include <set>

#include "measure/corpus.h"
#include "pipeline/generate.h"
#include "rig/gltf_import.h"
#include "test_util.h"
#include "validate/validate.h"

namespace sg {
namespace {

using sgtest::kSanitized;
using sgtest::sourcePath;

TEST(Corpus, SameSeedSameCaseOtherSeedOtherCase) {
  const CorpusCase a = randomCorpusCase(7), b = randomCorpusCase(7), c = randomCorpusCase(8);
  EXPECT_EQ(a.rigYaml, b.rigYaml);
  EXPECT_EQ(a.fragment, b.fragment);
  EXPECT_NE(a.rigYaml + a.fragment, c.rigYaml + c.fragment);
  const auto x = randomCorpus(5, 3), y = randomCorpus(5, 3);
  ASSERT_EQ(x.size(), 5u);
  for (size_t i = 0; i < x.size(); ++i) EXPECT_EQ(x[i].rigYaml, y[i].rigYaml);
  EXPECT_NE(randomCorpus(1, 4).front().rigYaml, x.front().rigYaml);
}

// Every case generates with the vocabulary's rules; over the seeds the corpus covers what the
// issue asks of it (a generator stuck on one shape would fail here).
TEST(Corpus, EveryRandomRigAndRequestGeneratesAndTheCorpusVaries) {
  const size_t n = kSanitized ? 12 : 40;
  const std::string dir = (std::filesystem::temp_directory_path() / ("sg_corpus_" + std::to_string(::getpid()))).string();
  std::set<int> influences;
  int unskinned = 0, bigPalette = 0, morphed = 0, manyTargets = 0, buffers = 0;
  for (const CorpusCase& c : randomCorpus(n, 11)) {
    SCOPED_TRACE(c.name + "\n" + c.rigYaml + c.fragment);
    const CorpusFiles f = writeCorpusCase(c, dir);
    GenerateOptions o;
    o.rigPath = f.rig;
    o.fragmentPath = f.fragment;
    o.rulesPaths = {sourcePath("examples/dawn/rules.yaml")};
    GenerateResult r;
    ASSERT_NO_THROW(r = generate(o));
    const Rig& rig = r.in.rig;
    influences.insert(int(rig.param("influences")));
    unskinned += rig.param("influences") == 0;
    bigPalette += rig.param("bones") > 256;
    morphed += rig.morphTargets() > 0;
    manyTargets += rig.morphTargets() > 30;
    buffers += r.glsl.text.find(" buffer ") != std::string::npos;
  }
  std::filesystem::remove_all(dir);
  EXPECT_GE(influences.size(), kSanitized ? 3u : 6u);
  EXPECT_GT(unskinned + morphed, 0);
  if (!kSanitized) {
    EXPECT_GT(unskinned, 0);
    EXPECT_GT(bigPalette, 0);
    EXPECT_GT(manyTargets, 0);
    EXPECT_GT(buffers, 0);  // some plans read storage buffers, others attributes and the uniform block
    EXPECT_LT(buffers, int(n));
  }
}

// Every engine finds plans of the same cost for random rigs under the profiles users pass: the
// H200's roofline, lavapipe's additive profile, and both as a portable choice (least worst-case
// regret, search/device_profile.h). corpus-462381904 (15 morph targets, a 288-bone palette) is
// the case where the integer program once returned a plan of worst regret 2.36x against the
// regression engine's 1.94x (search/ip_oracle.cpp).
TEST(Corpus, EveryEngineFindsTheSameCostUnderEachProfile) {
  const std::string dir = (std::filesystem::temp_directory_path() / ("sg_corpus_e_" + std::to_string(::getpid()))).string();
  std::vector<CorpusCase> cases = randomCorpus(kSanitized ? 2 : 8, 6);
  cases.insert(cases.begin(), randomCorpusCase(462381904));
  const std::string h200 = sourcePath("devices/nvidia-h200-roofline.yaml"), lavapipe = sourcePath("devices/llvmpipe-2core.yaml");
  const std::vector<std::pair<std::string, std::vector<std::string>>> profiles = {
      {h200, {}}, {lavapipe, {}}, {h200, {lavapipe}}};
  for (const CorpusCase& c : cases) {
    SCOPED_TRACE(c.name + "\n" + c.rigYaml + c.fragment);
    const CorpusFiles f = writeCorpusCase(c, dir);
    for (const auto& [profile, portable] : profiles) {
      SCOPED_TRACE(profile + (portable.empty() ? "" : " + " + portable.front()));
      std::vector<int64_t> costs;
      for (const char* engine : {"regression", "ip", "forward"}) {
        GenerateOptions o;
        o.rigPath = f.rig;
        o.fragmentPath = f.fragment;
        o.rulesPaths = {sourcePath("examples/dawn/rules.yaml")};
        o.deviceProfilePath = profile;
        o.portableProfilePaths = portable;
        o.searchEngine = engine;
        GenerateResult r;
        ASSERT_NO_THROW(r = generate(o)) << engine;
        costs.push_back(r.plan.cost);
      }
      EXPECT_EQ(costs[0], costs[1]) << "regression against ip";
      EXPECT_EQ(costs[0], costs[2]) << "regression against forward";
    }
  }
  std::filesystem::remove_all(dir);
}

TEST(Corpus, RandomCasesValidateOnLavapipe) {
  const std::string dir = (std::filesystem::temp_directory_path() / ("sg_corpus_v_" + std::to_string(::getpid()))).string();
  ValidateOptions vo;
  Validator v(vo);
  for (const CorpusCase& c : randomCorpus(kSanitized ? 2 : 6, 5)) {
    SCOPED_TRACE(c.name + "\n" + c.rigYaml + c.fragment);
    const CorpusFiles f = writeCorpusCase(c, dir);
    GenerateOptions o;
    o.rigPath = f.rig;
    o.fragmentPath = f.fragment;
    o.rulesPaths = {sourcePath("examples/dawn/rules.yaml")};
    o.capture = true;
    const ValidationScene scene = proceduralScene(loadRig(f.rig), "limb", 1, 2);
    const ValidateReport rep = v.run(scene, o);
    EXPECT_TRUE(rep.pass);
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace sg

// libFuzzer: the device-profile loader (YAML text → DeviceProfile), then the profile used as
// generate and build use it: the Dawn face priced and searched under it at its stated workload
// and at a measured one (a small draw, a warp reading many joints, past the constant cache),
// alone and as one device of a portable choice beside the shipped lavapipe profile. Besides
// crashes and sanitizer reports, a finding is a plan whose predicted time (predictPlanCost)
// is not its search cost: what explain and the reflection print would then disagree with
// what the search minimised.
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "fuzz_util.h"
#include "pipeline/generate.h"
#include "pipeline/stages.h"
#include "search/device_profile.h"

namespace {

struct Face {
  sg::Rig rig;
  sg::RuleSet rules;
  sg::FragmentInterface fragment;
  sg::DeviceProfile lavapipe;
};
const Face& face() {
  static const Face f = [] {
    const std::string src = SG_SOURCE_DIR;
    return Face{sg::loadRigStage(src + "/examples/dawn/face.rig.yaml"), sg::loadRulesStage({src + "/examples/dawn/rules.yaml"}),
                sg::loadFragmentStage(src + "/examples/dawn/face.frag", sg::TargetEnv::Vulkan1_0),
                sg::loadDeviceProfile(src + "/devices/llvmpipe-2core.yaml")};
  }();
  return f;
}

void searchUnder(const sg::DeviceProfile& profile, const sg::GenerateOptions& opts, bool portable) {
  const Face& f = face();
  std::vector<sg::DeviceProfile> others;
  if (portable) others.push_back(f.lavapipe);
  sg::LoadedInputs in = sg::prepareInputs(f.rig, f.rules, f.fragment, opts, profile, others);
  const sg::Plan plan = sg::searchUnderOptions(in, opts);
  if (portable) {
    std::vector<sg::DeviceProfile> all{*in.profile};
    all.insert(all.end(), in.portable.begin(), in.portable.end());
    (void)sg::describePortable(plan, in.problem, all, in.portableBest);
    return;
  }
  const sg::PlanCostPrediction c = sg::predictPlanCost(plan, in.problem, *in.profile);
  if (std::llround(c.totalNanoseconds * sg::kFemtosecondsPerNanosecond) != plan.cost) {
    std::fprintf(stderr, "predicted %.9f ns per vertex, searched %lld fs\n", c.totalNanoseconds, (long long)plan.cost);
    std::abort();
  }
  (void)sg::describePlanCost(plan, in.problem, *in.profile);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  sg::fuzz::expectInputErrorsOnly([&] {
    const sg::DeviceProfile profile = sg::parseDeviceProfile(sg::fuzz::text(data, size), "fuzz.profile.yaml");
    sg::GenerateOptions stated;  // the workload the profile states (or its defaults)
    searchUnder(profile, stated, false);
    sg::GenerateOptions measured;  // a small draw of a mesh whose warps read many joints
    measured.maxVertices = 2009;
    measured.workload.verticesPerDraw = 2009;
    measured.workload.jointsPerWarp = 12.5;
    measured.workload.paletteEntriesPerWarp = 40;
    measured.workload.activeMorphTargets = 3;
    measured.workload.invocationsPerVertex = 1.4;
    measured.workload.fragmentsPerVertex = 5.3;
    searchUnder(profile, measured, false);
    searchUnder(profile, measured, true);
  });
  return 0;
}

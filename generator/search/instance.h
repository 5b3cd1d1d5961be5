// The context of one generation: the loaded inputs and the problem instantiated from
// them. Built once by the load and instantiate stages (pipeline/stages.h) and read by
// every later one (search, emit, explain, graph, validate), so nothing re-reads a file.
#pragma once
#include <optional>
#include <vector>

#include "interface/fragment_interface.h"
#include "rig/rig.h"
#include "rules/rules.h"
#include "search/device_profile.h"
#include "search/problem.h"

namespace sg {

struct LoadedInputs {
  Rig rig;
  RuleSet rules;  // `cost: auto` resolved for this rig
  FragmentInterface fragment;
  std::vector<Varying> varyings;
  Problem problem;
  // The device profile the problem is priced with (priceStage); none: instruction slots.
  std::optional<DeviceProfile> profile;
};

}  // namespace sg

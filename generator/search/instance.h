// The context of one generation: the loaded inputs and the problem instantiated from
// them. Built once by the load and instantiate stages (pipeline/stages.h) and read by
// every later one (search, emit, explain, graph, validate), so nothing re-reads a file.
#pragma once
#include <optional>
#include <vector>

#include "common/diagnostics.h"
#include "interface/fragment_interface.h"
#include "rig/rig.h"
#include "rules/rules.h"
#include "search/device_profile.h"
#include "search/problem.h"
#include "search/workload.h"

namespace sg {

struct LoadedInputs {
  Rig rig;
  RuleSet rules;  // `cost: auto` resolved for this rig
  FragmentInterface fragment;
  std::vector<Varying> varyings;
  Problem problem;
  // The device profile the problem is priced with (priceStage); none: instruction slots.
  std::optional<DeviceProfile> profile;
  // A portable choice: the other devices' profiles (the plan's worst regret across `profile`
  // and these is minimised; searchStage's caller prices it, pipeline/generate.cpp).
  std::vector<DeviceProfile> portable;
  // Each device's optimum (`profile` first, then `portable`), fs per vertex: set by the search
  // of a portable choice, for the regret report (describePortable). Given before the search
  // (one per device), regret is measured against these instead: bench prices each forced
  // alternative against the optima of the unbanned problem, so that its regret compares with
  // the chosen plan's (searched under its bans, each device's optimum would be its own).
  std::vector<int64_t> portableBest;
  // The workload the problem is priced for (GenerateOptions::workload): reports show it.
  Workload workload;
  // What loading left out and why (error budgets' removals): printed by the CLI, and
  // attached to an error when the request then cannot be met.
  std::vector<Diagnostic> notes;
};

}  // namespace sg

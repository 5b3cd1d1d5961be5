// `cost: auto` — a rule's cost measured from its snippet (docs/cost-model.md):
// compile the snippet alone (analysis/probe.h), optimise with spirv-opt -O, and count
// the instructions of the function body weighted per opcode class, in vertex-program
// instruction slots (the unit of the hand-written costs).
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "analysis/probe.h"
#include "common/diagnostics.h"
#include "rules/rules.h"

namespace sg {

struct Rig;

struct CostItem {
  std::string what;  // "OpFAdd", "GLSL.std.450 Normalize", "OpFMul (fused into a multiply-add)"
  int count = 0;     // instructions of this kind
  int64_t slots = 0; // their total weight
};

struct CostBreakdown {
  int64_t total = 0;
  std::vector<CostItem> items;  // sorted by `what`
};

// Weighs the function bodies of an (optimised) SPIR-V module.
CostBreakdown measureSpirv(const std::vector<uint32_t>& words);

struct AutoCost {
  bool ok = false;
  int64_t cost = 0;
  CostBreakdown breakdown;
  std::vector<Diagnostic> diagnostics;  // why it could not be measured (located in the rules file)
};

// Measures rules.rules[rule] instantiated for `rig` (template errors and compile errors
// are returned as diagnostics, not thrown).
AutoCost measureRuleCost(const RuleSet& rules, int rule, const ProbeRig& rig);

// Replaces every `cost: auto` by the measured cost for `rig` (rules whose `when` is false
// for the rig are left alone: they are not instantiated). Throws InputError when a snippet
// cannot be measured (its compile errors, located at the rule's YAML lines).
void resolveAutoCosts(RuleSet& rules, const Rig& rig);

}  // namespace sg

// `cost: auto` — a rule's cost measured from its snippet (docs/cost-model.md):
// compile the snippet alone (analysis/probe.h), optimise with spirv-opt -O, and count
// the instructions of the function body weighted per opcode class, in vertex-program
// instruction slots (the unit of the hand-written costs).
#pragma once
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "analysis/probe.h"
#include "common/diagnostics.h"
#include "rules/rules.h"
#include "search/problem.h"

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

// Memory accesses per vertex of a program (the cost model's per-rule terms,
// docs/device-profiles.md), as elements fetched (loads of one element, whatever parts of it,
// count once): through a storage buffer, per binding; from the uniform block through an
// access chain with a computed index (palette[joint]).
struct SpirvAccesses {
  std::map<uint32_t, int64_t> bufferLoads;  // binding -> loads
  int64_t indexedUniformLoads = 0;
};
SpirvAccesses measureAccesses(const std::vector<uint32_t>& words);

struct RuleAccesses {
  bool ok = false;
  std::map<std::string, int64_t> bufferLoads;  // per buffer semantic read: element loads
  int64_t indexedUniformLoads = 0;
  std::vector<Diagnostic> diagnostics;
};
// Counted on the rule's probe (analysis/probe.h) optimised with loops of constant trip
// count unrolled, so a loop over the targets counts one load per target.
RuleAccesses measureRuleAccesses(const RuleSet& rules, int rule, const ProbeRig& rig);

// Sets the buffer-load, buffer-byte (loads x the buffer's element stride) and indexed
// uniform load terms of every action that reads a storage buffer or a uniform array, then
// reprices the problem. Throws InputError when a snippet cannot be measured.
void measureAccessTerms(Problem& p, const RuleSet& rules, const Rig& rig);

// Replaces every `cost: auto` by the measured cost for `rig` (rules whose `when` is false
// for the rig are left alone: they are not instantiated). Throws InputError when a snippet
// cannot be measured (its compile errors, located at the rule's YAML lines).
void resolveAutoCosts(RuleSet& rules, const Rig& rig);

}  // namespace sg

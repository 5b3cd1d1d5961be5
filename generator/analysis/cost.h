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
// docs/device-profiles.md): through a storage buffer, per binding; from the uniform block
// through an access chain with an index computed per vertex (palette[joint]: from a vertex
// input, or from a load at such an index; an index the same for the whole draw reads one
// address per warp, as a constant one does, and is not counted). An element is what one
// computed index selects (constant indices after it pick its parts); it is fetched once
// however many of its parts are read, in loads of up to 16 bytes (a vec4): a mat4 palette
// entry is 4 vec4 loads, a mat3x4 one 3, a vec4 or a float 1.
struct SpirvAccesses {
  std::map<uint32_t, int64_t> bufferLoads;      // binding -> elements
  std::map<uint32_t, int64_t> bufferVec4Loads;  // binding -> 16-byte loads
  int64_t indexedUniformLoads = 0;              // elements
  int64_t indexedUniformVec4Loads = 0;          // 16-byte loads
};
SpirvAccesses measureAccesses(const std::vector<uint32_t>& words);

struct RuleAccesses {
  bool ok = false;
  std::map<std::string, int64_t> bufferLoads;      // per buffer semantic read: elements
  std::map<std::string, int64_t> bufferVec4Loads;  // per buffer semantic read: 16-byte loads of its type
  int64_t indexedUniformLoads = 0, indexedUniformVec4Loads = 0;
  std::vector<Diagnostic> diagnostics;
};
// Counted on the rule's probe (analysis/probe.h) optimised with loops of constant trip
// count unrolled, so a loop over the targets counts one load per target.
RuleAccesses measureRuleAccesses(const RuleSet& rules, int rule, const ProbeRig& rig);

// Sets the buffer-load (elements), buffer vec4-load (16-byte loads; one per component for a
// buffer of tightly packed floats), buffer-byte (elements x the buffer's element stride) and
// indexed uniform load terms (elements and vec4 loads) of every action that reads a storage
// buffer or a uniform array, then reprices the problem. Throws InputError when a snippet cannot be measured.
void measureAccessTerms(Problem& p, const RuleSet& rules, const Rig& rig);

// Palette elements that several rules of a plan read at the same per-vertex index (the skin
// matrix and a linear blend of the position, each indexing the palette by the joints) are
// loaded once: the device's compiler reuses a uniform load of the same address (on the H200
// the 16-influence limb's plan that also blends the position from the palette takes 13.85 ns
// per vertex on the head, the one reading it once 13.90, where the palette is half the time).
// So a uniform array that every reader loads at a per-vertex index, and reads beside no other
// uniform array, carries its indexed-load terms on its resource item, paid once per plan, at the
// most any reader makes; its readers carry none. Readers that index it by different inputs
// (joints from a buffer, from attributes) share it too: a plan mixing them is under-counted, and
// never the cheapest (it reads both forms of the joints). Called by measureAccessTerms.
void shareIndexedUniformLoads(Problem& p);

// Replaces every `cost: auto` by the measured cost for `rig` (rules whose `when` is false
// for the rig are left alone: they are not instantiated). Throws InputError when a snippet
// cannot be measured (its compile errors, located at the rule's YAML lines).
void resolveAutoCosts(RuleSet& rules, const Rig& rig);

}  // namespace sg

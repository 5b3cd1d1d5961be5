// Rule instantiation, the one copy: a rule resolved against the shape of a rig (its
// parameters, the semantic instances it provides, the size of every indexed family and
// uniform array). The search problem (search/problem.cpp), the snippet probes that
// `check` and `cost: auto` compile (analysis/probe.cpp) and `check`'s name checks all go
// through here, so they accept and reject the same rules with the same messages.
#pragma once
#include <cstdint>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "common/diagnostics.h"
#include "rules/expr.h"
#include "rules/rules.h"
#include "rules/snippet.h"

namespace sg {

struct Rig;

// What a rule is instantiated against.
struct RigShape {
  std::string name;  // "dawn-face", or a description of a default rig
  std::map<std::string, int64_t> params;
  std::set<std::string> provided;           // "vertex.position", "morph.position[3]", ...
  std::map<std::string, int64_t> families;  // "morph.position" -> 5
  std::map<std::string, int64_t> arrays;    // uniform arrays: "skin.bones" -> 98
};

// "name[i]".
std::string indexedName(const std::string& name, int64_t i);

// The most instances a semantic family may have (its `count`).
constexpr int64_t kMostFamilyInstances = 256;

// Evaluates the family counts and uniform array sizes of `rules` against shape.params.
// A missing array parameter throws InputError when `strictArrays`, else sizes it 4.
// Counts outside 0..256 throw InputError at the semantic's declaration.
void evalFamilies(RigShape& shape, const RuleSet& rules, bool strictArrays);

// The shape of a real rig: its parameters, families, arrays and the instances its
// attributes (per morph target) and uniforms provide.
RigShape shapeOfRig(const Rig& rig, const RuleSet& rules);

// Rig parameters and has() of a shape (valid while `shape` lives).
ExprEnv shapeEnv(const RigShape& shape);

// Name and shape errors of one rule that need no rig: unknown semantics (with a
// did-you-mean), families used without an index and indexes on non-families, a family
// as product, a rule needing its own product. Every error, in source order.
std::vector<Diagnostic> ruleReferenceErrors(const RuleSet& rules, int rule);

// " (did you mean 'x'?)" for the declared semantic closest to `name`, or "".
std::string didYouMeanSemantic(const RuleSet& rules, const std::string& name);
// The same over any list of names.
std::string didYouMean(const std::string& name, const std::vector<std::string>& names);

struct RuleInstance {
  std::vector<std::string> needs;  // semantic instances, sorted, unique
  std::vector<ExpandedLine> code;  // the unrolled snippet
};

// Does the rule's `when` hold for the shape? (Empty `when` holds.) Throws InputError
// when it cannot be evaluated.
bool ruleApplies(const Rule& rule, const RigShape& shape);

// The rule's `cost` for the shape. Throws InputError for a cost outside 0..kMaxRuleCost and for an
// unresolved `cost: auto` (analysis/cost.h resolveAutoCosts measures it first).
int64_t ruleCost(const Rule& rule, const RigShape& shape);

// Instantiates rules.rules[rule] for `shape`: every reference resolved to instances
// (index expressions evaluated, [*] expanded, ranges checked) and its snippet unrolled with ${out} written `outText` and every other semantic instance
// written textOf(instance). Throws InputError (located in the rules file) for the
// errors of ruleReferenceErrors, indexes out of range, and snippets
// that use a semantic not listed in `needs`.
RuleInstance instantiateRule(const RuleSet& rules, int rule, const RigShape& shape, const std::string& outText,
                             const std::function<std::string(const std::string& instance)>& textOf);

}  // namespace sg

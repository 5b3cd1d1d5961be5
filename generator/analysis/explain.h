// `shadergen explain`: the chosen plan as a tree (which output needs which value, each
// rule with its cost, shared values paid once), the cheapest alternative of every choice
// (re-searched with the chosen rule banned), and, for an impossible request, which values
// cannot be produced and which missing rig inputs would make them possible.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "search/astar.h"
#include "search/instance.h"
#include "search/plan.h"
#include "search/search.h"

namespace sg {

// The optimal plan under the cost model (nullopt if the goals are unreachable).
// Throws InputError for an unknown heuristic name.
std::optional<Plan> searchPlan(const Problem& p, const std::string& heuristic, SearchStats* stats = nullptr);

struct Alternative {
  bool exists = false;
  int64_t planCost = 0;  // the best plan with the rule banned
  int64_t extra = 0;     // planCost - the chosen plan's cost
  std::vector<std::string> instead;  // rules of that plan the chosen plan does not use
};

struct PlanStep {
  int action = -1;       // index into Problem::actions
  int uses = 0;          // plan rules needing the product + outputs requesting it
  Alternative alternative;
};

struct Explanation {
  Plan plan;
  std::vector<PlanStep> steps;  // in plan order
  std::string heuristic;
};

struct ExplainOptions {
  std::string heuristic = "lmcut";
  bool alternatives = true;  // re-search once per chosen rule
};

// Explains `plan` (an optimal plan of in.problem).
Explanation explainPlan(const LoadedInputs& in, const Plan& plan, const ExplainOptions& opts);
std::string formatExplanation(const LoadedInputs& in, const Explanation& e);

struct UnreachableGoal {
  int fact = -1;
  std::vector<std::string> requestedBy;  // output (varying) names
  // Minimal sets of semantics the rig does not provide (and no applicable rule produces)
  // whose provision would make the goal producible; smallest first, at most 8 sets of at
  // most 4 semantics. Empty: no set of rig inputs helps (the rules cannot derive it).
  std::vector<std::vector<std::string>> missingInputs;
  std::vector<std::string> inapplicableRules;  // "rule 'x' does not apply: when '...' is false for rig 'r'"
};

std::vector<UnreachableGoal> analyzeUnreachable(const Problem& p, const RuleSet& rules,
                                                const std::vector<Varying>& varyings);
std::string formatUnreachable(const Problem& p, const std::vector<UnreachableGoal>& goals);

// The rules the rules files replaced or disabled (RuleSet::changes), one line each.
std::string formatRuleChanges(const RuleSet& rules);

// "morph.position[0..4]"-style compact list of fact names.
std::string compactFactList(const std::vector<std::string>& names);

}  // namespace sg

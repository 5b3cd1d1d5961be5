// A* over sets of computed facts. States are fact sets; reorderings of the same
// actions reach the same set and are expanded once. Only relevant actions (those
// that can contribute to a goal) and not-yet-produced facts are considered.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "search/heuristic.h"
#include "search/plan.h"
#include "search/problem.h"

namespace sg {

struct SearchStats {
  int64_t expanded = 0;
  int64_t generated = 0;
  int64_t relevantActions = 0;
  int64_t initialH = 0;
};

struct SearchLimits {
  int64_t maxExpansions = 5'000'000;  // guards against pathological rule sets
};

// Optimal plan under the cost model, or nullopt if the goals are unreachable.
// Throws std::runtime_error if the expansion limit is hit.
std::optional<Plan> astarSearch(const Problem& p, Heuristic& h, SearchStats* stats = nullptr,
                                const SearchLimits& limits = {});

// Facts reachable from the initial state by any sequence of actions.
std::vector<bool> reachableFacts(const Problem& p);
// Actions whose product can (transitively) contribute to a goal.
std::vector<bool> relevantActions(const Problem& p);

}  // namespace sg

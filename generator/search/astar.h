// A* over sets of computed facts. States are fact sets; reorderings of the same
// actions reach the same set and are expanded once. Only relevant actions (those
// that can contribute to a goal) and not-yet-produced facts are considered.
#pragma once
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "search/heuristic.h"
#include "search/plan.h"
#include "search/problem.h"

namespace sg {

struct SearchStats {
  int64_t expanded = 0;
  int64_t generated = 0;
  int64_t reopened = 0;  // closed nodes reached again more cheaply (inconsistent h)
  int64_t relevantActions = 0;
  int64_t initialH = 0;
  int64_t finalCost = -1;  // -1: no plan
  double heuristicSeconds = 0;  // time inside heuristic evaluations
  double totalSeconds = 0;      // the whole search, preprocessing included
  int64_t peakBytes = 0;        // nodes, duplicate table and open list when the search ends (nodes
                                // are never freed, so close to the peak; the IP: GLPK's peak)
  std::string engine;           // "regression", "forward" or "ip"
  std::string heuristic;        // the heuristic's name ("" for the IP)
};

struct SearchLimits {
  int64_t maxExpansions = 5'000'000;  // guards against pathological rule sets
  double maxSeconds = 0;              // wall-clock budget per search; 0 = none
};

// Thrown when a search hits a limit of SearchLimits; the message names the limit.
struct SearchLimitError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Optimal plan under the cost model, or nullopt if the goals are unreachable.
// Throws SearchLimitError if the expansion or time limit is hit.
std::optional<Plan> astarSearch(const Problem& p, Heuristic& h, SearchStats* stats = nullptr,
                                const SearchLimits& limits = {});

// Facts reachable from the initial state by any sequence of actions.
std::vector<bool> reachableFacts(const Problem& p);
// Actions whose product can (transitively) contribute to a goal.
std::vector<bool> relevantActions(const Problem& p);

}  // namespace sg

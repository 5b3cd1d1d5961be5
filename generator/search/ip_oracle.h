// Exact integer program for the single-effect delete-free problem, solved with GLPK:
// the independent oracle of the tests and benchmarks (docs/search.md), also available as
// `generate --search ip`. Variables: x_a (rule instance chosen), y_f (fact needed).
//   y_g = 1 for goals; sum of x over f's achievers >= y_f; x_a <= y_p for a's needs;
//   inside a cyclic strongly connected component, potentials t: t_add >= t_p + 1 when
//   x_a = 1 (big-M), so chosen achievers never justify each other in a loop.
// Every plan is a feasible point and every feasible point contains a plan of no greater
// cost, so the optimum equals the cheapest plan's cost.
#pragma once
#include <optional>

#include "search/astar.h"
#include "search/plan.h"
#include "search/problem.h"

namespace sg {

// Cheapest plan or nullopt if the goals are unreachable. Honours limits.maxSeconds
// (SearchLimitError); expansions in the stats are GLPK's branch-and-bound nodes.
std::optional<Plan> integerProgramSearch(const Problem& p, SearchStats* stats = nullptr, const SearchLimits& limits = {});

}  // namespace sg

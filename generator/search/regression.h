// Regression A* with a canonical decision order (docs/search.md). Every action adds one
// fact, so an optimal delete-free plan picks exactly one achiever for each needed fact.
// When the relevant fact graph is acyclic, needed facts are decided in a fixed order
// (highest topological rank first): a state is the set of needed-but-undecided facts, a
// transition picks an achiever for the highest-ranked one and opens its non-init
// preconditions. Reorderings of independent rules are never generated and states that
// need the same facts collapse.
#pragma once
#include <optional>
#include <string>

#include "search/astar.h"
#include "search/plan.h"
#include "search/problem.h"

namespace sg {

// Whether the relevant part of `p` is acyclic (regressionSearch applies).
bool regressionApplies(const Problem& p);

// Heuristics over open sets, all admissible: "blind", "hmax" (dearest open fact's h_max
// from init), "landmarks" (sum over the union of the open facts' fact landmarks of their
// cheapest achiever), "lmcut" (LM-cut from init to the open set, maxed with "landmarks").
// Returns nullopt if the goals are unreachable; throws std::invalid_argument for a cyclic
// relevant graph or an unknown heuristic, SearchLimitError at a limit.
std::optional<Plan> regressionSearch(const Problem& p, const std::string& heuristic, SearchStats* stats = nullptr,
                                     const SearchLimits& limits = {});

}  // namespace sg

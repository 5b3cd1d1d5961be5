// Shared delete-relaxation helpers for the heuristics and reachability analysis.
#pragma once
#include <cstdint>
#include <vector>

#include "search/problem.h"
#include "search/state.h"

namespace sg {

// h_max cost of every fact from `state` under per-action costs (kInfiniteCost = unreachable).
std::vector<int64_t> hmaxCosts(const Problem& p, const FactSet& state, const std::vector<int64_t>& actionCost);

}  // namespace sg

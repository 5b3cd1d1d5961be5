// Heuristics for the delete-free search (swappable, as in Fast Downward):
// each estimates the cost still needed to reach every goal from a state.
#pragma once
#include <cstdint>
#include <limits>
#include <memory>
#include <string>

#include "search/problem.h"
#include "search/state.h"

namespace sg {

constexpr int64_t kInfiniteCost = std::numeric_limits<int64_t>::max() / 4;

class Heuristic {
 public:
  virtual ~Heuristic() = default;
  virtual int64_t estimate(const FactSet& state) = 0;  // kInfiniteCost = dead end
  virtual const char* name() const = 0;
};

// h = 0 (uniform-cost search).
std::unique_ptr<Heuristic> makeBlindHeuristic(const Problem& p);
// h_max: the most expensive single goal, each precondition set costing its dearest member.
std::unique_ptr<Heuristic> makeHMaxHeuristic(const Problem& p);
// LM-cut (Helmert & Domshlak 2009): sums disjoint action landmarks; admissible, ≥ h_max.
std::unique_ptr<Heuristic> makeLmCutHeuristic(const Problem& p);

// "blind", "hmax", "lmcut"; nullptr for an unknown name.
std::unique_ptr<Heuristic> makeHeuristic(const std::string& name, const Problem& p);

}  // namespace sg

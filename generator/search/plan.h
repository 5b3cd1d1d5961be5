// A plan: the chosen actions in an order where every precondition is produced first.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace sg {

struct Problem;

struct Plan {
  std::vector<int> actions;  // indices into Problem::actions, in application order
  int64_t cost = 0;  // its actions' costs, the items they read (once each) and Problem::fixedCost
};

// Drops actions whose product no goal needs (zero-cost detours) and orders the rest
// topologically (stable: ties keep search order, so output is deterministic).
Plan tidyPlan(const Problem& p, const std::vector<int>& actions);

// "rule_a (3) -> rule_b (5) ... total 8"
std::string describePlan(const Problem& p, const Plan& plan);

}  // namespace sg

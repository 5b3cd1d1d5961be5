// Helpers shared by the search tests: the plan validity check.
#pragma once
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <set>
#include <vector>

#include "search/plan.h"
#include "search/problem.h"

namespace sg {

// Validates a plan: each action applicable in order from init, goals reached, cost is
// the sum of the actions' costs (and the costs of the inputs read, once each), no action repeated, and every action's product is new
// and needed (a goal or a precondition of a later action) — the tidy-plan contract.
inline ::testing::AssertionResult planIsValid(const Problem& p, const Plan& plan) {
  std::vector<bool> have(p.facts.size(), false);
  for (int f : p.init) have[f] = true;
  int64_t sum = 0;
  std::set<int> used;
  for (size_t i = 0; i < plan.actions.size(); ++i) {
    int ai = plan.actions[i];
    if (ai < 0 || ai >= static_cast<int>(p.actions.size()))
      return ::testing::AssertionFailure() << "action index out of range: " << ai;
    if (!used.insert(ai).second) return ::testing::AssertionFailure() << "action repeated: " << ai;
    const Action& a = p.actions[ai];
    for (int f : a.pre)
      if (!have[f])
        return ::testing::AssertionFailure() << "step " << i << " (" << a.name << ") precondition "
                                             << p.facts[f].name << " missing";
    if (have[a.add])
      return ::testing::AssertionFailure() << "step " << i << " (" << a.name << ") re-produces "
                                           << p.facts[a.add].name;
    bool needed = std::find(p.goals.begin(), p.goals.end(), a.add) != p.goals.end();
    for (size_t j = i + 1; j < plan.actions.size() && !needed; ++j) {
      const auto& later = p.actions[plan.actions[j]].pre;
      needed = std::find(later.begin(), later.end(), a.add) != later.end();
    }
    if (!needed)
      return ::testing::AssertionFailure() << "step " << i << " (" << a.name << ") produces an unneeded fact";
    have[a.add] = true;
    sum += a.cost;
  }
  for (int g : p.goals)
    if (!have[g]) return ::testing::AssertionFailure() << "goal " << p.facts[g].name << " not reached";
  // Under a device profile each rig input read (by a rule or as a pass-through goal) is
  // paid once, plus the fixed terms; both are zero without one.
  std::set<int> items;
  for (int ai : plan.actions)
    for (int f : p.actions[ai].pre)
      if (p.facts[f].resource >= 0) items.insert(p.facts[f].resource);
  for (int g : p.goals)
    if (p.facts[g].resource >= 0) items.insert(p.facts[g].resource);
  for (int r : items) sum += p.resources[r].cost;
  sum += p.fixedCost;
  if (sum != plan.cost)
    return ::testing::AssertionFailure() << "plan.cost " << plan.cost << " != sum of action and input costs " << sum;
  return ::testing::AssertionSuccess();
}

}  // namespace sg

#include "search/plan.h"

#include <fmt/format.h>

#include <algorithm>

#include "search/problem.h"

namespace sg {

Plan tidyPlan(const Problem& p, const std::vector<int>& actions) {
  // Which chosen action produces each fact.
  std::vector<int> producer(p.facts.size(), -1);
  for (int a : actions) producer[p.actions[a].add] = a;
  std::vector<bool> isInit(p.facts.size(), false);
  for (int f : p.init) isInit[f] = true;
  // Keep only producers reachable backwards from the goals.
  std::vector<bool> keep(p.actions.size(), false);
  std::vector<int> stack(p.goals.begin(), p.goals.end());
  std::vector<bool> seen(p.facts.size(), false);
  while (!stack.empty()) {
    int f = stack.back();
    stack.pop_back();
    if (seen[f] || isInit[f]) continue;
    seen[f] = true;
    int a = producer[f];
    if (a < 0) continue;
    keep[a] = true;
    for (int q : p.actions[a].pre) stack.push_back(q);
  }
  // The search order is already topological; filtering preserves it.
  Plan plan;
  for (int a : actions)
    if (keep[a]) {
      plan.actions.push_back(a);
      plan.cost += p.actions[a].cost;
    }
  // Inputs are paid once per plan however many rules read them (zero without a profile).
  for (int r : itemsRead(p, plan.actions)) plan.cost += p.resources[r].cost;
  plan.cost += p.fixedCost;
  // A roofline objective is not a sum of the actions' costs: the largest component.
  if (!p.componentWeights.empty()) plan.cost = weighPlan(p, planAmounts(p, plan.actions));
  return plan;
}

std::string describePlan(const Problem& p, const Plan& plan) {
  std::string out;
  for (size_t i = 0; i < plan.actions.size(); ++i) {
    const Action& a = p.actions[plan.actions[i]];
    out += fmt::format("  {:2}. {:<28} -> {:<24} cost {}\n", i + 1, a.name, p.facts[a.add].name, a.cost);
  }
  // Under a device profile costs are femtoseconds per vertex (search/device_profile.h).
  out += p.weights == kSlotWeights ? fmt::format("  total cost {}\n", plan.cost)
                                   : fmt::format("  total cost {} (fs per vertex, device profile)\n", plan.cost);
  return out;
}

}  // namespace sg

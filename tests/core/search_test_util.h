// Helpers shared by the search tests: the plan validity check, a search by engine name.
#pragma once
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <optional>
#include <string>
#include <set>
#include <stdexcept>
#include <vector>

#include "search/plan.h"
#include "search/problem.h"
#include "search/search.h"

namespace sg {

// The plan the named engine finds (default heuristic), with its statistics when asked.
inline std::optional<Plan> solveWith(const Problem& p, const std::string& engine, SearchStats* st = nullptr) {
  SearchOptions o;
  o.engine = engine;
  return findPlan(p, o, st);
}

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
  if (!p.componentWeights.empty()) {  // a roofline: the largest component of the amounts
    TermAmounts amounts = p.fixedTerms;
    for (int ai : plan.actions)
      for (size_t t = 0; t < kTermCount; ++t) amounts[t] += p.actions[ai].terms[t];
    for (int r : items)
      for (size_t t = 0; t < kTermCount; ++t) amounts[t] += p.resources[r].terms[t];
    sum = 0;
    for (const TermWeights& w : p.componentWeights) {
      int64_t c = 0;
      for (size_t t = 0; t < kTermCount; ++t) c += w[t] * amounts[t];
      sum = std::max(sum, c);
    }
  }
  if (sum != plan.cost)
    return ::testing::AssertionFailure() << "plan.cost " << plan.cost << " != sum of action and input costs " << sum;
  return ::testing::AssertionSuccess();
}

constexpr int64_t kNone = -1;  // exhaustiveOptimum: no feasible plan

// Exhaustive: every subset of actions, its delete-free closure from init; feasible if the
// goals are covered and the resource items read by the actions that fire (and by the goals
// the rig provides) fit every limit. `cost(fired, items)` prices a feasible subset (fired:
// per action; items: each distinct input read once); the cheapest, or kNone. Written from the
// definition, sharing nothing with the engines but the Problem.
template <class Cost>
int64_t exhaustiveMinimum(const Problem& p, Cost&& cost) {
  const size_t n = p.actions.size();
  if (n > 20) throw std::logic_error("instance too large for the exhaustive solver");
  int64_t best = kNone;
  for (uint32_t s = 0; s < (1u << n); ++s) {
    std::vector<bool> have(p.facts.size(), false), fired(n, false);
    for (int f : p.init) have[f] = true;
    for (bool changed = true; changed;) {
      changed = false;
      for (size_t a = 0; a < n; ++a) {
        const Action& act = p.actions[a];
        if (!(s >> a & 1u) || fired[a]) continue;
        if (!std::all_of(act.pre.begin(), act.pre.end(), [&](int q) { return have[q]; })) continue;
        fired[a] = true;
        have[act.add] = changed = true;
      }
    }
    if (!std::all_of(p.goals.begin(), p.goals.end(), [&](int g) { return have[g]; })) continue;
    std::set<int> items;
    for (size_t a = 0; a < n; ++a)
      if (fired[a])
        for (int q : p.actions[a].pre)
          if (p.facts[q].resource >= 0) items.insert(p.facts[q].resource);
    for (int g : p.goals)
      if (p.facts[g].resource >= 0) items.insert(p.facts[g].resource);
    std::vector<int64_t> use(p.limits.size(), 0);
    for (int i : items)
      if (static_cast<size_t>(p.resources[i].limit) < use.size()) use[p.resources[i].limit] += p.resources[i].amount;
    bool fits = true;
    for (size_t l = 0; l < use.size(); ++l) fits = fits && use[l] <= p.limits[l].max;
    if (!fits) continue;
    const int64_t c = cost(fired, items);
    if (best == kNone || c < best) best = c;
  }
  return best;
}

// The additive cost: the fired actions, each distinct item read (paid once: a device
// profile's inputs), and the fixed cost.
inline int64_t exhaustiveOptimum(const Problem& p) {
  return exhaustiveMinimum(p, [&](const std::vector<bool>& fired, const std::set<int>& items) {
    int64_t cost = p.fixedCost;
    for (size_t a = 0; a < fired.size(); ++a)
      if (fired[a]) cost += p.actions[a].cost;
    for (int i : items) cost += p.resources[i].cost;
    return cost;
  });
}

}  // namespace sg

// Device limits as constraints of the search (issue 14, docs/search.md "Resource limits"):
// every engine returns the cheapest plan whose rig inputs fit the limits. Checked against
// an independent exhaustive solver on random instances whose limits bind, against the
// integer program on random libraries, and on a hand-made instance where the cheapest
// plan overall breaks a limit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "random_library.h"
#include "search/ip_oracle.h"
#include "search/problem.h"
#include "search/regression.h"
#include "search/search.h"
#include "search_test_util.h"

namespace sg {
namespace {

// Gives every rig input a resource item (amount 1-3, one of two limits) and sets each
// limit just below what the unconstrained optimum reads, so that it binds.
void addBindingLimits(Problem& p, std::mt19937& rng) {
  p.limits = {ResourceLimit{"locations", "--a", INT64_MAX}, ResourceLimit{"bytes", "--b", INT64_MAX}};
  p.resources.clear();
  for (int f : p.init) {
    p.facts[f].resource = static_cast<int>(p.resources.size());
    p.resources.push_back(ResourceItem{p.facts[f].name, static_cast<int>(rng() % 2), 1 + static_cast<int64_t>(rng() % 3)});
  }
  std::optional<Plan> best = integerProgramSearch(p);
  if (!best) return;
  std::vector<int64_t> use = resourceUsage(p, best->actions);
  for (size_t l = 0; l < use.size(); ++l) p.limits[l].max = std::max<int64_t>(0, use[l] - static_cast<int64_t>(rng() % 2));
}

// Small random libraries (8-20 rules) with binding limits: regression (every heuristic),
// forward (falls back to the IP when its plan breaks a limit) and the IP all find the
// exhaustive optimum, or all agree that no plan fits.
TEST(SearchLimitsProperty, RandomInstancesMatchExhaustiveSolver) {
  int feasible = 0, infeasible = 0, changed = 0;
  for (uint64_t seed = 1; seed <= 300; ++seed) {
    SCOPED_TRACE(::testing::Message() << "seed " << seed);
    Problem p = sgtest::randomLibrary(sgtest::LibraryShape{8 + static_cast<int>(seed % 7), seed, 2, 4});
    std::mt19937 rng(static_cast<uint32_t>(seed));
    std::optional<Plan> unconstrained = integerProgramSearch(p);
    ASSERT_TRUE(unconstrained);
    addBindingLimits(p, rng);
    const int64_t opt = exhaustiveOptimum(p);
    if (opt == kNone) ++infeasible;
    else ++feasible;
    if (opt != kNone && opt > unconstrained->cost) ++changed;
    for (const char* h : {"blind", "hmax", "landmarks", "lmcut"}) {
      SCOPED_TRACE(h);
      auto plan = regressionSearch(p, h);
      ASSERT_EQ(plan.has_value(), opt != kNone);
      if (!plan) continue;
      EXPECT_EQ(plan->cost, opt);
      EXPECT_TRUE(planIsValid(p, *plan));
      EXPECT_LT(exceededLimit(p, resourceUsage(p, plan->actions)), 0);
    }
    for (const char* engine : {"ip", "forward"}) {
      SCOPED_TRACE(engine);
      auto plan = solveWith(p, engine);
      ASSERT_EQ(plan.has_value(), opt != kNone);
      if (!plan) continue;
      EXPECT_EQ(plan->cost, opt);
      EXPECT_TRUE(planIsValid(p, *plan));
      EXPECT_LT(exceededLimit(p, resourceUsage(p, plan->actions)), 0);
    }
  }
  // The limits matter: many instances get a dearer plan, some have none.
  EXPECT_GE(changed, 60);
  EXPECT_GE(infeasible, 10);
  EXPECT_GE(feasible, 150);
}

// Larger libraries (30-300 rules) against the integer program.
TEST(SearchLimitsProperty, LibrariesMatchOracle) {
  int changed = 0;
  for (uint64_t seed = 1; seed <= 60; ++seed) {
    SCOPED_TRACE(::testing::Message() << "seed " << seed);
    Problem p = sgtest::randomLibrary(sgtest::LibraryShape{20 + static_cast<int>(seed * 2), seed});
    std::mt19937 rng(static_cast<uint32_t>(seed));
    const int64_t free = integerProgramSearch(p)->cost;
    addBindingLimits(p, rng);
    auto oracle = integerProgramSearch(p);
    auto plan = solveWith(p, "auto");
    ASSERT_EQ(plan.has_value(), oracle.has_value());
    if (!plan) continue;
    EXPECT_EQ(plan->cost, oracle->cost);
    EXPECT_TRUE(planIsValid(p, *plan));
    EXPECT_LT(exceededLimit(p, resourceUsage(p, plan->actions)), 0);
    changed += plan->cost > free;
  }
  EXPECT_GE(changed, 10);
}

// goal <- cheap (cost 1, reads inputs a and b: 2 locations) | dear (cost 5, reads c: 1
// location); the other goal passes input d straight through (1 location).
Problem twoWays(int64_t maxLocations) {
  Problem p;
  for (const char* n : {"a", "b", "c", "d", "goal"}) {
    Fact f;
    f.name = n;
    p.facts.push_back(f);
  }
  p.init = {0, 1, 2, 3};
  p.limits = {ResourceLimit{"vertex input attributes", "--max-attributes", maxLocations}};
  for (int f = 0; f < 4; ++f) {
    p.facts[f].resource = f;
    p.resources.push_back(ResourceItem{p.facts[f].name, 0, 1});
  }
  p.actions.push_back(Action{"cheap", -1, {0, 1}, 4, 1, {}});
  p.actions.push_back(Action{"dear", -1, {2}, 4, 5, {}});
  p.goals = {3, 4};
  return p;
}

TEST(SearchLimits, CheapestPlanBreaksALimitSoTheCheapestFeasibleIsReturned) {
  for (const char* engine : {"auto", "regression", "forward", "ip"}) {
    SCOPED_TRACE(engine);
    auto free = solveWith(twoWays(3), engine);
    ASSERT_TRUE(free);
    EXPECT_EQ(free->cost, 1);  // within 3 locations the cheap rule fits (a, b, d)
    auto limited = solveWith(twoWays(2), engine);
    ASSERT_TRUE(limited);
    EXPECT_EQ(limited->cost, 5);  // a, b, d = 3 locations > 2: only c + d fit
    EXPECT_EQ(limited->actions.size(), 1u);
    EXPECT_EQ(twoWays(2).actions[limited->actions[0]].name, "dear");
    EXPECT_FALSE(solveWith(twoWays(1), engine).has_value());  // d alone and any achiever: 2
  }
  Problem p = twoWays(2);
  std::vector<int64_t> use = resourceUsage(p, {0});
  EXPECT_EQ(use[0], 3);
  EXPECT_EQ(describeExceeded(p, use, 0), "3 vertex input attributes, above the limit of 2 (--max-attributes)");
}

}  // namespace
}  // namespace sg

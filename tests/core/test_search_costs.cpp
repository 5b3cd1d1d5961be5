// Device-profile costs in the search (issue 21, docs/search.md "Device profiles"): every
// rig input a plan reads is paid once however many of its rules read it, on top of the
// rules' own terms. Every engine must still return the optimum: checked against an
// exhaustive solver written from that definition on small random instances with random
// weights (with and without binding device limits), against the integer program on
// larger libraries, and on hand-made instances where sharing an input decides the plan.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "random_library.h"
#include "search/device_profile.h"
#include "search/ip_oracle.h"
#include "search/problem.h"
#include "search/regression.h"
#include "search/search.h"
#include "search_test_util.h"

namespace sg {
namespace {

// Caps the vertex input attributes just below what the cheapest plan reads.
void bindAttributeLimit(Problem& p, std::mt19937& rng) {
  std::optional<Plan> best = integerProgramSearch(p);
  if (!best) return;
  std::vector<int64_t> use = resourceUsage(p, best->actions);
  p.limits[0].max = std::max<int64_t>(0, use[0] - static_cast<int64_t>(rng() % 2));
}

TEST(SearchCostsProperty, RandomProfilesMatchExhaustiveSolver) {
  int moved = 0, limited = 0;
  for (uint64_t seed = 1; seed <= 300; ++seed) {
    SCOPED_TRACE(::testing::Message() << "seed " << seed);
    Problem p = sgtest::randomLibrary(sgtest::LibraryShape{8 + static_cast<int>(seed % 9), seed, 2, 4});
    std::mt19937 rng(static_cast<uint32_t>(seed * 7919));
    const std::optional<Plan> slots = integerProgramSearch(p);
    ASSERT_TRUE(slots);
    sgtest::addRandomProfile(p, seed);
    if (seed % 3 == 0) {
      bindAttributeLimit(p, rng);
      ++limited;
    }
    const int64_t opt = exhaustiveOptimum(p);
    for (const char* h : {"blind", "hmax", "landmarks", "lmcut"}) {
      SCOPED_TRACE(h);
      SearchStats st;
      auto plan = regressionSearch(p, h, &st);
      ASSERT_EQ(plan.has_value(), opt != kNone);
      if (!plan) continue;
      EXPECT_EQ(plan->cost, opt);
      EXPECT_LE(st.initialH, opt);  // the estimate, inputs included, stays a lower bound
      EXPECT_TRUE(planIsValid(p, *plan));
      EXPECT_LT(exceededLimit(p, resourceUsage(p, plan->actions)), 0);
    }
    for (const char* engine : {"ip", "forward", "auto"}) {
      SCOPED_TRACE(engine);
      auto plan = solveWith(p, engine);
      ASSERT_EQ(plan.has_value(), opt != kNone);
      if (!plan) continue;
      EXPECT_EQ(plan->cost, opt);
      EXPECT_TRUE(planIsValid(p, *plan));
    }
    if (opt != kNone) {
      auto plan = regressionSearch(p, "lmcut");
      std::vector<int> a = plan->actions, b = slots->actions;
      std::sort(a.begin(), a.end());
      std::sort(b.begin(), b.end());
      moved += a != b;
    }
  }
  EXPECT_GE(limited, 100);
  EXPECT_GE(moved, 30);  // the weights matter: many optima differ from the slot model's
}

TEST(SearchCostsProperty, LibrariesWithProfilesMatchOracle) {
  for (uint64_t seed = 1; seed <= 40; ++seed) {
    SCOPED_TRACE(::testing::Message() << "seed " << seed);
    Problem p = sgtest::randomLibrary(sgtest::LibraryShape{20 + static_cast<int>(seed * 5), seed});
    std::mt19937 rng(static_cast<uint32_t>(seed));
    sgtest::addRandomProfile(p, seed);
    if (seed % 2 == 0) bindAttributeLimit(p, rng);
    auto oracle = integerProgramSearch(p);
    SearchStats st;
    auto plan = solveWith(p, "auto", &st);
    ASSERT_EQ(plan.has_value(), oracle.has_value());
    if (!plan) continue;
    EXPECT_EQ(st.engine, "regression");
    EXPECT_EQ(plan->cost, oracle->cost);
    EXPECT_TRUE(planIsValid(p, *plan));
  }
}

// The slot weights price every action at its arithmetic term and every input at 0: the
// search finds exactly what it found before the cost model had terms.
TEST(SearchCosts, SlotWeightsReproduceThePlainCosts) {
  for (uint64_t seed = 1; seed <= 30; ++seed) {
    Problem p = sgtest::randomLibrary(sgtest::LibraryShape{40, seed});
    const std::optional<Plan> before = regressionSearch(p, "lmcut");
    sgtest::addRandomProfile(p, seed);
    priceProblem(p, kSlotWeights);
    const std::optional<Plan> after = regressionSearch(p, "lmcut");
    ASSERT_TRUE(before && after);
    EXPECT_EQ(after->cost, before->cost);
    EXPECT_EQ(after->actions, before->actions);
  }
}

// g1 <- r1 (reads a); g2 <- r2 (reads a, 3 slots) | r3 (reads b, 1 slot). Under slots r3
// wins; when an input location costs more than 2 slots' worth, r2 wins because the plan
// reads a anyway (paid once, not per reader).
Problem sharedInput() {
  Problem p;
  for (const char* n : {"a", "b", "g1", "g2"}) {
    Fact f;
    f.name = n;
    p.facts.push_back(f);
  }
  p.init = {0, 1};
  p.goals = {2, 3};
  p.limits = {ResourceLimit{"vertex input attributes", "--max-attributes", INT64_MAX}};
  for (int f = 0; f < 2; ++f) {
    p.facts[f].resource = f;
    ResourceItem item{p.facts[f].name, 0, 1};
    item.terms[kTermLocations] = 1;
    p.resources.push_back(item);
  }
  auto rule = [&](const char* name, int pre, int add, int64_t slots) {
    Action a{name, -1, {pre}, add, slots, {}};
    a.terms[kTermArithmetic] = slots;
    p.actions.push_back(a);
  };
  rule("r1", 0, 2, 1);
  rule("r2", 0, 3, 3);
  rule("r3", 1, 3, 1);
  return p;
}

std::vector<std::string> names(const Problem& p, const Plan& plan) {
  std::vector<std::string> out;
  for (int a : plan.actions) out.push_back(p.actions[a].name);
  std::sort(out.begin(), out.end());
  return out;
}

TEST(SearchCosts, AnInputIsPaidOncePerPlan) {
  Problem p = sharedInput();
  priceProblem(p, kSlotWeights);
  for (const char* engine : {"regression", "forward", "ip"}) {
    auto plan = solveWith(p, engine);
    ASSERT_TRUE(plan);
    EXPECT_EQ(names(p, *plan), (std::vector<std::string>{"r1", "r3"})) << engine;
    EXPECT_EQ(plan->cost, 2) << engine;
  }
  // 10 per slot, 25 per location: r1 + r3 = 20 + 50 (a, b); r1 + r2 = 40 + 25 (a once).
  TermWeights w{};
  w[kTermArithmetic] = 10;
  w[kTermLocations] = 25;
  priceProblem(p, w);
  for (const char* engine : {"regression", "forward", "ip"}) {
    auto plan = solveWith(p, engine);
    ASSERT_TRUE(plan);
    EXPECT_EQ(names(p, *plan), (std::vector<std::string>{"r1", "r2"})) << engine;
    EXPECT_EQ(plan->cost, 65) << engine;
  }
  // At 15 per location reading b is cheaper again: 20 + 30 against 40 + 15.
  w[kTermLocations] = 15;
  priceProblem(p, w);
  EXPECT_EQ(names(p, *regressionSearch(p, "lmcut")), (std::vector<std::string>{"r1", "r3"}));
  EXPECT_EQ(integerProgramSearch(p)->cost, 50);
}

// The prediction adds each term over the plan's rules, its inputs once and the fixed terms.
TEST(SearchCosts, PredictionSumsTermsOnce) {
  Problem p = sharedInput();
  p.fixedTerms[kTermOutputs] = 8;
  p.fixedTerms[kTermVertices] = 1;
  DeviceProfile prof;
  prof.device = "test";
  prof.nanoseconds[kTermArithmetic] = 0.01;
  prof.nanoseconds[kTermLocations] = 0.5;
  prof.nanoseconds[kTermOutputs] = 0.125;
  prof.nanoseconds[kTermVertices] = 2;
  applyDeviceProfile(p, prof);
  auto plan = regressionSearch(p, "lmcut");
  ASSERT_TRUE(plan);
  // r1 + r2 reads only a: 4 slots, 1 location; 0.04 + 0.5 + 1 + 2 ns.
  EXPECT_EQ(names(p, *plan), (std::vector<std::string>{"r1", "r2"}));
  PlanCostPrediction c = predictPlanCost(*plan, p, prof);
  EXPECT_EQ(c.amounts[kTermArithmetic], 4);
  EXPECT_EQ(c.amounts[kTermLocations], 1);
  EXPECT_EQ(c.amounts[kTermOutputs], 8);
  EXPECT_DOUBLE_EQ(c.nanoseconds[kTermLocations], 0.5);
  EXPECT_DOUBLE_EQ(c.totalNanoseconds, 3.54);
  EXPECT_EQ(plan->cost, 3'540'000);  // femtoseconds
}

}  // namespace
}  // namespace sg

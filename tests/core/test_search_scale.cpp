// Issue 12: the search at the scale of real rules libraries. Seeded synthetic libraries
// (tests/support/random_library.h) solved by regression A* and checked against the exact
// integer program (GLPK), itself checked against exhaustive enumeration in test_search;
// search effort against the forward LM-cut A*; budgets that end in a named error; the
// shipped rules take the regression engine.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "pipeline/generate.h"
#include "random_library.h"
#include "search/heuristic.h"
#include "search/ip_oracle.h"
#include "search/regression.h"
#include "search/search.h"
#include "search_test_util.h"

namespace sg {
namespace {

using sgtest::LibraryShape;
using sgtest::randomLibrary;

// 1,000 small libraries (8-60 rules): regression A* (default heuristic) finds the
// oracle's optimum with a valid plan; its initial h never exceeds the optimum.
TEST(SearchProperty, ThousandSmallLibrariesMatchOracle) {
  int strictlyBetterThanH0 = 0;
  for (uint64_t seed = 1; seed <= 1000; ++seed) {
    LibraryShape shape;
    shape.rules = 8 + static_cast<int>(seed % 53);
    shape.seed = seed;
    Problem p = randomLibrary(shape);
    SCOPED_TRACE(::testing::Message() << "seed " << seed << ", " << shape.rules << " rules");
    auto oracle = integerProgramSearch(p);
    ASSERT_TRUE(oracle.has_value());  // the generator makes every semantic derivable
    SearchStats st;
    auto plan = findPlan(p, SearchOptions{}, &st);
    ASSERT_TRUE(plan.has_value());
    ASSERT_EQ(st.engine, "regression");
    EXPECT_EQ(plan->cost, oracle->cost);
    EXPECT_TRUE(planIsValid(p, *plan));
    EXPECT_LE(st.initialH, plan->cost);
    if (st.initialH < plan->cost) ++strictlyBetterThanH0;
  }
  // The instances are not trivial for the heuristic.
  EXPECT_GE(strictlyBetterThanH0, 100);
}

// 50 libraries of 300 rules, the size the forward search could not finish.
TEST(SearchProperty, FiftyLibrariesOf300RulesMatchOracle) {
  for (uint64_t seed = 1; seed <= 50; ++seed) {
    Problem p = randomLibrary(LibraryShape{300, 1000 + seed});
    SCOPED_TRACE(::testing::Message() << "seed " << 1000 + seed);
    auto oracle = integerProgramSearch(p);
    ASSERT_TRUE(oracle.has_value());
    SearchStats st;
    auto plan = findPlan(p, SearchOptions{}, &st);
    ASSERT_TRUE(plan.has_value());
    EXPECT_EQ(plan->cost, oracle->cost);
    EXPECT_TRUE(planIsValid(p, *plan));
  }
}

// The larger run documented in docs/search.md (minutes, not in CI):
//   SHADERGEN_SEARCH_LONG=1 build/tests/core/test_search_scale --gtest_filter='*LargerRun*'
TEST(SearchProperty, LargerRun) {
  if (!std::getenv("SHADERGEN_SEARCH_LONG")) GTEST_SKIP() << "set SHADERGEN_SEARCH_LONG=1 for the larger run";
  struct Batch {
    int count, minRules, maxRules, cyclicPercent;
    uint64_t firstSeed;
  };
  for (const Batch& b : {Batch{10000, 8, 60, 0, 100000}, Batch{2000, 8, 30, 25, 200000},
                         Batch{500, 61, 300, 0, 300000}, Batch{100, 1000, 1000, 0, 400000}}) {
    int64_t mostExpanded = 0;
    int unsolvable = 0;
    for (int i = 0; i < b.count; ++i) {
      LibraryShape shape{b.minRules + i % (b.maxRules - b.minRules + 1), b.firstSeed + static_cast<uint64_t>(i)};
      shape.cyclicPercent = b.cyclicPercent;
      Problem p = randomLibrary(shape);
      SCOPED_TRACE(::testing::Message() << "seed " << shape.seed << ", " << shape.rules << " rules");
      auto oracle = integerProgramSearch(p);
      // Cyclic needs can leave a semantic underivable: then no engine finds a plan.
      if (b.cyclicPercent == 0) ASSERT_TRUE(oracle.has_value());
      SearchStats st;
      auto plan = findPlan(p, SearchOptions{}, &st);
      ASSERT_EQ(plan.has_value(), oracle.has_value());
      if (!plan) {
        ++unsolvable;
        continue;
      }
      ASSERT_EQ(plan->cost, oracle->cost);
      ASSERT_TRUE(planIsValid(p, *plan));
      mostExpanded = std::max<int64_t>(mostExpanded, st.expanded);
    }
    std::printf("%d libraries of %d-%d rules (%d%% rules with a cyclic need): %d unsolvable (as the oracle says), "
                "the rest optimal; most expansions %lld\n",
                b.count, b.minRules, b.maxRules, b.cyclicPercent, unsolvable, static_cast<long long>(mostExpanded));
  }
}

// Every regression heuristic is admissible and finds the optimum; LM-cut (maxed with
// the landmark sum) dominates the landmark sum and h_max at the initial state.
TEST(SearchProperty, RegressionHeuristicsAgreeAndAreOrdered) {
  for (uint64_t seed = 1; seed <= 60; ++seed) {
    Problem p = randomLibrary(LibraryShape{8 + static_cast<int>(seed % 23), 5000 + seed});
    SCOPED_TRACE(::testing::Message() << "seed " << 5000 + seed);
    int64_t opt = integerProgramSearch(p)->cost;
    int64_t h0[4];
    int i = 0;
    for (const char* h : {"blind", "hmax", "landmarks", "lmcut"}) {
      SearchStats st;
      auto plan = regressionSearch(p, h, &st);
      ASSERT_TRUE(plan.has_value()) << h;
      EXPECT_EQ(plan->cost, opt) << h;
      EXPECT_LE(st.initialH, opt) << h;
      h0[i++] = st.initialH;
    }
    EXPECT_EQ(h0[0], 0);
    EXPECT_GE(h0[3], h0[1]);
    EXPECT_GE(h0[3], h0[2]);
  }
}

// Cyclic rule graphs: regression does not apply, "auto" falls back to forward A*, and
// both agree with the oracle (whose acyclicity constraints are exercised here).
TEST(SearchProperty, CyclicLibrariesFallBackToForward) {
  int cyclic = 0;
  for (uint64_t seed = 1; seed <= 80; ++seed) {
    LibraryShape shape{10 + static_cast<int>(seed % 15), 7000 + seed};
    shape.cyclicPercent = 25;
    Problem p = randomLibrary(shape);
    SCOPED_TRACE(::testing::Message() << "seed " << shape.seed);
    auto oracle = integerProgramSearch(p);
    SearchStats st;
    auto plan = findPlan(p, SearchOptions{}, &st);
    ASSERT_EQ(plan.has_value(), oracle.has_value());  // cyclic needs can make a goal underivable
    EXPECT_EQ(st.engine, regressionApplies(p) ? "regression" : "forward");
    if (!plan) continue;
    EXPECT_EQ(plan->cost, oracle->cost);
    EXPECT_TRUE(planIsValid(p, *plan));
    if (!regressionApplies(p)) {
      ++cyclic;
      EXPECT_THROW(findPlan(p, SearchOptions{"regression"}), std::invalid_argument);
    }
  }
  EXPECT_GE(cyclic, 20);
}

// The bar: never more expansions than the forward LM-cut A* (on libraries small
// enough for the forward search to finish quickly).
TEST(SearchEffort, RegressionExpandsNoMoreThanForwardLmCut) {
  int64_t regressionTotal = 0, forwardTotal = 0;
  for (uint64_t seed = 1; seed <= 60; ++seed) {
    Problem p = randomLibrary(LibraryShape{10 + static_cast<int>(seed % 31), 9000 + seed});
    SCOPED_TRACE(::testing::Message() << "seed " << 9000 + seed);
    SearchStats reg, fwd;
    auto a = findPlan(p, SearchOptions{"regression"}, &reg);
    auto b = findPlan(p, SearchOptions{"forward"}, &fwd);
    ASSERT_TRUE(a && b);
    EXPECT_EQ(a->cost, b->cost);
    EXPECT_LE(reg.expanded, fwd.expanded);
    regressionTotal += reg.expanded;
    forwardTotal += fwd.expanded;
  }
  std::printf("expansions over 60 libraries: regression %lld, forward LM-cut %lld\n",
              static_cast<long long>(regressionTotal), static_cast<long long>(forwardTotal));
}

// Budgets end a search with an error naming the limit, never a hang.
TEST(SearchLimits, ExpansionAndTimeLimitsNameTheLimit) {
  Problem p = randomLibrary(LibraryShape{300, 42});
  for (const char* engine : {"regression", "forward"}) {
    SCOPED_TRACE(engine);
    SearchOptions o{engine, "blind"};
    o.limits.maxExpansions = 5;
    try {
      findPlan(p, o);
      ADD_FAILURE() << "no limit error";
    } catch (const SearchLimitError& e) {
      EXPECT_NE(std::string(e.what()).find("expansion limit of 5"), std::string::npos) << e.what();
    }
    o.limits.maxExpansions = SearchLimits{}.maxExpansions;
    o.limits.maxSeconds = 0.02;  // blind search on 300 rules needs far longer
    try {
      findPlan(p, o);
      ADD_FAILURE() << "no limit error";
    } catch (const SearchLimitError& e) {
      EXPECT_NE(std::string(e.what()).find("time limit of 0.02 s"), std::string::npos) << e.what();
    }
  }
  // Within its budget the same search succeeds.
  SearchOptions o;
  o.limits.maxExpansions = 1000;
  EXPECT_TRUE(findPlan(p, o).has_value());
}

TEST(SearchLimits, UnknownEngineOrHeuristic) {
  Problem p = randomLibrary(LibraryShape{20, 1});
  EXPECT_THROW(findPlan(p, SearchOptions{"sideways"}), std::invalid_argument);
  EXPECT_THROW(findPlan(p, SearchOptions{"regression", "nope"}), std::invalid_argument);
  EXPECT_THROW(findPlan(p, SearchOptions{"forward", "landmarks"}), std::invalid_argument);
}

// Unreachable goals: every engine reports no plan.
TEST(SearchEngines, UnreachableGoal) {
  Problem p = randomLibrary(LibraryShape{30, 3});
  Fact lonely;
  lonely.name = "nobody.makes.this";
  p.facts.push_back(lonely);
  p.goals.push_back(static_cast<int>(p.facts.size()) - 1);
  for (const char* engine : {"auto", "regression", "forward", "ip"}) {
    SearchStats st;
    EXPECT_FALSE(findPlan(p, SearchOptions{engine}, &st).has_value()) << engine;
    EXPECT_EQ(st.finalCost, -1) << engine;
  }
}

// Same input, same plan (action order included), run after run.
TEST(SearchEngines, Deterministic) {
  Problem p = randomLibrary(LibraryShape{1000, 77});
  auto a = findPlan(p, SearchOptions{});
  auto b = findPlan(p, SearchOptions{});
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->actions, b->actions);
  EXPECT_EQ(a->cost, b->cost);
}

// The generator: well-formed, seeded, the requested shape.
TEST(RandomLibrary, ShapeAndDeterminism) {
  for (int rules : {10, 100, 1000}) {
    Problem p = randomLibrary(LibraryShape{rules, 9});
    EXPECT_EQ(static_cast<int>(p.actions.size()), rules);
    size_t computed = p.facts.size() - p.init.size();
    EXPECT_GE(p.goals.size(), std::min<size_t>(5, computed));
    EXPECT_LE(p.goals.size(), 10u);
    for (int g : p.goals) EXPECT_EQ(std::count(p.init.begin(), p.init.end(), g), 0);
    for (const auto& a : p.actions) {
      EXPECT_GE(a.pre.size(), 1u);
      EXPECT_LE(a.pre.size(), 3u);
      EXPECT_GE(a.cost, 1);
      EXPECT_LE(a.cost, 10);
      EXPECT_TRUE(std::is_sorted(a.pre.begin(), a.pre.end()));
    }
    Problem q = randomLibrary(LibraryShape{rules, 9});
    EXPECT_EQ(q.goals, p.goals);
    EXPECT_TRUE(regressionApplies(p));
  }
}

// The shipped rules: the Dawn rigs' problems are acyclic (the regression engine runs) and
// every engine finds the same cost.
TEST(SearchShipped, DawnTakesRegressionAndMatchesOracle) {
  const std::string dir = std::string(SG_SOURCE_DIR) + "/examples/dawn/";
  for (const char* rig : {"face.rig.yaml", "body.rig.yaml"}) {
    SCOPED_TRACE(rig);
    GenerateOptions o;
    o.rigPath = dir + rig;
    o.fragmentPath = dir + "face.frag";
    o.rulesPaths = {dir + "rules.yaml"};
    LoadedInputs in = loadInputs(o);
    SearchStats st;
    auto plan = findPlan(in.problem, SearchOptions{}, &st);
    ASSERT_TRUE(plan.has_value());
    EXPECT_EQ(st.engine, "regression");
    EXPECT_EQ(st.initialH, plan->cost);  // LM-cut over open sets is exact here
    auto oracle = integerProgramSearch(in.problem);
    ASSERT_TRUE(oracle.has_value());
    EXPECT_EQ(plan->cost, oracle->cost);
    SearchStats fwd;
    auto forward = findPlan(in.problem, SearchOptions{"forward"}, &fwd);
    ASSERT_TRUE(forward.has_value());
    EXPECT_EQ(forward->cost, plan->cost);
    EXPECT_LE(st.expanded, fwd.expanded);
  }
}

}  // namespace
}  // namespace sg

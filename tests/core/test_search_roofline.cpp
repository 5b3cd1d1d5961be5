// Roofline objectives in the search (issue 33, docs/search.md "Roofline objectives"): a plan
// costs the largest of several weighted sums of its term amounts (one per pipe a device
// overlaps, or one per device of a portable choice). Every engine must return the optimum:
// checked against an exhaustive solver written from that definition on small random
// instances (with and without binding device limits), the integer program against A* on
// larger libraries, and a hand-made instance where the largest pipe, not the sum, decides.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
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

// 2-4 components, each a random subset of the terms with random weights: a roofline's pipes
// over a shared additive part, as a profile builds them (search/device_profile.h). `magnitude`
// scales the weights: a real profile's are femtoseconds per unit (10^3 to 10^6), a portable
// choice's parts per 10^9 of a device's best (up to 10^8), where small ones are 1-30.
std::vector<TermWeights> randomComponents(uint64_t seed, int64_t magnitude = 1) {
  std::mt19937_64 rng(seed * 104729 + 3);
  auto pick = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
  auto weight = [&](int lo, int hi) {
    return pick(lo, hi) * magnitude + std::uniform_int_distribution<int64_t>(0, magnitude - 1)(rng);
  };
  TermWeights shared{};
  shared[kTermVertices] = weight(0, 20);
  const int k = pick(2, 4);
  std::vector<TermWeights> out;
  for (int c = 0; c < k; ++c) {
    TermWeights w = shared;
    for (size_t t = 0; t < kTermCount; ++t)
      if (pick(0, 2) == 0) w[t] += weight(1, 30);
    out.push_back(w);
  }
  return out;
}

// One goal, "out" from "in", reached by the ways addWay adds: each one action paying `locations`
// and `loads` (the fetch and memory pipes' terms).
Problem oneGoal() {
  Problem p;
  p.facts = {Fact{"in"}, Fact{"out"}};
  p.init = {0};
  p.goals = {1};
  return p;
}
void addWay(Problem& p, const char* name, int locations, int loads) {
  Action a{name, static_cast<int>(p.actions.size()), {0}, 1};
  a.terms[kTermLocations] = locations;
  a.terms[kTermBufferLoads] = loads;
  p.actions.push_back(a);
}

// From the definition: the cheapest feasible subset (exhaustiveMinimum), its amounts the fired
// actions' terms, each distinct item's terms once and the fixed terms (firedAmounts), its cost the
// largest component's weighted sum.
TermAmounts firedAmounts(const Problem& p, const std::vector<bool>& fired, const std::set<int>& items) {
  TermAmounts amounts = p.fixedTerms;
  for (size_t a = 0; a < fired.size(); ++a)
    if (fired[a])
      for (size_t t = 0; t < kTermCount; ++t) amounts[t] += p.actions[a].terms[t];
  for (int i : items)
    for (size_t t = 0; t < kTermCount; ++t) amounts[t] += p.resources[i].terms[t];
  return amounts;
}
int64_t exhaustiveLargest(const Problem& p) {
  return exhaustiveMinimum(p, [&](const std::vector<bool>& fired, const std::set<int>& items) {
    const TermAmounts amounts = firedAmounts(p, fired, items);
    int64_t cost = 0;
    for (const TermWeights& w : p.componentWeights) {
      int64_t c = 0;
      for (size_t t = 0; t < kTermCount; ++t) c += w[t] * amounts[t];
      cost = std::max(cost, c);
    }
    return cost;
  });
}

// Every engine against the exhaustive solver on 200 random instances whose component weights
// are of the given magnitude; returns (instances with a binding limit, instances where the sum's
// optimum is not the roofline's).
std::pair<int, int> checkRandomRooflines(int64_t magnitude) {
  int limited = 0, differs = 0;
  for (uint64_t seed = 1; seed <= 200; ++seed) {
    SCOPED_TRACE(::testing::Message() << "seed " << seed << ", weights of magnitude " << magnitude);
    Problem p = sgtest::randomLibrary(sgtest::LibraryShape{8 + static_cast<int>(seed % 9), seed, 2, 4});
    sgtest::addRandomProfile(p, seed);
    const std::optional<Plan> additive = integerProgramSearch(p);
    priceProblemByMax(p, randomComponents(seed, magnitude));
    if (seed % 3 == 0 && additive) {  // cap the attributes just below the additive optimum's use
      p.limits[0].max = std::max<int64_t>(0, resourceUsage(p, additive->actions)[0] - static_cast<int64_t>(seed % 2));
      ++limited;
    }
    const int64_t opt = exhaustiveLargest(p);
    for (const char* h : {"blind", "hmax", "landmarks", "lmcut"}) {
      SCOPED_TRACE(h);
      SearchStats st;
      auto plan = regressionSearch(p, h, &st);
      EXPECT_EQ(plan.has_value(), opt != kNone);
      if (!plan) continue;
      EXPECT_EQ(plan->cost, opt);
      EXPECT_EQ(plan->cost, weighPlan(p, planAmounts(p, plan->actions)));
      EXPECT_LE(st.initialH, opt);  // the estimate stays a lower bound
      EXPECT_LT(exceededLimit(p, resourceUsage(p, plan->actions)), 0);
    }
    for (const char* engine : {"ip", "forward", "auto"}) {
      SCOPED_TRACE(engine);
      auto plan = solveWith(p, engine);
      EXPECT_EQ(plan.has_value(), opt != kNone);
      if (plan) EXPECT_EQ(plan->cost, opt);
    }
    if (additive && opt != kNone) {
      // The additive optimum priced by the largest component: often not the roofline's best.
      differs += weighPlan(p, planAmounts(p, additive->actions)) > opt;
    }
  }
  return {limited, differs};
}

TEST(SearchRooflineProperty, RandomRooflinesMatchExhaustiveSolver) {
  const auto [limited, differs] = checkRandomRooflines(1);
  EXPECT_GE(limited, 60);
  EXPECT_GE(differs, 10);  // the max matters: the sum's plan is often not the roofline's
}

// At a device's magnitudes (10^4 to 10^7 per unit, costs past 10^9) the integer program once
// proved a plan optimal at 1.22x the optimum: GLPK's presolver mishandled the large
// coefficients of the auxiliary max's rows (search/ip_oracle.cpp).
TEST(SearchRooflineProperty, RandomRooflinesAtDeviceMagnitudesMatchExhaustiveSolver) {
  for (int64_t magnitude : {int64_t{10'000}, int64_t{10'000'000}}) {
    const auto [limited, differs] = checkRandomRooflines(magnitude);
    EXPECT_GE(limited, 60);
    EXPECT_GE(differs, 10);
  }
}

TEST(SearchRooflineProperty, LibrariesMatchIntegerProgram) {
  for (uint64_t seed = 1; seed <= 25; ++seed) {
    SCOPED_TRACE(::testing::Message() << "seed " << seed);
    Problem p = sgtest::randomLibrary(sgtest::LibraryShape{20 + static_cast<int>(seed * 4), seed});
    sgtest::addRandomProfile(p, seed);
    priceProblemByMax(p, randomComponents(seed + 1000));
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

// One goal, two ways: A reads 3 fetch units and 3 memory units (sum 6, largest pipe 3);
// B reads 5 fetch units (sum 5, largest 5). A sum prefers B; overlapping pipes prefer A.
TEST(SearchRoofline, TheLargestPipeDecidesNotTheSum) {
  Problem p = oneGoal();
  addWay(p, "overlapped", 3, 3);
  addWay(p, "fetch_only", 5, 0);
  TermWeights fetch{}, memory{}, sum{};
  fetch[kTermLocations] = 1;
  memory[kTermBufferLoads] = 1;
  sum[kTermLocations] = sum[kTermBufferLoads] = 1;
  priceProblem(p, sum);
  auto additive = solveWith(p, "auto");
  ASSERT_TRUE(additive);
  EXPECT_EQ(p.actions[additive->actions[0]].name, "fetch_only");
  priceProblemByMax(p, {fetch, memory});
  for (const char* engine : {"auto", "ip", "forward"}) {
    auto plan = solveWith(p, engine);
    ASSERT_TRUE(plan) << engine;
    EXPECT_EQ(p.actions[plan->actions[0]].name, "overlapped") << engine;
    EXPECT_EQ(plan->cost, 3) << engine;
  }
}

// One component is the additive model itself: the same plans and costs as priceProblem.
TEST(SearchRoofline, OneComponentIsTheSum) {
  for (uint64_t seed = 1; seed <= 30; ++seed) {
    Problem p = sgtest::randomLibrary(sgtest::LibraryShape{30, seed});
    sgtest::addRandomProfile(p, seed);
    const TermWeights w = p.weights;
    auto before = solveWith(p, "auto");
    priceProblemByMax(p, {w});
    EXPECT_TRUE(p.componentWeights.empty());
    auto after = solveWith(p, "auto");
    ASSERT_EQ(before.has_value(), after.has_value());
    if (before) {
      EXPECT_EQ(before->actions, after->actions);
      EXPECT_EQ(before->cost, after->cost);
    }
  }
}

}  // namespace
}  // namespace sg

namespace sg {
namespace {

// A portable choice (docs/device-profiles.md, "Portable plans"): three ways to one goal; device
// A pays locations, device B pays buffer loads. "fetch" is A's best (2 vs B's 10), "load" is
// B's best (2 vs A's 10), "mixed" costs 3 on both: regrets fetch 5x (on B), load 5x (on A),
// mixed 1.5x on both. The least worst-case regret is "mixed", though neither device prefers it.
TEST(SearchRoofline, APortablePlanMinimisesTheWorstRegret) {
  Problem p = oneGoal();
  addWay(p, "fetch", 2, 10);
  addWay(p, "load", 10, 2);
  addWay(p, "mixed", 3, 3);
  DeviceProfile a, b;
  a.device = "A";
  a.nanoseconds[kTermLocations] = 1;
  b.device = "B";
  b.nanoseconds[kTermBufferLoads] = 1;
  std::vector<int64_t> best;
  for (const DeviceProfile* d : {&a, &b}) {
    Problem one = p;
    applyDeviceProfile(one, *d);
    auto plan = solveWith(one, "auto");
    ASSERT_TRUE(plan);
    best.push_back(plan->cost);
  }
  EXPECT_EQ(best, (std::vector<int64_t>{2 * kFemtosecondsPerNanosecond, 2 * kFemtosecondsPerNanosecond}));
  applyPortableProfiles(p, {a, b}, best);
  for (const char* engine : {"auto", "ip"}) {
    auto plan = solveWith(p, engine);
    ASSERT_TRUE(plan) << engine;
    EXPECT_EQ(p.actions[plan->actions[0]].name, "mixed") << engine;
    EXPECT_EQ(plan->cost, kRegretScale * 3 / 2) << engine;  // 1.5x the best on both devices
  }
}

// The prediction of a roofline profile shows each term's price in its pipe, and those prices
// add up to the pipe's line: a reader can see why a pipe is the slowest.
TEST(SearchRoofline, ThePredictionShowsEachTermInItsPipe) {
  Problem p = oneGoal();
  addWay(p, "fetch_and_load", 3, 2);
  DeviceProfile prof;
  prof.device = "test";
  prof.nanoseconds[kTermVertices] = 1;
  p.fixedTerms[kTermVertices] = 1;
  DeviceProfile::Pipe fetch, memory;
  fetch.name = "fetch";
  fetch.nanoseconds[kTermLocations] = 0.5;
  memory.name = "memory";
  memory.nanoseconds[kTermBufferLoads] = 0.25;
  prof.pipes = {fetch, memory};
  applyDeviceProfile(p, prof);
  auto plan = solveWith(p, "auto");
  ASSERT_TRUE(plan);
  const std::string text = describePlanCost(*plan, p, prof);
  EXPECT_NE(text.find("+ 0.500000 x 3 = 1.500 in fetch"), std::string::npos) << text;
  EXPECT_NE(text.find("+ 0.250000 x 2 = 0.500 in memory"), std::string::npos) << text;
  EXPECT_NE(text.find("pipe fetch"), std::string::npos) << text;
  // 1 ns fixed + the slowest pipe (fetch, 1.5 ns); the memory pipe's 0.5 ns overlaps.
  EXPECT_DOUBLE_EQ(predictPlanCost(*plan, p, prof).totalNanoseconds, 2.5);
}

// A profile "test" of two pipes, each pricing one term.
struct PipeTerm {
  const char* name;
  int term;
  double ns;
};
DeviceProfile twoPipes(PipeTerm a, PipeTerm b) {
  DeviceProfile prof;
  prof.device = "test";
  for (const PipeTerm& x : {a, b}) {
    DeviceProfile::Pipe pipe;
    pipe.name = x.name;
    pipe.nanoseconds[static_cast<size_t>(x.term)] = x.ns;
    prof.pipes.push_back(pipe);
  }
  return prof;
}

// Pipes that overlap imperfectly (DeviceProfile::pipeSumShare s): a program pays its slowest
// pipe plus s times the others. "overlapped" reads 3 fetch and 3 memory units (1 ns each):
// 3 + 3s; "fetch_only" 5 fetch units: 5. The first wins while s < 2/3, the second above it, in
// every engine, and the prediction's total is the plan's cost.
TEST(SearchRoofline, PipesThatOverlapImperfectlyPayAShareOfTheOthers) {
  DeviceProfile prof = twoPipes({"fetch", kTermLocations, 1}, {"memory", kTermBufferLoads, 1});
  for (double share : {0.0, 0.5, 0.8}) {
    prof.pipeSumShare = share;
    Problem p = oneGoal();
    addWay(p, "overlapped", 3, 3);
    addWay(p, "fetch_only", 5, 0);
    applyDeviceProfile(p, prof);
    const bool overlapped = 3 + 3 * share < 5;
    const double ns = overlapped ? 3 + 3 * share : 5;
    for (const char* engine : {"auto", "ip", "forward"}) {
      auto plan = solveWith(p, engine);
      ASSERT_TRUE(plan) << engine;
      EXPECT_EQ(p.actions[plan->actions[0]].name, overlapped ? "overlapped" : "fetch_only") << engine << " at " << share;
      EXPECT_EQ(plan->cost, std::llround(ns * kFemtosecondsPerNanosecond)) << engine << " at " << share;
      const PlanCostPrediction c = predictPlanCost(*plan, p, prof);
      EXPECT_DOUBLE_EQ(c.totalNanoseconds, ns) << engine;
      EXPECT_DOUBLE_EQ(c.otherPipesNanoseconds, overlapped ? 3 * share : 0) << engine;
      if (share > 0) {
        const std::string text = describePlanCost(*plan, p, prof);
        EXPECT_NE(text.find(fmt::format("other pipes x {:g}", share)), std::string::npos) << text;
      }
    }
  }
}

// The search's components of a profile with a share reproduce its definition (additive + (1 - s)
// x slowest pipe + s x every pipe + each threshold's max(0, amount - at) x ns,
// DeviceProfile::predictNanoseconds) for random pipes, shares, thresholds, additive weights (on
// terms in pipes too) and amounts: the largest component is that sum, to the femtosecond rounding
// of each weight.
TEST(SearchRooflineProperty, ComponentsOfASharedProfileAreItsDefinition) {
  std::mt19937 rng(33);
  auto uniform = [&](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); };
  for (int instance = 0; instance < 300; ++instance) {
    DeviceProfile prof;
    prof.nanoseconds[kTermVertices] = uniform(0, 2);
    // Terms priced in the additive part too (the raster form's share outside the overlap).
    for (size_t t = 0; t < kTermCount; ++t)
      if (t != kTermVertices && t != kTermFragments && uniform(0, 1) < 0.3) prof.nanoseconds[t] = uniform(0, 0.3);
    const int pipes = 2 + instance % 4;
    for (int k = 0; k < pipes; ++k) {
      DeviceProfile::Pipe pipe;
      pipe.name = "p" + std::to_string(k);
      for (size_t t = 0; t < kTermCount; ++t)
        if (t != kTermVertices && t != kTermFragments && uniform(0, 1) < 0.4) pipe.nanoseconds[t] = uniform(0, 0.8);
      prof.pipes.push_back(pipe);
    }
    prof.pipeSumShare = instance % 3 == 0 ? 0 : uniform(0, 1);
    // Prices past a threshold on up to three terms (DeviceProfile::thresholds).
    for (size_t t = 0; t < kTermCount && prof.thresholds.size() < size_t(instance % 4); ++t)
      if (t != kTermVertices && t != kTermFragments && uniform(0, 1) < 0.3)
        prof.thresholds.push_back({static_cast<int>(t), std::floor(uniform(0, 150)), uniform(0, 2)});
    TermAmounts a{};
    a[kTermVertices] = 1;
    for (size_t t = 0; t < kTermCount; ++t)
      if (t != kTermVertices && t != kTermFragments) a[t] = std::uniform_int_distribution<int64_t>(0, 200)(rng);
    int64_t largest = 0;
    for (const TermWeights& w : profileComponents(prof)) largest = std::max(largest, weighTerms(w, a));
    int64_t units = 0;
    for (int64_t x : a) units += x;
    EXPECT_NEAR(static_cast<double>(largest) / kFemtosecondsPerNanosecond, prof.predictNanoseconds(a, 1000),
                1e-6 * static_cast<double>(units + 1) * double(1 + prof.thresholds.size()) + 1e-9)
        << "instance " << instance << ", share " << prof.pipeSumShare << ", thresholds " << prof.thresholds.size();
  }
}

// A price past a threshold (DeviceProfile::thresholds): 0.1 ns per location and 1 per buffer load,
// and 2 ns more per location past 14. "attributes" reads 16 locations: 1.6 + 2 x 2 = 5.6 ns;
// "buffered" 14 and 2 loads: 1.4 + 2 = 3.4. Without the threshold: 1.6 against 3.4. Every engine
// follows it, and the prediction shows the hinge on a line of its own.
TEST(SearchRoofline, AThresholdPricesOnlyTheUnitsPastIt) {
  for (bool threshold : {false, true}) {
    for (bool pipes : {false, true}) {
      DeviceProfile prof;
      prof.device = "test";
      prof.nanoseconds[kTermLocations] = 0.1;
      if (pipes) {  // the loads in a pipe of their own beside an empty one: the same prices
        prof = twoPipes({"memory", kTermBufferLoads, 1}, {"alu", kTermArithmetic, 1});
        prof.nanoseconds[kTermLocations] = 0.1;
      } else {
        prof.nanoseconds[kTermBufferLoads] = 1;
      }
      if (threshold) prof.thresholds.push_back({kTermLocations, 14, 2});
      Problem p = oneGoal();
      p.fixedTerms[kTermVertices] = 1;
      addWay(p, "attributes", 16, 0);
      addWay(p, "buffered", 14, 2);
      applyDeviceProfile(p, prof);
      const double ns = threshold ? 3.4 : 1.6;
      for (const char* engine : {"auto", "ip", "forward"}) {
        auto plan = solveWith(p, engine);
        ASSERT_TRUE(plan) << engine;
        EXPECT_EQ(p.actions[plan->actions[0]].name, threshold ? "buffered" : "attributes") << engine << (pipes ? ", pipes" : "");
        EXPECT_EQ(plan->cost, std::llround(ns * kFemtosecondsPerNanosecond)) << engine;
        EXPECT_DOUBLE_EQ(predictPlanCost(*plan, p, prof).totalNanoseconds, ns) << engine;
      }
      if (threshold) {  // the attributes' plan as the prediction shows it: 2 locations past 14, 4 ns
        Plan attributes;
        attributes.actions = {0};
        const PlanCostPrediction c = predictPlanCost(attributes, p, prof);
        ASSERT_EQ(c.thresholdNanoseconds.size(), 1u);
        EXPECT_DOUBLE_EQ(c.thresholdNanoseconds[0], 4);
        EXPECT_DOUBLE_EQ(c.totalNanoseconds, 5.6);
        const std::string text = describePlanCost(attributes, p, prof);
        EXPECT_NE(text.find("locations past 14"), std::string::npos) << text;
      }
    }
  }
}

// Every engine against the exhaustive solver under random profiles with thresholds, the cost
// computed from the definition (additive + slowest pipe + each max(0, amount - at) x price), not
// from the search's components: small integer femtosecond weights, so nothing is rounded.
TEST(SearchRooflineProperty, ThresholdsMatchExhaustiveSolverFromTheDefinition) {
  int binding = 0;
  for (uint64_t seed = 1; seed <= 150; ++seed) {
    SCOPED_TRACE(::testing::Message() << "seed " << seed);
    Problem p = sgtest::randomLibrary(sgtest::LibraryShape{8 + static_cast<int>(seed % 9), seed, 2, 4});
    sgtest::addRandomProfile(p, seed);
    std::mt19937_64 rng(seed * 31 + 7);
    auto pick = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
    constexpr double fs = 1.0 / kFemtosecondsPerNanosecond;
    DeviceProfile prof;
    for (int t : {kTermArithmetic, kTermLocations, kTermBufferLoads, kTermOutputs, kTermVertices}) prof.nanoseconds[size_t(t)] = pick(0, 12) * fs;
    if (seed % 2) {
      prof = twoPipes({"memory", kTermBufferLoads, pick(1, 20) * fs}, {"alu", kTermArithmetic, pick(1, 6) * fs});
      prof.nanoseconds[kTermLocations] = pick(0, 12) * fs;
    }
    prof.thresholds.push_back({kTermLocations, double(pick(0, 6)), pick(1, 40) * fs});
    if (seed % 3 == 0) prof.thresholds.push_back({kTermArithmetic, double(pick(0, 30)), pick(1, 10) * fs});
    applyDeviceProfile(p, prof);
    auto definition = [&](const TermAmounts& a) {
      auto fsOf = [](double ns) { return std::llround(ns * kFemtosecondsPerNanosecond); };
      int64_t cost = 0, slowest = 0;
      for (size_t t = 0; t < kTermCount; ++t) cost += fsOf(prof.nanoseconds[t]) * a[t];
      for (const DeviceProfile::Pipe& pipe : prof.pipes) {
        int64_t x = 0;
        for (size_t t = 0; t < kTermCount; ++t) x += fsOf(pipe.nanoseconds[t]) * a[t];
        slowest = std::max(slowest, x);
      }
      for (const DeviceProfile::Threshold& h : prof.thresholds)
        cost += fsOf(h.nanoseconds) * std::max<int64_t>(0, a[size_t(h.term)] - static_cast<int64_t>(h.at));
      return cost + slowest;
    };
    const int64_t opt = exhaustiveMinimum(
        p, [&](const std::vector<bool>& fired, const std::set<int>& items) { return definition(firedAmounts(p, fired, items)); });
    if (opt == kNone) continue;
    for (const char* h : {"blind", "hmax", "landmarks", "lmcut"}) {
      SearchStats st;
      auto plan = regressionSearch(p, h, &st);
      ASSERT_TRUE(plan) << h;
      EXPECT_EQ(plan->cost, opt) << h;
      EXPECT_EQ(definition(planAmounts(p, plan->actions)), opt) << h;
      EXPECT_LE(st.initialH, opt) << h;
    }
    for (const char* engine : {"ip", "forward", "auto"}) {
      auto plan = solveWith(p, engine);
      ASSERT_TRUE(plan) << engine;
      EXPECT_EQ(plan->cost, opt) << engine;
    }
    // Some optimum reads past a threshold, or avoids it at a price: the hinge is not idle.
    auto plan = solveWith(p, "auto");
    binding += plan && planAmounts(p, plan->actions)[kTermLocations] > static_cast<int64_t>(prof.thresholds[0].at);
  }
  EXPECT_GE(binding, 20);
}

// A profile's constant cache: a warp whose palette footprint is past its capacity pays the miss
// factor on every address, so the same two plans swap places across it, in every engine, and the
// prediction says which side of the capacity the workload is on.
TEST(SearchRoofline, TheConstantCacheMovesThePlanAcrossItsCapacity) {
  DeviceProfile prof = twoPipes({"memory", kTermBufferLoads, 0.25}, {"constant", kTermIndexedUniformLoads, 0.06});
  prof.scaledBy[kTermIndexedUniformLoads] = kFeatureJointsPerWarp;
  prof.constantCacheEntries = 29;
  prof.constantCacheMissFactor = 2;
  prof.workload.jointsPerWarp = 5;
  for (double footprint : {20.0, 40.0}) {
    Problem p = oneGoal();
    addWay(p, "buffer_palette", 0, 6);  // 6 x 0.25 = 1.5 ns in memory
    Action uniform{"uniform_palette", static_cast<int>(p.actions.size()), {0}, 1};
    uniform.terms[kTermIndexedUniformLoads] = 4;  // 4 x 5 joints x 0.06 = 1.2 ns, or 2.4 past the cache
    p.actions.push_back(uniform);
    prof.workload.paletteEntriesPerWarp = footprint;
    applyDeviceProfile(p, prof);
    for (const char* engine : {"auto", "ip"}) {
      auto plan = solveWith(p, engine);
      ASSERT_TRUE(plan) << engine;
      EXPECT_EQ(p.actions[plan->actions[0]].name, footprint < 29 ? "uniform_palette" : "buffer_palette") << engine;
      EXPECT_DOUBLE_EQ(predictPlanCost(*plan, p, prof).totalNanoseconds, footprint < 29 ? 1.2 : 1.5) << engine;
      const std::string text = describePlanCost(*plan, p, prof);
      EXPECT_NE(text.find(footprint < 29 ? "against its 29: within it" : "against its 29: past it, each address priced 2x"),
                std::string::npos)
          << text;
    }
  }
}

}  // namespace
}  // namespace sg

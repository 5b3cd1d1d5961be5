// pipeline/generate.h cheapestPlans and bansPinning, checked against an independent
// enumeration: every plan the search returns with any one or two rules banned. The k plans
// must be the k cheapest distinct plans of that enumeration and their own; and a plan pinned by
// bansPinning must stay the plan under other costs (no profile, another device's profile).
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <set>

#include "pipeline/generate.h"

namespace {

const std::string kSrc = SG_SOURCE_DIR;

struct Case {
  std::string rig, fragment, rules, profile;
};

std::vector<Case> cases() {
  const std::string dawn = kSrc + "/examples/dawn/", data = kSrc + "/tests/validate/data/";
  return {{dawn + "face.rig.yaml", dawn + "face.frag", dawn + "rules.yaml", kSrc + "/devices/llvmpipe-2core.yaml"},
          {dawn + "face.rig.yaml", dawn + "face.frag", dawn + "rules.yaml", ""},
          {data + "limb16.rig.yaml", data + "world.frag", kSrc + "/rules/standard.yaml", kSrc + "/devices/nvidia-h200-raster.yaml"},
          {data + "pbr_character.rig.yaml", kSrc + "/examples/threejs/standard_normalmap.frag", kSrc + "/rules/standard.yaml",
           kSrc + "/devices/nvidia-h200-raster.yaml"}};
}

sg::GenerateOptions optionsOf(const Case& c) {
  sg::GenerateOptions o;
  o.rigPath = c.rig;
  o.fragmentPath = c.fragment;
  o.rulesPaths = {c.rules};
  o.templateDir = kSrc + "/templates";
  o.deviceProfilePath = c.profile;
  return o;
}

// The plan's rule names, sorted, each once (cheapestPlans' identity of a plan), and its cost;
// nullopt where nothing serves the request under the bans.
std::optional<std::pair<std::vector<std::string>, int64_t>> search(const sg::LoadedInputs& in, sg::GenerateOptions o,
                                                                   const std::vector<std::string>& bans) {
  o.bannedRules.insert(o.bannedRules.end(), bans.begin(), bans.end());
  sg::LoadedInputs one = in;
  try {
    const sg::Plan p = sg::searchUnderOptions(one, o);
    std::set<std::string> names;
    for (int a : p.actions) names.insert(one.problem.actions[size_t(a)].name);
    return std::make_pair(std::vector<std::string>(names.begin(), names.end()), p.cost);
  } catch (const sg::InputError&) {
    return std::nullopt;
  }
}

TEST(CheapestPlans, AreTheCheapestOfEveryPlanOneOrTwoBansAway) {
  for (const Case& c : cases()) {
    SCOPED_TRACE(c.rig + " " + c.fragment + " " + (c.profile.empty() ? "slots" : c.profile));
    const sg::GenerateOptions o = optionsOf(c);
    const sg::LoadedInputs in = sg::loadInputs(o);
    const size_t k = 6;
    const std::vector<sg::RankedPlan> ranked = sg::cheapestPlans(in, o, k);
    ASSERT_GE(ranked.size(), 2u);
    ASSERT_LE(ranked.size(), k);

    // Each is what the search returns under its bans, the first is the search's own plan, and
    // no two are the same plan.
    std::set<std::vector<std::string>> seen;
    for (size_t i = 0; i < ranked.size(); ++i) {
      const auto again = search(in, o, ranked[i].bans);
      ASSERT_TRUE(again);
      EXPECT_EQ(again->first, ranked[i].rules);
      EXPECT_EQ(again->second, ranked[i].cost);
      EXPECT_TRUE(seen.insert(ranked[i].rules).second) << "plan " << i << " repeats an earlier one";
      if (i > 0) EXPECT_LE(ranked[i - 1].cost, ranked[i].cost);
    }
    EXPECT_TRUE(ranked.front().bans.empty());

    // The enumeration: every rule that any plan of it uses, banned alone and in pairs.
    std::map<std::vector<std::string>, int64_t> plans;
    std::set<std::string> rules;
    const auto base = search(in, o, {});
    plans[base->first] = base->second;
    for (const auto& r : base->first) rules.insert(r);
    std::vector<std::string> firstLevel(rules.begin(), rules.end());
    for (const auto& a : firstLevel)
      if (auto p = search(in, o, {a})) {
        plans[p->first] = p->second;
        for (const auto& r : p->first) rules.insert(r);
      }
    const std::vector<std::string> all(rules.begin(), rules.end());
    for (size_t i = 0; i < all.size(); ++i)
      for (size_t j = i + 1; j < all.size(); ++j)
        if (auto p = search(in, o, {all[i], all[j]})) plans[p->first] = p->second;
    for (const auto& r : ranked) plans[r.rules] = r.cost;
    std::vector<int64_t> costs;
    for (const auto& [names, cost] : plans) costs.push_back(cost);
    std::sort(costs.begin(), costs.end());
    ASSERT_GE(costs.size(), ranked.size());
    for (size_t i = 0; i < ranked.size(); ++i) EXPECT_EQ(ranked[i].cost, costs[i]) << "the " << i + 1 << "th cheapest plan";
    if (ranked.size() < k) EXPECT_EQ(costs.size(), ranked.size()) << "fewer than k found, but more exist";
  }
}

TEST(CheapestPlans, APinnedPlanStaysThePlanUnderOtherCosts) {
  for (const Case& c : cases()) {
    SCOPED_TRACE(c.rig + " " + (c.profile.empty() ? "slots" : c.profile));
    const sg::GenerateOptions o = optionsOf(c);
    const sg::LoadedInputs in = sg::loadInputs(o);
    for (const sg::RankedPlan& r : sg::cheapestPlans(in, o, 4)) {
      sg::GenerateOptions with = o;
      with.bannedRules = r.bans;
      const sg::GenerateResult g = sg::generateFrom(in, with);
      const std::vector<std::string> pin = sg::bansPinning(g.in.problem, g.plan, r.bans);
      for (const std::string other : {std::string(), kSrc + "/devices/nvidia-h200-raster.yaml", kSrc + "/devices/llvmpipe-2core.yaml"}) {
        sg::GenerateOptions elsewhere = o;
        elsewhere.deviceProfilePath = other;
        elsewhere.bannedRules = pin;
        const auto got = search(sg::loadInputs(elsewhere), elsewhere, {});
        ASSERT_TRUE(got);
        EXPECT_EQ(got->first, r.rules) << "under " << (other.empty() ? "slots" : other);
      }
    }
  }
}

}  // namespace

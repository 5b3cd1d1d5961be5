// Seeded generator of synthetic but well-formed rules libraries, emitted as search
// Problems directly (issue 12): layered semantics over a few rig inputs, 2-4
// alternative rules per semantic, 1-3 needs per rule drawn from lower layers with
// preferential attachment (popular intermediates are shared, so paying for a shared
// fact once matters), costs 1-10, 5-10 requested values from the upper layers.
// Header-only: used by tests/core and bench/.
#pragma once
#include <algorithm>
#include <cstdint>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "search/problem.h"

namespace sgtest {

struct LibraryShape {
  int rules = 100;
  uint64_t seed = 1;
  int minGoals = 5, maxGoals = 10;
  // Share of rules (percent) that also need a semantic of their own or a higher layer:
  // cyclic rule graphs, which the regression engine hands to the forward one.
  int cyclicPercent = 0;
};

inline sg::Problem randomLibrary(const LibraryShape& shape) {
  std::mt19937_64 rng(shape.seed);
  auto uniform = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
  sg::Problem p;
  // Alternatives per semantic: 2-4 until the rule count is reached (the last may get 1).
  std::vector<int> alternatives;
  for (int left = shape.rules; left > 0;) {
    int k = std::min(uniform(2, 4), left);
    alternatives.push_back(k);
    left -= k;
  }
  const int computed = static_cast<int>(alternatives.size());
  const int inputs = std::max(3, computed / 8);
  // Layers grow slowly with the library: 3 for tiny ones, ~10 for thousands of rules.
  int layers = 3;
  while ((1 << layers) < computed && layers < 10) ++layers;
  layers = std::max(3, layers - 2);
  std::vector<int> layerOf;
  for (int i = 0; i < inputs; ++i) {
    sg::Fact f;
    f.name = "in" + std::to_string(i);
    f.source = sg::Fact::Source::Attribute;
    p.facts.push_back(f);
    p.init.push_back(i);
    layerOf.push_back(0);
  }
  for (int i = 0; i < computed; ++i) {
    sg::Fact f;
    f.name = "s" + std::to_string(i);
    p.facts.push_back(f);
    layerOf.push_back(1 + i * layers / computed);
  }
  // Popularity pools per layer: a fact appears once plus once per use, so needs prefer
  // facts already needed elsewhere (sharing).
  std::vector<std::vector<int>> pool(layers + 1);
  for (int f = 0; f < static_cast<int>(p.facts.size()); ++f) pool[layerOf[f]].push_back(f);
  auto pickBelow = [&](int layer) {
    // Mostly the layer right below (depth), otherwise any lower layer.
    int l = uniform(0, 99) < 60 ? layer - 1 : uniform(0, layer - 1);
    const auto& v = pool[l];
    return v[std::uniform_int_distribution<size_t>(0, v.size() - 1)(rng)];
  };
  for (int i = 0; i < computed; ++i) {
    int fact = inputs + i, layer = layerOf[fact];
    for (int r = 0; r < alternatives[i]; ++r) {
      sg::Action a;
      a.name = "r" + std::to_string(p.actions.size());
      a.add = fact;
      std::set<int> pre;
      int needs = uniform(1, 3);
      for (int n = 0; n < needs; ++n) pre.insert(pickBelow(layer));
      if (shape.cyclicPercent > 0 && uniform(0, 99) < shape.cyclicPercent) {
        int other = inputs + uniform(0, computed - 1);
        if (other != fact && layerOf[other] >= layer) pre.insert(other);
      }
      a.pre.assign(pre.begin(), pre.end());
      for (int q : a.pre) pool[layerOf[q]].push_back(q);
      a.cost = uniform(1, 10);
      p.actions.push_back(std::move(a));
    }
  }
  // Goals: distinct semantics from the upper half of the layers.
  std::vector<int> upper;
  for (int f = inputs; f < static_cast<int>(p.facts.size()); ++f)
    if (layerOf[f] * 2 > layers) upper.push_back(f);
  std::shuffle(upper.begin(), upper.end(), rng);
  // Tiny libraries have few upper semantics: then the lower ones are requested too.
  for (int f = static_cast<int>(p.facts.size()) - 1; f >= inputs; --f)
    if (layerOf[f] * 2 <= layers) upper.push_back(f);
  int goals = std::min<int>(uniform(shape.minGoals, shape.maxGoals), computed);
  p.goals.assign(upper.begin(), upper.begin() + goals);
  std::sort(p.goals.begin(), p.goals.end());
  return p;
}

// A random device profile over a library (issue 21): the actions' costs become their
// arithmetic term, some actions get buffer and indexed uniform loads, every rig input a
// resource item with 1-2 locations and 4-16 bytes (read once per plan), the plan outputs
// and the vertex fixed terms; random weights (inputs from free to far dearer than rules),
// then priced. Used by tests/core/test_search_costs.cpp and bench/bench_search.cpp.
inline void addRandomProfile(sg::Problem& p, uint64_t seed) {
  std::mt19937_64 rng(seed * 7919 + 17);
  auto pick = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
  for (auto& a : p.actions) {
    a.terms = sg::TermAmounts{};
    a.terms[sg::kTermArithmetic] = a.cost;
    a.terms[sg::kTermBufferLoads] = pick(0, 3) == 0 ? pick(1, 4) : 0;
    a.terms[sg::kTermBufferBytes] = 16 * a.terms[sg::kTermBufferLoads];
    a.terms[sg::kTermIndexedUniformLoads] = pick(0, 4) == 0 ? pick(1, 4) : 0;
  }
  if (p.limits.empty()) p.limits = {sg::ResourceLimit{"vertex input attributes", "--max-attributes", INT64_MAX}};
  p.resources.clear();
  for (int f : p.init) {
    p.facts[f].resource = static_cast<int>(p.resources.size());
    sg::ResourceItem item{p.facts[f].name, 0, 1};
    item.terms[sg::kTermLocations] = pick(1, 2);
    item.terms[sg::kTermAttributeBytes] = 4 * pick(1, 4);
    p.resources.push_back(item);
  }
  p.fixedTerms = sg::TermAmounts{};
  p.fixedTerms[sg::kTermOutputs] = pick(4, 12);
  p.fixedTerms[sg::kTermVertices] = 1;
  sg::TermWeights w{};
  for (auto& x : w) x = pick(0, 3) == 0 ? 0 : pick(1, 12);
  w[sg::kTermLocations] = pick(0, 2) == 0 ? 0 : pick(1, 40);
  sg::priceProblem(p, w);
}

}  // namespace sgtest

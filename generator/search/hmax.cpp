// h_max by a Dijkstra-like fixpoint over preconditions (Bonet & Geffner 2001).
#include <algorithm>
#include <queue>

#include "search/heuristic.h"
#include "search/relaxation.h"

namespace sg {

std::vector<int64_t> hmaxCosts(const Problem& p, const FactSet& state, const std::vector<int64_t>& actionCost) {
  std::vector<int64_t> cost(p.facts.size(), kInfiniteCost);
  std::vector<int> unsatisfied(p.actions.size());
  std::vector<std::vector<int>> consumers(p.facts.size());
  using Item = std::pair<int64_t, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> open;
  for (size_t f = 0; f < p.facts.size(); ++f)
    if (state.test(static_cast<int>(f))) {
      cost[f] = 0;
      open.emplace(0, static_cast<int>(f));
    }
  for (size_t a = 0; a < p.actions.size(); ++a) {
    unsatisfied[a] = static_cast<int>(p.actions[a].pre.size());
    for (int f : p.actions[a].pre) consumers[f].push_back(static_cast<int>(a));
    if (unsatisfied[a] == 0) {
      int add = p.actions[a].add;
      if (actionCost[a] < cost[add]) {
        cost[add] = actionCost[a];
        open.emplace(cost[add], add);
      }
    }
  }
  std::vector<bool> done(p.facts.size(), false);
  while (!open.empty()) {
    auto [c, f] = open.top();
    open.pop();
    if (done[f] || c > cost[f]) continue;
    done[f] = true;
    for (int a : consumers[f]) {
      if (--unsatisfied[a] != 0) continue;
      // All preconditions are final now; f was the last and dearest.
      int64_t v = c + actionCost[a];
      int add = p.actions[a].add;
      if (v < cost[add]) {
        cost[add] = v;
        open.emplace(v, add);
      }
    }
  }
  return cost;
}

namespace {

class HMax : public Heuristic {
 public:
  explicit HMax(const Problem& p) : p_(p) {
    for (const auto& a : p.actions) costs_.push_back(a.cost);
  }
  int64_t estimate(const FactSet& state) override {
    auto c = hmaxCosts(p_, state, costs_);
    int64_t h = 0;
    for (int g : p_.goals) h = std::max(h, c[g]);
    return h;
  }
  const char* name() const override { return "hmax"; }

 private:
  const Problem& p_;
  std::vector<int64_t> costs_;
};

class Blind : public Heuristic {
 public:
  int64_t estimate(const FactSet&) override { return 0; }
  const char* name() const override { return "blind"; }
};

}  // namespace

std::unique_ptr<Heuristic> makeBlindHeuristic(const Problem&) { return std::make_unique<Blind>(); }
std::unique_ptr<Heuristic> makeHMaxHeuristic(const Problem& p) { return std::make_unique<HMax>(p); }

std::unique_ptr<Heuristic> makeHeuristic(const std::string& name, const Problem& p) {
  if (name == "blind") return makeBlindHeuristic(p);
  if (name == "hmax") return makeHMaxHeuristic(p);
  if (name == "lmcut") return makeLmCutHeuristic(p);
  return nullptr;
}

}  // namespace sg

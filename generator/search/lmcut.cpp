// LM-cut (Helmert & Domshlak, ICAPS 2009). Each round: h_max from the state, a
// precondition-choice function (the dearest precondition of each action), the goal
// zone (facts reaching the goal through zero-cost justification edges), and the cut
// (actions entering the zone from facts reachable without it). The cut's cheapest
// cost is added to h and subtracted from every cut action.
#include <algorithm>

#include "search/heuristic.h"
#include "search/relaxation.h"

namespace sg {
namespace {

constexpr int kNone = -1;  // "precondition" of actions with no preconditions: the artificial start fact

class LmCut : public Heuristic {
 public:
  explicit LmCut(const Problem& p) : p_(p) {
    for (const auto& a : p.actions) base_.push_back(a.cost);
  }
  const char* name() const override { return "lmcut"; }

  int64_t estimate(const FactSet& state) override {
    if (state.containsAll(p_.goals)) return 0;
    std::vector<int64_t> cost = base_;
    int64_t h = 0;
    const size_t nf = p_.facts.size();
    std::vector<int> pcf(p_.actions.size());
    for (;;) {
      std::vector<int64_t> hm = hmaxCosts(p_, state, cost);
      int goalPcf = kNone;
      int64_t hGoal = 0;
      for (int g : p_.goals)
        if (goalPcf == kNone || hm[g] > hGoal) {
          hGoal = hm[g];
          goalPcf = g;
        }
      if (hGoal >= kInfiniteCost) return kInfiniteCost;
      if (hGoal == 0) return h;
      for (size_t a = 0; a < p_.actions.size(); ++a) {
        pcf[a] = kNone;
        int64_t best = -1;
        for (int f : p_.actions[a].pre)
          if (hm[f] > best) {
            best = hm[f];
            pcf[a] = f;
          }
      }
      auto reachable = [&](size_t a) { return pcf[a] == kNone || hm[pcf[a]] < kInfiniteCost; };
      // Goal zone: backward over zero-cost justification edges.
      std::vector<bool> zone(nf, false);
      zone[goalPcf] = true;
      for (bool changed = true; changed;) {
        changed = false;
        for (size_t a = 0; a < p_.actions.size(); ++a)
          if (cost[a] == 0 && reachable(a) && zone[p_.actions[a].add] && pcf[a] != kNone && !zone[pcf[a]]) {
            zone[pcf[a]] = true;
            changed = true;
          }
      }
      // Facts reachable from the state without entering the zone.
      std::vector<bool> before(nf, false);
      for (size_t f = 0; f < nf; ++f) before[f] = state.test(static_cast<int>(f)) && !zone[f];
      for (bool changed = true; changed;) {
        changed = false;
        for (size_t a = 0; a < p_.actions.size(); ++a) {
          int add = p_.actions[a].add;
          if (!reachable(a) || zone[add] || before[add]) continue;
          if (pcf[a] == kNone || before[pcf[a]]) {
            before[add] = true;
            changed = true;
          }
        }
      }
      int64_t m = kInfiniteCost;
      std::vector<size_t> cut;
      for (size_t a = 0; a < p_.actions.size(); ++a)
        if (reachable(a) && zone[p_.actions[a].add] && (pcf[a] == kNone || before[pcf[a]])) {
          cut.push_back(a);
          m = std::min(m, cost[a]);
        }
      if (cut.empty() || m <= 0) return h;  // cannot happen with hGoal > 0; stay admissible
      h += m;
      for (size_t a : cut) cost[a] -= m;
    }
  }

 private:
  const Problem& p_;
  std::vector<int64_t> base_;
};

}  // namespace

std::unique_ptr<Heuristic> makeLmCutHeuristic(const Problem& p) { return std::make_unique<LmCut>(p); }

}  // namespace sg

#include "search/astar.h"

#include <queue>
#include <stdexcept>
#include <unordered_map>

#include <fmt/format.h>

#include "search/budget.h"

namespace sg {

std::vector<bool> reachableFacts(const Problem& p) {
  std::vector<bool> r(p.facts.size(), false);
  for (int f : p.init) r[f] = true;
  for (bool changed = true; changed;) {
    changed = false;
    for (const auto& a : p.actions) {
      if (r[a.add]) continue;
      bool ok = true;
      for (int f : a.pre) ok = ok && r[f];
      if (ok) r[a.add] = changed = true;
    }
  }
  return r;
}

std::vector<bool> relevantActions(const Problem& p) {
  std::vector<bool> factRelevant(p.facts.size(), false), actRelevant(p.actions.size(), false);
  std::vector<bool> init(p.facts.size(), false);
  for (int f : p.init) init[f] = true;
  for (int g : p.goals) factRelevant[g] = true;
  for (bool changed = true; changed;) {
    changed = false;
    for (size_t a = 0; a < p.actions.size(); ++a) {
      if (actRelevant[a] || !factRelevant[p.actions[a].add] || init[p.actions[a].add]) continue;
      actRelevant[a] = changed = true;
      for (int f : p.actions[a].pre) factRelevant[f] = true;
    }
  }
  // Also drop actions that can never fire.
  std::vector<bool> reach = reachableFacts(p);
  for (size_t a = 0; a < p.actions.size(); ++a)
    for (int f : p.actions[a].pre) actRelevant[a] = actRelevant[a] && reach[f];
  return actRelevant;
}

namespace {

struct Node {
  FactSet state;
  int64_t g = 0;
  int parent = -1;
  int action = -1;
  bool closed = false;
};

struct OpenEntry {
  int64_t f, g;
  int64_t seq;
  int node;
  bool operator>(const OpenEntry& o) const {
    if (f != o.f) return f > o.f;
    if (g != o.g) return g < o.g;  // prefer deeper nodes among equal f
    return seq > o.seq;            // then FIFO: deterministic
  }
};

}  // namespace

std::optional<Plan> astarSearch(const Problem& p, Heuristic& h, SearchStats* stats, const SearchLimits& limits) {
  std::vector<Node> nodes;
  std::unordered_map<FactSet, int, FactSetHash> index;
  std::priority_queue<OpenEntry, std::vector<OpenEntry>, std::greater<>> open;
  SearchStats local;
  SearchStats& st = stats ? *stats : local;
  st = SearchStats{};
  st.engine = "forward";
  st.heuristic = h.name();
  SearchBudget budget(limits);
  auto estimate = [&](const FactSet& s) { return timed(st.heuristicSeconds, [&] { return h.estimate(s); }); };
  auto finish = [&](std::optional<Plan> plan) {
    st.finalCost = plan ? plan->cost : -1;
    st.totalSeconds = budget.seconds();
    size_t stateBytes = (p.facts.size() + 63) / 64 * 8;
    st.peakBytes = static_cast<int64_t>(nodes.capacity() * (sizeof(Node) + stateBytes) +
                                        index.size() * (sizeof(FactSet) + stateBytes + 32) +
                                        open.size() * sizeof(OpenEntry));
    return plan;
  };
  std::vector<bool> relevant = relevantActions(p);
  std::vector<int> acts;
  for (size_t a = 0; a < p.actions.size(); ++a)
    if (relevant[a]) acts.push_back(static_cast<int>(a));
  st.relevantActions = static_cast<int64_t>(acts.size());
  int64_t seq = 0;

  FactSet init(p.facts.size());
  for (int f : p.init) init.set(f);
  int64_t h0 = estimate(init);
  st.initialH = h0;
  if (h0 >= kInfiniteCost) return finish(std::nullopt);
  nodes.push_back(Node{init, 0, -1, -1, false});
  index.emplace(init, 0);
  open.push(OpenEntry{h0, 0, seq++, 0});

  while (!open.empty()) {
    OpenEntry e = open.top();
    open.pop();
    Node& n = nodes[e.node];
    if (n.closed || e.g != n.g) continue;  // stale entry
    n.closed = true;
    if (n.state.containsAll(p.goals)) {
      std::vector<int> rev;
      for (int i = e.node; nodes[i].action >= 0; i = nodes[i].parent) rev.push_back(nodes[i].action);
      return finish(tidyPlan(p, std::vector<int>(rev.rbegin(), rev.rend())));
    }
    budget.onExpansion(++st.expanded);
    FactSet state = n.state;  // copy: nodes may reallocate below
    int64_t g = n.g;
    int parent = e.node;
    for (int a : acts) {
      const Action& act = p.actions[a];
      if (state.test(act.add) || !state.containsAll(act.pre)) continue;
      FactSet next = state;
      next.set(act.add);
      int64_t ng = g + act.cost;
      ++st.generated;
      budget.checkTime(st.expanded);
      auto it = index.find(next);
      if (it != index.end()) {
        Node& old = nodes[it->second];
        if (ng >= old.g) continue;
        // Cheaper path to a known state (possible with an admissible but inconsistent h): reopen.
        old.g = ng;
        old.parent = parent;
        old.action = a;
        if (old.closed) ++st.reopened;
        old.closed = false;
        int64_t hv = estimate(next);
        open.push(OpenEntry{ng + hv, ng, seq++, it->second});
        continue;
      }
      int64_t hv = estimate(next);
      if (hv >= kInfiniteCost) continue;
      int id = static_cast<int>(nodes.size());
      nodes.push_back(Node{next, ng, parent, a, false});
      index.emplace(std::move(next), id);
      open.push(OpenEntry{ng + hv, ng, seq++, id});
    }
  }
  return finish(std::nullopt);
}

}  // namespace sg

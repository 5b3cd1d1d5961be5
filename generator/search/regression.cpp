#include "search/regression.h"

#include <algorithm>
#include <bit>
#include <queue>
#include <stdexcept>
#include <unordered_set>

#include "search/budget.h"
#include "search/heuristic.h"

namespace sg {
namespace {

// The relevant, non-init part of a problem with facts renumbered by rank: every
// achiever's preconditions rank below its product.
struct RankedTask {
  struct Op {
    int action;  // index in Problem::actions
    int add;     // rank
    int64_t cost;
    int preBegin, preEnd;  // ranks of non-init preconditions in `pre`
    int itemBegin, itemEnd;  // resource items of its init preconditions in `items`
  };
  int n = 0;      // ranked facts
  int words = 0;  // 64-bit words of an open-set bitset
  std::vector<int> factOf;    // rank -> fact
  std::vector<Op> ops;        // grouped by product rank, ascending; cheapest first
  std::vector<int> achBegin;  // achievers of rank r: ops[achBegin[r], achBegin[r + 1])
  std::vector<int> pre;
  std::vector<int> goals;               // ranks of goals not in init
  std::vector<uint64_t> landmarks;      // n bitsets: facts every relaxed plan for r achieves
  std::vector<int64_t> cheapest, hmax;  // per rank: cheapest achiever, h_max from init
  bool unsolvable = false;
  bool cyclic = false;
  // Resource items (Problem::resources) that can break a limit; none when no plan could.
  int itemWords = 0;
  std::vector<int> items;       // ops' items, by Op::itemBegin/itemEnd
  std::vector<int> goalItems;   // items of goals the rig provides (read by every plan)
  // Per rank, itemWords words: items every derivation of the fact reads (resource
  // landmarks), for pruning partial plans that no completion can keep within the limits.
  std::vector<uint64_t> itemLandmarks;

  const uint64_t* landmarksOf(int r) const { return &landmarks[static_cast<size_t>(r) * words]; }
};

RankedTask rankTask(const Problem& p) {
  RankedTask t;
  std::vector<bool> reach = reachableFacts(p), relevant = relevantActions(p);
  std::vector<bool> isInit(p.facts.size(), false);
  for (int f : p.init) isInit[f] = true;
  for (int g : p.goals)
    if (!reach[g]) t.unsolvable = true;
  if (t.unsolvable) return t;
  // Relevant facts: products of relevant actions (never init, see relevantActions) and
  // the goals not in init; an action needing its own product can never fire.
  std::vector<int> acts;
  std::vector<bool> needed(p.facts.size(), false);
  for (size_t a = 0; a < p.actions.size(); ++a) {
    const Action& act = p.actions[a];
    if (!relevant[a] || std::binary_search(act.pre.begin(), act.pre.end(), act.add)) continue;
    acts.push_back(static_cast<int>(a));
    needed[act.add] = true;
  }
  for (int g : p.goals)
    if (!isInit[g]) needed[g] = true;
  // Kahn's algorithm over edges precondition -> product; level = longest path.
  std::vector<std::vector<int>> consumers(p.facts.size());
  std::vector<int> indegree(p.facts.size(), 0), level(p.facts.size(), 0);
  for (int a : acts)
    for (int q : p.actions[a].pre)
      if (!isInit[q]) {
        consumers[q].push_back(p.actions[a].add);
        ++indegree[p.actions[a].add];
      }
  std::vector<int> queue;
  for (size_t f = 0; f < p.facts.size(); ++f)
    if (needed[f] && indegree[f] == 0) queue.push_back(static_cast<int>(f));
  for (size_t i = 0; i < queue.size(); ++i)
    for (int c : consumers[queue[i]]) {
      level[c] = std::max(level[c], level[queue[i]] + 1);
      if (--indegree[c] == 0) queue.push_back(c);
    }
  size_t neededCount = static_cast<size_t>(std::count(needed.begin(), needed.end(), true));
  if (queue.size() != neededCount) {
    t.cyclic = true;
    return t;
  }
  // Rank by (level, fact): deterministic, and shallow facts are decided last.
  t.factOf = queue;
  std::sort(t.factOf.begin(), t.factOf.end(),
            [&](int a, int b) { return level[a] != level[b] ? level[a] < level[b] : a < b; });
  t.n = static_cast<int>(t.factOf.size());
  t.words = (t.n + 63) / 64;
  std::vector<int> rankOf(p.facts.size(), -1);
  for (int r = 0; r < t.n; ++r) rankOf[t.factOf[r]] = r;
  std::sort(acts.begin(), acts.end(), [&](int a, int b) {
    const Action &x = p.actions[a], &y = p.actions[b];
    if (rankOf[x.add] != rankOf[y.add]) return rankOf[x.add] < rankOf[y.add];
    return x.cost != y.cost ? x.cost < y.cost : a < b;
  });
  t.achBegin.assign(t.n + 1, 0);
  for (int a : acts) {
    const Action& act = p.actions[a];
    RankedTask::Op op{a, rankOf[act.add], act.cost, static_cast<int>(t.pre.size()), 0};
    for (int q : act.pre)
      if (!isInit[q]) t.pre.push_back(rankOf[q]);
    op.preEnd = static_cast<int>(t.pre.size());
    op.itemBegin = static_cast<int>(t.items.size());
    for (int q : act.pre)
      if (isInit[q] && p.facts[q].resource >= 0) t.items.push_back(p.facts[q].resource);
    std::sort(t.items.begin() + op.itemBegin, t.items.end());
    t.items.erase(std::unique(t.items.begin() + op.itemBegin, t.items.end()), t.items.end());
    op.itemEnd = static_cast<int>(t.items.size());
    t.ops.push_back(op);
    ++t.achBegin[op.add + 1];
  }
  for (int r = 0; r < t.n; ++r) t.achBegin[r + 1] += t.achBegin[r];
  for (int g : p.goals)
    if (!isInit[g]) t.goals.push_back(rankOf[g]);
    else if (p.facts[g].resource >= 0) t.goalItems.push_back(p.facts[g].resource);
  // Resources join the state only if reading every item of the relevant rules could break
  // a limit; otherwise the search is the unconstrained one.
  std::vector<int64_t> all(p.limits.size(), 0);
  std::vector<bool> counted(p.resources.size(), false);
  auto count = [&](int i) {
    if (counted[i]) return;
    counted[i] = true;
    if (static_cast<size_t>(p.resources[i].limit) < all.size()) all[p.resources[i].limit] += p.resources[i].amount;
  };
  for (int i : t.items) count(i);
  for (int i : t.goalItems) count(i);
  if (exceededLimit(p, all) >= 0) t.itemWords = static_cast<int>((p.resources.size() + 63) / 64);
  if (t.itemWords) {
    const size_t IW = static_cast<size_t>(t.itemWords);
    t.itemLandmarks.assign(static_cast<size_t>(t.n) * IW, 0);
    std::vector<uint64_t> acc(IW);
    for (int r = 0; r < t.n; ++r) {
      uint64_t* lm = &t.itemLandmarks[static_cast<size_t>(r) * IW];
      for (int o = t.achBegin[r]; o < t.achBegin[r + 1]; ++o) {
        const auto& op = t.ops[o];
        std::fill(acc.begin(), acc.end(), 0);
        for (int i = op.itemBegin; i < op.itemEnd; ++i) acc[static_cast<size_t>(t.items[i]) >> 6] |= uint64_t{1} << (t.items[i] & 63);
        for (int i = op.preBegin; i < op.preEnd; ++i)
          for (size_t w = 0; w < IW; ++w) acc[w] |= t.itemLandmarks[static_cast<size_t>(t.pre[i]) * IW + w];
        for (size_t w = 0; w < IW; ++w) lm[w] = o == t.achBegin[r] ? acc[w] : (lm[w] & acc[w]);
      }
    }
  }
  // Per rank, in ascending order (preconditions first): landmarks, cheapest achiever, h_max.
  t.landmarks.assign(static_cast<size_t>(t.n) * t.words, 0);
  t.cheapest.assign(t.n, kInfiniteCost);
  t.hmax.assign(t.n, kInfiniteCost);
  std::vector<uint64_t> acc(t.words);
  for (int r = 0; r < t.n; ++r) {
    uint64_t* lm = &t.landmarks[static_cast<size_t>(r) * t.words];
    bool first = true;
    for (int o = t.achBegin[r]; o < t.achBegin[r + 1]; ++o) {
      const auto& op = t.ops[o];
      std::fill(acc.begin(), acc.end(), 0);
      int64_t deepest = 0;
      for (int i = op.preBegin; i < op.preEnd; ++i) {
        const uint64_t* l = t.landmarksOf(t.pre[i]);
        for (int w = 0; w < t.words; ++w) acc[w] |= l[w];
        deepest = std::max(deepest, t.hmax[t.pre[i]]);
      }
      for (int w = 0; w < t.words; ++w) lm[w] = first ? acc[w] : (lm[w] & acc[w]);
      first = false;
      t.cheapest[r] = std::min(t.cheapest[r], op.cost);
      t.hmax[r] = std::min(t.hmax[r], deepest + op.cost);
    }
    lm[r >> 6] |= uint64_t{1} << (r & 63);
  }
  return t;
}

int topOf(const uint64_t* s, int words) {
  for (int w = words - 1; w >= 0; --w)
    if (s[w]) return w * 64 + 63 - std::countl_zero(s[w]);
  return -1;
}

template <class F>
void forEachBit(const uint64_t* s, int words, F&& f) {
  for (int w = 0; w < words; ++w)
    for (uint64_t b = s[w]; b; b &= b - 1) f(w * 64 + std::countr_zero(b));
}

// Admissible estimates of the cost of achieving an open set from init.
class OpenSetHeuristic {
 public:
  enum class Kind { Blind, HMax, Landmarks, LmCut };
  OpenSetHeuristic(const RankedTask& t, Kind kind) : t_(t), kind_(kind), acc_(t.words) {
    if (kind == Kind::LmCut) {
      cost_.resize(t.ops.size());
      pcf_.resize(t.ops.size());
      hm_.resize(t.n);
      zone_.resize(t.n);
      before_.resize(t.n);
    }
  }

  int64_t estimate(const uint64_t* open) {
    switch (kind_) {
      case Kind::Blind: return 0;
      case Kind::HMax: return hmax(open);
      case Kind::Landmarks: return landmarkSum(open);
      case Kind::LmCut: return std::max(landmarkSum(open), lmcut(open));
    }
    return 0;
  }

 private:
  int64_t hmax(const uint64_t* open) const {
    int64_t h = 0;
    forEachBit(open, t_.words, [&](int r) { h = std::max(h, t_.hmax[r]); });
    return h;
  }

  // Distinct landmark facts need distinct actions (each adds one fact).
  int64_t landmarkSum(const uint64_t* open) {
    std::fill(acc_.begin(), acc_.end(), 0);
    forEachBit(open, t_.words, [&](int r) {
      const uint64_t* l = t_.landmarksOf(r);
      for (int w = 0; w < t_.words; ++w) acc_[w] |= l[w];
    });
    int64_t h = 0;
    forEachBit(acc_.data(), t_.words, [&](int r) { h += t_.cheapest[r]; });
    return h;
  }

  // LM-cut (Helmert & Domshlak 2009) from init to the open set. Ranks are a topological
  // order, so each h_max round is one pass over the achievers below the top open fact
  // (no priority queue), and a round only recomputes ranks at or above the lowest
  // product whose cost the previous cut lowered.
  int64_t lmcut(const uint64_t* open) {
    int top = topOf(open, t_.words);
    if (top < 0) return 0;
    const int opEnd = t_.achBegin[top + 1];
    for (int o = 0; o < opEnd; ++o) cost_[o] = t_.ops[o].cost;
    int64_t h = 0;
    int from = 0;
    for (;;) {
      for (int r = from; r <= top; ++r) {
        int64_t best = kInfiniteCost;
        for (int o = t_.achBegin[r]; o < t_.achBegin[r + 1]; ++o) {
          const auto& op = t_.ops[o];
          int64_t deepest = 0;
          int arg = -1;
          for (int i = op.preBegin; i < op.preEnd; ++i)
            if (arg < 0 || hm_[t_.pre[i]] > deepest) {
              deepest = hm_[t_.pre[i]];
              arg = t_.pre[i];
            }
          pcf_[o] = arg;
          best = std::min(best, deepest + cost_[o]);
        }
        hm_[r] = best;
      }
      int goal = -1;
      forEachBit(open, t_.words, [&](int r) {
        if (goal < 0 || hm_[r] > hm_[goal]) goal = r;
      });
      if (hm_[goal] == 0) return h;
      // Goal zone: facts reaching the goal through zero-cost justification edges.
      std::fill(zone_.begin(), zone_.begin() + top + 1, 0);
      zone_[goal] = 1;
      for (int r = goal; r >= 0; --r) {
        if (!zone_[r]) continue;
        for (int o = t_.achBegin[r]; o < t_.achBegin[r + 1]; ++o)
          if (cost_[o] == 0 && pcf_[o] >= 0) zone_[pcf_[o]] = 1;
      }
      // Facts justified from init without entering the zone, then the cut.
      int64_t m = kInfiniteCost;
      for (int r = 0; r <= goal; ++r) {
        before_[r] = 0;
        for (int o = t_.achBegin[r]; o < t_.achBegin[r + 1]; ++o) {
          bool fromBefore = pcf_[o] < 0 || before_[pcf_[o]];
          if (!fromBefore) continue;
          if (zone_[r]) m = std::min(m, cost_[o]);
          else before_[r] = 1;
        }
      }
      if (m <= 0 || m >= kInfiniteCost) return h;  // cannot happen with hm(goal) > 0; stay admissible
      h += m;
      from = top + 1;
      for (int r = 0; r <= goal; ++r) {
        if (!zone_[r]) continue;
        for (int o = t_.achBegin[r]; o < t_.achBegin[r + 1]; ++o)
          if (pcf_[o] < 0 || before_[pcf_[o]]) {
            cost_[o] -= m;
            from = std::min(from, r);
          }
      }
    }
  }

  const RankedTask& t_;
  Kind kind_;
  std::vector<uint64_t> acc_;
  std::vector<int64_t> cost_, hm_;
  std::vector<int> pcf_;
  std::vector<char> zone_, before_;
};

struct RegressionNode {
  int64_t g;
  int64_t h;
  int parent;
  int op;  // index in RankedTask::ops
  bool closed;
};

struct RegressionOpenEntry {
  int64_t f, g;
  int64_t seq;
  int node;
  bool operator>(const RegressionOpenEntry& o) const {
    if (f != o.f) return f > o.f;
    if (g != o.g) return g < o.g;  // deeper first among equal f
    return seq < o.seq;            // then newest: dives, deterministic
  }
};

}  // namespace

bool regressionApplies(const Problem& p) { return !rankTask(p).cyclic; }

std::optional<Plan> regressionSearch(const Problem& p, const std::string& heuristic, SearchStats* stats,
                                     const SearchLimits& limits) {
  if (hasItemCosts(p)) {  // priced inputs: searched as facts, paid once (docs/search.md, "Device profiles")
    std::optional<Plan> plan = regressionSearch(inputsAsFacts(p), heuristic, stats, limits);
    if (!plan) return plan;
    return planOnInputs(p, *plan);  // same cost, without the "read" actions
  }
  OpenSetHeuristic::Kind kind;
  if (heuristic == "blind") kind = OpenSetHeuristic::Kind::Blind;
  else if (heuristic == "hmax") kind = OpenSetHeuristic::Kind::HMax;
  else if (heuristic == "landmarks") kind = OpenSetHeuristic::Kind::Landmarks;
  else if (heuristic == "lmcut") kind = OpenSetHeuristic::Kind::LmCut;
  else throw std::invalid_argument("unknown regression heuristic '" + heuristic + "'");
  SearchStats local;
  SearchStats& st = stats ? *stats : local;
  st = SearchStats{};
  st.engine = "regression";
  st.heuristic = heuristic;
  SearchBudget budget(limits);

  const RankedTask t = rankTask(p);
  if (t.cyclic) throw std::invalid_argument("regression search needs an acyclic relevant rule graph");
  st.relevantActions = static_cast<int64_t>(t.ops.size());
  // Node i's state: its open set (W words), then the resource items its decisions read
  // (t.itemWords words, none when no limit can bind) and its usage per limit: two partial
  // plans with the same open set but different items are different states, since the
  // items decide which completions still fit (docs/search.md, "Resource limits").
  std::vector<uint64_t> states;
  std::vector<int64_t> usage;  // node i's usage: [i * L, (i + 1) * L)
  std::vector<RegressionNode> nodes;
  const size_t OW = static_cast<size_t>(t.words), W = OW + static_cast<size_t>(t.itemWords);
  const size_t L = t.itemWords ? p.limits.size() : 0;
  auto stateOf = [&](int i) { return states.data() + static_cast<size_t>(i) * W; };
  auto hashOf = [&](int i) {
    uint64_t h = 1469598103934665603ull;
    const uint64_t* s = stateOf(i);
    for (size_t w = 0; w < W; ++w) h = (h ^ s[w]) * 1099511628211ull;
    return static_cast<size_t>(h ^ (h >> 29));
  };
  auto same = [&](int a, int b) { return std::equal(stateOf(a), stateOf(a) + W, stateOf(b)); };
  std::unordered_set<int, decltype(hashOf), decltype(same)> index(1024, hashOf, same);
  std::priority_queue<RegressionOpenEntry, std::vector<RegressionOpenEntry>, std::greater<>> open;
  auto finish = [&](std::optional<Plan> plan) {
    st.finalCost = plan ? plan->cost : -1;
    st.totalSeconds = budget.seconds();
    st.peakBytes = static_cast<int64_t>(states.capacity() * sizeof(uint64_t) + nodes.capacity() * sizeof(RegressionNode) +
                                        index.bucket_count() * sizeof(void*) + index.size() * 24 +
                                        open.size() * sizeof(RegressionOpenEntry));
    return plan;
  };
  if (t.unsolvable) return finish(std::nullopt);

  OpenSetHeuristic h(t, kind);
  auto estimate = [&](const uint64_t* s) { return timed(st.heuristicSeconds, [&] { return h.estimate(s); }); };
  states.assign(W, 0);
  for (int g : t.goals) states[static_cast<size_t>(g) >> 6] |= uint64_t{1} << (g & 63);
  usage.assign(L, 0);
  // Reads `items` into the state words at `s` (resource part) and `use`; false if a limit breaks.
  auto readItems = [&](uint64_t* s, int64_t* use, const int* begin, const int* end) {
    if (!L) return true;
    for (const int* it = begin; it != end; ++it) {
      uint64_t& w = s[OW + (static_cast<size_t>(*it) >> 6)];
      const uint64_t bit = uint64_t{1} << (*it & 63);
      if (w & bit) continue;
      w |= bit;
      const ResourceItem& item = p.resources[*it];
      if (static_cast<size_t>(item.limit) >= L) continue;
      use[item.limit] += item.amount;
      if (use[item.limit] > p.limits[item.limit].max) return false;
    }
    return true;
  };
  // Whether the items every completion must still read (the open facts' resource
  // landmarks) fit next to those already read.
  std::vector<uint64_t> extra(static_cast<size_t>(t.itemWords));
  auto landmarksFit = [&](const uint64_t* s, const int64_t* use) {
    const size_t IW = static_cast<size_t>(t.itemWords);
    std::fill(extra.begin(), extra.end(), 0);
    forEachBit(s, t.words, [&](int r) {
      for (size_t w = 0; w < IW; ++w) extra[w] |= t.itemLandmarks[static_cast<size_t>(r) * IW + w];
    });
    std::vector<int64_t> more(use, use + L);
    for (size_t w = 0; w < IW; ++w) extra[w] &= ~s[OW + w];
    bool fits = true;
    forEachBit(extra.data(), t.itemWords, [&](int i) {
      const ResourceItem& item = p.resources[i];
      if (static_cast<size_t>(item.limit) < L && (more[item.limit] += item.amount) > p.limits[item.limit].max)
        fits = false;
    });
    return fits;
  };
  if (!readItems(states.data(), usage.data(), t.goalItems.data(), t.goalItems.data() + t.goalItems.size()))
    return finish(std::nullopt);  // the pass-through inputs alone break a limit
  const int64_t g0 = p.fixedCost;  // what every plan pays (a device profile's fixed terms)
  int64_t h0 = estimate(stateOf(0));
  st.initialH = g0 + h0;
  nodes.push_back(RegressionNode{g0, h0, -1, -1, false});
  index.insert(0);
  int64_t seq = 0;
  open.push(RegressionOpenEntry{g0 + h0, g0, seq++, 0});
  std::vector<uint64_t> child(W);
  std::vector<int64_t> childUse(L);

  while (!open.empty()) {
    RegressionOpenEntry e = open.top();
    open.pop();
    if (nodes[e.node].closed || e.g != nodes[e.node].g) continue;  // stale entry
    nodes[e.node].closed = true;
    const int top = topOf(stateOf(e.node), t.words);  // the open-set part only
    if (top < 0) {
      // Walking back from the goal lists each decision after those of its preconditions.
      std::vector<int> order;
      for (int i = e.node; nodes[i].op >= 0; i = nodes[i].parent) order.push_back(t.ops[nodes[i].op].action);
      return finish(tidyPlan(p, order));
    }
    budget.onExpansion(++st.expanded);
    const int64_t g = nodes[e.node].g, hParent = nodes[e.node].h;
    for (int o = t.achBegin[top]; o < t.achBegin[top + 1]; ++o) {
      const auto& op = t.ops[o];
      std::copy(stateOf(e.node), stateOf(e.node) + W, child.begin());
      child[static_cast<size_t>(top) >> 6] &= ~(uint64_t{1} << (top & 63));
      for (int i = op.preBegin; i < op.preEnd; ++i)
        child[static_cast<size_t>(t.pre[i]) >> 6] |= uint64_t{1} << (t.pre[i] & 63);
      std::copy(usage.begin() + static_cast<long>(e.node * L), usage.begin() + static_cast<long>((e.node + 1) * L),
                childUse.begin());
      if (!readItems(child.data(), childUse.data(), t.items.data() + op.itemBegin, t.items.data() + op.itemEnd))
        continue;  // over a device limit: no completion of this partial plan is feasible
      if (L && !landmarksFit(child.data(), childUse.data())) continue;
      const int64_t ng = g + op.cost;
      ++st.generated;
      budget.checkTime(st.expanded);
      const int id = static_cast<int>(nodes.size());
      states.insert(states.end(), child.begin(), child.end());
      auto it = index.find(id);
      if (it != index.end()) {
        states.resize(states.size() - W);
        RegressionNode& old = nodes[*it];
        if (ng >= old.g) continue;
        // Cheaper path to a known open set (LM-cut is admissible, not consistent): reopen.
        if (old.closed) ++st.reopened;  // same items, so the same usage
        old = RegressionNode{ng, old.h, e.node, o, false};
        open.push(RegressionOpenEntry{ng + old.h, ng, seq++, *it});
        continue;
      }
      // Pathmax: a child's estimate never drops below its parent's less the step cost.
      int64_t hv = std::max(estimate(stateOf(id)), hParent - op.cost);
      nodes.push_back(RegressionNode{ng, hv, e.node, o, false});
      usage.insert(usage.end(), childUse.begin(), childUse.end());
      index.insert(id);
      open.push(RegressionOpenEntry{ng + hv, ng, seq++, id});
    }
  }
  return finish(std::nullopt);
}

}  // namespace sg

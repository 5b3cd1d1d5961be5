#include "search/regression.h"

#include <algorithm>
#include <bit>
#include <memory>
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

// Device limits during a regression search (docs/search.md, "Resource limits"): the items a
// partial plan reads live in its state words after the open set, its usage per limit beside.
class LimitTracker {
 public:
  LimitTracker(const Problem& p, const RankedTask& t)
      : p_(p), t_(t), OW(static_cast<size_t>(t.words)), L(t.itemWords ? p.limits.size() : 0),
        extra_(static_cast<size_t>(t.itemWords)) {}
  // Reads `items` into the state words at `s` (resource part) and `use`; false if a limit breaks.
  bool read(uint64_t* s, int64_t* use, const int* begin, const int* end) const {
    if (!L) return true;
    for (const int* it = begin; it != end; ++it) {
      uint64_t& w = s[OW + (static_cast<size_t>(*it) >> 6)];
      const uint64_t bit = uint64_t{1} << (*it & 63);
      if (w & bit) continue;
      w |= bit;
      const ResourceItem& item = p_.resources[*it];
      if (static_cast<size_t>(item.limit) >= L) continue;
      use[item.limit] += item.amount;
      if (use[item.limit] > p_.limits[item.limit].max) return false;
    }
    return true;
  }
  // Whether the items every completion must still read (the open facts' resource
  // landmarks) fit next to those already read.
  bool landmarksFit(const uint64_t* s, const int64_t* use) {
    if (!L) return true;
    const size_t IW = static_cast<size_t>(t_.itemWords);
    std::fill(extra_.begin(), extra_.end(), 0);
    forEachBit(s, t_.words, [&](int r) {
      for (size_t w = 0; w < IW; ++w) extra_[w] |= t_.itemLandmarks[static_cast<size_t>(r) * IW + w];
    });
    std::vector<int64_t> more(use, use + L);
    for (size_t w = 0; w < IW; ++w) extra_[w] &= ~s[OW + w];
    bool fits = true;
    forEachBit(extra_.data(), t_.itemWords, [&](int i) {
      const ResourceItem& item = p_.resources[i];
      if (static_cast<size_t>(item.limit) < L && (more[item.limit] += item.amount) > p_.limits[item.limit].max)
        fits = false;
    });
    return fits;
  }

 private:
  const Problem& p_;
  const RankedTask& t_;

 public:
  const size_t OW, L;  // open-set words; limits tracked (0: none can bind)

 private:
  std::vector<uint64_t> extra_;
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

// A* over the same open sets when a plan costs the largest of K sums (Problem::componentWeights,
// docs/search.md "Roofline objectives"). A label carries one g per component; its estimate is
// max over k of (g_k + h_k), each h_k the chosen heuristic on a task priced by component k,
// which bounds the rest of that sum, so the estimate bounds every completion and the first
// goal label taken is optimal. Costs no longer add up to a scalar, so a state keeps every label
// whose g vector no other label of that state undercuts in every component (dominance): a
// dominated label's completions all cost at least as much as the dominating label's.
std::optional<Plan> searchLargestComponent(const Problem& p, const RankedTask& t, OpenSetHeuristic::Kind kind,
                                           SearchStats& st, SearchBudget& budget) {
  const size_t K = p.componentWeights.size();
  // Ranks depend on the rule graph alone, so each component's task has the same ranks and
  // open sets; only its costs (and so the order of a rank's achievers) differ.
  std::vector<RankedTask> tasks;
  tasks.reserve(K);
  for (const TermWeights& w : p.componentWeights) {
    Problem q = p;
    priceProblem(q, w);
    tasks.push_back(rankTask(q));
  }
  std::vector<std::unique_ptr<OpenSetHeuristic>> hs;
  for (const RankedTask& tk : tasks) hs.push_back(std::make_unique<OpenSetHeuristic>(tk, kind));
  std::vector<int64_t> opCost(t.ops.size() * K), fixed(K);
  for (size_t o = 0; o < t.ops.size(); ++o)
    for (size_t k = 0; k < K; ++k)
      opCost[o * K + k] = weighTerms(p.componentWeights[k], p.actions[static_cast<size_t>(t.ops[o].action)].terms);
  for (size_t k = 0; k < K; ++k) fixed[k] = weighTerms(p.componentWeights[k], p.fixedTerms);

  const size_t OW = static_cast<size_t>(t.words), W = OW + static_cast<size_t>(t.itemWords);
  const size_t L = t.itemWords ? p.limits.size() : 0;
  struct Label {
    int parent, op;
    int nextSame;  // the next label of the same state (-1: none)
    bool closed, dominated;
  };
  std::vector<Label> labels;
  std::vector<uint64_t> states;  // W words per label
  std::vector<int64_t> g, h, usage;  // K, K and L per label
  auto stateOf = [&](int i) { return states.data() + static_cast<size_t>(i) * W; };
  auto hashOf = [&](int i) {
    uint64_t x = 1469598103934665603ull;
    const uint64_t* s = stateOf(i);
    for (size_t w = 0; w < W; ++w) x = (x ^ s[w]) * 1099511628211ull;
    return static_cast<size_t>(x ^ (x >> 29));
  };
  auto same = [&](int a, int b) { return std::equal(stateOf(a), stateOf(a) + W, stateOf(b)); };
  std::unordered_set<int, decltype(hashOf), decltype(same)> index(1024, hashOf, same);  // first label per state
  std::priority_queue<RegressionOpenEntry, std::vector<RegressionOpenEntry>, std::greater<>> open;
  auto f = [&](const int64_t* gl, const int64_t* hl) {
    int64_t m = 0;
    for (size_t k = 0; k < K; ++k) m = std::max(m, gl[k] + hl[k]);
    return m;
  };
  auto largest = [&](const int64_t* gl) { return *std::max_element(gl, gl + K); };
  auto estimate = [&](const uint64_t* s, int64_t* out) {
    timed(st.heuristicSeconds, [&] {
      for (size_t k = 0; k < K; ++k) out[k] = hs[k]->estimate(s);
      return 0;
    });
  };

  states.assign(W, 0);
  for (int goal : t.goals) states[static_cast<size_t>(goal) >> 6] |= uint64_t{1} << (goal & 63);
  usage.assign(L, 0);
  LimitTracker lim(p, t);
  if (!lim.read(states.data(), usage.data(), t.goalItems.data(), t.goalItems.data() + t.goalItems.size()))
    return std::nullopt;
  g = fixed;
  h.resize(K);
  estimate(stateOf(0), h.data());
  st.initialH = f(g.data(), h.data());
  labels.push_back(Label{-1, -1, -1, false, false});
  index.insert(0);
  int64_t seq = 0;
  open.push(RegressionOpenEntry{st.initialH, largest(g.data()), seq++, 0});
  std::vector<uint64_t> child(W);
  std::vector<int64_t> childUse(L), cg(K), ch(K);

  while (!open.empty()) {
    RegressionOpenEntry e = open.top();
    open.pop();
    Label& taken = labels[static_cast<size_t>(e.node)];
    if (taken.closed || taken.dominated) continue;
    taken.closed = true;
    const int top = topOf(stateOf(e.node), t.words);
    if (top < 0) {
      std::vector<int> order;
      for (int i = e.node; labels[static_cast<size_t>(i)].op >= 0; i = labels[static_cast<size_t>(i)].parent)
        order.push_back(t.ops[static_cast<size_t>(labels[static_cast<size_t>(i)].op)].action);
      return tidyPlan(p, order);
    }
    budget.onExpansion(++st.expanded);
    for (int o = t.achBegin[top]; o < t.achBegin[top + 1]; ++o) {
      const auto& op = t.ops[static_cast<size_t>(o)];
      std::copy(stateOf(e.node), stateOf(e.node) + W, child.begin());
      child[static_cast<size_t>(top) >> 6] &= ~(uint64_t{1} << (top & 63));
      for (int i = op.preBegin; i < op.preEnd; ++i)
        child[static_cast<size_t>(t.pre[i]) >> 6] |= uint64_t{1} << (t.pre[i] & 63);
      std::copy(usage.begin() + static_cast<long>(static_cast<size_t>(e.node) * L),
                usage.begin() + static_cast<long>((static_cast<size_t>(e.node) + 1) * L), childUse.begin());
      if (!lim.read(child.data(), childUse.data(), t.items.data() + op.itemBegin, t.items.data() + op.itemEnd)) continue;
      if (!lim.landmarksFit(child.data(), childUse.data())) continue;
      for (size_t k = 0; k < K; ++k) cg[k] = g[static_cast<size_t>(e.node) * K + k] + opCost[static_cast<size_t>(o) * K + k];
      ++st.generated;
      budget.checkTime(st.expanded);
      const int id = static_cast<int>(labels.size());
      states.insert(states.end(), child.begin(), child.end());
      auto it = index.find(id);
      int first = it == index.end() ? -1 : *it;
      bool undercut = false;
      for (int j = first; j >= 0 && !undercut; j = labels[static_cast<size_t>(j)].nextSame) {
        const int64_t* gj = &g[static_cast<size_t>(j) * K];
        undercut = !labels[static_cast<size_t>(j)].dominated &&
                   std::equal(gj, gj + K, cg.begin(), [](int64_t a, int64_t b) { return a <= b; });
      }
      if (undercut) {
        states.resize(states.size() - W);
        continue;
      }
      for (int j = first; j >= 0; j = labels[static_cast<size_t>(j)].nextSame) {
        const int64_t* gj = &g[static_cast<size_t>(j) * K];
        if (std::equal(cg.begin(), cg.end(), gj, [](int64_t a, int64_t b) { return a <= b; }))
          labels[static_cast<size_t>(j)].dominated = true;
      }
      // Pathmax per component, as in the one-sum search.
      estimate(stateOf(id), ch.data());
      for (size_t k = 0; k < K; ++k)
        ch[k] = std::max(ch[k], h[static_cast<size_t>(e.node) * K + k] - opCost[static_cast<size_t>(o) * K + k]);
      labels.push_back(Label{e.node, o, -1, false, false});
      if (first >= 0) {  // append to the state's chain
        int j = first;
        while (labels[static_cast<size_t>(j)].nextSame >= 0) j = labels[static_cast<size_t>(j)].nextSame;
        labels[static_cast<size_t>(j)].nextSame = id;
      } else {
        index.insert(id);
      }
      g.insert(g.end(), cg.begin(), cg.end());
      h.insert(h.end(), ch.begin(), ch.end());
      usage.insert(usage.end(), childUse.begin(), childUse.end());
      open.push(RegressionOpenEntry{f(cg.data(), ch.data()), largest(cg.data()), seq++, id});
    }
    st.peakBytes = std::max<int64_t>(st.peakBytes, static_cast<int64_t>(states.capacity() * sizeof(uint64_t) +
                                                                       labels.capacity() * sizeof(Label) +
                                                                       (g.capacity() + h.capacity()) * sizeof(int64_t)));
  }
  return std::nullopt;
}

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
  if (!p.componentWeights.empty()) {
    std::optional<Plan> plan = searchLargestComponent(p, t, kind, st, budget);
    st.finalCost = plan ? plan->cost : -1;
    st.totalSeconds = budget.seconds();
    return plan;
  }

  OpenSetHeuristic h(t, kind);
  auto estimate = [&](const uint64_t* s) { return timed(st.heuristicSeconds, [&] { return h.estimate(s); }); };
  states.assign(W, 0);
  for (int g : t.goals) states[static_cast<size_t>(g) >> 6] |= uint64_t{1} << (g & 63);
  usage.assign(L, 0);
  LimitTracker lim(p, t);
  if (!lim.read(states.data(), usage.data(), t.goalItems.data(), t.goalItems.data() + t.goalItems.size()))
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
      if (!lim.read(child.data(), childUse.data(), t.items.data() + op.itemBegin, t.items.data() + op.itemEnd))
        continue;  // over a device limit: no completion of this partial plan is feasible
      if (!lim.landmarksFit(child.data(), childUse.data())) continue;
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

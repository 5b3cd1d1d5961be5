#include "search/ip_oracle.h"

#include <glpk.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>

#include "search/budget.h"

namespace sg {
namespace {

// Strongly connected components (Tarjan, iterative) of the graph precondition -> product.
std::vector<int> components(int n, const std::vector<std::vector<int>>& succ) {
  std::vector<int> comp(n, -1), low(n), num(n, -1), stack;
  std::vector<bool> onStack(n, false);
  int counter = 0, comps = 0;
  std::vector<std::pair<int, size_t>> call;
  for (int s = 0; s < n; ++s) {
    if (num[s] >= 0) continue;
    call.emplace_back(s, 0);
    while (!call.empty()) {
      auto& [v, i] = call.back();
      if (i == 0) {
        num[v] = low[v] = counter++;
        stack.push_back(v);
        onStack[v] = true;
      }
      if (i < succ[v].size()) {
        int w = succ[v][i++];
        if (num[w] < 0) call.emplace_back(w, 0);
        else if (onStack[w]) low[v] = std::min(low[v], num[w]);
        continue;
      }
      if (low[v] == num[v]) {
        for (int w = -1; w != v;) {
          w = stack.back();
          stack.pop_back();
          onStack[w] = false;
          comp[w] = comps;
        }
        ++comps;
      }
      int done = v;
      call.pop_back();
      if (!call.empty()) low[call.back().first] = std::min(low[call.back().first], low[done]);
    }
  }
  return comp;
}

}  // namespace

std::optional<Plan> integerProgramSearch(const Problem& p, SearchStats* stats, const SearchLimits& limits) {
  SearchStats local;
  SearchStats& st = stats ? *stats : local;
  st = SearchStats{};
  st.engine = "ip";
  SearchBudget budget(limits);
  auto finish = [&](std::optional<Plan> plan) {
    st.finalCost = plan ? plan->cost : -1;
    st.totalSeconds = budget.seconds();
    return plan;
  };
  std::vector<bool> reach = reachableFacts(p), relevant = relevantActions(p);
  for (int g : p.goals)
    if (!reach[g]) return finish(std::nullopt);
  const int nf = static_cast<int>(p.facts.size());
  std::vector<bool> isInit(nf, false);
  for (int f : p.init) isInit[f] = true;
  std::vector<int> acts;
  for (size_t a = 0; a < p.actions.size(); ++a) {
    const Action& act = p.actions[a];
    if (relevant[a] && !std::binary_search(act.pre.begin(), act.pre.end(), act.add)) acts.push_back(static_cast<int>(a));
  }
  st.relevantActions = static_cast<int64_t>(acts.size());
  // Columns: x per action (1..), then y per needed non-init fact, then t per fact in a cycle.
  std::vector<int> yCol(nf, 0), tCol(nf, 0);
  std::vector<std::vector<int>> succ(nf);
  int cols = static_cast<int>(acts.size());
  auto needY = [&](int f) {
    if (!isInit[f] && yCol[f] == 0) yCol[f] = ++cols;
  };
  for (int g : p.goals) needY(g);
  for (int a : acts) {
    needY(p.actions[a].add);
    for (int q : p.actions[a].pre) {
      needY(q);
      if (!isInit[q]) succ[q].push_back(p.actions[a].add);
    }
  }
  if (cols == 0)  // every goal provided (GLPK rejects empty programs)
    return finish(exceededLimit(p, resourceUsage(p, {})) < 0 ? std::optional<Plan>(tidyPlan(p, {})) : std::nullopt);
  std::vector<int> comp = components(nf, succ);
  std::vector<int> compSize(nf + 1, 0);
  for (int f = 0; f < nf; ++f) ++compSize[comp[f]];
  auto inCycle = [&](int q, int add) { return comp[q] == comp[add] && compSize[comp[q]] > 1; };

  // GLPK keeps global state: free it all after each solve (this also resets its peak
  // memory counter, which the stats report per solve).
  struct Env {
    glp_prob* prob = glp_create_prob();
    ~Env() {
      glp_delete_prob(prob);
      glp_free_env();
    }
  } env;
  glp_prob* P = env.prob;
  glp_set_obj_dir(P, GLP_MIN);
  glp_add_cols(P, cols);
  for (size_t i = 0; i < acts.size(); ++i) {
    glp_set_col_kind(P, static_cast<int>(i) + 1, GLP_BV);
    glp_set_obj_coef(P, static_cast<int>(i) + 1, static_cast<double>(p.actions[acts[i]].cost));
  }
  for (int f = 0; f < nf; ++f)
    if (yCol[f]) glp_set_col_kind(P, yCol[f], GLP_BV);
  for (int g : p.goals)
    if (yCol[g]) glp_set_col_bnds(P, yCol[g], GLP_FX, 1, 1);
  std::vector<int> ia{0}, ja{0};
  std::vector<double> ar{0};
  int rows = 0;
  auto row = [&](double lo, std::initializer_list<std::pair<int, double>> terms) {
    glp_add_rows(P, 1);
    glp_set_row_bnds(P, ++rows, GLP_LO, lo, 0);
    for (auto [c, v] : terms) {
      ia.push_back(rows);
      ja.push_back(c);
      ar.push_back(v);
    }
  };
  // Achiever rows: sum x - y >= 0, one row per needed fact.
  std::vector<std::vector<int>> achievers(nf);
  for (size_t i = 0; i < acts.size(); ++i) achievers[p.actions[acts[i]].add].push_back(static_cast<int>(i) + 1);
  for (int f = 0; f < nf; ++f) {
    if (!yCol[f]) continue;
    glp_add_rows(P, 1);
    glp_set_row_bnds(P, ++rows, GLP_LO, 0, 0);
    for (int c : achievers[f]) {
      ia.push_back(rows);
      ja.push_back(c);
      ar.push_back(1);
    }
    ia.push_back(rows);
    ja.push_back(yCol[f]);
    ar.push_back(-1);
  }
  for (size_t i = 0; i < acts.size(); ++i) {
    const Action& act = p.actions[acts[i]];
    int x = static_cast<int>(i) + 1;
    for (int q : act.pre) {
      if (isInit[q]) continue;
      row(0, {{yCol[q], 1}, {x, -1}});
      if (!inCycle(q, act.add)) continue;
      for (int f : {q, act.add})
        if (!tCol[f]) {
          tCol[f] = ++cols;
          glp_add_cols(P, 1);
          glp_set_col_kind(P, cols, GLP_CV);
          glp_set_col_bnds(P, cols, GLP_DB, 0, compSize[comp[f]] - 1);
        }
      double big = compSize[comp[q]];
      row(1 - big, {{tCol[act.add], 1}, {tCol[q], -1}, {x, -big}});  // t_add - t_q >= 1 - M(1 - x)
    }
  }
  // Device limits: z_i = 1 if the plan reads resource item i (z_i >= x_a for every action
  // reading it; 1 for items of pass-through goals); per limit, sum amount_i z_i <= max.
  // Only when reading every item could break a limit (as in the regression engine), or when
  // items have costs (a device profile): then cost_i z_i joins the objective, so each input
  // is paid once however many chosen rules read it.
  std::vector<int> zCol(p.resources.size(), 0);
  std::vector<std::vector<int>> readers(p.resources.size());
  std::vector<bool> goalItem(p.resources.size(), false);
  for (size_t i = 0; i < acts.size(); ++i)
    for (int q : p.actions[acts[i]].pre)
      if (isInit[q] && p.facts[q].resource >= 0) readers[p.facts[q].resource].push_back(static_cast<int>(i) + 1);
  for (int g : p.goals)
    if (isInit[g] && p.facts[g].resource >= 0) goalItem[p.facts[g].resource] = true;
  std::vector<int64_t> all(p.limits.size(), 0);
  for (size_t r = 0; r < p.resources.size(); ++r)
    if ((!readers[r].empty() || goalItem[r]) && static_cast<size_t>(p.resources[r].limit) < all.size())
      all[p.resources[r].limit] += p.resources[r].amount;
  if (exceededLimit(p, all) >= 0 || hasItemCosts(p)) {
    for (size_t r = 0; r < p.resources.size(); ++r) {
      if (readers[r].empty() && !goalItem[r]) continue;
      zCol[r] = ++cols;
      glp_add_cols(P, 1);
      glp_set_col_kind(P, cols, GLP_BV);
      glp_set_obj_coef(P, cols, static_cast<double>(p.resources[r].cost));
      if (goalItem[r]) glp_set_col_bnds(P, cols, GLP_FX, 1, 1);
      for (int x : readers[r]) row(0, {{zCol[r], 1}, {x, -1}});
    }
    for (size_t l = 0; l < p.limits.size(); ++l) {
      if (p.limits[l].max == INT64_MAX) continue;
      glp_add_rows(P, 1);
      glp_set_row_bnds(P, ++rows, GLP_UP, 0, static_cast<double>(p.limits[l].max));
      for (size_t r = 0; r < p.resources.size(); ++r)
        if (zCol[r] && static_cast<size_t>(p.resources[r].limit) == l) {
          ia.push_back(rows);
          ja.push_back(zCol[r]);
          ar.push_back(static_cast<double>(p.resources[r].amount));
        }
    }
  }
  // A roofline objective (Problem::componentWeights): minimise an auxiliary T with one row
  // per component, T - (its actions' and items' sums) >= its fixed part; the x and z columns
  // then cost nothing themselves. The rows are in units of a thousandth of their largest
  // coefficient: at femtosecond or regret-per-10^9 magnitudes (10^9 and more) GLPK's MIP
  // presolver reduced a coefficient wrongly and proved a plan optimal at 1.22x the optimum
  // (tests/core/test_ip_oracle.cpp, ThePortableObjectiveIsSolvedExactly). The plan's cost is
  // weighed exactly afterwards (tidyPlan).
  if (!p.componentWeights.empty()) {
    const int t = ++cols;
    glp_add_cols(P, 1);
    glp_set_col_kind(P, t, GLP_CV);
    glp_set_col_bnds(P, t, GLP_LO, 0, 0);
    glp_set_obj_coef(P, t, 1);
    for (int c = 1; c < t; ++c) glp_set_obj_coef(P, c, 0);
    int64_t largest = 1;
    for (const TermWeights& w : p.componentWeights) {
      largest = std::max(largest, weighTerms(w, p.fixedTerms));
      for (int a : acts) largest = std::max(largest, weighTerms(w, p.actions[a].terms));
      for (size_t r = 0; r < p.resources.size(); ++r)
        if (zCol[r]) largest = std::max(largest, weighTerms(w, p.resources[r].terms));
    }
    const double unit = std::max(1.0, static_cast<double>(largest) / 1000.0);
    for (const TermWeights& w : p.componentWeights) {
      glp_add_rows(P, 1);
      glp_set_row_bnds(P, ++rows, GLP_LO, static_cast<double>(weighTerms(w, p.fixedTerms)) / unit, 0);
      auto put = [&](int col, const TermAmounts& terms) {
        const int64_t c = weighTerms(w, terms);
        if (!col || !c) return;
        ia.push_back(rows);
        ja.push_back(col);
        ar.push_back(-static_cast<double>(c) / unit);
      };
      for (size_t i = 0; i < acts.size(); ++i) put(static_cast<int>(i) + 1, p.actions[acts[i]].terms);
      for (size_t r = 0; r < p.resources.size(); ++r) put(zCol[r], p.resources[r].terms);
      ia.push_back(rows);
      ja.push_back(t);
      ar.push_back(1);
    }
  }
  glp_load_matrix(P, static_cast<int>(ia.size()) - 1, ia.data(), ja.data(), ar.data());

  glp_iocp parm;
  glp_init_iocp(&parm);
  parm.presolve = GLP_ON;
  parm.msg_lev = GLP_MSG_OFF;
  if (limits.maxSeconds > 0) parm.tm_lim = static_cast<int>(std::min(std::ceil(limits.maxSeconds * 1000), 2e9));
  glp_term_out(GLP_OFF);
  int ret = glp_intopt(P, &parm);
  int count = 0, cpeak = 0;
  size_t total = 0, tpeak = 0;
  glp_mem_usage(&count, &cpeak, &total, &tpeak);
  st.peakBytes = static_cast<int64_t>(tpeak);
  if (ret == GLP_ETMLIM)
    throw SearchLimitError(fmt::format("integer program gave up: time limit of {} s reached (--search-time-limit)",
                                       limits.maxSeconds));
  if (ret == GLP_ENOPFS || ret == GLP_ENODFS || glp_mip_status(P) == GLP_NOFEAS) return finish(std::nullopt);
  if (ret != 0 || glp_mip_status(P) != GLP_OPT)
    throw std::runtime_error(fmt::format("GLPK failed on the plan integer program (glp_intopt returned {})", ret));
  // Chosen actions, applied in a forward closure (their own order), then tidied.
  std::vector<int> chosen, order;
  for (size_t i = 0; i < acts.size(); ++i)
    if (glp_mip_col_val(P, static_cast<int>(i) + 1) > 0.5) chosen.push_back(acts[i]);
  std::vector<bool> have(nf, false), used(chosen.size(), false);
  for (int f : p.init) have[f] = true;
  for (bool changed = true; changed;) {
    changed = false;
    for (size_t i = 0; i < chosen.size(); ++i) {
      const Action& act = p.actions[chosen[i]];
      if (used[i] || have[act.add] || !std::all_of(act.pre.begin(), act.pre.end(), [&](int q) { return have[q]; }))
        continue;
      used[i] = have[act.add] = changed = true;
      order.push_back(chosen[i]);
    }
  }
  return finish(tidyPlan(p, order));
}

}  // namespace sg

#include "search/search.h"

#include <fmt/format.h>

#include <stdexcept>

#include "search/heuristic.h"
#include "search/ip_oracle.h"
#include "search/regression.h"

namespace sg {

std::optional<Plan> findPlan(const Problem& p, const SearchOptions& opts, SearchStats* stats) {
  const std::string& e = opts.engine;
  if (e == "ip") return integerProgramSearch(p, stats, opts.limits);
  if (e == "regression" || (e == "auto" && regressionApplies(p)))
    return regressionSearch(p, opts.heuristic, stats, opts.limits);
  if (e != "auto" && e != "forward") throw std::invalid_argument("unknown search engine '" + e + "'");
  // A roofline objective is not additive: the forward engine's g cannot carry it, so a
  // cyclic rule graph (or an explicit forward request) is solved by the integer program.
  if (!p.componentWeights.empty()) return integerProgramSearch(p, stats, opts.limits);
  // Priced inputs (a device profile) are searched as facts, so each is paid once.
  if (hasItemCosts(p)) {
    const Problem q = inputsAsFacts(p);
    SearchOptions o = opts;
    o.engine = "forward";
    std::optional<Plan> plan = findPlan(q, o, stats);
    if (!plan) return plan;
    return planOnInputs(p, *plan);  // same cost, without the "read" actions
  }
  auto h = makeHeuristic(opts.heuristic, p);
  if (!h) throw std::invalid_argument("unknown heuristic '" + opts.heuristic + "' for forward search");
  std::optional<Plan> plan = astarSearch(p, *h, stats, opts.limits);
  // Forward states are sets of produced facts and know nothing of device limits: its plan
  // is the cheapest overall. If that breaks a limit, the integer program (which has the
  // limits as constraints) finds the cheapest feasible one.
  if (plan && exceededLimit(p, resourceUsage(p, plan->actions)) >= 0) {
    SearchStats forward = stats ? *stats : SearchStats{};
    plan = integerProgramSearch(p, stats, opts.limits);
    if (stats) {
      stats->engine = "forward, then ip (the forward plan broke a device limit)";
      stats->expanded = forward.expanded;
      stats->generated = forward.generated;
    }
  }
  return plan;
}

std::string searchMethod(const SearchStats& st) {
  return st.heuristic.empty() ? "integer program" : st.heuristic + " A*";
}

std::string describeStats(const SearchStats& st) {
  std::string who = st.heuristic.empty() ? st.engine : fmt::format("{} A*, {}", st.engine, st.heuristic);
  return fmt::format(
      "search ({}): {} expanded, {} generated, {} reopened, {} relevant rules\n"
      "  initial h {} vs cost {}; heuristic {:.3f} ms of {:.3f} ms; {:.1f} KiB\n",
      who, st.expanded, st.generated, st.reopened, st.relevantActions, st.initialH, st.finalCost,
      st.heuristicSeconds * 1e3, st.totalSeconds * 1e3, static_cast<double>(st.peakBytes) / 1024);
}

}  // namespace sg

#include "analysis/explain.h"

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <functional>
#include <map>
#include <set>

#include "rig/vertex_encoding.h"
#include "search/search.h"

namespace sg {
namespace {


std::string sourceOf(const LoadedInputs& in, int f) {
  const Fact& fact = in.problem.facts[f];
  if (fact.source == Fact::Source::Attribute && fact.rigIndex >= 0)
    return "attribute " + in.rig.attributes[fact.rigIndex].name;
  if (fact.source == Fact::Source::Uniform && fact.rigIndex >= 0) return "uniform " + in.rig.uniforms[fact.rigIndex].name;
  return "";
}

}  // namespace

std::string compactFactList(const std::vector<std::string>& names) {
  // Consecutive instances of one family collapse into "name[a..b]".
  std::string out;
  for (size_t i = 0; i < names.size();) {
    auto [base, idx] = splitIndexed(names[i]);
    size_t j = i + 1;
    int64_t last = idx;
    while (idx >= 0 && j < names.size()) {
      auto [b2, i2] = splitIndexed(names[j]);
      if (b2 != base || i2 != last + 1) break;
      last = i2;
      ++j;
    }
    std::string item = (idx >= 0 && last > idx) ? fmt::format("{}[{}..{}]", base, idx, last) : names[i];
    out += (out.empty() ? "" : ", ") + item;
    i = j;
  }
  return out;
}

std::optional<Plan> searchPlan(const Problem& p, const std::string& heuristic, SearchStats* stats) {
  auto h = makeHeuristic(heuristic, p);
  if (!h) throw InputError(SourceLoc{}, fmt::format("unknown heuristic '{}' (blind, hmax, lmcut)", heuristic));
  SearchOptions o;  // the default engine: regression A* where the rule graph allows it
  o.heuristic = heuristic;
  return findPlan(p, o, stats);
}

Explanation explainPlan(const LoadedInputs& in, const Plan& plan, const ExplainOptions& opts) {
  const Problem& p = in.problem;
  Explanation e;
  e.plan = plan;
  e.heuristic = opts.heuristic;
  std::set<std::string> chosen;
  for (int a : plan.actions) chosen.insert(p.actions[a].name);
  for (int a : plan.actions) {
    PlanStep s;
    s.action = a;
    int f = p.actions[a].add;
    for (int b : plan.actions)
      if (std::binary_search(p.actions[b].pre.begin(), p.actions[b].pre.end(), f)) ++s.uses;
    for (const auto& v : in.varyings)
      for (const auto& sem : v.semantics)
        if (sem == p.facts[f].name) ++s.uses;
    if (opts.alternatives) {
      Problem q = withoutRules(p, {p.actions[a].name});
      std::optional<Plan> alt = searchPlan(q, opts.heuristic);
      if (alt) {
        s.alternative.exists = true;
        s.alternative.planCost = alt->cost;
        s.alternative.extra = alt->cost - plan.cost;
        std::set<std::string> seen;
        for (int b : alt->actions) {
          const std::string& n = q.actions[b].name;
          if (!chosen.count(n) && seen.insert(n).second) s.alternative.instead.push_back(n);
        }
      }
    }
    e.steps.push_back(std::move(s));
  }
  return e;
}

std::string formatExplanation(const LoadedInputs& in, const Explanation& e) {
  const Problem& p = in.problem;
  std::map<int, const PlanStep*> producer;  // fact -> step producing it
  for (const auto& s : e.steps) producer[p.actions[s.action].add] = &s;
  std::string out;
  out += fmt::format("plan for rig '{}' and fragment shader '{}': {} rules, total cost {}\n", in.rig.name,
                     std::filesystem::path(in.fragment.file).filename().string(), e.plan.actions.size(), e.plan.cost);
  out += "(a value needed more than once is computed once and paid once: marked 'shared')\n";

  auto altText = [&](const PlanStep& s) {
    if (!s.alternative.exists) return std::string("no alternative");
    std::string t = fmt::format("+{}", s.alternative.extra);
    if (!s.alternative.instead.empty()) {
      std::string list;
      for (const auto& n : s.alternative.instead) list += (list.empty() ? "" : ", ") + n;
      t += " via " + list;
    }
    return t;
  };

  std::set<int> printed;
  std::function<void(int, int)> node = [&](int f, int depth) {
    std::string ind(static_cast<size_t>(2 * depth), ' ');
    auto it = producer.find(f);
    if (it == producer.end()) return;  // inputs are listed by their consumer
    const PlanStep& s = *it->second;
    const Action& a = p.actions[s.action];
    if (printed.count(f)) {
      out += fmt::format("{}{}  (shared: computed above, paid once)\n", ind, p.facts[f].name);
      return;
    }
    printed.insert(f);
    std::string shared = s.uses > 1 ? fmt::format(", shared by {} uses, paid once", s.uses) : "";
    out += fmt::format("{}{} <- {} (cost {}{})  [without it: {}]\n", ind, p.facts[f].name, a.name, a.cost, shared,
                       altText(s));
    std::vector<std::string> inputs;
    for (int q : a.pre)
      if (!producer.count(q)) inputs.push_back(p.facts[q].name);
    if (!inputs.empty()) out += fmt::format("{}  from the rig: {}\n", ind, compactFactList(inputs));
    for (int q : a.pre) node(q, depth + 1);
  };
  for (const auto& v : in.varyings) {
    out += "\n";
    std::string sems;
    for (const auto& s : v.semantics) sems += (sems.empty() ? "" : ", ") + s;
    std::string where = v.location >= 0 ? fmt::format("location {}", v.location) : "position";
    std::string type(glslName(v.type));
    if (v.arraySize) type += fmt::format("[{}]", v.arraySize);
    std::string value = v.arraySize ? "{" + sems + "}" : v.semantics.size() > 1 ? "pack(" + sems + ")" : sems;
    out += fmt::format("{} ({} {}) = {}{}\n", v.name, type, where, value, v.via.empty() ? "" : "  [mapped by " + v.via + "]");
    for (const auto& s : v.semantics) {
      int f = p.findFact(s);
      if (f < 0) continue;
      if (producer.count(f)) node(f, 1);
      else {
        std::string src = sourceOf(in, f);
        out += fmt::format("  {}  (from the rig{})\n", s, src.empty() ? "" : ": " + src);
      }
    }
  }

  out += "\nchoices and their cheapest alternatives (best plan re-searched with the rule banned):\n";
  out += fmt::format("  {:<40} {:<24} {:>5} {:>5}  {}\n", "rule", "produces", "cost", "uses", "without it");
  int64_t sum = 0;
  for (const auto& s : e.steps) {
    const Action& a = p.actions[s.action];
    sum += a.cost;
    std::string without = "no alternative";
    if (s.alternative.exists) {
      without = fmt::format("total {} (+{})", s.alternative.planCost, s.alternative.extra);
      if (!s.alternative.instead.empty()) {
        std::string list;
        for (const auto& n : s.alternative.instead) list += (list.empty() ? "" : ", ") + n;
        without += " using " + list;
      }
    }
    out += fmt::format("  {:<40} {:<24} {:>5} {:>5}  {}\n", a.name, p.facts[a.add].name, a.cost, s.uses, without);
  }
  if (in.profile) {
    // Under a device profile the inputs (each paid once) and the fixed terms cost too.
    out += fmt::format("rules {} + rig inputs read and fixed terms {} (fs per vertex, device profile)\n", sum,
                       e.plan.cost - sum);
    sum = e.plan.cost;
  }
  out += fmt::format("total cost {} ({} rules, each paid once; {} A*)\n", sum, e.steps.size(), e.heuristic);
  if (in.profile) out += "\n" + describePlanCost(e.plan, p, *in.profile);
  out += "workload priced for: " + describeWorkload(in.workload) + "\n";
  if (!in.rules.changes.empty()) out += "\n" + formatRuleChanges(in.rules);
  return out;
}

std::string formatRuleChanges(const RuleSet& rules) {
  std::string out = "rules changed by the rules files (override: true, disable:):\n";
  for (const auto& c : rules.changes)
    out += fmt::format("  {} {} at {}:{} (the rule at {}:{})\n", c.disabled ? "disabled" : "overridden", c.rule,
                       c.loc.file, c.loc.line, c.original.file, c.original.line);
  return out;
}

std::vector<UnreachableGoal> analyzeUnreachable(const Problem& p, const RuleSet& rules,
                                                const std::vector<Varying>& varyings) {
  std::vector<bool> reach = reachableFacts(p);
  size_t n = p.facts.size();
  std::vector<bool> isInit(n, false), producible(n, false);
  for (int f : p.init) isInit[f] = true;
  for (const auto& a : p.actions) producible[a.add] = true;

  // Minimal sets of missing inputs per fact, by fixpoint over the AND/OR graph of actions.
  constexpr size_t kMaxSetSize = 4, kMaxSets = 8;
  using Sets = std::vector<std::vector<int>>;  // each sorted; the family is an antichain
  auto minimize = [&](Sets s) {
    for (auto& x : s) {
      std::sort(x.begin(), x.end());
      x.erase(std::unique(x.begin(), x.end()), x.end());
    }
    std::sort(s.begin(), s.end(), [](const auto& a, const auto& b) { return a.size() != b.size() ? a.size() < b.size() : a < b; });
    s.erase(std::unique(s.begin(), s.end()), s.end());
    Sets out;
    for (const auto& x : s) {
      if (x.size() > kMaxSetSize) continue;
      bool dominated = std::any_of(out.begin(), out.end(), [&](const auto& y) {
        return std::includes(x.begin(), x.end(), y.begin(), y.end());
      });
      if (!dominated) out.push_back(x);
      if (out.size() == kMaxSets) break;
    }
    return out;
  };
  // A value an encoding stores (vertex.tangent from a QTangent) is still an input a rig may
  // provide as it is, though decode rules produce it too: it stays a set of its own.
  std::set<std::string> plainInputs;
  for (const auto& e : vertexEncodings())
    for (const auto& s : e.decodes()) plainInputs.insert(s);
  auto family = [](const std::string& name) { return name.substr(0, name.find('[')); };
  std::vector<Sets> opts(n);
  for (size_t f = 0; f < n; ++f) {
    if (isInit[f]) opts[f] = {{}};
    else if (!producible[f] || plainInputs.count(family(p.facts[f].name))) opts[f] = {{static_cast<int>(f)}};
  }
  for (int iter = 0; iter < 200; ++iter) {
    bool changed = false;
    for (const auto& a : p.actions) {
      Sets combos{{}};
      for (int q : a.pre) {
        Sets next;
        for (const auto& c : combos)
          for (const auto& o : opts[q]) {
            std::vector<int> u = c;
            u.insert(u.end(), o.begin(), o.end());
            next.push_back(std::move(u));
          }
        combos = minimize(std::move(next));
        if (combos.empty()) break;
      }
      if (combos.empty()) continue;
      Sets merged = opts[a.add];
      merged.insert(merged.end(), combos.begin(), combos.end());
      merged = minimize(std::move(merged));
      if (merged != opts[a.add]) {
        opts[a.add] = std::move(merged);
        changed = true;
      }
    }
    if (!changed) break;
  }

  std::vector<UnreachableGoal> out;
  for (int g : p.goals) {
    if (reach[g]) continue;
    UnreachableGoal u;
    u.fact = g;
    for (const auto& v : varyings)
      for (const auto& s : v.semantics)
        if (s == p.facts[g].name) u.requestedBy.push_back(v.name);
    for (const auto& set : opts[g]) {
      std::vector<std::string> names;
      for (int f : set) names.push_back(p.facts[f].name);
      u.missingInputs.push_back(names);
    }
    // Rules skipped by `when` that produce the goal or an unreachable value behind it.
    std::set<std::string> cone;
    std::vector<bool> seen(n, false);
    std::function<void(int)> walk = [&](int f) {
      if (seen[f] || reach[f]) return;
      seen[f] = true;
      cone.insert(p.facts[f].name);
      for (const auto& a : p.actions)
        if (a.add == f)
          for (int q : a.pre) walk(q);
    };
    walk(g);
    for (const auto& [r, why] : p.skippedRules)
      if (cone.count(rules.rules[r].produces))
        u.inapplicableRules.push_back(fmt::format("rule '{}' does not apply ({})", rules.rules[r].name, why));
    out.push_back(std::move(u));
  }
  return out;
}

std::string formatUnreachable(const Problem& p, const std::vector<UnreachableGoal>& goals) {
  std::string out;
  for (const auto& g : goals) {
    std::string by;
    for (const auto& v : g.requestedBy) by += (by.empty() ? "" : ", ") + v;
    out += fmt::format("cannot produce '{}'{}", p.facts[g.fact].name, by.empty() ? "" : " (requested by " + by + ")");
    if (g.missingInputs.empty()) {
      out += ": no rule derives it from anything a rig could provide\n";
    } else {
      for (size_t i = 0; i < g.missingInputs.size(); ++i) {
        out += fmt::format("{}{{{}}}", i == 0 ? ": possible if the rig also provided " : " or ",
                           compactFactList(g.missingInputs[i]));
        // The rig stores it, but this generation withholds it: say so, not "provide it".
        for (const std::string& s : g.missingInputs[i])
          if (auto w = p.withheld.find(s); w != p.withheld.end())
            out += fmt::format(" (the rig stores {}, withheld: {})", s, w->second);
      }
      out += "\n";
    }
    for (const auto& r : g.inapplicableRules) out += "  " + r + "\n";
  }
  return out;
}

}  // namespace sg

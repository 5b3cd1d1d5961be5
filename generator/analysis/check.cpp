#include "analysis/check.h"

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <functional>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include "analysis/cost.h"
#include "analysis/probe.h"
#include "common/yaml_util.h"
#include "interface/fragment_interface.h"
#include "rig/gltf_import.h"
#include "rig/rig.h"
#include "rules/instantiate.h"
#include "rules/rules.h"
#include "search/astar.h"
#include "search/problem.h"

namespace sg {

bool costsDisagree(int64_t stated, int64_t measured) {
  int64_t lo = std::min(stated, measured), hi = std::max(stated, measured);
  return hi - lo > 1 && hi > 2 * lo;
}

namespace {

// Where the keys of each rule sit (the loader keeps only the rule's name and product).
struct RuleKeys {
  SourceLoc cost, when, glsl;
};

SourceLoc valueLoc(const YAML::Node& n, const std::string& file, const std::vector<std::string>& lines) {
  SourceLoc l = locOf(n, file);
  // Quoted scalars start after the quote (block scalars '|' stay on the indicator).
  if (l.line >= 1 && l.line <= static_cast<int>(lines.size()) && l.col >= 1) {
    const std::string& raw = lines[static_cast<size_t>(l.line - 1)];
    if (static_cast<size_t>(l.col) <= raw.size() && (raw[l.col - 1] == '"' || raw[l.col - 1] == '\'')) l.col += 1;
  }
  return l;
}

std::map<std::string, RuleKeys> locateRuleKeys(const RuleSet& rules) {
  std::map<std::string, RuleKeys> out;
  for (const auto& file : rules.files) {
    YAML::Node root;
    std::vector<std::string> lines;
    try {
      std::string text = readInputFile(file);
      root = parseYaml(text, file);
      std::istringstream in(text);
      for (std::string l; std::getline(in, l);) lines.push_back(l);
    } catch (const std::exception&) {
      continue;
    }
    if (!root.IsMap() || !root["rules"] || !root["rules"].IsSequence()) continue;
    for (const auto& r : root["rules"]) {
      if (!r.IsMap() || !r["name"] || !r["name"].IsScalar()) continue;
      SourceLoc nameLoc = locOf(r["name"], file);
      bool loaded = std::any_of(rules.rules.begin(), rules.rules.end(), [&](const Rule& x) {
        return x.name == r["name"].Scalar() && x.loc.file == file && x.loc.line == nameLoc.line;
      });
      if (!loaded) continue;  // replaced by an override, or disabled
      RuleKeys k;
      k.cost = valueLoc(r["cost"], file, lines);
      k.when = valueLoc(r["when"], file, lines);
      k.glsl = valueLoc(r["glsl"], file, lines);
      out.emplace(r["name"].Scalar(), k);
    }
  }
  return out;
}

class Checker {
 public:
  explicit Checker(const CheckOptions& opts) : opts_(opts) {}

  CheckReport run() {
    try {
      rules_ = loadRules(opts_.rulesPaths);
      if (!opts_.rigPath.empty()) {
        rig_ = loadRig(opts_.rigPath);  // a YAML rig or a glTF primitive (MODEL.glb#M/P)
        hasRig_ = true;
      }
    } catch (const InputError& e) {
      report_.schemaError = true;
      report_.findings.push_back(e.diagnostic());
      for (const auto& d : e.related) report_.findings.push_back(d);
      return finish();
    }
    keys_ = locateRuleKeys(rules_);
    for (const auto& c : rules_.changes)  // overrides and disables are deliberate: notes, not warnings
      add(Severity::Note, c.loc, fmt::format("rule '{}' {} the rule at {}:{}", c.rule,
                                             c.disabled ? "is disabled here:" : "overrides", c.original.file,
                                             c.original.line));
    structural_.assign(rules_.rules.size(), false);
    for (size_t r = 0; r < rules_.rules.size(); ++r) checkRuleNames(static_cast<int>(r));
    checkVaryings();
    checkConventions();
    checkGraph();
    bool clean = std::none_of(structural_.begin(), structural_.end(), [](bool b) { return b; }) && !varyingErrors_;
    std::vector<std::optional<int64_t>> measured(rules_.rules.size());
    if (opts_.compileSnippets) checkSnippets(measured);
    if (hasRig_ && clean) checkAgainstRig(measured);
    return finish();
  }

 private:
  void add(Severity s, SourceLoc loc, std::string msg) {
    report_.findings.push_back(Diagnostic{s, std::move(loc), std::move(msg)});
  }
  void error(SourceLoc loc, std::string msg) { add(Severity::Error, std::move(loc), std::move(msg)); }
  void warning(SourceLoc loc, std::string msg) { add(Severity::Warning, std::move(loc), std::move(msg)); }

  const RuleKeys& keysOf(const Rule& r) {
    static const RuleKeys none;
    auto it = keys_.find(r.name);
    return it == keys_.end() ? none : it->second;
  }

  std::string didYouMean(const std::string& name) const { return didYouMeanSemantic(rules_, name); }

  // ---- names, references and shapes -------------------------------------------------
  void checkRuleNames(int r) {
    const Rule& rule = rules_.rules[r];
    auto bad = [&](SourceLoc loc, std::string msg) {
      error(std::move(loc), std::move(msg));
      structural_[r] = true;
    };
    for (auto& d : ruleReferenceErrors(rules_, r)) bad(d.loc, d.message);  // the instantiation's own checks
    // has() of a semantic nobody declared is always false: almost certainly a typo.
    if (!rule.when.empty()) {
      static const std::regex hasRe(R"(has\s*\(\s*([A-Za-z_][A-Za-z0-9_.]*)\s*\))");
      const std::string& text = rule.when.text();
      SourceLoc at = keysOf(rule).when;
      for (auto it = std::sregex_iterator(text.begin(), text.end(), hasRe); it != std::sregex_iterator(); ++it) {
        std::string name = (*it)[1];
        if (rules_.findSemantic(name)) continue;
        SourceLoc l = at;
        if (l.col > 0) l.col += static_cast<int>(it->position(1));
        bad(l, fmt::format("rule '{}': 'when' tests has({}), an unknown semantic, which is always false{}", rule.name,
                           name, didYouMean(name)));
      }
    }
    // `${ out }` found by hand: std::regex recursion grows with the line (snippet lines
    // may be megabytes long).
    auto mentionsOut = [](const std::string& t) {
      for (size_t at = t.find("${"); at != std::string::npos; at = t.find("${", at + 2)) {
        size_t p = t.find_first_not_of(" \t", at + 2);
        if (p == std::string::npos || t.compare(p, 3, "out") != 0) continue;
        p = t.find_first_not_of(" \t", p + 3);
        if (p != std::string::npos && t[p] == '}') return true;
      }
      return false;
    };
    bool writesOut = false;
    for (const auto& l : rule.glsl)
      if (mentionsOut(l.text) || l.text.find("${" + rule.produces + "}") != std::string::npos) writesOut = true;
    if (!writesOut) {
      SourceLoc at = keysOf(rule).glsl.line ? keysOf(rule).glsl : rule.loc;
      bad(at, fmt::format("the snippet of rule '{}' never writes its product (no '${{out}}')", rule.name));
    }
  }

  void checkVaryings() {
    for (const auto& v : rules_.varyings) {
      int components = 0;
      std::set<ScalarKind> kinds;
      for (const auto& s : v.semantics) {
        const SemanticDecl* d = rules_.findSemantic(s);
        if (!d) {
          error(v.loc, fmt::format("varying '{}' maps to unknown semantic '{}'{}", v.name, s, didYouMean(s)));
          varyingErrors_ = true;
          continue;
        }
        if (!d->count.empty()) {
          error(v.loc, fmt::format("varying '{}' maps to '{}', an indexed family", v.name, s));
          varyingErrors_ = true;
        }
        components += componentCount(d->type);
        kinds.insert(scalarKind(d->type));
        if (v.semantics.size() > 1 && isMatrix(d->type)) {
          error(v.loc, fmt::format("varying '{}' packs '{}', a matrix ({}); only scalars and vectors pack", v.name, s,
                                   glslName(d->type)));
          varyingErrors_ = true;
        }
      }
      if (v.semantics.size() > 1 && components > 4) {
        error(v.loc, fmt::format("varying '{}' packs {} components; a vector holds at most 4", v.name, components));
        varyingErrors_ = true;
      }
      if (kinds.size() > 1) {
        error(v.loc, fmt::format("varying '{}' packs values of different scalar types (float and integer)", v.name));
        varyingErrors_ = true;
      }
    }
  }

  // Naming-convention entries: known semantics whose sizes fill the entry's type.
  void checkConventions() {
    for (const auto& c : rules_.conventions)
      for (const auto& e : c.entries) {
        int components = 0;
        bool known = true;
        for (const auto& s : e.semantics) {
          const SemanticDecl* d = rules_.findSemantic(s);
          if (!d) {
            error(e.loc, fmt::format("convention '{}' maps '{}' to unknown semantic '{}'{}", c.name, e.name, s, didYouMean(s)));
            known = false;
            continue;
          }
          components += componentCount(d->type);
        }
        std::optional<Type> t = e.type.empty() ? std::nullopt : parseType(e.type);
        if (known && t && components != componentCount(*t))
          error(e.loc, fmt::format("convention '{}' maps {} '{}' to {} components; a {} has {}", c.name, e.type, e.name,
                                   components, e.type, componentCount(*t)));
      }
  }

  // ---- the semantic graph: cycles, derivability, dead products ------------------------
  void checkGraph() {
    const auto& sems = rules_.semantics;
    std::map<std::string, int> id;
    for (size_t i = 0; i < sems.size(); ++i) id[sems[i].name] = static_cast<int>(i);
    int n = static_cast<int>(sems.size());
    // Edges need -> product, labelled by rule.
    std::vector<std::vector<std::pair<int, int>>> out(n);
    std::vector<bool> produced(n, false);
    for (size_t r = 0; r < rules_.rules.size(); ++r) {
      const Rule& rule = rules_.rules[r];
      auto p = id.find(rule.produces);
      if (p == id.end()) continue;
      produced[p->second] = true;
      for (const auto& ref : rule.needs) {
        auto q = id.find(ref.name);
        if (q != id.end() && q->second != p->second) out[q->second].push_back({p->second, static_cast<int>(r)});
      }
    }
    // Derivable from leaves (semantics no rule produces: a rig may provide them).
    std::vector<bool> derivable(n, false);
    for (int i = 0; i < n; ++i) derivable[i] = !produced[i];
    for (bool changed = true; changed;) {
      changed = false;
      for (const auto& rule : rules_.rules) {
        auto p = id.find(rule.produces);
        if (p == id.end() || derivable[p->second]) continue;
        bool ok = true;
        for (const auto& ref : rule.needs) {
          auto q = id.find(ref.name);
          if (q == id.end() || !derivable[q->second] || q->second == p->second) ok = false;
        }
        if (ok) derivable[p->second] = changed = true;
      }
    }
    // Strongly connected components (Tarjan).
    std::vector<int> index(n, -1), low(n, 0), comp(n, -1);
    std::vector<bool> onStack(n, false);
    std::vector<int> stack;
    int counter = 0, comps = 0;
    std::function<void(int)> strong = [&](int v) {
      index[v] = low[v] = counter++;
      stack.push_back(v);
      onStack[v] = true;
      for (auto [w, r] : out[v]) {
        if (index[w] < 0) {
          strong(w);
          low[v] = std::min(low[v], low[w]);
        } else if (onStack[w]) {
          low[v] = std::min(low[v], index[w]);
        }
      }
      if (low[v] == index[v]) {
        for (;;) {
          int w = stack.back();
          stack.pop_back();
          onStack[w] = false;
          comp[w] = comps;
          if (w == v) break;
        }
        ++comps;
      }
    };
    for (int v = 0; v < n; ++v)
      if (index[v] < 0) strong(v);
    std::vector<std::vector<int>> members(comps);
    for (int v = 0; v < n; ++v) members[comp[v]].push_back(v);
    std::set<int> badComponents;
    for (const auto& m : members) {
      if (m.size() < 2) continue;
      // A concrete cycle through the first member: BFS inside the component back to it.
      int s = m.front();
      std::map<int, std::pair<int, int>> prev;  // node -> (previous node, rule)
      std::vector<int> queue{s};
      bool closed = false;
      std::pair<int, int> last;
      for (size_t qi = 0; qi < queue.size() && !closed; ++qi) {
        int v = queue[qi];
        for (auto [w, r] : out[v]) {
          if (comp[w] != comp[s]) continue;
          if (w == s) {
            last = {v, r};
            closed = true;
            break;
          }
          if (prev.count(w)) continue;
          prev[w] = {v, r};
          queue.push_back(w);
        }
      }
      std::vector<std::pair<int, int>> path;  // (node, rule that consumes it)
      for (auto cur = last;;) {
        path.push_back(cur);
        if (cur.first == s) break;
        cur = prev[cur.first];
      }
      std::reverse(path.begin(), path.end());
      std::string text = "'" + sems[s].name + "'";
      for (auto [v, r] : path) text += fmt::format(" -> rule '{}' -> '{}'", rules_.rules[r].name,
                                                   rules_.rules[r].produces);
      int firstRule = path.front().second;
      std::vector<std::string> underivable;
      for (int v : m)
        if (!derivable[v]) underivable.push_back(sems[v].name);
      if (!underivable.empty()) {
        badComponents.insert(comp[s]);
        std::string list;
        for (const auto& u : underivable) list += (list.empty() ? "'" : ", '") + u + "'";
        error(rules_.rules[firstRule].loc,
              fmt::format("cycle with no way in: every derivation of {} needs {} itself ({})", list,
                          underivable.size() == 1 ? "the value" : "one of these values", text));
        for (int v : m)
          for (auto [w, r] : out[v])
            if (comp[w] == comp[s]) structural_[r] = true;
      } else {
        warning(rules_.rules[firstRule].loc,
                fmt::format("rules form a cycle ({}); harmless for the search (each value is computed once and "
                            "each also has a derivation outside the cycle), but usually a modelling mistake",
                            text));
      }
    }
    // Rules that can never fire because a need cannot be derived by any rule.
    for (size_t r = 0; r < rules_.rules.size(); ++r) {
      const Rule& rule = rules_.rules[r];
      if (structural_[r]) continue;
      for (const auto& ref : rule.needs) {
        auto q = id.find(ref.name);
        if (q == id.end() || derivable[q->second]) continue;
        warning(ref.loc, fmt::format("rule '{}' can never fire: no derivation of '{}' exists{}", rule.name, ref.name,
                                     badComponents.count(comp[q->second]) ? " (it is on a cycle with no way in)"
                                                                          : ""));
        break;
      }
    }
    // Products that never reach a requested value (only when the files map varyings:
    // a library without `varyings:` is a vocabulary where any semantic may be requested).
    if (rules_.varyings.empty()) return;
    std::vector<bool> useful(n, false);
    std::vector<int> work;
    auto mark = [&](const std::string& name) {
      auto it = id.find(name);
      if (it != id.end() && !useful[it->second]) {
        useful[it->second] = true;
        work.push_back(it->second);
      }
    };
    mark("clip.position");  // gl_Position is always requested
    for (const auto& v : rules_.varyings)
      for (const auto& s : v.semantics) mark(s);
    while (!work.empty()) {
      int v = work.back();
      work.pop_back();
      for (const auto& rule : rules_.rules)
        if (rule.produces == sems[v].name)
          for (const auto& ref : rule.needs) mark(ref.name);
    }
    for (size_t r = 0; r < rules_.rules.size(); ++r) {
      const Rule& rule = rules_.rules[r];
      auto p = id.find(rule.produces);
      if (p == id.end() || useful[p->second]) continue;
      warning(rule.producesLoc, fmt::format("rule '{}' produces '{}', which no varying needs, directly or through "
                                            "other rules",
                                            rule.name, rule.produces));
    }
  }

  // ---- snippets compiled alone, and their measured cost --------------------------------
  void checkSnippets(std::vector<std::optional<int64_t>>& measured) {
    std::vector<ProbeRig> probes;
    try {
      if (hasRig_) probes.push_back(probeRigFromRig(rig_, rules_));
      else probes = defaultProbeRigs(rules_);
    } catch (const InputError& e) {
      add(hasRig_ ? Severity::Error : Severity::Warning, e.diagnostic().loc,
          e.diagnostic().message + " (snippets not compiled)");
      return;
    }
    Severity unknownName = hasRig_ ? Severity::Error : Severity::Warning;
    for (size_t r = 0; r < rules_.rules.size(); ++r) {
      const Rule& rule = rules_.rules[r];
      CostRow row;
      row.rule = rule.name;
      row.loc = rule.loc;
      row.isAuto = rule.costAuto;
      if (structural_[r]) {
        report_.costs.push_back(row);
        continue;
      }
      const ProbeRig* chosen = nullptr;
      bool whenFailed = false;
      for (const auto& p : probes) {
        if (rule.when.empty()) {
          chosen = &p;
          break;
        }
        try {
          if (rule.when.eval(probeEnv(p)) != 0) {
            chosen = &p;
            break;
          }
        } catch (const InputError& e) {
          add(rule.when.failsForEveryRig() ? Severity::Error : unknownName, e.diagnostic().loc,
              fmt::format("rule '{}': cannot evaluate 'when' for {}: {}", rule.name, p.name, e.diagnostic().message));
          whenFailed = true;
          break;
        }
      }
      if (!chosen || whenFailed) {
        report_.costs.push_back(row);
        continue;
      }
      row.rig = chosen->name;
      if (!rule.costAuto) {
        try {
          row.stated = rule.cost.eval(probeEnv(*chosen));
          if (*row.stated < 0)
            error(keysOf(rule).cost.line ? keysOf(rule).cost : rule.loc,
                  fmt::format("rule '{}' has negative cost {} for {}", rule.name, *row.stated, chosen->name));
          else if (*row.stated > kMaxRuleCost)
            error(keysOf(rule).cost.line ? keysOf(rule).cost : rule.loc,
                  fmt::format("rule '{}' has cost {} for {}, above the limit of {}", rule.name, *row.stated,
                              chosen->name, kMaxRuleCost));
        } catch (const InputError& e) {
          // Without a rig a failure may be that rig's (an unknown name); one in a part that
          // every rig evaluates (a constant that overflows) is an error, as generate says.
          add(rule.cost.failsForEveryRig() ? Severity::Error : unknownName, e.diagnostic().loc,
              fmt::format("rule '{}': cannot evaluate 'cost' for {}: {}", rule.name, chosen->name,
                          e.diagnostic().message));
        }
      }
      AutoCost c = measureRuleCost(rules_, static_cast<int>(r), *chosen);
      if (!c.ok) {
        for (auto d : c.diagnostics) {
          if (d.loc.file.empty() || d.loc.line == 0) d.loc = rule.loc;
          d.message = fmt::format("{} (snippet of '{}' compiled alone for {})", d.message, rule.name, chosen->name);
          report_.findings.push_back(d);
        }
        report_.costs.push_back(row);
        continue;
      }
      row.measured = c.cost;
      measured[r] = c.cost;
      if (row.stated && costsDisagree(*row.stated, c.cost)) {
        row.disagrees = true;
        std::string parts;
        for (const auto& it : c.breakdown.items)
          if (it.slots) parts += fmt::format("{}{} x{} = {}", parts.empty() ? "" : ", ", it.what, it.count, it.slots);
        warning(keysOf(rule).cost.line ? keysOf(rule).cost : rule.loc,
                fmt::format("rule '{}' states cost {} but its snippet measures {} for {} ({}); see "
                            "docs/cost-model.md",
                            rule.name, *row.stated, c.cost, chosen->name, parts.empty() ? "no counted instructions" : parts));
      }
      report_.costs.push_back(row);
    }
  }

  // ---- instantiation against the given rig ---------------------------------------------
  void checkAgainstRig(const std::vector<std::optional<int64_t>>& measured) {
    RuleSet rs = rules_;
    for (size_t r = 0; r < rs.rules.size(); ++r)
      if (rs.rules[r].costAuto) rs.rules[r].cost = Expr::parse(std::to_string(measured[r].value_or(0)), rs.rules[r].loc);
    Problem p;
    try {
      p = buildProblem(rig_, rs, {});
    } catch (const InputError& e) {
      report_.findings.push_back(e.diagnostic());
      for (const auto& d : e.related) report_.findings.push_back(d);
      return;
    }
    for (const auto& [r, why] : p.skippedRules) {
      const Rule& rule = rules_.rules[r];
      if (rule.when.empty() || why.rfind("when", 0) != 0) continue;
      SourceLoc at = keysOf(rule).when.line ? keysOf(rule).when : rule.loc;
      warning(at, fmt::format("rule '{}' never fires for rig '{}': its 'when' ({}) is false", rule.name, rig_.name,
                              rule.when.text()));
    }
    std::vector<bool> reach = reachableFacts(p);
    std::vector<bool> producible(p.facts.size(), false);
    for (const auto& a : p.actions) producible[a.add] = true;
    for (const auto& a : p.actions) {
      if (a.rule < 0) continue;  // a bit-packed field's unpack reads only its attribute
      const Rule& rule = rules_.rules[a.rule];
      for (int f : a.pre) {
        if (reach[f]) continue;
        // The missing rig inputs behind it.
        std::set<std::string> missing;
        std::vector<bool> seen(p.facts.size(), false);
        std::function<void(int)> walk = [&](int g) {
          if (seen[g] || reach[g]) return;
          seen[g] = true;
          if (!producible[g]) {
            missing.insert(p.facts[g].name);
            return;
          }
          for (const auto& b : p.actions)
            if (b.add == g)
              for (int q : b.pre) walk(q);
        };
        walk(f);
        std::string list;
        for (const auto& m : missing) list += (list.empty() ? "'" : ", '") + m + "'";
        SourceLoc at = rule.loc;
        for (const auto& ref : rule.needs)
          if (ref.name == splitIndexed(p.facts[f].name).first) {
            at = ref.loc;
            break;
          }
        std::string why = producible[f] ? fmt::format("no applicable rule can derive it for this rig (missing: {})", list)
                                        : "the rig does not provide it and no applicable rule produces it";
        warning(at, fmt::format("rule '{}' never fires for rig '{}': it needs '{}', and {}", rule.name, rig_.name,
                                p.facts[f].name, why));
        break;
      }
    }
  }

  CheckReport finish() {
    std::map<std::string, size_t> fileOrder;
    for (size_t i = 0; i < rules_.files.size(); ++i) fileOrder.emplace(rules_.files[i], i);
    auto order = [&](const Diagnostic& d) {
      auto it = fileOrder.find(d.loc.file);
      return std::make_tuple(it == fileOrder.end() ? fileOrder.size() : it->second, d.loc.file, d.loc.line, d.loc.col);
    };
    std::stable_sort(report_.findings.begin(), report_.findings.end(),
                     [&](const Diagnostic& a, const Diagnostic& b) { return order(a) < order(b); });
    // The same finding from two paths (e.g. a probe and the instantiation) is reported once.
    std::vector<Diagnostic> unique;
    for (const auto& d : report_.findings) {
      bool dup = std::any_of(unique.begin(), unique.end(), [&](const Diagnostic& u) {
        return u.loc.file == d.loc.file && u.loc.line == d.loc.line && u.loc.col == d.loc.col && u.message == d.message;
      });
      if (!dup) unique.push_back(d);
    }
    report_.findings = scopeToNamedFiles(std::move(unique));
    report_.werror = opts_.werror;
    for (auto& d : report_.findings) {
      if (opts_.werror && d.severity == Severity::Warning) d.severity = Severity::Error;
      if (d.severity == Severity::Error) ++report_.errors;
      else if (d.severity == Severity::Warning) ++report_.warnings;
    }
    report_.groups = groupFindings(report_.findings);
    return std::move(report_);
  }

  // The user checks the files they name: warnings and notes located in included files
  // (the standard library, usually) are counted but shown only with --all. Errors are
  // always shown: an included file that fails breaks the named one too.
  std::vector<Diagnostic> scopeToNamedFiles(std::vector<Diagnostic> findings) {
    if (opts_.all) return findings;
    std::vector<std::filesystem::path> named;
    for (const auto& p : opts_.rulesPaths) named.push_back(canonicalOrSelf(p));
    if (!opts_.rigPath.empty()) named.push_back(canonicalOrSelf(opts_.rigPath));
    std::vector<Diagnostic> shown;
    for (auto& d : findings) {
      bool mine = d.loc.file.empty() || std::find(named.begin(), named.end(), canonicalOrSelf(d.loc.file)) != named.end();
      if (mine || d.severity == Severity::Error) shown.push_back(std::move(d));
      else ++report_.hiddenWarnings;
    }
    return shown;
  }

  static std::filesystem::path canonicalOrSelf(const std::string& p) {
    std::error_code ec;
    auto c = std::filesystem::weakly_canonical(p, ec);
    return ec ? std::filesystem::path(p) : c;
  }

  static std::vector<FindingGroup> groupFindings(const std::vector<Diagnostic>& findings) {
    std::vector<FindingGroup> groups;
    for (const auto& d : findings) {
      if (d.severity == Severity::Error) continue;
      std::string kind;  // quoted names elided: "rule '…' is never used"
      for (size_t i = 0; i < d.message.size(); ++i) {
        kind += d.message[i];
        if (d.message[i] != '\'') continue;
        size_t close = d.message.find('\'', i + 1);
        if (close == std::string::npos) continue;
        kind += "\u2026'";
        i = close;
      }
      auto it = std::find_if(groups.begin(), groups.end(), [&](const FindingGroup& g) { return g.kind == kind && g.severity == d.severity; });
      if (it == groups.end()) groups.push_back(FindingGroup{kind, d.severity, 1});
      else ++it->count;
    }
    std::stable_sort(groups.begin(), groups.end(), [](const FindingGroup& a, const FindingGroup& b) { return a.count > b.count; });
    return groups;
  }

  CheckOptions opts_;
  RuleSet rules_;
  Rig rig_;
  bool hasRig_ = false;
  std::map<std::string, RuleKeys> keys_;
  std::vector<bool> structural_;  // rule has a naming/shape error: skip deeper checks
  bool varyingErrors_ = false;
  CheckReport report_;
};

}  // namespace

CheckReport checkRules(const CheckOptions& opts) { return Checker(opts).run(); }

std::string formatCheckReport(const CheckReport& r) {
  std::string out;
  for (const auto& d : r.findings) out += renderDiagnostic(d) + "\n";
  bool several = std::any_of(r.groups.begin(), r.groups.end(), [](const FindingGroup& g) { return g.count > 1; });
  if (several) {
    out += "by kind:\n";
    for (const auto& g : r.groups)
      out += fmt::format("  {:>4} {}: {}\n", g.count, g.severity == Severity::Note ? "note" : "warning", g.kind);
  }
  out += fmt::format("{} error{}, {} warning{}", r.errors, r.errors == 1 ? "" : "s", r.warnings, r.warnings == 1 ? "" : "s");
  if (r.werror && r.errors) out += " (-Werror: warnings are errors)";
  if (r.hiddenWarnings)
    out += fmt::format("; {} warning{} and note{} in included files not shown (--all shows them)", r.hiddenWarnings,
                       r.hiddenWarnings == 1 ? "" : "s", r.hiddenWarnings == 1 ? "" : "s");
  return out + "\n";
}

std::string formatCostTable(const CheckReport& r) {
  std::string out = fmt::format("{:<36} {:>7} {:>9}  {}\n", "rule", "stated", "measured", "instantiated for");
  for (const auto& c : r.costs) {
    std::string stated = c.isAuto ? "auto" : c.stated ? std::to_string(*c.stated) : "-";
    std::string measured = c.measured ? std::to_string(*c.measured) : "-";
    out += fmt::format("{:<36} {:>7} {:>9}  {}{}\n", c.rule, stated, measured, c.rig.empty() ? "(not probed)" : c.rig,
                       c.disagrees ? "  <- differs by more than 2x" : "");
  }
  return out;
}

}  // namespace sg

// Rule instantiation (docs/rules-format.md, "Instantiation").
#include "rules/instantiate.h"

#include <fmt/format.h>

#include <algorithm>
#include <optional>

#include "rig/rig.h"

namespace sg {

std::string indexedName(const std::string& name, int64_t i) { return fmt::format("{}[{}]", name, i); }

void evalFamilies(RigShape& shape, const RuleSet& rules, bool strictArrays) {
  ExprEnv env;
  env.lookup = [&shape](const std::string& n, int64_t& v) {
    auto it = shape.params.find(n);
    if (it == shape.params.end()) return false;
    v = it->second;
    return true;
  };
  env.has = [](const std::string&) { return false; };  // counts come before anything is provided
  for (const auto& d : rules.semantics) {
    if (!d.count.empty()) {
      int64_t n = d.count.eval(env);
      if (n < 0 || n > kMostFamilyInstances)
        throw InputError(d.loc, fmt::format("semantic '{}' has count {} (allowed 0..{})", d.name, n, kMostFamilyInstances));
      shape.families[d.name] = n;
    }
    if (!d.arrayParam.empty()) {
      auto it = shape.params.find(d.arrayParam);
      if (it == shape.params.end()) {
        if (strictArrays)
          throw InputError(d.loc, fmt::format("semantic '{}' is sized by '{}', which rig '{}' does not define", d.name,
                                              d.arrayParam, shape.name));
        shape.arrays[d.name] = 4;
      } else {
        shape.arrays[d.name] = std::max<int64_t>(1, it->second);
      }
    }
  }
}

RigShape shapeOfRig(const Rig& rig, const RuleSet& rules) {
  RigShape s;
  s.name = rig.name;
  s.params = rig.params;
  // A rig that does not declare uniform_scale may scale bones and models per axis
  // (docs/rig-format.md): rules using mat3(M) as the normal matrix need uniform_scale.
  s.params.emplace("uniform_scale", 0);
  evalFamilies(s, rules, true);
  for (const auto& a : rig.attributes) {
    int targets = a.perMorphTarget ? rig.morphTargets() : 1;
    for (int t = 0; t < targets; ++t)
      for (const auto& part : a.provides) s.provided.insert(a.perMorphTarget ? indexedName(part.semantic, t) : part.semantic);
  }
  for (const auto& u : rig.uniforms) s.provided.insert(u.semantic);
  return s;
}

ExprEnv shapeEnv(const RigShape& shape) {
  ExprEnv env;
  const RigShape* s = &shape;
  env.lookup = [s](const std::string& n, int64_t& v) {
    auto it = s->params.find(n);
    if (it == s->params.end()) return false;
    v = it->second;
    return true;
  };
  env.has = [s](const std::string& n) { return s->provided.count(n) || s->provided.count(indexedName(n, 0)); };
  return env;
}

namespace {

size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (size_t j = 1; j <= b.size(); ++j)
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

}  // namespace

std::string didYouMean(const std::string& name, const std::vector<std::string>& names) {
  std::string best;
  size_t bestD = std::max<size_t>(2, name.size() / 4) + 1;
  for (const auto& n : names) {
    size_t dist = editDistance(name, n);
    if (dist < bestD) {
      bestD = dist;
      best = n;
    }
  }
  return best.empty() ? "" : fmt::format(" (did you mean '{}'?)", best);
}

std::string didYouMeanSemantic(const RuleSet& rules, const std::string& name) {
  std::vector<std::string> names;
  for (const auto& d : rules.semantics) names.push_back(d.name);
  return didYouMean(name, names);
}

std::vector<Diagnostic> ruleReferenceErrors(const RuleSet& rules, int r) {
  const Rule& rule = rules.rules[static_cast<size_t>(r)];
  std::vector<Diagnostic> out;
  auto bad = [&](SourceLoc loc, std::string msg) { out.push_back(Diagnostic{Severity::Error, std::move(loc), std::move(msg)}); };
  const SemanticDecl* prod = rules.findSemantic(rule.produces);
  if (!prod)
    bad(rule.producesLoc, fmt::format("rule '{}' produces unknown semantic '{}'{}", rule.name, rule.produces,
                                      didYouMeanSemantic(rules, rule.produces)));
  else if (!prod->count.empty())
    bad(rule.producesLoc, fmt::format("rule '{}' produces '{}', which is an indexed family; rules produce single "
                                      "semantics",
                                      rule.name, rule.produces));
  for (const auto& ref : rule.needs) {
    const SemanticDecl* d = rules.findSemantic(ref.name);
    if (!d) {
      bad(ref.loc, fmt::format("rule '{}' needs unknown semantic '{}'{}", rule.name, ref.name,
                               didYouMeanSemantic(rules, ref.name)));
      continue;
    }
    bool family = !d->count.empty();
    if (family && ref.index.empty())
      bad(ref.loc, fmt::format("'{}' is an indexed family: write '{}[*]' or '{}[i]'", ref.name, ref.name, ref.name));
    else if (!family && !ref.index.empty())
      bad(ref.loc, fmt::format("'{}' is not an indexed family (it has no 'count')", ref.name));
    if (ref.name == rule.produces)
      bad(ref.loc, fmt::format("rule '{}' needs its own product '{}': it can never fire", rule.name, rule.produces));
  }
  return out;
}

bool ruleApplies(const Rule& rule, const RigShape& shape) {
  return rule.when.empty() || rule.when.eval(shapeEnv(shape)) != 0;
}

int64_t ruleCost(const Rule& rule, const RigShape& shape) {
  if (rule.costAuto && rule.cost.empty())
    throw InputError(rule.loc, fmt::format("rule '{}': 'cost: auto' must be resolved before instantiation "
                                           "(resolveAutoCosts measures its snippet)",
                                           rule.name));
  int64_t cost = rule.cost.eval(shapeEnv(shape));
  if (cost < 0) throw InputError(rule.loc, fmt::format("rule '{}' has negative cost {}", rule.name, cost));
  // Above this, sums of costs could reach the search's "infinite" and plans would be lost.
  if (cost > kMaxRuleCost)
    throw InputError(rule.loc, fmt::format("rule '{}' has cost {}, above the limit of {}", rule.name, cost, kMaxRuleCost));
  return cost;
}

RuleInstance instantiateRule(const RuleSet& rules, int r, const RigShape& shape, const std::string& outText,
                             const std::function<std::string(const std::string& instance)>& textOf) {
  const Rule& rule = rules.rules[static_cast<size_t>(r)];
  if (auto errors = ruleReferenceErrors(rules, r); !errors.empty()) {
    InputError e(errors.front());
    e.related.assign(errors.begin() + 1, errors.end());
    throw e;
  }
  ExprEnv env = shapeEnv(shape);
  auto count = [&](const std::string& family) {
    auto it = shape.families.find(family);
    return it == shape.families.end() ? int64_t{0} : it->second;
  };
  std::set<std::string> needs;
  for (const auto& ref : rule.needs) {
    bool family = !rules.findSemantic(ref.name)->count.empty();
    if (!family) {
      needs.insert(ref.name);
    } else if (ref.index == "*") {
      for (int64_t i = 0; i < count(ref.name); ++i) needs.insert(indexedName(ref.name, i));
    } else {
      SourceLoc at = ref.loc;
      if (at.col > 0) at.col += static_cast<int>(ref.name.size()) + 1;
      int64_t i = Expr::parse(ref.index, at).eval(env);
      if (i < 0 || i >= count(ref.name))
        throw InputError(ref.loc, fmt::format("needs '{}[{}]': index {} is out of range ({} has {} instances for {})",
                                              ref.name, i, i, ref.name, count(ref.name), shape.name));
      needs.insert(indexedName(ref.name, i));
    }
  }

  SnippetContext ctx;
  ctx.rigEnv = env;
  ctx.outText = outText;
  ctx.semantic = [&](const std::string& name, int64_t idx, const SourceLoc& at, std::string& text) {
    const SemanticDecl* d = rules.findSemantic(name);
    if (!d) {
      if (idx >= 0) return false;  // not a semantic: an expression such as ${k[0]}
      throw InputError(at, fmt::format("rule '{}' uses unknown semantic '{}'{}", rule.name, name,
                                       didYouMeanSemantic(rules, name)));
    }
    bool family = !d->count.empty();
    if (family && idx < 0) throw InputError(at, fmt::format("'{}' is an indexed family: write ${{{}[i]}}", name, name));
    if (!family && idx >= 0) throw InputError(at, fmt::format("'{}' is not an indexed family", name));
    if (family && idx >= count(name))
      throw InputError(at, fmt::format("snippet uses '{}[{}]': index {} is out of range ({} has {} instances for {})",
                                       name, idx, idx, name, count(name), shape.name));
    std::string full = family ? indexedName(name, idx) : name;
    if (full == rule.produces) {
      text = outText;
      return true;
    }
    if (!needs.count(full))
      throw InputError(at, fmt::format("rule '{}' uses '{}' but does not list it in 'needs'", rule.name, full));
    text = textOf(full);
    return true;
  };
  RuleInstance inst;
  inst.code = expandSnippet(rule.glsl, ctx);
  inst.needs.assign(needs.begin(), needs.end());
  return inst;
}

}  // namespace sg

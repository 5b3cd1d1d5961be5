// Instantiates rules against a rig (docs/rules-format.md, "Instantiation").
#include "search/problem.h"

#include <fmt/format.h>

#include <algorithm>
#include <map>
#include <optional>
#include <set>

#include "interface/fragment_interface.h"
#include "rig/rig.h"
#include "rules/rules.h"
#include "rules/snippet.h"

namespace sg {

std::string factRef(int fact) { return std::string(1, kFactRefBegin) + std::to_string(fact) + kFactRefEnd; }

std::pair<std::string, int64_t> splitIndexed(const std::string& s) {
  auto lb = s.find('[');
  if (lb == std::string::npos || s.back() != ']') return {s, -1};
  try {
    return {s.substr(0, lb), std::stoll(s.substr(lb + 1, s.size() - lb - 2))};
  } catch (const std::exception&) {
    return {s, -1};
  }
}

int Problem::findFact(const std::string& name) const {
  for (size_t i = 0; i < facts.size(); ++i)
    if (facts[i].name == name) return static_cast<int>(i);
  return -1;
}

namespace {

std::string indexed(const std::string& name, int64_t i) { return fmt::format("{}[{}]", name, i); }


class Builder {
 public:
  Builder(const Rig& rig, const RuleSet& rules) : rig_(rig), rules_(rules) {
    env_.lookup = [this](const std::string& n, int64_t& v) {
      auto it = rig_.params.find(n);
      if (it == rig_.params.end()) return false;
      v = it->second;
      return true;
    };
    env_.has = [this](const std::string& s) { return provided_.count(s) || provided_.count(indexed(s, 0)); };
  }

  Problem build(const std::vector<Varying>& varyings) {
    declareFacts();
    provideFromRig();
    for (size_t r = 0; r < rules_.rules.size(); ++r) instantiate(static_cast<int>(r));
    for (const auto& v : varyings)
      for (const auto& s : v.semantics) {
        int f = p_.findFact(s);
        if (f < 0) throw InputError(v.loc, fmt::format("'{}' requests unknown semantic '{}'", v.name, s));
        p_.goals.push_back(f);
      }
    std::sort(p_.goals.begin(), p_.goals.end());
    p_.goals.erase(std::unique(p_.goals.begin(), p_.goals.end()), p_.goals.end());
    std::sort(p_.init.begin(), p_.init.end());
    return std::move(p_);
  }

 private:
  void declareFacts() {
    for (const auto& d : rules_.semantics) {
      Fact f;
      f.type = d.type;
      if (!d.arrayParam.empty()) {
        if (!rig_.params.count(d.arrayParam))
          throw InputError(d.loc, fmt::format("semantic '{}' is sized by '{}', which rig '{}' does not define", d.name,
                                              d.arrayParam, rig_.name));
        f.arraySize = static_cast<int>(rig_.param(d.arrayParam));
      }
      if (d.count.empty()) {
        f.name = d.name;
        add(f);
        continue;
      }
      int64_t n = d.count.eval(env_);
      if (n < 0 || n > 256) throw InputError(d.loc, fmt::format("semantic '{}' has count {} (allowed 0..256)", d.name, n));
      families_[d.name] = n;
      for (int64_t i = 0; i < n; ++i) {
        f.name = indexed(d.name, i);
        add(f);
      }
    }
  }

  void add(const Fact& f) {
    index_[f.name] = static_cast<int>(p_.facts.size());
    p_.facts.push_back(f);
  }

  int factOrFail(const std::string& name, const SourceLoc& at, const char* who) {
    auto it = index_.find(name);
    if (it != index_.end()) return it->second;
    auto [base, i] = splitIndexed(name);
    if (families_.count(base))
      throw InputError(at, fmt::format("{} '{}': index {} is out of range (the rig has {} instances)", who, name, i,
                                       families_[base]));
    throw InputError(at, fmt::format("{} unknown semantic '{}' (not declared in the rules)", who, name));
  }

  void provide(int f, Fact::Source src, int rigIndex, int target, const std::string& swizzle, Type have,
               const SourceLoc& at) {
    Fact& fact = p_.facts[f];
    if (fact.type != have)
      throw InputError(at, fmt::format("'{}' is {} in the rules but the rig provides {}", fact.name,
                                       glslName(fact.type), glslName(have)));
    fact.source = src;
    fact.rigIndex = rigIndex;
    fact.target = target;
    fact.swizzle = swizzle;
    provided_.insert(fact.name);
    p_.init.push_back(f);
  }

  void provideFromRig() {
    for (size_t a = 0; a < rig_.attributes.size(); ++a) {
      const RigAttribute& attr = rig_.attributes[a];
      int targets = attr.perMorphTarget ? rig_.morphTargets() : 1;
      for (int t = 0; t < targets; ++t)
        for (const auto& part : attr.provides) {
          std::string name = attr.perMorphTarget ? indexed(part.semantic, t) : part.semantic;
          int n = part.swizzle.empty() ? componentCount(attr.shaderType) : static_cast<int>(part.swizzle.size());
          std::optional<Type> have = vectorType(scalarKind(attr.shaderType), n);
          if (!have)  // e.g. "xy" of a uint8x4: there is no uvec2 type
            throw InputError(attr.loc, fmt::format("attribute '{}' provides '{}' through swizzle '{}': {} components of "
                                                   "{} have no supported type",
                                                   attr.name, name, part.swizzle, n, glslName(attr.shaderType)));
          int f = factOrFail(name, attr.loc, fmt::format("attribute '{}' provides", attr.name).c_str());
          provide(f, Fact::Source::Attribute, static_cast<int>(a), attr.perMorphTarget ? t : -1, part.swizzle, *have,
                  attr.loc);
        }
    }
    for (size_t u = 0; u < rig_.uniforms.size(); ++u) {
      const RigUniform& un = rig_.uniforms[u];
      int f = factOrFail(un.semantic, un.loc, fmt::format("uniform '{}' provides", un.name).c_str());
      const Fact& fact = p_.facts[f];
      if (fact.arraySize != un.arraySize)
        throw InputError(un.loc, fmt::format("uniform '{}': semantic '{}' is {} but the uniform is {}", un.name,
                                             un.semantic,
                                             fact.arraySize ? fmt::format("an array of {}", fact.arraySize) : "not an array",
                                             un.arraySize ? fmt::format("an array of {}", un.arraySize) : "not an array"));
      provide(f, Fact::Source::Uniform, static_cast<int>(u), -1, "", un.type, un.loc);
    }
  }

  void instantiate(int r) {
    const Rule& rule = rules_.rules[r];
    if (!rule.when.empty() && rule.when.eval(env_) == 0) {
      p_.skippedRules.emplace_back(r, fmt::format("when '{}' is false for rig '{}'", rule.when.text(), rig_.name));
      return;
    }
    Action act;
    act.name = rule.name;
    act.rule = r;
    if (families_.count(rule.produces))
      throw InputError(rule.producesLoc, fmt::format("rule '{}' produces '{}', which is an indexed family; rules "
                                                     "produce single semantics",
                                                     rule.name, rule.produces));
    act.add = factOrFail(rule.produces, rule.producesLoc, fmt::format("rule '{}' produces", rule.name).c_str());
    std::set<int> pre;
    for (const auto& ref : rule.needs) {
      bool family = families_.count(ref.name) != 0;
      if (ref.index.empty()) {
        if (family)
          throw InputError(ref.loc, fmt::format("'{}' is an indexed family: write '{}[*]' or '{}[i]'", ref.name,
                                                ref.name, ref.name));
        pre.insert(factOrFail(ref.name, ref.loc, "needs"));
      } else if (!family) {
        throw InputError(ref.loc, fmt::format("'{}' is not an indexed family", ref.name));
      } else if (ref.index == "*") {
        for (int64_t i = 0; i < families_[ref.name]; ++i) pre.insert(index_[indexed(ref.name, i)]);
      } else {
        SourceLoc at = ref.loc;
        if (at.col > 0) at.col += static_cast<int>(ref.name.size()) + 1;
        int64_t i = Expr::parse(ref.index, at).eval(env_);
        pre.insert(factOrFail(indexed(ref.name, i), ref.loc, "needs"));
      }
    }
    if (pre.count(act.add))
      throw InputError(rule.producesLoc, fmt::format("rule '{}' needs its own product '{}'", rule.name, rule.produces));
    act.pre.assign(pre.begin(), pre.end());
    // `cost: auto` is measured before instantiation (analysis/cost.h resolveAutoCosts).
    if (rule.costAuto && rule.cost.empty())
      throw InputError(rule.loc, fmt::format("rule '{}': 'cost: auto' must be resolved before instantiation "
                                             "(resolveAutoCosts measures its snippet)",
                                             rule.name));
    act.cost = rule.cost.eval(env_);
    if (act.cost < 0) throw InputError(rule.loc, fmt::format("rule '{}' has negative cost {}", rule.name, act.cost));
    // Above this, sums of costs could reach the search's "infinite" and plans would be lost.
    if (act.cost > kMaxRuleCost)
      throw InputError(rule.loc, fmt::format("rule '{}' has cost {}, above the limit of {}", rule.name, act.cost,
                                             kMaxRuleCost));

    SnippetContext ctx;
    ctx.rigEnv = env_;
    ctx.outText = factRef(act.add);
    ctx.semantic = [&](const std::string& name, int64_t idx, const SourceLoc& at, std::string& text) {
      bool family = families_.count(name) != 0;
      if (!family && !index_.count(name)) {
        if (idx >= 0) return false;
        throw InputError(at, fmt::format("rule '{}' uses unknown semantic '{}'", rule.name, name));
      }
      if (family && idx < 0)
        throw InputError(at, fmt::format("'{}' is an indexed family: write ${{{}[i]}}", name, name));
      std::string full = family ? indexed(name, idx) : name;
      int f = factOrFail(full, at, "snippet uses");
      if (f == act.add) {
        text = factRef(f);
        return true;
      }
      if (!pre.count(f))
        throw InputError(at, fmt::format("rule '{}' uses '{}' but does not list it in 'needs'", rule.name, full));
      text = factRef(f);
      return true;
    };
    for (auto& l : expandSnippet(rule.glsl, ctx)) act.code.push_back(CodeLine{std::move(l.text), l.loc});
    if (p_.facts[act.add].source != Fact::Source::Computed) {
      p_.skippedRules.emplace_back(r, fmt::format("'{}' is provided by the rig", rule.produces));
      return;
    }
    p_.actions.push_back(std::move(act));
  }

  const Rig& rig_;
  const RuleSet& rules_;
  ExprEnv env_;
  Problem p_;
  std::map<std::string, int> index_;
  std::map<std::string, int64_t> families_;
  std::set<std::string> provided_;
};

}  // namespace

Problem buildProblem(const Rig& rig, const RuleSet& rules, const std::vector<Varying>& varyings) {
  return Builder(rig, rules).build(varyings);
}

Problem withoutRules(const Problem& p, const std::vector<std::string>& ruleNames) {
  Problem q = p;
  q.actions.clear();
  for (const auto& a : p.actions)
    if (std::find(ruleNames.begin(), ruleNames.end(), a.name) == ruleNames.end()) q.actions.push_back(a);
  return q;
}

}  // namespace sg

// The search problem of a rig: facts, the rig's inputs, and the rules instantiated
// through rules/instantiate.h (docs/rules-format.md, "Instantiation").
#include "search/problem.h"

#include <fmt/format.h>

#include <algorithm>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>

#include "interface/fragment_interface.h"
#include "rig/packed_fields.h"
#include "rig/rig.h"
#include "rules/rules.h"
#include "rules/instantiate.h"
#include "search/plan.h"

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

const char* termName(int term) {
  static const char* const names[kTermCount] = {"arithmetic",   "locations",  "attribute_bytes",
                                                "buffer_bytes", "buffer_loads", "indexed_uniform_loads",
                                                "buffer_vec4_loads", "indexed_uniform_vec4_loads",
                                                "outputs",      "vertices",     "fragments",
                                                "buffer_table_loads", "buffer_table_vec4_loads"};
  return term >= 0 && term < kTermCount ? names[term] : "?";
}

int termByName(const std::string& name) {
  for (int t = 0; t < kTermCount; ++t)
    if (name == termName(t)) return t;
  return -1;
}

int64_t weighTerms(const TermWeights& w, const TermAmounts& a) {
  // Saturates far below INT64_MAX so that sums of a plan's costs cannot overflow either.
  constexpr int64_t kCap = INT64_MAX / 1024;
  int64_t sum = 0;
  for (int t = 0; t < kTermCount; ++t) {
    int64_t x = 0;
    if (__builtin_mul_overflow(w[t], a[t], &x) || __builtin_add_overflow(sum, x, &sum) || sum > kCap) return kCap;
  }
  return sum;
}

Problem inputsAsFacts(const Problem& p) {
  Problem q = p;
  std::vector<bool> isInit(p.facts.size(), false), passThrough(p.resources.size(), false);
  for (int f : p.init) isInit[f] = true;
  for (int g : p.goals)
    if (isInit[g] && p.facts[g].resource >= 0) passThrough[p.facts[g].resource] = true;
  std::vector<int> factOf(p.resources.size(), -1);
  for (size_t r = 0; r < p.resources.size(); ++r) {
    if (p.resources[r].cost <= 0) continue;
    if (passThrough[r]) {  // read by every plan
      q.fixedCost += p.resources[r].cost;
      for (size_t t = 0; t < kTermCount; ++t) q.fixedTerms[t] += p.resources[r].terms[t];
      q.resources[r].cost = 0;
      q.resources[r].terms = {};
      continue;
    }
    factOf[r] = static_cast<int>(q.facts.size());
    Fact f;
    f.name = "read " + p.resources[r].name;
    q.facts.push_back(f);
    Action a;
    a.name = f.name;
    a.add = factOf[r];
    a.cost = p.resources[r].cost;
    a.terms = p.resources[r].terms;
    q.actions.push_back(std::move(a));
    q.resources[r].cost = 0;  // paid by its action now
    q.resources[r].terms = {};
  }
  for (size_t a = 0; a < p.actions.size(); ++a) {
    std::vector<int>& pre = q.actions[a].pre;
    for (int f : p.actions[a].pre)
      if (int r = p.facts[f].resource; r >= 0 && factOf[r] >= 0) pre.push_back(factOf[r]);
    std::sort(pre.begin(), pre.end());
    pre.erase(std::unique(pre.begin(), pre.end()), pre.end());
  }
  return q;
}

Plan planOnInputs(const Problem& p, const Plan& onFacts) {
  std::vector<int> actions;
  for (int a : onFacts.actions)
    if (a < static_cast<int>(p.actions.size())) actions.push_back(a);
  return tidyPlan(p, actions);
}

int vertexInputLocations(Type t) { return t == Type::Mat4 ? 4 : t == Type::Mat3 ? 3 : 1; }

int Problem::findFact(const std::string& name) const {
  for (size_t i = 0; i < facts.size(); ++i)
    if (facts[i].name == name) return static_cast<int>(i);
  return -1;
}

namespace {

// Facts for every declared semantic instance, the rig's attributes and uniforms bound to
// them, then one action per applicable rule (rules/instantiate.h does the resolving).
class Builder {
 public:
  Builder(const Rig& rig, const RuleSet& rules) : rig_(rig), rules_(rules), shape_(shapeOfRig(rig, rules)) {}

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
    p_.fixedTerms[kTermVertices] = 1;
    p_.fixedTerms[kTermFragments] = 1;
    for (const auto& v : varyings) p_.fixedTerms[kTermOutputs] += int64_t{componentCount(v.type)} * std::max(1, v.arraySize);
    priceProblem(p_, kSlotWeights);
    setDeviceLimits(p_, kVulkanMinVertexAttributes, kVulkanMinUniformBytes, kVulkanMinStorageBuffers);
    return std::move(p_);
  }

 private:
  void declareFacts() {
    for (const auto& d : rules_.semantics) {
      Fact f;
      f.type = d.type;
      if (auto a = shape_.arrays.find(d.name); a != shape_.arrays.end()) f.arraySize = static_cast<int>(rig_.param(d.arrayParam));
      auto fam = shape_.families.find(d.name);
      if (fam == shape_.families.end()) {
        f.name = d.name;
        add(f);
        continue;
      }
      for (int64_t i = 0; i < fam->second; ++i) {
        f.name = indexedName(d.name, i);
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
    if (auto fam = shape_.families.find(base); fam != shape_.families.end())
      throw InputError(at, fmt::format("{} '{}': index {} is out of range (the rig has {} instances)", who, name, i,
                                       fam->second));
    throw InputError(at, fmt::format("{} unknown semantic '{}' (not declared in the rules){}", who, name,
                                     didYouMeanSemantic(rules_, name)));
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
    p_.init.push_back(f);
  }

  void provideFromRig() {
    for (size_t a = 0; a < rig_.attributes.size(); ++a) {
      const RigAttribute& attr = rig_.attributes[a];
      if (!attr.fields.empty()) {
        provideFields(static_cast<int>(a));
        continue;
      }
      int targets = attr.perMorphTarget ? rig_.morphTargets() : 1;
      for (int t = 0; t < targets; ++t)
        for (const auto& part : attr.provides) {
          std::string name = attr.perMorphTarget ? indexedName(part.semantic, t) : part.semantic;
          int n = part.swizzle.empty() ? componentCount(attr.shaderType) : static_cast<int>(part.swizzle.size());
          std::optional<Type> have = vectorType(scalarKind(attr.shaderType), n);
          if (!have)  // e.g. "xy" of a uint8x4: there is no uvec2 type
            throw InputError(attr.loc, fmt::format("attribute '{}' provides '{}' through swizzle '{}': {} components of "
                                                   "{} have no supported type",
                                                   attr.name, name, part.swizzle, n, glslName(attr.shaderType)));
          int f = factOrFail(name, attr.loc, fmt::format("attribute '{}' provides", attr.name).c_str());
          provide(f, Fact::Source::Attribute, static_cast<int>(a), attr.perMorphTarget ? t : -1, part.swizzle, *have,
                  attr.loc);
          const int item = resourceFor(attr.perMorphTarget ? fmt::format("attribute a_{}{}", attr.name, t)
                                                           : "attribute a_" + attr.name,
                                       kLimitAttributes, 1);
          p_.facts[f].resource = item;
          p_.resources[item].terms[kTermLocations] = vertexInputLocations(attr.shaderType);
          p_.resources[item].terms[kTermAttributeBytes] = formatBytes(attr.format);
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
      p_.facts[f].resource = resourceFor("uniform u_" + un.name, kLimitUniformBytes, std140Bytes(un.type, un.arraySize));
    }
    for (const auto& d : rules_.semantics)
      if (!d.bufferOf.empty()) provideBuffer(d);
  }

  // A bit-packed attribute (rig/packed_fields.h): its words are a fact of their own, read
  // (its location and bytes paid once) by one unpack action per part, which costs the
  // part's unpack arithmetic. So the search weighs the unpacking of each value it reads.
  void provideFields(int a) {
    const RigAttribute& attr = rig_.attributes[static_cast<size_t>(a)];
    const std::string input = "a_" + attr.name;
    Fact w;
    w.name = "attribute " + input;  // not a semantic name: no rule can read it
    w.type = attr.shaderType;
    const int words = static_cast<int>(p_.facts.size());
    p_.facts.push_back(w);
    provide(words, Fact::Source::Attribute, a, -1, "", attr.shaderType, attr.loc);
    const int item = resourceFor("attribute " + input, kLimitAttributes, 1);
    p_.facts[words].resource = item;
    p_.resources[item].terms[kTermLocations] = vertexInputLocations(attr.shaderType);
    p_.resources[item].terms[kTermAttributeBytes] = formatBytes(attr.format);
    for (const auto& part : attr.provides) {
      const PackedField& field = attr.fields[static_cast<size_t>(part.field)];
      const int n = part.swizzle.empty() ? formatComponents(field.format) : static_cast<int>(part.swizzle.size());
      const std::optional<Type> have = vectorType(formatIsInteger(field.format) ? ScalarKind::UInt : ScalarKind::Float, n);
      if (!have)
        throw InputError(field.loc, fmt::format("attribute '{}' provides '{}' through swizzle '{}' of a {} field: {} "
                                                "components have no supported type",
                                                attr.name, part.semantic, part.swizzle, formatName(field.format), n));
      const int f = factOrFail(part.semantic, field.loc, fmt::format("attribute '{}' provides", attr.name).c_str());
      if (p_.facts[f].type != *have)
        throw InputError(field.loc, fmt::format("'{}' is {} in the rules but the rig provides {}", part.semantic,
                                                glslName(p_.facts[f].type), glslName(*have)));
      const FieldUnpack u = unpackField(field, part.swizzle, factRef(words), componentCount(attr.shaderType));
      Action act;
      act.name = fmt::format("unpack_{}.{}", attr.name, part.semantic);
      act.pre = {words};
      act.add = f;
      act.cost = act.terms[kTermArithmetic] = u.slots;
      act.code.push_back(CodeLine{factRef(f) + " = " + u.glsl + ";", field.loc});
      p_.actions.push_back(std::move(act));
      unpacked_.insert(f);
    }
  }

  // A `buffer_of:` semantic is provided when the rig provides every instance of what it
  // packs: families of attributes (per-vertex buffers) or one uniform array (a palette).
  void provideBuffer(const SemanticDecl& d) {
    BufferSource b;
    b.fact = index_.at(d.name);
    const ScalarKind kind = scalarKind(d.type);
    int components = 0;
    for (const auto& name : d.bufferOf) {
      const SemanticDecl* src = rules_.findSemantic(name);
      if (!src) throw InputError(d.loc, fmt::format("semantic '{}': buffer_of names unknown semantic '{}'", d.name, name));
      if (scalarKind(src->type) != kind)
        throw InputError(d.loc, fmt::format("semantic '{}' is {} but '{}' is {}", d.name, glslName(d.type), name,
                                            glslName(src->type)));
      if (!src->arrayParam.empty()) {  // a uniform array
        if (d.bufferOf.size() != 1 || src->type != d.type)
          throw InputError(d.loc, fmt::format("semantic '{}': a buffer of uniform array '{}' holds only it, as {}",
                                              d.name, name, glslName(src->type)));
        int f = index_.at(name);
        if (p_.facts[f].source != Fact::Source::Uniform) return;
        b.kind = BufferSource::Kind::Array;
        b.uniform = p_.facts[f].rigIndex;
        b.count = p_.facts[f].arraySize;
        b.element = d.type;
        break;
      }
      auto fam = shape_.families.find(name);
      if (fam == shape_.families.end())
        throw InputError(d.loc, fmt::format("semantic '{}': buffer_of '{}' is neither a family (count:) nor a "
                                            "uniform array", d.name, name));
      if (!b.parts.empty() && fam->second != b.count)
        throw InputError(d.loc, fmt::format("semantic '{}': families '{}' and '{}' have different counts", d.name,
                                            b.parts[0].family, name));
      b.count = fam->second;
      BufferSource::Part part{name, componentCount(src->type), components, {}};
      for (int64_t i = 0; i < fam->second; ++i) {
        int f = index_.at(indexedName(name, i));
        if (p_.facts[f].source != Fact::Source::Attribute) return;  // the rig lacks an instance
        part.facts.push_back(f);
      }
      components += part.components;
      b.parts.push_back(std::move(part));
    }
    if (b.kind == BufferSource::Kind::PerVertex) {
      if (components != componentCount(d.type))
        throw InputError(d.loc, fmt::format("semantic '{}' is {} but buffer_of packs {} components", d.name,
                                            glslName(d.type), components));
      if (b.count == 0) return;
      b.element = kind == ScalarKind::UInt ? Type::UVec4 : kind == ScalarKind::Int ? Type::IVec4 : Type::Vec4;
      // Tight floats for vec3/vec2/float: a 52-target face at 180k vertices must stay
      // within maxStorageBufferRange (2^27 bytes guaranteed).
      if (kind == ScalarKind::Float && components < 4) b.element = Type::Float;
      b.components = b.element == Type::Float ? components : 4;
      b.strideBytes = 4 * b.components;
    } else {
      b.components = 16;
      b.strideBytes = 64;
    }
    Fact& fact = p_.facts[b.fact];
    if (b.kind == BufferSource::Kind::PerVertex && b.element == Type::Float && components == 4) b.element = Type::Vec4;
    fact.source = Fact::Source::Buffer;
    fact.rigIndex = static_cast<int>(p_.buffers.size());
    fact.resource = resourceFor("storage buffer " + d.name, kLimitStorageBuffers, 1);
    p_.init.push_back(b.fact);
    p_.buffers.push_back(std::move(b));
  }

  int resourceFor(const std::string& name, int limit, int64_t amount) {
    for (size_t i = 0; i < p_.resources.size(); ++i)
      if (p_.resources[i].name == name) return static_cast<int>(i);
    p_.resources.push_back(ResourceItem{name, limit, amount});
    return static_cast<int>(p_.resources.size()) - 1;
  }

  // Bytes a uniform adds to a std140 block, rounded up to 16: exact for arrays and
  // matrices (their std140 stride is a multiple of 16), an over-estimate by at most 12
  // bytes for a lone scalar or vector that could pack after another member. Additive, so
  // the search and the integer program can sum it (docs/search.md).
  static int64_t std140Bytes(Type t, int arraySize) {
    int64_t element = t == Type::Mat4 ? 64 : t == Type::Mat3 ? 48 : 16;
    return element * std::max(1, arraySize);
  }

  void instantiate(int r) {
    const Rule& rule = rules_.rules[r];
    if (!ruleApplies(rule, shape_)) {
      p_.skippedRules.emplace_back(r, fmt::format("when '{}' is false for rig '{}'", rule.when.text(), rig_.name));
      return;
    }
    Action act;
    act.name = rule.name;
    act.rule = r;
    auto product = index_.find(rule.produces);
    RuleInstance inst = instantiateRule(rules_, r, shape_, product == index_.end() ? "" : factRef(product->second),
                                        [&](const std::string& instance) { return factRef(index_.at(instance)); });
    act.add = product->second;  // instantiateRule checked the product is a declared single semantic
    for (const auto& n : inst.needs) act.pre.push_back(index_.at(n));
    std::sort(act.pre.begin(), act.pre.end());
    // `cost: auto` is measured before instantiation (analysis/cost.h resolveAutoCosts).
    act.cost = ruleCost(rule, shape_);
    act.terms[kTermArithmetic] = act.cost;
    for (auto& l : inst.code) act.code.push_back(CodeLine{std::move(l.text), l.loc});
    if (p_.facts[act.add].source != Fact::Source::Computed || unpacked_.count(act.add)) {
      p_.skippedRules.emplace_back(r, fmt::format("'{}' is provided by the rig", rule.produces));
      return;
    }
    p_.actions.push_back(std::move(act));
  }

  const Rig& rig_;
  const RuleSet& rules_;
  RigShape shape_;
  Problem p_;
  std::map<std::string, int> index_;
  std::set<int> unpacked_;  // facts a bit-packed attribute's field provides
};

}  // namespace

Problem buildProblem(const Rig& rig, const RuleSet& rules, const std::vector<Varying>& varyings) {
  Problem p = Builder(rig, rules).build(varyings);
  p.withheld = rig.withheld;
  return p;
}

void setDeviceLimits(Problem& p, int64_t maxAttributes, int64_t maxUniformBytes, int64_t maxStorageBuffers) {
  p.limits.assign(3, ResourceLimit{});
  p.limits[kLimitStorageBuffers] =
      ResourceLimit{"storage buffers", "maxPerStageDescriptorStorageBuffers", maxStorageBuffers};
  p.limits[kLimitAttributes] = ResourceLimit{"vertex input attributes", "--max-attributes", maxAttributes};
  p.limits[kLimitUniformBytes] =
      ResourceLimit{"uniform block bytes (std140, members rounded to 16)", "maxUniformBufferRange", maxUniformBytes};
}

void dropOversizedBuffers(Problem& p, int64_t maxVertices, int64_t maxBytes) {
  if (maxVertices <= 0) return;
  for (auto& b : p.buffers) {
    if (b.kind != BufferSource::Kind::PerVertex) continue;
    // Checked in long double: vertices x count x stride can pass 2^63 for hostile options.
    long double bytes = static_cast<long double>(maxVertices) * b.count * b.strideBytes;
    if (bytes <= static_cast<long double>(maxBytes)) continue;
    b.oversize = fmt::format("{:.0f} bytes for {} vertices, over the {} bytes of maxStorageBufferRange",
                             static_cast<double>(bytes), maxVertices, maxBytes);
    p.facts[b.fact].source = Fact::Source::Computed;
    p.init.erase(std::remove(p.init.begin(), p.init.end(), b.fact), p.init.end());
  }
}

std::vector<int> itemsRead(const Problem& p, const std::vector<int>& actions) {
  std::vector<bool> seen(p.resources.size(), false);
  auto read = [&](int f) {
    if (int r = p.facts[f].resource; r >= 0) seen[r] = true;
  };
  for (int a : actions)
    for (int q : p.actions[a].pre) read(q);
  for (int g : p.goals) read(g);
  std::vector<int> items;
  for (size_t r = 0; r < seen.size(); ++r)
    if (seen[r]) items.push_back(static_cast<int>(r));
  return items;
}

std::vector<int64_t> resourceUsage(const Problem& p, const std::vector<int>& actions) {
  std::vector<int64_t> usage(p.limits.size(), 0);
  for (int r : itemsRead(p, actions))
    if (static_cast<size_t>(p.resources[r].limit) < usage.size()) usage[p.resources[r].limit] += p.resources[r].amount;
  return usage;
}

void priceProblem(Problem& p, const TermWeights& w) {
  p.weights = w;
  p.componentWeights.clear();
  for (auto& a : p.actions) a.cost = weighTerms(w, a.terms);
  for (auto& r : p.resources) r.cost = weighTerms(w, r.terms);
  p.fixedCost = weighTerms(w, p.fixedTerms);
}

void priceProblemByMax(Problem& p, const std::vector<TermWeights>& components) {
  if (components.empty()) throw std::invalid_argument("priceProblemByMax: no components");
  if (components.size() == 1) return priceProblem(p, components[0]);
  auto largest = [&](const TermAmounts& a) {
    int64_t m = 0;
    for (const TermWeights& w : components) m = std::max(m, weighTerms(w, a));
    return m;
  };
  p.weights = components[0];
  p.componentWeights = components;
  for (auto& a : p.actions) a.cost = largest(a.terms);
  for (auto& r : p.resources) r.cost = largest(r.terms);
  p.fixedCost = largest(p.fixedTerms);
}

TermAmounts planAmounts(const Problem& p, const std::vector<int>& actions) {
  TermAmounts a = p.fixedTerms;
  auto add = [&](const TermAmounts& x) {
    for (size_t t = 0; t < kTermCount; ++t) a[t] += x[t];
  };
  for (int act : actions) add(p.actions[static_cast<size_t>(act)].terms);
  for (int r : itemsRead(p, actions)) add(p.resources[static_cast<size_t>(r)].terms);
  return a;
}

std::vector<int64_t> componentCosts(const Problem& p, const TermAmounts& amounts) {
  if (p.componentWeights.empty()) return {weighTerms(p.weights, amounts)};
  std::vector<int64_t> out;
  for (const TermWeights& w : p.componentWeights) out.push_back(weighTerms(w, amounts));
  return out;
}

int64_t weighPlan(const Problem& p, const TermAmounts& amounts) {
  const std::vector<int64_t> c = componentCosts(p, amounts);
  return *std::max_element(c.begin(), c.end());
}

bool hasItemCosts(const Problem& p) {
  return std::any_of(p.resources.begin(), p.resources.end(), [](const ResourceItem& r) { return r.cost > 0; });
}

int exceededLimit(const Problem& p, const std::vector<int64_t>& usage) {
  for (size_t l = 0; l < p.limits.size() && l < usage.size(); ++l)
    if (usage[l] > p.limits[l].max) return static_cast<int>(l);
  return -1;
}

std::string describeExceeded(const Problem& p, const std::vector<int64_t>& usage, int limit) {
  const ResourceLimit& l = p.limits[limit];
  return fmt::format("{} {}, above the limit of {} ({})", usage[limit], l.what, l.max, l.option);
}

Problem withoutRules(const Problem& p, const std::vector<std::string>& ruleNames) {
  Problem q = p;
  q.actions.clear();
  for (const auto& a : p.actions)
    if (std::find(ruleNames.begin(), ruleNames.end(), a.name) == ruleNames.end()) q.actions.push_back(a);
  return q;
}

}  // namespace sg

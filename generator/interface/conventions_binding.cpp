// Naming conventions applied to fragment inputs (fragment_interface.h, matchConvention).
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>

#include "interface/fragment_interface.h"
#include "rules/rules.h"

namespace sg {

void checkConventionNames(const RuleSet& rules, const std::vector<std::string>& conventions) {
  for (const auto& name : conventions) {
    if (name == "none" && conventions.size() == 1) continue;
    if (name == "none")
      throw InputError(SourceLoc{}, "--conventions none cannot be combined with other conventions");
    if (!rules.findConvention(name)) {
      std::string known;
      for (const auto& c : rules.conventions) known += (known.empty() ? "" : ", ") + c.name;
      throw InputError(SourceLoc{}, fmt::format("--conventions {}: no convention of that name in the rules files "
                                                "(known: {})",
                                                name, known.empty() ? "none" : known));
    }
  }
}

ConventionMatch matchConvention(const RuleSet& rules, const std::string& name, Type type, int arraySize,
                                const std::vector<std::string>& conventions) {
  ConventionMatch m;
  if (conventions.size() == 1 && conventions[0] == "none") return m;
  std::vector<const NamingConvention*> order;
  if (conventions.empty()) {
    for (const auto& c : rules.conventions) order.push_back(&c);
  } else {
    for (const auto& n : conventions)
      if (const NamingConvention* c = rules.findConvention(n)) order.push_back(c);
  }
  std::string typeName(glslName(type));
  if (arraySize) typeName += fmt::format("[{}]", arraySize);
  struct Hit {
    const NamingConvention* convention;
    const ConventionEntry* entry;
  };
  std::vector<Hit> hits;
  for (const NamingConvention* c : order) {
    std::vector<std::string> otherTypes;
    const ConventionEntry* found = nullptr;
    for (const auto& e : c->entries) {
      if (e.name != name) continue;
      if (!arraySize && (e.type.empty() || e.type == typeName)) found = &e;
      else otherTypes.push_back(e.type.empty() ? "non-array" : e.type);
    }
    if (found) hits.push_back(Hit{c, found});
    else if (!otherTypes.empty())
      m.notes.push_back(fmt::format("convention '{}' maps '{}' only as {}", c->name, name,
                                    fmt::join(otherTypes, " or ")));
  }
  if (hits.empty()) return m;
  auto sems = [](const Hit& h) { return fmt::format("{}", fmt::join(h.entry->semantics, ", ")); };
  if (!conventions.empty()) {  // chosen: the first wins
    m.semantics = hits[0].entry->semantics;
    m.convention = hits[0].convention->name;
    m.loc = hits[0].entry->loc;
    return m;
  }
  bool agree = std::all_of(hits.begin(), hits.end(),
                           [&](const Hit& h) { return h.entry->semantics == hits[0].entry->semantics; });
  if (!agree) {
    std::string meanings;
    for (const auto& h : hits) meanings += fmt::format("{}{} in '{}'", meanings.empty() ? "" : ", ", sems(h), h.convention->name);
    m.notes.push_back(fmt::format("'{}' is ambiguous across naming conventions ({}); choose one with --conventions NAME",
                                  name, meanings));
    return m;
  }
  m.semantics = hits[0].entry->semantics;
  for (const auto& h : hits) m.convention += (m.convention.empty() ? "" : "/") + h.convention->name;
  m.loc = hits[0].entry->loc;
  return m;
}

}  // namespace sg

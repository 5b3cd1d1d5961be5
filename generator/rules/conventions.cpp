// `conventions:` sections of rules files and rule overrides (loader_parts.h).
#include <fmt/format.h>

#include <algorithm>

#include "common/types.h"
#include "rules/loader_parts.h"

namespace sg {

const NamingConvention* RuleSet::findConvention(const std::string& name) const {
  for (const auto& c : conventions)
    if (c.name == name) return &c;
  return nullptr;
}

namespace {

std::vector<std::string> semanticList(const YamlCtx& y, const YAML::Node& n, const std::string& varying) {
  std::vector<std::string> out;
  if (n.IsScalar()) {
    out.push_back(n.Scalar());
  } else {
    y.expectSeq(n, "a semantic or a list of semantics");
    for (const auto& s : n) out.push_back(y.scalar(s, "a semantic name"));
    if (out.empty()) y.fail(n, fmt::format("'{}' maps to no semantic", varying));
  }
  return out;
}

}  // namespace

void loadConventions(RuleSet& set, const YamlCtx& y, const YAML::Node& section) {
  y.expectMap(section, "'conventions'");
  for (auto it = section.begin(); it != section.end(); ++it) {
    NamingConvention c;
    c.name = y.scalar(it->first, "a convention name");
    c.loc = locOf(it->first, y.file);
    if (c.name.empty() || c.name == "none" || c.name == "all")
      y.fail(it->first, fmt::format("'{}' cannot name a convention (reserved by --conventions)", c.name));
    if (const NamingConvention* prev = set.findConvention(c.name)) {
      if (prev->loc.file == c.loc.file && prev->loc.line == c.loc.line) continue;  // same file included twice
      y.fail(it->first, fmt::format("convention '{}' is defined twice (first at {}:{})", c.name, prev->loc.file,
                                    prev->loc.line));
    }
    YAML::Node body = it->second;  // a copy: it->second lives in a temporary proxy
    y.expectMap(body, "a convention");
    y.checkKeys(body, {"doc", "names"});
    if (body["doc"]) c.doc = y.scalar(body["doc"], "'doc'");
    if (!body["names"]) y.fail(body, fmt::format("convention '{}' has no 'names'", c.name));
    YAML::Node names = body["names"];
    y.expectMap(names, "'names'");
    for (auto n = names.begin(); n != names.end(); ++n) {
      std::string varying = y.scalar(n->first, "a varying name");
      SourceLoc at = locOf(n->first, y.file);
      for (const auto& e : c.entries)
        if (e.name == varying)
          y.fail(n->first, fmt::format("'{}' is named twice in convention '{}'", varying, c.name));
      YAML::Node value = n->second;
      if (value.IsMap()) {  // a meaning per input type: { vec2: uv0, vec4: [uv0, uv1] }
        for (auto t = value.begin(); t != value.end(); ++t) {
          std::string type = y.scalar(t->first, "a GLSL type");
          if (!parseType(type)) y.fail(t->first, fmt::format("unknown type '{}'", type));
          c.entries.push_back(ConventionEntry{varying, type, semanticList(y, t->second, varying), locOf(t->first, y.file)});
        }
      } else {
        c.entries.push_back(ConventionEntry{varying, "", semanticList(y, value, varying), at});
      }
    }
    set.conventions.push_back(std::move(c));
  }
}

void applyDisable(RuleSet& set, const YamlCtx& y, const YAML::Node& list) {
  y.expectSeq(list, "'disable' (a list of rule names)");
  for (const auto& n : list) {
    std::string name = y.scalar(n, "a rule name");
    auto it = std::find_if(set.rules.begin(), set.rules.end(), [&](const Rule& r) { return r.name == name; });
    if (it == set.rules.end()) {
      for (const auto& c : set.changes)
        if (c.rule == name && c.disabled)
          y.fail(n, fmt::format("disable: rule '{}' is already disabled (at {}:{})", name, c.loc.file, c.loc.line));
      y.fail(n, fmt::format("disable: no rule '{}' in the files loaded before this one", name));
    }
    set.changes.push_back(RuleChange{name, true, locOf(n, y.file), it->loc});
    set.rules.erase(it);
  }
}

void replaceRule(RuleSet& set, const YamlCtx& y, const YAML::Node& nameNode, size_t existing, Rule rule,
                 bool overrides) {
  Rule& old = set.rules[existing];
  if (!overrides)
    y.fail(nameNode, fmt::format("rule '{}' is defined twice (first at {}:{}); to replace it, add 'override: true'",
                                 rule.name, old.loc.file, old.loc.line));
  if (old.loc.file == rule.loc.file)
    y.fail(nameNode, fmt::format("rule '{}' overrides a rule of its own file (at {}:{}); edit that rule instead",
                                 rule.name, old.loc.file, old.loc.line));
  set.changes.push_back(RuleChange{rule.name, false, rule.loc, old.loc});
  old = std::move(rule);  // in place: rule order (and so the output) does not depend on who overrides
}

void failNothingToOverride(const RuleSet& set, const YamlCtx& y, const YAML::Node& nameNode, const std::string& rule) {
  for (const auto& c : set.changes)
    if (c.rule == rule && c.disabled)
      y.fail(nameNode, fmt::format("rule '{}' has 'override: true' but that rule was disabled at {}:{}", rule,
                                   c.loc.file, c.loc.line));
  y.fail(nameNode, fmt::format("rule '{}' has 'override: true' but no file loaded before this one defines a rule '{}'",
                               rule, rule));
}

}  // namespace sg

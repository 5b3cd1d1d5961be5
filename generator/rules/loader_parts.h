// Parts of the rules loader kept apart from rules_loader.cpp: naming conventions
// (`conventions:`) and rule overrides (`override: true`, `disable:`). Internal to rules/.
#pragma once
#include "common/yaml_util.h"
#include "rules/rules.h"

namespace sg {

// Reads a `conventions:` section: { name: { doc:, names: { varying: semantic | [packed] |
// { vec4: ..., vec2: ... } } } }.
void loadConventions(RuleSet& set, const YamlCtx& y, const YAML::Node& section);

// Applies a `disable: [rule names]` list: removes rules loaded before this file (its
// includes, or files named earlier on the command line).
void applyDisable(RuleSet& set, const YamlCtx& y, const YAML::Node& list);

// `rule` has the name of `set.rules[existing]`. With `override: true` (overrides) it
// replaces that rule in place; otherwise it is an error ("defined twice").
void replaceRule(RuleSet& set, const YamlCtx& y, const YAML::Node& nameNode, size_t existing, Rule rule,
                 bool overrides);
// `override: true` on a rule whose name no earlier rule has: an error.
[[noreturn]] void failNothingToOverride(const RuleSet& set, const YamlCtx& y, const YAML::Node& nameNode,
                                        const std::string& rule);

}  // namespace sg

// "Did you mean ...?" for fragment inputs that name no semantic: the declared semantics
// closest to the input's name (engine prefixes like v_, vertex_, out_ dropped, camelCase
// and snake_case split into words, common abbreviations expanded) and of a fitting type.
#pragma once
#include <string>
#include <vector>

#include "common/types.h"

namespace sg {

struct RuleSet;

// At most `limit` semantic names, best first; empty when nothing is close.
std::vector<std::string> closestSemantics(const RuleSet& rules, const std::string& inputName, Type type,
                                          size_t limit = 3);

// The words of a GLSL or semantic name, lower case, abbreviations expanded:
// "vWorldPos" -> {world, position}; "v_texcoord_0" -> {texcoord0}; "world.eye_dir" -> {world, eye, dir}.
std::vector<std::string> nameWords(const std::string& name, bool isSemantic);

}  // namespace sg

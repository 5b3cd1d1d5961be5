// Snippet templates: GLSL lines with `${...}` substitutions and line directives
//   @for VAR in COUNT   ...   @end     (VAR = 0 .. COUNT-1, unrolled)
//   @if COND   ...   [@else ...]   @end
// `${out}` is the rule's product, `${sem}` / `${sem[EXPR]}` a semantic, and any other
// `${EXPR}` an integer expression (loop variables, rig parameters).
#pragma once
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "rules/expr.h"
#include "rules/rules.h"

namespace sg {

// Limits of one unrolled snippet (docs/limits.md).
constexpr size_t kMaxSnippetLines = 16384;
constexpr size_t kMaxSnippetBytes = 1u << 20;
constexpr int64_t kMaxSnippetIterations = 1 << 20;

struct SnippetContext {
  ExprEnv rigEnv;  // rig parameters and has()
  // Resolves a semantic reference (name, evaluated index or -1) to replacement text.
  // Returns false if `name` is not a semantic (then ${...} is evaluated as an expression).
  std::function<bool(const std::string& name, int64_t index, const SourceLoc& at, std::string& text)> semantic;
  std::string outText;  // replacement for ${out}
};

struct ExpandedLine {
  std::string text;
  SourceLoc loc;
};

// Unrolls the template. Throws InputError located at the offending line/column.
std::vector<ExpandedLine> expandSnippet(const std::vector<TemplateLine>& lines, const SnippetContext& ctx);

}  // namespace sg

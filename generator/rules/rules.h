// A rules file: typed semantics, varying names, and rules that produce one semantic
// from others at a cost, under conditions on the rig, with a GLSL snippet template.
// Format: docs/rules-format.md.
#pragma once
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/diagnostics.h"
#include "common/types.h"
#include "rules/definition.h"
#include "rules/expr.h"

namespace sg {

// Limits (docs/limits.md). A rule's cost, once evaluated for a rig, must be 0..kMaxRuleCost:
// the search adds costs in 64 bits and keeps values near INT64_MAX/4 for "unreachable".
constexpr int64_t kMaxRuleCost = 1'000'000'000;
constexpr size_t kMaxRules = 10000;
constexpr size_t kMaxSemantics = 10000;
constexpr size_t kMaxIncludeDepth = 32;

struct SemanticDecl {
  std::string name;  // "world.normal"
  Type type = Type::Vec3;
  int arraySize = 0;       // uniform arrays (mat4[bones]): resolved against the rig, 0 = scalar
  std::string arrayParam;  // rig parameter giving the uniform array size
  Expr count;              // indexed family (morph.position[i]): instance count expression
  // `buffer_of:` (docs/buffers.md): this semantic is a storage buffer holding every instance
  // of these families (packed per element, in order) or of one uniform array; snippets
  // read it as a function, ${name}(i).
  std::vector<std::string> bufferOf;
  // `bound:` (docs/rules-format.md): a per-draw count whose largest value is this expression
  // over the rig's parameters (morph.active_count <= max_active_targets). The cost analysis
  // counts the loads of a loop it bounds once per iteration at that value. Null = none.
  Expr bound;
  std::string doc;
  SourceLoc loc;
  // What the value is (docs/validation.md, "Definitions"): a formula over other semantics,
  // evaluated by validate's reference interpreter. Null = no definition (outputs carrying it
  // are reported unchecked).
  DefNodeP definition;
  std::string definitionText;
  // Uniforms: how validation draws values (docs/validation.md, "Poses"): "" (by the
  // standard pose, or unknown), rigid, affine, projection, unit, point, weight, int.
  std::string kind;
  double rangeLo = 0, rangeHi = 1;  // weight / int / scalar kinds
  SourceLoc kindLoc;
};

// A reference to a semantic in `needs:`: "world.position", "morph.position[*]", "skin.joints[k/4]".
struct SemanticRef {
  std::string name;
  std::string index;  // "" none, "*" all instances, else an index expression
  SourceLoc loc;
};

// One line of a snippet template, with where it sits in the rules file.
struct TemplateLine {
  std::string text;
  SourceLoc loc;  // line and column of the first character of text
};

struct Rule {
  std::string name;
  std::string produces;
  std::vector<SemanticRef> needs;
  Expr when;            // empty = always
  Expr cost;            // evaluated against the rig
  bool costAuto = false;
  std::vector<TemplateLine> glsl;
  std::string doc;
  SourceLoc loc;         // the rule's 'name' key
  SourceLoc producesLoc;
};

// How a fragment input name maps to semantics: one, or several packed into a vector.
struct VaryingMapping {
  std::string name;
  std::vector<std::string> semantics;
  SourceLoc loc;
};

// A naming convention (`conventions:`, rules/conventions.yaml): the varying names one
// ecosystem (three.js, the glTF Sample Viewer, Filament...) gives to semantics.
struct ConventionEntry {
  std::string name;  // "vNormal"
  std::string type;  // "" = any input type, else the GLSL type this meaning applies to ("vec4")
  std::vector<std::string> semantics;  // one, or several packed in component order
  SourceLoc loc;
};
struct NamingConvention {
  std::string name;  // "threejs"
  std::string doc;
  std::vector<ConventionEntry> entries;
  SourceLoc loc;
};

// A shared snippet (`snippets:`, docs/rules-format.md "Shared snippets"): one computation's
// text that several rules insert with `@use name(arg, ...)` after fetching its inputs in
// their own way, so that a fix lands in every fetch form. Expanded when a rule loads.
struct SharedSnippet {
  std::string name;
  std::vector<std::string> params;  // ${param} in the text is replaced by the argument
  std::vector<TemplateLine> glsl;
  std::string doc;
  SourceLoc loc;
};

// A rule a later file replaced (`override: true`) or removed (`disable:`).
struct RuleChange {
  std::string rule;
  bool disabled = false;  // false: replaced
  SourceLoc loc;          // the overriding rule's name, or the `disable:` entry
  SourceLoc original;     // the rule it replaced or removed
};

struct RuleSet {
  std::vector<std::string> files;  // every file read (includes too), in load order
  std::vector<SemanticDecl> semantics;
  std::vector<Rule> rules;
  std::vector<VaryingMapping> varyings;
  std::vector<NamingConvention> conventions;
  std::vector<RuleChange> changes;  // overrides and disables, in load order
  std::vector<SharedSnippet> snippets;

  const SemanticDecl* findSemantic(const std::string& name) const;
  const VaryingMapping* findVarying(const std::string& name) const;
  const NamingConvention* findConvention(const std::string& name) const;
  const SharedSnippet* findSnippet(const std::string& name) const;
  const Rule* findRule(const std::string& name) const;  // nullptr: no rule of that name (a misspelt ban)
};

// Loads rule files (and their `include:`s, relative to the including file) into one set.
// Throws InputError: malformed YAML, unknown keys, duplicate names, bad types...
RuleSet loadRules(const std::vector<std::string>& paths);
void loadRulesInto(RuleSet& set, const std::string& path);
void loadRulesText(RuleSet& set, const std::string& text, const std::string& fileName);

}  // namespace sg

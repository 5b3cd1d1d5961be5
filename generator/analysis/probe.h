// Compiling one rule's snippet on its own: a tiny vertex shader that declares every
// semantic the rule needs as a uniform of its type and the product as a local, with
// the snippet instantiated against a rig. `check` uses it to find snippets that do
// not compile; `cost: auto` measures the compiled result (analysis/cost.h).
#pragma once
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "common/diagnostics.h"
#include "common/glsl_compile.h"
#include "rules/instantiate.h"
#include "rules/rules.h"

namespace sg {

struct Rig;

// What a snippet is instantiated against: the rig's shape (rules/instantiate.h), and
// how its attributes are read.
struct ProbeRig : RigShape {
  // Semantics a real rig stores in (part of) a vertex attribute: the probe declares the
  // attribute as a vertex input and reads the swizzle, as the emitted shader does (so
  // vec4(normal, occlusion) from one float4 attribute costs nothing). Others are uniforms.
  struct Stream {
    std::string input;  // GLSL input name, "a_normal" / "a_coord_morph3"
    Type type = Type::Vec4;
    std::string swizzle;  // "" = whole attribute
  };
  std::map<std::string, Stream> streams;
  // Semantics the rig provides in its uniform block: the same for every vertex of a draw.
  // Every other value a rule reads varies per vertex (an attribute, or another rule's product).
  std::set<std::string> uniforms;
  bool isDefault = false;
};

// The rig as a probe rig (families and arrays evaluated against its parameters).
// Throws InputError when a count expression cannot be evaluated.
ProbeRig probeRigFromRig(const Rig& rig, const RuleSet& rules);

// Rigs used when no rig is given: morph_targets=2, influences=4, bones=4 with every
// semantic no rule produces provided; then rigid (influences=1) and unskinned
// (influences=0) variants without morph targets, the last one providing only vertex
// streams. A rule is probed with the first whose `when` holds.
std::vector<ProbeRig> defaultProbeRigs(const RuleSet& rules);

// Expression environment of a probe rig (rig parameters and has()).
ExprEnv probeEnv(const ProbeRig& rig);

struct SnippetProbe {
  GlslUnit unit;  // the probe vertex shader; sourceFiles[0] is the rule's file
  std::vector<SourceLoc> snippetLines;  // where each emitted snippet line sits in the rules file
  std::string productType;  // GLSL type of the product
  SourceLoc end;  // just past the last snippet line's text (where a missing ';' is reported)
  std::vector<std::string> buffers;  // the storage buffers read: binding i + 1 holds buffers[i] (a fact name)
};

// Builds the probe shader for rules.rules[rule]. Throws InputError (located in the rules
// file) for template errors, unknown semantics and semantics used but not in `needs`.
// `forAccesses` (the probe analysis/cost.h counts memory accesses on): a semantic with a
// `bound:` (a per-draw count) is the constant of its bound, so a loop it limits has a constant
// trip count and its loads count per iteration at the most it can run; and a value that varies
// per vertex (neither a rig uniform nor a uniform array) is a vertex input, not a uniform, so an
// index computed from it is told from one that is the same for the whole draw.
SnippetProbe buildSnippetProbe(const RuleSet& rules, int rule, const ProbeRig& rig, bool forAccesses = false);

// Compiles the probe with glslang; diagnostics point at the rule's YAML lines (columns
// refined with refineSnippetColumns). Errors glslang reports after the snippet (a missing
// ';' or bracket shows up at the next token) point just past the snippet's last line.
CompileResult compileSnippetProbe(const SnippetProbe& probe, const Rule& rule);

// glslang reports lines only. For diagnostics on a snippet line (file and line in
// `snippetLines`), sets the column to the token the message quotes when it appears on
// that YAML line, else to the first character of the snippet text.
void refineSnippetColumns(std::vector<Diagnostic>& diags, const std::vector<SourceLoc>& snippetLines);
// The same error (primary and related diagnostics) with refineSnippetColumns applied.
InputError refineSnippetError(const InputError& e, const std::vector<SourceLoc>& snippetLines);

}  // namespace sg

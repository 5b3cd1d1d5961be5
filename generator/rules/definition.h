// Semantic definitions: the `definition:` formula of a semantic (docs/validation.md,
// "Definitions"), in a small expression language over other semantics. Parsed and type
// checked here (rules stage); evaluated by the reference interpreter (validate stage),
// never compiled into shaders.
//
// Language: numbers (1, 0.5, 1e-6), semantics (world.normal), rig parameters (influences),
// local names (let / sum variables); + - * / % with GLSL's vector/matrix rules; < <= > >=
// == != && || ! ; c ? a : b; swizzles (.xyz, .w, also on semantics: camera.view.xyz is
// not a swizzle of a mat4 and is refused); indexing (v[i], m[col], family[i], array[j]);
// calls: dot cross normalize length abs sign min max clamp sqrt inverse transpose
// determinant float mat3 mat4 vec2 vec3 vec4 has(semantic);
// sum(i, count, body) adds body for i = 0..count-1 (count: a rig-constant integer);
// let x = value; body.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "common/diagnostics.h"
#include "common/types.h"

namespace sg {

struct RuleSet;

constexpr size_t kMaxDefinitionChars = 4096;
constexpr int kMaxDefinitionDepth = 64;

enum class DefType { Bool, Int, Float, Vec2, Vec3, Vec4, Mat3, Mat4 };
const char* defTypeName(DefType t);
int defTypeComponents(DefType t);  // 1, 2, 3, 4, 9, 16
// How a declared semantic type is evaluated (integer vectors as Vec4, uint as Int).
DefType declType(Type t);

struct DefNode {
  enum Kind { Num, Name, Call, Unary, Binary, Ternary, Index, Swizzle, Sum, Let } kind = Num;
  std::string text;  // Name: the name; Call: the function; Unary/Binary: the operator;
                     // Swizzle: the letters; Sum/Let: the local variable
  double value = 0;
  bool integer = false;  // Num: written without '.' or exponent
  std::vector<std::shared_ptr<DefNode>> args;
  SourceLoc loc;
  // Filled by checkDefinitions:
  DefType type = DefType::Float;
  enum Ref { Unresolved, Semantic, Param, Local } ref = Unresolved;  // Name nodes
  int semantic = -1;  // Name (Semantic) and Call has(): index into RuleSet::semantics
  int depth = 1;
};
using DefNodeP = std::shared_ptr<DefNode>;

// Parses `text` (starting at `loc` in its file). Throws InputError located inside the text.
DefNodeP parseDefinition(const std::string& text, const SourceLoc& loc);
// Same, for text spread over several source lines (a folded YAML block): segment k starts at
// text offset segments[k].first, which sits at segments[k].second in the file.
DefNodeP parseDefinition(const std::string& text, const std::vector<std::pair<size_t, SourceLoc>>& segments);

// Resolves names and types of every definition in `set`: unknown semantics (with a
// did-you-mean), type errors, family/array misuse, cycles between definitions, a
// definition whose type differs from its semantic's. Throws InputError at the first error.
void checkDefinitions(RuleSet& set);

// Semantics a definition reads directly (indexes into RuleSet::semantics), sorted, unique.
std::vector<int> definitionReads(const DefNode& root);

}  // namespace sg

// Values of semantic definitions and the operations on them, in double precision with GLM.
// One implementation shared by the tree-walking interpreter (interpreter.cpp) and the
// compiled program (definition_program.cpp), which folds uniform-only parts with these and
// calls them per vertex for the rare operations it has no kernel for (inverse, determinant,
// a per-vertex index into a vector). docs/validation.md, "Definitions".
#pragma once
#include <glm/glm.hpp>

#include <cstdint>
#include <string>
#include <vector>

#include "rules/definition.h"
#include "rules/rules.h"
#include "runtime/mesh.h"
#include "validate/interpreter.h"

namespace sg::defval {

// Every value lives in a dmat4: scalars in [0][0], vectors in column 0, mat3 upper-left.
// Components past the type's are 0.
struct Val {
  DefType t = DefType::Float;
  glm::dmat4 m = glm::dmat4(0.0);
};

Val scalar(double x, DefType t = DefType::Float);
Val vec(const glm::dvec4& x, DefType t);
inline double s(const Val& v) { return v.m[0][0]; }
bool isMat(DefType t);
bool isScalar(DefType t);  // int, float or bool
DefType vecType(int n);

// Flat components (what outputs and uniforms hold): vectors in order, matrices column-major.
void flatten(const Val& v, double* out);
Val unflatten(DefType t, const double* in);
std::string showVal(const Val& v);  // "0.5" or "(1, 2, 3)"

// Errors in the data, located at the definition node: std::invalid_argument.
[[noreturn]] void fail(const DefNode& n, const std::string& msg);
// `x` as an integer index or count, or fail ("index 1.5 is not an integer").
int64_t integral(const DefNode& n, double x, const char* what);

// a op b for + - * / % with GLSL's vector and matrix rules (integer / and % truncate).
Val arith(const DefNode& n, const std::string& op, Val a, Val b);
// == != < > <= >= on scalars: a bool.
Val compare(const std::string& op, const Val& a, const Val& b);
// A call of node `n` (any function but has() and sum()) on evaluated arguments (at most 4).
Val call(const DefNode& n, Val* args, size_t count);
// b[i] for a vector (a float) or a matrix (a column); fails out of range.
Val element(const DefNode& n, const Val& b, int64_t i);
// b.xyz
Val swizzle(const std::string& letters, const Val& b);
// The component a swizzle letter selects (xyzw, rgba).
int swizzleComponent(char c);

// Where a provided semantic (element `index` of a family or uniform array, -1 for none)
// lives: a uniform's values from `offset`, a vertex stream, or neither. `error` is set for
// bad data (an index past a uniform array, a stream of the wrong length).
struct Source {
  const std::vector<double>* uniform = nullptr;
  size_t offset = 0;
  const std::vector<glm::vec4>* stream = nullptr;
  std::string name;   // "morph.position[2]"
  std::string error;  // unlocated message
  bool outOfRange = false;  // the error is an index past a uniform array (located at the index)
};
Source findSource(const RuleSet& rules, const rt::Mesh& mesh, const UniformValues& uniforms, int sem, int64_t index);
// The value of a stream at a vertex, typed as the semantic is declared.
Val streamValue(const glm::vec4& x, DefType t);

}  // namespace sg::defval

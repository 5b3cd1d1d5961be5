// The reference interpreter: evaluates the `definition:` formulas of semantics
// (rules/definition.h) on the CPU in double precision, per vertex of a mesh in a pose. It
// reads only definitions and the rig's data; it never compiles or runs a rule's GLSL, so
// agreement with a generated shader is evidence that the shader computes the defined value.
// evaluate() compiles the definitions into a flat program run on every core
// (validate/definition_program.h); the tree walker (evaluateByTree) is its oracle and
// reports errors and the inputs behind a NaN. docs/validation.md, "Definitions".
#pragma once
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "rules/instantiate.h"
#include "rules/rules.h"
#include "runtime/mesh.h"

namespace sg {

// Uniform values by semantic: flat column-major components (mat3: 9, mat4: 16), arrays
// element after element.
using UniformValues = std::map<std::string, std::vector<double>>;

// A semantic (or one it needs) has no definition and is not provided: the output is unchecked.
struct UndefinedSemantic : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The semantics `semantic`'s definition may read, directly or through other definitions, on
// any branch (families by their name), `semantic` included; nullopt if it is not declared.
std::optional<std::set<std::string>> definitionReadsOf(const RuleSet& rules, const std::string& semantic);

class Interpreter {
 public:
  // `shape`: rig parameters and provided instances (has()); `mesh`: per-vertex streams by
  // semantic; `uniforms`: the uniform values of the pose. All must outlive the interpreter.
  Interpreter(const RuleSet& rules, const RigShape& shape, const rt::Mesh& mesh, const UniformValues& uniforms);
  ~Interpreter();

  // "" if `semantic` can be evaluated, else why not ("'x' has no definition and the rig does
  // not provide it"). Throws std::invalid_argument for errors in the data (index out of range).
  std::string uncheckedReason(const std::string& semantic);

  // Values of each semantic at every vertex: result[s][v * n + c], n = components of
  // semantic s (vectors 1..4, mat3 9, mat4 16). Throws UndefinedSemantic,
  // std::invalid_argument (bad data: joint index out of range, missing rig parameter).
  // Semantics the requested ones share are computed once.
  std::vector<std::vector<double>> evaluate(const std::vector<std::string>& semantics);
  // evaluate(semantics) compiled once, to run again after the mesh's stream values change in
  // place (same vectors, same sizes): what finite differences of the reference need
  // (validate/float_check.h). Valid while this interpreter lives.
  std::function<std::vector<std::vector<double>>()> evaluator(const std::vector<std::string>& semantics);
  // The same, walking the definition trees vertex by vertex (the compiled program's oracle).
  std::vector<std::vector<double>> evaluateByTree(const std::vector<std::string>& semantics);
  // Threads evaluate() uses: 0 (the default) for every core. The values do not depend on it.
  void setThreads(unsigned threads);

  // A semantic that reads only uniforms (a normal matrix defined from model.matrix).
  std::vector<double> evaluateUniform(const std::string& semantic);

  // The provided values read to compute `semantic` at `vertex`, one "name = (x, y, z)" each,
  // in the order first read: what a NaN report shows.
  std::vector<std::string> inputsAt(const std::string& semantic, size_t vertex);

  int components(const std::string& semantic) const;

  struct State;

 private:
  std::unique_ptr<State> s_;
};

}  // namespace sg

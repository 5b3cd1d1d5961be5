// Semantic definitions compiled into a flat program (docs/validation.md, "Definitions"):
// what Interpreter::evaluate runs. The checked definition trees (rules/definition.h) of the
// requested semantics are compiled once per mesh and pose into instructions over typed
// registers, each holding one component for a batch of vertices; everything that does not
// depend on the vertex (uniforms, rig parameters, has(), products and inverses of uniform
// matrices) is evaluated while compiling, once. Sums are unrolled, lets and semantics
// referenced twice are registers computed once, swizzles and columns are views (no copy).
// The program runs the batches on every core, each writing its own rows of the output.
//
// Errors in the data (an index past the bone palette, an undefined semantic reached on some
// vertices) are checks in the program: a batch where one fails is handed back, and the
// caller evaluates it with the tree walker, which throws the error it always threw.
#pragma once
#include <memory>
#include <vector>

#include "validate/interpreter.h"

namespace sg {

class DefinitionProgram {
 public:
  static constexpr size_t kBatch = 64;  // vertices evaluated together

  // The program for `semantics` (indexes into rules.semantics). Null when the definitions
  // cannot be compiled: a sum whose count depends on the vertex, or too many instructions
  // (the tree walker evaluates those). All arguments must outlive the program.
  static std::unique_ptr<DefinitionProgram> compile(const RuleSet& rules, const RigShape& shape, const rt::Mesh& mesh,
                                                    const UniformValues& uniforms, const std::vector<int>& semantics);
  ~DefinitionProgram();

  // Evaluates every vertex into out[k][v * n + c] (n: components of semantic k; `out` sized
  // by the caller) on `threads` threads (0: every core); the values do not depend on the
  // thread count. Returns the batches, in increasing order, where a check failed: their
  // rows are not written.
  std::vector<size_t> run(std::vector<std::vector<double>>& out, unsigned threads) const;

  struct Stats {
    size_t instructions = 0;    // per batch of vertices
    size_t perVertexCalls = 0;  // operations evaluated vertex by vertex (inverse of a per-vertex matrix, ...)
    size_t checks = 0;          // instructions that can hand a batch back
    size_t constants = 0;       // doubles computed while compiling (uniform-only values, literals)
  };
  Stats stats() const;

  struct Impl;

 private:
  explicit DefinitionProgram(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> p_;
};

}  // namespace sg

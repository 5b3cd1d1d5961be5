// The independent CPU reference: every computed semantic of docs/semantics.md, written
// straight from its definition with plain GLM. It never reads a rules file and shares no
// code with the rules or the GLSL templates, so agreement between a generated shader and
// this file is evidence that the shader computes the documented value.
//
// Arithmetic is done in double precision and rounded to float at the end, so the reference
// is (much) closer to the exact value than any float GPU computation; tolerances in the
// validator therefore only need to cover the GPU's rounding.
#pragma once
#include "runtime/mesh.h"

#include <glm/glm.hpp>

#include <memory>
#include <string>
#include <vector>

namespace sg::rt {

// Per-vertex value of `semantic` (vocabulary of docs/semantics.md) for the mesh in the pose.
// Components beyond the semantic's size are 0; scalars in .x. mat4 semantics (skin.matrix,
// camera.view, ...) and arrays (morph.weights) are not per-vertex vectors and throw.
// Throws std::invalid_argument naming the semantic if it is unknown or if the mesh or pose
// lacks the data it needs (e.g. "world.normal needs vertex.normal, which mesh 'fox' does
// not have"), or if the data is inconsistent (stream length, joint index out of range).
//
// Besides the computed semantics, these are supported:
//   - any stream the mesh carries, by its own name ("vertex.texcoord0", "morph.normal[2]",
//     "skin.weights[0]", and unknown "vertex.*" attributes), returned as stored;
//   - "out.<name>": pass-through of "vertex.<name>" (docs/semantics.md, last row);
//   - "camera.position": the uniform, broadcast to every vertex.
// Morphing sums over the targets i < shape.morphTargets whose stream exists in the mesh
// (object.position uses morph.position[i], object.normal morph.normal[i], ...).
std::vector<glm::vec4> referenceValues(const std::string& semantic, const Mesh&, const Pose&,
                                       const RigShape&);

// True if referenceValues knows `semantic` (independent of any mesh: it may still throw for a
// mesh that lacks the data). False for unknown names and for mat4/array semantics.
bool isReferenceSemantic(const std::string& semantic);

// Number of meaningful components of `semantic` (1..4). Unknown "vertex.*" attributes report 4.
// Throws std::invalid_argument if !isReferenceSemantic(semantic).
int referenceComponents(const std::string& semantic);

// The same computation with intermediate per-vertex arrays (object/world frames, skin
// matrices) kept between calls, for evaluating several semantics of one mesh in one pose.
// The mesh and pose are referenced, not copied: they must outlive the evaluator and not change.
class ReferenceEvaluator {
 public:
  ReferenceEvaluator(const Mesh&, const Pose&, const RigShape&);
  ~ReferenceEvaluator();
  ReferenceEvaluator(const ReferenceEvaluator&) = delete;
  ReferenceEvaluator& operator=(const ReferenceEvaluator&) = delete;

  std::vector<glm::vec4> values(const std::string& semantic);

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace sg::rt

// The second check of a rig that stores encoded or quantized streams (issue 22): the device's
// outputs against the reference on the original float data, within tolerances derived from
// the stated worst errors of the formats and encodings by first-order error propagation
// through the reference, plus second-order terms. Derivation: docs/validation.md, "Against
// the float data".
#pragma once
#include <map>
#include <string>
#include <vector>

#include "runtime/mesh.h"
#include "validate/interpreter.h"
#include "validate/program_inputs.h"

namespace sg {

struct FloatReference {
  // Per requested semantic, values[s][v * n + c] as Interpreter::evaluate lays them out.
  std::vector<std::vector<double>> values;     // the reference on the float data
  std::vector<std::vector<double>> tolerance;  // how far storing the inputs may move each value
};

// The reference of `semantics` on `floatMesh` and, per value, the tolerance
//   sum over bounded inputs of |d value / d input| . bound  (a direction: |gradient| . radius)
//   + sum over inputs of |d2 value / d input2| . bound^2
//   + |f(x + c) + f(x - c) - 2 f(x)|, c the corner of the bounds where the first-order
//     change of that value is largest (the cross terms along it)
// with the derivatives from central differences of the reference: two evaluations per
// bounded input component, and two per component of each semantic. Where `stored` holds a
// bounded input as the device's data has it (quantizeForRig's values, at the same vertices),
// the tolerance is at least |f(stored) - f(x)|: the stored data is a point within the bounds,
// so what they allow reaches that far at least, and the sum above can fall short of it when an
// extremum lies inside a wide bound (1 - (n.v)^2 at a silhouette as a 2-bit weight rounds).
// A stored component outside its bound is not used (the check then fails as without it).
// One more evaluation. `floatMesh` is perturbed and restored in place.
FloatReference floatReference(const RuleSet& rules, const RigShape& shape, rt::Mesh& floatMesh,
                              const UniformValues& uniforms, const std::vector<InputErrorBound>& bounds,
                              const std::vector<std::string>& semantics,
                              const std::map<std::string, std::vector<glm::vec4>>& stored);

}  // namespace sg

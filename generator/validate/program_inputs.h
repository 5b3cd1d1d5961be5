// The data a generated program reads on a device, built from the plan (its emitted
// interface and reflection), the mesh and the pose in one place: vertex streams, the
// uniform block (with the sparse active-target list), storage buffers (per-vertex and
// palettes) and the descriptors the shader declares (rt::ProgramInputs). validate, render
// and bench feed programs only through programInputs/feedPose.
#pragma once
#include <cstdint>
#include <vector>

#include "pipeline/generate.h"
#include "runtime/mesh.h"
#include "runtime/vk_program.h"
#include "validate/interpreter.h"

namespace sg {

// Everything program `r` reads over `mesh` (already quantizeForRig'd) in `pose`: its vertex
// streams, storage buffers, uniform block and declared descriptors. Throws InputError when
// the mesh or pose lacks what the program reads.
rt::ProgramInputs programInputs(const GenerateResult& r, const rt::Mesh& mesh, const rt::Pose& pose);
// The per-vertex storage buffers program `r` reads over `mesh` (quantizeForRig'd): morph
// deltas, joints and weights, each element (v, i) at v * count + i (docs/buffers.md). The
// palettes follow the pose (feedPose) and are not among them.
std::vector<rt::StorageBufferData> perVertexBuffers(const GenerateResult& r, const rt::Mesh& mesh);
// Feeds `inputs` (built by programInputs for this mesh) for another pose: the uniform
// block and the palettes. Returns the uniform values it fed (the reference uses the same).
UniformValues feedPose(const GenerateResult& r, const rt::Mesh& mesh, const rt::Pose& pose, rt::ProgramInputs& inputs);

// A pose's uniform values by semantic: the pose's own, then those defined by a formula over
// them (a normal matrix), rounded to float as the GPU gets them.
UniformValues uniformValues(const Rig& rig, const RuleSet& rules, const RigShape& shape, const rt::Mesh& mesh,
                            const rt::Pose& pose);

// The descriptors of a shader's reflection, as the runtime checks them.
std::vector<rt::DescriptorBinding> declaredDescriptors(const std::vector<ShaderDescriptor>& reflected);

// The mesh with every integer/normalized stream rounded as its attribute format stores it
// (what the GPU reads back), so the reference sees exactly the GPU's values: encoded
// streams derived from their sources (and the sources replaced by their decodes), the
// mesh's bounds as uniforms, unorm skin weights rounded to sum to exactly one.
rt::Mesh quantizeForRig(const Rig& rig, const rt::Mesh& mesh);
// The components a widened attribute's format lacks (docs/rig-format.md, "Widened
// attributes") set in `mesh` as the device reads them, 0 and 1 for w, whatever the mesh held
// there. quantizeForRig does it; the float data of the second check needs it too: no stored
// value carries those components, so they have no error to bound.
void fillWidenedComponents(const Rig& rig, rt::Mesh& mesh);
// How far quantizeForRig(rig, mesh) may move one stream the reference reads, from the
// worst errors the formats (storedValueMaxError) and encodings (encodingMaxError) state:
// per vertex, component k by at most bound[v][k] (a box), or, for a unit vector
// (octahedral), xyz by at most bound[v].x in Euclidean distance (a ball). Streams stored
// exactly (float32, integers) have none. docs/validation.md, "Against the float data".
struct InputErrorBound {
  std::string semantic;  // "vertex.normal", "morph.position[2]"
  bool ball = false;
  std::vector<glm::dvec4> bound;
};
std::vector<InputErrorBound> quantizationErrorBounds(const Rig& rig, const rt::Mesh& mesh);
// The stream of one program input over `mesh` (quantizeForRig'd): the attribute's elements
// encoded in its format, tightly packed (the stride is the format's size).
rt::VertexStream vertexStream(const Rig& rig, const EmittedInput& in, const rt::Mesh& mesh);

}  // namespace sg

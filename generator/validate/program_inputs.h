// The data a generated program reads on a device, built from the plan (its emitted
// interface and reflection), the mesh and the pose in one place: vertex streams, the
// uniform block (with the sparse active-target list), storage buffers (per-vertex and
// palettes). validate, render and bench feed programs only through here.
#pragma once
#include <cstdint>
#include <vector>

#include "pipeline/generate.h"
#include "runtime/mesh.h"
#include "runtime/vk_harness.h"
#include "validate/interpreter.h"

namespace sg {

// The mesh with every integer/normalized stream rounded as its attribute format stores it
// (what the GPU reads back), so the reference sees exactly the GPU's values.
rt::Mesh quantizeForRig(const Rig& rig, const rt::Mesh& mesh);

// One input's vertex stream.
rt::VertexStream vertexStream(const Rig& rig, const EmittedInput& in, const rt::Mesh& mesh);

// The storage buffers a generated shader reads, filled from the mesh (per-vertex buffers,
// `perVertex`) or from the pose (palettes, !perVertex), in the layout of docs/buffers.md.
std::vector<rt::StorageBufferData> buildStorageBuffers(const Problem& p, const EmittedGlsl& glsl, const rt::Mesh& mesh,
                                                       const rt::Pose& pose, bool perVertex);

// The sparse-morph protocol (docs/buffers.md): the targets with a non-zero weight, in
// increasing order, and their count, for rigs that read them.
void addActiveTargets(const Rig& rig, const rt::Pose& pose, UniformValues& values);

// A pose's uniform values: the pose's own, then those defined by a formula over them (a
// normal matrix), rounded to float as the GPU gets them.
UniformValues uniformValues(const Rig& rig, const RuleSet& rules, const RigShape& shape, const rt::Mesh& mesh,
                            const rt::Pose& pose);

// The uniform block laid out as reflected, from values by semantic.
std::vector<uint8_t> buildUniforms(const Rig& rig, const EmittedGlsl& glsl, const SpirvModule& spv,
                                   const UniformValues& values);

// The uniform block for a pose (uniforms with a definition, such as a normal matrix,
// computed from the pose's).
std::vector<uint8_t> uniformBlock(const Rig& rig, const RuleSet& rules, const EmittedGlsl& glsl, const SpirvModule& spv,
                                  const rt::Mesh& mesh, const rt::Pose& pose);

}  // namespace sg

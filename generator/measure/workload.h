// The workload a program is priced for (search/workload.h, docs/device-profiles.md,
// "Workload"), measured from the mesh it will draw: a glTF rig's own primitive (its vertices,
// its index order, its skin's joint indices, its animations' morph weights), or a procedural
// mesh for a YAML rig (`--mesh`). The CLI and the measuring commands call this and pass the
// plain figures to the pipeline (GenerateOptions::workload); the pipeline never reads a mesh.
//
// - verticesPerDraw: the mesh's vertex count.
// - jointsPerWarp: the vertices in the order the index buffer first references them (the order
//   a GPU shades them; unreferenced vertices are never shaded and left out), cut into groups of
//   32 (a warp; the last group may be short). For each group and each influence slot, the
//   number of distinct joint indices among the group's vertices whose weight in that slot is
//   non-zero; the mean over the (group, slot) pairs that have at least one such vertex. So
//   1 <= jointsPerWarp <= min(32, joints of the skin); 0 when nothing is skinned.
// - paletteEntriesPerWarp: the same groups, the distinct joint indices over all their
//   weighted slots together (a warp's palette footprint); the mean over the groups that have
//   one. jointsPerWarp <= paletteEntriesPerWarp <= min(32 x slots, joints); 0 unskinned.
// - activeMorphTargets: the most morph targets with a non-zero weight at once: over every
//   animation that drives the primitive's mesh node, sampled at its keyframes and halfway
//   between them; else the node's or mesh's default weights. Procedural meshes have no
//   animation: unknown (-1), unless a caller knows the pose it draws (bench: the timed pose).
// - invocationsPerVertex: meshoptimizer's FIFO post-transform cache model
//   (meshopt_analyzeVertexCache) over the triangles in index order, with cache size 32, warp
//   32 and primitive group 32: the parameters meshoptimizer's own demo uses to model NVIDIA
//   hardware (32-entry cache, 32-thread warps), the device issue 33 measures. The figure is
//   vertices transformed over vertices referenced (1 = each shaded once). 0 (unknown) for
//   primitives that are not triangles or whose indices cannot be read.
#pragma once
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "render/render.h"
#include "rig/gltf_import.h"
#include "runtime/mesh.h"
#include "search/workload.h"

namespace sg {

constexpr uint32_t kWorkloadWarp = 32;          // vertices per group of jointsPerWarp
constexpr uint32_t kWorkloadCacheSize = 32;     // meshopt_analyzeVertexCache's cache_size
constexpr uint32_t kWorkloadCacheWarp = 32;     // its warp_size
constexpr uint32_t kWorkloadPrimGroup = 32;     // its primgroup_size

// The figures of one mesh: `indices` in draw order (empty: 0..vertexCount-1), a triangle list
// when `triangles` (else only the order is read). Influences come from the streams
// skin.joints[s] / skin.weights[s], the first `influences` slots (-1: all; a level-of-detail
// rig reads fewer than its mesh stores); indices past the mesh are ignored.
Workload measureWorkload(const rt::Mesh& mesh, const std::vector<uint32_t>& indices, bool triangles,
                         double activeMorphTargets, const std::string& source, int influences = -1);

// The most morph weights that are non-zero at once over the model's animations (see above).
// 0 for a primitive without morph targets.
int gltfActiveMorphTargets(const GltfModelData& data);

// The workload of a scene that is drawn (bench, calibrate): its mesh and triangles, and the
// non-zero morph weights of the pose it is drawn in.
Workload sceneWorkload(const RenderScene& scene, const std::string& source);

// The workload a generation is priced for: a glTF rig ("MODEL.glb#m/p") measured on its own
// primitive; a YAML rig on the procedural mesh `mesh` ("" = unknown: an empty Workload, whose
// source says so). `params` are the rig parameters the generation sets (--set), which shape
// the procedural mesh's skinning. Throws InputError as loading the rig does, and for a mesh
// given with a glTF rig or an unknown mesh name.
Workload rigWorkload(const std::string& rigPath, const std::map<std::string, int64_t>& params, const std::string& mesh);

}  // namespace sg

// `shadergen bake occlusion` on a glTF model (docs/bake.md): every vertex of every mesh
// primitive gets the occlusion of the whole scene (all meshes, posed at bind pose or at an
// animation time), stored as the application-specific attribute _OCCLUSION; every morph
// target gets its own shape baked and stores the difference from the base as its
// _OCCLUSION delta. `rig import` maps them to vertex.occlusion / morph.occlusion.
#pragma once
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "bake/occlusion.h"

namespace sg::bake {

struct GltfBakeOptions {
  OcclusionOptions occlusion;  // its progress callback is replaced; use `progress` below
  std::optional<double> time;  // pose at this time of `animation`; unset: bind pose
  std::string animation;       // name or index ("" = the first); only with `time`
  bool binary = true;          // write .glb (false: .gltf with embedded buffers)
  // Progress of the pass `pass` (1-based) of `passes`: `done` of `total` points.
  std::function<void(int pass, int passes, const std::string& what, size_t done, size_t total)> progress;
};

struct BakedPrimitive {
  int mesh = 0, primitive = 0;
  std::string meshName;
  size_t vertices = 0;
  int targets = 0;
  double meanOcclusion = 0;               // over the base shape's vertices
  std::vector<double> meanAbsTargetDelta;  // per target
};

struct GltfBakeResult {
  std::string bytes;  // the output file
  std::vector<BakedPrimitive> primitives;
  size_t rays = 0;       // cast in total
  size_t triangles = 0;  // in the base scene
  int passes = 0;        // BVH builds: 1 + one per morph target
  std::vector<std::string> notes;  // warnings (vertices without a normal, ...)
  std::vector<std::string> inputs;  // the model and the buffer files it names (never to be overwritten)
};

// Throws InputError (file: error: ...) for unreadable models and for primitives the rig
// import cannot decode.
GltfBakeResult bakeGltfOcclusion(const std::string& file, const GltfBakeOptions& opts);

// `shadergen bake tangents`: a TANGENT (VEC4 float, bake/tangents.h) on every primitive that
// has NORMAL and TEXCOORD_0 but no TANGENT, and on each of its morph targets a TANGENT delta
// (the target shape's frames minus the base's). Primitives that have tangents keep them.
struct TangentPrimitive {
  int mesh = 0, primitive = 0;
  std::string meshName;
  size_t vertices = 0;
  int targets = 0;
  size_t fallbacks = 0;  // vertices without a texture direction (orthonormal basis of the normal)
};

struct GltfTangentResult {
  std::string bytes;                      // the output file
  std::vector<TangentPrimitive> primitives;  // the primitives that got tangents
  std::vector<std::string> notes;         // primitives left as they were, external images
  std::vector<std::string> inputs;        // the model and its buffer files
};

// Throws InputError as bakeGltfOcclusion does. `binary`: .glb, else .gltf with embedded buffers.
GltfTangentResult bakeGltfTangents(const std::string& file, bool binary);

}  // namespace sg::bake

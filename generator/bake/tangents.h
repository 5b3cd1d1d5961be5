// Tangent baking (docs/bake.md, `shadergen bake tangents`): per-vertex tangent frames from
// positions, normals and texture coordinates, for models that ship no TANGENT (the glTF 2.0
// spec asks clients to compute them then; a Dawn-style shader needs them from the vertex
// program). Plain data in, plain data out: the glTF side lives in gltf_bake.h.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "bake/occlusion.h"

namespace sg::bake {

using Vec2 = std::array<float, 2>;
using Vec4 = std::array<float, 4>;

struct TangentResult {
  // xyz: unit, orthogonal to the normal, along increasing u; w: +1 or -1 so that
  // cross(normal, xyz) * w points along increasing v (glTF's TANGENT convention).
  std::vector<Vec4> tangents;
  // Vertices with no usable texture direction (no triangle, or all its triangles have
  // degenerate UVs): they get the orthonormal basis of the normal (Duff et al. 2017), w = +1.
  size_t fallbacks = 0;
};

// Each triangle's dP/du and dP/dv (from its edges and UV differences) are summed at its
// corners, weighted by the corner's angle so a vertex's frame does not depend on how its
// fan is split; the sum is made orthogonal to the normal (Gram-Schmidt). Normals need not
// be unit length; a zero normal gives a zero tangent.
TangentResult bakeTangents(const std::vector<Vec3>& positions, const std::vector<Vec3>& normals,
                           const std::vector<Vec2>& uvs, const std::vector<std::array<uint32_t, 3>>& triangles);

}  // namespace sg::bake

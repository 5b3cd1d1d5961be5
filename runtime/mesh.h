// Vertex data and poses for running generated shaders and the GLM reference.
// Streams are keyed by the semantic they carry (docs/semantics.md), so the same
// mesh feeds both the Vulkan harness (through the rig's attribute layout) and
// the reference (which only knows semantics).
#pragma once
#include <glm/glm.hpp>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace sg::rt {

struct Mesh {
  std::string name;
  size_t vertexCount = 0;
  // Per-vertex values by semantic: "vertex.position", "vertex.normal", "vertex.occlusion",
  // "vertex.tangent", "vertex.handedness", "vertex.texcoord0", "vertex.color0",
  // "morph.position[i]", "morph.normal[i]", "morph.occlusion[i]", "morph.tangent[i]",
  // "skin.joints[s]" (integral values stored as floats), "skin.weights[s]".
  // Unused components are 0. Scalars live in .x.
  std::map<std::string, std::vector<glm::vec4>> streams;
  // Uniform values that belong to the mesh, not to a pose, by semantic: the bounds of its
  // bounds-relative positions (mesh.bounds_min, mesh.bounds_extent) and the scales of
  // scaled morph deltas (morph.position_scale, one per target), derived with them.
  std::map<std::string, std::vector<double>> uniforms;

  bool has(const std::string& semantic) const { return streams.count(semantic) != 0; }
  const std::vector<glm::vec4>& at(const std::string& semantic) const { return streams.at(semantic); }
};

// Vertices 0, n, 2n, ... of `mesh` (n >= 1), with its uniforms: a sample of a large mesh.
inline Mesh everyNthVertex(const Mesh& mesh, size_t n) {
  Mesh m;
  m.name = mesh.name + "/" + std::to_string(n);
  m.vertexCount = (mesh.vertexCount + n - 1) / n;
  for (const auto& [sem, values] : mesh.streams) {
    auto& s = m.streams[sem];
    for (size_t v = 0; v < values.size(); v += n) s.push_back(values[v]);
  }
  m.uniforms = mesh.uniforms;
  return m;
}

// Uniform values for one frame. Matrices are column-major (GLM / GLSL convention).
struct Pose {
  std::vector<glm::mat4> bones;       // skin.bones
  std::vector<float> morphWeights;    // morph.weights
  glm::vec3 cameraPosition{0.0f};     // camera.position (world space)
  glm::mat4 view{1.0f};               // camera.view (rigid: rotation + translation)
  glm::mat4 projection{1.0f};         // camera.projection
  glm::mat4 model{1.0f};              // model.matrix
  glm::mat4 dapple{1.0f};             // dapple.matrix
  // Uniforms of other semantics (declared by users' rules): flat column-major components,
  // arrays element after element, by semantic (docs/validation.md, "Poses").
  std::map<std::string, std::vector<double>> uniforms;
  glm::mat4 viewProjection() const { return projection * view; }  // camera.view_projection
};

// Rig parameters the reference needs (mirrors the rig's deformers).
struct RigShape {
  int bones = 0;
  int influences = 0;     // 0 = unskinned, 1 = rigid, 2/4/8 = linear blend
  int morphTargets = 0;
  bool hasModelMatrix = false;  // unskinned rigs transform by model.matrix when provided
  // The rig declares uniform_scale: world.normal uses mat3(M), else its inverse transpose.
  bool uniformScale = false;
};

}  // namespace sg::rt

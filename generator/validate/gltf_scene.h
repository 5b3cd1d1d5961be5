// Validation scenes from real glTF models (docs/gltf.md): the primitive's own vertex data,
// the skeleton and morph weights posed at times of one of its animations, and a camera
// framing the posed model.
#pragma once
#include <glm/glm.hpp>

#include <optional>
#include <string>
#include <vector>

#include "rig/gltf_import.h"
#include "validate/validate.h"

namespace sg {

struct GltfSceneOptions {
  // Animation times in seconds (clamped to the animation's range by sampling). Empty: two
  // times, the start and 40% into the animation (or 0 and 1 without animations).
  std::vector<double> times;
  std::string animation;  // name or index; "" = the first animation (rest pose if none)
  // Every morph target at this weight in place of the animation's and the defaults (an
  // expression held through the motion): models whose animations leave the weights at 0,
  // such as RobotExpressive's, otherwise never exercise their targets.
  std::optional<double> morphWeight;
  GltfReadOptions read;  // how the model's data is read (the overload that imports it)
  // Pose every instance of the primitive (gltfInstances), each at every time: poses are
  // instance-major (pose i * times + k). false: the first alone (the import's node).
  bool allInstances = false;
};

// One node of the scene drawing the primitive's mesh, posed with its own transform, skin and
// morph weights (docs/gltf.md, "Instances"); on a node with EXT_mesh_gpu_instancing, one of
// its GPU instances.
struct GltfInstance {
  int node = -1;  // -1: no node instantiates the mesh (posed at the origin)
  int skin = -1;  // the skin posing it (-1: rigid, at the node)
  std::string name;  // "node 12 'Armature.003'", "node 0 'Cube' instance 17" (for reports)
  int gpuInstance = -1;  // the element of the node's EXT_mesh_gpu_instancing (-1: none)
  glm::dmat4 instanceMatrix{1.0};  // its T·R·S: placed at global(node) · instanceMatrix
};
// GPU instances checked per node: each is a posing and a device draw, and a node may carry
// 100,000; more are sampled evenly, the first and the last included.
constexpr size_t kMaxGpuInstancesChecked = 256;
// The primitive's distinct instances: the import's node first, then every other node of the
// scene drawing the mesh (depth first, pre-order). A skinned primitive's node is placed by its
// skin: a node with the same skin and the same morph weights (node defaults, no animated
// `weights`) as an earlier one poses it identically and is left out, as is a node without a
// skin (noted in `notes`). A rigid primitive's node with EXT_mesh_gpu_instancing gives one
// instance per GPU instance (at most kMaxGpuInstancesChecked, noted when fewer); a skinned
// one's is posed once (its joints place the vertices, noted). Throws InputError for a skin
// whose joints the vertices overrun.
std::vector<GltfInstance> gltfInstances(const GltfImport& model, std::vector<std::string>* notes = nullptr);

// What was posed, for reports.
struct GltfSceneInfo {
  std::string animation;  // "" = no animation (node transforms and default weights)
  double start = 0, end = 0;
  std::vector<double> times;
  std::vector<GltfInstance> instances;  // posed (one unless allInstances)
  std::vector<std::string> notes;       // instances left out, and why
};

// One pose per time (and instance). Skinned: skin.bones[j] = global(joint_j) · inverseBind_j (world space;
// the skinned mesh node's own transform is ignored, as the glTF spec requires). Unskinned:
// model.matrix = global(mesh node) · instanceMatrix. Throws InputError for an unknown animation.
ValidationScene gltfScene(const GltfImport& model, const GltfSceneOptions& opts, GltfSceneInfo* info = nullptr);
// From a rig path "model.glb#m/p".
ValidationScene gltfScene(const std::string& modelRef, const GltfSceneOptions& opts, GltfSceneInfo* info = nullptr);

// Building blocks (exposed for tests).
// Index of the animation named or numbered `which` ("" = 0); -1 if the model has none and
// `which` is empty. Throws InputError if `which` names no animation.
int findGltfAnimation(const GltfModelData& data, const std::string& which);
// Samples a channel at time t (clamped to its keyframes): `components` values.
std::vector<double> sampleGltfChannel(const GltfChannel& ch, double t);
// Global transforms of every node with animation `anim` (-1: none) applied at time t; also
// the morph weights of the mesh node `meshNode` (default: the import's; node/mesh defaults,
// then the animation).
std::vector<glm::dmat4> gltfNodeGlobals(const GltfModelData& data, int anim, double t,
                                        std::vector<double>* morphWeights = nullptr);
std::vector<glm::dmat4> gltfNodeGlobals(const GltfModelData& data, int anim, double t,
                                        std::vector<double>* morphWeights, int meshNode);
// The uniforms for time t (camera framing the posed model), of `instance` (default: the
// import's node and skin, at its first GPU instance if it has any).
rt::Pose gltfPose(const GltfImport& model, const rt::Mesh& mesh, const rt::RigShape& shape, int anim, double t,
                  const GltfInstance* instance = nullptr);

}  // namespace sg

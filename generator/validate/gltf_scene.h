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
};

// What was posed, for reports.
struct GltfSceneInfo {
  std::string animation;  // "" = no animation (node transforms and default weights)
  double start = 0, end = 0;
  std::vector<double> times;
};

// One pose per time. Skinned: skin.bones[j] = global(joint_j) · inverseBind_j (world space;
// the skinned mesh node's own transform is ignored, as the glTF spec requires). Unskinned:
// model.matrix = global(mesh node). Throws InputError for an unknown animation.
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
// the morph weights of the primitive's mesh node (node/mesh defaults, then the animation).
std::vector<glm::dmat4> gltfNodeGlobals(const GltfModelData& data, int anim, double t,
                                        std::vector<double>* morphWeights = nullptr);
// The uniforms for time t (camera framing the posed model).
rt::Pose gltfPose(const GltfImport& model, const rt::Mesh& mesh, const rt::RigShape& shape, int anim, double t);

}  // namespace sg

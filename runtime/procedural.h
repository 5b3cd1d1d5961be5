// Procedural test meshes and seeded random poses for the harness, the reference and the
// validation suite. Everything is deterministic: meshes are analytic, and poses draw from
// std::mt19937 (whose raw output the standard fixes) through distributions implemented here
// (std::uniform_real_distribution & co. differ between standard libraries).
#pragma once
#include "runtime/mesh.h"

#include <cstdint>

namespace sg::rt {

struct MeshOptions {
  int morphTargets = 0;
  bool morphNormals = true;    // morph.normal[i] (and morph.occlusion[i] if occlusion)
  bool morphTangents = false;  // morph.tangent[i] (needs tangents)
  int influences = 4;          // 0 = unskinned; skin.joints/weights[s] for s < ceil(influences/4)
  int bones = 8;
  bool tangents = true;        // vertex.tangent + vertex.handedness
  bool occlusion = true;       // vertex.occlusion
};

// A tessellated cylinder "limb" along +Y (y in [-1, 1], radius ~0.25 with a bulge) over a
// chain of `bones` bones; each vertex is weighted to its up-to-`influences` nearest bones
// (weights sum to 1, sorted by decreasing weight, unused slots weight 0 with joint 0).
// Vertex count: (rings + 1) * (segments + 1) (the seam column is duplicated for the UVs).
// Requires rings >= 1, segments >= 3; throws std::invalid_argument otherwise.
Mesh makeLimb(int rings, int segments, const MeshOptions&);

// A head-like ellipsoid (UV sphere, the exact poles left out so every tangent is defined)
// with morph targets (smooth displacement fields along the normal and sideways), weighted
// like the limb to bones placed in the head: bone 0 = neck (below the head), the others
// (skull/face) spread just under the surface. Vertex count: (rings + 1) * (segments + 1).
Mesh makeHead(int rings, int segments, const MeshOptions&);

// Dawn scale: makeHead(299, 599) = 180,000 vertices, 98 bones, 5 morph targets (position,
// normal, occlusion), 4 influences, tangents. Named "dawn".
Mesh makeDawnScale();

// The RigShape matching meshes built with these options (hasModelMatrix = false).
RigShape rigShapeFor(const MeshOptions&);

struct PoseOptions {
  float maxAngleDegrees = 60.0f;      // bone rotation angle, uniform in [-max, max]
  float maxTranslation = 0.3f;        // bone translation, each component in [-max, max]
  float uniformScaleRange = 0.1f;     // bone uniform scale in [1 - r, 1 + r]
  float nonUniformScaleFraction = 0;  // fraction of bones given a non-uniform scale (off by default)
  float nonUniformScaleMin = 0.8f, nonUniformScaleMax = 1.2f;  // per-axis factor of those bones
  float morphWeightMin = 0.0f, morphWeightMax = 1.0f;          // morph weights, uniform in [min, max]
  bool modelNonUniformScale = false;  // model = translate * rotate * scale(per-axis factor)
};

// Poses that find bugs (validate's default unless the rig declares uniform_scale): half the
// bones and the model matrix scaled per axis by 0.25..2.5 (normals then need the inverse
// transpose), morph weights in [-0.5, 1.5] (a rule that clamps them fails).
PoseOptions hostilePoseOptions(bool uniformScale);

// Seeded random pose with non-trivial rotations. Bones: rotate(random axis, angle) *
// translate(t) * scale(s) (rigid + uniform scale unless opts.nonUniformScaleFraction > 0);
// morph weights in [0, 1]; camera at distance 3..5 from the origin in a random direction
// looking at it (view = glm::lookAt, rigid); Vulkan projection (45° perspective, depth 0..1,
// Y flipped); dapple = a random rotation; model = a random rigid transform.
// Same seed -> identical pose on every platform.
Pose makeRandomPose(const RigShape&, uint32_t seed);
Pose makeRandomPose(const RigShape&, uint32_t seed, const PoseOptions&);

// The rest pose: identity bones, zero morph weights, identity model and dapple, camera at
// (0, 0, 4) looking at the origin, the same projection as makeRandomPose.
Pose makeRestPose(const RigShape&);

}  // namespace sg::rt

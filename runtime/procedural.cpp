// Procedural meshes and poses (see procedural.h). Meshes are analytic functions of the grid
// coordinates (u, v); poses come from std::mt19937 through the hand-written Rng below.
#include "runtime/procedural.h"

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace sg::rt {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kTwoPi = 2.0 * kPi;

using glm::dvec3;

// Floats from the raw 32-bit mt19937 output (fixed by the standard), so the same seed gives
// the same numbers with every standard library. Every draw is its own statement: function
// arguments are evaluated in an unspecified order.
class Rng {
 public:
  explicit Rng(uint32_t seed) : engine_(seed) {}
  // Uniform in [0, 1): the top 24 bits, exactly representable as a float.
  float unit() { return static_cast<float>(static_cast<uint32_t>(engine_()) >> 8) * (1.0f / 16777216.0f); }
  float uniform(float lo, float hi) { return lo + (hi - lo) * unit(); }
  glm::vec3 vec3(float lo, float hi) {
    float x = uniform(lo, hi);
    float y = uniform(lo, hi);
    float z = uniform(lo, hi);
    return {x, y, z};
  }
  // Uniform on the unit sphere, by rejection from the cube.
  glm::vec3 unitVector() {
    for (;;) {
      glm::vec3 v = vec3(-1.0f, 1.0f);
      float l2 = glm::dot(v, v);
      if (l2 > 1e-4f && l2 <= 1.0f) return v / std::sqrt(l2);
    }
  }

 private:
  std::mt19937 engine_;
};

// The analytic surface at grid point (u, v): position, unit normal, and the unit tangent
// along increasing u (exactly orthogonal to the normal).
struct SurfacePoint {
  dvec3 position, normal, tangent;
};

double frac(double x) { return x - std::floor(x); }

glm::vec4 v4(const dvec3& v) { return glm::vec4(glm::vec3(v), 0.0f); }
glm::vec4 s4(double s) { return glm::vec4(static_cast<float>(s), 0.0f, 0.0f, 0.0f); }

void checkGrid(int rings, int segments, const MeshOptions& opts) {
  if (rings < 1) throw std::invalid_argument("procedural mesh needs rings >= 1, got " + std::to_string(rings));
  if (segments < 3)
    throw std::invalid_argument("procedural mesh needs segments >= 3, got " + std::to_string(segments));
  if (opts.morphTargets < 0) throw std::invalid_argument("procedural mesh needs morphTargets >= 0");
  if (opts.influences < 0) throw std::invalid_argument("procedural mesh needs influences >= 0");
  if (opts.influences > 0 && opts.bones < 1)
    throw std::invalid_argument("procedural mesh with influences needs bones >= 1, got " +
                                std::to_string(opts.bones));
}

// Each vertex weighted to its min(K, bones) nearest bone centres, weight ∝ 1 / (d² + 0.02),
// normalised and sorted by decreasing weight (ties by joint index).
void addSkinning(Mesh& mesh, const std::vector<dvec3>& positions, const std::vector<dvec3>& centres,
                 int influences) {
  if (influences <= 0) return;
  const int sets = (influences + 3) / 4;
  const int used = std::min<int>(influences, static_cast<int>(centres.size()));
  const size_t n = positions.size();
  std::vector<std::vector<glm::vec4>*> joints, weights;
  for (int s = 0; s < sets; ++s) {
    joints.push_back(&mesh.streams["skin.joints[" + std::to_string(s) + "]"]);
    weights.push_back(&mesh.streams["skin.weights[" + std::to_string(s) + "]"]);
    joints.back()->assign(n, glm::vec4(0.0f));
    weights.back()->assign(n, glm::vec4(0.0f));
  }
  std::vector<std::pair<double, int>> byDistance(centres.size());
  std::vector<std::pair<double, int>> chosen(static_cast<size_t>(used));
  for (size_t v = 0; v < n; ++v) {
    for (size_t b = 0; b < centres.size(); ++b) {
      dvec3 d = positions[v] - centres[b];
      byDistance[b] = {glm::dot(d, d), static_cast<int>(b)};
    }
    std::partial_sort(byDistance.begin(), byDistance.begin() + used, byDistance.end());
    double total = 0.0;
    for (int k = 0; k < used; ++k) {
      double w = 1.0 / (byDistance[static_cast<size_t>(k)].first + 0.02);
      chosen[static_cast<size_t>(k)] = {w, byDistance[static_cast<size_t>(k)].second};
      total += w;
    }
    std::sort(chosen.begin(), chosen.end(), [](const auto& a, const auto& b) {
      return a.first != b.first ? a.first > b.first : a.second < b.second;
    });
    for (int k = 0; k < used; ++k) {
      (*joints[static_cast<size_t>(k / 4)])[v][k % 4] = static_cast<float>(chosen[static_cast<size_t>(k)].second);
      (*weights[static_cast<size_t>(k / 4)])[v][k % 4] =
          static_cast<float>(chosen[static_cast<size_t>(k)].first / total);
    }
  }
}

// Fills every stream from the analytic surface `at(u, v)` on a (rings+1) x (segments+1) grid.
template <class SurfaceFn>
Mesh buildMesh(std::string name, int rings, int segments, const MeshOptions& opts, SurfaceFn at,
               const std::vector<dvec3>& boneCentres) {
  checkGrid(rings, segments, opts);
  Mesh mesh;
  mesh.name = std::move(name);
  const size_t n = static_cast<size_t>(rings + 1) * static_cast<size_t>(segments + 1);
  mesh.vertexCount = n;

  auto& position = mesh.streams["vertex.position"];
  auto& normal = mesh.streams["vertex.normal"];
  auto& tex0 = mesh.streams["vertex.texcoord0"];
  auto& tex1 = mesh.streams["vertex.texcoord1"];
  position.resize(n);
  normal.resize(n);
  tex0.resize(n);
  tex1.resize(n);
  std::vector<glm::vec4>* occlusion = nullptr;
  std::vector<glm::vec4>* tangent = nullptr;
  std::vector<glm::vec4>* handedness = nullptr;
  std::vector<glm::vec4>* binormal = nullptr;
  auto& color = mesh.streams["vertex.color0"];
  color.resize(n);
  if (opts.occlusion) (occlusion = &mesh.streams["vertex.occlusion"])->resize(n);
  if (opts.tangents) {
    (tangent = &mesh.streams["vertex.tangent"])->resize(n);
    (handedness = &mesh.streams["vertex.handedness"])->resize(n);
    (binormal = &mesh.streams["vertex.binormal"])->resize(n);
  }
  struct Target {
    std::vector<glm::vec4>*dp = nullptr, *dn = nullptr, *docc = nullptr, *dt = nullptr;
  };
  std::vector<Target> targets(static_cast<size_t>(opts.morphTargets));
  for (int i = 0; i < opts.morphTargets; ++i) {
    auto idx = "[" + std::to_string(i) + "]";
    Target& t = targets[static_cast<size_t>(i)];
    (t.dp = &mesh.streams["morph.position" + idx])->resize(n);
    if (opts.morphNormals) {
      (t.dn = &mesh.streams["morph.normal" + idx])->resize(n);
      if (opts.occlusion) (t.docc = &mesh.streams["morph.occlusion" + idx])->resize(n);
    }
    if (opts.morphTangents && opts.tangents) (t.dt = &mesh.streams["morph.tangent" + idx])->resize(n);
  }
  // Keep the sum of all deltas bounded (normal deltas sum to < 0.55 in length, so the morphed
  // normal never vanishes and the morphed tangent never becomes parallel to it).
  const double amp = 1.0 / std::max(1.0, opts.morphTargets / 5.0);

  std::vector<dvec3> positions(n);
  for (int i = 0; i <= rings; ++i) {
    const double v = static_cast<double>(i) / rings;
    for (int j = 0; j <= segments; ++j) {
      const double u = static_cast<double>(j) / segments;
      const size_t k = static_cast<size_t>(i) * static_cast<size_t>(segments + 1) + static_cast<size_t>(j);
      const SurfacePoint sp = at(u, v);
      positions[k] = sp.position;
      position[k] = v4(sp.position);
      normal[k] = v4(sp.normal);
      tex0[k] = glm::vec4(static_cast<float>(u), static_cast<float>(v), 0.0f, 0.0f);
      color[k] = glm::vec4(static_cast<float>(u), static_cast<float>(v), static_cast<float>(0.5 * (u + v)), 1.0f);
      tex1[k] = glm::vec4(static_cast<float>(0.25 + 0.5 * v), static_cast<float>(0.75 - 0.5 * u), 0.0f, 0.0f);
      if (occlusion) (*occlusion)[k] = s4(0.55 + 0.35 * std::sin(3.0 * kTwoPi * u) * std::cos(kTwoPi * v));
      if (tangent) {
        // Deliberately not orthogonal to the normal: the rules must Gram-Schmidt it.
        dvec3 t = glm::normalize(sp.tangent + 0.15 * std::sin(kTwoPi * (3.0 * u + v)) * sp.normal);
        (*tangent)[k] = v4(t);
        (*handedness)[k] = s4(u < 0.5 ? 1.0 : -1.0);  // mirrored UVs on the second half
        // A stored binormal for rigs without tangent.w (only its sign against N x T matters).
        (*binormal)[k] = v4((u < 0.5 ? 1.0 : -1.0) * glm::normalize(glm::cross(sp.normal, t)));
      }
      for (int m = 0; m < opts.morphTargets; ++m) {
        const Target& tg = targets[static_cast<size_t>(m)];
        const double uc = frac(0.17 + 0.31 * m), vc = 0.3 + 0.4 * frac(0.2 + 0.53 * m);
        double du = std::abs(u - uc);
        du = std::min(du, 1.0 - du);
        const double dv = v - vc;
        const double e = amp * std::exp(-(du * du + dv * dv) / (0.25 * 0.25));
        const double along = 0.08 * e * (1.0 + 0.5 * std::sin(kTwoPi * u * (m + 1)));
        const double sideways = 0.04 * e * std::cos(kTwoPi * v * (m + 1));
        (*tg.dp)[k] = v4(along * sp.normal + sideways * sp.tangent);
        if (tg.dn)
          (*tg.dn)[k] = v4(0.06 * e *
                           dvec3(std::sin(kTwoPi * (u + 0.1 * m)), std::cos(kTwoPi * (v + 0.2 * m)),
                                 std::sin(kTwoPi * (u + v) + m)));
        if (tg.docc) (*tg.docc)[k] = s4(0.1 * e * std::sin(kTwoPi * (u + 0.37 * m)));
        if (tg.dt)
          (*tg.dt)[k] = v4(0.05 * e *
                           dvec3(std::cos(kTwoPi * (v + 0.3 * m)), std::sin(kTwoPi * (u - 0.1 * m)),
                                 std::cos(kTwoPi * (u + 2.0 * v) + m)));
      }
    }
  }
  addSkinning(mesh, positions, boneCentres, opts.influences);
  return mesh;
}

glm::mat4 vulkanProjection() {
  glm::mat4 p = glm::perspectiveRH_ZO(glm::radians(45.0f), 4.0f / 3.0f, 0.1f, 100.0f);
  p[1][1] *= -1.0f;  // Vulkan's clip-space Y points down
  return p;
}

glm::mat4 lookAtOrigin(const glm::vec3& eye) {
  glm::vec3 dir = glm::normalize(eye);
  glm::vec3 up = std::abs(dir.y) > 0.95f ? glm::vec3(0, 0, 1) : glm::vec3(0, 1, 0);
  return glm::lookAt(eye, glm::vec3(0.0f), up);
}

}  // namespace

Mesh makeLimb(int rings, int segments, const MeshOptions& opts) {
  // Surface (r(y) cos θ, y, r(y) sin θ) with y = -1 + 2v, θ = 2πu, r bulging in the middle.
  auto at = [](double u, double v) {
    const double theta = kTwoPi * u, y = -1.0 + 2.0 * v;
    const double r = 0.25 * (1.0 + 0.25 * std::sin(kPi * v));
    const double drdy = 0.25 * 0.25 * kPi * std::cos(kPi * v) * 0.5;
    const double c = std::cos(theta), s = std::sin(theta);
    SurfacePoint p;
    p.position = dvec3(r * c, y, r * s);
    p.normal = glm::normalize(dvec3(c, -drdy, s));
    p.tangent = dvec3(-s, 0.0, c);
    return p;
  };
  std::vector<dvec3> centres;
  for (int b = 0; b < opts.bones; ++b) centres.emplace_back(0.0, -1.0 + 2.0 * (b + 0.5) / opts.bones, 0.0);
  return buildMesh("limb", rings, segments, opts, at, centres);
}

Mesh makeHead(int rings, int segments, const MeshOptions& opts) {
  // Ellipsoid with semi-axes (a, b, c); polar angle φ in [φ0, π − φ0] (v = 0 at the top).
  constexpr double a = 0.45, b = 0.6, c = 0.5, phi0 = 0.05;
  auto at = [](double u, double v) {
    const double theta = kTwoPi * u, phi = phi0 + (kPi - 2.0 * phi0) * v;
    const double ct = std::cos(theta), st = std::sin(theta), cp = std::cos(phi), sp = std::sin(phi);
    SurfacePoint p;
    p.position = dvec3(a * sp * ct, b * cp, c * sp * st);
    p.normal = glm::normalize(dvec3(p.position.x / (a * a), p.position.y / (b * b), p.position.z / (c * c)));
    p.tangent = glm::normalize(dvec3(-a * st, 0.0, c * ct));  // ∂P/∂θ: orthogonal to the normal
    return p;
  };
  std::vector<dvec3> centres;
  // Bone 0 is the neck, below the head; the others are the skull/face bones, spread just
  // under the surface (a bone at the centre would never be among a vertex's nearest).
  if (opts.bones >= 1) centres.emplace_back(0.0, -0.65, 0.0);
  const int rest = opts.bones - 1;
  const double golden = kPi * (3.0 - std::sqrt(5.0));
  for (int k = 0; k < rest; ++k) {  // Fibonacci points just under the surface
    const double y = 1.0 - 2.0 * (k + 0.5) / rest, r = std::sqrt(std::max(0.0, 1.0 - y * y));
    const double ang = golden * k;
    centres.emplace_back(0.85 * a * r * std::cos(ang), 0.85 * b * y, 0.85 * c * r * std::sin(ang));
  }
  return buildMesh("head", rings, segments, opts, at, centres);
}

Mesh makeDawnScale() {
  MeshOptions opts;
  opts.morphTargets = 5;
  opts.morphNormals = true;
  opts.influences = 4;
  opts.bones = 98;
  Mesh mesh = makeHead(299, 599, opts);  // 300 x 600 = 180,000 vertices
  mesh.name = "dawn";
  return mesh;
}

RigShape rigShapeFor(const MeshOptions& opts) {
  RigShape shape;
  shape.bones = opts.influences > 0 ? opts.bones : 0;
  shape.influences = opts.influences;
  shape.morphTargets = opts.morphTargets;
  shape.hasModelMatrix = false;
  return shape;
}

Pose makeRandomPose(const RigShape& shape, uint32_t seed) { return makeRandomPose(shape, seed, PoseOptions{}); }

Pose makeRandomPose(const RigShape& shape, uint32_t seed, const PoseOptions& opts) {
  // Draw order (part of the determinism contract): bones, morph weights, camera, dapple, model.
  Rng rng(seed);
  Pose pose;
  for (int b = 0; b < shape.bones; ++b) {
    glm::vec3 axis = rng.unitVector();
    float angle = glm::radians(rng.uniform(-opts.maxAngleDegrees, opts.maxAngleDegrees));
    glm::vec3 t = rng.vec3(-opts.maxTranslation, opts.maxTranslation);
    float s = rng.uniform(1.0f - opts.uniformScaleRange, 1.0f + opts.uniformScaleRange);
    glm::vec3 scale(s);
    if (opts.nonUniformScaleFraction > 0.0f && rng.unit() < opts.nonUniformScaleFraction)
      scale *= rng.vec3(opts.nonUniformScaleMin, opts.nonUniformScaleMax);
    pose.bones.push_back(glm::rotate(glm::mat4(1.0f), angle, axis) * glm::translate(glm::mat4(1.0f), t) *
                         glm::scale(glm::mat4(1.0f), scale));
  }
  const bool unitWeights = opts.morphWeightMin == 0.0f && opts.morphWeightMax == 1.0f;
  for (int i = 0; i < shape.morphTargets; ++i)
    pose.morphWeights.push_back(unitWeights ? rng.unit() : rng.uniform(opts.morphWeightMin, opts.morphWeightMax));

  glm::vec3 dir = rng.unitVector();
  float dist = rng.uniform(3.0f, 5.0f);
  pose.cameraPosition = dir * dist;
  pose.view = lookAtOrigin(pose.cameraPosition);
  pose.projection = vulkanProjection();

  glm::vec3 dappleAxis = rng.unitVector();
  float dappleAngle = rng.uniform(0.0f, static_cast<float>(kTwoPi));
  pose.dapple = glm::rotate(glm::mat4(1.0f), dappleAngle, dappleAxis);

  glm::vec3 modelT = rng.vec3(-0.5f, 0.5f);
  glm::vec3 modelAxis = rng.unitVector();
  float modelAngle = rng.uniform(0.0f, static_cast<float>(kTwoPi));
  pose.model = glm::translate(glm::mat4(1.0f), modelT) * glm::rotate(glm::mat4(1.0f), modelAngle, modelAxis);
  if (opts.modelNonUniformScale)  // drawn last: poses without it keep their values
    pose.model = pose.model * glm::scale(glm::mat4(1.0f), rng.vec3(opts.nonUniformScaleMin, opts.nonUniformScaleMax));
  return pose;
}

PoseOptions hostilePoseOptions(bool uniformScale) {
  PoseOptions o;
  o.morphWeightMin = -0.5f;
  o.morphWeightMax = 1.5f;
  if (!uniformScale) {
    o.nonUniformScaleFraction = 0.5f;
    o.nonUniformScaleMin = 0.25f;
    o.nonUniformScaleMax = 2.5f;
    o.modelNonUniformScale = true;
  }
  return o;
}

Pose makeRestPose(const RigShape& shape) {
  Pose pose;
  pose.bones.assign(static_cast<size_t>(std::max(0, shape.bones)), glm::mat4(1.0f));
  pose.morphWeights.assign(static_cast<size_t>(std::max(0, shape.morphTargets)), 0.0f);
  pose.cameraPosition = glm::vec3(0.0f, 0.0f, 4.0f);
  pose.view = lookAtOrigin(pose.cameraPosition);
  pose.projection = vulkanProjection();
  return pose;
}

}  // namespace sg::rt

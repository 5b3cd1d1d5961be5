#include "validate/gltf_scene.h"

#include <fmt/format.h>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <cmath>

#include "runtime/reference.h"

namespace sg {
namespace {

glm::dquat quatXYZW(const double* v) { return glm::dquat(v[3], v[0], v[1], v[2]); }  // glm: (w, x, y, z)

// Spherical linear interpolation along the shorter arc (glTF spec, Appendix C).
glm::dquat slerpShortest(glm::dquat a, glm::dquat b, double s) {
  double d = glm::dot(a, b);
  if (d < 0) {
    b = -b;
    d = -d;
  }
  if (d > 0.9995) return glm::normalize(a * (1.0 - s) + b * s);
  double theta0 = std::acos(std::min(d, 1.0));
  double theta = theta0 * s;
  double sin0 = std::sin(theta0);
  return glm::normalize(a * (std::sin(theta0 - theta) / sin0) + b * (std::sin(theta) / sin0));
}

glm::dmat4 fromArray(const std::array<double, 16>& m) {
  glm::dmat4 r;
  for (int c = 0; c < 4; ++c)
    for (int k = 0; k < 4; ++k) r[c][k] = m[static_cast<size_t>(c * 4 + k)];
  return r;
}

glm::mat4 fromArrayF(const std::array<float, 16>& m) {
  glm::mat4 r;
  for (int c = 0; c < 4; ++c)
    for (int k = 0; k < 4; ++k) r[c][k] = m[static_cast<size_t>(c * 4 + k)];
  return r;
}

rt::Mesh meshFrom(const GltfModelData& d, const std::string& name) {
  rt::Mesh m;
  m.name = name;
  m.vertexCount = d.vertexCount;
  for (const auto& [sem, values] : d.streams) {
    auto& s = m.streams[sem];
    s.reserve(values.size());
    for (const auto& v : values) s.emplace_back(v[0], v[1], v[2], v[3]);
  }
  return m;
}

}  // namespace

int findGltfAnimation(const GltfModelData& data, const std::string& which) {
  if (which.empty()) return data.animations.empty() ? -1 : 0;
  for (size_t i = 0; i < data.animations.size(); ++i)
    if (data.animations[i].name == which) return static_cast<int>(i);
  bool numeric = !which.empty() && std::all_of(which.begin(), which.end(), [](char c) { return c >= '0' && c <= '9'; });
  if (numeric && which.size() < 7) {
    int i = std::stoi(which);
    if (static_cast<size_t>(i) < data.animations.size()) return i;
  }
  std::string names;
  for (const auto& a : data.animations) names += (names.empty() ? "'" : ", '") + a.name + "'";
  throw InputError(SourceLoc{data.file, 0, 0},
                   fmt::format("the model has no animation '{}' (it has {})", which,
                               names.empty() ? std::string("none") : names));
}

std::vector<double> sampleGltfChannel(const GltfChannel& ch, double t) {
  const size_t n = static_cast<size_t>(ch.components);
  const size_t keys = ch.times.size();
  const bool cubic = ch.interpolation == GltfInterpolation::CubicSpline;
  // Element e of keyframe k (cubic: 0 = in-tangent, 1 = value, 2 = out-tangent).
  auto elem = [&](size_t k, size_t e) { return &ch.values[((cubic ? 3 * k + e : k) * n)]; };
  std::vector<double> out(n);
  auto copy = [&](size_t k) {
    const float* v = elem(k, 1);
    for (size_t c = 0; c < n; ++c) out[c] = v[c];
    return out;
  };
  if (t <= ch.times.front() || keys == 1) return copy(0);
  if (t >= ch.times.back()) return copy(keys - 1);
  size_t k = static_cast<size_t>(std::upper_bound(ch.times.begin(), ch.times.end(), static_cast<float>(t)) -
                                 ch.times.begin()) - 1;
  // Float keyframe times compared with a double t: keep T[k] <= t < T[k+1].
  while (k + 1 < keys - 1 && t >= ch.times[k + 1]) ++k;
  while (k > 0 && t < ch.times[k]) --k;
  double t0 = ch.times[k], t1 = ch.times[k + 1];
  double td = t1 - t0;
  double s = std::clamp((t - t0) / td, 0.0, 1.0);
  switch (ch.interpolation) {
    case GltfInterpolation::Step: return copy(k);
    case GltfInterpolation::Linear: {
      const float* a = elem(k, 1);
      const float* b = elem(k + 1, 1);
      if (ch.path == GltfPath::Rotation) {
        double qa[4] = {a[0], a[1], a[2], a[3]}, qb[4] = {b[0], b[1], b[2], b[3]};
        glm::dquat q = slerpShortest(glm::normalize(quatXYZW(qa)), glm::normalize(quatXYZW(qb)), s);
        return {q.x, q.y, q.z, q.w};
      }
      for (size_t c = 0; c < n; ++c) out[c] = a[c] + s * (static_cast<double>(b[c]) - a[c]);
      return out;
    }
    case GltfInterpolation::CubicSpline: {
      // glTF spec, Appendix C: Hermite spline with tangents scaled by the keyframe interval.
      const float* vk = elem(k, 1);
      const float* bk = elem(k, 2);      // out-tangent of k
      const float* ak1 = elem(k + 1, 0); // in-tangent of k+1
      const float* vk1 = elem(k + 1, 1);
      double s2 = s * s, s3 = s2 * s;
      double h00 = 2 * s3 - 3 * s2 + 1, h10 = s3 - 2 * s2 + s, h01 = -2 * s3 + 3 * s2, h11 = s3 - s2;
      for (size_t c = 0; c < n; ++c)
        out[c] = h00 * vk[c] + h10 * td * bk[c] + h01 * vk1[c] + h11 * td * ak1[c];
      if (ch.path == GltfPath::Rotation) {
        double len = std::sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2] + out[3] * out[3]);
        if (len > 0)
          for (auto& x : out) x /= len;
      }
      return out;
    }
  }
  return out;
}

std::vector<glm::dmat4> gltfNodeGlobals(const GltfModelData& data, int anim, double t,
                                        std::vector<double>* morphWeights) {
  return gltfNodeGlobals(data, anim, t, morphWeights, data.meshNode);
}

std::vector<glm::dmat4> gltfNodeGlobals(const GltfModelData& data, int anim, double t,
                                        std::vector<double>* morphWeights, int meshNode) {
  const size_t N = data.nodes.size();
  std::vector<std::array<double, 3>> tr(N), sc(N);
  std::vector<std::array<double, 4>> rot(N);
  std::vector<bool> animated(N, false);
  for (size_t i = 0; i < N; ++i) {
    tr[i] = data.nodes[i].translation;
    rot[i] = data.nodes[i].rotation;
    sc[i] = data.nodes[i].scale;
  }
  std::vector<double> weights = data.meshWeights;
  if (meshNode >= 0 && !data.nodes[static_cast<size_t>(meshNode)].weights.empty()) {
    const auto& nw = data.nodes[static_cast<size_t>(meshNode)].weights;
    for (size_t i = 0; i < weights.size() && i < nw.size(); ++i) weights[i] = nw[i];
  }
  if (anim >= 0) {
    for (const GltfChannel& ch : data.animations[static_cast<size_t>(anim)].channels) {
      std::vector<double> v = sampleGltfChannel(ch, t);
      size_t node = static_cast<size_t>(ch.node);
      switch (ch.path) {
        case GltfPath::Translation: std::copy(v.begin(), v.end(), tr[node].begin()); animated[node] = true; break;
        case GltfPath::Rotation: std::copy(v.begin(), v.end(), rot[node].begin()); animated[node] = true; break;
        case GltfPath::Scale: std::copy(v.begin(), v.end(), sc[node].begin()); animated[node] = true; break;
        case GltfPath::Weights:
          if (ch.node == meshNode)
            for (size_t i = 0; i < weights.size() && i < v.size(); ++i) weights[i] = v[i];
          break;
      }
    }
  }
  if (morphWeights) *morphWeights = weights;

  std::vector<glm::dmat4> local(N);
  for (size_t i = 0; i < N; ++i) {
    const GltfNode& n = data.nodes[i];
    if (n.hasMatrix && !animated[i]) {
      local[i] = fromArray(n.matrix);
    } else {
      local[i] = fromArray(gltfTrs(tr[i].data(), rot[i].data(), sc[i].data()));
    }
  }
  std::vector<int> parent(N, -1);
  for (size_t i = 0; i < N; ++i)
    for (int c : data.nodes[i].children) parent[static_cast<size_t>(c)] = static_cast<int>(i);
  // Parents before children, without recursion (node chains can be as long as the file):
  // walk up to the first finished ancestor, then fill the chain top-down. The importer
  // refused cycles.
  std::vector<glm::dmat4> global(N);
  std::vector<char> done(N, 0);
  std::vector<size_t> chain;
  for (size_t i = 0; i < N; ++i) {
    chain.clear();
    for (size_t k = i; !done[k]; k = static_cast<size_t>(parent[k])) {
      chain.push_back(k);
      if (parent[k] < 0) break;
    }
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
      size_t k = *it;
      global[k] = parent[k] < 0 ? local[k] : global[static_cast<size_t>(parent[k])] * local[k];
      done[k] = 1;
    }
  }
  return global;
}

rt::Pose gltfPose(const GltfImport& model, const rt::Mesh& mesh, const rt::RigShape& shape, int anim, double t,
                  const GltfInstance* instance) {
  const GltfModelData& d = model.data;
  const int node = instance ? instance->node : d.meshNode;
  const int skinIndex = instance ? instance->skin : d.skin;
  std::vector<double> weights;
  std::vector<glm::dmat4> G = gltfNodeGlobals(d, anim, t, &weights, node);
  rt::Pose pose;
  if (skinIndex >= 0) {
    const GltfSkin& skin = d.skins[static_cast<size_t>(skinIndex)];
    // glTF skinning: jointMatrix_j = inverse(global(meshNode)) · global(joint_j) · IBM_j puts
    // vertices in the mesh node's space, and the spec then ignores the skinned node's transform;
    // the palette maps bind pose to world directly: global(joint_j) · IBM_j. Another
    // instance's skin may have more joints than the program's palette (the vertices use only
    // the first ones) or fewer (gltfInstances checked the vertices stay below them): identity.
    for (size_t j = 0; j < static_cast<size_t>(shape.bones); ++j)
      pose.bones.push_back(j < skin.joints.size()
                               ? glm::mat4(G[static_cast<size_t>(skin.joints[j])] * glm::dmat4(fromArrayF(skin.inverseBind[j])))
                               : glm::mat4(1.0f));
  } else {
    glm::dmat4 place = instance ? instance->instanceMatrix : glm::dmat4(1.0);
    if (!instance && node >= 0 && !d.nodes[static_cast<size_t>(node)].instances.empty())
      place = fromArray(d.nodes[static_cast<size_t>(node)].instances.front());  // as gltfInstances lists it first
    // EXT_mesh_gpu_instancing: the instance's transform applies in the node's local space.
    pose.model = node >= 0 ? glm::mat4(G[static_cast<size_t>(node)] * place) : glm::mat4(1.0f);
  }
  for (int i = 0; i < shape.morphTargets; ++i)
    pose.morphWeights.push_back(static_cast<float>(static_cast<size_t>(i) < weights.size() ? weights[static_cast<size_t>(i)] : 0.0));

  // Camera: frame the posed model's world-space bounding box from the front (+Z is the
  // front of a glTF asset), slightly right and above; rigid lookAt, Vulkan projection.
  std::vector<glm::vec4> world = rt::referenceValues("world.position", mesh, pose, shape);
  glm::dvec3 lo(1e300), hi(-1e300);
  for (const auto& p : world) {
    lo = glm::min(lo, glm::dvec3(p));
    hi = glm::max(hi, glm::dvec3(p));
  }
  if (world.empty()) lo = hi = glm::dvec3(0.0);
  glm::dvec3 centre = (lo + hi) * 0.5;
  double radius = std::max(glm::length(hi - lo) * 0.5, 1e-3);
  const double fovy = glm::radians(45.0);
  double dist = radius / std::sin(fovy / 2) * 1.1;
  glm::dvec3 dir = glm::normalize(glm::dvec3(0.35, 0.3, 1.0));
  glm::dvec3 eye = centre + dir * dist;
  pose.cameraPosition = glm::vec3(eye);
  pose.view = glm::mat4(glm::lookAt(eye, centre, glm::dvec3(0, 1, 0)));
  double nearZ = std::max(dist - 1.5 * radius, dist * 1e-3);
  double farZ = dist + 1.5 * radius;
  glm::mat4 p = glm::perspectiveRH_ZO(static_cast<float>(fovy), 4.0f / 3.0f, static_cast<float>(nearZ),
                                      static_cast<float>(farZ));
  p[1][1] *= -1.0f;  // Vulkan clip-space Y points down
  pose.projection = p;
  return pose;
}

std::vector<GltfInstance> gltfInstances(const GltfImport& model, std::vector<std::string>* notes) {
  const GltfModelData& d = model.data;
  auto describe = [&](int n) {
    const std::string& name = d.nodes[static_cast<size_t>(n)].name;
    return name.empty() ? fmt::format("node {}", n) : fmt::format("node {} '{}'", n, name);
  };
  std::vector<GltfInstance> out;
  // A node's GPU instances (EXT_mesh_gpu_instancing): one instance each for a rigid
  // primitive, at most kMaxGpuInstancesChecked spread evenly (floor(k (N-1) / (K-1)): the
  // first and the last, distinct, the same every run). A skinned one is placed by its joints,
  // and the extension defines no instanced skinning: posed once, with a note.
  static const std::vector<std::array<double, 16>> none;
  auto add = [&](GltfInstance inst) {
    const auto& gpu = inst.node >= 0 ? d.nodes[static_cast<size_t>(inst.node)].instances : none;
    if (gpu.empty() || d.skin >= 0) {
      if (!gpu.empty() && notes)
        notes->push_back(fmt::format("{} has {} GPU instances (EXT_mesh_gpu_instancing), which are not posed for "
                                     "the skinned mesh {}: posed once, by its joints",
                                     inst.name, gpu.size(), d.mesh));
      out.push_back(std::move(inst));
      return;
    }
    const size_t N = gpu.size(), K = std::min(N, kMaxGpuInstancesChecked);
    if (K < N && notes)
      notes->push_back(fmt::format("checked {} of {} GPU instances of {} (EXT_mesh_gpu_instancing), evenly spread, "
                                   "the first and the last included",
                                   K, N, inst.name));
    for (size_t k = 0; k < K; ++k) {
      const size_t g = K == 1 ? 0 : k * (N - 1) / (K - 1);
      GltfInstance gi = inst;
      gi.gpuInstance = static_cast<int>(g);
      gi.instanceMatrix = fromArray(gpu[g]);
      gi.name = fmt::format("{} instance {}", inst.name, g);
      out.push_back(std::move(gi));
    }
  };
  add(GltfInstance{d.meshNode, d.skin, d.meshNode >= 0 ? describe(d.meshNode) : "no node (origin)"});
  // Nodes whose morph weights an animation sets: their instances differ even under one skin.
  std::vector<char> animatedWeights(d.nodes.size(), 0);
  for (const auto& a : d.animations)
    for (const auto& ch : a.channels)
      if (ch.path == GltfPath::Weights) animatedWeights[static_cast<size_t>(ch.node)] = 1;
  // The highest joint index the vertices use (skins with fewer joints cannot pose them).
  int usedJoints = 0;
  for (const auto& [sem, values] : d.streams)
    if (sem.rfind("skin.joints[", 0) == 0)
      for (const auto& v : values)
        for (float j : v) usedJoints = std::max(usedJoints, static_cast<int>(j) + 1);
  for (int n : gltfSceneNodes(d)) {
    const GltfNode& node = d.nodes[static_cast<size_t>(n)];
    if (node.mesh != d.mesh || n == d.meshNode) continue;
    GltfInstance inst{n, -1, describe(n)};
    if (d.skin >= 0) {
      if (node.skin < 0 || static_cast<size_t>(node.skin) >= d.skins.size()) {
        if (notes) notes->push_back(fmt::format("{} draws the skinned mesh {} without a skin: not posed", inst.name, d.mesh));
        continue;
      }
      inst.skin = node.skin;
      const bool same = std::any_of(out.begin(), out.end(), [&](const GltfInstance& o) {
        return o.skin == inst.skin && o.node >= 0 && !animatedWeights[static_cast<size_t>(o.node)] &&
               !animatedWeights[static_cast<size_t>(n)] && d.nodes[static_cast<size_t>(o.node)].weights == node.weights;
      });
      if (same) {
        if (notes) notes->push_back(fmt::format("{} poses mesh {} exactly as an earlier node with skin {}: not repeated",
                                                inst.name, d.mesh, inst.skin));
        continue;
      }
      const size_t joints = d.skins[static_cast<size_t>(inst.skin)].joints.size();
      if (static_cast<size_t>(usedJoints) > joints)
        throw InputError(SourceLoc{d.file, 0, 0},
                         fmt::format("{} poses mesh {} with skin {} of {} joints, but its vertices use joint {}",
                                     inst.name, d.mesh, inst.skin, joints, usedJoints - 1));
    }
    add(std::move(inst));
  }
  return out;
}

ValidationScene gltfScene(const GltfImport& model, const GltfSceneOptions& opts, GltfSceneInfo* info) {
  const GltfModelData& d = model.data;
  int anim = findGltfAnimation(d, opts.animation);
  ValidationScene s;
  s.mesh = meshFrom(d, model.rig.name);
  s.shape.bones = static_cast<int>(model.rig.param("bones"));
  s.shape.influences = static_cast<int>(model.rig.param("influences"));
  s.shape.morphTargets = model.rig.morphTargets();
  s.shape.hasModelMatrix = d.skin < 0;
  s.shape.uniformScale = model.rig.param("uniform_scale") != 0;
  GltfSceneInfo inf;
  if (anim >= 0) {
    const GltfAnimation& a = d.animations[static_cast<size_t>(anim)];
    inf.animation = a.name;
    inf.start = a.start;
    inf.end = a.end;
  } else {
    inf.end = 1.0;
  }
  inf.times = opts.times;
  if (inf.times.empty()) inf.times = {inf.start, inf.start + 0.4 * (inf.end - inf.start)};
  inf.instances = gltfInstances(model, &inf.notes);
  if (!opts.allInstances) inf.instances.resize(1);
  for (const GltfInstance& instance : inf.instances)
    for (double t : inf.times) {
      s.poses.push_back(gltfPose(model, s.mesh, s.shape, anim, t, &instance));
      if (opts.morphWeight)
        std::fill(s.poses.back().morphWeights.begin(), s.poses.back().morphWeights.end(), static_cast<float>(*opts.morphWeight));
    }
  if (info) *info = inf;
  return s;
}

ValidationScene gltfScene(const std::string& modelRef, const GltfSceneOptions& opts, GltfSceneInfo* info) {
  return gltfScene(importGltfRef(modelRef, opts.read), opts, info);
}

}  // namespace sg

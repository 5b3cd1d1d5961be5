// glTF scene and animation (gltf_scene.h).
#include "rig/gltf_scene.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include "common/diagnostics.h"

namespace sg {

std::array<double, 16> gltfTrs(const double* t, const double* q, const double* s) {
  const glm::dmat4 m = glm::translate(glm::dmat4(1.0), glm::dvec3(t[0], t[1], t[2])) *
                       glm::mat4_cast(glm::normalize(glm::dquat(q[3], q[0], q[1], q[2]))) *  // glm: (w, x, y, z)
                       glm::scale(glm::dmat4(1.0), glm::dvec3(s[0], s[1], s[2]));
  std::array<double, 16> out{};
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) out[static_cast<size_t>(c * 4 + r)] = m[c][r];
  return out;
}

}  // namespace sg

namespace sg::gltf {
namespace {
// The glTF-Validator's tolerance for a unit quaternion: |length - 1| at most this
// (ROTATION_NON_UNIT, ACCESSOR_ANIMATION_SAMPLER_OUTPUT_NON_NORMALIZED_QUATERNION).
constexpr double kUnitQuaternionTolerance = 0.00769;
double quaternionLength(const float* q) {
  return std::sqrt(double(q[0]) * q[0] + double(q[1]) * q[1] + double(q[2]) * q[2] + double(q[3]) * q[3]);
}

// EXT_mesh_gpu_instancing on node `index`: one T·R·S per element (an absent attribute is the
// identity part). ROTATION is float or normalized (signed) byte/short VEC4, normalised before
// use like a node's rotation; TRANSLATION and SCALE are float VEC3, or byte/short (normalized
// or not) under KHR_mesh_quantization, as the extension allows.
std::vector<std::array<double, 16>> readGpuInstances(const tinygltf::Node& n, size_t index, const std::string& file,
                                                     Reader& reader, std::vector<Diagnostic>& diagnostics) {
  static const char* kExt = "EXT_mesh_gpu_instancing";
  auto it = n.extensions.find(kExt);
  if (it == n.extensions.end()) return {};
  const std::string where = fmt::format("node {} ('{}', /nodes/{}/extensions/{}", index, n.name, index, kExt);
  // tinygltf reads an empty object as null, so "attributes": {} reads as no attributes.
  static const tinygltf::Value kNone;
  const tinygltf::Value& ext = it->second;
  const tinygltf::Value& attrs = ext.IsObject() && ext.Has("attributes") ? ext.Get("attributes") : kNone;
  const char* names[3] = {"TRANSLATION", "ROTATION", "SCALE"};
  std::vector<AccessorData> attr(3);
  std::string first;  // the attribute that set the count
  size_t count = 0;
  for (size_t k = 0; k < 3; ++k) {
    if (!attrs.Has(names[k])) continue;
    const tinygltf::Value& v = attrs.Get(names[k]);
    const std::string what = fmt::format("{}/attributes/{})", where, names[k]);
    if (!v.IsInt()) fail(file, fmt::format("{}: {} is not an accessor index", what, names[k]));
    AccessorData d = reader.read(v.GetNumberAsInt(), what);
    const bool rotation = k == 1;
    const bool small = d.componentType == TINYGLTF_COMPONENT_TYPE_BYTE || d.componentType == TINYGLTF_COMPONENT_TYPE_SHORT;
    if (d.type != (rotation ? TINYGLTF_TYPE_VEC4 : TINYGLTF_TYPE_VEC3) ||
        !(d.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT || (small && (d.normalized || !rotation))))
      fail(file, fmt::format("{}: {} is {}{} {}; it must be {}", what, names[k], d.normalized ? "normalized " : "",
                             componentTypeName(d.componentType), typeName(d.type),
                             rotation ? "VEC4 of float, or normalized byte or short"
                                      : "VEC3 of float, or byte or short, normalized or not (KHR_mesh_quantization)"));
    if (first.empty()) {
      first = names[k];
      count = d.count;
    } else if (d.count != count) {
      fail(file, fmt::format("{}: {} has {} elements but {} has {}; every attribute has one per instance", what,
                             names[k], d.count, first, count));
    }
    attr[k] = std::move(d);
  }
  if (first.empty()) fail(file, where + "): its \"attributes\" have no TRANSLATION, ROTATION or SCALE");
  if (count == 0) fail(file, where + "): its attributes have no elements (no instance)");
  reader.charge(count, sizeof(std::array<double, 16>), where + ") instance matrices");
  std::vector<std::array<double, 16>> out;
  out.reserve(count);
  size_t nonUnit = 0;
  for (size_t i = 0; i < count; ++i) {
    double t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
    for (size_t c = 0; c < 3; ++c) {
      if (!attr[0].values.empty()) t[c] = attr[0].values[i * 3 + c];
      if (!attr[2].values.empty()) s[c] = attr[2].values[i * 3 + c];
    }
    if (!attr[1].values.empty()) {
      const double len = quaternionLength(&attr[1].values[i * 4]);
      if (!(len > 0))
        fail(file, fmt::format("{}/attributes/ROTATION): instance {} is a quaternion of length 0: it is no rotation",
                               where, i));
      if (!(std::abs(len - 1) <= kUnitQuaternionTolerance)) ++nonUnit;
      std::copy_n(&attr[1].values[i * 4], 4, q);
    }
    out.push_back(gltfTrs(t, q, s));
  }
  if (nonUnit)
    diagnostics.push_back(Diagnostic{Severity::Warning, SourceLoc{file, 0, 0},
                                     fmt::format("{}/attributes/ROTATION): {} of {} instance quaternions are not of unit "
                                                 "length; they are normalised before use",
                                                 where, nonUnit, count),
                                     "ROTATION_NON_UNIT"});
  return out;
}
}  // namespace

void readScene(const tinygltf::Model& model, const std::string& file, int mesh, const std::string& meshDesc,
               Reader& reader, GltfModelData& data, std::vector<std::string>& notes,
               std::vector<Diagnostic>& diagnostics) {
  for (const auto& n : model.nodes) {
    GltfNode g;
    g.name = n.name;
    g.children = n.children;
    g.mesh = n.mesh;
    g.skin = n.skin;
    if (n.matrix.size() == 16) {
      g.hasMatrix = true;
      std::copy(n.matrix.begin(), n.matrix.end(), g.matrix.begin());
    }
    if (n.translation.size() == 3) std::copy(n.translation.begin(), n.translation.end(), g.translation.begin());
    if (n.rotation.size() == 4) {
      std::copy(n.rotation.begin(), n.rotation.end(), g.rotation.begin());
      const double len = std::sqrt(n.rotation[0] * n.rotation[0] + n.rotation[1] * n.rotation[1] +
                                   n.rotation[2] * n.rotation[2] + n.rotation[3] * n.rotation[3]);
      if (!(len > 0))
        fail(file, fmt::format("node {} ('{}', /nodes/{}/rotation): the rotation quaternion has length 0: it is no "
                               "rotation",
                               data.nodes.size(), n.name, data.nodes.size()));
      if (!(std::abs(len - 1) <= kUnitQuaternionTolerance))
        diagnostics.push_back(Diagnostic{
            Severity::Warning, SourceLoc{file, 0, 0},
            fmt::format("node {} ('{}', /nodes/{}/rotation): the rotation quaternion has length {:.6g}, not 1; it is "
                        "normalised before use",
                        data.nodes.size(), n.name, data.nodes.size(), len),
            "ROTATION_NON_UNIT"});
    }
    if (n.scale.size() == 3) std::copy(n.scale.begin(), n.scale.end(), g.scale.begin());
    g.weights = n.weights;
    g.instances = readGpuInstances(n, data.nodes.size(), file, reader, diagnostics);
    for (int c : g.children)
      if (c < 0 || static_cast<size_t>(c) >= model.nodes.size())
        fail(file, fmt::format("node '{}' has a child {} that does not exist", n.name, c));
    data.nodes.push_back(std::move(g));
  }
  {
    // Parents (and a cycle check: glTF node graphs are forests).
    std::vector<int> parent(model.nodes.size(), -1);
    for (size_t i = 0; i < model.nodes.size(); ++i)
      for (int c : model.nodes[i].children) {
        if (parent[static_cast<size_t>(c)] >= 0)
          fail(file, fmt::format("node {} has two parents; glTF node hierarchies are trees", c));
        parent[static_cast<size_t>(c)] = static_cast<int>(i);
      }
    // Every node has at most one parent, so following parents either ends at a root or
    // comes back: one linear pass with three colours (a long chain costs O(n), not O(n²)).
    std::vector<char> state(parent.size(), 0);  // 0 unvisited, 1 on the current walk, 2 done
    for (size_t i = 0; i < parent.size(); ++i) {
      int p = static_cast<int>(i);
      while (p >= 0 && state[static_cast<size_t>(p)] == 0) {
        state[static_cast<size_t>(p)] = 1;
        p = parent[static_cast<size_t>(p)];
      }
      if (p >= 0 && state[static_cast<size_t>(p)] == 1)
        fail(file, fmt::format("node {} is part of a cycle in the node hierarchy", p));
      for (int q = static_cast<int>(i); q >= 0 && state[static_cast<size_t>(q)] == 1; q = parent[static_cast<size_t>(q)])
        state[static_cast<size_t>(q)] = 2;
    }
    int sceneIndex = model.defaultScene >= 0 ? model.defaultScene : (model.scenes.empty() ? -1 : 0);
    if (sceneIndex >= 0 && static_cast<size_t>(sceneIndex) < model.scenes.size()) {
      data.sceneRoots = model.scenes[static_cast<size_t>(sceneIndex)].nodes;
    } else {
      for (size_t i = 0; i < parent.size(); ++i)
        if (parent[i] < 0) data.sceneRoots.push_back(static_cast<int>(i));
    }
    for (int r : data.sceneRoots)
      if (r < 0 || static_cast<size_t>(r) >= model.nodes.size())
        fail(file, fmt::format("the scene refers to node {}, which does not exist", r));
    // The node that instantiates the mesh: first in the scene (depth first, pre-order), else
    // any. Iterative: a chain of nodes as long as the file allows must not overflow the stack.
    std::vector<int> todo(data.sceneRoots.rbegin(), data.sceneRoots.rend());
    std::vector<char> seen(data.nodes.size(), 0);  // a scene may list a root twice
    while (!todo.empty() && data.meshNode < 0) {
      int n = todo.back();
      todo.pop_back();
      if (seen[static_cast<size_t>(n)]) continue;
      seen[static_cast<size_t>(n)] = 1;
      const GltfNode& node = data.nodes[static_cast<size_t>(n)];
      if (node.mesh == mesh) data.meshNode = n;
      todo.insert(todo.end(), node.children.rbegin(), node.children.rend());
    }
    if (data.meshNode < 0)
      for (size_t i = 0; i < data.nodes.size(); ++i)
        if (data.nodes[i].mesh == mesh) {
          data.meshNode = static_cast<int>(i);
          break;
        }
    if (data.meshNode < 0) notes.push_back(fmt::format("no node instantiates {}; it is posed at the origin", meshDesc));
  }
  for (size_t si = 0; si < model.skins.size(); ++si) {
    const auto& s = model.skins[si];
    GltfSkin g;
    g.name = s.name;
    g.joints = s.joints;
    for (int j : g.joints)
      if (j < 0 || static_cast<size_t>(j) >= model.nodes.size())
        fail(file, fmt::format("skin {} has joint node {}, which does not exist", si, j));
    if (s.inverseBindMatrices >= 0) {
      AccessorData ibm = reader.read(s.inverseBindMatrices, fmt::format("skin {} inverseBindMatrices", si));
      if (ibm.type != TINYGLTF_TYPE_MAT4 || ibm.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT ||
          ibm.count < g.joints.size())
        fail(file, fmt::format("skin {}: inverseBindMatrices must be {} float MAT4", si, g.joints.size()));
      for (size_t j = 0; j < g.joints.size(); ++j) {
        std::array<float, 16> m{};
        std::copy(ibm.values.begin() + static_cast<long>(j * 16), ibm.values.begin() + static_cast<long>(j * 16 + 16),
                  m.begin());
        g.inverseBind.push_back(m);
      }
    } else {
      std::array<float, 16> id{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
      g.inverseBind.assign(g.joints.size(), id);
    }
    data.skins.push_back(std::move(g));
  }
  for (size_t ai = 0; ai < model.animations.size(); ++ai) {
    const auto& a = model.animations[ai];
    GltfAnimation g;
    g.name = a.name.empty() ? std::to_string(ai) : a.name;
    bool first = true;
    for (size_t ci = 0; ci < a.channels.size(); ++ci) {
      const auto& c = a.channels[ci];
      std::string what = fmt::format("animation '{}' channel {}", g.name, ci);
      if (c.target_node < 0) continue;  // e.g. KHR_animation_pointer targets: not posed here
      if (static_cast<size_t>(c.target_node) >= model.nodes.size())
        fail(file, fmt::format("{} targets node {}, which does not exist", what, c.target_node));
      GltfChannel ch;
      ch.node = c.target_node;
      if (c.target_path == "translation") ch.path = GltfPath::Translation;
      else if (c.target_path == "rotation") ch.path = GltfPath::Rotation;
      else if (c.target_path == "scale") ch.path = GltfPath::Scale;
      else if (c.target_path == "weights") ch.path = GltfPath::Weights;
      else continue;
      if (c.sampler < 0 || static_cast<size_t>(c.sampler) >= a.samplers.size())
        fail(file, fmt::format("{} uses sampler {}, which does not exist", what, c.sampler));
      const auto& smp = a.samplers[static_cast<size_t>(c.sampler)];
      if (smp.interpolation == "STEP") ch.interpolation = GltfInterpolation::Step;
      else if (smp.interpolation == "CUBICSPLINE") ch.interpolation = GltfInterpolation::CubicSpline;
      else if (smp.interpolation.empty() || smp.interpolation == "LINEAR") ch.interpolation = GltfInterpolation::Linear;
      else fail(file, fmt::format("{}: unknown interpolation '{}'", what, smp.interpolation));
      AccessorData in = reader.read(smp.input, what + " input");
      AccessorData out = reader.read(smp.output, what + " output");
      if (in.components != 1 || in.count == 0) fail(file, fmt::format("{}: the input must be non-empty SCALAR times", what));
      ch.times = in.values;
      for (size_t k = 1; k < ch.times.size(); ++k)
        if (!(ch.times[k] > ch.times[k - 1])) fail(file, fmt::format("{}: keyframe times must increase", what));
      size_t perKey = ch.interpolation == GltfInterpolation::CubicSpline ? 3 : 1;
      size_t total = out.values.size();
      if (ch.path == GltfPath::Weights) {
        if (total == 0 || total % (ch.times.size() * perKey) != 0)
          fail(file, fmt::format("{}: {} output values do not divide into {} keyframes", what, total, ch.times.size()));
        ch.components = static_cast<int>(total / (ch.times.size() * perKey));
      } else {
        ch.components = ch.path == GltfPath::Rotation ? 4 : 3;
        if (out.components != ch.components || out.count != ch.times.size() * perKey)
          fail(file, fmt::format("{}: expected {} {} output elements, found {} {}", what, ch.times.size() * perKey,
                                 ch.components == 4 ? "VEC4" : "VEC3", out.count, typeName(out.type)));
      }
      if (ch.path == GltfPath::Rotation) {
        // Cubic splines: only the values are quaternions (not the tangents around them).
        size_t bad = 0, first = 0;
        double worst = 1;
        for (size_t k = perKey / 3; k < out.count; k += perKey) {
          const double len = quaternionLength(&out.values[k * 4]);
          if (!(len > 0))
            fail(file, fmt::format("{} (node {} rotation, sampler {}, output accessor {}, /animations/{}/channels/{}/sampler): "
                                   "keyframe {} is a quaternion of length 0: it is no rotation",
                                   what, c.target_node, c.sampler, smp.output, ai, ci, k / perKey));
          if (std::abs(len - 1) <= kUnitQuaternionTolerance) continue;
          if (bad++ == 0) first = k;
          if (!(std::abs(len - 1) <= std::abs(worst - 1))) worst = len;
        }
        if (bad)
          diagnostics.push_back(Diagnostic{
              Severity::Warning, SourceLoc{file, 0, 0},
              fmt::format("{} (node {} rotation, sampler {}, output accessor {}, /animations/{}/channels/{}/sampler): "
                          "{} of {} keyframe quaternions are not of unit length (first: keyframe {}; the farthest from "
                          "1: length {:.6g}); posing normalises them (three.js does not)",
                          what, c.target_node, c.sampler, smp.output, ai, ci, bad, ch.times.size(), first / perKey,
                          worst),
              "ACCESSOR_ANIMATION_SAMPLER_OUTPUT_NON_NORMALIZED_QUATERNION"});
      }
      ch.values = std::move(out.values);
      g.start = first ? ch.times.front() : std::min(g.start, ch.times.front());
      g.end = first ? ch.times.back() : std::max(g.end, ch.times.back());
      first = false;
      g.channels.push_back(std::move(ch));
    }
    data.animations.push_back(std::move(g));
  }
}

}  // namespace sg::gltf

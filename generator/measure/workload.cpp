#include "measure/workload.h"

#include <fmt/format.h>
#include <meshoptimizer.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "rig/rig_lod.h"
#include "validate/gltf_scene.h"

namespace sg {

Workload measureWorkload(const rt::Mesh& mesh, const std::vector<uint32_t>& indices, bool triangles,
                         double activeMorphTargets, const std::string& source, int influences) {
  Workload w;
  w.source = source;
  w.activeMorphTargets = activeMorphTargets;
  const size_t n = mesh.vertexCount;
  w.verticesPerDraw = double(n);
  if (n == 0) return w;

  // The shading order: first reference in the index buffer.
  std::vector<uint32_t> order;
  if (indices.empty()) {
    order.resize(n);
    for (size_t v = 0; v < n; ++v) order[v] = uint32_t(v);
  } else {
    std::vector<char> seen(n, 0);
    for (uint32_t i : indices)
      if (i < n && !seen[i]) {
        seen[i] = 1;
        order.push_back(i);
      }
  }

  // Distinct joints per warp-sized group and influence slot, over influences that weigh; and
  // per group over all its slots.
  const size_t groups = (order.size() + kWorkloadWarp - 1) / kWorkloadWarp;
  std::vector<std::set<float>> footprint(groups);
  double sum = 0;
  size_t pairs = 0;
  for (int set = 0;; ++set) {
    auto j = mesh.streams.find(fmt::format("skin.joints[{}]", set));
    auto wt = mesh.streams.find(fmt::format("skin.weights[{}]", set));
    if (j == mesh.streams.end() || wt == mesh.streams.end()) break;
    if (j->second.size() < n || wt->second.size() < n) break;
    for (int c = 0; c < 4 && (influences < 0 || 4 * set + c < influences); ++c)
      for (size_t g = 0; g < order.size(); g += kWorkloadWarp) {
        std::set<float> joints;
        for (size_t k = g; k < std::min(order.size(), g + kWorkloadWarp); ++k)
          if (wt->second[order[k]][c] != 0.0f) joints.insert(j->second[order[k]][c]);
        if (joints.empty()) continue;
        sum += double(joints.size());
        ++pairs;
        footprint[g / kWorkloadWarp].insert(joints.begin(), joints.end());
      }
  }
  if (pairs) w.jointsPerWarp = sum / double(pairs);
  double entries = 0;
  size_t skinned = 0;
  for (const auto& f : footprint)
    if (!f.empty()) {
      entries += double(f.size());
      ++skinned;
    }
  if (skinned) w.paletteEntriesPerWarp = entries / double(skinned);

  // Post-transform cache reuse (meshoptimizer's FIFO model), per vertex the draw shades.
  if (triangles && !order.empty()) {
    std::vector<uint32_t> list;
    if (indices.empty()) {
      list = order;
    } else {
      list.reserve(indices.size());
      for (size_t t = 0; t + 3 <= indices.size(); t += 3)
        if (indices[t] < n && indices[t + 1] < n && indices[t + 2] < n)
          list.insert(list.end(), indices.begin() + long(t), indices.begin() + long(t) + 3);
    }
    list.resize(list.size() / 3 * 3);
    if (!list.empty()) {
      const meshopt_VertexCacheStatistics s = meshopt_analyzeVertexCache(
          list.data(), list.size(), n, kWorkloadCacheSize, kWorkloadCacheWarp, kWorkloadPrimGroup);
      w.invocationsPerVertex = double(s.vertices_transformed) / double(order.size());
    }
  }
  return w;
}

int gltfActiveMorphTargets(const GltfModelData& data) {
  auto active = [](const std::vector<double>& weights) {
    return int(std::count_if(weights.begin(), weights.end(), [](double x) { return x != 0.0; }));
  };
  int most = -1;
  for (size_t a = 0; a < data.animations.size(); ++a) {
    std::vector<float> keys;
    for (const auto& ch : data.animations[a].channels)
      if (ch.path == GltfPath::Weights && ch.node == data.meshNode) keys.insert(keys.end(), ch.times.begin(), ch.times.end());
    if (keys.empty()) continue;  // this animation leaves the weights alone
    std::sort(keys.begin(), keys.end());
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    std::vector<double> times;
    for (size_t k = 0; k < keys.size(); ++k) {
      times.push_back(keys[k]);
      if (k + 1 < keys.size()) times.push_back(0.5 * (double(keys[k]) + double(keys[k + 1])));
    }
    for (double t : times) {
      std::vector<double> weights;
      gltfNodeGlobals(data, int(a), t, &weights);
      most = std::max(most, active(weights));
    }
  }
  if (most < 0) {  // no animation moves them: the defaults hold
    std::vector<double> weights;
    gltfNodeGlobals(data, -1, 0, &weights);
    most = active(weights);
  }
  return most;
}

Workload sceneWorkload(const RenderScene& scene, const std::string& source) {
  double active = 0;
  for (float x : scene.pose.morphWeights) active += x != 0.0f;
  return measureWorkload(scene.mesh, scene.indices, true, active, source);
}

Workload rigWorkload(const std::string& rigPath, const std::map<std::string, int64_t>& params, const std::string& mesh) {
  if (isGltfPath(rigPath)) {
    if (!mesh.empty())
      throw InputError(SourceLoc{}, fmt::format("--mesh {}: a glTF rig ({}) is measured on its own mesh", mesh, rigPath));
    const GltfRef ref = parseGltfRef(rigPath);
    const GltfImport model = importGltfRef(rigPath);
    const GltfModelData& d = model.data;
    GltfSceneOptions so;
    so.times = {0.0};
    ValidationScene vs;
    int active = 0;
    try {  // posing reads the animations, which generation itself never needs
      vs = gltfScene(model, so);
      active = gltfActiveMorphTargets(d);
    } catch (const InputError& e) {
      Workload w;
      w.verticesPerDraw = double(d.vertexCount);
      w.source = fmt::format("{} mesh {} primitive {} ({} vertices; the rest not measured: {})", d.stem, d.mesh, d.primitive,
                             d.vertexCount, e.diagnostic().message);
      return w;
    }
    const bool triangles = d.indicesError.empty() && d.mode >= 4 && d.mode <= 6;
    std::vector<uint32_t> indices = d.indices;
    if (triangles) indices = triangleList(d.indices, d.mode, vs.mesh.vertexCount, ref.file);
    const std::string source = fmt::format("{} mesh {} primitive {} ({} vertices{})", d.stem, d.mesh, d.primitive, d.vertexCount,
                                           d.indicesError.empty() ? "" : "; its indices could not be read");
    if (!d.indicesError.empty()) indices.clear();
    const auto lod = params.find("influences");
    Workload w = measureWorkload(vs.mesh, indices, triangles, active, source,
                                 lod == params.end() ? -1 : int(lod->second));
    if (!d.indicesError.empty()) w.jointsPerWarp = w.paletteEntriesPerWarp = 0;  // no shading order known
    return w;
  }
  Workload w;
  if (mesh.empty()) {
    w.source = "unknown (no mesh given: the profile's defaults)";
    return w;
  }
  Rig rig = loadRig(rigPath);
  if (!params.empty()) rig = rigWithParameters(rig, params, SourceLoc{});
  RenderOptions ro;
  ro.mesh = mesh;
  const RenderScene s = renderScene(rig, ro);
  return measureWorkload(s.mesh, s.indices, true, -1,
                         fmt::format("procedural mesh '{}' ({} vertices)", mesh, s.mesh.vertexCount));
}

}  // namespace sg

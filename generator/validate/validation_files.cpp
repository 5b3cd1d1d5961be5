#include "validate/validation_files.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace sg {
namespace {

using Json = nlohmann::ordered_json;

// Paths are bytes on Linux: invalid UTF-8 is replaced (U+FFFD), not an exception.
std::string dump(const Json& j) { return j.dump(2, ' ', false, Json::error_handler_t::replace) + "\n"; }

// A number, or null where it is not finite (JSON has no NaN or infinity).
Json number(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

Json instanceJson(const GltfInstance& inst, size_t index) {
  Json j;
  j["index"] = index;
  j["node"] = inst.node;
  j["node_description"] = inst.name;
  j["skin"] = inst.skin;
  j["gpu_instance"] = inst.gpuInstance;  // EXT_mesh_gpu_instancing's element (-1: none)
  return j;
}

Json outputJson(const OutputReport& o, bool full) {
  Json j;
  j["name"] = o.name;
  if (full) {
    j["semantics"] = o.semantics;
    j["type"] = o.type;
    j["components"] = o.components;
  }
  j["pass"] = o.pass;
  if (o.unchecked) {
    j["unchecked"] = o.uncheckedReason;
    return j;
  }
  j["max_abs_error"] = number(o.maxAbsError);
  j["max_rel_error"] = number(o.maxRelError);
  j["worst_vertex"] = o.worstVertex;
  j["worst_component"] = o.worstComponent;
  Json gpu = Json::array(), ref = Json::array();
  for (double v : o.worstGpu) gpu.push_back(number(v));
  for (double v : o.worstReference) ref.push_back(number(v));
  j["worst_device"] = gpu;
  j["worst_reference"] = ref;
  if (!o.nonFinite.empty()) j["non_finite"] = o.nonFinite;
  if (o.floatCheck.ran) {
    const auto& f = o.floatCheck;
    Json fc;
    fc["pass"] = f.pass;
    fc["max_deviation"] = number(f.maxDeviation);
    fc["tolerance_over_deviation"] = number(f.ratio);
    fc["worst_vertex"] = f.worstVertex;
    fc["worst_component"] = f.worstComponent;
    fc["not_compared"] = f.notCompared;
    j["float_check"] = fc;
  }
  return j;
}

// The output carrying `semantic` alone (as its first element), or -1.
int outputCarrying(const RunReport& run, const std::string& semantic) {
  for (size_t i = 0; i < run.outputs.size(); ++i)
    if (!run.outputs[i].semantics.empty() && run.outputs[i].semantics.front() == semantic &&
        run.outputs[i].components >= 3)
      return static_cast<int>(i);
  return -1;
}

void appendFloats(std::string& bin, const std::vector<float>& v) {
  static_assert(sizeof(float) == 4);
  const size_t at = bin.size();
  bin.resize(at + v.size() * 4);
  std::memcpy(bin.data() + at, v.data(), v.size() * 4);  // little-endian hosts (x86-64, AArch64)
}

// A glTF 2.0 binary: one node per instance, each a mesh of the primitive's triangles (its
// mode and indices) with the device's world positions (and normals).
std::string posedGlb(const ValidatedPart& part, const RunReport& run, size_t timeIndex, int posOut, int nrmOut) {
  const size_t nv = part.vertices;
  std::string bin;
  Json accessors = Json::array(), views = Json::array(), meshes = Json::array(), nodes = Json::array();
  auto addView = [&](size_t offset, size_t length, int target) {
    Json v;
    v["buffer"] = 0;
    v["byteOffset"] = offset;
    v["byteLength"] = length;
    v["target"] = target;
    views.push_back(v);
    return views.size() - 1;
  };
  int indicesAccessor = -1;
  if (!part.indices.empty()) {
    const size_t at = bin.size();
    bin.resize(at + part.indices.size() * 4);
    std::memcpy(bin.data() + at, part.indices.data(), part.indices.size() * 4);
    Json a;
    a["bufferView"] = addView(at, part.indices.size() * 4, 34963);
    a["componentType"] = 5125;
    a["count"] = part.indices.size();
    a["type"] = "SCALAR";
    accessors.push_back(a);
    indicesAccessor = static_cast<int>(accessors.size() - 1);
  }
  auto vec3 = [&](const std::vector<float>& values, int comps, bool normalize, bool bounds) {
    std::vector<float> out(nv * 3);
    float lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    bool any = false;
    for (size_t v = 0; v < nv; ++v) {
      float p[3] = {values[v * static_cast<size_t>(comps)], values[v * static_cast<size_t>(comps) + 1],
                    values[v * static_cast<size_t>(comps) + 2]};
      if (normalize) {
        float len = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
        if (len > 0 && std::isfinite(len))
          for (float& c : p) c /= len;
      }
      bool finite = std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
      for (int c = 0; c < 3; ++c) {
        out[v * 3 + static_cast<size_t>(c)] = p[c];
        if (!finite) continue;
        lo[c] = any ? std::min(lo[c], p[c]) : p[c];
        hi[c] = any ? std::max(hi[c], p[c]) : p[c];
      }
      any = any || finite;
    }
    const size_t at = bin.size();
    appendFloats(bin, out);
    Json a;
    a["bufferView"] = addView(at, out.size() * 4, 34962);
    a["componentType"] = 5126;
    a["count"] = nv;
    a["type"] = "VEC3";
    if (bounds) {
      a["min"] = {lo[0], lo[1], lo[2]};
      a["max"] = {hi[0], hi[1], hi[2]};
    }
    accessors.push_back(a);
    return accessors.size() - 1;
  };
  for (size_t i = 0; i < part.instances.size(); ++i) {
    const size_t pose = i * part.times.size() + timeIndex;
    Json prim;
    prim["attributes"]["POSITION"] = vec3(run.captured[pose][static_cast<size_t>(posOut)],
                                          run.outputs[static_cast<size_t>(posOut)].components, false, true);
    if (nrmOut >= 0)
      prim["attributes"]["NORMAL"] = vec3(run.captured[pose][static_cast<size_t>(nrmOut)],
                                          run.outputs[static_cast<size_t>(nrmOut)].components, true, false);
    if (indicesAccessor >= 0) prim["indices"] = indicesAccessor;
    prim["mode"] = part.mode;
    Json mesh;
    mesh["name"] = fmt::format("{} instance {}", part.name, i);
    mesh["primitives"] = Json::array({prim});
    meshes.push_back(mesh);
    Json node;
    node["name"] = part.instances[i].name;
    node["mesh"] = i;
    nodes.push_back(node);
  }
  Json g;
  g["asset"]["version"] = "2.0";
  g["asset"]["generator"] = fmt::format("shadergen {} validate --save-outputs", shadergenVersion());
  g["scene"] = 0;
  Json roots = Json::array();
  for (size_t i = 0; i < nodes.size(); ++i) roots.push_back(i);
  g["scenes"] = Json::array({Json{{"nodes", roots}}});
  g["nodes"] = nodes;
  g["meshes"] = meshes;
  g["accessors"] = accessors;
  g["bufferViews"] = views;
  g["buffers"] = Json::array({Json{{"byteLength", bin.size()}}});
  // GLB: 12-byte header, a JSON chunk padded with spaces, a BIN chunk padded with zeros.
  std::string json = g.dump(-1, ' ', false, Json::error_handler_t::replace);
  json.resize((json.size() + 3) / 4 * 4, ' ');
  bin.resize((bin.size() + 3) / 4 * 4, '\0');
  auto u32 = [](std::string& s, uint32_t v) {
    for (int k = 0; k < 4; ++k) s.push_back(static_cast<char>((v >> (8 * k)) & 0xff));
  };
  std::string glb;
  u32(glb, 0x46546C67);  // "glTF"
  u32(glb, 2);
  u32(glb, static_cast<uint32_t>(12 + 8 + json.size() + 8 + bin.size()));
  u32(glb, static_cast<uint32_t>(json.size()));
  u32(glb, 0x4E4F534A);  // "JSON"
  glb += json;
  u32(glb, static_cast<uint32_t>(bin.size()));
  u32(glb, 0x004E4942);  // "BIN\0"
  glb += bin;
  return glb;
}

}  // namespace

std::string validationReportJson(const ValidationContext& ctx, const std::vector<ValidatedPart>& parts) {
  Json r;
  r["shadergen"] = shadergenVersion();
  r["command"] = "validate";
  r["rig"] = ctx.model;
  for (const auto& p : parts)
    if (p.error.empty()) {
      r["device"] = p.report.device;
      r["driver"] = p.report.driver;
      r["running"] = p.report.via;
      r["validation_layers"] = p.report.validationLayers;
      break;
    }
  r["animation"] = ctx.animation;
  r["tolerance"] = {{"abs", ctx.tolerance.abs}, {"rel", ctx.tolerance.rel},
                    {"rule", "|device - reference| <= abs + rel * max(1, largest |reference| component of the output "
                             "at the vertex)"}};
  r["strict"] = ctx.strict;
  bool pass = !parts.empty();
  Json prims = Json::array();
  for (const auto& p : parts) {
    Json j;
    j["name"] = p.name;
    j["rig"] = p.rig;
    if (!p.error.empty()) {
      j["pass"] = false;
      j["error"] = p.error;
      pass = false;
      prims.push_back(j);
      continue;
    }
    j["pass"] = p.report.pass;
    pass = pass && p.report.pass;
    j["vertices"] = p.vertices;
    j["times"] = p.times;
    Json insts = Json::array();
    for (size_t i = 0; i < p.instances.size(); ++i) insts.push_back(instanceJson(p.instances[i], i));
    j["instances"] = insts;
    j["instances_left_out"] = p.instanceNotes;
    Json notes = Json::array();
    for (const auto& n : p.report.notes) notes.push_back(formatDiagnostic(n));
    j["notes"] = notes;
    Json runs = Json::array();
    for (const auto& run : p.report.runs) {
      Json rj;
      rj["label"] = run.label;
      rj["pass"] = run.pass;
      rj["plan_cost"] = run.planCost;
      rj["rules"] = run.rules;
      rj["validation_messages"] = run.validationMessages;
      Json outs = Json::array();
      for (const auto& o : run.outputs) outs.push_back(outputJson(o, true));
      rj["outputs"] = outs;
      Json poses = Json::array();
      for (size_t k = 0; k < run.poseOutputs.size(); ++k) {
        Json pj;
        const size_t nt = std::max<size_t>(1, p.times.size());
        pj["instance"] = k / nt;
        pj["node"] = k / nt < p.instances.size() ? p.instances[k / nt].node : -1;
        pj["time"] = k % nt < p.times.size() ? number(p.times[k % nt]) : Json(nullptr);
        bool posePass = true;
        Json po = Json::array();
        for (const auto& o : run.poseOutputs[k]) {
          posePass = posePass && o.pass;
          po.push_back(outputJson(o, false));
        }
        pj["pass"] = posePass;
        pj["outputs"] = po;
        poses.push_back(pj);
      }
      rj["poses"] = poses;
      runs.push_back(rj);
    }
    j["runs"] = runs;
    prims.push_back(j);
  }
  r["pass"] = pass;
  r["primitives"] = prims;
  return dump(r);
}

std::vector<std::pair<std::string, std::string>> savedOutputFiles(const ValidationContext& ctx,
                                                                   const std::vector<ValidatedPart>& parts) {
  std::vector<std::pair<std::string, std::string>> files;
  Json index;
  index["shadergen"] = shadergenVersion();
  index["rig"] = ctx.model;
  index["animation"] = ctx.animation;
  index["format"] = "every .bin: little-endian float32, `components` values per vertex, `count` vertices "
                    "(integer outputs converted to float32)";
  Json prims = Json::array();
  for (const auto& p : parts) {
    if (!p.error.empty() || p.report.runs.empty() || p.report.runs.front().captured.empty()) continue;
    const RunReport& run = p.report.runs.front();
    Json pj;
    pj["name"] = p.name;
    pj["rig"] = p.rig;
    pj["vertices"] = p.vertices;
    pj["times"] = p.times;
    Json insts = Json::array();
    for (size_t i = 0; i < p.instances.size(); ++i) insts.push_back(instanceJson(p.instances[i], i));
    pj["instances"] = insts;
    const int posOut = outputCarrying(run, "world.position");
    const int nrmOut = outputCarrying(run, "world.normal");
    Json gltfs = Json::array();
    if (posOut >= 0) {
      for (size_t t = 0; t < p.times.size(); ++t) {
        std::string name = fmt::format("{}.t{}.glb", p.name, t);
        files.emplace_back(name, posedGlb(p, run, t, posOut, nrmOut));
        Json g;
        g["file"] = name;
        g["time_index"] = t;
        g["time"] = p.times[t];
        g["position"] = run.outputs[static_cast<size_t>(posOut)].name;
        g["normal"] = nrmOut >= 0 ? Json(run.outputs[static_cast<size_t>(nrmOut)].name) : Json(nullptr);
        gltfs.push_back(g);
      }
    } else {
      pj["gltf_left_out"] = "no output carries world.position (a fragment shader input for it adds one)";
    }
    pj["gltf"] = gltfs;
    Json arrays = Json::array();
    for (size_t k = 0; k < run.captured.size(); ++k) {
      const size_t nt = std::max<size_t>(1, p.times.size());
      for (size_t o = 0; o < run.outputs.size(); ++o) {
        const OutputReport& out = run.outputs[o];
        std::string name = fmt::format("{}.i{}.t{}.{}.bin", p.name, k / nt, k % nt, out.name);
        std::string bytes;
        appendFloats(bytes, run.captured[k][o]);
        files.emplace_back(name, std::move(bytes));
        Json a;
        a["file"] = name;
        a["output"] = out.name;
        a["semantics"] = out.semantics;
        a["type"] = out.type;
        a["component_type"] = "float32";
        a["components"] = out.components;
        a["count"] = p.vertices;
        a["instance"] = k / nt;
        a["node"] = k / nt < p.instances.size() ? p.instances[k / nt].node : -1;
        a["time_index"] = k % nt;
        a["time"] = k % nt < p.times.size() ? number(p.times[k % nt]) : Json(nullptr);
        arrays.push_back(a);
      }
    }
    pj["arrays"] = arrays;
    prims.push_back(pj);
  }
  index["primitives"] = prims;
  files.emplace_back("outputs.json", dump(index));
  return files;
}

}  // namespace sg

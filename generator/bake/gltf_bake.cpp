// glTF side of the bakers (occlusion, tangents). tinygltf's implementation is compiled once, in
// rig/gltf_load.cpp; vertex data is decoded by the rig import (sparse accessors,
// normalized formats) so the baker sees exactly what `rig import` and validation see.
// The same configuration as the implementation (the class's defaults depend on it).
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>

#include "bake/gltf_bake.h"

#include <fmt/format.h>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <sstream>

#include "bake/tangents.h"
#include "common/diagnostics.h"
#include "rig/gltf_import.h"
#include "validate/gltf_scene.h"

namespace sg::bake {
namespace {

[[noreturn]] void fail(const std::string& file, const std::string& msg) { throw InputError(SourceLoc{file, 0, 0}, msg); }

// The primitive's triangles as vertex index triples: strips and fans are expanded; points
// and lines have none (their vertices are baked, but block nothing). The indices are the
// import's (`GltfModelData::indices`: read by the checked accessor reader, sparse accessors
// applied, every index below the vertex count), as `render` draws them.
std::vector<std::array<uint32_t, 3>> primitiveTriangles(const tinygltf::Primitive& p, const GltfModelData& d,
                                                        const std::string& file) {
  std::vector<uint32_t> idx;
  if (p.indices >= 0) {
    if (!d.indicesError.empty()) fail(file, d.indicesError);
    idx = d.indices;
  } else {
    idx.resize(d.vertexCount);
    for (size_t i = 0; i < d.vertexCount; ++i) idx[i] = static_cast<uint32_t>(i);
  }
  std::vector<std::array<uint32_t, 3>> tris;
  int mode = p.mode < 0 ? TINYGLTF_MODE_TRIANGLES : p.mode;
  if (mode == TINYGLTF_MODE_TRIANGLES) {
    for (size_t i = 0; i + 2 < idx.size(); i += 3) tris.push_back({idx[i], idx[i + 1], idx[i + 2]});
  } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
    for (size_t i = 0; i + 2 < idx.size(); ++i)
      tris.push_back(i % 2 ? std::array<uint32_t, 3>{idx[i + 1], idx[i], idx[i + 2]}
                           : std::array<uint32_t, 3>{idx[i], idx[i + 1], idx[i + 2]});
  } else if (mode == TINYGLTF_MODE_TRIANGLE_FAN) {
    for (size_t i = 1; i + 1 < idx.size(); ++i) tris.push_back({idx[0], idx[i], idx[i + 1]});
  }
  return tris;
}

struct PrimitiveData {
  int mesh = 0, primitive = 0;
  GltfImport imp;
  std::vector<std::array<uint32_t, 3>> triangles;
};

// A node drawing a mesh (node -1: a mesh no node instantiates, drawn at the origin).
struct Instance {
  int node = -1;
  int mesh = 0;
};

struct Posed {
  std::vector<Vec3> positions, normals;
};

Vec3 toVec3(const glm::dvec3& v) { return {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)}; }
glm::dvec3 at3(const std::vector<std::array<float, 4>>& s, size_t i) { return glm::dvec3(s[i][0], s[i][1], s[i][2]); }

// The primitive drawn by `inst` with morph target `target` at weight 1 (-1: the base shape),
// in world space. Unskinned: the node's global transform. Skinned: the stored (bind-pose)
// positions, or, at an animation time, linear blend skinning with global(joint)·IBM as the
// renderer does. Normals: the stored normal (+ the target's delta) through the inverse
// transpose; without NORMAL, area-weighted face normals of the posed triangles.
Posed posePrimitive(const PrimitiveData& p, const Instance& inst, int target, const std::vector<glm::dmat4>& G,
                    bool animated) {
  const GltfModelData& d = p.imp.data;
  const size_t n = d.vertexCount;
  const auto& pos = d.streams.at("vertex.position");
  const std::vector<std::array<float, 4>>* dpos = nullptr;
  const std::vector<std::array<float, 4>>* nrm = nullptr;
  const std::vector<std::array<float, 4>>* dnrm = nullptr;
  if (target >= 0) {
    if (auto it = d.streams.find(fmt::format("morph.position[{}]", target)); it != d.streams.end()) dpos = &it->second;
    if (auto it = d.streams.find(fmt::format("morph.normal[{}]", target)); it != d.streams.end()) dnrm = &it->second;
  }
  if (auto it = d.streams.find("vertex.normal"); it != d.streams.end()) nrm = &it->second;

  const GltfNode* node = inst.node >= 0 ? &d.nodes[static_cast<size_t>(inst.node)] : nullptr;
  int skin = node ? node->skin : -1;
  bool skinned = skin >= 0 && skin < static_cast<int>(d.skins.size()) && d.streams.count("skin.joints[0]");
  std::vector<glm::dmat4> joints;
  if (skinned && animated) {
    const GltfSkin& s = d.skins[static_cast<size_t>(skin)];
    for (size_t j = 0; j < s.joints.size(); ++j) {
      glm::dmat4 ibm;
      for (int c = 0; c < 4; ++c)
        for (int k = 0; k < 4; ++k) ibm[c][k] = s.inverseBind[j][static_cast<size_t>(c * 4 + k)];
      joints.push_back(G[static_cast<size_t>(s.joints[j])] * ibm);
    }
  }
  glm::dmat4 nodeM = node && !skinned ? G[static_cast<size_t>(inst.node)] : glm::dmat4(1.0);

  Posed out;
  out.positions.resize(n);
  out.normals.resize(n);
  for (size_t v = 0; v < n; ++v) {
    glm::dmat4 M = nodeM;
    if (!joints.empty()) {
      M = glm::dmat4(0.0);
      for (int s = 0; s < kMaxInfluenceSets; ++s) {
        auto jt = d.streams.find(fmt::format("skin.joints[{}]", s));
        auto wt = d.streams.find(fmt::format("skin.weights[{}]", s));
        if (jt == d.streams.end() || wt == d.streams.end()) break;
        for (size_t c = 0; c < 4; ++c) {
          double w = wt->second[v][c];
          size_t j = static_cast<size_t>(jt->second[v][c]);  // checked against the import's skin
          if (j >= joints.size())
            throw InputError(SourceLoc{d.file, 0, 0},
                             fmt::format("node '{}' draws mesh '{}' with skin {}, which has {} joints; vertex {} uses "
                                         "joint {}",
                                         node->name, d.meshName, skin, joints.size(), v, j));
          if (w != 0) M += w * joints[j];
        }
      }
    }
    glm::dvec3 p3 = at3(pos, v) + (dpos ? at3(*dpos, v) : glm::dvec3(0.0));
    out.positions[v] = toVec3(glm::dvec3(M * glm::dvec4(p3, 1.0)));
    if (nrm) {
      glm::dvec3 n3 = at3(*nrm, v) + (dnrm ? at3(*dnrm, v) : glm::dvec3(0.0));
      glm::dmat3 N = glm::transpose(glm::inverse(glm::dmat3(M)));
      glm::dvec3 w = N * n3;
      double len = glm::length(w);
      out.normals[v] = len > 0 && std::isfinite(len) ? toVec3(w / len) : Vec3{0, 0, 0};
    }
  }
  if (!nrm) {
    std::vector<glm::dvec3> acc(n, glm::dvec3(0.0));
    for (const auto& t : p.triangles) {
      glm::dvec3 a(out.positions[t[0]][0], out.positions[t[0]][1], out.positions[t[0]][2]);
      glm::dvec3 b(out.positions[t[1]][0], out.positions[t[1]][1], out.positions[t[1]][2]);
      glm::dvec3 c(out.positions[t[2]][0], out.positions[t[2]][1], out.positions[t[2]][2]);
      glm::dvec3 f = glm::cross(b - a, c - a);  // |f| = twice the area: area weighting
      for (uint32_t k : t) acc[k] += f;
    }
    for (size_t v = 0; v < n; ++v) {
      double len = glm::length(acc[v]);
      out.normals[v] = len > 0 ? toVec3(acc[v] / len) : Vec3{0, 0, 0};
    }
  }
  return out;
}

TriangleSoup soupOf(const Posed& posed, const std::vector<std::array<uint32_t, 3>>& tris) {
  TriangleSoup s;
  s.positions = posed.positions;
  s.triangles = tris;
  return s;
}

uint64_t mix(uint64_t a, uint64_t b) {
  uint64_t x = a * 0x9e3779b97f4a7c15ull + b + 0x632be59bd9b4e019ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}
// The random stream of a vertex: a function of (mesh, primitive, target, vertex) only.
uint64_t streamOf(int mesh, int primitive, int target, size_t vertex) {
  return mix(mix(mix(static_cast<uint64_t>(mesh), static_cast<uint64_t>(primitive)),
                 static_cast<uint64_t>(target + 1)),
             vertex);
}

// Appends `values` (`components` floats per element: SCALAR, VEC3 or VEC4) as an accessor in
// buffer 0 and returns its index.
int appendFloatAccessor(tinygltf::Model& m, const std::vector<float>& values, int components) {
  if (m.buffers.empty()) m.buffers.emplace_back();
  auto& buf = m.buffers[0].data;
  while (buf.size() % 4) buf.push_back(0);
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = buf.size();
  view.byteLength = values.size() * sizeof(float);
  view.target = TINYGLTF_TARGET_ARRAY_BUFFER;
  buf.resize(buf.size() + view.byteLength);
  if (!values.empty()) std::memcpy(buf.data() + view.byteOffset, values.data(), view.byteLength);
  m.bufferViews.push_back(view);
  tinygltf::Accessor a;
  a.bufferView = static_cast<int>(m.bufferViews.size()) - 1;
  a.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
  a.type = components == 1 ? TINYGLTF_TYPE_SCALAR : components == 3 ? TINYGLTF_TYPE_VEC3 : TINYGLTF_TYPE_VEC4;
  const size_t c = static_cast<size_t>(components);
  a.count = values.size() / c;
  if (a.count > 0) {  // min and max per component (required for morph target POSITION only; kept for all)
    a.minValues.assign(c, std::numeric_limits<double>::infinity());
    a.maxValues.assign(c, -std::numeric_limits<double>::infinity());
    for (size_t i = 0; i < values.size(); ++i) {
      a.minValues[i % c] = std::min<double>(a.minValues[i % c], values[i]);
      a.maxValues[i % c] = std::max<double>(a.maxValues[i % c], values[i]);
    }
  }
  m.accessors.push_back(a);
  return static_cast<int>(m.accessors.size()) - 1;
}

// Every primitive of the model decoded as the rig import decodes it, with its triangles.
std::vector<PrimitiveData> decodePrimitives(const tinygltf::Model& model, size_t inputBytes, const std::string& file) {
  if (model.meshes.empty()) fail(file, "the model has no meshes: nothing to bake");
  std::vector<PrimitiveData> prims;
  for (size_t m = 0; m < model.meshes.size(); ++m)
    for (size_t p = 0; p < model.meshes[m].primitives.size(); ++p) {
      PrimitiveData d;
      d.mesh = static_cast<int>(m);
      d.primitive = static_cast<int>(p);
      GltfImportOptions io;
      io.mesh = d.mesh;
      io.primitive = d.primitive;
      d.imp = importGltfModel(model, inputBytes, file, io);  // parsed once, not per primitive
      d.triangles = primitiveTriangles(model.meshes[m].primitives[p], d.imp.data, file);
      prims.push_back(std::move(d));
    }
  if (prims.empty()) fail(file, "the model's meshes have no primitives: nothing to bake");
  return prims;
}

// tinygltf writes an object that has only default members as `null` (`nodes: [{}]`, an empty
// scene or texture, all valid glTF) and a perspective camera's absent `zfar` (infinite) as 0:
// both make the output invalid, and our own loader refuses it. Returns whether it changed `j`.
bool repairTinygltfJson(nlohmann::json& j) {
  bool changed = false;
  for (auto& [key, value] : j.items())
    if (value.is_array())
      for (auto& e : value)
        if (e.is_null()) e = nlohmann::json::object(), changed = true;
  if (j.contains("cameras") && j["cameras"].is_array())
    for (auto& c : j["cameras"]) {
      auto p = c.find("perspective");
      if (p == c.end() || !p->is_object()) continue;
      auto z = p->find("zfar");
      if (z != p->end() && z->is_number() && z->get<double>() == 0) p->erase(z), changed = true;
    }
  return changed;
}

uint32_t readU32(const std::string& s, size_t at) {
  uint32_t v;
  std::memcpy(&v, s.data() + at, 4);
  return v;
}
void putU32(std::string& s, uint32_t v) { s.append(reinterpret_cast<const char*>(&v), 4); }

// tinygltf's output with its JSON repaired (repairTinygltfJson); byte-identical when nothing
// needed it. A GLB is rebuilt around the new JSON chunk, its BIN chunk copied as it was.
std::string repairSerialised(const std::string& bytes, bool binary) {
  if (!binary) {
    nlohmann::json j = nlohmann::json::parse(bytes);
    return repairTinygltfJson(j) ? j.dump(2) + "\n" : bytes;
  }
  const size_t jsonLen = readU32(bytes, 12);  // header 12 bytes, then the JSON chunk's length
  nlohmann::json j = nlohmann::json::parse(bytes.substr(20, jsonLen));
  if (!repairTinygltfJson(j)) return bytes;
  std::string json = j.dump();
  json.append((4 - json.size() % 4) % 4, ' ');
  const std::string rest = bytes.substr(20 + jsonLen);  // the BIN chunk, if any
  std::string out = bytes.substr(0, 8);
  putU32(out, static_cast<uint32_t>(20 + json.size() + rest.size()));
  putU32(out, static_cast<uint32_t>(json.size()));
  out += bytes.substr(16, 4);  // "JSON"
  return out + json + rest;
}

// The output file: every buffer embedded (buffer 0 in the GLB binary chunk, the others as
// data URIs); `inputs` gets the model and its buffer files, `notes` the images left external.
std::string serialise(tinygltf::Model& model, const std::string& file, bool binary, std::vector<std::string>& inputs,
                      std::vector<std::string>& notes) {
  for (const auto& img : model.images)
    if (!img.uri.empty() && img.uri.rfind("data:", 0) != 0)
      notes.push_back(fmt::format("image '{}' stays an external reference ('{}'), relative to the output file",
                                  img.name, img.uri));
  inputs.push_back(file);
  for (const auto& b : model.buffers)
    if (!b.uri.empty() && b.uri.rfind("data:", 0) != 0)
      inputs.push_back((std::filesystem::path(file).parent_path() / b.uri).string());
  for (auto& b : model.buffers) b.uri.clear();
  tinygltf::TinyGLTF writer;
  std::ostringstream os;
  if (!writer.WriteGltfSceneToStream(&model, os, !binary, binary)) fail(file, "cannot serialise the baked model");
  return repairSerialised(os.str(), binary);
}

std::vector<Vec3> vec3Stream(const GltfModelData& d, const std::string& name) {
  std::vector<Vec3> out;
  for (const auto& v : d.streams.at(name)) out.push_back({v[0], v[1], v[2]});
  return out;
}

}  // namespace

GltfBakeResult bakeGltfOcclusion(const std::string& file, const GltfBakeOptions& opts) {
  tinygltf::Model model;
  size_t inputBytes = loadGltfModel(file, model);  // the rig import's checked loader (docs/limits.md)
  GltfBakeResult result;

  std::vector<PrimitiveData> prims = decodePrimitives(model, inputBytes, file);
  std::map<std::pair<int, int>, size_t> primIndex;
  for (size_t i = 0; i < prims.size(); ++i) primIndex[{prims[i].mesh, prims[i].primitive}] = i;
  const GltfModelData& sceneData = prims[0].imp.data;  // nodes, skins, animations: the same for all

  int anim = -1;
  double t = 0;
  if (opts.time) {
    anim = findGltfAnimation(sceneData, opts.animation);
    t = *opts.time;
  }
  std::vector<glm::dmat4> G = gltfNodeGlobals(sceneData, anim, t);

  // Instances: every node of the scene drawing a mesh (gltfSceneNodes' order), then each
  // primitive's baking instance (the node the rig import poses it with) if the scene does not
  // already hold it.
  std::vector<Instance> instances;
  for (int n : gltfSceneNodes(sceneData)) {
    const GltfNode& node = sceneData.nodes[static_cast<size_t>(n)];
    if (node.mesh >= 0 && node.mesh < static_cast<int>(model.meshes.size())) instances.push_back({n, node.mesh});
  }
  std::vector<size_t> bakeInstance(prims.size());
  for (size_t i = 0; i < prims.size(); ++i) {
    int node = prims[i].imp.data.meshNode;
    auto it = std::find_if(instances.begin(), instances.end(),
                           [&](const Instance& x) { return x.node == node && x.mesh == prims[i].mesh; });
    if (it == instances.end()) {
      instances.push_back({node, prims[i].mesh});
      it = instances.end() - 1;
    }
    bakeInstance[i] = static_cast<size_t>(it - instances.begin());
  }

  // The base scene: every instance of every primitive at its base shape.
  struct Piece {
    size_t instance, prim;
    Posed posed;
  };
  std::vector<Piece> pieces;
  for (size_t i = 0; i < instances.size(); ++i)
    for (size_t p = 0; p < model.meshes[static_cast<size_t>(instances[i].mesh)].primitives.size(); ++p) {
      size_t pi = primIndex.at({instances[i].mesh, static_cast<int>(p)});
      pieces.push_back({i, pi, posePrimitive(prims[pi], instances[i], -1, G, opts.time.has_value())});
    }
  auto sceneWithout = [&](size_t skipInstance, size_t skipPrim) {
    TriangleSoup s;
    for (const auto& pc : pieces)
      if (!(pc.instance == skipInstance && pc.prim == skipPrim)) s.append(soupOf(pc.posed, prims[pc.prim].triangles));
    return s;
  };
  TriangleSoup base = sceneWithout(SIZE_MAX, SIZE_MAX);
  result.triangles = base.triangles.size();

  OcclusionOptions occ = opts.occlusion;
  occ.offset = occ.offset >= 0 ? occ.offset : defaultOffset(base);
  int passes = 1;
  for (const auto& p : prims) passes += p.imp.morphTargets;
  result.passes = passes;
  int pass = 0;
  auto bakePass = [&](const TriangleSoup& scene, const std::vector<BakePoint>& points, const std::string& what) {
    ++pass;
    OcclusionOptions o = occ;
    o.progress = nullptr;
    if (opts.progress)
      o.progress = [&, what](size_t done, size_t total) { opts.progress(pass, passes, what, done, total); };
    result.rays += points.size() * static_cast<size_t>(o.rays);
    return bakeOcclusion(*makeEmbreeCaster(scene), points, o, o.offset);
  };

  // Pass 1: every primitive's base shape at its baking instance.
  std::vector<BakePoint> points;
  std::vector<size_t> firstPoint(prims.size());
  std::vector<const Posed*> bakedPose(prims.size());
  size_t noNormal = 0;
  for (size_t i = 0; i < prims.size(); ++i) {
    auto pc = std::find_if(pieces.begin(), pieces.end(),
                           [&](const Piece& x) { return x.instance == bakeInstance[i] && x.prim == i; });
    bakedPose[i] = &pc->posed;
    firstPoint[i] = points.size();
    for (size_t v = 0; v < pc->posed.positions.size(); ++v) {
      points.push_back({pc->posed.positions[v], pc->posed.normals[v], streamOf(prims[i].mesh, prims[i].primitive, -1, v)});
      if (pc->posed.normals[v] == Vec3{0, 0, 0}) ++noNormal;
    }
  }
  std::vector<float> baseOcc = bakePass(base, points, "base shape");
  if (noNormal)
    result.notes.push_back(fmt::format("{} vertex(es) have no normal (no NORMAL and no triangle uses them, or a zero "
                                       "normal): their occlusion is 0",
                                       noNormal));

  // One pass per morph target: that primitive's instance swapped for its target shape.
  std::vector<std::vector<std::vector<float>>> deltas(prims.size());
  for (size_t i = 0; i < prims.size(); ++i) {
    const PrimitiveData& p = prims[i];
    size_t n = p.imp.data.vertexCount;
    for (int tgt = 0; tgt < p.imp.morphTargets; ++tgt) {
      Posed shape = posePrimitive(p, instances[bakeInstance[i]], tgt, G, opts.time.has_value());
      TriangleSoup scene = sceneWithout(bakeInstance[i], i);
      scene.append(soupOf(shape, p.triangles));
      std::vector<BakePoint> tp;
      for (size_t v = 0; v < n; ++v) tp.push_back({shape.positions[v], shape.normals[v], streamOf(p.mesh, p.primitive, tgt, v)});
      std::vector<float> occT =
          bakePass(scene, tp, fmt::format("mesh '{}' primitive {} target {}", p.imp.data.meshName, p.primitive, tgt));
      std::vector<float> d(n);
      for (size_t v = 0; v < n; ++v) d[v] = occT[v] - baseOcc[firstPoint[i] + v];
      deltas[i].push_back(std::move(d));
    }
  }

  // Store: _OCCLUSION on the primitive and on each of its targets.
  bool replaced = false;
  for (size_t i = 0; i < prims.size(); ++i) {
    const PrimitiveData& p = prims[i];
    size_t n = p.imp.data.vertexCount;
    std::vector<float> values(baseOcc.begin() + static_cast<long>(firstPoint[i]),
                              baseOcc.begin() + static_cast<long>(firstPoint[i] + n));
    auto& prim = model.meshes[static_cast<size_t>(p.mesh)].primitives[static_cast<size_t>(p.primitive)];
    replaced |= prim.attributes.count("_OCCLUSION") != 0;
    prim.attributes["_OCCLUSION"] = appendFloatAccessor(model, values, 1);
    BakedPrimitive bp;
    bp.mesh = p.mesh;
    bp.primitive = p.primitive;
    bp.meshName = p.imp.data.meshName;
    bp.vertices = n;
    bp.targets = p.imp.morphTargets;
    double sum = 0;
    for (float v : values) sum += v;
    bp.meanOcclusion = n ? sum / static_cast<double>(n) : 0;
    for (int tgt = 0; tgt < p.imp.morphTargets; ++tgt) {
      const auto& d = deltas[i][static_cast<size_t>(tgt)];
      prim.targets[static_cast<size_t>(tgt)]["_OCCLUSION"] = appendFloatAccessor(model, d, 1);
      double s = 0;
      for (float v : d) s += std::fabs(v);
      bp.meanAbsTargetDelta.push_back(n ? s / static_cast<double>(n) : 0);
    }
    result.primitives.push_back(std::move(bp));
  }
  if (replaced) result.notes.push_back("the model already had _OCCLUSION attributes: they are replaced");
  result.bytes = serialise(model, file, opts.binary, result.inputs, result.notes);
  return result;
}


GltfTangentResult bakeGltfTangents(const std::string& file, bool binary) {
  tinygltf::Model model;
  size_t inputBytes = loadGltfModel(file, model);
  GltfTangentResult result;
  for (const PrimitiveData& p : decodePrimitives(model, inputBytes, file)) {
    const GltfModelData& d = p.imp.data;
    const std::string where = fmt::format("mesh '{}' primitive {}", d.meshName, p.primitive);
    auto& prim = model.meshes[static_cast<size_t>(p.mesh)].primitives[static_cast<size_t>(p.primitive)];
    if (prim.attributes.count("TANGENT")) {
      result.notes.push_back(where + " keeps its own TANGENT");
      continue;
    }
    if (!d.streams.count("vertex.normal") || !d.streams.count("vertex.texcoord0")) {
      result.notes.push_back(where + " has no NORMAL or no TEXCOORD_0: no tangents");
      continue;
    }
    if (p.triangles.empty()) {
      result.notes.push_back(where + " has no triangles: no tangents");
      continue;
    }
    std::vector<Vec2> uvs;
    for (const auto& v : d.streams.at("vertex.texcoord0")) uvs.push_back({v[0], v[1]});
    std::vector<Vec3> pos = vec3Stream(d, "vertex.position"), nrm = vec3Stream(d, "vertex.normal");
    TangentResult base = bakeTangents(pos, nrm, uvs, p.triangles);
    std::vector<float> flat;
    for (const Vec4& t : base.tangents) flat.insert(flat.end(), t.begin(), t.end());
    prim.attributes["TANGENT"] = appendFloatAccessor(model, flat, 4);
    // Each target's shape gets its own frames; its TANGENT delta is the difference of xyz
    // (glTF morphs no handedness).
    for (int tgt = 0; tgt < p.imp.morphTargets; ++tgt) {
      std::vector<Vec3> tp = pos, tn = nrm;
      auto add = [&](std::vector<Vec3>& to, const std::string& name) {
        auto it = d.streams.find(fmt::format("{}[{}]", name, tgt));
        if (it == d.streams.end()) return;
        for (size_t v = 0; v < to.size(); ++v)
          for (int c = 0; c < 3; ++c) to[v][static_cast<size_t>(c)] += it->second[v][static_cast<size_t>(c)];
      };
      add(tp, "morph.position");
      add(tn, "morph.normal");
      TangentResult shape = bakeTangents(tp, tn, uvs, p.triangles);
      std::vector<float> delta;
      for (size_t v = 0; v < pos.size(); ++v)
        for (size_t c = 0; c < 3; ++c) delta.push_back(shape.tangents[v][c] - base.tangents[v][c]);
      prim.targets[static_cast<size_t>(tgt)]["TANGENT"] = appendFloatAccessor(model, delta, 3);
    }
    result.primitives.push_back({p.mesh, p.primitive, d.meshName, d.vertexCount, p.imp.morphTargets, base.fallbacks});
  }
  result.bytes = serialise(model, file, binary, result.inputs, result.notes);
  return result;
}

}  // namespace sg::bake

// The glTF baker on models built here (tinygltf writes them): a box whose morph target
// closes its lid (the delta is the known jump from the open box's fraction to 1), a lid
// moved over a floor by an animation (--time), determinism and hostile inputs; then shared
// models baked, imported and validated on lavapipe end to end.
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <sys/wait.h>
#include <unistd.h>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "../core/core_test_util.h"
#include "bake/gltf_bake.h"
#include "common/diagnostics.h"
#include "rig/gltf_import.h"

namespace sg::bake {
namespace {

namespace fs = std::filesystem;
constexpr double kZ99 = 2.5758293035489;

fs::path tempDir() { return sgtest::freshDir("bake"); }

std::string readFile(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}
void writeFile(const fs::path& p, const std::string& bytes) { sgtest::writeText(p, bytes); }

// --- building models ---------------------------------------------------------------------
struct Mesh {
  std::vector<float> positions, normals;  // xyz per vertex
  std::vector<uint32_t> indices;
  std::vector<std::vector<float>> targetPositions;  // xyz deltas per target
  void quad(std::array<float, 3> a, std::array<float, 3> b, std::array<float, 3> c, std::array<float, 3> d,
            std::array<float, 3> n) {
    uint32_t base = static_cast<uint32_t>(positions.size() / 3);
    for (auto& p : {a, b, c, d}) {
      positions.insert(positions.end(), p.begin(), p.end());
      normals.insert(normals.end(), n.begin(), n.end());
    }
    indices.insert(indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
  }
  size_t vertices() const { return positions.size() / 3; }
};

int addAccessor(tinygltf::Model& m, const void* data, size_t bytes, int componentType, int type, size_t count) {
  auto& buf = m.buffers[0].data;
  tinygltf::BufferView v;
  v.buffer = 0;
  v.byteOffset = buf.size();
  v.byteLength = bytes;
  buf.insert(buf.end(), static_cast<const unsigned char*>(data), static_cast<const unsigned char*>(data) + bytes);
  m.bufferViews.push_back(v);
  tinygltf::Accessor a;
  a.bufferView = static_cast<int>(m.bufferViews.size()) - 1;
  a.componentType = componentType;
  a.type = type;
  a.count = count;
  m.accessors.push_back(a);
  return static_cast<int>(m.accessors.size()) - 1;
}

int addMesh(tinygltf::Model& m, const Mesh& mesh) {
  if (m.buffers.empty()) m.buffers.emplace_back();
  size_t n = mesh.vertices();
  tinygltf::Primitive p;
  int pos = addAccessor(m, mesh.positions.data(), mesh.positions.size() * 4, TINYGLTF_COMPONENT_TYPE_FLOAT,
                        TINYGLTF_TYPE_VEC3, n);
  std::vector<double> lo{1e30, 1e30, 1e30}, hi{-1e30, -1e30, -1e30};
  for (size_t i = 0; i < n; ++i)
    for (size_t c = 0; c < 3; ++c) lo[c] = std::min(lo[c], double(mesh.positions[3 * i + c])), hi[c] = std::max(hi[c], double(mesh.positions[3 * i + c]));
  m.accessors[static_cast<size_t>(pos)].minValues = lo;
  m.accessors[static_cast<size_t>(pos)].maxValues = hi;
  p.attributes["POSITION"] = pos;
  if (!mesh.normals.empty())
    p.attributes["NORMAL"] = addAccessor(m, mesh.normals.data(), mesh.normals.size() * 4, TINYGLTF_COMPONENT_TYPE_FLOAT,
                                         TINYGLTF_TYPE_VEC3, n);
  p.indices = addAccessor(m, mesh.indices.data(), mesh.indices.size() * 4, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT,
                          TINYGLTF_TYPE_SCALAR, mesh.indices.size());
  for (const auto& t : mesh.targetPositions)
    p.targets.push_back({{"POSITION", addAccessor(m, t.data(), t.size() * 4, TINYGLTF_COMPONENT_TYPE_FLOAT,
                                                  TINYGLTF_TYPE_VEC3, n)}});
  p.mode = TINYGLTF_MODE_TRIANGLES;
  tinygltf::Mesh gm;
  gm.primitives.push_back(p);
  gm.weights.assign(mesh.targetPositions.size(), 0.0);
  m.meshes.push_back(gm);
  return static_cast<int>(m.meshes.size()) - 1;
}

// A one-quad model (one node, one scene) as JSON, for tests that add what tinygltf cannot write.
nlohmann::json quadModelJson() {
  tinygltf::Model m;
  Mesh quad;
  quad.quad({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1});
  addMesh(m, quad);
  m.nodes.emplace_back();
  m.nodes[0].mesh = 0;
  m.scenes.push_back({});
  m.scenes[0].nodes = {0};
  m.asset.version = "2.0";
  tinygltf::TinyGLTF w;
  std::ostringstream os;
  EXPECT_TRUE(w.WriteGltfSceneToStream(&m, os, true, false));
  return nlohmann::json::parse(os.str());
}

void save(tinygltf::Model& m, const fs::path& file);

// A model whose scene is one node drawing `mesh`, saved as `file`.
void saveSingleMesh(const Mesh& mesh, const fs::path& file) {
  tinygltf::Model m;
  addMesh(m, mesh);
  m.nodes.emplace_back();
  m.nodes[0].mesh = 0;
  m.scenes.push_back({});
  m.scenes[0].nodes = {0};
  save(m, file);
}

void save(tinygltf::Model& m, const fs::path& file) {
  m.asset.version = "2.0";
  tinygltf::TinyGLTF w;
  std::ostringstream os;
  ASSERT_TRUE(w.WriteGltfSceneToStream(&m, os, false, true));
  writeFile(file, os.str());
}

// An open box: floor [-1,1]² at z = 0 (a fan around its centre, vertex 0), walls up to z = 1,
// normals inward. A lid lies in the plane z = 1 but beside the box (x in [3, 5]), where no
// ray from inside crosses that plane; its morph target slides it over the opening.
Mesh cavityBox() {
  Mesh b;
  b.positions = {0, 0, 0};
  b.normals = {0, 0, 1};
  float c[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  for (auto& p : c) b.positions.insert(b.positions.end(), {p[0], p[1], 0}), b.normals.insert(b.normals.end(), {0, 0, 1});
  for (uint32_t i = 0; i < 4; ++i) b.indices.insert(b.indices.end(), {0, 1 + i, 1 + (i + 1) % 4});
  b.quad({-1, -1, 0}, {1, -1, 0}, {1, -1, 1}, {-1, -1, 1}, {0, 1, 0});
  b.quad({1, 1, 0}, {-1, 1, 0}, {-1, 1, 1}, {1, 1, 1}, {0, -1, 0});
  b.quad({-1, 1, 0}, {-1, -1, 0}, {-1, -1, 1}, {-1, 1, 1}, {1, 0, 0});
  b.quad({1, -1, 0}, {1, 1, 0}, {1, 1, 1}, {1, -1, 1}, {-1, 0, 0});
  size_t before = b.vertices();
  b.quad({3, -1, 1}, {5, -1, 1}, {5, 1, 1}, {3, 1, 1}, {0, 0, -1});
  std::vector<float> delta(b.positions.size(), 0.0f);
  for (size_t v = before; v < b.vertices(); ++v) delta[3 * v] = -4.0f;  // x in [3, 5] -> [-1, 1]
  b.targetPositions.push_back(delta);
  return b;
}

// The open box seen from the centre of its floor: the opening is a 2×2 square at height 1.
// Solid angle of a centred a×b rectangle at distance d: 4·asin(ab/√((a²+4d²)(b²+4d²))) =
// 2π/3, so 1/3 of the hemisphere is open (uniform). Cosine: four corner pieces of the
// parallel-rectangle view factor (1/2π)[X/√(1+X²)·atan(Y/√(1+X²)) + (X↔Y)], X = Y = 1.
const double kOpenUniform = 1.0 / 3.0;
const double kOpenCosine = 4.0 / M_PI * M_SQRT1_2 * std::atan(M_SQRT1_2);

GltfImport bakeAndImport(const fs::path& in, const fs::path& out, GltfBakeOptions o) {
  GltfBakeResult r = bakeGltfOcclusion(in.string(), o);
  writeFile(out, r.bytes);
  return importGltf(out.string());
}

void expectWithinBound(double estimate, double p, int rays, const std::string& what) {
  double bound = kZ99 * std::sqrt(p * (1 - p) / rays);
  EXPECT_LE(std::fabs(estimate - p), bound) << what << ": estimate " << estimate << ", exact " << p;
}

TEST(GltfBake, MorphTargetClosingACavityGetsTheRightDelta) {
  fs::path dir = tempDir();
  saveSingleMesh(cavityBox(), dir / "cavity.glb");
  for (auto [dist, open] : {std::pair{Distribution::Uniform, kOpenUniform}, std::pair{Distribution::Cosine, kOpenCosine}}) {
    GltfBakeOptions o;
    o.occlusion.rays = 16384;
    o.occlusion.distribution = dist;
    GltfImport imp = bakeAndImport(dir / "cavity.glb", dir / "cavity.baked.glb", o);
    ASSERT_TRUE(imp.data.streams.count("vertex.occlusion"));
    ASSERT_TRUE(imp.data.streams.count("morph.occlusion[0]"));
    float base = imp.data.streams["vertex.occlusion"][0][0];
    float delta = imp.data.streams["morph.occlusion[0]"][0][0];
    expectWithinBound(base, 1 - open, o.occlusion.rays, "open box, floor centre");
    // Closed: every ray is blocked, so base + delta is 1 (a ray exactly along a seam aside).
    EXPECT_GE(base + delta, 1.0f - 1.0f / o.occlusion.rays);
    expectWithinBound(delta, open, o.occlusion.rays, "delta of the closing target");
    // The rig import maps them for the rules.
    bool hasOcc = false, hasOccMorph = false;
    for (const auto& a : imp.rig.attributes)
      for (const auto& p : a.provides) {
        hasOcc |= p.semantic == "vertex.occlusion";
        hasOccMorph |= p.semantic == "morph.occlusion" && a.perMorphTarget;
      }
    EXPECT_TRUE(hasOcc);
    EXPECT_TRUE(hasOccMorph);
    EXPECT_EQ(imp.rig.param("morph_targets"), 1);
  }
  // Dawn's layout: occlusion in normal.w, deltas in the normal deltas' w (no NORMAL deltas
  // here, so they stay separate: a note says so).
  GltfImportOptions io;
  io.packOcclusionInNormal = true;
  GltfImport packed = importGltf((dir / "cavity.baked.glb").string(), io);
  bool normalW = false;
  for (const auto& a : packed.rig.attributes)
    if (a.name == "normal")
      normalW = formatComponents(a.format) == 4 && a.provides.size() == 2 && a.provides[1].semantic == "vertex.occlusion";
  EXPECT_TRUE(normalW);
  fs::remove_all(dir);
}

// Two meshes: a floor, and a 2×2 lid that an animation moves from far away (t = 0) to
// height 1 over the floor's centre (t = 1). The whole scene occludes, posed at --time.
// Unskinned, the lid's node moves; skinned, the lid is stored far away (its bind pose) and
// its joint carries it over the floor (the skinned node's own transform is ignored).
void animatedLid(bool skinned) {
  fs::path dir = tempDir();
  tinygltf::Model m;
  Mesh floor, lid;
  floor.positions = {0, 0, 0};
  floor.normals = {0, 0, 1};
  float c[4][2] = {{-9, -9}, {9, -9}, {9, 9}, {-9, 9}};
  for (auto& p : c) floor.positions.insert(floor.positions.end(), {p[0], p[1], 0}), floor.normals.insert(floor.normals.end(), {0, 0, 1});
  for (uint32_t i = 0; i < 4; ++i) floor.indices.insert(floor.indices.end(), {0, 1 + i, 1 + (i + 1) % 4});
  float x0 = skinned ? 100.0f : 0.0f, z0 = skinned ? 1.0f : 0.0f;  // stored lid: far away when skinned
  lid.quad({x0 - 1, -1, z0}, {x0 + 1, -1, z0}, {x0 + 1, 1, z0}, {x0 - 1, 1, z0}, {0, 0, -1});
  addMesh(m, floor);
  addMesh(m, lid);
  m.nodes.resize(skinned ? 3 : 2);
  m.nodes[0].mesh = 0;
  m.nodes[1].mesh = 1;
  m.nodes[1].translation = {100, 0, 1};
  int animated = 1;
  if (skinned) {
    std::vector<uint8_t> joints(16, 0);
    std::vector<float> weights{1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    auto& prim = m.meshes[1].primitives[0];
    prim.attributes["JOINTS_0"] = addAccessor(m, joints.data(), 16, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_TYPE_VEC4, 4);
    prim.attributes["WEIGHTS_0"] = addAccessor(m, weights.data(), 64, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC4, 4);
    std::vector<float> ibm{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -100, 0, -1, 1};  // joint rest at (100, 0, 1)
    tinygltf::Skin skin;
    skin.joints = {2};
    skin.inverseBindMatrices = addAccessor(m, ibm.data(), 64, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_MAT4, 1);
    m.skins.push_back(skin);
    m.nodes[1].skin = 0;
    m.nodes[1].translation = {7, 7, 7};  // ignored for a skinned mesh
    m.nodes[2].translation = {100, 0, 1};
    animated = 2;
  }
  m.scenes.push_back({});
  m.scenes[0].nodes = skinned ? std::vector<int>{0, 1, 2} : std::vector<int>{0, 1};
  std::vector<float> times{0, 1}, moves{100, 0, 1, 0, 0, 1};
  tinygltf::Animation anim;
  anim.name = "close";
  tinygltf::AnimationSampler s;
  s.input = addAccessor(m, times.data(), 8, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_SCALAR, 2);
  m.accessors[static_cast<size_t>(s.input)].minValues = {0};
  m.accessors[static_cast<size_t>(s.input)].maxValues = {1};
  s.output = addAccessor(m, moves.data(), 24, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, 2);
  s.interpolation = "LINEAR";
  anim.samplers.push_back(s);
  tinygltf::AnimationChannel ch;
  ch.sampler = 0;
  ch.target_node = animated;
  ch.target_path = "translation";
  anim.channels.push_back(ch);
  m.animations.push_back(anim);
  save(m, dir / "lid.glb");

  GltfBakeOptions o;
  o.occlusion.rays = 16384;
  EXPECT_EQ(bakeAndImport(dir / "lid.glb", dir / "out.glb", o).data.streams["vertex.occlusion"][0][0], 0.0f);
  o.time = 1.0;
  o.animation = "close";
  float covered = bakeAndImport(dir / "lid.glb", dir / "out.glb", o).data.streams["vertex.occlusion"][0][0];
  expectWithinBound(covered, kOpenUniform, o.occlusion.rays, "lid over the floor at t = 1");
  o.time = 0.5;  // half way: the lid spans x in [49, 51], far from the floor's centre
  EXPECT_LT(bakeAndImport(dir / "lid.glb", dir / "out.glb", o).data.streams["vertex.occlusion"][0][0], 0.01f);
  o.animation = "nope";
  EXPECT_THROW(bakeGltfOcclusion((dir / "lid.glb").string(), o), InputError);
  fs::remove_all(dir);
}

TEST(GltfBake, AnimationTimePosesTheWholeScene) { animatedLid(false); }
TEST(GltfBake, AnimationTimeSkinsSkinnedMeshes) { animatedLid(true); }

TEST(GltfBake, OutputIsDeterministicAndThreadIndependent) {
  fs::path dir = tempDir();
  saveSingleMesh(cavityBox(), dir / "cavity.glb");
  GltfBakeOptions o;
  o.occlusion.rays = 333;
  o.occlusion.threads = 1;
  std::string one = bakeGltfOcclusion((dir / "cavity.glb").string(), o).bytes;
  o.occlusion.threads = 4;
  std::string four = bakeGltfOcclusion((dir / "cavity.glb").string(), o).bytes;
  EXPECT_EQ(one, four);
  o.binary = false;  // .gltf: JSON with embedded buffers, readable back
  writeFile(dir / "out.gltf", bakeGltfOcclusion((dir / "cavity.glb").string(), o).bytes);
  GltfImport back = importGltf((dir / "out.gltf").string());
  GltfImport glb = [&] {
    writeFile(dir / "out.glb", one);
    return importGltf((dir / "out.glb").string());
  }();
  EXPECT_EQ(back.data.streams["vertex.occlusion"], glb.data.streams["vertex.occlusion"]);
  fs::remove_all(dir);
}

// A sparse index accessor (valid glTF, which `render` draws) was refused by the baker, which
// read indices itself ("indices must be a non-sparse SCALAR"); the triangles are now the
// import's, sparse values applied: the bake equals that of the same indices stored densely.
TEST(GltfBake, SparseIndicesAreApplied) {
  fs::path dir = tempDir();
  const Mesh box = cavityBox();
  Mesh dense = box;  // the first wall's two triangles (elements 12..17) collapsed onto vertex 0
  for (size_t e = 12; e < 18; ++e) dense.indices[e] = 0;
  saveSingleMesh(dense, dir / "dense.glb");
  tinygltf::Model m;
  addMesh(m, box);
  const std::vector<uint8_t> at = {12, 13, 14, 15, 16, 17};
  const std::vector<uint32_t> zeros(at.size(), 0);
  const int zeroAcc = addAccessor(m, zeros.data(), zeros.size() * 4, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT,
                                  TINYGLTF_TYPE_SCALAR, zeros.size());  // 4-byte aligned: all before is
  const int atAcc = addAccessor(m, at.data(), at.size(), TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_TYPE_SCALAR, at.size());
  auto& idx = m.accessors[static_cast<size_t>(m.meshes[0].primitives[0].indices)];
  idx.sparse.isSparse = true;
  idx.sparse.count = static_cast<int>(at.size());
  idx.sparse.indices.bufferView = m.accessors[static_cast<size_t>(atAcc)].bufferView;
  idx.sparse.indices.byteOffset = 0;
  idx.sparse.indices.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
  idx.sparse.values.bufferView = m.accessors[static_cast<size_t>(zeroAcc)].bufferView;
  idx.sparse.values.byteOffset = 0;
  m.accessors.resize(m.accessors.size() - 2);  // their views stay: the sparse data
  m.nodes.emplace_back();
  m.nodes[0].mesh = 0;
  m.scenes.push_back({});
  m.scenes[0].nodes = {0};
  save(m, dir / "sparse.glb");
  saveSingleMesh(box, dir / "box.glb");
  GltfBakeOptions o;
  o.occlusion.rays = 256;
  o.occlusion.threads = 1;
  auto occlusion = [&](const std::string& name) {
    return bakeAndImport(dir / (name + ".glb"), dir / (name + ".baked.glb"), o).data.streams["vertex.occlusion"];
  };
  const auto sparse = occlusion("sparse");
  EXPECT_EQ(sparse, occlusion("dense"));
  EXPECT_NE(sparse, occlusion("box"));  // the sparse values matter
  EXPECT_NO_THROW(bakeGltfTangents((dir / "sparse.glb").string(), true));
  fs::remove_all(dir);
}

// tinygltf writes an object with only default members as `null` and an infinite camera's
// absent zfar as 0: a valid model with an empty node, scene and texture and such a camera
// baked to invalid glTF that no loader, ours included, read back.
TEST(GltfBake, EmptyObjectsAndAnInfiniteCameraStayValid) {
  fs::path dir = tempDir();
  nlohmann::json j = quadModelJson();
  j["nodes"].push_back(nlohmann::json::object());
  j["scenes"][0]["nodes"].push_back(1);
  j["scenes"].push_back(nlohmann::json::object());
  j["textures"] = nlohmann::json::array({nlohmann::json::object()});
  j["cameras"] = nlohmann::json::parse(R"([{"type": "perspective", "perspective": {"yfov": 1, "znear": 0.1}}])");
  j["nodes"][0]["camera"] = 0;
  writeFile(dir / "in.gltf", j.dump());
  auto jsonOf = [](const std::string& bytes, bool binary) {
    if (!binary) return nlohmann::json::parse(bytes);
    uint32_t n;
    std::memcpy(&n, bytes.data() + 12, 4);
    return nlohmann::json::parse(bytes.substr(20, n));
  };
  for (bool binary : {false, true}) {
    GltfBakeOptions o;
    o.occlusion.rays = 8;
    o.occlusion.threads = 1;
    o.binary = binary;
    const std::string ext = binary ? ".glb" : ".gltf";
    std::string occ = bakeGltfOcclusion((dir / "in.gltf").string(), o).bytes;
    std::string tan = bakeGltfTangents((dir / "in.gltf").string(), binary).bytes;
    writeFile(dir / ("occ" + ext), occ);
    writeFile(dir / ("tan" + ext), tan);
    for (const std::string& bytes : {occ, tan}) {
      nlohmann::json out = jsonOf(bytes, binary);
      EXPECT_EQ(out["nodes"][1], nlohmann::json::object()) << ext;
      EXPECT_EQ(out["scenes"][1], nlohmann::json::object()) << ext;
      EXPECT_EQ(out["textures"][0], nlohmann::json::object()) << ext;
      EXPECT_FALSE(out["cameras"][0]["perspective"].contains("zfar")) << ext;
    }
    EXPECT_NO_THROW(importGltf((dir / ("occ" + ext)).string())) << ext;
    EXPECT_NO_THROW(importGltf((dir / ("tan" + ext)).string())) << ext;
  }
  fs::remove_all(dir);
}

// tinygltf keeps no data URI of an image: the baker wrote an embedded texture as
// `"bufferView": -1` (invalid, and the image lost). It is written back as it was.
TEST(GltfBake, EmbeddedImageIsKept) {
  fs::path dir = tempDir();
  nlohmann::json j = quadModelJson();
  const std::string uri = "data:image/png;base64,iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAIAAACQd1PeAAAADElEQVR4nGP4z8AAAAMBAQDJ/pLvAAAAAElFTkSuQmCC";
  j["images"] = nlohmann::json::array({{{"uri", uri}}});
  j["textures"] = nlohmann::json::array({{{"source", 0}}});
  writeFile(dir / "in.gltf", j.dump());
  GltfBakeOptions o;
  o.occlusion.rays = 8;
  o.occlusion.threads = 1;
  o.binary = false;
  const nlohmann::json occ = nlohmann::json::parse(bakeGltfOcclusion((dir / "in.gltf").string(), o).bytes);
  const nlohmann::json tan = nlohmann::json::parse(bakeGltfTangents((dir / "in.gltf").string(), false).bytes);
  for (const nlohmann::json& out : {occ, tan}) EXPECT_EQ(out["images"], j["images"]);
  fs::remove_all(dir);
}

// --- Dawn's head: a procedural head with eye sockets and a closed-eye morph target --------
// An ellipsoid (UV grid, the poles left open) with two eye sockets: bowls pushed in along
// the radius. Target 0 closes the eyes: the socket vertices move back onto the ellipsoid
// (the eyelids), so the closed head is a convex polyhedron. Skinned to a neck and a head
// joint; an animation blinks (weights 0 → 1 → 0.3) and nods the head. Written as .glb.
struct Head {
  tinygltf::Model model;
  enum Zone { Outside, Socket, Rim };  // Rim: near a socket (its faces may dip in)
  std::vector<Zone> zone;              // per vertex
};

Head dawnHead(int rings = 40, int segments = 56) {
  const double rx = 0.8, ry = 1.0, rz = 0.9, socket = 0.24, depth = 0.3;
  const glm::dvec3 eyes[2] = {glm::normalize(glm::dvec3(0.36, 0.15, 0.92)), glm::normalize(glm::dvec3(-0.36, 0.15, 0.92))};
  Head h;
  std::vector<glm::dvec3> open, closed, uv;
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j <= segments; ++j) {
      double th = M_PI * (0.06 + 0.88 * i / rings), ph = 2 * M_PI * j / segments;
      glm::dvec3 dir(std::sin(th) * std::sin(ph), std::cos(th), std::sin(th) * std::cos(ph));  // +z: the face
      double scale = 1;
      Head::Zone zone = Head::Outside;
      for (const auto& e : eyes) {
        double a = std::acos(std::clamp(glm::dot(dir, e), -1.0, 1.0));
        if (a < socket) scale = 1 - depth * std::sqrt(1 - (a / socket) * (a / socket));
        if (a < 1.6 * socket) zone = Head::Rim;
      }
      if (scale < 1) zone = Head::Socket;
      glm::dvec3 surface(rx * dir.x, ry * dir.y, rz * dir.z);
      closed.push_back(surface);
      open.push_back(surface * scale);
      uv.push_back({double(j) / segments, double(i) / rings, 0});
      h.zone.push_back(zone);
    }
  std::vector<uint32_t> idx;
  auto at = [&](int i, int j) { return static_cast<uint32_t>(i * (segments + 1) + j); };
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j)
      idx.insert(idx.end(), {at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j), at(i + 1, j + 1), at(i, j + 1)});
  auto normals = [&](const std::vector<glm::dvec3>& p) {
    std::vector<glm::dvec3> n(p.size(), glm::dvec3(0));
    for (size_t t = 0; t < idx.size(); t += 3) {
      glm::dvec3 f = glm::cross(p[idx[t + 1]] - p[idx[t]], p[idx[t + 2]] - p[idx[t]]);
      for (int k = 0; k < 3; ++k) n[idx[t + k]] += f;
    }
    // The seam column is duplicated: both copies get the summed normal.
    for (int i = 0; i <= rings; ++i) {
      glm::dvec3 s = n[at(i, 0)] + n[at(i, segments)];
      n[at(i, 0)] = n[at(i, segments)] = s;
    }
    for (auto& v : n) v = glm::normalize(v);
    return n;
  };
  std::vector<glm::dvec3> nOpen = normals(open), nClosed = normals(closed);
  size_t count = open.size();
  std::vector<float> P, N, T, UV0, UV1, dP, dN, W;
  std::vector<uint8_t> J;
  for (size_t v = 0; v < count; ++v) {
    P.insert(P.end(), {float(open[v].x), float(open[v].y), float(open[v].z)});
    N.insert(N.end(), {float(nOpen[v].x), float(nOpen[v].y), float(nOpen[v].z)});
    glm::dvec3 around = glm::normalize(glm::cross(glm::dvec3(0, 1, 0), nOpen[v]) + glm::dvec3(1e-9, 0, 0));
    glm::dvec3 t = glm::normalize(around - glm::dot(around, nOpen[v]) * nOpen[v]);
    T.insert(T.end(), {float(t.x), float(t.y), float(t.z), 1.0f});
    UV0.insert(UV0.end(), {float(uv[v].x), float(uv[v].y)});
    UV1.insert(UV1.end(), {float(2 * uv[v].x), float(2 * uv[v].y)});
    glm::dvec3 dp = closed[v] - open[v], dn = nClosed[v] - nOpen[v];
    dP.insert(dP.end(), {float(dp.x), float(dp.y), float(dp.z)});
    dN.insert(dN.end(), {float(dn.x), float(dn.y), float(dn.z)});
    double wHead = std::clamp((open[v].y + 0.9) / 0.7, 0.0, 1.0);
    J.insert(J.end(), {1, 0, 0, 0});
    W.insert(W.end(), {float(wHead), float(1 - wHead), 0.0f, 0.0f});
  }
  tinygltf::Model& m = h.model;
  m.buffers.emplace_back();
  auto acc = [&](const auto& v, int ct, int type, size_t n) {
    return addAccessor(m, v.data(), v.size() * sizeof(v[0]), ct, type, n);
  };
  const int F = TINYGLTF_COMPONENT_TYPE_FLOAT;
  tinygltf::Primitive p;
  p.attributes["POSITION"] = acc(P, F, TINYGLTF_TYPE_VEC3, count);
  m.accessors.back().minValues = {-rx, -ry, -rz};
  m.accessors.back().maxValues = {rx, ry, rz};
  p.attributes["NORMAL"] = acc(N, F, TINYGLTF_TYPE_VEC3, count);
  p.attributes["TANGENT"] = acc(T, F, TINYGLTF_TYPE_VEC4, count);
  p.attributes["TEXCOORD_0"] = acc(UV0, F, TINYGLTF_TYPE_VEC2, count);
  p.attributes["TEXCOORD_1"] = acc(UV1, F, TINYGLTF_TYPE_VEC2, count);
  p.attributes["JOINTS_0"] = acc(J, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_TYPE_VEC4, count);
  p.attributes["WEIGHTS_0"] = acc(W, F, TINYGLTF_TYPE_VEC4, count);
  p.indices = acc(idx, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR, idx.size());
  p.targets.push_back({{"POSITION", acc(dP, F, TINYGLTF_TYPE_VEC3, count)}, {"NORMAL", acc(dN, F, TINYGLTF_TYPE_VEC3, count)}});
  p.mode = TINYGLTF_MODE_TRIANGLES;
  tinygltf::Mesh mesh;
  mesh.name = "head";
  mesh.primitives.push_back(p);
  mesh.weights = {0.0};
  m.meshes.push_back(mesh);
  // Nodes: 0 the skinned mesh, 1 the neck joint (root), 2 the head joint.
  m.nodes.resize(3);
  m.nodes[0].name = "head_mesh";
  m.nodes[0].mesh = 0;
  m.nodes[0].skin = 0;
  m.nodes[1].name = "neck";
  m.nodes[1].translation = {0, -1.2, 0};
  m.nodes[1].children = {2};
  m.nodes[2].name = "head";
  m.nodes[2].translation = {0, 1.2, 0};
  std::vector<float> ibm{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 1.2f, 0, 1,  //
                         1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  tinygltf::Skin skin;
  skin.joints = {2, 1};  // joint 0: head, joint 1: neck (JOINTS_0 = (1, 0): head first)
  std::swap_ranges(ibm.begin(), ibm.begin() + 16, ibm.begin() + 16);
  skin.inverseBindMatrices = acc(ibm, F, TINYGLTF_TYPE_MAT4, 2);
  m.skins.push_back(skin);
  m.scenes.push_back({});
  m.scenes[0].nodes = {0, 1};
  // Animation "blink": eyes close and half open again; the head nods.
  std::vector<float> times{0, 1, 2}, blink{0, 1, 0.3f};
  double s = std::sin(0.15), c = std::cos(0.15);
  std::vector<float> nod{0, 0, 0, 1, float(s), 0, 0, float(c), 0, 0, 0, 1};
  tinygltf::Animation anim;
  anim.name = "blink";
  int in = acc(times, F, TINYGLTF_TYPE_SCALAR, 3);
  m.accessors.back().minValues = {0};
  m.accessors.back().maxValues = {2};
  tinygltf::AnimationSampler sw, sr;
  sw.input = sr.input = in;
  sw.output = acc(blink, F, TINYGLTF_TYPE_SCALAR, 3);
  sr.output = acc(nod, F, TINYGLTF_TYPE_VEC4, 3);
  sw.interpolation = sr.interpolation = "LINEAR";
  anim.samplers = {sw, sr};
  tinygltf::AnimationChannel cw, cr;
  cw.sampler = 0, cw.target_node = 0, cw.target_path = "weights";
  cr.sampler = 1, cr.target_node = 2, cr.target_path = "rotation";
  anim.channels = {cw, cr};
  m.animations.push_back(anim);
  return h;
}

// --- the CLI: hostile inputs get a diagnostic and a non-zero exit, and no output -------------
struct CliRun {
  int status;
  std::string err;
};
CliRun cli(const std::string& args, const fs::path& dir) {
  std::string cmd = fmt::format("{} {} 2> {}/err.txt > {}/out.txt", SG_CLI, args, dir.string(), dir.string());
  int rc = std::system(cmd.c_str());
  return {WIFEXITED(rc) ? WEXITSTATUS(rc) : -1, readFile(dir / "err.txt")};
}

TEST(GltfBakeCli, HostileInputs) {
  fs::path dir = tempDir();
  std::string out = (dir / "out.glb").string();
  CliRun r = cli(fmt::format("bake occlusion {}/missing.glb -o {}", dir.string(), out), dir);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("missing.glb: error: cannot read the glTF model: no such file"), std::string::npos) << r.err;
  writeFile(dir / "truncated.glb", "glTF\x02\x00\x00\x00garbage");
  r = cli(fmt::format("bake occlusion {}/truncated.glb -o {}", dir.string(), out), dir);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("truncated.glb: error:"), std::string::npos) << r.err;
  // An index past the vertex count.
  tinygltf::Model m;
  Mesh bad = cavityBox();
  bad.indices[4] = 999;
  addMesh(m, bad);
  save(m, dir / "badindex.glb");
  r = cli(fmt::format("bake occlusion {}/badindex.glb -o {}", dir.string(), out), dir);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("index 999"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  // Usage errors: exit status 2.
  save(m = {}, dir / "empty.glb");
  EXPECT_EQ(cli(fmt::format("bake occlusion {}/empty.glb -o {}", dir.string(), out), dir).status, 1);
  EXPECT_EQ(cli(fmt::format("bake occlusion {}/badindex.glb -o {}/out.txt", dir.string(), dir.string()), dir).status, 2);
  EXPECT_EQ(cli(fmt::format("bake occlusion {}/badindex.glb -o {} --rays 0", dir.string(), out), dir).status, 2);
  EXPECT_EQ(cli(fmt::format("bake occlusion {}/badindex.glb -o {} --distribution cosin", dir.string(), out), dir).status, 2);
  EXPECT_EQ(cli(fmt::format("bake occlusion {}/badindex.glb -o {} --animation x", dir.string(), out), dir).status, 2);
  EXPECT_FALSE(fs::exists(out));
  fs::remove_all(dir);
}

// --- shared models: bake, import, validate on lavapipe ---------------------------------------
std::string modelPath(const std::string& rel) {
  const char* env = std::getenv("SHADERGEN_SHARED_DIR");
  return std::string(env && *env ? env : SG_SHARED_DIR) + "/models/" + rel;
}

struct EndToEnd {
  const char* model;
  const char* fragment;
  const char* validateArgs;
};

TEST(GltfBakeCli, SharedModelsBakedImportedAndValidated) {
  if (!fs::exists(modelPath("README.md"))) GTEST_SKIP() << "no shared models at " << modelPath("");
  fs::path dir = tempDir();
  const std::string rules = std::string(SG_SOURCE_DIR) + "/rules/standard.yaml";
  // AnimatedMorphSphere: normals, two targets moving position and normal (occlusion deltas
  // blended with the normal, listing 3-3). Fox: skinned, no NORMAL (normals from faces).
  for (const EndToEnd& c : {EndToEnd{"AnimatedMorphSphere/AnimatedMorphSphere.gltf", "occlusion.frag", "--time 1.2 --time 3.9"},
                            EndToEnd{"Fox/Fox.glb", "occlusion_uv.frag", "--animation Survey --time 0.5"}}) {
    std::string baked = (dir / "baked.glb").string();
    CliRun r = cli(fmt::format("bake occlusion {} -o {} --rays 64", modelPath(c.model), baked), dir);
    ASSERT_EQ(r.status, 0) << c.model << ": " << r.err;
    GltfImport imp = importGltf(baked);
    const auto& occ = imp.data.streams.at("vertex.occlusion");
    double lo = 1, hi = 0;
    for (const auto& v : occ) lo = std::min<double>(lo, v[0]), hi = std::max<double>(hi, v[0]);
    EXPECT_GE(lo, 0.0);
    EXPECT_LE(hi, 1.0);
    for (int t = 0; t < imp.morphTargets; ++t) {
      const auto& d = imp.data.streams.at(fmt::format("morph.occlusion[{}]", t));
      double sum = 0;
      for (const auto& v : d) sum += std::fabs(v[0]);
      EXPECT_GT(sum, 0) << c.model << " target " << t << " changes no occlusion";
    }
    std::string frag = std::string(SG_SOURCE_DIR) + "/tests/bake/data/" + c.fragment;
    r = cli(fmt::format("validate --rig {}#0/0 -f {} -r {} --map occlusion=object.occlusion --cross-check {}", baked,
                        frag, rules, c.validateArgs),
            dir);
    EXPECT_EQ(r.status, 0) << c.model << ": " << r.err << readFile(dir / "out.txt");
    EXPECT_NE(readFile(dir / "out.txt").find("occlusion"), std::string::npos);
  }
  fs::remove_all(dir);
}


// The Dawn example: the procedural head baked (the sockets occluded while open, nothing
// once closed: the closed head is convex), imported in Dawn's normal.w layout, and
// Dawn's face shader validated on lavapipe on the baked data, blinking.
TEST(GltfBakeCli, DawnHeadWithClosedEyeTarget) {
  fs::path dir = tempDir();
  Head h = dawnHead();
  save(h.model, dir / "head.glb");
  std::string baked = (dir / "head.baked.glb").string();
  CliRun r = cli(fmt::format("bake occlusion {}/head.glb -o {} --rays 128", dir.string(), baked), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  GltfImport imp = importGltf(baked);
  const auto& base = imp.data.streams.at("vertex.occlusion");
  const auto& delta = imp.data.streams.at("morph.occlusion[0]");
  double socketSum = 0;
  size_t sockets = 0;
  for (size_t v = 0; v < base.size(); ++v) {
    // Closed: a convex polyhedron, so base + delta is exactly 0 everywhere.
    EXPECT_EQ(base[v][0] + delta[v][0], 0.0f) << "vertex " << v;
    if (h.zone[v] == Head::Socket) socketSum += base[v][0], ++sockets;
    else if (h.zone[v] == Head::Outside) EXPECT_EQ(base[v][0], 0.0f) << "vertex " << v << " outside the sockets";
  }
  ASSERT_GT(sockets, 20u);
  EXPECT_GT(socketSum / double(sockets), 0.15) << "the open sockets are barely occluded";

  // Dawn's layout: normal.w and the normal deltas' w.
  r = cli(fmt::format("rig import {} --pack-occlusion -q -o {}/head.rig.yaml", baked, dir.string()), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  std::string yaml = readFile(dir / "head.rig.yaml");
  EXPECT_NE(yaml.find(R"(normal: { format: float32x4, provides: { "vertex.normal": xyz, "vertex.occlusion": w } })"),
            std::string::npos) << yaml;
  EXPECT_NE(yaml.find(R"(normal_morph: { format: float32x4, per_target: true, provides: { "morph.normal": xyz, "morph.occlusion": w } })"),
            std::string::npos) << yaml;

  // Dawn's face shader on the baked head (no dapple texture: its slot carries 1 − N·V).
  std::string src = SG_SOURCE_DIR;
  std::string map = "--map SkinSilhouetteVec=object.occlusion,view.one_minus_ndotv_sq,view.one_minus_ndotv,view.one_minus_ndotv";
  r = cli(fmt::format("validate --rig {}#0/0 -f {}/examples/dawn/face.frag -r {}/examples/dawn/rules.yaml {} "
                      "--time 0.5 --time 1.5 --cross-check",
                      baked, src, src, map),
          dir);
  EXPECT_EQ(r.status, 0) << r.err << readFile(dir / "out.txt");
  std::string report = readFile(dir / "out.txt");
  EXPECT_NE(report.find("SkinSilhouetteVec"), std::string::npos) << report;
  // The packed rig (procedural mesh): the normal.w layout generates and validates too.
  r = cli(fmt::format("validate --rig {}/head.rig.yaml -f {}/examples/dawn/face.frag -r {}/examples/dawn/rules.yaml {}",
                      dir.string(), src, src, map),
          dir);
  EXPECT_EQ(r.status, 0) << r.err << readFile(dir / "out.txt");
  fs::remove_all(dir);
}

// `bake tangents` on a shared model with NORMAL, TEXCOORD_0 and eight morph targets but no
// TANGENT: every frame unit and in its tangent plane, each target's frames (base + delta)
// in the target shape's tangent plane, and listing 3-4's tangent frame generated and
// validated on lavapipe mid-animation (the plan Gram-Schmidts the morphed tangent).
TEST(GltfBakeCli, TangentsForAModelWithMorphTargets) {
  if (!fs::exists(modelPath("README.md"))) GTEST_SKIP() << "no shared models at " << modelPath("");
  fs::path dir = tempDir();
  std::string out = (dir / "tangents.glb").string();
  CliRun r = cli(fmt::format("bake tangents {} -o {}", modelPath("MorphStressTest/MorphStressTest.gltf"), out), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  GltfImportOptions io;
  io.primitive = 1;
  GltfImport imp = importGltf(out, io);
  ASSERT_EQ(imp.morphTargets, 8);
  const auto& t = imp.data.streams.at("vertex.tangent");
  const auto& w = imp.data.streams.at("vertex.handedness");
  const auto& n = imp.data.streams.at("vertex.normal");
  auto v3 = [](const std::array<float, 4>& a) { return glm::dvec3(a[0], a[1], a[2]); };
  for (size_t v = 0; v < t.size(); ++v) {
    EXPECT_NEAR(glm::length(v3(t[v])), 1.0, 1e-5) << v;
    EXPECT_NEAR(glm::dot(v3(t[v]), glm::normalize(v3(n[v]))), 0.0, 1e-5) << v;
    EXPECT_EQ(std::fabs(w[v][0]), 1.0f) << v;
  }
  double moved = 0;
  for (int k = 0; k < 8; ++k) {
    const auto& dt = imp.data.streams.at(fmt::format("morph.tangent[{}]", k));
    const auto& dn = imp.data.streams.at(fmt::format("morph.normal[{}]", k));
    for (size_t v = 0; v < t.size(); ++v) {
      glm::dvec3 tt = v3(t[v]) + v3(dt[v]), nn = glm::normalize(v3(n[v]) + v3(dn[v]));
      EXPECT_NEAR(glm::dot(tt, nn), 0.0, 1e-5) << "target " << k << " vertex " << v;
      moved += glm::length(v3(dt[v]));
    }
  }
  EXPECT_GT(moved, 1.0) << "no target turns any frame";
  // A model that has TANGENT keeps it (a warning says so) and bytes do not depend on the run.
  std::string again = (dir / "again.glb").string();
  r = cli(fmt::format("bake tangents {} -o {}", out, again), dir);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("keeps its own TANGENT"), std::string::npos) << r.err;
  EXPECT_EQ(importGltf(again, io).data.streams.at("vertex.tangent"), t);
  std::string src = SG_SOURCE_DIR;
  std::string args = fmt::format(
      "--rig {}#0/1 -f {}/examples/dawn/face.frag -r {}/examples/dawn/rules.yaml --map SkinSilhouetteVec="
      "view.one_minus_ndotv,view.one_minus_ndotv_sq,view.one_minus_ndotv,view.one_minus_ndotv --map "
      "SkinUVST=vertex.texcoord0,vertex.texcoord1",
      out, src, src);
  r = cli("generate " + args + " -o " + (dir / "gen").string(), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(readFile(dir / "out.txt").find("object_tangent_morphed"), std::string::npos) << readFile(dir / "out.txt");
  r = cli("validate " + args + " --animation TheWave --time 0.9 --cross-check", dir);
  EXPECT_EQ(r.status, 0) << r.err << readFile(dir / "out.txt");
  fs::remove_all(dir);
}

// The README picture's model (examples/head): three.js's LeePerrySmith scan, baked and
// validated as examples/head/make-picture.sh does (fewer rays), with listing 3-4's face shader.
TEST(GltfBakeCli, ScannedHeadBakesAndValidatesWithTheDawnFaceShader) {
  std::string head = modelPath("LeePerrySmith/LeePerrySmith.glb");
  if (!fs::exists(head)) GTEST_SKIP() << "no " << head << " (examples/head/README.md)";
  fs::path dir = tempDir();
  std::string occluded = (dir / "occluded.glb").string(), baked = (dir / "head.glb").string();
  CliRun r = cli(fmt::format("bake occlusion {} -o {} --rays 64", head, occluded), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  r = cli(fmt::format("bake tangents {} -o {}", occluded, baked), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  GltfImport imp = importGltf(baked);
  ASSERT_EQ(imp.data.vertexCount, 9279u);
  // The crown of the head is convex, open sky: the vertices within 2% of the top (+y) of
  // the bounding box see almost nothing above them; eyes and mouth are closed, so some
  // vertices (inside the lids and lips) see almost nothing but the head.
  const auto& pos = imp.data.streams.at("vertex.position");
  const auto& occ = imp.data.streams.at("vertex.occlusion");
  float top = -1e30f, bottom = 1e30f;
  for (const auto& p : pos) top = std::max(top, p[1]), bottom = std::min(bottom, p[1]);
  size_t crown = 0, shut = 0;
  for (size_t v = 0; v < pos.size(); ++v) {
    if (pos[v][1] > top - 0.02f * (top - bottom)) {
      ++crown;
      EXPECT_LT(occ[v][0], 0.1f) << "crown vertex " << v;
    }
    shut += occ[v][0] > 0.9f;
  }
  EXPECT_GT(crown, 5u);
  EXPECT_GT(shut, 100u);
  const auto& t = imp.data.streams.at("vertex.tangent");
  const auto& n = imp.data.streams.at("vertex.normal");
  for (size_t v = 0; v < t.size(); ++v)
    ASSERT_NEAR(t[v][0] * n[v][0] + t[v][1] * n[v][1] + t[v][2] * n[v][2], 0.0, 1e-4) << v;
  const std::string src = SG_SOURCE_DIR;
  r = cli(fmt::format("validate --rig {}#0/0 -f {}/examples/dawn/face.frag -r {}/examples/dawn/rules.yaml "
                      "--map SkinSilhouetteVec=object.visibility,view.one_minus_ndotv_sq,view.one_minus_ndotv,"
                      "view.one_minus_ndotv --map SkinUVST=vertex.texcoord0,vertex.texcoord0 --cross-check",
                      baked, src, src),
          dir);
  EXPECT_EQ(r.status, 0) << r.err << readFile(dir / "out.txt");
  EXPECT_NE(readFile(dir / "out.txt").find("object.visibility"), std::string::npos);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace sg::bake

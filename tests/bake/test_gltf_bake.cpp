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

#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <sys/wait.h>
#include <unistd.h>

#include "bake/gltf_bake.h"
#include "common/diagnostics.h"
#include "rig/gltf_import.h"

namespace sg::bake {
namespace {

namespace fs = std::filesystem;
constexpr double kZ99 = 2.5758293035489;

fs::path tempDir() {
  fs::path d = fs::temp_directory_path() / fmt::format("sg_bake_test_{}", ::getpid());
  fs::create_directories(d);
  return d;
}

std::string readFile(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}
void writeFile(const fs::path& p, const std::string& bytes) { std::ofstream(p, std::ios::binary) << bytes; }

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
  tinygltf::Model m;
  addMesh(m, cavityBox());
  m.nodes.emplace_back();
  m.nodes[0].mesh = 0;
  m.scenes.push_back({});
  m.scenes[0].nodes = {0};
  save(m, dir / "cavity.glb");
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
TEST(GltfBake, AnimationTimePosesTheWholeScene) {
  fs::path dir = tempDir();
  tinygltf::Model m;
  Mesh floor, lid;
  floor.positions = {0, 0, 0};
  floor.normals = {0, 0, 1};
  float c[4][2] = {{-9, -9}, {9, -9}, {9, 9}, {-9, 9}};
  for (auto& p : c) floor.positions.insert(floor.positions.end(), {p[0], p[1], 0}), floor.normals.insert(floor.normals.end(), {0, 0, 1});
  for (uint32_t i = 0; i < 4; ++i) floor.indices.insert(floor.indices.end(), {0, 1 + i, 1 + (i + 1) % 4});
  lid.quad({-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, {0, 0, -1});
  addMesh(m, floor);
  addMesh(m, lid);
  m.nodes.resize(2);
  m.nodes[0].mesh = 0;
  m.nodes[1].mesh = 1;
  m.nodes[1].translation = {100, 0, 1};
  m.scenes.push_back({});
  m.scenes[0].nodes = {0, 1};
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
  ch.target_node = 1;
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
  o.animation = "nope";
  EXPECT_THROW(bakeGltfOcclusion((dir / "lid.glb").string(), o), InputError);
  fs::remove_all(dir);
}

TEST(GltfBake, OutputIsDeterministicAndThreadIndependent) {
  fs::path dir = tempDir();
  tinygltf::Model m;
  addMesh(m, cavityBox());
  m.nodes.emplace_back();
  m.nodes[0].mesh = 0;
  save(m, dir / "cavity.glb");
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
  EXPECT_NE(r.err.find("missing.glb: error: cannot open"), std::string::npos) << r.err;
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

}  // namespace
}  // namespace sg::bake

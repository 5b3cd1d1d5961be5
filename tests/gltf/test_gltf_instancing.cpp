// EXT_mesh_gpu_instancing (docs/gltf.md, "Instances"): the import's per-instance T·R·S, one
// validated and drawn instance per GPU instance of a rigid primitive (at most
// kMaxGpuInstancesChecked per node), checked against values worked out by hand. The models
// are written here (no shared data needed).
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <sys/wait.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "cli_run.h"
#include "gltf_builder.h"
#include "render/render.h"
#include "rig/gltf_import.h"
#include "runtime/reference.h"
#include "validate/gltf_scene.h"

namespace sg {
namespace {

namespace fs = std::filesystem;
using test::CliRun;
using test::GltfBuilder;
using test::cli;

std::string sourcePath(const std::string& rel) { return std::string(SG_SOURCE_DIR) + "/" + rel; }

fs::path scratch(const std::string& name) {
  fs::path d = fs::temp_directory_path() / ("sg_instancing_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// A triangle (0,0,0), (1,0,0), (0,1,0) under node 0 'pivot' (translation (0,10,0), 45° about
// +Y) on node 1 'tris' (translation (5,0,0)) with three GPU instances:
//   0: T (1,0,0);  1: T (0,2,0), R 90° about +Z (float), S 2;  2: T (0,0,-3), S (1,3,1).
std::string threeInstances() {
  GltfBuilder b;
  int pos = b.accessor(b.view(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}), 5126, 3, "VEC3",
                       R"("min":[0,0,0],"max":[1,1,0])");
  const float h = std::sqrt(0.5f);
  int t = b.accessor(b.view(std::vector<float>{1, 0, 0, 0, 2, 0, 0, 0, -3}), 5126, 3, "VEC3");
  int r = b.accessor(b.view(std::vector<float>{0, 0, 0, 1, 0, 0, h, h, 0, 0, 0, 1}), 5126, 3, "VEC4");
  int s = b.accessor(b.view(std::vector<float>{1, 1, 1, 2, 2, 2, 1, 3, 1}), 5126, 3, "VEC3");
  return b.json(fmt::format(
      R"("meshes":[{{"name":"tri","primitives":[{{"attributes":{{"POSITION":{}}}}}]}}],)"
      R"("nodes":[{{"name":"pivot","children":[1],"translation":[0,10,0],"rotation":[0,{},0,{}]}},)"
      R"({{"name":"tris","mesh":0,"translation":[5,0,0],"extensions":{{"EXT_mesh_gpu_instancing":)"
      R"({{"attributes":{{"TRANSLATION":{},"ROTATION":{},"SCALE":{}}}}}}}}}],)"
      R"("scenes":[{{"nodes":[0]}}],"extensionsUsed":["EXT_mesh_gpu_instancing"])",
      pos, std::sin(M_PI / 8), std::cos(M_PI / 8), t, r, s));
}

// Where vertex p of GPU instance i lands, worked out by hand: the instance's T·R·S, then node
// 1's translation, then node 0's rotation (x, y, z) -> (c x + c z, y, c z - c x), c = cos 45°,
// and translation.
std::array<double, 3> handWorld(int i, double px, double py, double pz) {
  double q[3];
  if (i == 0) q[0] = px + 1, q[1] = py, q[2] = pz;
  else if (i == 1) q[0] = -2 * py, q[1] = 2 * px + 2, q[2] = 2 * pz;  // Rz(90°): (x, y) -> (-y, x)
  else q[0] = px, q[1] = 3 * py, q[2] = pz - 3;
  q[0] += 5;
  const double c = std::sqrt(0.5);
  return {c * q[0] + c * q[2], q[1] + 10, c * q[2] - c * q[0]};
}
const double kTri[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};

// (a) The per-instance matrices equal T·R·S written out by hand, with a normalized-short
// rotation (-32768 reads as -1) and absent attributes as identity parts.
TEST(GltfInstancing, ImportReadsEachInstanceAsTRS) {
  GltfBuilder b;
  int pos = b.accessor(b.view(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}), 5126, 3, "VEC3");
  int t = b.accessor(b.view(std::vector<float>{1, 2, 3, -1, 0.5f, 0, 0, 0, 0}), 5126, 3, "VEC3");
  // 90° about +Z (23170/32767 each, normalised), identity, 180° about +Y.
  int r = b.accessor(b.view(std::vector<int16_t>{0, 0, 23170, 23170, 0, 0, 0, 32767, 0, -32768, 0, 0}), 5122, 3,
                     "VEC4", R"("normalized":true)");
  int s = b.accessor(b.view(std::vector<float>{2, 3, 4, 1, 1, 1, 1, 1, 1}), 5126, 3, "VEC3");
  int s2 = b.accessor(b.view(std::vector<float>{5, 5, 5, 0.5f, 0.5f, 0.5f}), 5126, 2, "VEC3");
  GltfImport imp = importGltfText(
      b.json(fmt::format(
          R"("meshes":[{{"primitives":[{{"attributes":{{"POSITION":{}}}}}]}}],)"
          R"("nodes":[{{"mesh":0,"extensions":{{"EXT_mesh_gpu_instancing":{{"attributes":{{"TRANSLATION":{},"ROTATION":{},"SCALE":{}}}}}}}}},)"
          R"({{"mesh":0,"extensions":{{"EXT_mesh_gpu_instancing":{{"attributes":{{"SCALE":{}}}}}}}}},{{"mesh":0}}],)"
          R"("scenes":[{{"nodes":[0,1,2]}}])",
          pos, t, r, s, s2)),
      "inst.gltf");
  const auto& a = imp.data.nodes[0].instances;
  ASSERT_EQ(a.size(), 3u);
  // Column-major: Rz(90°) = columns (0,1,0), (-1,0,0), (0,0,1), scaled by (2,3,4), then T.
  const std::array<double, 16> m0{0, 2, 0, 0, -3, 0, 0, 0, 0, 0, 4, 0, 1, 2, 3, 1};
  const std::array<double, 16> m1{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -1, 0.5, 0, 1};
  const std::array<double, 16> m2{-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1};  // Ry(180°)
  for (size_t k = 0; k < 16; ++k) {
    EXPECT_NEAR(a[0][k], m0[k], 1e-6) << "instance 0, element " << k;
    EXPECT_NEAR(a[1][k], m1[k], 1e-12) << "instance 1, element " << k;
    EXPECT_NEAR(a[2][k], m2[k], 1e-12) << "instance 2, element " << k;
  }
  const auto& b1 = imp.data.nodes[1].instances;  // SCALE only: no translation, no rotation
  ASSERT_EQ(b1.size(), 2u);
  const std::array<double, 16> s5{5, 0, 0, 0, 0, 5, 0, 0, 0, 0, 5, 0, 0, 0, 0, 1};
  for (size_t k = 0; k < 16; ++k) EXPECT_DOUBLE_EQ(b1[0][k], s5[k]);
  EXPECT_DOUBLE_EQ(b1[1][0], 0.5);
  EXPECT_TRUE(imp.data.nodes[2].instances.empty());
  // Scale (2,3,4) is per axis: mat3(model) is no normal matrix.
  EXPECT_EQ(imp.rig.param("uniform_scale"), 0);
}

// (b) One instance per GPU instance, each posed at global(node) · T·R·S (the reference's world
// positions match the hand values), named by node and element.
TEST(GltfInstancing, EveryGpuInstanceIsPosedAtNodeTimesInstance) {
  GltfImport imp = importGltfText(threeInstances(), "three.gltf");
  std::vector<std::string> notes;
  std::vector<GltfInstance> inst = gltfInstances(imp, &notes);
  ASSERT_EQ(inst.size(), 3u);
  EXPECT_TRUE(notes.empty());
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(inst[size_t(i)].node, 1);
    EXPECT_EQ(inst[size_t(i)].gpuInstance, i);
    EXPECT_EQ(inst[size_t(i)].name, fmt::format("node 1 'tris' instance {}", i));
  }
  GltfSceneOptions so;
  so.times = {0};
  so.allInstances = true;
  GltfSceneInfo info;
  ValidationScene scene = gltfScene(imp, so, &info);
  ASSERT_EQ(scene.poses.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    std::vector<glm::vec4> w = rt::referenceValues("world.position", scene.mesh, scene.poses[size_t(i)], scene.shape);
    ASSERT_EQ(w.size(), 3u);
    for (int v = 0; v < 3; ++v) {
      std::array<double, 3> e = handWorld(i, kTri[v][0], kTri[v][1], kTri[v][2]);
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(w[size_t(v)][c], e[size_t(c)], 1e-5) << "instance " << i << " vertex " << v;
    }
  }
  // One instance (other commands): the first GPU instance, with or without gltfInstances.
  so.allInstances = false;
  ValidationScene one = gltfScene(imp, so);
  ASSERT_EQ(one.poses.size(), 1u);
  rt::Pose direct = gltfPose(imp, one.mesh, one.shape, -1, 0);
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) {
      EXPECT_FLOAT_EQ(one.poses[0].model[c][r], scene.poses[0].model[c][r]);
      EXPECT_FLOAT_EQ(direct.model[c][r], scene.poses[0].model[c][r]);
    }
}

// (c) A node of 300 instances: 256 checked, spread evenly with the first and the last, and a
// note saying so.
TEST(GltfInstancing, LargeCountsAreSampledEvenlyWithANote) {
  const size_t n = 300;
  std::vector<float> t;
  for (size_t i = 0; i < n; ++i) t.insert(t.end(), {float(i), 0, 0});
  GltfBuilder b;
  int pos = b.accessor(b.view(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}), 5126, 3, "VEC3");
  int tr = b.accessor(b.view(t), 5126, n, "VEC3");
  GltfImport imp = importGltfText(
      b.json(fmt::format(R"("meshes":[{{"primitives":[{{"attributes":{{"POSITION":{}}}}}]}}],)"
                         R"("nodes":[{{"name":"many","mesh":0,"extensions":{{"EXT_mesh_gpu_instancing":{{"attributes":{{"TRANSLATION":{}}}}}}}}}],)"
                         R"("scenes":[{{"nodes":[0]}}])",
                         pos, tr)),
      "many.gltf");
  std::vector<std::string> notes;
  std::vector<GltfInstance> inst = gltfInstances(imp, &notes);
  ASSERT_EQ(inst.size(), kMaxGpuInstancesChecked);
  EXPECT_EQ(inst.front().gpuInstance, 0);
  EXPECT_EQ(inst.back().gpuInstance, 299);
  for (size_t k = 1; k < inst.size(); ++k) {
    const int step = inst[k].gpuInstance - inst[k - 1].gpuInstance;
    EXPECT_TRUE(step == 1 || step == 2) << "evenly spread: 299 / 255 apart, rounded down";
    EXPECT_DOUBLE_EQ(inst[k].instanceMatrix[3][0], inst[k].gpuInstance) << "its own element's translation";
  }
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("checked 256 of 300 GPU instances of node 0 'many'"), std::string::npos) << notes[0];
  EXPECT_EQ(gltfInstances(imp).size(), 256u) << "the same choice every time";
}

// A skinned primitive on a node with the extension: its joints place it, so it is posed once,
// with a note (the extension defines no instanced skinning).
TEST(GltfInstancing, SkinnedMeshIsPosedOnceWithANote) {
  nlohmann::json m = nlohmann::json::parse(test::tinySkinnedModel());
  m["accessors"].push_back({{"bufferView", 0}, {"componentType", 5126}, {"count", 2}, {"type", "VEC3"}});
  m["nodes"][0]["extensions"]["EXT_mesh_gpu_instancing"]["attributes"]["TRANSLATION"] = m["accessors"].size() - 1;
  GltfImport imp = importGltfText(m.dump(), "skinned.gltf");
  ASSERT_EQ(imp.data.nodes[0].instances.size(), 2u);
  std::vector<std::string> notes;
  std::vector<GltfInstance> inst = gltfInstances(imp, &notes);
  ASSERT_EQ(inst.size(), 1u);
  EXPECT_EQ(inst[0].gpuInstance, -1);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("node 0 'skinned' has 2 GPU instances (EXT_mesh_gpu_instancing), which are not posed for the "
                          "skinned mesh 0"),
            std::string::npos)
      << notes[0];
}


// (b, on the device) `validate` checks every GPU instance, and the world positions the device
// computed for each equal the hand values.
TEST(GltfInstancing, ValidateChecksEveryGpuInstanceOnTheDevice) {
  fs::path d = scratch("validate");
  std::ofstream(d / "m.gltf") << threeInstances();
  CliRun r = cli(fmt::format("validate --rig \"{}#*\" -f \"{}\" -r \"{}\" --time 0 --no-validation-layers --report "
                             "\"{}\" --save-outputs \"{}\"",
                             (d / "m.gltf").string(), sourcePath("tests/gltf/data/minimal.frag"),
                             sourcePath("rules/standard.yaml"), (d / "r.json").string(), (d / "saved").string()));
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("instances: 3 checked, each at every time (node 1 'tris' instance 0, node 1 'tris' instance 1, "
                       "node 1 'tris' instance 2)"),
            std::string::npos)
      << r.out;
  std::ifstream rin(d / "r.json");
  nlohmann::json rep = nlohmann::json::parse(rin);
  ASSERT_EQ(rep["primitives"][0]["instances"].size(), 3u);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(rep["primitives"][0]["instances"][i]["gpu_instance"], i);
  std::ifstream sin(d / "saved" / "outputs.json");
  nlohmann::json saved = nlohmann::json::parse(sin);
  int checked = 0;
  for (const auto& a : saved["primitives"][0]["arrays"]) {
    if (a["output"] != "world_position") continue;
    const int i = a["instance"].get<int>();
    std::ifstream f(d / "saved" / a["file"].get<std::string>(), std::ios::binary);
    std::vector<float> v(9);
    f.read(reinterpret_cast<char*>(v.data()), 36);
    for (int k = 0; k < 3; ++k) {
      std::array<double, 3> e = handWorld(i, kTri[k][0], kTri[k][1], kTri[k][2]);
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(v[size_t(k * 3 + c)], e[size_t(c)], 1e-4) << "instance " << i;
    }
    ++checked;
  }
  EXPECT_EQ(checked, 3);
  fs::remove_all(d);
}

// `render` draws every GPU instance (the scene's first, then the others).
TEST(GltfInstancing, RenderDrawsEveryGpuInstance) {
  fs::path d = scratch("render");
  std::ofstream(d / "m.gltf") << threeInstances();
  RenderOptions ro;
  ro.gen.rigPath = (d / "m.gltf").string() + "#*";
  ro.gen.fragmentPath = sourcePath("tests/gltf/data/minimal.frag");
  ro.gen.rulesPaths = {sourcePath("rules/standard.yaml")};
  ro.width = ro.height = 64;
  std::vector<GltfPart> gp = gltfParts((d / "m.gltf").string());
  std::vector<ModelPart> parts{modelPart(ro, gp.at(0))};
  ASSERT_EQ(parts[0].instances.size(), 2u) << "instances 1 and 2 after the scene's own pose (instance 0)";
  frameModel(parts, ro.camera, 1.0f);
  RenderSession session("", false);
  FragmentProgram fp = compileFragmentFile(ro.gen.fragmentPath, ro.gen.targetEnv);
  std::vector<rt::Image> draws;
  session.renderModel(parts, fp, texturesFor(fp, ro.lighting), ro, &draws);
  ASSERT_EQ(draws.size(), 3u);
  for (const auto& im : draws) {
    size_t covered = 0;
    for (float z : im.depth) covered += z < 1.0f;
    EXPECT_GT(covered, 0u);
  }
  fs::remove_all(d);
}

}  // namespace
}  // namespace sg

// Workload features (measure/workload.h): hand-computed values on tiny meshes built here,
// and bounds that must hold on real models (../shared/models).
#include <gtest/gtest.h>

#include <filesystem>

#include "measure/workload.h"

namespace sg {
namespace {

// n vertices with influence set 0 (slots x..w); joints/weights filled by the caller.
rt::Mesh skinned(size_t n) {
  rt::Mesh m;
  m.vertexCount = n;
  m.streams["vertex.position"].assign(n, glm::vec4(0));
  m.streams["skin.joints[0]"].assign(n, glm::vec4(0));
  m.streams["skin.weights[0]"].assign(n, glm::vec4(0));
  return m;
}

TEST(Workload, JointsPerWarpCountsDistinctWeightedJointsPerGroupAndSlot) {
  rt::Mesh m = skinned(64);
  auto& j = m.streams["skin.joints[0]"];
  auto& w = m.streams["skin.weights[0]"];
  for (size_t v = 0; v < 64; ++v) {
    j[v].x = float(v % 4);  // slot 0: joints 0..3 in every group of 32 -> 4 each
    w[v].x = 1;
    if (v < 32) {  // slot 1: joint 7 in the first group only -> 1
      j[v].y = 7;
      w[v].y = 0.5f;
    }
    j[v].z = float(v);  // slot 2: a different joint per vertex, all weighing 0 -> not counted
  }
  // Pairs (group, slot) with a weighted influence: (0,0)=4, (1,0)=4, (0,1)=1: mean 9/3.
  Workload wl = measureWorkload(m, {}, false, -1, "hand");
  EXPECT_DOUBLE_EQ(wl.jointsPerWarp, 3.0);
  // A rig reading only the first influence: slot 0 alone, 4 per group.
  EXPECT_DOUBLE_EQ(measureWorkload(m, {}, false, -1, "hand", 1).jointsPerWarp, 4.0);
  // A warp's palette footprint, every weighted slot together: {0,1,2,3,7} and {0,1,2,3}.
  EXPECT_DOUBLE_EQ(wl.paletteEntriesPerWarp, 4.5);
  // What explain and bench print (docs/device-profiles.md reads the footprint from it).
  EXPECT_NE(describeWorkload(wl).find("3.00 distinct joints per warp (4.5 over all its influences)"), std::string::npos)
      << describeWorkload(wl);
  EXPECT_DOUBLE_EQ(measureWorkload(m, {}, false, -1, "hand", 1).paletteEntriesPerWarp, 4.0);
  for (size_t v = 0; v < 32; ++v) j[v].y = 3;  // slot 1 reads a joint slot 0 reads too: one entry
  EXPECT_DOUBLE_EQ(measureWorkload(m, {}, false, -1, "hand").paletteEntriesPerWarp, 4.0);
  EXPECT_DOUBLE_EQ(measureWorkload(m, {}, false, -1, "hand").jointsPerWarp, 3.0);
  EXPECT_DOUBLE_EQ(wl.verticesPerDraw, 64);
  EXPECT_EQ(wl.activeMorphTargets, -1);
  EXPECT_EQ(wl.invocationsPerVertex, 0);  // not triangles: unknown
  EXPECT_EQ(wl.source, "hand");
}

TEST(Workload, GroupsFollowTheIndexBuffersFirstReferencesAndSkipUnreferencedVertices) {
  // 34 vertices: 0..15 on joint 0, 16..31 on joint 1, 32 on joint 2, 33 (never drawn) on 5.
  rt::Mesh m = skinned(34);
  for (size_t v = 0; v < 34; ++v) {
    m.streams["skin.joints[0]"][v].x = v < 16 ? 0.f : v < 32 ? 1.f : v == 32 ? 2.f : 5.f;
    m.streams["skin.weights[0]"][v].x = 1;
  }
  // Shaded order 32, 0, 1, ..., 31: groups {32, 0..30} -> joints {2, 0, 1} = 3 and {31} -> 1.
  std::vector<uint32_t> idx{32, 0, 1};
  for (uint32_t v = 2; v < 32; v += 3) idx.insert(idx.end(), {v, v + 1, v + 2});
  Workload byIndex = measureWorkload(m, idx, true, 0, "");
  EXPECT_DOUBLE_EQ(byIndex.jointsPerWarp, 2.0);
  // In vertex order (no index buffer) the groups are {0..31} -> 2 and {32, 33} -> 2.
  EXPECT_DOUBLE_EQ(measureWorkload(m, {}, false, 0, "").jointsPerWarp, 2.0);
  m.streams["skin.joints[0]"][33].x = 2;  // then {32, 33} -> 1: mean 1.5
  EXPECT_DOUBLE_EQ(measureWorkload(m, {}, false, 0, "").jointsPerWarp, 1.5);
  EXPECT_DOUBLE_EQ(measureWorkload(m, idx, true, 0, "").jointsPerWarp, 2.0);  // 33 is never shaded
}

TEST(Workload, UnskinnedMeshesHaveNoJointsPerWarp) {
  rt::Mesh m;
  m.vertexCount = 3;
  m.streams["vertex.position"].assign(3, glm::vec4(0));
  EXPECT_EQ(measureWorkload(m, {0, 1, 2}, true, 0, "").jointsPerWarp, 0);
  rt::Mesh z = skinned(3);  // streams present, every weight 0
  EXPECT_EQ(measureWorkload(z, {0, 1, 2}, true, 0, "").jointsPerWarp, 0);
  EXPECT_EQ(measureWorkload(z, {0, 1, 2}, true, 0, "").paletteEntriesPerWarp, 0);
  EXPECT_EQ(describeWorkload(measureWorkload(z, {0, 1, 2}, true, 0, "")).find("over all its influences"), std::string::npos);
}

TEST(Workload, InvocationsPerVertexCountTransformsPerShadedVertex) {
  // 300 vertices in 100 separate triangles: each shaded once, whatever the cache model.
  rt::Mesh m;
  m.vertexCount = 310;  // 10 never referenced: they do not dilute the figure
  std::vector<uint32_t> once;
  for (uint32_t v = 0; v < 300; ++v) once.push_back(v);
  EXPECT_DOUBLE_EQ(measureWorkload(m, once, true, 0, "").invocationsPerVertex, 1.0);
  // The same list drawn twice: 300 vertices between two uses of each, far beyond a 32-entry
  // cache, so each is shaded twice.
  std::vector<uint32_t> twice = once;
  twice.insert(twice.end(), once.begin(), once.end());
  EXPECT_DOUBLE_EQ(measureWorkload(m, twice, true, 0, "").invocationsPerVertex, 2.0);
  // A triangle repeated at once hits the cache: 3 transforms for 3 vertices.
  rt::Mesh t;
  t.vertexCount = 3;
  EXPECT_DOUBLE_EQ(measureWorkload(t, {0, 1, 2, 0, 1, 2, 2, 1, 0}, true, 0, "").invocationsPerVertex, 1.0);
}

const std::string kSource = SG_SOURCE_DIR;
const std::string kModels = std::string(SG_SHARED_DIR) + "/models/";

TEST(Workload, ProceduralMeshOfAYamlRig) {
  // The Dawn face (98 bones, 4 influences) on the procedural head: 41 x 49 vertices in rows.
  const Workload w = rigWorkload(kSource + "/examples/dawn/face.rig.yaml", {}, "head");
  EXPECT_EQ(w.verticesPerDraw, 41 * 49);
  EXPECT_GE(w.jointsPerWarp, 1.0);
  EXPECT_LE(w.jointsPerWarp, 32.0);
  EXPECT_EQ(w.activeMorphTargets, -1);  // no animation: unknown
  // Rows of 49 vertices do not fit a 32-entry cache: each vertex is shaded about twice,
  // between once and the six times of no reuse.
  EXPECT_GT(w.invocationsPerVertex, 1.2);
  EXPECT_LT(w.invocationsPerVertex, 3.0);
  // One influence: every vertex reads only its nearest bone; fewer distinct joints per group.
  const Workload one = rigWorkload(kSource + "/examples/dawn/face.rig.yaml", {{"influences", 1}}, "head");
  EXPECT_GE(one.jointsPerWarp, 1.0);
  EXPECT_NE(one.jointsPerWarp, w.jointsPerWarp);
  // No mesh: unknown, and said so.
  const Workload none = rigWorkload(kSource + "/examples/dawn/face.rig.yaml", {}, "");
  EXPECT_FALSE(none.known());
  EXPECT_NE(none.source.find("unknown"), std::string::npos);
  EXPECT_THROW(rigWorkload(kSource + "/examples/dawn/face.rig.yaml", {}, "cube"), InputError);
}

TEST(Workload, RealModelsWithinTheirSkinsAndTargets) {
  if (!std::filesystem::exists(kModels + "Fox/Fox.glb")) GTEST_SKIP() << "no ../shared/models";
  size_t skinnedParts = 0, morphedParts = 0;
  for (const char* file : {"CesiumMan/CesiumMan.glb", "RiggedFigure/RiggedFigure.glb", "Fox/Fox.glb",
                           "RobotExpressive/RobotExpressive.glb"}) {
    const std::string path = kModels + file;
    if (!std::filesystem::exists(path)) continue;
    for (const GltfPart& part : gltfParts(path)) {
      SCOPED_TRACE(part.ref);
      GltfImportOptions io;
      io.mesh = part.mesh;
      io.primitive = part.primitive;
      const GltfImport model = importGltf(path, io);
      const Workload w = rigWorkload(part.ref, {}, "");
      EXPECT_EQ(w.verticesPerDraw, double(model.data.vertexCount));
      if (model.joints > 0) {
        ++skinnedParts;
        EXPECT_GE(w.jointsPerWarp, 1.0);
        EXPECT_LE(w.jointsPerWarp, std::min(32.0, double(model.joints)));
      } else {
        EXPECT_EQ(w.jointsPerWarp, 0);
      }
      EXPECT_GE(w.activeMorphTargets, 0);
      EXPECT_LE(w.activeMorphTargets, model.morphTargets);
      if (model.morphTargets > 0) ++morphedParts;
      // Indexed triangles: each referenced vertex shaded at least once, at most 6 times per
      // triangle corner's worth (3 per triangle over at least 1/2 a vertex per triangle).
      EXPECT_GE(w.invocationsPerVertex, 1.0);
      EXPECT_LE(w.invocationsPerVertex, 6.0);
      EXPECT_NE(w.source.find(model.data.stem), std::string::npos);
    }
  }
  EXPECT_GT(skinnedParts, 3u);
  // RobotExpressive's head primitives have 3 targets whose animations leave them at 0
  // (validate/gltf_scene.h): none active. AnimatedMorphSphere's animation moves its 2.
  if (std::filesystem::exists(kModels + "RobotExpressive/RobotExpressive.glb")) {
    EXPECT_GE(morphedParts, 3u);
    for (const GltfPart& part : gltfParts(kModels + "RobotExpressive/RobotExpressive.glb"))
      EXPECT_EQ(rigWorkload(part.ref, {}, "").activeMorphTargets, 0) << part.ref;
  }
  const Workload sphere = rigWorkload(kModels + "AnimatedMorphSphere/AnimatedMorphSphere.gltf", {}, "");
  EXPECT_GE(sphere.activeMorphTargets, 1);
  EXPECT_LE(sphere.activeMorphTargets, 2);
  EXPECT_THROW(rigWorkload(kModels + "Fox/Fox.glb#0/0", {}, "head"), InputError);  // its own mesh only
  // A level-of-detail glTF rig with one influence reads slot 0 only, the slot whose joints
  // vary most across a warp (later slots hold fewer, often zero-weight, influences): its mean
  // is that slot's alone.
  const double lod = rigWorkload(kModels + "Fox/Fox.glb#0/0", {{"influences", 1}}, "").jointsPerWarp;
  EXPECT_GT(lod, rigWorkload(kModels + "Fox/Fox.glb#0/0", {}, "").jointsPerWarp);
  EXPECT_LE(lod, 24.0);  // the Fox's skin has 24 joints
}

}  // namespace
}  // namespace sg

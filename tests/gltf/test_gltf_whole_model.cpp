// Whole models (MODEL.glb#*, docs/gltf.md#whole-models): part names, and every command over
// the shared Fox and three.js's RobotExpressive (rigid meshes on animated nodes, a morphed
// head, skinned hands; tests/gltf/data/RobotExpressive).
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "cli_run.h"
#include "gltf_test_util.h"
#include "render/render.h"
#include "runtime/reference.h"
#include "validate/gltf_scene.h"
#include "rig/gltf_import.h"
#include "variants/manifest.h"

namespace sg {
namespace {

namespace fs = std::filesystem;
using test::dataPath;
using test::modelPath;
using test::sourcePath;
using test::CliRun;
using test::cli;
using test::shell;

// three.js's RobotExpressive (CC0): a fetched data file, so it lives in ../shared/models, not
// in this repository; the tests that need it skip until it is installed there.
std::string robot() { return modelPath("RobotExpressive/RobotExpressive.glb"); }
#define SKIP_WITHOUT_ROBOT()                                                                       \
  if (!fs::exists(robot()))                                                                        \
  GTEST_SKIP() << robot() << " is not installed (three.js's RobotExpressive.glb, CC0; see docs/gltf.md)"


fs::path scratch(const std::string& name) {
  fs::path d = fs::temp_directory_path() / ("sg_whole_" + name);
  fs::remove_all(d);
  return d;
}

// The 19 primitives of RobotExpressive, named from its JSON (mesh names, primitive counts).
const std::vector<std::string> kRobotParts = {
    "m0p0-Foot.L",     "m1p0-Torso", "m1p1-Torso",  "m2p0-Head",       "m2p1-Head",       "m2p2-Head",
    "m3p0-Foot.R",     "m4p0-Shoulder.L", "m5p0-Arm.L", "m6p0-Shoulder.R", "m7p0-Arm.R",  "m8p0-Leg.L",
    "m9p0-LowerLeg.L", "m10p0-Leg.R", "m11p0-LowerLeg.R", "m12p0-Hand.R", "m12p1-Hand.R", "m13p0-Hand.L",
    "m13p1-Hand.L"};

TEST(WholeModel, PartNamesAreIndexedSanitizedAndUnique) {
  EXPECT_EQ(gltfPartName(2, 1, "Head"), "m2p1-Head");
  EXPECT_EQ(gltfPartName(3, 0, ""), "m3p0");
  EXPECT_EQ(gltfPartName(0, 0, "../a b/\xc3\xa9"), "m0p0-.._a_b___");
  EXPECT_EQ(gltfPartName(1, 2, std::string(100, 'x')), "m1p2-" + std::string(48, 'x'));
  // Two meshes of one name still differ (the index prefix).
  EXPECT_NE(gltfPartName(0, 0, "Cube"), gltfPartName(1, 0, "Cube"));

  SKIP_WITHOUT_ROBOT();
  std::vector<GltfPart> parts = gltfParts(robot());
  std::vector<std::string> names;
  for (const auto& p : parts) names.push_back(p.name);
  EXPECT_EQ(names, kRobotParts);
  EXPECT_EQ(parts[4].ref, robot() + "#2/1");
  EXPECT_EQ(parts[4].meshName, "Head");
  EXPECT_EQ(parseGltfRef(robot() + "#*", true).wholeModel, true);
  EXPECT_THROW(parseGltfRef(robot() + "#*"), InputError);  // commands that take one primitive
}

// The model's kinds of primitive, as the import sees them: what "rigid, skinned and morphed
// parts together" means for this model.
TEST(WholeModel, RobotHasRigidSkinnedAndMorphedParts) {
  SKIP_WITHOUT_ROBOT();
  int rigid = 0, skinned = 0, morphed = 0;
  for (const auto& p : gltfParts(robot())) {
    GltfImportOptions o;
    o.mesh = p.mesh;
    o.primitive = p.primitive;
    GltfImport imp = importGltf(robot(), o);
    if (imp.joints > 0) ++skinned;
    if (imp.morphTargets > 0) ++morphed;
    if (imp.joints == 0 && imp.morphTargets == 0) ++rigid;
  }
  EXPECT_EQ(rigid, 12);
  EXPECT_EQ(skinned, 4);  // the hands, 43 joints each
  EXPECT_EQ(morphed, 3);  // the head's primitives: Angry, Surprised, Sad
}

// Done-when of issue 24: one command validates every primitive, at two times, for the Fox
// and for the robot (with an expression held, so the head's targets are exercised).
TEST(WholeModel, ValidateEveryPrimitiveOfFoxAndRobotAtTwoTimes) {
  CliRun fox = cli(fmt::format("validate --rig \"{}#*\" -f \"{}\" -r \"{}\" --animation Run --time 0.25 --time 0.8",
                            modelPath("Fox/Fox.glb"), dataPath("uv.frag"), sourcePath("rules/standard.yaml")));
  EXPECT_EQ(fox.status, 0) << fox.out;
  EXPECT_NE(fox.out.find("1 of 1 primitive(s) pass"), std::string::npos) << fox.out;
  EXPECT_NE(fox.out.find("PASS  m0p0-fox1"), std::string::npos) << fox.out;

  SKIP_WITHOUT_ROBOT();
  CliRun r = cli(fmt::format("validate --rig \"{}#*\" -f \"{}\" -r \"{}\" --animation Dance --time 0.6 --time 2.1 "
                          "--morph-weight 0.6",
                          robot(), dataPath("lit.frag"), sourcePath("rules/standard.yaml")));
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("19 of 19 primitive(s) pass"), std::string::npos) << r.out;
  for (const auto& name : kRobotParts)
    EXPECT_NE(r.out.find("PASS  " + name + "  "), std::string::npos) << name << "\n" << r.out;
  EXPECT_NE(r.out.find("m12p0-Hand.R  (" + robot() + "#12/0): "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("skinned (43 joints)"), std::string::npos);
  EXPECT_NE(r.out.find("rigid, 3 morph target(s)"), std::string::npos);
  EXPECT_EQ(r.out.find("not exercised"), std::string::npos) << "--morph-weight must reach the head";
}

// A broken rule that only the morphed primitives use (the position deltas counted twice):
// the command fails and names exactly the primitive it breaks, m2p2-Head, the eyebrows:
// the head's other two primitives have targets whose position deltas are all zero (their
// accessors' min and max are 0), so doubling them changes nothing. The others still pass.
TEST(WholeModel, PlantedRuleFailureNamesTheMorphedPrimitives) {
  SKIP_WITHOUT_ROBOT();
  fs::path d = scratch("broken_rule");
  fs::create_directories(d);
  std::ofstream(d / "broken.yaml") << "include: [" << sourcePath("rules/standard.yaml") << "]\n"
                                   << R"(rules:
  - name: object_position_morphed
    override: true
    produces: object.position
    needs: [vertex.position, "morph.position[*]", morph.weights]
    when: has(morph.position)
    cost: morph_targets
    glsl: |
      ${out} = ${vertex.position};
      @for i in morph_targets
      ${out} += 2.0 * ${morph.weights}[${i}] * ${morph.position[i]};
      @end
)";
  CliRun r = cli(fmt::format("validate --rig \"{}#*\" -f \"{}\" -r \"{}\" --animation Wave --time 0.5 --morph-weight 0.8 "
                             "--report \"{}\"",
                             robot(), dataPath("lit.frag"), (d / "broken.yaml").string(), (d / "report.json").string()));
  EXPECT_EQ(r.status, 1) << r.out;
  // The report of a failing model is written too, and says where it fails.
  std::ifstream rin(d / "report.json");
  nlohmann::json rep = nlohmann::json::parse(rin);
  EXPECT_FALSE(rep["pass"].get<bool>());
  EXPECT_EQ(rep["tolerance"]["abs"], 1e-6);
  ASSERT_EQ(rep["primitives"].size(), 19u);
  for (const auto& p : rep["primitives"]) {
    const bool broken = p["name"] == "m2p2-Head";
    EXPECT_EQ(p["pass"].get<bool>(), !broken) << p["name"];
    const auto& run = p["runs"][0];
    EXPECT_FALSE(run["rules"].empty());
    EXPECT_EQ(run["poses"].size(), 1u);  // one instance, one time
    if (!broken) continue;
    EXPECT_FALSE(run["poses"][0]["pass"].get<bool>());
    bool positionFails = false;
    for (const auto& o : run["poses"][0]["outputs"])
      if (o["name"] == "gl_Position") positionFails = !o["pass"].get<bool>() && o["max_rel_error"].get<double>() > 1e-5;
    EXPECT_TRUE(positionFails) << run["poses"][0].dump();
  }
  EXPECT_NE(r.out.find("18 of 19 primitive(s) pass"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("RobotExpressive.glb#*: error: 1 of 19 primitive(s) failed (m2p2-Head); the model does not validate"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("FAIL  m2p2-Head  "), std::string::npos);
  EXPECT_NE(r.out.find("RobotExpressive.glb#2/2: error: primitive m2p2-Head failed"), std::string::npos);
  EXPECT_NE(r.out.find("PASS  m2p1-Head  "), std::string::npos);
  EXPECT_NE(r.out.find("PASS  m12p0-Hand.R  "), std::string::npos);
  EXPECT_NE(r.out.find("PASS  m1p0-Torso  "), std::string::npos);
  fs::remove_all(d);
}

// generate and rig import write one set of outputs per primitive and an index; a hostile
// primitive makes them fail naming it, with nothing written (not even the directory).
TEST(WholeModel, GenerateAndImportWriteEveryPrimitiveOrNothing) {
  SKIP_WITHOUT_ROBOT();
  fs::path out = scratch("generate");
  CliRun g = cli(fmt::format("generate -q --rig \"{}#*\" -f \"{}\" -r \"{}\" -o \"{}\" --emit glsl,spv,reflection", robot(),
                          dataPath("lit.frag"), sourcePath("rules/standard.yaml"), out.string()));
  ASSERT_EQ(g.status, 0) << g.out;
  std::ifstream in(out / "index.json");
  nlohmann::json index = nlohmann::json::parse(in);
  ASSERT_EQ(index["primitives"].size(), kRobotParts.size());
  for (size_t i = 0; i < kRobotParts.size(); ++i) {
    const auto& e = index["primitives"][i];
    EXPECT_EQ(e["name"], kRobotParts[i]);
    EXPECT_EQ(e["rig"], fmt::format("{}#{}/{}", robot(), e["mesh"].get<int>(), e["primitive"].get<int>()));
    ASSERT_EQ(e["files"].size(), 3u);
    for (const auto& f : e["files"]) EXPECT_TRUE(fs::is_regular_file(out / f.get<std::string>())) << f;
  }
  // Each primitive's program is the one `generate --rig MODEL#m/p` makes.
  fs::path one = scratch("generate_one.vert");
  CliRun single = cli(fmt::format("generate -q --rig \"{}#12/1\" -f \"{}\" -r \"{}\" -o \"{}\" --emit glsl", robot(),
                               dataPath("lit.frag"), sourcePath("rules/standard.yaml"), one.string()));
  ASSERT_EQ(single.status, 0) << single.out;
  auto slurp = [](const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
  };
  std::string a = slurp(out / "m12p1-Hand.R.vert"), b = slurp(one);
  // The GLSL names its own output file in a comment; the program is otherwise identical.
  auto strip = [](std::string s, const std::string& name) {
    for (size_t p; (p = s.find(name)) != std::string::npos;) s.erase(p, name.size());
    return s;
  };
  EXPECT_EQ(strip(a, (out / "m12p1-Hand.R.vert").string()), strip(b, one.string()));
  EXPECT_NE(a.find("bones"), std::string::npos);  // the hand is skinned

  fs::path rigs = scratch("rigs");
  CliRun imp = cli(fmt::format("rig import -q \"{}#*\" -o \"{}\"", robot(), rigs.string()));
  ASSERT_EQ(imp.status, 0) << imp.out;
  for (const auto& name : kRobotParts) EXPECT_TRUE(fs::is_regular_file(rigs / (name + ".yaml"))) << name;
  Rig head = loadRigFile((rigs / "m2p1-Head.yaml").string());
  EXPECT_EQ(head.name, "RobotExpressive/Head/1");
  EXPECT_EQ(head.morphTargets(), 3);

  // A model whose second mesh is hostile: nothing is written, the primitive is named.
  fs::path bad = scratch("hostile");
  fs::create_directories(bad);
  std::ofstream(bad / "m.gltf")
      << R"({"asset":{"version":"2.0"},"buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}],)"
         R"("bufferViews":[{"buffer":0,"byteLength":36}],"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"},)"
         R"({"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","byteOffset":400}],)"
         R"("meshes":[{"name":"good","primitives":[{"attributes":{"POSITION":0}}]},{"name":"bad","primitives":[{"attributes":{"POSITION":1}}]}],)"
         R"("nodes":[{"mesh":0},{"mesh":1}],"scenes":[{"nodes":[0,1]}]})";
  fs::path none = bad / "out" / "shaders";
  CliRun fail = cli(fmt::format("generate -q --rig \"{}#*\" -f \"{}\" -r \"{}\" -o \"{}\"", (bad / "m.gltf").string(),
                             dataPath("minimal.frag"), sourcePath("rules/standard.yaml"), none.string()));
  EXPECT_EQ(fail.status, 1) << fail.out;
  EXPECT_NE(fail.out.find("error: primitive m1p0-bad failed"), std::string::npos) << fail.out;
  EXPECT_NE(fail.out.find("1 of 2 primitive(s) failed (m1p0-bad); nothing was written"), std::string::npos) << fail.out;
  EXPECT_FALSE(fs::exists(bad / "out")) << "a failed whole-model generate left a directory";
  fs::remove_all(out);
  fs::remove_all(one);
  fs::remove_all(rigs);
  fs::remove_all(bad);
}

// A manifest's whole-model rig is one rig per primitive; a rig axis value naming the model
// stands for all of them, and exclusions name the parts.
// bench MODEL.glb#*: every primitive timed on its own mesh (its vertex count, its workload),
// one table each, each program validated on the device first.
TEST(WholeModel, BenchTimesEveryPrimitiveOnItsOwnMesh) {
  SKIP_WITHOUT_ROBOT();
  CliRun b = cli(fmt::format("bench --rig \"{}#*\" -f \"{}\" -r \"{}\" --draws 1 --frames 1 --rounds 1 --raster off "
                             "--no-alternatives --no-floor --no-validation-layers",
                             robot(), sourcePath("examples/render/flat.frag"), sourcePath("rules/standard.yaml")));
  ASSERT_EQ(b.status, 0) << b.out;
  for (const GltfPart& part : gltfParts(robot())) {
    SCOPED_TRACE(part.ref);
    const size_t at = b.out.find(fmt::format("## {} ({})", part.name, part.ref));
    ASSERT_NE(at, std::string::npos) << b.out;
    GltfImportOptions io;
    io.mesh = part.mesh;
    io.primitive = part.primitive;
    const size_t vertices = importGltf(robot(), io).data.vertexCount;
    EXPECT_EQ(b.out.find(fmt::format("mesh: {} vertices", vertices), at), b.out.find("mesh: ", at));
    EXPECT_EQ(b.out.find(fmt::format("workload: {} vertices per draw", vertices), at), b.out.find("workload: ", at));
    EXPECT_NE(b.out.find("| generated | pass |", at), std::string::npos);
  }
  // With a profile, generate records the primitive's workload in the reflection; without one
  // the workload prices nothing and --mesh is refused.
  fs::path json = scratch("workload.json");
  CliRun g = cli(fmt::format("generate -q --rig \"{}#12/1\" -f \"{}\" -r \"{}\" --device-profile \"{}\" --emit reflection -o \"{}\"",
                             robot(), sourcePath("examples/render/flat.frag"), sourcePath("rules/standard.yaml"),
                             sourcePath("devices/nvidia-h200.yaml"), json.string()));
  ASSERT_EQ(g.status, 0) << g.out;
  const nlohmann::json r = nlohmann::json::parse(std::ifstream(json));
  ASSERT_TRUE(r.contains("workload")) << r.dump();
  EXPECT_GE(r["workload"]["joints_per_warp"].get<double>(), 1.0);  // the hand is skinned
  CliRun refused = cli(fmt::format("generate -q --rig \"{}\" -f \"{}\" -r \"{}\" --mesh dawn -o \"{}\"",
                                   sourcePath("examples/dawn/face.rig.yaml"), sourcePath("examples/dawn/face.frag"),
                                   sourcePath("examples/dawn/rules.yaml"), json.string()));
  EXPECT_NE(refused.status, 0);
  EXPECT_NE(refused.out.find("--mesh: does not apply without --device-profile"), std::string::npos) << refused.out;
}

TEST(WholeModel, ManifestExpandsAWholeModelIntoOneRigPerPrimitive) {
  SKIP_WITHOUT_ROBOT();
  std::string text = fmt::format(R"(rules: {}
rigs:
  robot: {}#*
  face: {}
passes:
  lit: {}
axes:
  rig: [face, robot]
exclude:
  - {{ rig: robot.m2p1-Head }}
)",
                                 sourcePath("rules/standard.yaml"), robot(), sourcePath("examples/dawn/face.rig.yaml"),
                                 dataPath("lit.frag"));
  Manifest m = loadManifestText(text, "m.yaml");
  ASSERT_EQ(m.rigs.size(), 1 + kRobotParts.size());
  EXPECT_EQ(m.rigs[0].name, "robot.m0p0-Foot.L");
  EXPECT_EQ(m.rigs[0].path, robot() + "#0/0");
  EXPECT_EQ(m.rigs.back().name, "face");
  std::vector<Variant> vs = expandVariants(m);
  ASSERT_EQ(vs.size(), 1 + kRobotParts.size() - 1);
  EXPECT_EQ(vs[0].name, "face-lit");
  EXPECT_EQ(vs[1].name, "robot.m0p0-Foot.L-lit");
  for (const auto& v : vs) EXPECT_NE(v.name, "robot.m2p1-Head-lit");

  EXPECT_THROW(loadManifestText("rules: r.yaml\nrigs:\n  r: face.rig.yaml#*\npasses:\n  p: x.frag\n", "m.yaml"),
               InputError);
}

// The whole model drawn: the picture covers exactly the union of the primitives' own
// silhouettes under the same camera, each pixel shows the nearest primitive, and the
// rigid parts are drawn at their animated nodes (the union is larger than any one part).
TEST(WholeModel, RenderCoversTheUnionOfThePrimitivesSilhouettes) {
  SKIP_WITHOUT_ROBOT();
  fs::path png = scratch("robot.png");
  const std::string frag = dataPath("lit.frag");
  CliRun r = cli(fmt::format("render --rig \"{}#*\" -f \"{}\" -r \"{}\" --animation Wave --time 0.9 --size 160x200 -o \"{}\"",
                          robot(), frag, sourcePath("rules/standard.yaml"), png.string()));
  ASSERT_EQ(r.status, 0) << r.out;
  rt::Image whole = readPng(png.string());

  RenderOptions ro;
  ro.gen.rigPath = robot() + "#*";
  ro.gen.fragmentPath = frag;
  ro.gen.rulesPaths = {sourcePath("rules/standard.yaml")};
  ro.animation = "Wave";
  ro.time = 0.9;
  ro.width = 160;
  ro.height = 200;
  std::vector<ModelPart> parts;
  for (const auto& p : gltfParts(robot())) parts.push_back(modelPart(ro, p));
  frameModel(parts, ro.camera, 160.0f / 200.0f);
  RenderSession session("", false);
  FragmentProgram fp = compileFragmentFile(frag, ro.gen.targetEnv);
  std::vector<rt::Texture> textures = texturesFor(fp, ro.lighting);
  std::vector<rt::Image> own;
  for (const auto& p : parts) own.push_back(session.render(p.gen, fp, textures, p.scene, ro).image);

  size_t unionCovered = 0, largest = 0, mismatched = 0;
  for (const auto& im : own) {
    size_t c = 0;
    for (float d : im.depth) c += d < 1.0f;
    EXPECT_GT(c, 0u) << "a primitive is not in the picture";
    largest = std::max(largest, c);
  }
  for (size_t px = 0; px < whole.rgba.size() / 4; ++px) {
    size_t nearest = SIZE_MAX;
    for (size_t i = 0; i < own.size(); ++i)
      if (own[i].depth[px] < 1.0f && (nearest == SIZE_MAX || own[i].depth[px] < own[nearest].depth[px])) nearest = i;
    const uint8_t* w = &whole.rgba[px * 4];
    // lit.frag never writes the background's colour (its grey is at least 0.2).
    bool covered = !(w[0] == 15 && w[1] == 15 && w[2] == 20);
    if (nearest != SIZE_MAX) ++unionCovered;
    if (covered != (nearest != SIZE_MAX)) {
      ++mismatched;
      continue;
    }
    if (nearest != SIZE_MAX && std::memcmp(w, &own[nearest].rgba[px * 4], 3) != 0) ++mismatched;
  }
  EXPECT_EQ(mismatched, 0u);
  EXPECT_GT(unionCovered, largest + largest / 2) << "the parts do not add up to a character";
  fs::remove(png);
}

// A mesh that two nodes instantiate is drawn at both: one primitive, one program, two
// triangles in the picture, side by side (translations -2 and +2 on x).
TEST(WholeModel, RenderDrawsEveryNodeThatInstantiatesAMesh) {
  fs::path d = scratch("instances");
  fs::create_directories(d);
  std::ofstream(d / "m.gltf")
      << R"({"asset":{"version":"2.0"},"buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}],)"
         R"("bufferViews":[{"buffer":0,"byteLength":36}],"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],)"
         R"("meshes":[{"name":"tri","primitives":[{"attributes":{"POSITION":0}}]}],)"
         R"("nodes":[{"mesh":0,"translation":[-2,0,0]},{"mesh":0,"translation":[2,0,0]}],"scenes":[{"nodes":[0,1]}]})";
  RenderOptions ro;
  ro.gen.rigPath = (d / "m.gltf").string() + "#*";
  ro.gen.fragmentPath = dataPath("minimal.frag");
  ro.gen.rulesPaths = {sourcePath("rules/standard.yaml")};
  ro.width = ro.height = 96;
  std::vector<GltfPart> gp = gltfParts((d / "m.gltf").string());
  ASSERT_EQ(gp.size(), 1u);
  std::vector<ModelPart> parts{modelPart(ro, gp[0])};
  ASSERT_EQ(parts[0].instances.size(), 1u);
  frameModel(parts, ro.camera, 1.0f);
  RenderSession session("", false);
  FragmentProgram fp = compileFragmentFile(ro.gen.fragmentPath, ro.gen.targetEnv);
  std::vector<rt::Image> draws;
  RenderResult r = session.renderModel(parts, fp, texturesFor(fp, ro.lighting), ro, &draws);
  ASSERT_EQ(draws.size(), 2u);
  // Each instance covers pixels on its own side of the image and none of the other's.
  auto columns = [](const rt::Image& im) {
    uint32_t lo = im.width, hi = 0;
    size_t n = 0;
    for (uint32_t y = 0; y < im.height; ++y)
      for (uint32_t x = 0; x < im.width; ++x)
        if (im.depth[size_t(y) * im.width + x] < 1.0f) {
          lo = std::min(lo, x);
          hi = std::max(hi, x);
          ++n;
        }
    return std::make_tuple(lo, hi, n);
  };
  auto [lo0, hi0, n0] = columns(draws[0]);
  auto [lo1, hi1, n1] = columns(draws[1]);
  auto [loW, hiW, nW] = columns(r.image);
  EXPECT_GT(n0, 0u);
  EXPECT_GT(n1, 0u);
  EXPECT_LT(hi0, lo1) << "the node at x = -2 is drawn left of the one at x = +2";
  EXPECT_EQ(nW, n0 + n1);
  EXPECT_EQ(loW, lo0);
  EXPECT_EQ(hiW, hi1);
  fs::remove_all(d);
}

// RecursiveSkeletons: one mesh drawn by 84 nodes, each with its own skin (skeletons nested in
// skeletons). Every instance is posed with its own skin and checked at every time; the report
// lists them; each is posed differently (84 distinct places in the saved outputs).
std::string skeletons() { return modelPath("RecursiveSkeletons/RecursiveSkeletons.glb"); }

TEST(WholeModel, EveryInstanceOfRecursiveSkeletonsIsValidatedAndListed) {
  fs::path out = scratch("skeletons");
  CliRun r = cli(fmt::format("validate --rig \"{}#*\" -f \"{}\" -r \"{}\" --time 0.7 --time 1.4 --no-validation-layers "
                             "--report \"{}\" --save-outputs \"{}\"",
                             skeletons(), dataPath("minimal.frag"), sourcePath("rules/standard.yaml"),
                             (out / "report.json").string(), (out / "saved").string()));
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("instances: 84 checked, each at every time"), std::string::npos) << r.out;
  // The line names the first four and the last (the report lists every one, below).
  const std::string line = r.out.substr(r.out.find("instances: 84"), r.out.find('\n', r.out.find("instances: 84")) - r.out.find("instances: 84"));
  EXPECT_EQ(std::count(line.begin(), line.end(), ','), 6) << line;  // "checked, ": 1; the names: 5
  EXPECT_NE(line.find(", ..., node "), std::string::npos) << line;
  EXPECT_NE(r.out.find("PASS  m0p0-skinned_mesh  (" + skeletons() + "#0/0): 40 vertices, skinned (10 joints), 84 instance(s)"),
            std::string::npos)
      << r.out;
  std::ifstream in(out / "report.json");
  nlohmann::json rep = nlohmann::json::parse(in);
  ASSERT_EQ(rep["primitives"].size(), 1u);
  const auto& prim = rep["primitives"][0];
  ASSERT_EQ(prim["instances"].size(), 84u);
  std::set<int> nodes, skins;
  for (const auto& i : prim["instances"]) {
    nodes.insert(i["node"].get<int>());
    skins.insert(i["skin"].get<int>());
  }
  EXPECT_EQ(nodes.size(), 84u);
  EXPECT_EQ(skins.size(), 84u) << "each node has its own skin";
  const auto& poses = prim["runs"][0]["poses"];
  ASSERT_EQ(poses.size(), 168u);  // 84 instances x 2 times, instance-major
  for (size_t k = 0; k < poses.size(); ++k) {
    EXPECT_EQ(poses[k]["instance"], k / 2);
    EXPECT_EQ(poses[k]["time"], k % 2 ? 1.4 : 0.7);
    EXPECT_TRUE(poses[k]["pass"].get<bool>());
  }
  EXPECT_FALSE(rep["driver"].get<std::string>().empty());
  // Every instance posed in its own place: 84 distinct centroids at t = 0.7.
  std::ifstream sin(out / "saved" / "outputs.json");
  nlohmann::json saved = nlohmann::json::parse(sin);
  std::set<std::tuple<long, long, long>> centroids;
  for (const auto& a : saved["primitives"][0]["arrays"]) {
    if (a["output"] != "world_position" || a["time_index"] != 0) continue;
    std::ifstream f(out / "saved" / a["file"].get<std::string>(), std::ios::binary);
    std::vector<float> v(40 * 3);
    f.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(v.size() * 4));
    double c[3] = {0, 0, 0};
    for (size_t i = 0; i < 40; ++i)
      for (int k = 0; k < 3; ++k) c[k] += v[i * 3 + static_cast<size_t>(k)] / 40;
    centroids.insert({std::lround(c[0] * 1e4), std::lround(c[1] * 1e4), std::lround(c[2] * 1e4)});
  }
  EXPECT_EQ(centroids.size(), 84u);
  fs::remove_all(out);
}

// --report and --save-outputs write the same bytes on every run, under names that depend only
// on the model, the primitive, the instance, the time index and the output.
TEST(WholeModel, ReportAndSavedOutputsAreByteIdenticalAcrossRuns) {
  auto run = [&](const fs::path& out) {
    return cli(fmt::format("validate --rig \"{}#*\" -f \"{}\" -r \"{}\" --time 0.25 --no-validation-layers "
                           "--report \"{}\" --save-outputs \"{}\"",
                           modelPath("AnimatedMorphSphere/AnimatedMorphSphere.gltf"), dataPath("lit.frag"),
                           sourcePath("rules/standard.yaml"), (out / "report.json").string(), (out / "saved").string()));
  };
  fs::path a = scratch("determinism_a"), b = scratch("determinism_b");
  CliRun ra = run(a), rb = run(b);
  ASSERT_EQ(ra.status, 0) << ra.out;
  ASSERT_EQ(rb.status, 0) << rb.out;
  auto slurp = [](const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
  };
  std::vector<std::string> names;
  for (const auto& e : fs::recursive_directory_iterator(a))
    if (e.is_regular_file()) names.push_back(fs::relative(e.path(), a).string());
  std::sort(names.begin(), names.end());
  // report.json, outputs.json, one .glb and the 4 outputs of lit.frag's plan (gl_Position, world
  // position, eye direction, normal) of the one instance at the one time.
  EXPECT_EQ(names, (std::vector<std::string>{"report.json", "saved/m0p0-Sphere.i0.t0.gl_Position.bin",
                                             "saved/m0p0-Sphere.i0.t0.world_eye_dir.bin",
                                             "saved/m0p0-Sphere.i0.t0.world_normal.bin",
                                             "saved/m0p0-Sphere.i0.t0.world_position.bin", "saved/m0p0-Sphere.t0.glb",
                                             "saved/outputs.json"}));
  for (const auto& n : names) EXPECT_EQ(slurp(a / n), slurp(b / n)) << n << " differs between two runs";
  // The report names the file's device and the tolerance; the saved .glb is a GLB 2.0.
  std::string glb = slurp(a / "saved/m0p0-Sphere.t0.glb");
  ASSERT_GE(glb.size(), 20u);
  EXPECT_EQ(glb.substr(0, 4), "glTF");
  uint32_t total = 0;
  std::memcpy(&total, glb.data() + 8, 4);
  EXPECT_EQ(total, glb.size());
  // Writing over an input is refused before anything is written.
  CliRun clobber = cli(fmt::format("validate --rig \"{}#*\" -f \"{}\" -r \"{}\" --time 0.25 --report \"{}\"",
                                   modelPath("AnimatedMorphSphere/AnimatedMorphSphere.gltf"), dataPath("lit.frag"),
                                   sourcePath("rules/standard.yaml"), dataPath("lit.frag")));
  EXPECT_NE(clobber.status, 0);
  EXPECT_NE(clobber.out.find("refusing to overwrite an input"), std::string::npos) << clobber.out;
  fs::remove_all(a);
  fs::remove_all(b);
}

// The 84 figures drawn: the whole picture covers exactly the union of the 84 instances' own
// draws under the same camera, and every instance is in it (256 pixels: at 128 the thinnest
// figures fall between pixel centres).
TEST(WholeModel, RenderDrawsAll84RecursiveSkeletons) {
  fs::path png = scratch("skeletons.png");
  const std::string frag = dataPath("solid.frag");
  CliRun r = cli(fmt::format("render --rig \"{}#*\" -f \"{}\" -r \"{}\" --time 0.7 --size 256x256 -o \"{}\"",
                             skeletons(), frag, sourcePath("rules/standard.yaml"), png.string()));
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(r.out.find("not drawn"), std::string::npos) << r.out;
  rt::Image whole = readPng(png.string());
  RenderOptions ro;
  ro.gen.rigPath = skeletons() + "#*";
  ro.gen.fragmentPath = frag;
  ro.gen.rulesPaths = {sourcePath("rules/standard.yaml")};
  ro.time = 0.7;
  ro.width = ro.height = 256;
  std::vector<ModelPart> parts{modelPart(ro, gltfParts(skeletons()).front())};
  ASSERT_EQ(parts[0].instances.size(), 83u);
  frameModel(parts, ro.camera, 1.0f);
  RenderSession session("", false);
  FragmentProgram fp = compileFragmentFile(frag, ro.gen.targetEnv);
  std::vector<rt::Image> draws;
  session.renderModel(parts, fp, texturesFor(fp, ro.lighting), ro, &draws);
  ASSERT_EQ(draws.size(), 84u);
  size_t unionCovered = 0, mismatched = 0, largest = 0;
  std::vector<size_t> empty;
  for (size_t i = 0; i < draws.size(); ++i) {
    size_t c = 0;
    for (float d : draws[i].depth) c += d < 1.0f;
    if (c == 0) empty.push_back(i);
    largest = std::max(largest, c);
  }
  EXPECT_TRUE(empty.empty()) << "instances not in the picture: " << fmt::format("{}", fmt::join(empty, ", "));
  for (size_t px = 0; px < whole.rgba.size() / 4; ++px) {
    bool inUnion = false;
    for (const auto& im : draws) inUnion = inUnion || im.depth[px] < 1.0f;
    const uint8_t* w = &whole.rgba[px * 4];
    bool covered = w[0] == 255 && w[1] == 128 && w[2] == 64;  // solid.frag's colour, not the background
    unionCovered += inUnion;
    mismatched += covered != inUnion;
  }
  EXPECT_EQ(mismatched, 0u);
  EXPECT_GT(unionCovered, 2 * largest) << "84 figures cover far more than the largest one";
  fs::remove(png);
}

// gltfInstances on a skinned triangle drawn by two nodes (the bad-input corpus's model:
// skin 0 = joints [2, 3], vertex 2 bound to joint 1 = node 3, translated +1 on x): each
// instance posed by its own skin; a second skin larger than the palette poses with its first
// joints; a node repeating an earlier node's skin, or drawing the skinned mesh without one,
// is left out with a note.
TEST(WholeModel, InstancesArePosedByTheirOwnSkin) {
  std::ifstream in(sourcePath("tests/bad-input/gltf/instance-skin-too-small-validate/m.gltf"));
  nlohmann::json base = nlohmann::json::parse(in);
  fs::path d = scratch("skins");
  fs::create_directories(d);
  auto instancesOf = [&](const nlohmann::json& node1, const nlohmann::json& skin1, std::vector<std::string>* notes,
                         std::vector<glm::vec4>* secondWorld) {
    nlohmann::json m = base;
    m["nodes"][1] = node1;
    m["skins"][1]["joints"] = skin1;
    std::ofstream((d / "m.gltf").string()) << m.dump();
    GltfImport imp = importGltf((d / "m.gltf").string());
    GltfSceneOptions so;
    so.times = {0};
    so.allInstances = true;
    GltfSceneInfo info;
    ValidationScene scene = gltfScene(imp, so, &info);
    if (notes) *notes = info.notes;
    if (secondWorld && scene.poses.size() > 1)
      *secondWorld = rt::referenceValues("world.position", scene.mesh, scene.poses[1], scene.shape);
    if (scene.poses.size() == 2) {
      std::vector<glm::vec4> first = rt::referenceValues("world.position", scene.mesh, scene.poses[0], scene.shape);
      EXPECT_FLOAT_EQ(first[2].x, 1.0f) << "instance 0: vertex 2 follows node 3 (+1 on x)";
    }
    return info.instances;
  };
  std::vector<std::string> notes;
  std::vector<glm::vec4> world;
  // Skin 1 = joints [4, 2, 3]: three joints for a two-joint palette; vertex 2's joint 1 is node 2 (at the origin).
  std::vector<GltfInstance> two = instancesOf({{"mesh", 0}, {"skin", 1}}, {4, 2, 3}, &notes, &world);
  ASSERT_EQ(two.size(), 2u);
  EXPECT_EQ(two[0].node, 0);
  EXPECT_EQ(two[0].skin, 0);
  EXPECT_EQ(two[1].node, 1);
  EXPECT_EQ(two[1].skin, 1);
  ASSERT_EQ(world.size(), 3u);
  EXPECT_FLOAT_EQ(world[2].x, 0.0f) << "instance 1: vertex 2 follows node 2 (its skin's joint 1)";
  EXPECT_TRUE(notes.empty());
  // The same skin as node 0: posed identically, left out.
  EXPECT_EQ(instancesOf({{"mesh", 0}, {"skin", 0}}, {4}, &notes, nullptr).size(), 1u);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("node 1 poses mesh 0 exactly as an earlier node with skin 0"), std::string::npos) << notes[0];
  // No skin on a node drawing a skinned mesh: left out.
  EXPECT_EQ(instancesOf({{"mesh", 0}}, {4}, &notes, nullptr).size(), 1u);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("draws the skinned mesh 0 without a skin"), std::string::npos) << notes[0];
  // A skin too small for the joints the vertices use: the primitive fails, naming the node
  // (the import refuses it, ACCESSOR_JOINTS_INDEX_OOB against every skin instancing the mesh).
  try {
    instancesOf({{"mesh", 0}, {"skin", 1}}, {4}, nullptr, nullptr);
    ADD_FAILURE() << "a one-joint skin cannot pose vertices bound to joint 1";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("is joint 1, but skin 1 (of node 1) has 1 joints"), std::string::npos)
        << e.what();
  }
  fs::remove_all(d);
}

// A morphed mesh under two nodes with their own default weights: two instances, each posed
// with its node's weights (and with the animation's, when it targets that node).
TEST(WholeModel, InstancesCarryTheirNodesMorphWeights) {
  fs::path d = scratch("morph_instances");
  fs::create_directories(d);
  std::ofstream(d / "m.gltf")
      << R"({"asset":{"version":"2.0"},"buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}],)"
         R"("bufferViews":[{"buffer":0,"byteLength":36}],"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],)"
         R"("meshes":[{"name":"tri","primitives":[{"attributes":{"POSITION":0},"targets":[{"POSITION":0}]}],"weights":[0.5]}],)"
         R"("nodes":[{"mesh":0,"weights":[0.25]},{"mesh":0,"translation":[2,0,0]},{"mesh":0,"weights":[1.0]}],"scenes":[{"nodes":[0,1,2]}]})";
  GltfImport imp = importGltf((d / "m.gltf").string());
  GltfSceneOptions so;
  so.times = {0};
  so.allInstances = true;
  GltfSceneInfo info;
  ValidationScene scene = gltfScene(imp, so, &info);
  ASSERT_EQ(info.instances.size(), 3u);
  ASSERT_EQ(scene.poses.size(), 3u);
  EXPECT_FLOAT_EQ(scene.poses[0].morphWeights.at(0), 0.25f);  // node 0's own weights
  EXPECT_FLOAT_EQ(scene.poses[1].morphWeights.at(0), 0.5f);   // node 1: the mesh's
  EXPECT_FLOAT_EQ(scene.poses[2].morphWeights.at(0), 1.0f);
  EXPECT_FLOAT_EQ(scene.poses[1].model[3][0], 2.0f);  // node 1's translation
  fs::remove_all(d);
}

}  // namespace
}  // namespace sg

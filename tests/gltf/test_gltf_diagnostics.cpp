// Import diagnostics (docs/gltf.md#import-diagnostics-and-weights): RobotExpressive's hand
// weights warned about and renormalised (or kept), the choice in the reflection, -Werror; and
// the Khronos glTF-Validator (tests/js/gltf_validate.mjs, npm gltf-validator) run over every
// shared model, the committed gltfpack outputs and the bad-input corpus's weight, joint,
// quaternion and frame cases: every finding of a code the import maps is reported by the
// import at the same JSON pointer, and the import reports nothing there the validator does not.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <regex>
#include <set>

#include "gltf_test_util.h"
#include <shadergen/shadergen.h>
#include "pipeline/generate.h"
#include "rig/gltf_import.h"
#include "validate/gltf_scene.h"
#include "variants/builder.h"
#include "variants/manifest.h"

namespace sg {
namespace {

namespace fs = std::filesystem;
using test::dataPath;
using test::modelPath;
using test::sourcePath;

std::string robot() { return modelPath("RobotExpressive/RobotExpressive.glb"); }

GltfImport importPart(const std::string& file, int mesh, int primitive, bool normalize, bool werror = false) {
  GltfImportOptions o;
  o.mesh = mesh;
  o.primitive = primitive;
  o.read.normalizeWeights = normalize;
  o.read.warningsAsErrors = werror;
  return importGltf(file, o);
}

const Diagnostic* findCode(const Rig& rig, const std::string& code) {
  for (const auto& d : rig.importDiagnostics)
    if (d.code == code) return &d;
  return nullptr;
}

// The four hand primitives (meshes 12 and 13, Hand.R and Hand.L): 752 of their 1,108 vertices
// have float weights off 1 by more than the validator's tolerance, up to 1.755; renormalised by
// default to the stored weights over their sum, kept as stored with --no-normalize-weights.
TEST(GltfDiagnostics, RobotExpressiveHandWeights) {
  if (!fs::exists(robot())) GTEST_SKIP() << robot() << " is not installed";
  size_t vertices = 0, off = 0;
  double worst = 1;
  for (int mesh : {12, 13})
    for (int prim : {0, 1}) {
      SCOPED_TRACE(fmt::format("#{}/{}", mesh, prim));
      GltfImport stored = importPart(robot(), mesh, prim, false);
      GltfImport normal = importPart(robot(), mesh, prim, true);
      EXPECT_EQ(stored.rig.skinWeights, "stored");
      EXPECT_EQ(normal.rig.skinWeights, "normalized");
      const Diagnostic* ds = findCode(stored.rig, "ACCESSOR_WEIGHTS_NON_NORMALIZED");
      const Diagnostic* dn = findCode(normal.rig, "ACCESSOR_WEIGHTS_NON_NORMALIZED");
      ASSERT_TRUE(ds && dn);
      EXPECT_EQ(dn->severity, Severity::Warning);
      EXPECT_NE(dn->message.find(fmt::format("/meshes/{}/primitives/{}/attributes/WEIGHTS_0", mesh, prim)),
                std::string::npos);
      EXPECT_NE(dn->message.find("renormalised"), std::string::npos) << dn->message;
      EXPECT_NE(ds->message.find("kept as stored (--no-normalize-weights)"), std::string::npos) << ds->message;
      const auto& ws = stored.data.streams.at("skin.weights[0]");
      const auto& wn = normal.data.streams.at("skin.weights[0]");
      ASSERT_EQ(ws.size(), wn.size());
      size_t here = 0;
      for (size_t v = 0; v < ws.size(); ++v) {
        double sum = 0;
        for (float w : ws[v]) sum += w;
        double nsum = 0;
        for (float w : wn[v]) nsum += w;
        EXPECT_NEAR(nsum, 1.0, 1e-6) << "vertex " << v;
        if (std::abs(sum - 1) > 1e-5) {
          ++here;
          worst = std::max(worst, sum);
          for (int c = 0; c < 4; ++c) EXPECT_NEAR(wn[v][c], ws[v][c] / sum, 1e-6) << "vertex " << v;
        } else if (std::abs(sum - 1) < 1e-7) {
          EXPECT_EQ(wn[v], ws[v]) << "vertex " << v << ": normalized weights are left alone";
        }
      }
      EXPECT_NE(dn->message.find(fmt::format("the weights of {} of {} vertices do not sum to 1", here, ws.size())),
                std::string::npos)
          << dn->message;
      vertices += ws.size();
      off += here;
    }
  EXPECT_EQ(vertices, 1108u);
  EXPECT_EQ(off, 752u);
  EXPECT_NEAR(worst, 1.755, 5e-4);
}

TEST(GltfDiagnostics, WerrorMakesTheWarningsErrors) {
  if (!fs::exists(robot())) GTEST_SKIP() << robot() << " is not installed";
  try {
    importPart(robot(), 12, 1, true, true);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.diagnostic().severity, Severity::Error);
    EXPECT_EQ(e.diagnostic().code, "ACCESSOR_WEIGHTS_NON_NORMALIZED");
    EXPECT_NE(formatDiagnostic(e.diagnostic()).find("(-Werror) [ACCESSOR_WEIGHTS_NON_NORMALIZED]"), std::string::npos);
  }
  // Notes (the skinned node's ignored transform) stay notes: the Fox has none, only notes.
  GltfImport body = importPart(robot(), 12, 1, true, false);
  EXPECT_TRUE(findCode(body.rig, "NODE_SKINNED_MESH_LOCAL_TRANSFORMS"));
  EXPECT_NO_THROW(importPart(modelPath("CesiumMan/CesiumMan.glb"), 0, 0, true, true));
}

// The host must feed what was validated: the reflection says which weights.
TEST(GltfDiagnostics, ReflectionRecordsTheWeights) {
  if (!fs::exists(robot())) GTEST_SKIP() << robot() << " is not installed";
  for (bool normalize : {true, false}) {
    GenerateOptions o;
    o.rigPath = robot() + "#12/1";
    o.fragmentPath = dataPath("minimal.frag");
    o.rulesPaths = {sourcePath("rules/standard.yaml")};
    o.gltf.normalizeWeights = normalize;
    GenerateResult r = generate(o);
    nlohmann::json j = nlohmann::json::parse(reflectionOf(r));
    EXPECT_EQ(j.value("skin_weights", ""), normalize ? "normalized" : "stored");
    ASSERT_FALSE(r.in.notes.empty());  // the import's warning reaches loading's notes
    EXPECT_EQ(r.in.notes.front().code, "ACCESSOR_WEIGHTS_NON_NORMALIZED");
  }
  GenerateOptions rigid;
  rigid.rigPath = robot() + "#0/0";
  rigid.fragmentPath = dataPath("minimal.frag");
  rigid.rulesPaths = {sourcePath("rules/standard.yaml")};
  EXPECT_FALSE(nlohmann::json::parse(reflectionOf(generate(rigid))).contains("skin_weights"));
}

// A build records the weights per variant in its index (and the import's warnings once).
TEST(GltfDiagnostics, BuildIndexRecordsTheWeights) {
  if (!fs::exists(robot())) GTEST_SKIP() << robot() << " is not installed";
  const fs::path dir = fs::path(::testing::TempDir()) / "gltf_diagnostics_build";
  fs::create_directories(dir);
  const std::string manifest = (dir / "v.yaml").string();
  std::ofstream(manifest) << fmt::format("rules: {}\nrigs:\n  hand: {}#12/1\n  foot: {}#0/0\npasses:\n  plain: {}\n"
                                         "output: {}\n",
                                         sourcePath("rules/standard.yaml"), robot(), robot(), dataPath("minimal.frag"),
                                         (dir / "out").string());
  for (bool normalize : {true, false}) {
    const Manifest m = loadManifest(manifest);
    const std::vector<Variant> variants = expandVariants(m);
    BuildOptions bo;
    bo.gltf.normalizeWeights = normalize;
    const BuildReport r = buildVariants(m, variants, bo);
    ASSERT_EQ(r.failed, 0u);
    size_t weightWarnings = 0;
    for (const auto& d : r.warnings) weightWarnings += d.code == "ACCESSOR_WEIGHTS_NON_NORMALIZED";
    EXPECT_EQ(weightWarnings, 1u);
    for (const auto& f : r.files)
      if (f.path == r.indexPath) {
        nlohmann::json index = nlohmann::json::parse(f.contents);
        for (const auto& v : index.at("variants"))
          EXPECT_EQ(v.value("skin_weights", ""), v.at("rig") == "hand" ? (normalize ? "normalized" : "stored") : "")
              << v.dump();
      }
  }
}

// The library (shadergen::core) returns the import's warnings with a successful result.
TEST(GltfDiagnostics, LibraryReturnsTheImportWarnings) {
  if (!fs::exists(robot())) GTEST_SKIP() << robot() << " is not installed";
  shadergen::Options o;
  o.rig = robot() + "#12/1";
  o.fragment = dataPath("minimal.frag");
  o.rules = {sourcePath("rules/standard.yaml")};
  shadergen::Result r = shadergen::generate(o);
  ASSERT_TRUE(r.ok);
  ASSERT_FALSE(r.diagnostics.empty());
  EXPECT_EQ(r.diagnostics.front().severity, "warning");
  EXPECT_EQ(r.diagnostics.front().code, "ACCESSOR_WEIGHTS_NON_NORMALIZED");
  EXPECT_NE(r.reflection.find(R"("skin_weights": "normalized")"), std::string::npos);
  o.warningsAsErrors = true;
  r = shadergen::generate(o);
  EXPECT_FALSE(r.ok);
  ASSERT_FALSE(r.diagnostics.empty());
  EXPECT_EQ(r.diagnostics.front().severity, "error");
}

// The option reaches the validated scene: at "Wave" t = 0.9 the right hand skinned (on the CPU,
// here) with the stored weights is stretched far from the renormalised one (the old result,
// a blade), while vertices whose weights summed to 1 are posed identically.
TEST(GltfDiagnostics, KeptWeightsStretchTheWavingHand) {
  if (!fs::exists(robot())) GTEST_SKIP() << robot() << " is not installed";
  auto posed = [&](bool normalize) {
    GltfSceneOptions so;
    so.animation = "Wave";
    so.times = {0.9};
    so.read.normalizeWeights = normalize;
    ValidationScene s = gltfScene(robot() + "#12/1", so);
    const auto& p = s.mesh.at("vertex.position");
    const auto& j = s.mesh.at("skin.joints[0]");
    const auto& w = s.mesh.at("skin.weights[0]");
    std::vector<glm::dvec3> out;
    for (size_t v = 0; v < s.mesh.vertexCount; ++v) {
      glm::dvec4 x(0);
      for (int c = 0; c < 4; ++c)
        x += double(w[v][c]) * glm::dmat4(s.poses[0].bones[static_cast<size_t>(j[v][c])]) * glm::dvec4(glm::dvec3(p[v]), 1);
      out.push_back(glm::dvec3(x));
    }
    return std::make_pair(out, s.mesh.at("skin.weights[0]"));
  };
  const auto [normal, wn] = posed(true);
  const auto [stored, ws] = posed(false);
  glm::dvec3 lo(1e30), hi(-1e30);
  for (const auto& x : normal) lo = glm::min(lo, x), hi = glm::max(hi, x);
  const double size = glm::length(hi - lo);
  double worst = 0;
  for (size_t v = 0; v < normal.size(); ++v) {
    const double d = glm::length(normal[v] - stored[v]);
    worst = std::max(worst, d);
    if (wn[v] == ws[v]) EXPECT_EQ(d, 0.0) << "vertex " << v;
  }
  std::cout << fmt::format("Hand.R at Wave t = 0.9: stored weights move a vertex {:.4g} ({:.1f}% of the hand's {:.4g})\n",
                           worst, 100 * worst / size, size);
  EXPECT_GT(worst, 0.25 * size) << "the stored weights should stretch the hand (size " << size << ")";
}

// ---- the glTF-Validator comparison ---------------------------------------------------------

// The validator's codes the import maps (docs/gltf.md#import-diagnostics-and-weights).
const std::set<std::string> kMapped{
    "ACCESSOR_WEIGHTS_NON_NORMALIZED", "ACCESSOR_WEIGHTS_NEGATIVE",        "ACCESSOR_JOINTS_INDEX_DUPLICATE",
    "ACCESSOR_JOINTS_INDEX_OOB",       "ACCESSOR_INVALID_FLOAT",           "ROTATION_NON_UNIT",
    "ACCESSOR_VECTOR3_NON_UNIT",       "ACCESSOR_INVALID_SIGN",            "NODE_SKINNED_MESH_NON_ROOT",
    "NODE_SKINNED_MESH_LOCAL_TRANSFORMS", "ACCESSOR_ANIMATION_SAMPLER_OUTPUT_NON_NORMALIZED_QUATERNION"};

std::string run(const std::string& cmd, int& status) {
  std::string out;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return out;
  std::array<char, 4096> buf;
  for (size_t n; (n = fread(buf.data(), 1, buf.size(), p)) > 0;) out.append(buf.data(), n);
  status = pclose(p);
  return out;
}

struct Finding {
  std::string code, pointer;
  bool operator<(const Finding& o) const { return std::tie(code, pointer) < std::tie(o.code, o.pointer); }
};

// Every finding of the import of every primitive (an import that fails: its errors), each at
// each JSON pointer its message names.
std::set<Finding> importFindings(const std::string& file) {
  std::vector<Diagnostic> all;
  for (const GltfPart& part : gltfParts(file)) {
    try {
      GltfImport imp = importPart(file, part.mesh, part.primitive, true);
      all.insert(all.end(), imp.rig.importDiagnostics.begin(), imp.rig.importDiagnostics.end());
    } catch (const InputError& e) {
      all.push_back(e.diagnostic());
      all.insert(all.end(), e.related.begin(), e.related.end());
    }
  }
  std::set<Finding> out;
  static const std::regex pointer(R"((/(?:meshes|nodes|animations|accessors)/[^ ,)]*))");
  for (const auto& d : all)
    for (std::sregex_iterator it(d.message.begin(), d.message.end(), pointer), end; it != end; ++it)
      if (!d.code.empty()) out.insert({d.code, (*it)[1]});
  return out;
}

std::string primitiveOf(const std::string& pointer) {  // "/meshes/3/primitives/1/attributes/X" -> "/meshes/3/primitives/1/"
  static const std::regex prim(R"(^(/meshes/\d+/primitives/\d+/))");
  std::smatch m;
  return std::regex_search(pointer, m, prim) ? m[1].str() : pointer;
}

TEST(GltfDiagnostics, ValidatorFindingsAreReported) {
  const std::string script = sourcePath("tests/js/gltf_validate.mjs");
  const std::string module = sourcePath("tests/js/node_modules/gltf-validator/package.json");
  int status = -1;
  run("node --version > /dev/null 2>&1", status);
  if (status != 0) GTEST_SKIP() << "no node (Node.js from Debian: cmake/dev.sh installs it)";
  if (!fs::exists(module)) GTEST_SKIP() << "no " << module << " (cmake/dev.sh runs npm ci in tests/js)";

  std::vector<std::string> models;
  for (const auto& dir : fs::directory_iterator(modelPath("")))
    if (dir.is_directory())
      for (const auto& f : fs::directory_iterator(dir.path()))
        if (isGltfPath(f.path().string())) models.push_back(f.path().string());
  for (const auto& f : fs::directory_iterator(dataPath("gltfpack")))
    if (isGltfPath(f.path().string())) models.push_back(f.path().string());
  for (const char* c : {"weights-sum-above-one", "weights-all-zero", "weights-negative", "weights-unorm-sum-below",
                        "weights-nan", "joints-out-of-range", "joints-out-of-range-zero-weight",
                        "joints-weighted-twice", "quaternion-node-short", "quaternion-sampler-long",
                        "normal-zero-tangent-sign", "instance-skin-too-small"})
    models.push_back(sourcePath(fmt::format("tests/bad-input/gltf/{}/m.gltf", c)));
  std::sort(models.begin(), models.end());
  ASSERT_GE(models.size(), 11u + 8u + 12u);

  std::string cmd = "cd " + sourcePath("tests/js") + " && node gltf_validate.mjs";
  for (const auto& m : models) cmd += " '" + m + "'";
  const std::string out = run(cmd, status);
  ASSERT_EQ(status, 0) << cmd << "\n" << out;
  const nlohmann::json report = nlohmann::json::parse(out);

  size_t compared = 0;
  for (const auto& m : models) {
    SCOPED_TRACE(m);
    std::set<Finding> validator;
    for (const auto& issue : report.at(m))
      if (kMapped.count(issue.at("code").get<std::string>()))
        validator.insert({issue.at("code"), issue.at("pointer")});
    const std::set<Finding> ours = importFindings(m);
    std::set<std::string> weightsElsewhere;  // primitives with negative or twice-weighted joints
    for (const auto& f : ours)
      if (f.code == "ACCESSOR_WEIGHTS_NEGATIVE" || f.code == "ACCESSOR_JOINTS_INDEX_DUPLICATE")
        weightsElsewhere.insert(primitiveOf(f.pointer));
    for (const auto& f : validator) {
      ++compared;
      // The validator leaves negative and twice-used weights out of its sum; the import sums
      // what the program blends and reports those under their own codes.
      const bool elsewhere = f.code == "ACCESSOR_WEIGHTS_NON_NORMALIZED" && weightsElsewhere.count(primitiveOf(f.pointer));
      EXPECT_TRUE(ours.count(f) || elsewhere) << "the validator's " << f.code << " at " << f.pointer
                                              << " is not reported by the import";
    }
    for (const auto& f : ours)
      if (kMapped.count(f.code))
        EXPECT_TRUE(validator.count(f)) << "the import reports " << f.code << " at " << f.pointer
                                        << ", which the validator does not";
  }
  EXPECT_GE(compared, 4u + 3u + 12u);  // RobotExpressive's hands, CesiumMan's and RiggedFigure's nodes, the corpus
}

}  // namespace
}  // namespace sg

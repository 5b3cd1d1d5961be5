// The second check of an encoded or quantized rig (validate/float_check.h, docs/validation.md
// "Against the float data"): the stated bounds hold for what quantizeForRig stores, the
// propagated tolerance is the first-order bound where that is exact and bounds the reference's
// actual response to perturbations within the bounds, every encoded rig of the repository
// passes, and codes coarser than their format claims fail.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <map>
#include <random>
#include <tuple>

#include "rig/vertex_encoding.h"
#include "test_util.h"
#include "validate/float_check.h"
#include "validate/poses.h"
#include "validate/validate.h"

namespace {

namespace fs = std::filesystem;
using sgtest::dataPath;
using sgtest::sourcePath;

using sgtest::standardRules;

// quantizeForRig moves no stream further than quantizationErrorBounds says, and for the
// rounded formats (not the values they hold exactly) nearly that far.
TEST(ErrorBounds, HoldForEveryStoredStreamAndAreReached) {
  for (const std::string& file : {dataPath("octahedral.rig.yaml"), dataPath("bounds.rig.yaml"), dataPath("limb4_unorm8.rig.yaml"),
                                  dataPath("formats_a.rig.yaml"), dataPath("formats_b.rig.yaml"), dataPath("qtangent.rig.yaml"),
                                  dataPath("morph_scaled.rig.yaml"), sourcePath("examples/dawn/face-packed.rig.yaml")}) {
    SCOPED_TRACE(file);
    const sg::Rig rig = sg::loadRigFile(file);
    const sg::ValidationScene scene = sg::proceduralScene(rig, "head", 1, 1);
    const sg::rt::Mesh q = sg::quantizeForRig(rig, scene.mesh);
    sg::rt::Mesh original = scene.mesh;
    original.uniforms = q.uniforms;
    const auto bounds = sg::quantizationErrorBounds(rig, original);
    ASSERT_FALSE(bounds.empty());
    double reached = 0;
    for (const auto& b : bounds) {
      const auto& x = original.at(b.semantic);
      const auto& y = q.at(b.semantic);
      double worst = 0;  // the largest deviation / bound
      for (size_t v = 0; v < x.size(); ++v) {
        if (b.ball) {
          const double d = glm::length(glm::dvec3(y[v]) - glm::dvec3(x[v]));
          ASSERT_LE(d, b.bound[v].x) << b.semantic << " vertex " << v;
          worst = std::max(worst, d / b.bound[v].x);
        } else {
          for (int k = 0; k < 4; ++k) {
            const double d = std::abs(double(y[v][k]) - double(x[v][k]));
            ASSERT_LE(d, b.bound[v][k]) << b.semantic << " vertex " << v << " component " << k;
            if (b.bound[v][k] > 0) worst = std::max(worst, d / b.bound[v][k]);
          }
        }
      }
      std::cout << file << " " << b.semantic << (b.ball ? " (direction)" : "") << ": worst " << worst << " of the bound\n";
      reached = std::max(reached, worst);
      // Weights renormalised in bytes, positions in the box and unit vectors reach a good part
      // of their bounds on a mesh of 2009 vertices.
      if (b.semantic == "skin.weights[0]" || b.semantic == "vertex.position" || b.semantic == "vertex.normal")
        EXPECT_GE(worst, 0.3) << b.semantic;
    }
    EXPECT_GE(reached, 0.5);
  }
}

// world.position is linear in the position: its tolerance is exactly sum_k |M_ik| eps_k.
// The mesh comes back as it was.
TEST(FloatReference, LinearInputGetsExactlyTheFirstOrderBound) {
  const sg::Rig rig = sg::loadRigFile(dataPath("unskinned_model.rig.yaml"));
  const sg::ValidationScene scene = sg::proceduralScene(rig, "limb", 1, 1);
  const sg::RuleSet& rules = standardRules();
  const sg::UniformValues uniforms = sg::poseUniforms(rig, scene.poses[0]);
  const glm::dvec3 eps(1e-3, 2e-3, 5e-4);
  const sg::InputErrorBound position{"vertex.position", false,
                                     std::vector<glm::dvec4>(scene.mesh.vertexCount, glm::dvec4(eps, 0))};
  sg::rt::Mesh mesh = scene.mesh;
  const sg::FloatReference f =
      sg::floatReference(rules, sg::shapeOfRig(rig, rules), mesh, uniforms, {position}, {"world.position"}, {});
  EXPECT_EQ(mesh.at("vertex.position"), scene.mesh.at("vertex.position"));
  const glm::dmat4 m(scene.poses[0].model);
  ASSERT_EQ(f.tolerance[0].size(), 3 * scene.mesh.vertexCount);
  for (size_t v = 0; v < scene.mesh.vertexCount; ++v)
    for (int i = 0; i < 3; ++i) {
      const double expected = std::abs(m[0][i]) * eps.x + std::abs(m[1][i]) * eps.y + std::abs(m[2][i]) * eps.z;
      ASSERT_NEAR(f.tolerance[0][v * 3 + static_cast<size_t>(i)], expected, 1e-9 * expected) << v << " " << i;
    }
}

// A direction within r of the normal: world.normal = normalize(N u), u = n / |n|, moves to
// first order by r |row_i(J)| with J = (I - o o^T) N (I - u u^T) / (|N u| |n|), o the output.
TEST(FloatReference, DirectionGetsTheEuclideanNormOfItsJacobianRow) {
  const sg::Rig rig = sg::loadRigFile(dataPath("unskinned_model.rig.yaml"));
  const sg::ValidationScene scene = sg::proceduralScene(rig, "limb", 1, 1);
  const sg::RuleSet& rules = standardRules();
  const sg::UniformValues uniforms = sg::poseUniforms(rig, scene.poses[0]);
  const double r = 1e-4;
  const sg::InputErrorBound normal{"vertex.normal", true, std::vector<glm::dvec4>(scene.mesh.vertexCount, glm::dvec4(r))};
  sg::rt::Mesh mesh = scene.mesh;
  const sg::FloatReference f = sg::floatReference(rules, sg::shapeOfRig(rig, rules), mesh, uniforms, {normal}, {"world.normal"}, {});
  const glm::dmat3 nm = glm::transpose(glm::inverse(glm::dmat3(glm::dmat4(scene.poses[0].model))));
  const glm::dmat3 id(1.0);
  for (size_t v = 0; v < scene.mesh.vertexCount; ++v) {
    const glm::dvec3 n(scene.mesh.at("vertex.normal")[v]);
    const glm::dvec3 u = glm::normalize(n), w = nm * u, o = glm::normalize(w);
    const glm::dmat3 j = (id - glm::outerProduct(o, o)) * nm * (id - glm::outerProduct(u, u)) / (glm::length(w) * glm::length(n));
    for (int i = 0; i < 3; ++i) {
      const double expected = r * glm::length(glm::dvec3(j[0][i], j[1][i], j[2][i]));
      ASSERT_NEAR(f.tolerance[0][v * 3 + static_cast<size_t>(i)], expected, 1e-2 * expected + 1e-12) << v << " " << i;
    }
  }
}

// The property the second check rests on: moving the inputs anywhere within their bounds
// (box corners, directions of the full radius, coarse bounds where the second-order term
// matters) changes each reference value by at most its tolerance.
TEST(FloatReference, BoundsTheReferencesResponseToPerturbationsWithinTheBounds) {
  const sg::Rig rig = sg::loadRigFile(dataPath("limb4_unorm8.rig.yaml"));
  const sg::ValidationScene scene = sg::proceduralScene(rig, "limb", 1, 1);
  const sg::RuleSet& rules = standardRules();
  const sg::RigShape shape = sg::shapeOfRig(rig, rules);
  const sg::UniformValues uniforms = sg::poseUniforms(rig, scene.poses[0]);
  const size_t n = scene.mesh.vertexCount;
  const std::vector<sg::InputErrorBound> bounds = {
      {"skin.weights[0]", false, std::vector<glm::dvec4>(n, glm::dvec4(4.0 / 255))},
      {"vertex.position", false, std::vector<glm::dvec4>(n, glm::dvec4(2e-3, 1e-3, 3e-3, 0))},
      {"vertex.normal", true, std::vector<glm::dvec4>(n, glm::dvec4(0.03))},  // about 1.7 degrees
      {"vertex.tangent", true, std::vector<glm::dvec4>(n, glm::dvec4(0.03))},
  };
  const std::vector<std::string> semantics = {"world.position", "world.normal", "world.tangent", "world.binormal",
                                              "view.ndotv", "view.one_minus_ndotv_sq"};
  sg::rt::Mesh mesh = scene.mesh;
  const sg::FloatReference f = sg::floatReference(rules, shape, mesh, uniforms, bounds, semantics, {});
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> sign(0, 1);
  std::normal_distribution<double> g(0, 1);
  double closest = 0;  // the largest change / tolerance seen
  for (int sample = 0; sample < 12; ++sample) {
    sg::rt::Mesh moved = scene.mesh;
    for (const auto& b : bounds)
      for (size_t v = 0; v < n; ++v) {
        glm::vec4& x = moved.streams.at(b.semantic)[v];
        if (b.ball) {  // 0.999 of the radius: the float data rounds the step
          const glm::dvec3 d = glm::normalize(glm::dvec3(g(rng), g(rng), g(rng))) * (0.999 * b.bound[v].x);
          x = glm::vec4(glm::vec3(glm::dvec3(x) + d), x.w);
        } else {
          for (int k = 0; k < 4; ++k) x[k] = static_cast<float>(x[k] + (sign(rng) ? 0.999 : -0.999) * b.bound[v][k]);
        }
      }
    const auto values = sg::Interpreter(rules, shape, moved, uniforms).evaluate(semantics);
    for (size_t s = 0; s < semantics.size(); ++s)
      for (size_t i = 0; i < values[s].size(); ++i) {
        const double change = std::abs(values[s][i] - f.values[s][i]);
        ASSERT_LE(change, f.tolerance[s][i]) << semantics[s] << " value " << i << " sample " << sample;
        closest = std::max(closest, change / f.tolerance[s][i]);
      }
  }
  std::cout << "largest change / tolerance: " << closest << "\n";
  EXPECT_GE(closest, 0.3);  // and the tolerance is not far above what the perturbations reach
}

sg::ValidateReport validate(const std::string& rig, const std::string& frag, const std::string& rules,
                            const std::string& mesh, const std::function<void(sg::ValidationScene&)>& plant = {},
                            size_t floatCheckVertices = 20000) {
  sg::ValidateOptions vo;
  vo.gen.rigPath = rig;
  vo.gen.fragmentPath = frag;
  vo.gen.rulesPaths = {rules};
  vo.floatCheckVertices = floatCheckVertices;
  sg::ValidationScene scene = sg::proceduralScene(sg::loadRigFile(rig), mesh, 1, 2);
  if (plant) plant(scene);
  sg::Validator v(vo);
  sg::ValidateReport rep = v.run(scene);
  std::cout << sg::formatReport(rep);
  return rep;
}

sg::ValidateReport validateOnLimb(const std::string& rig, const std::function<void(sg::ValidationScene&)>& plant = {}) {
  return validate(dataPath(rig), dataPath("world.frag"), sourcePath("rules/standard.yaml"), "limb", plant);
}

// A bound wide enough to hold an extremum (weights_2bit.rig.yaml: a weight in a 2-bit channel,
// an error of up to 1/6): the sum of slopes and curvatures falls short of what the stored data
// itself changes, which the tolerance then takes as its floor. The change is the reference
// evaluated on the stored data, a point within the bounds (ErrorBounds above).
TEST(FloatReference, TheStoredDataItselfIsWithinTheTolerance) {
  const sg::Rig rig = sg::loadRigFile(dataPath("weights_2bit.rig.yaml"));
  const sg::ValidationScene scene = sg::proceduralScene(rig, "head", 1, 2);  // validate's poses
  const sg::RuleSet& rules = standardRules();
  const sg::RigShape shape = sg::shapeOfRig(rig, rules);
  const sg::rt::Mesh q = sg::quantizeForRig(rig, scene.mesh);
  const auto bounds = sg::quantizationErrorBounds(rig, scene.mesh);
  std::map<std::string, std::vector<glm::vec4>> stored;
  sg::rt::Mesh atStored = scene.mesh;
  for (const auto& b : bounds) stored[b.semantic] = atStored.streams.at(b.semantic) = q.at(b.semantic);
  const std::vector<std::string> semantics = {"view.one_minus_ndotv_sq", "view.ndotv", "world.normal"};
  size_t short_ = 0;
  for (const auto& pose : scene.poses) {
    const sg::UniformValues uniforms = sg::poseUniforms(rig, pose);
    const auto reached = sg::Interpreter(rules, shape, atStored, uniforms).evaluate(semantics);
    sg::rt::Mesh mesh = scene.mesh;
    const sg::FloatReference sum = sg::floatReference(rules, shape, mesh, uniforms, bounds, semantics, {});
    const sg::FloatReference floored = sg::floatReference(rules, shape, mesh, uniforms, bounds, semantics, stored);
    for (size_t s = 0; s < semantics.size(); ++s)
      for (size_t i = 0; i < reached[s].size(); ++i) {
        const double change = std::abs(reached[s][i] - floored.values[s][i]);
        ASSERT_EQ(floored.values[s][i], sum.values[s][i]);
        ASSERT_LE(change, floored.tolerance[s][i]) << semantics[s] << " value " << i;
        ASSERT_GE(floored.tolerance[s][i], sum.tolerance[s][i]) << semantics[s] << " value " << i;
        short_ += change > sum.tolerance[s][i];
      }
  }
  std::cout << short_ << " values changed by the stored data more than the sum allows\n";
  EXPECT_GT(short_, 0u);  // the failure this floor removes: validate failed this rig before it
  // And the whole check: both pass on the device.
  const sg::ValidateReport rep = validate(dataPath("weights_2bit.rig.yaml"), dataPath("world.frag"),
                                          sourcePath("rules/standard.yaml"), "head");
  EXPECT_TRUE(rep.pass);
}

// Both checks pass on every encoded or quantized rig of the repository, and the second one
// sees what storing changed: deviations from the float data far above float rounding.
TEST(FloatCheck, EveryEncodedRigPassesBoth) {
  std::vector<sg::ValidateReport> reports;
  for (const char* rig : {"octahedral.rig.yaml", "bounds.rig.yaml", "limb4_unorm8.rig.yaml", "qtangent.rig.yaml", "morph_scaled.rig.yaml"})
    reports.push_back(validateOnLimb(rig));
  reports.push_back(validate(sourcePath("examples/dawn/face-packed.rig.yaml"), sourcePath("examples/dawn/face.frag"),
                             sourcePath("examples/dawn/rules.yaml"), "head"));
  for (const auto& rep : reports) {
    EXPECT_TRUE(rep.pass);
    double seen = 0;
    for (const auto& o : rep.runs.at(0).outputs) {
      if (o.unchecked) continue;
      EXPECT_TRUE(o.floatCheck.ran) << o.name;
      EXPECT_EQ(o.floatCheck.notCompared, 0u) << o.name;
      EXPECT_GE(o.floatCheck.ratio, 1.0) << o.name;
      seen = std::max(seen, o.floatCheck.maxDeviation);
    }
    EXPECT_GT(seen, 1e-4);
  }
}

// The packed Dawn face's second check on a sample of the head mesh compares 1 vertex in 5.
TEST(FloatCheck, LargeMeshesAreSampled) {
  sg::ValidateReport rep = validate(sourcePath("examples/dawn/face-packed.rig.yaml"), sourcePath("examples/dawn/face.frag"),
                                    sourcePath("examples/dawn/rules.yaml"), "head", {}, 500);
  EXPECT_TRUE(rep.pass);
  EXPECT_EQ(rep.runs.at(0).floatCheckStride, 5u);  // 2009 vertices
  EXPECT_NE(sg::formatReport(rep).find("(1 vertex in 5)"), std::string::npos);
  for (const auto& o : rep.runs.at(0).outputs) {
    EXPECT_TRUE(o.floatCheck.ran) << o.name;
    EXPECT_EQ(o.floatCheck.worstVertex % 5, 0u) << o.name;  // only the sample is compared
  }
}

// Off when asked, and off by itself where every stream is stored exactly (float32, integers).
TEST(FloatCheck, RunsOnlyWhereSomethingIsQuantized) {
  sg::ValidateOptions vo;
  vo.gen.rigPath = dataPath("limb4_unorm8.rig.yaml");
  vo.gen.fragmentPath = dataPath("world.frag");
  vo.gen.rulesPaths = {sourcePath("rules/standard.yaml")};
  vo.checkFloatData = false;
  const sg::ValidationScene scene = sg::proceduralScene(sg::loadRigFile(vo.gen.rigPath), "limb", 1, 1);
  sg::ValidateReport off = sg::Validator(vo).run(scene);
  EXPECT_TRUE(off.pass);
  for (const auto& o : off.runs.at(0).outputs) EXPECT_FALSE(o.floatCheck.ran) << o.name;
  EXPECT_EQ(sg::formatReport(off).find("vs float data"), std::string::npos);
  vo.checkFloatData = true;
  vo.gen.rigPath = dataPath("unskinned_model.rig.yaml");
  sg::ValidateReport exact = sg::Validator(vo).run(sg::proceduralScene(sg::loadRigFile(vo.gen.rigPath), "limb", 1, 1));
  for (const auto& o : exact.runs.at(0).outputs) EXPECT_FALSE(o.floatCheck.ran) << o.name;
}

// Codes given with the mesh, as an application's packer would supply them, rounded to
// `coarse` steps of the format the rig declares (snorm16 for the frame, unorm16 for the
// position): the device decodes them exactly (the first check passes), but they are up to
// `coarse` times further from the float data than the format's stated error.
void plantCodes(sg::ValidationScene& scene, const std::string& encoded, double steps, double coarse) {
  const sg::VertexEncoding& e = *sg::encodingOf(encoded);
  const sg::PositionBounds box = sg::positionBounds(scene.mesh.at("vertex.position"));
  std::vector<glm::vec4> codes;
  for (const glm::vec4& x : scene.mesh.at(e.sources[0])) {
    glm::dvec3 c = e.name == "bounds" ? sg::boundsEncode(box, glm::dvec3(x)) : glm::dvec3(sg::octahedralEncode(glm::dvec3(x)), 0);
    for (int k = 0; k < e.components; ++k) c[k] = std::round(c[k] * steps / coarse) * coarse / steps;
    codes.emplace_back(glm::vec3(c), 0);
  }
  scene.mesh.streams[encoded] = std::move(codes);
}

// The rigs with every other stream in float32, so that the planted error is not hidden
// under the tolerance other inputs earn (unorm8 weights move a normal by far more).
TEST(FloatCheck, CodesTenTimesCoarserThanTheirFormatFail) {
  const fs::path dir = fs::temp_directory_path() / ("sg_float_check_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  for (const auto& [file, encoded, steps, output] :
       {std::tuple<const char*, const char*, double, const char*>{"octahedral.rig.yaml", "vertex.normal_octahedral", 32767,
                                                                   "world_normal"},
        {"bounds.rig.yaml", "vertex.position_in_bounds", 65535, "world_position"}}) {
    SCOPED_TRACE(file);
    std::string text = sgtest::readText(dataPath(file));
    ASSERT_TRUE(sgtest::replaceOnce(text, "format: float16x4, provides: { vertex.texcoord0", "format: float32x4, provides: { vertex.texcoord0"));
    ASSERT_TRUE(sgtest::replaceOnce(text, "weights:  { format: unorm8x4", "weights:  { format: float32x4"));
    if (std::string(encoded) == "vertex.position_in_bounds")
      ASSERT_TRUE(sgtest::replaceOnce(text, "format: snorm16x4, provides: { vertex.normal_octahedral: xy, vertex.tangent_octahedral: zw }",
                                      "format: float32x4, provides: { vertex.normal_octahedral: xy, vertex.tangent_octahedral: zw }"));
    const std::string rig = (dir / file).string();
    sgtest::writeText(rig, text);
    const std::string code = encoded;  // structured bindings cannot be captured before C++20
    const double codeSteps = steps;
    auto run = [&](double coarse) {
      return validate(rig, dataPath("world.frag"), sourcePath("rules/standard.yaml"), "limb",
                      [&](sg::ValidationScene& s) { plantCodes(s, code, codeSteps, coarse); });
    };
    // The codes the packer writes pass; ten times coarser, only the second check fails.
    EXPECT_TRUE(run(1).pass);
    sg::ValidateReport rep = run(10);
    EXPECT_FALSE(rep.pass);
    for (const auto& o : rep.runs.at(0).outputs) {
      EXPECT_TRUE(o.storedPass) << o.name;  // the decode is exact
      if (o.name == output) EXPECT_FALSE(o.floatCheck.pass) << o.name;
    }
  }
  fs::remove_all(dir);
}

}  // namespace

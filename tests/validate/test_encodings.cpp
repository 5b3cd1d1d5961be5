// Encoded vertex semantics (rig/vertex_encoding.h, rules/encodings.yaml): the octahedral
// mapping checked against its geometry, its stated worst error against a dense sample, a
// stored frame validated on the device, a planted wrong decode caught, and error budgets
// removing what they should.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <optional>
#include <random>

#include <nlohmann/json.hpp>
#include <vulkan/vulkan_core.h>

#include "rig/vertex_encoding.h"
#include "test_util.h"
#include "pipeline/generate.h"
#include "rig/gltf_import.h"
#include "validate/gltf_scene.h"
#include "validate/pack.h"
#include "validate/validate.h"

namespace {

using sgtest::dataPath;
using sgtest::sourcePath;

std::vector<glm::dvec3> unitVectors(size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0, 1);
  std::vector<glm::dvec3> out;
  while (out.size() < n) {
    glm::dvec3 v(g(rng), g(rng), g(rng));
    if (glm::length(v) > 1e-6) out.push_back(glm::normalize(v));
  }
  // The places an octahedral map is most likely to get wrong: axes, folds, face centres.
  for (double sx : {-1.0, 1.0})
    for (double sy : {-1.0, 1.0})
      for (double sz : {-1.0, 1.0}) {
        out.push_back(glm::normalize(glm::dvec3(sx, sy, sz)));
        out.push_back(glm::dvec3(sx, 0, 0));
        out.push_back(glm::dvec3(0, sy, 0));
        out.push_back(glm::dvec3(0, 0, sz));
        out.push_back(glm::normalize(glm::dvec3(sx, sy, 0)));
        out.push_back(glm::normalize(glm::dvec3(sx * 1e-9, sy, sz * 1e-12)));
      }
  return out;
}

double angleDegrees(const glm::dvec3& a, const glm::dvec3& b) {
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b)) * 180 / 3.14159265358979323846;
}

// The code is the point where the direction meets the octahedron |x|+|y|+|z| = 1 (upper
// half as is, lower half reflected over the square's diagonals), so: it lies in the
// square, inside the diamond for z >= 0 and outside it for z < 0, and the 3D point it
// names is parallel to the direction. Checked from the geometry, not through the decoder.
TEST(Octahedral, CodeIsWhereTheDirectionMeetsTheOctahedron) {
  for (const glm::dvec3& v : unitVectors(100000, 1)) {
    const glm::dvec2 e = sg::octahedralEncode(v);
    ASSERT_LE(std::abs(e.x), 1.0);
    ASSERT_LE(std::abs(e.y), 1.0);
    const double l1 = std::abs(e.x) + std::abs(e.y);
    const glm::dvec3 p = v / (std::abs(v.x) + std::abs(v.y) + std::abs(v.z));  // on the octahedron
    if (v.z >= 0) {
      ASSERT_LE(l1, 1.0 + 1e-12);
      ASSERT_NEAR(e.x, p.x, 1e-12);
      ASSERT_NEAR(e.y, p.y, 1e-12);
    } else {
      ASSERT_GE(l1, 1.0 - 1e-12) << v.x << " " << v.y << " " << v.z << " -> " << e.x << " " << e.y;
      // The reflection over the diagonal of the code's quadrant maps the code back to p.
      ASSERT_NEAR(std::abs(e.x), 1 - std::abs(p.y), 1e-12);
      ASSERT_NEAR(std::abs(e.y), 1 - std::abs(p.x), 1e-12);
      if (p.x != 0) ASSERT_EQ(e.x > 0, p.x > 0);
      if (p.y != 0) ASSERT_EQ(e.y > 0, p.y > 0);
    }
    ASSERT_LT(angleDegrees(sg::octahedralDecode(e), v), 1e-9);
  }
  EXPECT_EQ(sg::octahedralEncode(glm::dvec3(0)), glm::dvec2(0));
  EXPECT_EQ(sg::octahedralDecode(glm::dvec2(0)), glm::dvec3(0, 0, 1));
}

// The stated worst error holds for every sampled direction rounded to the format as the
// device reads it, and is not loose: the sample comes within 10 % of it for 8 bits.
TEST(Octahedral, StoredErrorStaysWithinTheStatedBoundAndNearIt) {
  const sg::VertexEncoding& normal = *sg::encodingOf("vertex.normal_octahedral");
  const std::vector<glm::dvec3> dirs = unitVectors(400000, 2);
  for (sg::VertexFormat f : {sg::VertexFormat::Snorm8x2, sg::VertexFormat::Snorm16x4, sg::VertexFormat::Float16x2}) {
    const double bound = *sg::encodingMaxError(normal, f);
    double worst = 0;
    for (const glm::dvec3& v : dirs) {
      const glm::vec2 code(sg::octahedralEncode(v));  // stored from float data, as validation does
      const glm::dvec2 read(sg::storedValue(f, 0, code.x), sg::storedValue(f, 1, code.y));
      worst = std::max(worst, angleDegrees(sg::octahedralDecode(read), v));
    }
    std::cout << sg::formatName(f) << ": worst " << worst << " deg of stated " << bound << "\n";
    EXPECT_LE(worst, bound) << sg::formatName(f);
    if (f == sg::VertexFormat::Snorm8x2) EXPECT_GE(worst, 0.9 * bound);
  }
  EXPECT_NEAR(*sg::encodingMaxError(normal, sg::VertexFormat::Snorm8x2), 0.957, 0.001);
  EXPECT_FALSE(sg::encodingMaxError(normal, sg::VertexFormat::Unorm16x2));  // no negative codes
}

// `rig` (tests/validate/data) with world.frag on the limb mesh, in two poses, on lavapipe.
sg::ValidateReport validateOnLimb(sg::GenerateOptions gen, const std::string& rig) {
  sg::ValidateOptions vo;
  vo.gen = std::move(gen);
  vo.gen.rigPath = dataPath(rig);
  vo.gen.fragmentPath = dataPath("world.frag");
  if (vo.gen.rulesPaths.empty()) vo.gen.rulesPaths = {sourcePath("rules/standard.yaml")};
  sg::ValidationScene scene = sg::proceduralScene(sg::loadRigFile(vo.gen.rigPath), "limb", 1, 2);
  sg::Validator v(vo);
  sg::ValidateReport rep = v.run(scene);
  std::cout << sg::formatReport(rep);
  return rep;
}

// `rig` validated with `rules` under error `budgets`.
sg::ValidateReport validateWith(const std::string& rig, const std::string& rules, std::map<std::string, double> budgets) {
  sg::GenerateOptions gen;
  gen.rulesPaths = {rules};
  gen.maxError = std::move(budgets);
  return validateOnLimb(gen, rig);
}

sg::ValidateReport validateOctahedral(const std::string& rules, std::map<std::string, double> budgets = {}) {
  return validateWith("octahedral.rig.yaml", rules, std::move(budgets));
}

// The frame stored as two octahedral codes in one snorm16x4 location: the plan decodes
// both, and the device agrees with the reference on every output.
TEST(Octahedral, StoredFrameValidatesOnTheDevice) {
  sg::ValidateReport rep = validateOctahedral(sourcePath("rules/standard.yaml"));
  EXPECT_TRUE(rep.pass);
  ASSERT_FALSE(rep.runs.empty());
  EXPECT_TRUE(sgtest::planHas(rep.runs[0], "vertex_normal_from_octahedral"));
  EXPECT_TRUE(sgtest::planHas(rep.runs[0], "vertex_tangent_from_octahedral"));
}

// A decode with the fold's sign flipped is right for the upper half of the sphere only:
// validation must fail it on the outputs that depend on the frame.
TEST(Octahedral, PlantedSignFlipFailsValidation) {
  sgtest::RulesCopy rules("octahedral_sign_flip");
  ASSERT_TRUE(rules.edit("vocabulary.yaml", "greaterThanEqual(p_.xy, vec2(0.0))", "lessThan(p_.xy, vec2(0.0))"));
  sg::ValidateReport broken = validateOctahedral(rules.rulesFile("standard.yaml").string());
  EXPECT_FALSE(broken.pass);
  const std::set<std::string> failed = sgtest::failingOutputs(broken.runs.at(0));
  EXPECT_TRUE(failed.count("world_normal")) << ::testing::PrintToString(failed);
  EXPECT_TRUE(failed.count("world_tangent")) << ::testing::PrintToString(failed);
  EXPECT_FALSE(failed.count("world_position"));
}

// A budget below snorm16's 0.0037 deg removes the stored normal code: this rig has no other
// normal, so the request fails, and the error says which attribute the budget removed.
// A budget above it changes nothing.
TEST(Octahedral, ABudgetTighterThanTheEncodingRemovesIt) {
  try {
    validateOctahedral(sourcePath("rules/standard.yaml"), {{"vertex.normal", 0.001}});
    FAIL() << "expected the request to fail";
  } catch (const sg::InputError& e) {
    std::string all = sg::formatDiagnostic(e.diagnostic());
    for (const auto& d : e.related) all += "\n" + sg::formatDiagnostic(d);
    EXPECT_NE(all.find("cannot produce 'world.normal'"), std::string::npos) << all;
    // Its suggestion to provide the code the rig stores says the budget withheld it.
    EXPECT_NE(all.find("{vertex.normal_octahedral} (the rig stores vertex.normal_octahedral, withheld: over the "
                       "--max-error budget)"),
              std::string::npos)
        << all;
    EXPECT_NE(all.find("octahedral.rig.yaml:12:3: note: vertex.normal_octahedral (attribute 'frame', snorm16x4) is not "
                       "offered to the search: it errs up to 0.00372 deg, over the budget of 0.001 deg"),
              std::string::npos)
        << all;
  }
  EXPECT_TRUE(validateOctahedral(sourcePath("rules/standard.yaml"), {{"vertex.normal", 0.01}}).pass);
  // Through the library as through the CLI, a budget for a value no encoding stores is refused.
  try {
    validateOctahedral(sourcePath("rules/standard.yaml"), {{"world.normal", 0.01}});
    FAIL() << "expected the budget to be refused";
  } catch (const sg::InputError& e) {
    EXPECT_NE(e.diagnostic().message.find("--max-error world.normal: no encoding stores 'world.normal'"), std::string::npos)
        << e.diagnostic().message;
  }
}

// Bounds-relative positions, checked from the definition: the bounds hold every point (the
// smallest coordinate exactly, the extent rounded up by at most one float step), every code
// lies in [0, 1], and a point read back through each format errs by at most the stated
// fraction of the box's diagonal, and for 8 bits nearly that much. The box sits far from
// the origin with very unequal sides, and one axis is flat.
TEST(Bounds, CodesLieInTheBoxAndDecodeWithinTheStatedError) {
  const sg::VertexEncoding& position = *sg::encodingOf("vertex.position_in_bounds");
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  for (const glm::dvec3 size : {glm::dvec3(2, 0.001, 50), glm::dvec3(1, 1, 0)}) {
    const glm::dvec3 corner(1000, -3, 0.5);
    std::vector<glm::vec4> points;
    for (int i = 0; i < 100000; ++i) points.emplace_back(glm::vec3(corner + size * glm::dvec3(u(rng), u(rng), u(rng))), 1);
    points.emplace_back(NAN, INFINITY, -INFINITY, 1);  // left out of the bounds, encodes as 0
    const sg::PositionBounds b = sg::positionBounds(points);
    glm::dvec3 lo(INFINITY), hi(-INFINITY);
    for (size_t i = 0; i + 1 < points.size(); ++i)
      lo = glm::min(lo, glm::dvec3(points[i])), hi = glm::max(hi, glm::dvec3(points[i]));
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(double(b.min[k]), lo[k]);
      EXPECT_GE(double(b.min[k]) + double(b.extent[k]), hi[k]);
      EXPECT_LE(double(b.extent[k]), (hi[k] - lo[k]) * (1 + std::ldexp(1.0, -22)));
    }
    EXPECT_EQ(sg::boundsEncode(b, glm::dvec3(points.back())), glm::dvec3(0));
    const double diagonal = glm::length(hi - lo);
    for (sg::VertexFormat f : {sg::VertexFormat::Unorm8x4, sg::VertexFormat::Unorm10_10_10_2, sg::VertexFormat::Unorm16x4,
                               sg::VertexFormat::Float16x4}) {
      const double bound = *sg::encodingMaxError(position, f);
      double worst = 0;
      for (size_t i = 0; i + 1 < points.size(); ++i) {
        const glm::vec3 code(sg::boundsEncode(b, glm::dvec3(points[i])));  // stored from float data
        ASSERT_TRUE(glm::all(glm::greaterThanEqual(code, glm::vec3(0))) && glm::all(glm::lessThanEqual(code, glm::vec3(1))));
        glm::dvec3 read;
        for (int k = 0; k < 3; ++k) read[k] = sg::storedValue(f, k, code[k]);
        worst = std::max(worst, glm::length(sg::boundsDecode(b, read) - glm::dvec3(points[i])) / diagonal);
      }
      std::cout << sg::formatName(f) << ": worst " << worst << " of the diagonal, stated " << bound << "\n";
      EXPECT_LE(worst, bound) << sg::formatName(f);
      if (f == sg::VertexFormat::Unorm8x4) EXPECT_GE(worst, 0.8 * bound);
    }
  }
  EXPECT_NEAR(*sg::encodingMaxError(position, sg::VertexFormat::Unorm16x4), 7.69e-6, 0.01e-6);  // 0.5/65535 + 2^-24
  EXPECT_FALSE(sg::encodingMaxError(position, sg::VertexFormat::Snorm16x4));  // codes are in [0, 1]
}

sg::ValidateReport validateBounds(const std::string& rules, std::map<std::string, double> budgets = {}) {
  return validateWith("bounds.rig.yaml", rules, std::move(budgets));
}

// A 32-byte vertex in five locations: the position relative to the bounds in unorm16, the
// frame in octahedral codes. Every decode runs on the device and agrees with the reference.
TEST(Bounds, PackedVertexValidatesOnTheDevice) {
  sg::ValidateReport rep = validateBounds(sourcePath("rules/standard.yaml"));
  EXPECT_TRUE(rep.pass);
  ASSERT_FALSE(rep.runs.empty());
  EXPECT_TRUE(sgtest::planHas(rep.runs[0], "vertex_position_from_bounds"));
  EXPECT_TRUE(sgtest::planHas(rep.runs[0], "vertex_normal_from_octahedral"));
}

// A decode that forgets the bounds' scale puts every point in a unit box at the corner:
// validation fails the outputs that depend on the position, and only those.
TEST(Bounds, PlantedMissingScaleFailsValidation) {
  sgtest::RulesCopy rules("bounds_missing_scale");
  ASSERT_TRUE(rules.edit("encodings.yaml", "${vertex.position_in_bounds} * ${mesh.bounds_extent}", "${vertex.position_in_bounds}"));
  sg::ValidateReport broken = validateBounds(rules.rulesFile("standard.yaml").string());
  EXPECT_FALSE(broken.pass);
  const std::set<std::string> failed = sgtest::failingOutputs(broken.runs.at(0));
  EXPECT_TRUE(failed.count("world_position")) << ::testing::PrintToString(failed);
  EXPECT_TRUE(failed.count("gl_Position")) << ::testing::PrintToString(failed);
  EXPECT_FALSE(failed.count("world_normal"));
  EXPECT_FALSE(failed.count("world_tangent"));
}

// A position budget below unorm16's 7.6e-6 of the diagonal removes the code (the rig has
// no other position); 1e-4 (the packed-layout target) keeps it.
TEST(Bounds, ABudgetTighterThanTheEncodingRemovesIt) {
  try {
    validateBounds(sourcePath("rules/standard.yaml"), {{"vertex.position", 1e-6}});
    FAIL() << "expected the request to fail";
  } catch (const sg::InputError& e) {
    std::string all = sg::formatDiagnostic(e.diagnostic());
    for (const auto& d : e.related) all += "\n" + sg::formatDiagnostic(d);
    EXPECT_NE(all.find("bounds.rig.yaml:12:3: note: vertex.position_in_bounds (attribute 'position', unorm16x4) is not "
                       "offered to the search: it errs up to 7.69e-06 of the bounds diagonal, over the budget of 1e-06 of "
                       "the bounds diagonal"),
              std::string::npos)
        << all;
  }
  EXPECT_TRUE(validateBounds(sourcePath("rules/standard.yaml"), {{"vertex.position", 1e-4}}).pass);
}

// QTangents, checked against the geometry of rotations, not through the library's decoder:
// the test rotates with its own Hamilton product, v' = q v q*.
glm::dvec4 hamilton(const glm::dvec4& a, const glm::dvec4& b) {  // (x, y, z, w)
  const glm::dvec3 u(a), v(b);
  return glm::dvec4(a.w * v + b.w * u + glm::cross(u, v), a.w * b.w - glm::dot(u, v));
}
glm::dvec3 rotate(const glm::dvec4& q, const glm::dvec3& v) {
  const glm::dvec4 r = hamilton(hamilton(q, glm::dvec4(v, 0)), glm::dvec4(-glm::dvec3(q), q.w));
  return glm::dvec3(r) / glm::dot(q, q);
}

struct Frame {
  glm::dvec3 normal, tangent;  // as stored: the tangent need not be perpendicular, nor either unit
  double handedness;
};

// 1e5 random frames (normal and tangent independent, lengths 0.5..2, both handedness
// signs), frames whose quaternion has w = 0 or nearly (rotations by about half a turn,
// where the bias must keep w's sign), and degenerate ones: zero and parallel tangents.
std::vector<Frame> frames(size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0, 1);
  std::uniform_real_distribution<double> len(0.5, 2);
  auto unit = [&] {
    glm::dvec3 v(g(rng), g(rng), g(rng));
    return glm::normalize(v);
  };
  std::vector<Frame> out;
  for (size_t i = 0; i < n; ++i) out.push_back({len(rng) * unit(), len(rng) * unit(), i % 2 ? -1.0 : 1.0});
  for (size_t i = 0; i < n / 4; ++i) {
    const double w = std::vector<double>{0, 1e-9, 1e-5, 3e-5, 1e-3, 8e-3}[i % 6];
    const glm::dvec4 q(std::sqrt(1 - w * w) * unit(), w);
    out.push_back({rotate(q, {0, 0, 1}), rotate(q, {1, 0, 0}), i % 4 < 2 ? -1.0 : 1.0});
  }
  for (double h : {-1.0, 1.0})
    for (int i = 0; i < 100; ++i) {
      const glm::dvec3 nrm = unit();
      out.push_back({nrm, glm::dvec3(0), h});
      out.push_back({nrm, 3.0 * nrm, h});
      out.push_back({nrm, -nrm + 1e-5 * unit(), h});
    }
  for (double h : {-1.0, 1.0}) out.push_back({{0, 0, 1}, {1, 0, 0}, h});  // the identity: w = +-1
  return out;
}

// The frame an encoder must store: the normal normalised, the tangent made perpendicular
// to it, or nothing (zero or parallel: the encoder's documented fallback applies).
std::optional<glm::dvec3> expectedTangent(const Frame& f) {
  const glm::dvec3 n = glm::normalize(f.normal);
  const glm::dvec3 g = f.tangent - glm::dot(f.tangent, n) * n;
  if (glm::length(g) <= 1e-3 * glm::length(f.tangent) || glm::length(f.tangent) == 0) return std::nullopt;
  return glm::normalize(g);
}

// The code is the unit quaternion of the orthonormalised frame's rotation: it takes +z to
// the normal and +x to the tangent, its w has the handedness's sign and at least the bias.
// A degenerate tangent gets one deterministic tangent per normal, perpendicular to it,
// the same for a zero and a parallel tangent.
TEST(QTangent, CodeIsTheRotationOfTheOrthonormalisedFrame) {
  const double bias = sg::qtangentBias(sg::VertexFormat::Snorm16x4);
  EXPECT_EQ(bias, 1.0 / 32767);
  size_t degenerate = 0;
  for (const Frame& f : frames(100000, 4)) {
    const glm::dvec4 q = sg::qtangentEncode(f.normal, f.tangent, f.handedness, bias);
    ASSERT_NEAR(glm::length(q), 1.0, 1e-12);
    ASSERT_EQ(q.w < 0, f.handedness < 0);
    ASSERT_GE(std::abs(q.w), bias * (1 - 1e-12));
    const glm::dvec3 n = rotate(q, {0, 0, 1}), t = rotate(q, {1, 0, 0});
    // The bias may turn the frame by up to 2 asin(bias).
    const double slack = glm::degrees(2 * std::asin(bias)) * 1.0001 + 1e-9;
    ASSERT_LE(angleDegrees(n, f.normal), slack);
    ASSERT_NEAR(glm::dot(n, t), 0.0, 1e-12);
    if (const auto want = expectedTangent(f)) {
      ASSERT_LE(angleDegrees(t, *want), slack);
    } else {
      ++degenerate;
      const glm::dvec4 zero = sg::qtangentEncode(f.normal, glm::dvec3(0), f.handedness, bias);
      ASSERT_EQ(sg::qtangentEncode(f.normal, 2.0 * f.normal, f.handedness, bias), zero);
      ASSERT_EQ(sg::qtangentEncode(f.normal, glm::dvec3(NAN), f.handedness, bias), zero);
    }
  }
  EXPECT_GE(degenerate, 400u);
  // A zero normal is +z; a handedness of 0 or NaN is +1.
  const glm::dvec4 q = sg::qtangentEncode(glm::dvec3(0), {1, 0, 0}, 0.0, bias);
  EXPECT_LT(angleDegrees(rotate(q, {0, 0, 1}), {0, 0, 1}), 1e-9);
  EXPECT_GT(q.w, 0);
  EXPECT_GT(sg::qtangentEncode({0, 0, 1}, {1, 0, 0}, NAN, bias).w, 0);
}

// Rounded to each format as the device reads it, every frame decodes to an orthonormal one
// with the exact handedness and its normal and tangent within the stated angle, and the
// statement is not loose: the sample reaches most of it for 8 bits.
TEST(QTangent, StoredErrorStaysWithinTheStatedBoundAndNearIt) {
  const sg::VertexEncoding& qt = *sg::encodingOf("vertex.qtangent");
  const std::vector<Frame> all = frames(100000, 5);
  for (sg::VertexFormat f : {sg::VertexFormat::Snorm8x4, sg::VertexFormat::Snorm16x4, sg::VertexFormat::Float16x4,
                             sg::VertexFormat::Float32x4}) {
    const double bound = *sg::encodingMaxError(qt, f);
    double worst = 0;
    size_t handednessWrong = 0;
    for (const Frame& fr : all) {
      const glm::vec4 code(sg::qtangentEncode(fr.normal, fr.tangent, fr.handedness, sg::qtangentBias(f)));
      glm::dvec4 read;
      for (int c = 0; c < 4; ++c) read[c] = sg::storedValue(f, c, code[c]);
      const sg::QTangentFrame d = sg::qtangentDecode(read);
      ASSERT_NEAR(glm::length(d.normal), 1.0, 1e-12);
      ASSERT_NEAR(glm::length(d.tangent), 1.0, 1e-12);
      ASSERT_NEAR(glm::dot(d.normal, d.tangent), 0.0, 1e-12);
      handednessWrong += d.handedness != (fr.handedness < 0 ? -1.0 : 1.0);
      worst = std::max(worst, angleDegrees(d.normal, fr.normal));
      if (const auto want = expectedTangent(fr)) worst = std::max(worst, angleDegrees(d.tangent, *want));
    }
    std::cout << sg::formatName(f) << ": worst " << worst << " deg of stated " << bound << "\n";
    EXPECT_EQ(handednessWrong, 0u) << sg::formatName(f);
    EXPECT_LE(worst, bound) << sg::formatName(f);
    if (f == sg::VertexFormat::Snorm8x4 || f == sg::VertexFormat::Snorm16x4) EXPECT_GE(worst, 0.9 * bound);
  }
  EXPECT_NEAR(*sg::encodingMaxError(qt, sg::VertexFormat::Snorm16x4), 0.00463, 0.00001);
  EXPECT_FALSE(sg::encodingMaxError(qt, sg::VertexFormat::Unorm16x4));  // no negative components
  EXPECT_FALSE(sg::encodingMaxError(qt, sg::VertexFormat::Snorm16x2));  // four components
}

sg::ValidateReport validateQTangent(const std::string& rules, std::map<std::string, double> budgets = {}) {
  return validateWith("qtangent.rig.yaml", rules, std::move(budgets));
}

// The whole frame in one snorm16x4 location: the plan decodes the normal, the tangent and
// the handedness from it, and the device agrees with the reference on every output.
TEST(QTangent, StoredFrameValidatesOnTheDevice) {
  sg::ValidateReport rep = validateQTangent(sourcePath("rules/standard.yaml"));
  EXPECT_TRUE(rep.pass);
  ASSERT_FALSE(rep.runs.empty());
  EXPECT_TRUE(sgtest::planHas(rep.runs[0], "vertex_normal_from_qtangent"));
  EXPECT_TRUE(sgtest::planHas(rep.runs[0], "vertex_tangent_from_qtangent"));
  EXPECT_TRUE(sgtest::planHas(rep.runs[0], "vertex_handedness_from_qtangent"));
}

// Planted wrong decodes: the handedness's sign flipped fails the binormal (the limb's
// mirrored half and the rest alike) and nothing else; two quaternion components swapped
// in the normal's column fails the normal and what follows from it, not the position.
TEST(QTangent, PlantedWrongDecodesFailValidation) {
  {
    sgtest::RulesCopy rules("qtangent_handedness_flip");
    ASSERT_TRUE(rules.edit("encodings.yaml", "${vertex.qtangent}.w < 0.0 ? -1.0 : 1.0", "${vertex.qtangent}.w < 0.0 ? 1.0 : -1.0"));
    sg::ValidateReport broken = validateQTangent(rules.rulesFile("standard.yaml").string());
    EXPECT_FALSE(broken.pass);
    const std::set<std::string> failed = sgtest::failingOutputs(broken.runs.at(0));
    EXPECT_TRUE(failed.count("world_binormal")) << ::testing::PrintToString(failed);
    EXPECT_FALSE(failed.count("world_normal"));
    EXPECT_FALSE(failed.count("world_tangent"));
    EXPECT_FALSE(failed.count("world_position"));
  }
  {
    sgtest::RulesCopy rules("qtangent_swapped_component");
    ASSERT_TRUE(rules.edit("encodings.yaml", "vec3(a_.x * q_.z + a_.y * q_.w,", "vec3(a_.x * q_.w + a_.y * q_.z,"));
    sg::ValidateReport broken = validateQTangent(rules.rulesFile("standard.yaml").string());
    EXPECT_FALSE(broken.pass);
    const std::set<std::string> failed = sgtest::failingOutputs(broken.runs.at(0));
    EXPECT_TRUE(failed.count("world_normal")) << ::testing::PrintToString(failed);
    EXPECT_FALSE(failed.count("world_position"));
  }
}

// A tangent budget below snorm16's 0.0046 deg removes the code (the rig has no other
// frame), and the note names the budget it broke; one above it changes nothing. The
// handedness is exact: no budget applies to it.
TEST(QTangent, ABudgetTighterThanTheEncodingRemovesIt) {
  try {
    validateQTangent(sourcePath("rules/standard.yaml"), {{"vertex.tangent", 0.001}});
    FAIL() << "expected the request to fail";
  } catch (const sg::InputError& e) {
    std::string all = sg::formatDiagnostic(e.diagnostic());
    for (const auto& d : e.related) all += "\n" + sg::formatDiagnostic(d);
    EXPECT_NE(all.find("qtangent.rig.yaml:12:3: note: vertex.qtangent (attribute 'frame', snorm16x4) is not offered to "
                       "the search: it errs up to 0.00463 deg, over the budget of 0.001 deg for vertex.tangent"),
              std::string::npos)
        << all;
  }
  EXPECT_TRUE(validateQTangent(sourcePath("rules/standard.yaml"), {{"vertex.normal", 0.005}, {"vertex.tangent", 0.005}}).pass);
  std::string why;
  EXPECT_FALSE(sg::parseErrorBudget("vertex.handedness", "0.1deg", why));
  EXPECT_NE(why.find("no encoding stores 'vertex.handedness'"), std::string::npos) << why;
}

// Morph deltas relative to their target's scale, checked from the definition: the scale is
// the target's largest |component| (rounded up by at most one float step), every code lies
// in [-1, 1], and a delta read back through each format errs by at most the stated fraction
// of its target's scale, and for 8 bits nearly that much. Targets of very different sizes,
// one that moves nothing, and non-finite components (left out, encoded as 0).
TEST(ScaledDeltas, CodesLieInTheUnitCubeAndDecodeWithinTheStatedError) {
  const sg::VertexEncoding& scaled = *sg::encodingOf("morph.position_scaled");
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> u(-1, 1);
  for (const double size : {1e-4, 1.0, 300.0, 0.0}) {
    std::vector<glm::vec4> deltas;
    for (int i = 0; i < 100000; ++i) deltas.emplace_back(glm::vec3(size * glm::dvec3(u(rng), 0.5 * u(rng), u(rng))), 0);
    deltas.emplace_back(NAN, INFINITY, -INFINITY, 0);
    const float scale = sg::deltaScale(deltas);
    double largest = 0;
    for (size_t i = 0; i + 1 < deltas.size(); ++i)
      for (int k = 0; k < 3; ++k) largest = std::max(largest, std::abs(double(deltas[i][k])));
    EXPECT_GE(double(scale), largest);
    EXPECT_LE(double(scale), largest * (1 + std::ldexp(1.0, -23)));
    EXPECT_EQ(sg::scaledEncode(scale, glm::dvec3(deltas.back())), glm::dvec3(0));
    for (sg::VertexFormat f : {sg::VertexFormat::Snorm8x4, sg::VertexFormat::Snorm10_10_10_2, sg::VertexFormat::Snorm16x4,
                               sg::VertexFormat::Float16x4}) {
      const double bound = *sg::encodingMaxError(scaled, f);
      double worst = 0;
      for (size_t i = 0; i + 1 < deltas.size(); ++i) {
        const glm::vec3 code(sg::scaledEncode(scale, glm::dvec3(deltas[i])));  // stored from float data
        ASSERT_TRUE(glm::all(glm::lessThanEqual(glm::abs(code), glm::vec3(1))));
        glm::dvec3 read;
        for (int k = 0; k < 3; ++k) read[k] = sg::storedValue(f, k, code[k]);
        const double err = glm::length(sg::scaledDecode(scale, read) - glm::dvec3(deltas[i]));
        if (size == 0) ASSERT_EQ(err, 0.0);
        else worst = std::max(worst, err / scale);
      }
      if (size == 0) continue;
      std::cout << sg::formatName(f) << " (size " << size << "): worst " << worst << " of the scale, stated " << bound << "\n";
      EXPECT_LE(worst, bound) << sg::formatName(f);
      if (f == sg::VertexFormat::Snorm8x4) EXPECT_GE(worst, 0.8 * bound);
    }
  }
  EXPECT_NEAR(*sg::encodingMaxError(scaled, sg::VertexFormat::Snorm16x4), 2.653e-5, 0.001e-5);  // sqrt(3) (0.5/32767 + 2^-24)
  EXPECT_FALSE(sg::encodingMaxError(scaled, sg::VertexFormat::Unorm16x4));  // deltas are signed
}

sg::ValidateReport validateScaled(const std::string& rules, std::map<std::string, double> budgets = {}) {
  return validateWith("morph_scaled.rig.yaml", rules, std::move(budgets));
}

// Four targets' position deltas as snorm16 codes and a scale each: the plan sums them with
// the scale folded into the weight, and the device agrees with the reference everywhere.
TEST(ScaledDeltas, MorphedLimbValidatesOnTheDevice) {
  sg::ValidateReport rep = validateScaled(sourcePath("rules/standard.yaml"));
  EXPECT_TRUE(rep.pass);
  ASSERT_FALSE(rep.runs.empty());
  EXPECT_TRUE(sgtest::planHas(rep.runs[0], "object_position_morphed_scaled"));
}

// A sum that forgets the scale moves every vertex by the codes themselves: validation fails
// the outputs that depend on the position, and only those.
TEST(ScaledDeltas, PlantedMissingScaleFailsValidation) {
  sgtest::RulesCopy rules("scaled_missing_scale");
  ASSERT_TRUE(rules.edit("morph.yaml", "(${morph.weights}[${i}] * ${morph.position_scale}[${i}])", "${morph.weights}[${i}]"));
  sg::ValidateReport broken = validateScaled(rules.rulesFile("standard.yaml").string());
  EXPECT_FALSE(broken.pass);
  const std::set<std::string> failed = sgtest::failingOutputs(broken.runs.at(0));
  EXPECT_TRUE(failed.count("world_position")) << ::testing::PrintToString(failed);
  EXPECT_TRUE(failed.count("gl_Position")) << ::testing::PrintToString(failed);
  EXPECT_FALSE(failed.count("world_normal"));
}

// A delta budget below snorm16's 2.65e-5 of the scale would remove the codes, and with
// them the targets' movement (the unmorphed rule would apply): refused at the attribute.
// A budget above it changes nothing.
TEST(ScaledDeltas, ABudgetTighterThanTheEncodingIsRefused) {
  try {
    validateScaled(sourcePath("rules/standard.yaml"), {{"morph.position", 1e-6}});
    FAIL() << "expected the budget to be refused";
  } catch (const sg::InputError& e) {
    const std::string all = sg::formatDiagnostic(e.diagnostic());
    EXPECT_NE(all.find("morph_scaled.rig.yaml:15:3: error: morph.position_scaled (attribute 'position_morph', snorm16x4) "
                       "is not offered to the search: it errs up to 2.65e-05 of the target's scale, over the budget of "
                       "1e-06 of the target's scale for morph.position (--max-error); the rig stores no other "
                       "morph.position deltas"),
              std::string::npos)
        << all;
  }
  EXPECT_TRUE(validateScaled(sourcePath("rules/standard.yaml"), {{"morph.position", 1e-4}}).pass);
}

}  // namespace

namespace {

// A rig storing the frame both ways offers the search a real choice. Instruction slots
// charge nothing for a location, so the decode only costs: the float frame. The H200
// profile charges 0.36 ns per location and 0.0016 ns per slot: one location saved for 22
// slots of decode is cheaper, so the codes. Lavapipe on a 2-core CPU charges 1.58 ns per
// location and 0.66 ns per slot: the decode would cost 14.5 ns to save 1.6, so the floats,
// its own choice. Every plan validates on the device, and the chosen rig keeps only the
// attributes of the chosen form.
TEST(Octahedral, TheSearchChoosesTheStoredFormPerDevice) {
  for (const std::string profile : {"", "nvidia-h200.yaml", "llvmpipe-2core.yaml"}) {
    const bool h200 = profile == "nvidia-h200.yaml";
    SCOPED_TRACE(profile.empty() ? "instruction slots" : profile);
    sg::GenerateOptions gen;
    if (!profile.empty()) gen.deviceProfilePath = sourcePath("devices/" + profile);
    sg::ValidateReport rep = validateOnLimb(gen, "octahedral_or_float.rig.yaml");
    EXPECT_TRUE(rep.pass);
    ASSERT_FALSE(rep.runs.empty());
    EXPECT_EQ(sgtest::planHas(rep.runs[0], "vertex_normal_from_octahedral"), h200);
    EXPECT_EQ(sgtest::planHas(rep.runs[0], "vertex_tangent_from_octahedral"), h200);
    // What the program reads: the generator's own view of the chosen rig.
    gen.rigPath = dataPath("octahedral_or_float.rig.yaml");
    gen.fragmentPath = dataPath("world.frag");
    gen.rulesPaths = {sourcePath("rules/standard.yaml")};
    sg::GenerateResult g = sg::generate(gen);
    std::set<std::string> read;
    for (const auto& a : g.in.rig.attributes) read.insert(a.name);
    EXPECT_EQ(read.count("frame"), h200 ? 1u : 0u);
    EXPECT_EQ(read.count("normal"), h200 ? 0u : 1u);
    ASSERT_EQ(g.in.notes.size(), 2u);
    EXPECT_NE(g.in.notes[0].message.find(h200 ? "the plan reads vertex.normal_octahedral" : "the plan reads vertex.normal;"),
              std::string::npos)
        << g.in.notes[0].message;
    // validate says which form it ran.
    ASSERT_EQ(rep.notes.size(), 2u);
    EXPECT_EQ(rep.notes[0].message, g.in.notes[0].message);
    EXPECT_NE(sg::formatReport(rep).find("note: vertex.tangent: the plan reads"), std::string::npos);
  }
}


// The same choice for a QTangent against the float frame (normal, and tangent with its
// handedness in w: two locations, 28 bytes): slots and lavapipe keep the floats, the H200
// profile reads the one snorm16x4 location and decodes the three values from it. Every
// plan validates on the device; the note lists the whole plain form.
TEST(QTangent, TheSearchChoosesTheStoredFormPerDevice) {
  for (const std::string profile : {"", "nvidia-h200.yaml", "llvmpipe-2core.yaml"}) {
    const bool h200 = profile == "nvidia-h200.yaml";
    SCOPED_TRACE(profile.empty() ? "instruction slots" : profile);
    sg::GenerateOptions gen;
    if (!profile.empty()) gen.deviceProfilePath = sourcePath("devices/" + profile);
    sg::ValidateReport rep = validateOnLimb(gen, "qtangent_or_float.rig.yaml");
    EXPECT_TRUE(rep.pass);
    ASSERT_FALSE(rep.runs.empty());
    EXPECT_EQ(sgtest::planHas(rep.runs[0], "vertex_normal_from_qtangent"), h200);
    EXPECT_EQ(sgtest::planHas(rep.runs[0], "vertex_handedness_from_qtangent"), h200);
    ASSERT_EQ(rep.notes.size(), 1u);
    EXPECT_NE(rep.notes[0].message.find(h200 ? "the plan reads vertex.qtangent; the rig also stores vertex.normal, "
                                               "vertex.tangent, vertex.handedness"
                                             : "the plan reads vertex.normal, vertex.tangent, vertex.handedness; the "
                                               "rig also stores vertex.qtangent"),
              std::string::npos)
        << rep.notes[0].message;
  }
}
}  // namespace

namespace {

// The packer on a real model: AnimatedMorphSphere's rig as `rig import` derives it, edited
// to store the normal as an octahedral snorm16x2 code, the tangent as one beside its
// handedness and the position relative to the bounds in unorm16. The bytes it writes, read
// back by the layout alone (offset, stride, format, bias and scale), decode to the model's
// own float normals and tangents within the stated 0.0037 degrees, its positions within
// the stated 7.7e-6 of the bounds diagonal.
TEST(Pack, RealModelsFrameReadBackFromTheLayoutWithinTheStatedError) {
  const std::string model = std::string(SG_SHARED_DIR) + "/models/AnimatedMorphSphere/AnimatedMorphSphere.gltf#0/0";
  if (!std::filesystem::exists(std::string(SG_SHARED_DIR) + "/models/AnimatedMorphSphere")) GTEST_SKIP() << "no ../shared";
  sg::Rig rig = sg::importGltf(model.substr(0, model.find('#'))).rig;  // mesh 0, primitive 0
  for (auto& a : rig.attributes) {
    if (a.name == "normal") {
      a.format = sg::VertexFormat::Snorm16x2;
      a.provides = {{"vertex.normal_octahedral", ""}};
    } else if (a.name == "tangent") {
      a.format = sg::VertexFormat::Snorm16x4;
      a.provides = {{"vertex.tangent_octahedral", "xy"}, {"vertex.handedness", "z"}};
    } else if (a.name == "position") {
      a.format = sg::VertexFormat::Unorm16x4;
      a.provides = {{"vertex.position_in_bounds", "xyz"}};
    }
  }
  rig.uniforms.push_back({"bounds_min", "mesh.bounds_min", sg::Type::Vec3, "", 0, {}});
  rig.uniforms.push_back({"bounds_extent", "mesh.bounds_extent", sg::Type::Vec3, "", 0, {}});
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("sg_pack_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string rigPath = (dir / "sphere.rig.yaml").string();
  sgtest::writeText(rigPath, sg::rigToYaml(rig));

  sg::GenerateOptions o;
  o.rigPath = rigPath;
  o.fragmentPath = sourcePath("tests/gltf/data/frame.frag");
  o.rulesPaths = {sourcePath("rules/standard.yaml")};
  const sg::GenerateResult r = sg::generate(o);
  const sg::ValidationScene scene = sg::gltfScene(model, sg::GltfSceneOptions{});
  const sg::PackedVertices packed = sg::packVertices(r, scene.mesh);
  std::filesystem::remove_all(dir);

  const nlohmann::json layout = nlohmann::json::parse(packed.layoutJson);
  ASSERT_EQ(layout["vertex_count"], scene.mesh.vertexCount);
  ASSERT_EQ(layout["bytes"], packed.bytes.size());
  auto streamOf = [&](const std::string& attribute) {
    for (const auto& s : layout["streams"])
      if (s["attribute"] == attribute) return s;
    ADD_FAILURE() << "no stream for " << attribute;
    return nlohmann::json{};
  };
  // snorm16 component c of vertex v: max(value / 32767, -1) (Vulkan's conversion).
  auto snorm16 = [&](const nlohmann::json& s, size_t v, int c) {
    int16_t raw;
    std::memcpy(&raw, packed.bytes.data() + s["offset"].get<size_t>() + v * s["stride"].get<size_t>() + 2 * c, 2);
    return std::max(raw / 32767.0, -1.0);
  };
  const nlohmann::json normal = streamOf("normal"), tangent = streamOf("tangent");
  ASSERT_EQ(normal["format"], "snorm16x2");
  ASSERT_EQ(normal["stride"], 4);
  ASSERT_EQ(tangent["stride"], 8);
  const double bound = normal["provides"][0]["max_error_deg"];
  EXPECT_NEAR(bound, 0.00372, 1e-5);
  double worstNormal = 0, worstTangent = 0;
  size_t handednessWrong = 0;
  const auto& n = scene.mesh.at("vertex.normal");
  const auto& t = scene.mesh.at("vertex.tangent");
  const auto& w = scene.mesh.at("vertex.handedness");
  for (size_t v = 0; v < scene.mesh.vertexCount; ++v) {
    const glm::dvec3 dn = sg::octahedralDecode({snorm16(normal, v, 0), snorm16(normal, v, 1)});
    const glm::dvec3 dt = sg::octahedralDecode({snorm16(tangent, v, 0), snorm16(tangent, v, 1)});
    worstNormal = std::max(worstNormal, angleDegrees(dn, glm::normalize(glm::dvec3(n[v]))));
    worstTangent = std::max(worstTangent, angleDegrees(dt, glm::normalize(glm::dvec3(t[v]))));
    if (snorm16(tangent, v, 2) != w[v].x) ++handednessWrong;
  }
  std::cout << scene.mesh.vertexCount << " vertices: worst normal " << worstNormal << " deg, tangent " << worstTangent
            << " deg (stated " << bound << ")\n";
  EXPECT_LE(worstNormal, bound);
  EXPECT_LE(worstTangent, bound);
  EXPECT_GT(worstNormal, 0.0);  // the data really went through 16 bits (the sphere's tangents are
  // all +x, which the code holds exactly: they check the stream's place and its handedness)
  EXPECT_EQ(handednessWrong, 0u);

  // The position: bias + code * scale from the layout alone, against the model's floats.
  const nlohmann::json position = streamOf("position");
  ASSERT_EQ(position["format"], "unorm16x4");
  const nlohmann::json& part = position["provides"][0];
  ASSERT_EQ(part["encodes"], nlohmann::json::array({"vertex.position"}));
  const double positionBound = part["max_error_of_bounds_diagonal"];
  EXPECT_EQ(layout["uniforms"]["mesh.bounds_min"], part["bias"]);
  const auto& p = scene.mesh.at("vertex.position");
  glm::dvec3 lo(INFINITY), hi(-INFINITY);
  for (const glm::vec4& q : p) lo = glm::min(lo, glm::dvec3(q)), hi = glm::max(hi, glm::dvec3(q));
  double worstPosition = 0;
  for (size_t v = 0; v < scene.mesh.vertexCount; ++v) {
    glm::dvec3 read;
    for (int c = 0; c < 3; ++c) {
      uint16_t raw;
      std::memcpy(&raw, packed.bytes.data() + position["offset"].get<size_t>() + v * position["stride"].get<size_t>() + 2 * c, 2);
      read[c] = part["bias"][c].get<double>() + raw / 65535.0 * part["scale"][c].get<double>();
    }
    worstPosition = std::max(worstPosition, glm::length(read - glm::dvec3(p[v])) / glm::length(hi - lo));
  }
  std::cout << "worst position " << worstPosition << " of the bounds diagonal (stated " << positionBound << ")\n";
  EXPECT_LE(worstPosition, positionBound);
  EXPECT_GT(worstPosition, 0.0);
}

// The same model with its whole frame as one snorm16x4 QTangent and its position deltas as
// snorm16 codes with a scale per target: it validates on the device against the reference
// on what the device reads, and the packed bytes, read back by the layout alone (the
// quaternion rotated with the test's own product, each delta as code * the part's scale),
// give the model's own normals, tangents (orthonormalised), handedness and deltas within
// the stated errors.
TEST(Pack, RealModelsQTangentsAndScaledDeltasReadBackFromTheLayout) {
  const std::string model = std::string(SG_SHARED_DIR) + "/models/AnimatedMorphSphere/AnimatedMorphSphere.gltf#0/0";
  if (!std::filesystem::exists(std::string(SG_SHARED_DIR) + "/models/AnimatedMorphSphere")) GTEST_SKIP() << "no ../shared";
  sg::Rig rig = sg::importGltf(model.substr(0, model.find('#'))).rig;
  std::erase_if(rig.attributes, [](const sg::RigAttribute& a) { return a.name == "tangent"; });
  for (auto& a : rig.attributes) {
    if (a.name == "normal") {
      a.format = sg::VertexFormat::Snorm16x4;
      a.provides = {{"vertex.qtangent", ""}};
    } else if (a.name == "position_morph") {
      a.format = sg::VertexFormat::Snorm16x4;
      a.provides = {{"morph.position_scaled", "xyz"}};
    }
  }
  rig.uniforms.push_back({"morph_scale", "morph.position_scale", sg::Type::Float, "morph_targets", 2, {}});
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("sg_pack_qt_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string rigPath = (dir / "sphere.rig.yaml").string();
  sgtest::writeText(rigPath, sg::rigToYaml(rig));

  sg::ValidateOptions vo;
  vo.gen.rigPath = rigPath;
  vo.gen.fragmentPath = sourcePath("tests/gltf/data/frame.frag");
  vo.gen.rulesPaths = {sourcePath("rules/standard.yaml")};
  const sg::ValidationScene scene = sg::gltfScene(model, sg::GltfSceneOptions{});
  sg::Validator validator(vo);
  const sg::ValidateReport rep = validator.run(scene);
  std::cout << sg::formatReport(rep);
  EXPECT_TRUE(rep.pass);
  ASSERT_FALSE(rep.runs.empty());
  EXPECT_TRUE(sgtest::planHas(rep.runs[0], "vertex_normal_from_qtangent"));
  EXPECT_TRUE(sgtest::planHas(rep.runs[0], "object_position_morphed_scaled"));

  const sg::GenerateResult r = sg::generate(vo.gen);
  const sg::PackedVertices packed = sg::packVertices(r, scene.mesh);
  std::filesystem::remove_all(dir);
  const nlohmann::json layout = nlohmann::json::parse(packed.layoutJson);
  auto snorm16 = [&](const nlohmann::json& s, size_t v, int c) {
    int16_t raw;
    std::memcpy(&raw, packed.bytes.data() + s["offset"].get<size_t>() + v * s["stride"].get<size_t>() + 2 * c, 2);
    return std::max(raw / 32767.0, -1.0);
  };
  const auto& n = scene.mesh.at("vertex.normal");
  const auto& t = scene.mesh.at("vertex.tangent");
  const auto& w = scene.mesh.at("vertex.handedness");
  int targetsRead = 0;
  for (const auto& s : layout["streams"]) {
    const nlohmann::json& part = s["provides"][0];
    if (s["attribute"] == "normal") {
      ASSERT_EQ(part["encodes"], nlohmann::json::array({"vertex.normal", "vertex.tangent", "vertex.handedness"}));
      const double bound = part["max_error_deg"];
      double worst = 0;
      size_t handednessWrong = 0;
      for (size_t v = 0; v < scene.mesh.vertexCount; ++v) {
        const glm::dvec4 q(snorm16(s, v, 0), snorm16(s, v, 1), snorm16(s, v, 2), snorm16(s, v, 3));
        const Frame f{glm::dvec3(n[v]), glm::dvec3(t[v]), w[v].x};
        worst = std::max(worst, angleDegrees(rotate(q, {0, 0, 1}), f.normal));
        if (const auto want = expectedTangent(f)) worst = std::max(worst, angleDegrees(rotate(q, {1, 0, 0}), *want));
        handednessWrong += (q.w < 0) != (f.handedness < 0);
      }
      std::cout << "QTangents: worst " << worst << " deg (stated " << bound << ")\n";
      EXPECT_LE(worst, bound);
      EXPECT_GT(worst, 0.0);
      EXPECT_EQ(handednessWrong, 0u);
    }
    if (s["attribute"] == "position_morph") {
      const int target = s["target"];
      const double scale = part["scale"], bound = part["max_error_of_target_scale"];
      EXPECT_EQ(layout["uniforms"]["morph.position_scale"][target], part["scale"]);
      const auto& d = scene.mesh.at("morph.position[" + std::to_string(target) + "]");
      double worst = 0;
      for (size_t v = 0; v < scene.mesh.vertexCount; ++v) {
        const glm::dvec3 read(snorm16(s, v, 0) * scale, snorm16(s, v, 1) * scale, snorm16(s, v, 2) * scale);
        worst = std::max(worst, glm::length(read - glm::dvec3(d[v])) / scale);
      }
      std::cout << "target " << target << " (scale " << scale << "): worst " << worst << " of the scale (stated " << bound
                << ")\n";
      EXPECT_LE(worst, bound);
      EXPECT_GT(worst, 0.0);
      ++targetsRead;
    }
  }
  EXPECT_EQ(targetsRead, 2);
}

}  // namespace

namespace {

// Unorm8 skin weights of a real model (Fox, 1,728 vertices of 4 influences) as the device
// reads them: every vertex's codes sum to exactly 255 (rounding each alone drifts by up to
// two steps), and no weight moves by more than one step from the model's own.
TEST(SkinWeights, Unorm8WeightsAreRenormalisedToSumToOne) {
  if (!std::filesystem::exists(std::string(SG_SHARED_DIR) + "/models/Fox")) GTEST_SKIP() << "no ../shared";
  const std::string model = std::string(SG_SHARED_DIR) + "/models/Fox/Fox.glb";
  sg::Rig rig = sg::importGltf(model).rig;
  bool found = false;
  for (auto& a : rig.attributes)
    for (const auto& p : a.provides)
      if (p.semantic == "skin.weights[0]") a.format = sg::VertexFormat::Unorm8x4, found = true;
  ASSERT_TRUE(found);
  const sg::ValidationScene scene = sg::gltfScene(model, sg::GltfSceneOptions{});
  const sg::rt::Mesh q = sg::quantizeForRig(rig, scene.mesh);
  const auto& before = scene.mesh.at("skin.weights[0]");
  const auto& after = q.at("skin.weights[0]");
  size_t driftedAlone = 0;
  for (size_t v = 0; v < q.vertexCount; ++v) {
    long codes = 0, alone = 0;
    for (int c = 0; c < 4; ++c) {
      const double code = after[v][c] * 255.0;
      ASSERT_NEAR(code, std::round(code), 1e-4) << "not a code at vertex " << v;
      codes += std::lround(code);
      alone += std::lround(before[v][c] * 255.0);
      EXPECT_LE(std::abs(after[v][c] - before[v][c]), 1.0 / 255 + 1e-7) << v;
    }
    ASSERT_EQ(codes, 255) << "vertex " << v;
    driftedAlone += alone != 255;
  }
  std::cout << driftedAlone << " of " << q.vertexCount << " vertices would not sum to 255 rounded weight by weight\n";
  EXPECT_GT(driftedAlone, 0u);  // the case is real on this model
}

}  // namespace

namespace {

// Every vertex format's VkFormat against the Vulkan header: the value the runtime binds and
// the name the reflection JSON and the C header print (rig/vertex_format.h).
TEST(VertexFormats, VulkanFormatsAreTheHeadersOwn) {
  int checked = 0;
#define SG_EXPECT_VK(F, VK)                                                          \
  EXPECT_EQ(sg::vulkanFormat(sg::VertexFormat::F).value, static_cast<uint32_t>(VK)); \
  EXPECT_STREQ(sg::vulkanFormat(sg::VertexFormat::F).name, #VK);                     \
  ++checked
  SG_EXPECT_VK(Float32x1, VK_FORMAT_R32_SFLOAT);
  SG_EXPECT_VK(Float32x2, VK_FORMAT_R32G32_SFLOAT);
  SG_EXPECT_VK(Float32x3, VK_FORMAT_R32G32B32_SFLOAT);
  SG_EXPECT_VK(Float32x4, VK_FORMAT_R32G32B32A32_SFLOAT);
  SG_EXPECT_VK(Unorm8x4, VK_FORMAT_R8G8B8A8_UNORM);
  SG_EXPECT_VK(Uint8x4, VK_FORMAT_R8G8B8A8_UINT);
  SG_EXPECT_VK(Unorm16x4, VK_FORMAT_R16G16B16A16_UNORM);
  SG_EXPECT_VK(Uint16x4, VK_FORMAT_R16G16B16A16_UINT);
  SG_EXPECT_VK(Uint32x4, VK_FORMAT_R32G32B32A32_UINT);
  SG_EXPECT_VK(Float16x2, VK_FORMAT_R16G16_SFLOAT);
  SG_EXPECT_VK(Float16x4, VK_FORMAT_R16G16B16A16_SFLOAT);
  SG_EXPECT_VK(Snorm8x2, VK_FORMAT_R8G8_SNORM);
  SG_EXPECT_VK(Snorm8x4, VK_FORMAT_R8G8B8A8_SNORM);
  SG_EXPECT_VK(Snorm16x2, VK_FORMAT_R16G16_SNORM);
  SG_EXPECT_VK(Snorm16x4, VK_FORMAT_R16G16B16A16_SNORM);
  SG_EXPECT_VK(Unorm8x2, VK_FORMAT_R8G8_UNORM);
  SG_EXPECT_VK(Unorm16x2, VK_FORMAT_R16G16_UNORM);
  SG_EXPECT_VK(Unorm10_10_10_2, VK_FORMAT_A2B10G10R10_UNORM_PACK32);
  SG_EXPECT_VK(Snorm10_10_10_2, VK_FORMAT_A2B10G10R10_SNORM_PACK32);
  SG_EXPECT_VK(Uint8x2, VK_FORMAT_R8G8_UINT);
  SG_EXPECT_VK(Uint16x2, VK_FORMAT_R16G16_UINT);
  SG_EXPECT_VK(Uint32x1, VK_FORMAT_R32_UINT);
  SG_EXPECT_VK(Uint32x2, VK_FORMAT_R32G32_UINT);
#undef SG_EXPECT_VK
  EXPECT_EQ(checked, sg::kVertexFormatCount);
}

}  // namespace

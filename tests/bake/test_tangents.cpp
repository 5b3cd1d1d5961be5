// Tangent baking (bake/tangents.h) against frames known in closed form: planes mapped by
// any affine UV map, mirrored UVs, a cylinder, and degenerate UVs.
#include "bake/tangents.h"

#include <gtest/gtest.h>

#include <glm/glm.hpp>

#include <cmath>

namespace sg::bake {
namespace {

struct Grid {
  std::vector<Vec3> positions, normals;
  std::vector<Vec2> uvs;
  std::vector<std::array<uint32_t, 3>> triangles;
};

// An n x n vertex grid; `place(i, j)` gives position, normal and uv of vertex (i, j).
template <class F>
Grid grid(int n, F place) {
  Grid g;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      auto [p, nrm, uv] = place(i, j);
      g.positions.push_back({float(p.x), float(p.y), float(p.z)});
      g.normals.push_back({float(nrm.x), float(nrm.y), float(nrm.z)});
      g.uvs.push_back({float(uv.x), float(uv.y)});
    }
  auto at = [n](int i, int j) { return uint32_t(j * n + i); };
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      g.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      g.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  return g;
}

glm::dvec3 xyz(const Vec4& t) { return {t[0], t[1], t[2]}; }

// The plane z = 0 (normal +z), uv = M (x, y) + c. Then (x, y) = M⁻¹ (uv − c), so dP/du is
// M⁻¹'s first column and dP/dv its second: the tangent is the first column normalised, and
// w is the sign of det(M⁻¹) (+1 when cross(+z, dP/du) turns towards dP/dv).
TEST(BakeTangents, PlaneUnderAnyAffineUvMap) {
  const glm::dmat2 maps[] = {glm::dmat2(1, 0, 0, 1), glm::dmat2(-1, 0, 0, 1), glm::dmat2(0.5, 0.8, -1.3, 0.2),
                             glm::dmat2(2, 1, 1, -3)};  // columns: identity, mirrored u, sheared, flipped
  for (const glm::dmat2& M : maps) {
    Grid g = grid(6, [&](int i, int j) {
      glm::dvec2 xy(i * 0.3, j * 0.25);
      return std::tuple(glm::dvec3(xy, 0), glm::dvec3(0, 0, 1), M * xy + glm::dvec2(0.1, -0.4));
    });
    TangentResult r = bakeTangents(g.positions, g.normals, g.uvs, g.triangles);
    glm::dmat2 inv = glm::inverse(M);
    glm::dvec3 want = glm::normalize(glm::dvec3(inv[0], 0));
    double w = glm::determinant(inv) > 0 ? 1 : -1;
    EXPECT_EQ(r.fallbacks, 0u);
    for (size_t v = 0; v < r.tangents.size(); ++v) {
      EXPECT_NEAR(glm::length(xyz(r.tangents[v]) - want), 0.0, 1e-6) << "vertex " << v;
      EXPECT_EQ(r.tangents[v][3], w) << "vertex " << v;
    }
  }
}

// Half a cylinder of radius 2 around y: P = (2 sin θ, y, 2 cos θ), uv = (θ / 2π, y). dP/du
// ∝ (cos θ, 0, −sin θ), the circle's direction, and dP/dv = +y. The grid is symmetric about
// every inner vertex, so the chords' angle-weighted sum points exactly along the circle.
TEST(BakeTangents, CylinderFollowsItsCircles) {
  const int n = 24;
  Grid g = grid(n, [&](int i, int j) {
    double th = 2 * M_PI * i / (n - 1) * 0.5, y = j * 0.2;  // half the circle
    return std::tuple(glm::dvec3(2 * std::sin(th), y, 2 * std::cos(th)), glm::dvec3(std::sin(th), 0, std::cos(th)),
                      glm::dvec2(th / (2 * M_PI), y));
  });
  TangentResult r = bakeTangents(g.positions, g.normals, g.uvs, g.triangles);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      double th = 2 * M_PI * i / (n - 1) * 0.5;
      const Vec4& t = r.tangents[size_t(j * n + i)];
      glm::dvec3 nrm(std::sin(th), 0, std::cos(th));
      EXPECT_NEAR(glm::dot(xyz(t), nrm), 0.0, 1e-6);  // always in the tangent plane
      EXPECT_NEAR(glm::length(xyz(t)), 1.0, 1e-6);
      EXPECT_EQ(t[3], 1.0f);
      // Boundary vertices see one side only: a chord, within half a segment's angle.
      double tol = (i == 0 || i == n - 1) ? 1 - std::cos(M_PI / (n - 1)) + 1e-6 : 1e-6;
      EXPECT_NEAR(glm::dot(xyz(t), glm::dvec3(std::cos(th), 0, -std::sin(th))), 1.0, tol) << i << "," << j;
    }
}

// Triangle winding carries no meaning here (the normal decides the side).
TEST(BakeTangents, WindingDoesNotMatter) {
  Grid g = grid(5, [](int i, int j) {
    glm::dvec2 xy(i, j);
    return std::tuple(glm::dvec3(xy, 0), glm::dvec3(0, 0, 1), glm::dvec2(0.3 * i + 0.1 * j, -0.2 * i + 0.5 * j));
  });
  TangentResult a = bakeTangents(g.positions, g.normals, g.uvs, g.triangles);
  for (auto& t : g.triangles) std::swap(t[1], t[2]);
  TangentResult b = bakeTangents(g.positions, g.normals, g.uvs, g.triangles);
  for (size_t v = 0; v < a.tangents.size(); ++v)
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(a.tangents[v][c], b.tangents[v][c], 1e-6);
}

TEST(BakeTangents, DegenerateUvsFallBackToTheNormalsBasis) {
  Grid g = grid(4, [](int i, int j) {
    glm::dvec3 n = glm::normalize(glm::dvec3(0.3, -0.5, 0.8));
    glm::dvec3 a = glm::normalize(glm::cross(n, glm::dvec3(1, 0, 0))), b = glm::cross(n, a);
    return std::tuple(a * double(i) + b * double(j), n, glm::dvec2(0.5, 0.5));  // every uv the same
  });
  TangentResult r = bakeTangents(g.positions, g.normals, g.uvs, g.triangles);
  EXPECT_EQ(r.fallbacks, r.tangents.size());
  for (const Vec4& t : r.tangents) {
    EXPECT_NEAR(glm::length(xyz(t)), 1.0, 1e-6);
    EXPECT_NEAR(glm::dot(xyz(t), glm::dvec3(g.normals[0][0], g.normals[0][1], g.normals[0][2])), 0.0, 1e-6);
    EXPECT_EQ(t[3], 1.0f);
  }
  // A zero normal has no tangent plane: a zero tangent, not NaN.
  g.normals.assign(g.normals.size(), Vec3{0, 0, 0});
  for (const Vec4& t : bakeTangents(g.positions, g.normals, g.uvs, g.triangles).tangents)
    EXPECT_EQ(xyz(t), glm::dvec3(0.0));
}

}  // namespace
}  // namespace sg::bake

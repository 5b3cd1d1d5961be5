// Known answers for the occlusion baker (docs/bake.md derives them): the open plane, the
// bottom of a closed box, the inner edge of two perpendicular planes, the corner of three,
// and a sphere over a plane (analytic view factor). Stochastic estimates must lie within
// the 99 % binomial confidence bound for the number of rays; exact cases must be exact.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "bake/occlusion.h"

namespace sg::bake {
namespace {

constexpr double kZ99 = 2.5758293035489;  // two-sided 99 % normal quantile

// k/n against p: |k/n − p| ≤ z·sqrt(p(1−p)/n).
void expectWithinBound(double estimate, double p, size_t n, const std::string& what) {
  double bound = kZ99 * std::sqrt(p * (1 - p) / static_cast<double>(n));
  EXPECT_LE(std::fabs(estimate - p), bound) << what << ": estimate " << estimate << ", exact " << p << ", " << n
                                            << " rays, 99% bound ±" << bound;
}

void quad(TriangleSoup& s, Vec3 a, Vec3 b, Vec3 c, Vec3 d) {
  uint32_t base = static_cast<uint32_t>(s.positions.size());
  s.positions.insert(s.positions.end(), {a, b, c, d});
  s.triangles.push_back({base, base + 1, base + 2});
  s.triangles.push_back({base, base + 2, base + 3});
}

// UV sphere (inscribed polyhedron: its vertices lie on the sphere).
void sphere(TriangleSoup& s, Vec3 c, float r, int rings, int segments) {
  uint32_t base = static_cast<uint32_t>(s.positions.size());
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j <= segments; ++j) {
      double th = M_PI * i / rings, ph = 2 * M_PI * j / segments;
      s.positions.push_back({c[0] + r * float(std::sin(th) * std::cos(ph)), c[1] + r * float(std::sin(th) * std::sin(ph)),
                             c[2] + r * float(std::cos(th))});
    }
  auto at = [&](int i, int j) { return base + static_cast<uint32_t>(i * (segments + 1) + j); };
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      s.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      s.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
}

// Pooled estimate over `count` points at the same place (independent streams): k/n over all rays.
double pooled(const TriangleSoup& scene, Vec3 p, Vec3 n, Distribution d, int rays, int count, uint64_t seed = 7) {
  std::vector<BakePoint> pts;
  for (int i = 0; i < count; ++i) pts.push_back({p, n, static_cast<uint64_t>(1000 + i)});
  OcclusionOptions o;
  o.rays = rays;
  o.distribution = d;
  o.seed = seed;
  o.offset = 1e-5;  // the default (relative to the scene's size) is large for 1000-unit planes
  auto occ = bakeOcclusion(scene, pts, o);
  double sum = 0;
  for (float v : occ) sum += v;
  return sum / count;
}

const float kL = 1000.0f;  // "infinite" planes

TEST(Occlusion, OpenPlaneIsExactlyZero) {
  TriangleSoup s;
  quad(s, {-10, -10, 0}, {10, -10, 0}, {10, 10, 0}, {-10, 10, 0});
  std::vector<BakePoint> pts;
  for (int i = 0; i < 9; ++i) pts.push_back({{float(i) - 4.0f, 0.5f * float(i) - 2.0f, 0}, {0, 0, 1}, uint64_t(i)});
  pts.push_back({{0, 0, 0}, {0, 0, -1}, 99});  // facing away: nothing below either
  OcclusionOptions o;
  o.rays = 512;
  for (auto d : {Distribution::Uniform, Distribution::Cosine}) {
    o.distribution = d;
    for (float v : bakeOcclusion(s, pts, o)) EXPECT_EQ(v, 0.0f);
  }
}

TriangleSoup closedBox() {  // [-1, 1]^3, all faces
  TriangleSoup s;
  quad(s, {-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1});
  quad(s, {-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1});
  quad(s, {-1, -1, -1}, {1, -1, -1}, {1, -1, 1}, {-1, -1, 1});
  quad(s, {-1, 1, -1}, {1, 1, -1}, {1, 1, 1}, {-1, 1, 1});
  quad(s, {-1, -1, -1}, {-1, 1, -1}, {-1, 1, 1}, {-1, -1, 1});
  quad(s, {1, -1, -1}, {1, 1, -1}, {1, 1, 1}, {1, -1, 1});
  return s;
}

TEST(Occlusion, BottomOfClosedBoxIsExactlyOne) {
  TriangleSoup s = closedBox();
  std::vector<BakePoint> pts{{{0, 0, -1}, {0, 0, 1}, 1},
                             {{0.9f, -0.9f, -1}, {0, 0, 1}, 2},
                             {{0.999f, 0.999f, -1}, {0, 0, 1}, 3},  // near the corner
                             {{0, 0, 0}, {0.3f, -0.2f, 0.9f}, 4}};  // inside, any direction
  OcclusionOptions o;
  o.rays = 1024;
  for (auto d : {Distribution::Uniform, Distribution::Cosine}) {
    o.distribution = d;
    for (float v : bakeOcclusion(s, pts, o)) EXPECT_EQ(v, 1.0f);
  }
}

TEST(Occlusion, MaxDistanceIgnoresFartherGeometry) {
  TriangleSoup s = closedBox();
  OcclusionOptions o;
  o.rays = 1024;
  o.maxDistance = 0.9;  // every wall is ≥ 1 away from the centre of the bottom face (offset ~3e-4)
  EXPECT_EQ(bakeOcclusion(s, {{{0, 0, -1}, {0, 0, 1}, 1}}, o)[0], 0.0f);
  o.maxDistance = 2.5;  // the farthest point of the box (a top corner) is √(1+1+4) ≈ 2.45 away
  EXPECT_EQ(bakeOcclusion(s, {{{0, 0, -1}, {0, 0, 1}, 1}}, o)[0], 1.0f);
}

// Floor z = 0 (x ≥ 0) and wall x = 0 (z ≥ 0); the edge vertex's normal is the bisector.
// Open: the quarter space x > 0, z > 0. Uniform: 1/2 blocked; cosine: 1 − 1/√2 blocked.
TEST(Occlusion, InnerEdgeOfTwoPlanes) {
  TriangleSoup s;
  quad(s, {0, -kL, 0}, {kL, -kL, 0}, {kL, kL, 0}, {0, kL, 0});
  quad(s, {0, -kL, 0}, {0, kL, 0}, {0, kL, kL}, {0, -kL, kL});
  Vec3 n{float(M_SQRT1_2), 0, float(M_SQRT1_2)};
  const int rays = 4096, count = 8;
  expectWithinBound(pooled(s, {0, 3, 0}, n, Distribution::Uniform, rays, count), 0.5, rays * count, "edge, uniform");
  expectWithinBound(pooled(s, {0, -2, 0}, n, Distribution::Cosine, rays, count), 1 - M_SQRT1_2, rays * count,
                    "edge, cosine");
}

// Floor z = 0, walls x = 0 and y = 0, each a quarter plane bounding the positive octant;
// normal (1,1,1)/√3. Open: the octant. Uniform: 3/4 blocked; cosine: 1 − √3/4 blocked.
TEST(Occlusion, CornerOfThreePlanes) {
  TriangleSoup s;
  quad(s, {0, 0, 0}, {kL, 0, 0}, {kL, kL, 0}, {0, kL, 0});
  quad(s, {0, 0, 0}, {0, kL, 0}, {0, kL, kL}, {0, 0, kL});
  quad(s, {0, 0, 0}, {kL, 0, 0}, {kL, 0, kL}, {0, 0, kL});
  float c = float(1 / std::sqrt(3.0));
  const int rays = 4096, count = 8;
  expectWithinBound(pooled(s, {0, 0, 0}, {c, c, c}, Distribution::Uniform, rays, count), 0.75, rays * count,
                    "corner, uniform");
  expectWithinBound(pooled(s, {0, 0, 0}, {c, c, c}, Distribution::Cosine, rays, count), 1 - std::sqrt(3.0) / 4,
                    rays * count, "corner, cosine");
}

// A sphere of radius R centred at height H above the point (normal up): it subtends a cone
// of half-angle α, sin α = R/H. Uniform: 1 − cos α blocked; cosine: the view factor
// sin²α = (R/H)².
TEST(Occlusion, SphereOverPlaneMatchesViewFactor) {
  for (auto [r, h] : {std::pair{1.0, 2.0}, std::pair{1.0, 1.25}, std::pair{0.5, 3.0}}) {
    TriangleSoup s;
    quad(s, {-kL, -kL, 0}, {kL, -kL, 0}, {kL, kL, 0}, {-kL, kL, 0});
    sphere(s, {0, 0, float(h)}, float(r), 96, 192);
    double sinA = r / h;
    const int rays = 4096, count = 8;
    std::string what = "R " + std::to_string(r) + ", H " + std::to_string(h);
    expectWithinBound(pooled(s, {0, 0, 0}, {0, 0, 1}, Distribution::Uniform, rays, count),
                      1 - std::sqrt(1 - sinA * sinA), rays * count, what + ", uniform");
    expectWithinBound(pooled(s, {0, 0, 0}, {0, 0, 1}, Distribution::Cosine, rays, count), sinA * sinA, rays * count,
                      what + ", cosine");
  }
}

// The estimate is a binomial count: over many points with independent streams, the
// fraction outside the 99 % bound must be about 1 % (a biased or correlated sampler fails).
TEST(Occlusion, CoverageOfTheConfidenceBound) {
  TriangleSoup s;
  quad(s, {0, -kL, 0}, {kL, -kL, 0}, {kL, kL, 0}, {0, kL, 0});
  quad(s, {0, -kL, 0}, {0, kL, 0}, {0, kL, kL}, {0, -kL, kL});
  Vec3 n{float(M_SQRT1_2), 0, float(M_SQRT1_2)};
  std::vector<BakePoint> pts;
  for (int i = 0; i < 2000; ++i) pts.push_back({{0, float(i % 50) - 25.0f, 0}, n, uint64_t(i)});
  OcclusionOptions o;
  o.rays = 256;
  auto occ = bakeOcclusion(s, pts, o);
  double bound = kZ99 * std::sqrt(0.25 / o.rays);
  int outside = 0;
  for (float v : occ) outside += std::fabs(v - 0.5) > bound;
  // 2000 trials at p ≤ 0.01 (a bit less: the count is discrete): ≤ 20 expected, 40 is ~4.5σ.
  EXPECT_LE(outside, 40);
}

TEST(Occlusion, DirectionsFollowTheDistribution) {
  Vec3 n{0.48f, -0.6f, 0.64f};
  for (auto d : {Distribution::Uniform, Distribution::Cosine}) {
    double sum = 0, sum2 = 0;
    const int count = 20000;
    for (int i = 0; i < count; ++i) {
      Vec3 v = hemisphereDirection(n, d, 3, 42, i);
      double len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      ASSERT_NEAR(len, 1.0, 1e-5);
      double c = (v[0] * n[0] + v[1] * n[1] + v[2] * n[2]);
      ASSERT_GE(c, -1e-6);
      sum += c;
      sum2 += c * c;
    }
    // E[cos θ]: uniform 1/2 (variance 1/12); cosine 2/3 (variance 1/18).
    double mean = sum / count, expect = d == Distribution::Uniform ? 0.5 : 2.0 / 3.0;
    double sd = std::sqrt((d == Distribution::Uniform ? 1.0 / 12 : 1.0 / 18) / count);
    EXPECT_NEAR(mean, expect, 4 * sd);
    (void)sum2;
  }
}

TEST(Occlusion, DeterministicForASeedAndIndependentOfThreads) {
  TriangleSoup s = closedBox();
  TriangleSoup open;  // a box without its top: fractional answers
  for (size_t t = 0; t < s.triangles.size(); ++t)
    if (t != 2 && t != 3) open.triangles.push_back(s.triangles[t]);
  open.positions = s.positions;
  std::vector<BakePoint> pts;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-0.95f, 0.95f);
  for (int i = 0; i < 300; ++i) pts.push_back({{u(rng), u(rng), -1}, {0, 0, 1}, uint64_t(i)});
  OcclusionOptions o;
  o.rays = 128;
  o.threads = 1;
  auto one = bakeOcclusion(open, pts, o);
  o.threads = 3;
  auto three = bakeOcclusion(open, pts, o);
  EXPECT_EQ(one, three);
  // A point's value does not depend on the other points.
  auto alone = bakeOcclusion(open, {pts[137]}, o);
  EXPECT_EQ(alone[0], one[137]);
  o.seed = 2;
  EXPECT_NE(bakeOcclusion(open, pts, o), one);
}

// Embree against the plain loop on random triangle soups: the same rays must agree (up to
// rays grazing a shared edge, which either may count).
TEST(Occlusion, EmbreeAgreesWithBruteForce) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1, 1);
  TriangleSoup s;
  for (int t = 0; t < 300; ++t) {
    Vec3 c{2 * u(rng), 2 * u(rng), 2 * u(rng)};
    uint32_t base = static_cast<uint32_t>(s.positions.size());
    for (int k = 0; k < 3; ++k) s.positions.push_back({c[0] + 0.4f * u(rng), c[1] + 0.4f * u(rng), c[2] + 0.4f * u(rng)});
    s.triangles.push_back({base, base + 1, base + 2});
  }
  std::vector<BakePoint> pts;
  for (int i = 0; i < 200; ++i) pts.push_back({{2 * u(rng), 2 * u(rng), 2 * u(rng)}, {u(rng), u(rng), u(rng)}, uint64_t(i)});
  OcclusionOptions o;
  o.rays = 64;
  auto embree = bakeOcclusion(*makeEmbreeCaster(s), pts, o, 1e-4);
  auto brute = bakeOcclusion(*makeBruteForceCaster(s), pts, o, 1e-4);
  double diff = 0, total = 0;
  for (size_t i = 0; i < pts.size(); ++i) {
    diff += std::fabs(embree[i] - brute[i]) * o.rays;
    total += embree[i] * o.rays;
  }
  EXPECT_GT(total, 1000);  // the scene does block a good share
  EXPECT_LE(diff, 3) << "rays that disagree, out of " << pts.size() * o.rays;
}

}  // namespace
}  // namespace sg::bake

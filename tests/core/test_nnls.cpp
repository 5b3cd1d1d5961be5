// NNLS against the mathematics: exact recovery of non-negative solutions, the optimum of an
// exhaustive search over supports (solved independently, by the normal equations), and the
// Karush-Kuhn-Tucker conditions of min |Ax - b|^2, x >= 0.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "common/nnls.h"

namespace sg {
namespace {

struct Instance {
  size_t m, n;
  std::vector<double> a, b;
};

Instance randomInstance(std::mt19937& rng, size_t m, size_t n) {
  std::uniform_real_distribution<double> u(-1, 1);
  Instance in{m, n, std::vector<double>(m * n), std::vector<double>(m)};
  for (auto& v : in.a) v = u(rng);
  for (auto& v : in.b) v = u(rng);
  return in;
}

double residual(const Instance& in, const std::vector<double>& x) {
  double rr = 0;
  for (size_t i = 0; i < in.m; ++i) {
    double r = in.b[i];
    for (size_t j = 0; j < in.n; ++j) r -= in.a[i * in.n + j] * x[j];
    rr += r * r;
  }
  return std::sqrt(rr);
}

// Least squares on a support by Gauss-Jordan elimination of the normal equations: an
// independent solver for the oracle (well conditioned random data only).
std::vector<double> normalEquations(const Instance& in, const std::vector<size_t>& cols) {
  const size_t k = cols.size();
  std::vector<std::vector<double>> g(k, std::vector<double>(k + 1, 0));
  for (size_t r = 0; r < k; ++r) {
    for (size_t c = 0; c < k; ++c)
      for (size_t i = 0; i < in.m; ++i) g[r][c] += in.a[i * in.n + cols[r]] * in.a[i * in.n + cols[c]];
    for (size_t i = 0; i < in.m; ++i) g[r][k] += in.a[i * in.n + cols[r]] * in.b[i];
  }
  for (size_t p = 0; p < k; ++p) {
    size_t best = p;
    for (size_t r = p + 1; r < k; ++r)
      if (std::abs(g[r][p]) > std::abs(g[best][p])) best = r;
    std::swap(g[p], g[best]);
    for (size_t r = 0; r < k; ++r) {
      if (r == p) continue;
      double f = g[r][p] / g[p][p];
      for (size_t c = p; c <= k; ++c) g[r][c] -= f * g[p][c];
    }
  }
  std::vector<double> x(k);
  for (size_t r = 0; r < k; ++r) x[r] = g[r][k] / g[r][r];
  return x;
}

// The NNLS optimum is the least-squares solution on its support, positive there: the best
// feasible one over all 2^n supports.
double exhaustiveOptimum(const Instance& in, std::vector<double>& bestX) {
  double best = residual(in, std::vector<double>(in.n, 0));
  bestX.assign(in.n, 0);
  for (unsigned mask = 1; mask < (1u << in.n); ++mask) {
    std::vector<size_t> cols;
    for (size_t j = 0; j < in.n; ++j)
      if (mask & (1u << j)) cols.push_back(j);
    std::vector<double> z = normalEquations(in, cols);
    bool feasible = true;
    for (double v : z) feasible = feasible && v > 0;
    if (!feasible) continue;
    std::vector<double> x(in.n, 0);
    for (size_t c = 0; c < cols.size(); ++c) x[cols[c]] = z[c];
    double r = residual(in, x);
    if (r < best) best = r, bestX = x;
  }
  return best;
}

TEST(Nnls, RecoversAnExactNonNegativeSolution) {
  std::mt19937 rng(7);
  Instance in = randomInstance(rng, 40, 6);
  std::vector<double> truth{0.57, 0, 2.5, 0.01, 0, 1.25};
  for (size_t i = 0; i < in.m; ++i) {
    in.b[i] = 0;
    for (size_t j = 0; j < in.n; ++j) in.b[i] += in.a[i * in.n + j] * truth[j];
  }
  NnlsResult r = nnls(in.a, in.m, in.n, in.b);
  ASSERT_TRUE(r.converged);
  for (size_t j = 0; j < in.n; ++j) EXPECT_NEAR(r.x[j], truth[j], 1e-10) << j;
  EXPECT_LT(r.residualNorm, 1e-10);
}

TEST(Nnls, MatchesTheExhaustiveOptimumAndSatisfiesKkt) {
  std::mt19937 rng(2026);
  for (int trial = 0; trial < 200; ++trial) {
    size_t n = 1 + trial % 7, m = n + 3 + trial % 11;
    Instance in = randomInstance(rng, m, n);
    NnlsResult r = nnls(in.a, in.m, in.n, in.b);
    std::vector<double> oracleX;
    double oracle = exhaustiveOptimum(in, oracleX);
    ASSERT_TRUE(r.converged) << trial;
    EXPECT_NEAR(r.residualNorm, oracle, 1e-9 * (1 + oracle)) << trial;
    EXPECT_NEAR(residual(in, r.x), r.residualNorm, 1e-12) << trial;
    // KKT: x >= 0; gradient of the residual w = A^T (b - Ax) is <= 0 where x = 0 and 0 where x > 0.
    std::vector<double> w(n, 0);
    for (size_t i = 0; i < m; ++i) {
      double res = in.b[i];
      for (size_t j = 0; j < n; ++j) res -= in.a[i * n + j] * r.x[j];
      for (size_t j = 0; j < n; ++j) w[j] += in.a[i * n + j] * res;
    }
    for (size_t j = 0; j < n; ++j) {
      EXPECT_GE(r.x[j], 0) << trial;
      if (r.x[j] > 0) EXPECT_NEAR(w[j], 0, 1e-9) << trial << " column " << j;
      else EXPECT_LE(w[j], 1e-9) << trial << " column " << j;
      EXPECT_NEAR(r.x[j], oracleX[j], 1e-7) << trial << " column " << j;  // unique: A has full column rank
    }
  }
}

TEST(Nnls, ZeroAndDuplicateColumns) {
  // Column 1 is zero, column 2 duplicates column 0: the residual is still optimal and the
  // zero column gets no weight.
  std::mt19937 rng(3);
  Instance in = randomInstance(rng, 12, 3);
  for (size_t i = 0; i < in.m; ++i) {
    in.a[i * 3 + 1] = 0;
    in.a[i * 3 + 2] = in.a[i * 3 + 0];
    in.b[i] = 2 * in.a[i * 3 + 0];
  }
  NnlsResult r = nnls(in.a, in.m, in.n, in.b);
  EXPECT_EQ(r.x[1], 0);
  EXPECT_NEAR(r.x[0] + r.x[2], 2, 1e-10);
  EXPECT_LT(r.residualNorm, 1e-10);
}

TEST(Nnls, AllNegativeCorrelationGivesZero) {
  // b = -A 1 with A >= 0: every column points away from b, so x = 0 and |r| = |b|.
  Instance in{3, 2, {1, 0, 0, 1, 1, 1}, {-1, -1, -2}};
  NnlsResult r = nnls(in.a, in.m, in.n, in.b);
  EXPECT_EQ(r.x, (std::vector<double>{0, 0}));
  EXPECT_NEAR(r.residualNorm, std::sqrt(6.0), 1e-15);
}

TEST(Nnls, RejectsMismatchedSizes) {
  EXPECT_THROW(nnls({1, 2, 3}, 2, 2, {1, 2}), std::invalid_argument);
  EXPECT_THROW(nnls({1, 2}, 2, 1, {1}), std::invalid_argument);
  EXPECT_THROW(nnls({}, 0, 0, {}), std::invalid_argument);
}

}  // namespace
}  // namespace sg

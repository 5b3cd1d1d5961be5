// Non-negative least squares: minimise |A x - b|^2 subject to x >= 0 (Lawson and Hanson,
// "Solving Least Squares Problems", 1974, chapter 23). The device calibration fits per-term
// weights (ns per location, per byte, ...) that cannot be negative: a negative weight would
// let the search buy time by reading more.
#pragma once
#include <cstddef>
#include <vector>

namespace sg {

struct NnlsResult {
  std::vector<double> x;  // n weights, each >= 0
  double residualNorm = 0;  // |A x - b|
  int iterations = 0;
  bool converged = true;  // false: the iteration limit (3n outer steps) ended it
};

// `a` is m x n, row-major (a[i * n + j]); `b` has m entries; m >= 1, n >= 1. Columns that are
// all zero get weight 0. Throws std::invalid_argument on mismatched sizes.
NnlsResult nnls(const std::vector<double>& a, size_t m, size_t n, const std::vector<double>& b);

// Unconstrained least squares over the columns `cols` of A (Householder QR); columns that are
// linearly dependent on earlier ones (relative tolerance 1e-12) get 0. Returns |cols| values.
std::vector<double> leastSquaresOnColumns(const std::vector<double>& a, size_t m, size_t n, const std::vector<double>& b,
                                          const std::vector<size_t>& cols);

}  // namespace sg

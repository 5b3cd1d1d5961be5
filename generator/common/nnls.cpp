#include "common/nnls.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace sg {

std::vector<double> leastSquaresOnColumns(const std::vector<double>& a, size_t m, size_t n, const std::vector<double>& b,
                                          const std::vector<size_t>& cols) {
  const size_t k = cols.size();
  // Column-major copy of the chosen columns, reduced in place to R by Householder reflections
  // that are applied to the right-hand side as they are made.
  std::vector<double> q(m * k);
  std::vector<double> originalNorm(k, 0);
  for (size_t c = 0; c < k; ++c)
    for (size_t i = 0; i < m; ++i) {
      q[c * m + i] = a[i * n + cols[c]];
      originalNorm[c] += q[c * m + i] * q[c * m + i];
    }
  std::vector<double> rhs = b;
  std::vector<size_t> pivotRow(k, m);  // m: dependent column
  size_t row = 0;
  for (size_t c = 0; c < k && row < m; ++c) {
    double* col = &q[c * m];
    double norm = 0;
    for (size_t i = row; i < m; ++i) norm += col[i] * col[i];
    norm = std::sqrt(norm);
    if (norm <= 1e-12 * std::sqrt(originalNorm[c]) || norm == 0) continue;
    // v = x - alpha e_row with alpha = -sign(x_row) |x| (no cancellation); H = I - 2 v v^T / v^T v.
    double alpha = col[row] > 0 ? -norm : norm;
    std::vector<double> v(col + row, col + m);
    v[0] -= alpha;
    double vv = 0;
    for (double x : v) vv += x * x;
    auto reflect = [&](double* y) {
      double d = 0;
      for (size_t i = 0; i < v.size(); ++i) d += v[i] * y[row + i];
      d = 2 * d / vv;
      for (size_t i = 0; i < v.size(); ++i) y[row + i] -= d * v[i];
    };
    for (size_t c2 = c; c2 < k; ++c2) reflect(&q[c2 * m]);
    reflect(rhs.data());
    pivotRow[c] = row++;
  }
  // Back substitution over the independent columns (R is upper triangular in pivot rows).
  std::vector<double> x(k, 0);
  for (size_t c = k; c-- > 0;) {
    if (pivotRow[c] == m) continue;
    const size_t r = pivotRow[c];
    double s = rhs[r];
    for (size_t c2 = c + 1; c2 < k; ++c2)
      if (pivotRow[c2] != m) s -= q[c2 * m + r] * x[c2];
    x[c] = s / q[c * m + r];
  }
  return x;
}

NnlsResult nnls(const std::vector<double>& a, size_t m, size_t n, const std::vector<double>& b) {
  if (m == 0 || n == 0 || a.size() != m * n || b.size() != m)
    throw std::invalid_argument("nnls: A must be m x n and b must have m entries (m, n >= 1)");
  NnlsResult res;
  res.x.assign(n, 0.0);
  std::vector<bool> passive(n, false);
  auto gradient = [&](std::vector<double>& w) {  // w = A^T (b - A x): descent direction
    std::vector<double> r = b;
    for (size_t i = 0; i < m; ++i)
      for (size_t j = 0; j < n; ++j) r[i] -= a[i * n + j] * res.x[j];
    w.assign(n, 0.0);
    for (size_t i = 0; i < m; ++i)
      for (size_t j = 0; j < n; ++j) w[j] += a[i * n + j] * r[i];
  };
  // Tolerance on the gradient: rounding of A^T b at the scale of the data.
  double scale = 0;
  for (size_t j = 0; j < n; ++j) {
    double s = 0;
    for (size_t i = 0; i < m; ++i) s += std::abs(a[i * n + j] * b[i]);
    scale = std::max(scale, s);
  }
  const double tol = 1e3 * std::numeric_limits<double>::epsilon() * std::max(scale, 1e-300) * static_cast<double>(m);

  std::vector<double> w;
  const int maxOuter = static_cast<int>(3 * n);
  std::vector<bool> blocked(n, false);  // columns whose entry made no progress (rounding)
  for (;;) {
    gradient(w);
    size_t t = n;
    for (size_t j = 0; j < n; ++j)
      if (!passive[j] && !blocked[j] && w[j] > tol && (t == n || w[j] > w[t])) t = j;
    if (t == n) break;
    if (res.iterations++ >= maxOuter) {
      res.converged = false;
      break;
    }
    passive[t] = true;
    bool entered = true;
    for (;;) {
      std::vector<size_t> cols;
      for (size_t j = 0; j < n; ++j)
        if (passive[j]) cols.push_back(j);
      std::vector<double> zp = leastSquaresOnColumns(a, m, n, b, cols);
      std::vector<double> z(n, 0.0);
      bool positive = true;
      for (size_t c = 0; c < cols.size(); ++c) {
        z[cols[c]] = zp[c];
        if (zp[c] <= 0) positive = false;
      }
      if (positive) {
        res.x = z;
        break;
      }
      if (z[t] <= 0 && res.x[t] == 0) {  // the entering column cannot move: rounding; give up on it
        passive[t] = false;
        blocked[t] = true;
        entered = false;
        break;
      }
      // Step from x toward z until the first passive weight reaches zero, then drop the zeros.
      double step = 1;
      for (size_t j : cols)
        if (z[j] <= 0) step = std::min(step, res.x[j] / (res.x[j] - z[j]));
      for (size_t j = 0; j < n; ++j) {
        res.x[j] += step * (z[j] - res.x[j]);
        if (passive[j] && res.x[j] <= 0) {
          res.x[j] = 0;
          passive[j] = false;
        }
      }
    }
    if (entered) std::fill(blocked.begin(), blocked.end(), false);  // x moved: retry every column
  }
  double rr = 0;
  for (size_t i = 0; i < m; ++i) {
    double r = b[i];
    for (size_t j = 0; j < n; ++j) r -= a[i * n + j] * res.x[j];
    rr += r * r;
  }
  res.residualNorm = std::sqrt(rr);
  return res;
}

}  // namespace sg

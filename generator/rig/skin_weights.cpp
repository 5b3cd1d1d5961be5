#include "rig/skin_weights.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace sg {

bool skinWeightsNormalized(const float* w, size_t n) {
  float sum = 0;
  double tolerance = 0;
  for (size_t k = 0; k < n; ++k)
    if (w[k] != 0) sum += w[k], tolerance += 2e-7;
  return std::abs(double(sum) - 1) <= tolerance;
}

void normalizeSkinWeights(double* w, size_t n, double steps) {
  if (n == 0) return;
  double sum = 0;
  for (size_t k = 0; k < n; ++k) sum += std::abs(w[k]);
  if (!(sum > 0) || !std::isfinite(sum)) {
    std::fill(w, w + n, 0.0);
    w[0] = 1;
    return;
  }
  if (steps <= 0) {
    for (size_t k = 0; k < n; ++k) w[k] /= sum;
    return;
  }
  std::vector<double> scaled(n), code(n);
  double total = 0;
  for (size_t k = 0; k < n; ++k) {
    scaled[k] = std::max(0.0, w[k]) / sum * steps;  // unorm codes are never negative
    total += code[k] = std::floor(scaled[k]);
  }
  std::vector<size_t> order(n);
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return scaled[a] - code[a] > scaled[b] - code[b]; });
  for (size_t k = 0; total < steps && k < n; ++k, ++total) code[order[k]] += 1;
  for (size_t k = 0; k < n; ++k) w[k] = code[k] / steps;
}

}  // namespace sg

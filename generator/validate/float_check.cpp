#include "validate/float_check.h"

#include <cmath>

namespace sg {

FloatReference floatReference(const RuleSet& rules, const RigShape& shape, rt::Mesh& floatMesh,
                              const UniformValues& uniforms, const std::vector<InputErrorBound>& bounds,
                              const std::vector<std::string>& semantics) {
  auto evaluate = [&] { return Interpreter(rules, shape, floatMesh, uniforms).evaluate(semantics); };
  FloatReference out;
  out.values = evaluate();
  const std::vector<std::vector<double>>& f0 = out.values;
  std::vector<std::vector<double>> first, second, ballSquares;
  for (const auto& v : f0) first.emplace_back(v.size(), 0.0), second.emplace_back(v.size(), 0.0);
  std::vector<int> widths;
  Interpreter probe(rules, shape, floatMesh, uniforms);
  for (const auto& s : semantics) widths.push_back(probe.components(s));
  const size_t n = floatMesh.vertexCount;
  std::vector<bool> unbounded(n, false);  // an input's bound is infinite (a value its format cannot hold)
  std::vector<double> bound(n), up(n), down(n);
  for (const InputErrorBound& b : bounds) {
    std::vector<glm::vec4>& stream = floatMesh.streams.at(b.semantic);
    if (b.ball) ballSquares = std::vector<std::vector<double>>(first.size());
    for (int k = 0; k < (b.ball ? 3 : 4); ++k) {
      bool any = false;
      for (size_t v = 0; v < n; ++v) {
        bound[v] = v < b.bound.size() ? b.bound[v][b.ball ? 0 : k] : 0.0;
        if (std::isinf(bound[v])) unbounded[v] = true;
        if (!(bound[v] > 0) || std::isinf(bound[v]) || v >= stream.size() || !std::isfinite(stream[v][k])) bound[v] = 0;
        any = any || bound[v] > 0;
      }
      if (!any) continue;
      // Steps of the bound itself (the secant over the range the error can reach), at least
      // 4 float steps so that the float data moves; the steps taken are measured exactly.
      auto step = [&](double sign, std::vector<double>& taken) {
        for (size_t v = 0; v < n; ++v) {
          if (bound[v] == 0) continue;
          const float x = stream[v][k];
          const double ulp = double(std::nextafter(std::abs(x), INFINITY)) - std::abs(x);
          stream[v][k] = static_cast<float>(x + sign * std::max(bound[v], 4 * ulp));
          taken[v] = std::abs(double(stream[v][k]) - x);
        }
      };
      const std::vector<glm::vec4> saved = stream;
      step(1, up);
      const auto fp = evaluate();
      stream = saved;
      step(-1, down);
      const auto fm = evaluate();
      stream = saved;
      for (size_t s = 0; s < f0.size(); ++s) {
        const auto w = static_cast<size_t>(widths[s]);
        if (b.ball && ballSquares[s].empty()) ballSquares[s].assign(f0[s].size(), 0.0);
        for (size_t v = 0; v < n; ++v) {
          if (bound[v] == 0) continue;
          // Slope (f+ - f-) / (a + c) and curvature 2 (c f+ + a f- - (a + c) f0) / (a c (a + c))
          // for steps a up and c down, both times the bound (the curvature's square root).
          const double a = up[v], c = down[v];
          const double slopeScale = bound[v] / (a + c), curvatureScale = 2 * bound[v] * bound[v] / (a * c * (a + c));
          for (size_t i = v * w; i < (v + 1) * w; ++i) {
            const double linear = std::abs(fp[s][i] - fm[s][i]) * slopeScale;
            if (b.ball) ballSquares[s][i] += linear * linear;
            else first[s][i] += linear;
            second[s][i] += std::sqrt(std::abs(c * fp[s][i] + a * fm[s][i] - (a + c) * f0[s][i]) * curvatureScale);
          }
        }
      }
    }
    // A ball: the largest |J . d| over |d| <= r is r |J| (Cauchy-Schwarz).
    if (b.ball)
      for (size_t s = 0; s < first.size(); ++s)
        for (size_t i = 0; i < ballSquares[s].size(); ++i) first[s][i] += std::sqrt(ballSquares[s][i]);
  }
  for (size_t s = 0; s < first.size(); ++s) {
    const auto w = static_cast<size_t>(widths[s]);
    for (size_t i = 0; i < first[s].size(); ++i)
      first[s][i] = unbounded[i / w] ? INFINITY : first[s][i] + second[s][i] * second[s][i];
  }
  out.tolerance = std::move(first);
  return out;
}

}  // namespace sg

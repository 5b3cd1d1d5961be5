#include "validate/float_check.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <optional>
#include <set>

namespace sg {
namespace {

// One bounded input component: per vertex its bound (0: not perturbed), and per reference
// value the first-order change J . bound it can cause, signed (the worst corner's direction).
struct Axis {
  const InputErrorBound* group;
  int component;
  std::vector<double> bound;
  std::vector<std::vector<float>> linear;  // [semantic][value]
};

}  // namespace

FloatReference floatReference(const RuleSet& rules, const RigShape& shape, rt::Mesh& floatMesh,
                              const UniformValues& uniforms, const std::vector<InputErrorBound>& bounds,
                              const std::vector<std::string>& semantics,
                              const std::map<std::string, std::vector<glm::vec4>>& stored) {
  // Compiled once per set of semantics: the perturbations change stream values in place. An
  // input is perturbed only for the semantics that can read it.
  Interpreter reference(rules, shape, floatMesh, uniforms);
  using Evaluator = std::function<std::vector<std::vector<double>>()>;
  std::map<std::vector<size_t>, Evaluator> evaluators;
  auto evaluator = [&](const std::vector<size_t>& which) -> Evaluator& {
    auto it = evaluators.find(which);
    if (it != evaluators.end()) return it->second;
    std::vector<std::string> names;
    for (size_t s : which) names.push_back(semantics[s]);
    return evaluators.emplace(which, reference.evaluator(names)).first->second;
  };
  std::vector<std::optional<std::set<std::string>>> reads;
  for (const auto& s : semantics) reads.push_back(definitionReadsOf(rules, s));
  auto readers = [&](const std::string& stream) {
    const std::string family = stream.substr(0, stream.find('['));
    std::vector<size_t> which;
    for (size_t s = 0; s < semantics.size(); ++s)
      if (!reads[s] || reads[s]->count(family)) which.push_back(s);
    return which;
  };
  std::vector<size_t> all(semantics.size());
  for (size_t s = 0; s < all.size(); ++s) all[s] = s;
  FloatReference out;
  out.values = evaluator(all)();
  const std::vector<std::vector<double>>& f0 = out.values;
  std::vector<size_t> widths;
  for (const auto& s : semantics) widths.push_back(static_cast<size_t>(reference.components(s)));
  const size_t n = floatMesh.vertexCount;
  std::vector<bool> unbounded(n, false);  // an input's bound is infinite (a value its format cannot hold)
  std::map<std::string, std::vector<glm::vec4>> saved;  // the streams as given, restored after each evaluation
  std::vector<Axis> axes;
  for (const InputErrorBound& b : bounds) {
    const std::vector<glm::vec4>& stream = floatMesh.streams.at(b.semantic);
    saved.emplace(b.semantic, stream);
    for (int k = 0; k < (b.ball ? 3 : 4); ++k) {
      Axis a{&b, k, std::vector<double>(n, 0.0), {}};
      bool any = false;
      for (size_t v = 0; v < n && v < b.bound.size() && v < stream.size(); ++v) {
        const double e = b.bound[v][b.ball ? 0 : k];
        if (std::isinf(e)) unbounded[v] = true;
        if (e > 0 && std::isfinite(e) && std::isfinite(stream[v][k])) a.bound[v] = e, any = true;
      }
      if (any) axes.push_back(std::move(a));
    }
  }

  // Each axis alone, both ways: the slope and the curvature along it. Steps of the bound
  // itself (the secant over the range the error can reach), at least 4 float steps so that
  // the float data moves; the steps taken are measured exactly.
  std::vector<std::vector<double>> first, second;
  for (const auto& v : f0) first.emplace_back(v.size(), 0.0), second.emplace_back(v.size(), 0.0);
  std::vector<double> up(n), down(n);
  for (Axis& a : axes) {
    std::vector<glm::vec4>& stream = floatMesh.streams.at(a.group->semantic);
    const std::vector<glm::vec4>& given = saved.at(a.group->semantic);
    const int k = a.component;
    auto step = [&](double sign, std::vector<double>& taken) {
      for (size_t v = 0; v < n; ++v) {
        if (a.bound[v] == 0) continue;
        const float x = given[v][k];
        const double ulp = double(std::nextafter(std::abs(x), INFINITY)) - std::abs(x);
        stream[v][k] = static_cast<float>(x + sign * std::max(a.bound[v], 4 * ulp));
        taken[v] = std::abs(double(stream[v][k]) - x);
      }
    };
    a.linear.resize(f0.size());  // empty for a semantic that cannot read the input: J = 0
    const std::vector<size_t> which = readers(a.group->semantic);
    if (which.empty()) continue;
    step(1, up);
    const auto fp = evaluator(which)();
    step(-1, down);
    const auto fm = evaluator(which)();
    std::copy(given.begin(), given.end(), stream.begin());
    for (size_t j = 0; j < which.size(); ++j) {
      const size_t s = which[j];
      const size_t w = widths[s];
      a.linear[s].assign(f0[s].size(), 0.0f);
      for (size_t v = 0; v < n; ++v) {
        if (a.bound[v] == 0) continue;
        // Slope (f+ - f-) / (u + d) and curvature 2 (d f+ + u f- - (u + d) f0) / (u d (u + d))
        // for steps u up and d down, times the bound (its square for the curvature).
        const double u = up[v], d = down[v];
        const double slopeScale = a.bound[v] / (u + d), curvatureScale = 2 * a.bound[v] * a.bound[v] / (u * d * (u + d));
        for (size_t i = v * w; i < (v + 1) * w; ++i) {
          const double linear = (fp[j][i] - fm[j][i]) * slopeScale;
          a.linear[s][i] = static_cast<float>(linear);
          if (!a.group->ball) first[s][i] += std::abs(linear);
          second[s][i] += std::abs(d * fp[j][i] + u * fm[j][i] - (u + d) * f0[s][i]) * curvatureScale;
        }
      }
    }
  }
  // A direction: the largest |J . e| over |e| <= r is r |J| (Cauchy-Schwarz). Per direction,
  // value i of semantic s (stride w, offset c): |J| r at every vertex.
  auto ballNorms = [&](size_t s, size_t w, size_t c) {
    std::map<const InputErrorBound*, std::vector<double>> norms;
    for (const Axis& a : axes) {
      if (!a.group->ball || a.linear[s].empty()) continue;
      auto& sq = norms[a.group];
      sq.resize(n, 0.0);
      for (size_t v = 0; v < n; ++v) sq[v] += double(a.linear[s][v * w + c]) * double(a.linear[s][v * w + c]);
    }
    for (auto& [g, sq] : norms)
      for (double& x : sq) x = std::sqrt(x);
    return norms;
  };
  for (size_t s = 0; s < f0.size(); ++s)
    for (size_t c = 0; c < widths[s]; ++c)
      for (const auto& [g, norm] : ballNorms(s, widths[s], c))
        for (size_t v = 0; v < n; ++v) first[s][v * widths[s] + c] += norm[v];

  // Every input at once, at the corner of the bounds where the first-order change of one
  // value is largest (each box component at the sign of its slope, each direction along its
  // gradient), both ways: f+ + f- - 2 f0 there is the second-order change along that corner
  // with every cross term (a bilinear skin matrix times position has no curvature along any
  // single axis). One pair of evaluations per component of each semantic.
  std::vector<std::vector<double>> corner;
  for (const auto& v : f0) corner.emplace_back(v.size(), 0.0);
  for (size_t s = 0; s < f0.size() && !axes.empty(); ++s) {
    const size_t w = widths[s];
    for (size_t c = 0; c < w; ++c) {
      const auto norms = ballNorms(s, w, c);
      struct Move {
        std::vector<glm::dvec4> step, slope;  // per vertex: the corner's offset, and d value / d input
      };
      std::map<std::string, Move> moves;
      for (const Axis& a : axes) {
        if (a.linear[s].empty()) continue;
        Move& m = moves[a.group->semantic];
        m.step.resize(n, glm::dvec4(0));
        m.slope.resize(n, glm::dvec4(0));
        for (size_t v = 0; v < n; ++v) {
          if (a.bound[v] == 0) continue;
          const double lin = a.linear[s][v * w + c];
          m.slope[v][a.component] = lin / a.bound[v];
          if (!a.group->ball) {
            m.step[v][a.component] += lin < 0 ? -a.bound[v] : a.bound[v];
          } else if (const double norm = norms.at(a.group)[v]; norm > 0) {
            m.step[v][a.component] += a.bound[v] * lin / norm;
          }
        }
      }
      if (moves.empty()) continue;  // no bounded input reaches this semantic
      // f+ + f- - 2 f0, less the first-order part of the steps' asymmetry (the float data rounds
      // them): J . (up - down).
      std::vector<double> both(n, 0.0);
      for (double sign : {1.0, -1.0}) {
        for (const auto& [sem, m] : moves) {
          std::vector<glm::vec4>& stream = floatMesh.streams.at(sem);
          const std::vector<glm::vec4>& given = saved.at(sem);
          for (size_t v = 0; v < n && v < stream.size(); ++v) {
            stream[v] = glm::vec4(glm::dvec4(given[v]) + sign * m.step[v]);
            both[v] -= glm::dot(m.slope[v], glm::dvec4(stream[v]) - glm::dvec4(given[v]));
          }
        }
        const auto f = evaluator({s})();
        for (size_t v = 0; v < n; ++v) both[v] += f[0][v * w + c];
      }
      for (const auto& [sem, m] : moves) {
        const std::vector<glm::vec4>& given = saved.at(sem);
        std::copy(given.begin(), given.end(), floatMesh.streams.at(sem).begin());
      }
      for (size_t v = 0; v < n; ++v) corner[s][v * w + c] = std::abs(both[v] - 2 * f0[s][v * w + c]);
    }
  }

  // The stored data itself, every bounded input at once, where it lies within its bounds.
  std::vector<std::vector<double>> reached;
  bool anyStored = false;
  for (const InputErrorBound& b : bounds) {
    const auto it = stored.find(b.semantic);
    if (it == stored.end()) continue;
    std::vector<glm::vec4>& stream = floatMesh.streams.at(b.semantic);
    const std::vector<glm::vec4>& given = saved.at(b.semantic);
    for (size_t v = 0; v < n && v < stream.size() && v < it->second.size() && v < b.bound.size(); ++v) {
      const glm::vec4 y = it->second[v];
      if (b.ball) {
        if (glm::length(glm::dvec3(y) - glm::dvec3(given[v])) <= b.bound[v].x)
          stream[v] = glm::vec4(glm::vec3(y), given[v].w), anyStored = true;
      } else {
        for (int k = 0; k < 4; ++k)
          if (b.bound[v][k] > 0 && std::abs(double(y[k]) - double(given[v][k])) <= b.bound[v][k])
            stream[v][k] = y[k], anyStored = true;
      }
    }
  }
  if (anyStored) {
    reached = evaluator(all)();
    for (const auto& [sem, given] : saved) std::copy(given.begin(), given.end(), floatMesh.streams.at(sem).begin());
  }

  out.tolerance = std::move(first);
  for (size_t s = 0; s < f0.size(); ++s) {
    const size_t w = widths[s];
    for (size_t i = 0; i < f0[s].size(); ++i) {
      double t = out.tolerance[s][i] + second[s][i] + corner[s][i];
      if (anyStored && std::isfinite(reached[s][i]) && std::isfinite(f0[s][i])) t = std::max(t, std::abs(reached[s][i] - f0[s][i]));
      out.tolerance[s][i] = unbounded[i / w] ? INFINITY : t;
    }
  }
  return out;
}

}  // namespace sg

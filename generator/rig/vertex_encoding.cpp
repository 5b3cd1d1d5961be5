#include "rig/vertex_encoding.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "common/diagnostics.h"

namespace sg {

const std::vector<VertexEncoding>& vertexEncodings() {
  static const std::vector<VertexEncoding> all = {
      {"vertex.normal_octahedral", "vertex.normal", "octahedral", "deg"},
      {"vertex.tangent_octahedral", "vertex.tangent", "octahedral", "deg"},
  };
  return all;
}

const VertexEncoding* encodingOf(const std::string& encodedSemantic) {
  for (const auto& e : vertexEncodings())
    if (e.encoded == encodedSemantic) return &e;
  return nullptr;
}

namespace {
double signNotZero(double x) { return x >= 0 ? 1.0 : -1.0; }
}  // namespace

glm::dvec2 octahedralEncode(const glm::dvec3& v) {
  const double l1 = std::abs(v.x) + std::abs(v.y) + std::abs(v.z);
  if (!(l1 > 0) || !std::isfinite(l1)) return glm::dvec2(0);
  const glm::dvec3 p = v / l1;
  if (p.z >= 0) return glm::dvec2(p.x, p.y);
  return glm::dvec2((1 - std::abs(p.y)) * signNotZero(p.x), (1 - std::abs(p.x)) * signNotZero(p.y));
}

glm::dvec3 octahedralDecode(const glm::dvec2& e) {
  glm::dvec3 p(e.x, e.y, 1 - std::abs(e.x) - std::abs(e.y));
  if (p.z < 0) p = glm::dvec3((1 - std::abs(e.y)) * signNotZero(e.x), (1 - std::abs(e.x)) * signNotZero(e.y), p.z);
  return glm::normalize(p);
}

std::optional<double> encodingMaxError(const VertexEncoding& e, VertexFormat f) {
  if (e.name != "octahedral") return std::nullopt;
  double perComponent = 0;
  switch (f) {
    case VertexFormat::Snorm8x2: case VertexFormat::Snorm8x4: perComponent = 0.5 / 127; break;
    case VertexFormat::Snorm16x2: case VertexFormat::Snorm16x4: perComponent = 0.5 / 32767; break;
    case VertexFormat::Float16x2: case VertexFormat::Float16x4: perComponent = std::ldexp(1.0, -11); break;
    case VertexFormat::Float32x2: case VertexFormat::Float32x4: perComponent = 0; break;
    default: return std::nullopt;
  }
  perComponent += std::ldexp(1.0, -24);
  return glm::degrees(std::sqrt(18.0) * perComponent);
}

std::string encodingFormats(const VertexEncoding& e) {
  return e.name == "octahedral" ? "snorm8x2/x4, snorm16x2/x4, float16x2/x4, float32x2/x4 (two components)" : "";
}

Rig withinErrorBudgets(const Rig& rig, const std::map<std::string, double>& budgets, std::vector<Diagnostic>& notes) {
  std::string sources;
  for (const auto& e : vertexEncodings())
    if (sources.find(e.source) == std::string::npos) sources += (sources.empty() ? "" : ", ") + e.source;
  for (const auto& budget : budgets) {
    const std::string& semantic = budget.first;  // (Clang 14 cannot capture a structured binding)
    if (std::none_of(vertexEncodings().begin(), vertexEncodings().end(), [&](const auto& e) { return e.source == semantic; }))
      throw InputError(SourceLoc{}, fmt::format("--max-error {}: no encoding stores '{}' (budgets apply to {})", semantic,
                                                semantic, sources));
  }
  std::set<std::string> over;
  for (const RigAttribute& a : rig.attributes)
    for (const auto& p : a.provides) {
      const VertexEncoding* e = encodingOf(p.semantic);
      auto budget = e ? budgets.find(e->source) : budgets.end();
      const std::optional<double> err = e ? encodingMaxError(*e, a.format) : std::nullopt;
      if (budget == budgets.end() || !err || *err <= budget->second) continue;
      over.insert(p.semantic);
      notes.push_back(Diagnostic{Severity::Note, a.loc,
                                 fmt::format("{} (attribute '{}', {}) is not offered to the search: it errs up to {:.3g} {}, "
                                             "over the budget of {:.3g} {} for {} (--max-error)",
                                             p.semantic, a.name, formatName(a.format), *err, e->unit, budget->second,
                                             e->unit, e->source)});
    }
  return withoutProvided(rig, over);
}

const RigAttribute* attributeProviding(const Rig& rig, const std::string& semantic) {
  for (const RigAttribute& a : rig.attributes)
    for (const auto& p : a.provides)
      if (p.semantic == semantic && !a.perMorphTarget) return &a;
  return nullptr;
}

Rig withoutProvided(const Rig& rig, const std::set<std::string>& semantics) {
  Rig out = rig;
  out.attributes.clear();
  for (RigAttribute a : rig.attributes) {
    std::erase_if(a.provides, [&](const ProvidedPart& p) { return semantics.count(p.semantic) != 0; });
    if (!a.provides.empty()) out.attributes.push_back(std::move(a));
  }
  return out;
}

}  // namespace sg

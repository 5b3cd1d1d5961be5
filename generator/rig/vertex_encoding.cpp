#include "rig/vertex_encoding.h"

#include <fmt/format.h>

#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <cmath>
#include <initializer_list>

#include "common/diagnostics.h"

namespace sg {

const std::vector<VertexEncoding>& vertexEncodings() {
  static const std::vector<VertexEncoding> all = {
      {"vertex.normal_octahedral", {"vertex.normal"}, {}, "octahedral", "deg", 2, {}},
      {"vertex.tangent_octahedral", {"vertex.tangent"}, {}, "octahedral", "deg", 2, {}},
      {"vertex.position_in_bounds", {"vertex.position"}, {}, "bounds", "of the bounds diagonal", 3,
       {"mesh.bounds_min", "mesh.bounds_extent"}},
      {"vertex.qtangent", {"vertex.normal", "vertex.tangent"}, {"vertex.handedness"}, "qtangent", "deg", 4, {}},
      {"morph.position_scaled", {"morph.position"}, {}, "scaled", "of the target's scale", 3, {"morph.position_scale"}, true},
  };
  return all;
}

std::vector<std::string> VertexEncoding::decodes() const {
  std::vector<std::string> out = sources;
  out.insert(out.end(), exact.begin(), exact.end());
  return out;
}

std::string VertexEncoding::decodesText() const {
  std::string out;
  for (const std::string& s : decodes()) out += (out.empty() ? "" : ", ") + s;
  return out;
}

const VertexEncoding* encodingOf(const std::string& encodedSemantic) {
  for (const auto& e : vertexEncodings())
    if (e.encoded == encodedSemantic) return &e;
  return nullptr;
}

std::vector<const VertexEncoding*> encodingsOf(const std::string& sourceSemantic) {
  std::vector<const VertexEncoding*> out;
  for (const auto& e : vertexEncodings())
    if (std::find(e.sources.begin(), e.sources.end(), sourceSemantic) != e.sources.end()) out.push_back(&e);
  return out;
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

float deltaScale(const std::vector<glm::vec4>& deltas) {
  double largest = 0;
  for (const glm::vec4& d : deltas)
    for (int k = 0; k < 3; ++k)
      if (std::isfinite(d[k])) largest = std::max(largest, std::abs(double(d[k])));
  float scale = static_cast<float>(largest);
  if (double(scale) < largest) scale = std::nextafter(scale, INFINITY);
  return scale;
}

glm::dvec3 scaledEncode(float scale, const glm::dvec3& delta) {
  glm::dvec3 code(0);
  for (int k = 0; k < 3; ++k)
    if (scale > 0 && std::isfinite(delta[k])) code[k] = std::clamp(delta[k] / scale, -1.0, 1.0);
  return code;
}

glm::dvec3 scaledDecode(float scale, const glm::dvec3& code) { return code * double(scale); }

glm::dvec4 qtangentEncode(const glm::dvec3& normal, const glm::dvec3& tangent, double handedness, double bias) {
  glm::dvec3 n = normal;
  const double nn = glm::dot(n, n);
  n = nn > 0 && std::isfinite(nn) ? n / std::sqrt(nn) : glm::dvec3(0, 0, 1);
  const glm::dvec3 g = tangent - glm::dot(tangent, n) * n;
  glm::dvec3 t;
  if (glm::dot(g, g) > 1e-6 * glm::dot(tangent, tangent)) {  // false for a zero or non-finite tangent
    t = glm::normalize(g);
  } else {  // object.tangent's fallback: Duff et al. 2017
    const double s = n.z >= 0 ? 1.0 : -1.0, a = -1 / (s + n.z);
    t = glm::dvec3(1 + s * n.x * n.x * a, s * n.x * n.y * a, -s * n.x);
  }
  glm::dquat q = glm::normalize(glm::quat_cast(glm::dmat3(t, glm::cross(n, t), n)));
  if ((q.w < 0) != (handedness < 0)) q = -q;  // w carries the handedness
  const double sign = handedness < 0 ? -1.0 : 1.0;
  if (std::abs(q.w) < bias) {  // raise |w| to the bias, xyz scaled to stay a unit quaternion
    const glm::dvec3 v(q.x, q.y, q.z);
    const glm::dvec3 scaled = v * (std::sqrt(1 - bias * bias) / glm::length(v));
    return glm::dvec4(scaled, sign * bias);
  }
  return glm::dvec4(q.x, q.y, q.z, q.w);
}

QTangentFrame qtangentDecode(const glm::dvec4& code) {
  const glm::dvec4 u = glm::normalize(code);
  const glm::dquat q(u.w, u.x, u.y, u.z);
  return QTangentFrame{q * glm::dvec3(0, 0, 1), q * glm::dvec3(1, 0, 0), code.w < 0 ? -1.0 : 1.0};
}

double qtangentBias(VertexFormat f) {
  switch (f) {
    case VertexFormat::Snorm8x4: return 1.0 / 127;
    case VertexFormat::Snorm16x4: return 1.0 / 32767;
    case VertexFormat::Float16x4: return std::ldexp(1.0, -14);
    default: return std::ldexp(1.0, -126);  // float32
  }
}

PositionBounds positionBounds(const std::vector<glm::vec4>& positions) {
  glm::dvec3 lo(INFINITY), hi(-INFINITY);
  for (const glm::vec4& p : positions)
    for (int k = 0; k < 3; ++k)
      if (std::isfinite(p[k])) lo[k] = std::min(lo[k], double(p[k])), hi[k] = std::max(hi[k], double(p[k]));
  PositionBounds b;
  for (int k = 0; k < 3; ++k) {
    if (!(lo[k] <= hi[k])) continue;  // no finite coordinate on this axis
    b.min[k] = static_cast<float>(lo[k]);
    float extent = static_cast<float>(hi[k] - lo[k]);
    while (double(b.min[k]) + double(extent) < hi[k]) extent = std::nextafter(extent, INFINITY);
    b.extent[k] = extent;
  }
  return b;
}

glm::dvec3 boundsEncode(const PositionBounds& b, const glm::dvec3& p) {
  glm::dvec3 code(0);
  for (int k = 0; k < 3; ++k)
    if (b.extent[k] > 0 && std::isfinite(p[k])) code[k] = std::clamp((p[k] - b.min[k]) / b.extent[k], 0.0, 1.0);
  return code;
}

glm::dvec3 boundsDecode(const PositionBounds& b, const glm::dvec3& code) {
  return glm::dvec3(b.min) + code * glm::dvec3(b.extent);
}

namespace {
// How far a code component in [-1, 1] can be from what the device reads of it in f: half a
// step of a normalized format, 2^-12 for float16 (its steps are <= 2^-11 below 1), plus the
// float32 rounding of the code before it is stored (2^-24).
double codeRounding(VertexFormat f) {
  double half = 0;
  switch (f) {
    case VertexFormat::Snorm8x2: case VertexFormat::Snorm8x4: half = 0.5 / 127; break;
    case VertexFormat::Snorm10_10_10_2: half = 0.5 / 511; break;
    case VertexFormat::Snorm16x2: case VertexFormat::Snorm16x4: half = 0.5 / 32767; break;
    case VertexFormat::Unorm8x2: case VertexFormat::Unorm8x4: half = 0.5 / 255; break;
    case VertexFormat::Unorm10_10_10_2: half = 0.5 / 1023; break;
    case VertexFormat::Unorm16x2: case VertexFormat::Unorm16x4: half = 0.5 / 65535; break;
    case VertexFormat::Float16x2: case VertexFormat::Float16x4: half = std::ldexp(1.0, -12); break;
    default: break;  // float32: the code itself
  }
  return half + std::ldexp(1.0, -24);
}

bool oneOf(VertexFormat f, std::initializer_list<VertexFormat> formats) {
  return std::find(formats.begin(), formats.end(), f) != formats.end();
}
}  // namespace

std::optional<double> encodingMaxError(const VertexEncoding& e, VertexFormat f) {
  using F = VertexFormat;
  if (e.name == "bounds") {  // codes in [0, 1]
    if (!oneOf(f, {F::Unorm8x4, F::Unorm10_10_10_2, F::Unorm16x4, F::Float16x4, F::Float32x3, F::Float32x4})) return std::nullopt;
    return codeRounding(f);
  }
  if (e.name == "scaled") {
    if (!oneOf(f, {F::Snorm8x4, F::Snorm10_10_10_2, F::Snorm16x4, F::Float16x4, F::Float32x3, F::Float32x4})) return std::nullopt;
    return std::sqrt(3.0) * codeRounding(f);
  }
  if (e.name == "qtangent") {
    if (!oneOf(f, {F::Snorm8x4, F::Snorm16x4, F::Float16x4, F::Float32x4})) return std::nullopt;
    const double err = codeRounding(f), b = qtangentBias(f);
    const double c = std::max(2 * err, std::hypot(std::sqrt(3.0) * err + b * b, b));  // see the header
    return glm::degrees(2 * std::asin(c));
  }
  if (e.name != "octahedral") return std::nullopt;
  if (!oneOf(f, {F::Snorm8x2, F::Snorm8x4, F::Snorm16x2, F::Snorm16x4, F::Float16x2, F::Float16x4, F::Float32x2,
                 F::Float32x4}))
    return std::nullopt;
  // float16 as first stated, a whole step (half of one, codeRounding, would do too)
  const bool float16 = f == F::Float16x2 || f == F::Float16x4;
  return glm::degrees(std::sqrt(18.0) * (float16 ? std::ldexp(1.0, -11) + std::ldexp(1.0, -24) : codeRounding(f)));
}

std::string encodingFormats(const VertexEncoding& e) {
  std::string names;  // the formats encodingMaxError knows, so the two never disagree
  for (int i = 0; i < kVertexFormatCount; ++i)
    if (const auto f = static_cast<VertexFormat>(i); encodingMaxError(e, f))
      names += (names.empty() ? "" : ", ") + std::string(formatName(f));
  return fmt::format("{} ({} components)", names, e.components);
}

namespace {
std::string noEncodingStores(const std::string& semantic) {
  std::string sources;
  for (const auto& e : vertexEncodings())
    for (const std::string& s : e.sources)
      if (sources.find(s) == std::string::npos) sources += (sources.empty() ? "" : ", ") + s;
  return fmt::format("no encoding stores '{}' (budgets apply to {})", semantic, sources);
}
}  // namespace

std::optional<double> parseErrorBudget(const std::string& semantic, const std::string& text, std::string& why) {
  const auto encodings = encodingsOf(semantic);
  if (encodings.empty()) {
    why = noEncodingStores(semantic);
    return std::nullopt;
  }
  const bool angle = encodings.front()->angular();
  const bool deg = text.size() > 3 && text.compare(text.size() - 3, 3, "deg") == 0;
  const bool rad = text.size() > 3 && text.compare(text.size() - 3, 3, "rad") == 0;
  const std::string number = deg || rad ? text.substr(0, text.size() - 3) : text;
  double value = -1;
  size_t used = 0;
  try {
    value = std::stod(number, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  const std::string expected = angle ? fmt::format("a positive angle in deg or rad ({}=0.1deg)", semantic)
                                     : fmt::format("a positive fraction {} ({}=1e-4)", encodings.front()->unit, semantic);
  if (number.empty() || used != number.size() || !std::isfinite(value) || value <= 0 || (angle != (deg || rad))) {
    why = fmt::format("expected {}, got '{}'", expected, text);
    return std::nullopt;
  }
  return rad ? glm::degrees(value) : value;
}

Rig withinErrorBudgets(const Rig& rig, const std::map<std::string, double>& budgets, std::vector<Diagnostic>& notes) {
  for (const auto& budget : budgets) {
    if (encodingsOf(budget.first).empty())
      throw InputError(SourceLoc{}, fmt::format("--max-error {}: {}", budget.first, noEncodingStores(budget.first)));
  }
  std::set<std::string> over;
  for (const RigAttribute& a : rig.attributes)
    for (const auto& p : a.provides) {
      const VertexEncoding* e = encodingOf(p.semantic);
      const std::optional<double> err = e ? encodingMaxError(*e, partFormat(a, p)) : std::nullopt;
      if (!err) continue;
      for (const std::string& source : e->sources) {  // the first budget it breaks removes it
        auto budget = budgets.find(source);
        if (budget == budgets.end() || *err <= budget->second) continue;
        over.insert(p.semantic);
        const std::string why = fmt::format("{} (attribute '{}', {}) is not offered to the search: it errs up to {:.3g} {}, "
                                            "over the budget of {:.3g} {} for {} (--max-error)",
                                            p.semantic, a.name, formatName(partFormat(a, p)), *err, e->unit, budget->second,
                                            e->unit, source);
        // Without its deltas a morph target would silently stop moving the value (the
        // unmorphed rules apply): no plan meets the budget, unless the rig stores them plainly too.
        if (e->perTarget && !std::any_of(rig.attributes.begin(), rig.attributes.end(), [&](const RigAttribute& b) {
              return b.perMorphTarget && std::any_of(b.provides.begin(), b.provides.end(),
                                                     [&](const ProvidedPart& q) { return q.semantic == source; });
            }))
          throw InputError(a.loc, why + fmt::format("; the rig stores no other {} deltas, and its morph targets must move it",
                                                    source));
        notes.push_back(Diagnostic{Severity::Note, a.loc, why});
        break;
      }
    }
  Rig out = withoutProvided(rig, over);
  for (const std::string& s : over) out.withheld[s] = "over the --max-error budget";
  return out;
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

#include "validate/poses.h"

#include <fmt/format.h>

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <random>
#include <set>

#include "common/input_file.h"
#include "common/yaml_util.h"

namespace sg {
namespace {

const std::set<std::string>& standardUniforms() {
  static const std::set<std::string> names = {"skin.bones",   "morph.weights",          "camera.position",
                                              "camera.view",  "camera.projection",      "camera.view_projection",
                                              "model.matrix", "dapple.matrix",
                                              // derived from morph.weights (docs/buffers.md)
                                              "morph.active_targets", "morph.active_count",
                                              // derived from the mesh (rig/vertex_encoding.h)
                                              "mesh.bounds_min", "mesh.bounds_extent", "morph.position_scale"};
  return names;
}

// A deterministic draw: std::mt19937's raw output is fixed by the standard; the mapping to
// floats is done here (library distributions differ between standard libraries).
struct Rng {
  std::mt19937 engine;
  explicit Rng(uint32_t seed) : engine(seed) {}
  double unit() { return static_cast<double>(engine() >> 8) * (1.0 / 16777216.0); }
  double uniform(double lo, double hi) { return lo + (hi - lo) * unit(); }
  glm::dvec3 unitVector() {
    for (;;) {
      glm::dvec3 v(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1));
      double l = glm::length(v);
      if (l > 0.1 && l <= 1.0) return v / l;
    }
  }
};

uint32_t seedOf(const std::string& name, size_t pose) {
  uint32_t h = 2166136261u;
  for (char c : name) h = (h ^ static_cast<uint8_t>(c)) * 16777619u;
  return h ^ static_cast<uint32_t>(pose * 0x9E3779B9u);
}

// One element of a uniform of `kind`, as float values (what the GPU gets).
std::vector<double> drawElement(const SemanticDecl& d, Rng& rng) {
  const std::string& kind = d.kind;
  const int n = componentCount(d.type);
  std::vector<double> out;
  auto matrix = [&](const glm::mat4& m) {
    int dim = d.type == Type::Mat3 ? 3 : 4;
    for (int c = 0; c < dim; ++c)
      for (int r = 0; r < dim; ++r) out.push_back(m[c][r]);
  };
  if (kind == "rigid" || kind == "affine" || kind == "projection") {
    if (!isMatrix(d.type)) throw InputError(d.kindLoc, fmt::format("kind '{}' needs a mat3 or mat4 semantic", kind));
    glm::mat4 m(1.0f);
    if (kind == "projection") {
      float fov = static_cast<float>(rng.uniform(0.5, 1.6)), aspect = static_cast<float>(rng.uniform(0.5, 2.0));
      float zn = static_cast<float>(rng.uniform(0.1, 1.0)), zf = static_cast<float>(rng.uniform(10.0, 100.0));
      m = glm::perspectiveRH_ZO(fov, aspect, zn, zf);
      m[1][1] = -m[1][1];  // Vulkan's y points down
      // Seen from 3..5 units away, looking at the origin (where the meshes are): usable as
      // a view-projection too, with w well away from 0 (the perspective divide stays
      // well-conditioned).
      glm::vec3 eye(rng.unitVector() * rng.uniform(3.0, 5.0));
      glm::vec3 up = std::abs(eye.y) > 0.9f * glm::length(eye) ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
      m = m * glm::lookAt(eye, glm::vec3(0.0f), up);
    } else {
      glm::vec3 axis(rng.unitVector());
      float angle = static_cast<float>(rng.uniform(-3.14159, 3.14159));
      glm::vec3 t(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
      m = glm::translate(glm::mat4(1.0f), t) * glm::rotate(glm::mat4(1.0f), angle, axis);
      if (kind == "affine")
        m = m * glm::scale(glm::mat4(1.0f), glm::vec3(rng.uniform(0.25, 2.5), rng.uniform(0.25, 2.5), rng.uniform(0.25, 2.5)));
    }
    matrix(m);
    return out;
  }
  if (isMatrix(d.type)) throw InputError(d.kindLoc, fmt::format("kind '{}' does not apply to a matrix (rigid, affine, projection)", kind));
  if (kind == "unit") {
    glm::dvec4 v;
    double l = 0;
    while (l < 0.1) {
      v = glm::dvec4(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
      for (int c = n; c < 4; ++c) v[c] = 0;
      l = glm::length(v);
    }
    for (int c = 0; c < n; ++c) out.push_back(static_cast<float>(v[c] / l));
    return out;
  }
  double lo = kind == "point" ? -2.0 : d.rangeLo, hi = kind == "point" ? 2.0 : d.rangeHi;
  for (int c = 0; c < n; ++c) {
    double x = rng.uniform(lo, hi);
    out.push_back(kind == "int" ? std::floor(rng.uniform(lo, hi + 1 - 1e-9)) : static_cast<double>(static_cast<float>(x)));
  }
  return out;
}

void pushMat(std::vector<double>& out, const glm::mat4& m) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) out.push_back(m[c][r]);
}

// The value of a uniform rt::Pose holds in a named field, `arraySize` elements at least for
// an array; nullopt for any other semantic.
std::optional<std::vector<double>> poseField(const std::string& s, const rt::Pose& pose, int arraySize) {
  std::vector<double> v;
  if (s == "skin.bones") {
    for (const auto& b : pose.bones) pushMat(v, b);
  } else if (s == "morph.weights") {
    for (int i = 0; i < std::max(arraySize, static_cast<int>(pose.morphWeights.size())); ++i)
      v.push_back(i < static_cast<int>(pose.morphWeights.size()) ? pose.morphWeights[static_cast<size_t>(i)] : 0.0);
  } else if (s == "camera.position") {
    v = {pose.cameraPosition.x, pose.cameraPosition.y, pose.cameraPosition.z};
  } else if (s == "camera.view") {
    pushMat(v, pose.view);
  } else if (s == "camera.projection") {
    pushMat(v, pose.projection);
  } else if (s == "camera.view_projection") {
    pushMat(v, pose.viewProjection());
  } else if (s == "model.matrix") {
    pushMat(v, pose.model);
  } else if (s == "dapple.matrix") {
    pushMat(v, pose.dapple);
  } else {
    return std::nullopt;
  }
  return v;
}

}  // namespace

bool isStandardUniform(const std::string& semantic) { return standardUniforms().count(semantic) != 0; }

void drawDeclaredUniforms(std::vector<rt::Pose>& poses, const Rig& rig, const RuleSet& rules) {
  for (size_t p = 0; p < poses.size(); ++p)
    for (const auto& u : rig.uniforms) {
      if (isStandardUniform(u.semantic) || poses[p].uniforms.count(u.semantic)) continue;
      const SemanticDecl* d = rules.findSemantic(u.semantic);
      if (d && d->definition) continue;  // computed from the other uniforms in each pose
      if (!d || d->kind.empty())
        throw InputError(u.loc, fmt::format("validation has no value for uniform semantic '{}': declare its 'kind' "
                                            "(rigid, affine, projection, unit, point, weight, int) or a 'definition'",
                                            u.semantic));
      Rng rng(seedOf(u.semantic, p));
      std::vector<double> v;
      for (int i = 0; i < std::max(1, u.arraySize); ++i) {
        auto e = drawElement(*d, rng);
        v.insert(v.end(), e.begin(), e.end());
      }
      poses[p].uniforms[u.semantic] = std::move(v);
    }
}

UniformValues poseUniforms(const Rig& rig, const rt::Pose& pose) {
  UniformValues u = pose.uniforms;
  for (const auto& ru : rig.uniforms)
    if (auto v = poseField(ru.semantic, pose, ru.arraySize)) u[ru.semantic] = std::move(*v);
  return u;
}

UniformValues definitionInputs(const Rig& rig, const RuleSet& rules, const rt::Pose& pose) {
  UniformValues out;
  for (const auto& ru : rig.uniforms) {
    const SemanticDecl* d = rules.findSemantic(ru.semantic);
    if (!d || !d->definition) continue;
    const std::set<std::string> reads = *definitionReadsOf(rules, ru.semantic);
    for (const std::string& s : reads) {
      const bool declared = std::any_of(rig.uniforms.begin(), rig.uniforms.end(), [&](const RigUniform& u) { return u.semantic == s; });
      if (declared || rules.findSemantic(s)->definition) continue;
      if (auto v = poseField(s, pose, 0)) out[s] = std::move(*v);
    }
  }
  return out;
}

std::string formatPoseFile(const std::vector<rt::Pose>& poses) {
  auto list = [](auto begin, auto end) {
    std::string s = "[";
    for (auto it = begin; it != end; ++it) s += fmt::format("{}{}", it == begin ? "" : ", ", *it);
    return s + "]";
  };
  auto mat = [&](const glm::mat4& m) { return list(&m[0][0], &m[0][0] + 16); };
  std::string s = "# shadergen validate poses (docs/validation.md): replay with validate --poses FILE\nposes:\n";
  for (const auto& p : poses) {
    s += "  - bones:";
    if (p.bones.empty()) s += " []";
    s += "\n";
    for (const auto& b : p.bones) s += "      - " + mat(b) + "\n";
    s += "    morph_weights: " + list(p.morphWeights.begin(), p.morphWeights.end()) + "\n";
    s += "    camera_position: " + list(&p.cameraPosition[0], &p.cameraPosition[0] + 3) + "\n";
    s += "    view: " + mat(p.view) + "\n";
    s += "    projection: " + mat(p.projection) + "\n";
    s += "    model: " + mat(p.model) + "\n";
    s += "    dapple: " + mat(p.dapple) + "\n";
    if (!p.uniforms.empty()) {
      s += "    uniforms:\n";
      for (const auto& [name, v] : p.uniforms) s += fmt::format("      {}: {}\n", name, list(v.begin(), v.end()));
    }
  }
  return s;
}

std::vector<rt::Pose> parsePoseFile(const std::string& text, const std::string& fileName) {
  YamlCtx y{fileName};
  YAML::Node root = parseYaml(text, fileName);
  if (!root.IsDefined() || root.IsNull()) throw InputError(SourceLoc{fileName, 1, 1}, "empty pose file");
  y.expectMap(root, "a pose file");
  y.checkKeys(root, {"poses"});
  if (!root["poses"]) y.fail(root, "missing 'poses'");
  YAML::Node list = root["poses"];
  y.expectSeq(list, "'poses'");
  if (list.size() == 0) y.fail(list, "'poses' is empty");
  auto number = [&](const YAML::Node& n) {
    std::string s = y.scalar(n, "a number");
    char* end = nullptr;
    double v = std::strtod(s.c_str(), &end);
    if (s.empty() || end != s.c_str() + s.size() || !std::isfinite(v)) y.fail(n, fmt::format("'{}' is not a finite number", s));
    return v;
  };
  auto floats = [&](const YAML::Node& n, size_t count, const char* what) {
    y.expectSeq(n, what);
    if (count && n.size() != count) y.fail(n, fmt::format("{} has {} numbers, not {}", what, n.size(), count));
    std::vector<double> v;
    for (const auto& x : n) v.push_back(number(x));
    return v;
  };
  auto toFloat = [&](const YAML::Node& n, double v) {
    if (std::abs(v) > 3.4e38) y.fail(n, "number out of the range of a float");
    return static_cast<float>(v);
  };
  auto mat = [&](const YAML::Node& n, const char* what) {
    auto v = floats(n, 16, what);
    glm::mat4 m;
    for (int i = 0; i < 16; ++i) (&m[0][0])[i] = toFloat(n, v[static_cast<size_t>(i)]);
    return m;
  };
  std::vector<rt::Pose> poses;
  for (const auto& pn : list) {
    y.expectMap(pn, "a pose");
    y.checkKeys(pn, {"bones", "morph_weights", "camera_position", "view", "projection", "model", "dapple", "uniforms"});
    rt::Pose p;
    if (pn["bones"]) {
      y.expectSeq(pn["bones"], "'bones'");
      for (const auto& b : pn["bones"]) p.bones.push_back(mat(b, "a bone matrix"));
    }
    if (pn["morph_weights"])
      for (double w : floats(pn["morph_weights"], 0, "'morph_weights'")) p.morphWeights.push_back(toFloat(pn["morph_weights"], w));
    if (pn["camera_position"]) {
      auto v = floats(pn["camera_position"], 3, "'camera_position'");
      p.cameraPosition = glm::vec3(toFloat(pn, v[0]), toFloat(pn, v[1]), toFloat(pn, v[2]));
    }
    if (pn["view"]) p.view = mat(pn["view"], "'view'");
    if (pn["projection"]) p.projection = mat(pn["projection"], "'projection'");
    if (pn["model"]) p.model = mat(pn["model"], "'model'");
    if (pn["dapple"]) p.dapple = mat(pn["dapple"], "'dapple'");
    if (auto u = pn["uniforms"]) {
      y.expectMap(u, "'uniforms'");
      for (auto it = u.begin(); it != u.end(); ++it)
        p.uniforms[y.scalar(it->first, "a semantic name")] = floats(it->second, 0, "a uniform value");
    }
    poses.push_back(std::move(p));
  }
  return poses;
}

std::vector<rt::Pose> readPoseFile(const std::string& path) { return parsePoseFile(readInputFile(path), path); }

}  // namespace sg

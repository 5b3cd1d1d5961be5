// The GLM reference of docs/semantics.md. Each computed semantic below is the formula of its
// row in that table, evaluated in double precision; nothing here is derived from rules/ or
// templates/. Intermediate per-vertex arrays are cached in ReferenceEvaluator::State.
#include "runtime/reference.h"

#include <glm/glm.hpp>

#include <cctype>
#include <cmath>
#include <cstddef>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace sg::rt {
namespace {

using glm::dmat3;
using glm::dmat4;
using glm::dvec3;
using glm::dvec4;

// Computed semantics (docs/semantics.md, "Computed") and their component counts.
const std::map<std::string, int>& computedSemantics() {
  static const std::map<std::string, int> table = {
      {"object.position", 3},     {"object.normal", 3},
      {"object.occlusion", 1},    {"object.tangent", 3},
      {"world.position", 3},      {"world.normal", 3},
      {"world.tangent", 3},       {"world.handedness", 1},
      {"world.binormal", 3},      {"frame.row_x", 3},
      {"frame.row_y", 3},         {"frame.row_z", 3},
      {"world.eye_dir", 3},       {"eye.position", 4},
      {"eye.normal", 3},          {"view.ndotv", 1},
      {"view.one_minus_ndotv", 1}, {"view.one_minus_ndotv_sq", 1},
      {"dapple.normal_z", 1},     {"clip.position", 4},
      {"eye.to_camera", 3},       {"eye.tangent", 3},
      {"eye.binormal", 3},
      {"camera.position", 3},
  };
  return table;
}

// Semantics of the vocabulary that are not per-vertex vectors.
const std::set<std::string>& nonVectorSemantics() {
  static const std::set<std::string> names = {
      "skin.matrix",       "skin.bones",   "morph.weights", "camera.view", "camera.projection",
      "camera.view_projection", "model.matrix", "dapple.matrix",
  };
  return names;
}

bool isIdentifier(const std::string& s) {
  if (s.empty() || !(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
  for (char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) return false;
  return true;
}

bool isDigits(const std::string& s) {
  if (s.empty()) return false;
  for (char c : s)
    if (!std::isdigit(static_cast<unsigned char>(c))) return false;
  return true;
}

// "morph.position[3]" with prefix "morph.position" -> true.
bool isIndexed(const std::string& s, const std::string& prefix) {
  if (s.size() < prefix.size() + 3 || s.compare(0, prefix.size(), prefix) != 0) return false;
  if (s[prefix.size()] != '[' || s.back() != ']') return false;
  return isDigits(s.substr(prefix.size() + 1, s.size() - prefix.size() - 2));
}

bool hasDigitSuffix(const std::string& s, const std::string& prefix) {
  return s.size() > prefix.size() && s.compare(0, prefix.size(), prefix) == 0 &&
         isDigits(s.substr(prefix.size()));
}

// Component count of a rig-provided per-vertex stream name, if it is one.
std::optional<int> streamComponents(const std::string& s) {
  static const std::map<std::string, int> vertexTable = {
      {"vertex.position", 3}, {"vertex.normal", 3},     {"vertex.occlusion", 1},
      {"vertex.tangent", 3},  {"vertex.handedness", 1}, {"vertex.binormal", 3},
  };
  if (auto it = vertexTable.find(s); it != vertexTable.end()) return it->second;
  if (hasDigitSuffix(s, "vertex.texcoord")) return 2;
  if (hasDigitSuffix(s, "vertex.color")) return 4;
  if (s.rfind("vertex.", 0) == 0 && isIdentifier(s.substr(7))) return 4;  // unknown attribute
  if (isIndexed(s, "morph.position") || isIndexed(s, "morph.normal") ||
      isIndexed(s, "morph.tangent"))
    return 3;
  if (isIndexed(s, "morph.occlusion")) return 1;
  if (isIndexed(s, "skin.joints") || isIndexed(s, "skin.weights")) return 4;
  return std::nullopt;
}

std::optional<int> componentsOf(const std::string& s) {
  if (auto it = computedSemantics().find(s); it != computedSemantics().end()) return it->second;
  if (auto c = streamComponents(s)) return c;
  if (s.rfind("out.", 0) == 0) return streamComponents("vertex." + s.substr(4));
  return std::nullopt;
}

glm::vec4 toVec4(const dvec3& v) {
  return glm::vec4(static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z), 0.0f);
}
glm::vec4 toVec4(const dvec4& v) { return glm::vec4(v); }
glm::vec4 toVec4(double s) { return glm::vec4(static_cast<float>(s), 0.0f, 0.0f, 0.0f); }

dvec3 xyz(const glm::vec4& v) { return dvec3(v.x, v.y, v.z); }

}  // namespace

struct ReferenceEvaluator::State {
  const Mesh& mesh;
  const Pose& pose;
  RigShape shape;
  size_t n;
  std::string requested;  // the semantic being evaluated, for error messages

  std::optional<std::vector<dvec3>> objPos, objNormal, objTangent;
  std::optional<std::vector<double>> objOcc;
  std::optional<std::vector<dvec3>> worldPos, worldNormal, worldTangent;
  bool skinReady = false;  // prepareSkinning() done
  dmat4 skinUniform{1.0};  // K = 0
  std::vector<dmat4> skinBones;
  std::vector<const std::vector<glm::vec4>*> skinJoints, skinWeights;

  State(const Mesh& m, const Pose& p, const RigShape& s)
      : mesh(m), pose(p), shape(s), n(m.vertexCount) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw std::invalid_argument(requested + ": " + what);
  }

  const std::vector<glm::vec4>& stream(const std::string& name) const {
    auto it = mesh.streams.find(name);
    if (it == mesh.streams.end())
      throw std::invalid_argument(requested + " needs " + name + ", which mesh '" + mesh.name +
                                  "' does not have");
    if (it->second.size() != n)
      fail("stream " + name + " of mesh '" + mesh.name + "' has " +
           std::to_string(it->second.size()) + " values, but the mesh has " + std::to_string(n) +
           " vertices");
    return it->second;
  }

  // (w_i, stream) for the targets i < shape.morphTargets whose `prefix[i]` stream exists.
  std::vector<std::pair<double, const std::vector<glm::vec4>*>> morphTerms(
      const std::string& prefix) const {
    std::vector<std::pair<double, const std::vector<glm::vec4>*>> terms;
    for (int i = 0; i < shape.morphTargets; ++i) {
      std::string name = prefix + "[" + std::to_string(i) + "]";
      if (!mesh.has(name)) continue;
      if (static_cast<size_t>(i) >= pose.morphWeights.size())
        throw std::invalid_argument(requested + " needs morph.weights[" + std::to_string(i) +
                                    "], which the pose does not have (it has " +
                                    std::to_string(pose.morphWeights.size()) + " weights)");
      terms.emplace_back(static_cast<double>(pose.morphWeights[static_cast<size_t>(i)]),
                         &stream(name));
    }
    return terms;
  }

  // object.position = vertex.position + Σ_i w_i·morph.position[i]
  const std::vector<dvec3>& objectPosition() {
    if (objPos) return *objPos;
    const auto& base = stream("vertex.position");
    auto terms = morphTerms("morph.position");
    std::vector<dvec3> out(n);
    for (size_t v = 0; v < n; ++v) {
      dvec3 p = xyz(base[v]);
      for (const auto& [w, s] : terms) p += w * xyz((*s)[v]);
      out[v] = p;
    }
    objPos = std::move(out);
    return *objPos;
  }

  // object.normal = normalize(vertex.normal + Σ_i w_i·morph.normal[i])
  const std::vector<dvec3>& objectNormal() {
    if (objNormal) return *objNormal;
    const auto& base = stream("vertex.normal");
    auto terms = morphTerms("morph.normal");
    std::vector<dvec3> out(n);
    for (size_t v = 0; v < n; ++v) {
      dvec3 nrm = xyz(base[v]);
      for (const auto& [w, s] : terms) nrm += w * xyz((*s)[v]);
      out[v] = glm::normalize(nrm);
    }
    objNormal = std::move(out);
    return *objNormal;
  }

  // object.occlusion = vertex.occlusion + Σ_i w_i·morph.occlusion[i]
  const std::vector<double>& objectOcclusion() {
    if (objOcc) return *objOcc;
    const auto& base = stream("vertex.occlusion");
    auto terms = morphTerms("morph.occlusion");
    std::vector<double> out(n);
    for (size_t v = 0; v < n; ++v) {
      double o = base[v].x;
      for (const auto& [w, s] : terms) o += w * static_cast<double>((*s)[v].x);
      out[v] = o;
    }
    objOcc = std::move(out);
    return *objOcc;
  }

  // normalize(t − dot(t, N)·N) for a unit normal N; degenerate (|g|² <= 1e-6·|t|²): the
  // tangent of the orthonormal basis of N (Duff et al. 2017)
  static dvec3 orthonormalTangent(const dvec3& t, const dvec3& N) {
    const dvec3 g = t - glm::dot(t, N) * N;
    if (glm::dot(g, g) > 1e-6 * glm::dot(t, t)) return glm::normalize(g);
    const double s = N.z >= 0.0 ? 1.0 : -1.0, a = -1.0 / (s + N.z);
    return dvec3(1.0 + s * N.x * N.x * a, s * N.x * N.y * a, -s * N.x);
  }

  // object.tangent = normalize(t − dot(t, N)·N), t = vertex.tangent + Σ_i w_i·morph.tangent[i],
  // N = object.normal; degenerate (|g|² <= 1e-6·|t|²): the orthonormal basis of N
  const std::vector<dvec3>& objectTangent() {
    if (objTangent) return *objTangent;
    const auto& base = stream("vertex.tangent");
    auto terms = morphTerms("morph.tangent");
    const auto& normals = objectNormal();
    std::vector<dvec3> out(n);
    for (size_t v = 0; v < n; ++v) {
      dvec3 t = xyz(base[v]);
      for (const auto& [w, s] : terms) t += w * xyz((*s)[v]);
      out[v] = orthonormalTangent(t, normals[v]);
    }
    objTangent = std::move(out);
    return *objTangent;
  }

  // skin.matrix: M = Σ_{k<K} weight_k·B_{joint_k}; K = 1: B_{joint_0}; K = 0: model.matrix if
  // provided, else identity. Influence k lives in skin.joints[k/4][k%4], skin.weights[k/4][k%4].
  // The streams are resolved and every joint index checked once; M itself is recomputed per
  // vertex by skinAt (cheaper than storing 128 bytes per vertex).
  void prepareSkinning() {
    if (skinReady) return;
    const int K = shape.influences;
    if (K < 0) fail("rig has a negative influence count (" + std::to_string(K) + ")");
    skinJoints.clear();
    skinWeights.clear();
    if (K == 0) {
      skinUniform = shape.hasModelMatrix ? dmat4(pose.model) : dmat4(1.0);
      skinReady = true;
      return;
    }
    const int sets = (K + 3) / 4;
    for (int s = 0; s < sets; ++s) {
      skinJoints.push_back(&stream("skin.joints[" + std::to_string(s) + "]"));
      if (K > 1) skinWeights.push_back(&stream("skin.weights[" + std::to_string(s) + "]"));
    }
    if (pose.bones.empty())
      throw std::invalid_argument(requested + " needs skin.bones, which the pose does not have");
    skinBones.assign(pose.bones.begin(), pose.bones.end());
    const double boneCount = static_cast<double>(skinBones.size());
    for (size_t v = 0; v < n; ++v) {
      for (int k = 0; k < K; ++k) {
        const float j = (*skinJoints[static_cast<size_t>(k / 4)])[v][k % 4];
        if (!(j >= 0.0f) || j != std::floor(j) || static_cast<double>(j) >= boneCount)
          fail("skin.joints[" + std::to_string(k / 4) + "] of mesh '" + mesh.name +
               "' has joint index " + std::to_string(j) + " at vertex " + std::to_string(v) +
               " (component " + std::to_string(k % 4) + "), but the pose has " +
               std::to_string(skinBones.size()) + " bones");
      }
    }
    skinReady = true;
  }

  dmat4 skinAt(size_t v) const {
    const int K = shape.influences;
    if (K == 0) return skinUniform;
    auto joint = [&](int k) -> const dmat4& {
      return skinBones[static_cast<size_t>((*skinJoints[static_cast<size_t>(k / 4)])[v][k % 4])];
    };
    if (K == 1) return joint(0);
    dmat4 M(0.0);
    for (int k = 0; k < K; ++k)
      M += static_cast<double>((*skinWeights[static_cast<size_t>(k / 4)])[v][k % 4]) * joint(k);
    return M;
  }

  // world.position = (M·vec4(object.position, 1)).xyz
  const std::vector<dvec3>& worldPosition() {
    if (worldPos) return *worldPos;
    const auto& p = objectPosition();
    prepareSkinning();
    std::vector<dvec3> out(n);
    for (size_t v = 0; v < n; ++v) out[v] = dvec3(skinAt(v) * dvec4(p[v], 1.0));
    worldPos = std::move(out);
    return *worldPos;
  }

  // world.normal = normalize(transpose(inverse(mat3(M)))·object.normal); a rig declaring
  // uniform_scale: normalize(mat3(M)·object.normal)
  const std::vector<dvec3>& worldNormalValues() {
    if (worldNormal) return *worldNormal;
    const auto& N = objectNormal();
    prepareSkinning();
    std::vector<dvec3> out(n);
    for (size_t v = 0; v < n; ++v) {
      const dmat3 M3(skinAt(v));
      out[v] = glm::normalize((shape.uniformScale ? M3 : glm::transpose(glm::inverse(M3))) * N[v]);
    }
    worldNormal = std::move(out);
    return *worldNormal;
  }

  // world.tangent = normalize(mat3(M)·object.tangent)
  const std::vector<dvec3>& worldTangentValues() {
    if (worldTangent) return *worldTangent;
    const auto& T = objectTangent();
    prepareSkinning();
    std::vector<dvec3> out(n);
    for (size_t v = 0; v < n; ++v) out[v] = glm::normalize(dmat3(skinAt(v)) * T[v]);
    worldTangent = std::move(out);
    return *worldTangent;
  }

  // world.handedness = vertex.handedness; without it, the side of a stored binormal B of the
  // bind-pose frame: sign(dot(cross(N, T), B)), N = normalize(vertex.normal), T = the tangent
  // orthonormalised against N as object.tangent is (defined where vertex.tangent ∥ N).
  const std::vector<glm::vec4>& handedness() {
    if (mesh.has("vertex.handedness") || !mesh.has("vertex.binormal")) return stream("vertex.handedness");
    if (derivedHandedness.empty()) {
      const auto& N = stream("vertex.normal");
      const auto& T = stream("vertex.tangent");
      const auto& B = stream("vertex.binormal");
      derivedHandedness.resize(n);
      for (size_t v = 0; v < n; ++v) {
        const dvec3 normal = glm::normalize(xyz(N[v]));
        const dvec3 frameTangent = orthonormalTangent(xyz(T[v]), normal);
        derivedHandedness[v].x = glm::dot(glm::cross(normal, frameTangent), xyz(B[v])) < 0.0 ? -1.0f : 1.0f;
      }
    }
    return derivedHandedness;
  }
  std::vector<glm::vec4> derivedHandedness;

  // world.binormal = world.handedness · normalize(cross(world.normal, world.tangent))
  dvec3 binormal(size_t v, const std::vector<dvec3>& N, const std::vector<dvec3>& T,
                 const std::vector<glm::vec4>& h) const {
    return static_cast<double>(h[v].x) * glm::normalize(glm::cross(N[v], T[v]));
  }

  // world.eye_dir = normalize(world.position − camera.position)
  dvec3 eyeDir(const dvec3& worldPosition) const {
    return glm::normalize(worldPosition - dvec3(pose.cameraPosition));
  }

  std::vector<glm::vec4> evaluate(const std::string& sem);
};

std::vector<glm::vec4> ReferenceEvaluator::State::evaluate(const std::string& sem) {
  requested = sem;
  auto fill = [&](auto&& f) {
    std::vector<glm::vec4> out;
    out.reserve(n);
    for (size_t v = 0; v < n; ++v) out.push_back(toVec4(f(v)));
    return out;
  };

  if (nonVectorSemantics().count(sem))
    throw std::invalid_argument(sem +
                                ": is not a per-vertex vector (mat4 or array semantic); the "
                                "reference does not evaluate it");
  if (!componentsOf(sem)) throw std::invalid_argument("unknown semantic '" + sem + "'");

  // Streams by their own name, and out.* pass-through.
  if (!computedSemantics().count(sem)) {
    std::string name = sem.rfind("out.", 0) == 0 ? "vertex." + sem.substr(4) : sem;
    return stream(name);
  }

  if (sem == "object.position") {
    const auto& p = objectPosition();
    return fill([&](size_t v) { return p[v]; });
  }
  if (sem == "object.normal") {
    const auto& N = objectNormal();
    return fill([&](size_t v) { return N[v]; });
  }
  if (sem == "object.occlusion") {
    const auto& o = objectOcclusion();
    return fill([&](size_t v) { return o[v]; });
  }
  if (sem == "object.tangent") {
    const auto& T = objectTangent();
    return fill([&](size_t v) { return T[v]; });
  }
  if (sem == "world.position") {
    const auto& p = worldPosition();
    return fill([&](size_t v) { return p[v]; });
  }
  if (sem == "world.normal") {
    const auto& N = worldNormalValues();
    return fill([&](size_t v) { return N[v]; });
  }
  if (sem == "world.tangent") {
    const auto& T = worldTangentValues();
    return fill([&](size_t v) { return T[v]; });
  }
  if (sem == "world.handedness") {
    const auto& h = handedness();
    return fill([&](size_t v) { return static_cast<double>(h[v].x); });
  }
  if (sem == "world.binormal") {
    const auto& h = handedness();
    const auto& N = worldNormalValues();
    const auto& T = worldTangentValues();
    return fill([&](size_t v) { return binormal(v, N, T, h); });
  }
  if (sem == "frame.row_x" || sem == "frame.row_y" || sem == "frame.row_z") {
    // Rows of the tangent→world matrix [T B N]: row_c = (T.c, B.c, N.c).
    const int c = sem.back() - 'x';
    const auto& h = handedness();
    const auto& N = worldNormalValues();
    const auto& T = worldTangentValues();
    return fill([&](size_t v) {
      dvec3 B = binormal(v, N, T, h);
      return dvec3(T[v][c], B[c], N[v][c]);
    });
  }
  if (sem == "world.eye_dir") {
    const auto& p = worldPosition();
    return fill([&](size_t v) { return eyeDir(p[v]); });
  }
  if (sem == "eye.position") {
    // eye.position = camera.view · vec4(world.position, 1)
    const dmat4 view(pose.view);
    const auto& p = worldPosition();
    return fill([&](size_t v) { return view * dvec4(p[v], 1.0); });
  }
  if (sem == "eye.normal") {
    // eye.normal = mat3(camera.view) · world.normal
    const dmat3 view3(dmat4(pose.view));
    const auto& N = worldNormalValues();
    return fill([&](size_t v) { return view3 * N[v]; });
  }
  // three.js's view-space varyings, written the way its shader chunks compute them (not as
  // the vocabulary defines them): vViewPosition = -mvPosition.xyz; vTangent the tangent
  // rotated into view space; vBitangent = tangent.w * normalize(cross(vNormal, vTangent)),
  // a cross product taken in view space.
  if (sem == "eye.to_camera") {
    const dmat4 view(pose.view);
    const auto& p = worldPosition();
    return fill([&](size_t v) { return -dvec3(view * dvec4(p[v], 1.0)); });
  }
  if (sem == "eye.tangent" || sem == "eye.binormal") {
    const dmat3 view3(dmat4(pose.view));
    const auto& T = worldTangentValues();
    if (sem == "eye.tangent") return fill([&](size_t v) { return view3 * T[v]; });
    const auto& N = worldNormalValues();
    const auto& h = handedness();
    return fill([&](size_t v) {
      return static_cast<double>(h[v].x) * glm::normalize(glm::cross(view3 * N[v], view3 * T[v]));
    });
  }
  if (sem == "view.ndotv" || sem == "view.one_minus_ndotv" || sem == "view.one_minus_ndotv_sq") {
    // view.ndotv = abs(dot(world.normal, world.eye_dir))
    const auto& p = worldPosition();
    const auto& N = worldNormalValues();
    const int which = sem == "view.ndotv" ? 0 : sem == "view.one_minus_ndotv" ? 1 : 2;
    return fill([&](size_t v) {
      double ndotv = std::abs(glm::dot(N[v], eyeDir(p[v])));
      if (which == 0) return ndotv;
      double om = 1.0 - ndotv;
      return which == 1 ? om : om * om;
    });
  }
  if (sem == "dapple.normal_z") {
    // dapple.normal_z = (mat3(dapple.matrix)·world.normal).z
    const dmat3 d3(dmat4(pose.dapple));
    const auto& N = worldNormalValues();
    return fill([&](size_t v) { return (d3 * N[v]).z; });
  }
  if (sem == "clip.position") {
    // clip.position = camera.projection · camera.view · vec4(world.position, 1)
    const dmat4 pv = dmat4(pose.projection) * dmat4(pose.view);
    const auto& p = worldPosition();
    return fill([&](size_t v) { return pv * dvec4(p[v], 1.0); });
  }
  if (sem == "camera.position") {
    const dvec3 c(pose.cameraPosition);
    return fill([&](size_t) { return c; });
  }
  throw std::invalid_argument("unknown semantic '" + sem + "'");  // table and dispatch disagree
}

ReferenceEvaluator::ReferenceEvaluator(const Mesh& mesh, const Pose& pose, const RigShape& shape)
    : state_(std::make_unique<State>(mesh, pose, shape)) {}

ReferenceEvaluator::~ReferenceEvaluator() = default;

std::vector<glm::vec4> ReferenceEvaluator::values(const std::string& semantic) {
  return state_->evaluate(semantic);
}

std::vector<glm::vec4> referenceValues(const std::string& semantic, const Mesh& mesh,
                                       const Pose& pose, const RigShape& shape) {
  ReferenceEvaluator eval(mesh, pose, shape);
  return eval.values(semantic);
}

bool isReferenceSemantic(const std::string& semantic) {
  return componentsOf(semantic).has_value();
}

int referenceComponents(const std::string& semantic) {
  if (auto c = componentsOf(semantic)) return *c;
  if (nonVectorSemantics().count(semantic))
    throw std::invalid_argument(semantic + ": is not a per-vertex vector (mat4 or array semantic)");
  throw std::invalid_argument("unknown semantic '" + semantic + "'");
}

}  // namespace sg::rt

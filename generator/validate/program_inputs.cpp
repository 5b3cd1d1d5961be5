#include "validate/program_inputs.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "rig/packed_fields.h"
#include "rig/skin_weights.h"
#include "rig/vertex_encoding.h"
#include "rules/instantiate.h"
#include "validate/poses.h"

namespace sg {
namespace {

VkFormat vkFormat(VertexFormat f) { return static_cast<VkFormat>(vulkanFormat(f).value); }

std::string partSemantic(const RigAttribute& a, const ProvidedPart& p, int target) {
  return target >= 0 ? fmt::format("{}[{}]", p.semantic, target) : p.semantic;
}

int swizzleIndex(char c) { return c == 'x' ? 0 : c == 'y' ? 1 : c == 'z' ? 2 : 3; }

// Writes a part's values from the mesh into `comps` (n components per vertex: those of the
// attribute, or of the part's field), each at the component its swizzle names.
void gatherPart(const RigAttribute& a, const ProvidedPart& p, int target, const rt::Mesh& mesh, int n,
                std::vector<float>& comps) {
  std::string sem = partSemantic(a, p, target);
  if (!mesh.has(sem))
    throw InputError(a.loc, fmt::format("mesh '{}' has no data for '{}' (attribute '{}')", mesh.name, sem, a.name));
  const auto& src = mesh.at(sem);
  std::string swz = p.swizzle.empty() ? std::string("xyzw").substr(0, static_cast<size_t>(n)) : p.swizzle;
  for (size_t v = 0; v < mesh.vertexCount; ++v)
    for (size_t k = 0; k < swz.size(); ++k)
      if (swizzleIndex(swz[k]) < n)  // past a widened attribute's format: the device fills it
        comps[v * static_cast<size_t>(n) + static_cast<size_t>(swizzleIndex(swz[k]))] = src[v][static_cast<int>(k)];
}

// Replaces, in the mesh, every value an attribute of a non-float32 format carries by the
// value the device reads back from its stored form, so the reference sees exactly what the
// GPU reads. A part's stream component k is the attribute's component of its swizzle's
// k-th letter (10-10-10-2 stores w in 2 bits, x, y and z in 10). Components past a widened
// attribute's format are fillWidened's.
void quantizeStreams(const Rig& rig, rt::Mesh& m) {
  for (const auto& a : rig.attributes) {
    int targets = a.perMorphTarget ? rig.morphTargets() : 1;
    for (int t = 0; t < targets; ++t)
      for (const auto& p : a.provides) {
        const VertexFormat format = partFormat(a, p);  // a bit-packed field's own
        if (formatIsFloat32(format)) continue;
        const int n = formatComponents(format);
        auto it = m.streams.find(partSemantic(a, p, a.perMorphTarget ? t : -1));
        if (it == m.streams.end()) continue;
        const std::string swz = p.swizzle.empty() ? std::string("xyzw").substr(0, static_cast<size_t>(n)) : p.swizzle;
        for (auto& v : it->second)
          for (size_t k = 0; k < swz.size(); ++k)
            if (const int c = swizzleIndex(swz[k]); c < n) v[static_cast<int>(k)] = storedValue(format, c, v[static_cast<int>(k)]);
      }
  }
}

// A widened attribute (shader_type past the format): the device reads 0 in the components
// the format lacks, and 1 for w, whatever the mesh holds there.
void fillWidened(const Rig& rig, rt::Mesh& m) {
  for (const auto& a : rig.attributes) {
    if (!a.widened) continue;
    const int n = formatComponents(a.format);
    for (int t = 0; t < (a.perMorphTarget ? rig.morphTargets() : 1); ++t)
      for (const auto& p : a.provides) {
        if (p.field >= 0) continue;  // a bit-packed field reads its own format's components
        auto it = m.streams.find(partSemantic(a, p, a.perMorphTarget ? t : -1));
        if (it == m.streams.end()) continue;
        const std::string swz =
            p.swizzle.empty() ? std::string("xyzw").substr(0, static_cast<size_t>(componentCount(a.shaderType))) : p.swizzle;
        for (auto& v : it->second)
          for (size_t k = 0; k < swz.size(); ++k)
            if (const int c = swizzleIndex(swz[k]); c >= n) v[static_cast<int>(k)] = c == 3 ? 1.0f : 0.0f;
      }
  }
}

// Skin weights stored unorm8/16: rounding each weight alone lets a vertex's sum drift from
// 1 by up to half a step per weight, which shrinks or swells the skin. As gltfpack does,
// the codes of a vertex whose weights sum to 1 are rounded to sum to exactly 2^bits - 1
// (largest remainders first), across every weight set of the rig (8 influences: 2 sets).
// The weight sets renormaliseWeights rounds together and their bits (none: it leaves them).
struct WeightSets {
  std::vector<std::string> sets;
  int bits = 0;
};
WeightSets renormalisedWeights(const Rig& rig, const rt::Mesh& m) {
  WeightSets out;
  for (const auto& a : rig.attributes)
    for (const auto& p : a.provides) {
      if (p.semantic.rfind("skin.weights[", 0) != 0) continue;
      const VertexFormat format = partFormat(a, p);
      const int b = format == VertexFormat::Unorm8x4 ? 8 : format == VertexFormat::Unorm16x4 ? 16 : 0;
      if (b == 0 || (out.bits != 0 && b != out.bits) || (!p.swizzle.empty() && p.swizzle != "xyzw")) return {};  // floats, or mixed
      out.bits = b;
      if (!m.has(p.semantic)) return {};
      out.sets.push_back(p.semantic);
    }
  return out;
}

// A vertex's weights are renormalised when they sum to one within this: its sum, or NaN.
double partitionSum(const std::vector<const std::vector<glm::vec4>*>& sets, size_t v) {
  double sum = 0;
  for (const auto* s : sets)
    for (int c = 0; c < 4; ++c) sum += std::max(0.0, double((*s)[v][c]));
  return std::abs(sum - 1) <= 1e-3 ? sum : NAN;
}

void renormaliseWeights(const Rig& rig, rt::Mesh& m) {
  const auto [sets, bits] = renormalisedWeights(rig, m);
  if (sets.empty()) return;
  const double steps = std::ldexp(1.0, bits) - 1;
  std::vector<std::vector<glm::vec4>*> streams;
  std::vector<const std::vector<glm::vec4>*> read;
  for (const auto& s : sets) streams.push_back(&m.streams.at(s)), read.push_back(streams.back());
  std::vector<double> w(sets.size() * 4);
  for (size_t v = 0; v < m.vertexCount; ++v) {
    if (std::isnan(partitionSum(read, v))) continue;  // not a partition of one: rounded as it is
    for (size_t s = 0; s < sets.size(); ++s)
      for (int c = 0; c < 4; ++c) w[s * 4 + static_cast<size_t>(c)] = (*streams[s])[v][c];
    normalizeSkinWeights(w.data(), w.size(), steps);  // rig/skin_weights.h: the import's renormalisation
    for (size_t s = 0; s < sets.size(); ++s)
      for (int c = 0; c < 4; ++c) (*streams[s])[v][c] = static_cast<float>(w[s * 4 + static_cast<size_t>(c)]);
  }
}

// The encoded semantics the rig stores (rig/vertex_encoding.h), with their formats: one
// per morph target for a per-target attribute.
struct StoredEncoding {
  const VertexEncoding* e;
  VertexFormat format;
  int target;  // -1: not per target
  std::string name(const std::string& semantic) const { return target < 0 ? semantic : indexedName(semantic, target); }
  std::vector<std::string> values() const {
    std::vector<std::string> out;
    for (const std::string& v : e->decodes()) out.push_back(name(v));
    return out;
  }
};
std::vector<StoredEncoding> storedEncodings(const Rig& rig) {
  std::vector<StoredEncoding> out;
  for (const auto& a : rig.attributes)
    for (const auto& p : a.provides)
      if (const VertexEncoding* e = encodingOf(p.semantic); e && e->perTarget == a.perMorphTarget)
        for (int t = a.perMorphTarget ? 0 : -1; t < (a.perMorphTarget ? rig.morphTargets() : 0); ++t)
          out.push_back({e, partFormat(a, p), t});
  return out;
}

bool declaresUniform(const Rig& rig, const std::string& semantic) {
  return std::any_of(rig.uniforms.begin(), rig.uniforms.end(), [&](const RigUniform& u) { return u.semantic == semantic; });
}

// The mesh's bounds: those `addBounds` put in it, else from its positions.
PositionBounds meshBounds(const rt::Mesh& m) {
  if (!m.uniforms.count("mesh.bounds_min") || !m.uniforms.count("mesh.bounds_extent")) {
    if (!m.has("vertex.position"))
      throw InputError(SourceLoc{}, fmt::format("mesh '{}' has no positions to take its bounds from", m.name));
    return positionBounds(m.at("vertex.position"));
  }
  const auto& lo = m.uniforms.at("mesh.bounds_min");
  const auto& ext = m.uniforms.at("mesh.bounds_extent");
  PositionBounds b;
  for (int k = 0; k < 3; ++k) b.min[k] = static_cast<float>(lo[static_cast<size_t>(k)]), b.extent[k] = static_cast<float>(ext[static_cast<size_t>(k)]);
  return b;
}

// The mesh's bounds as uniforms, from its float positions, for a rig that reads them.
void addBounds(const Rig& rig, rt::Mesh& m) {
  if (!declaresUniform(rig, "mesh.bounds_min") && !declaresUniform(rig, "mesh.bounds_extent")) return;
  if (m.uniforms.count("mesh.bounds_min") && m.uniforms.count("mesh.bounds_extent")) return;
  const PositionBounds b = meshBounds(m);
  m.uniforms["mesh.bounds_min"] = {b.min.x, b.min.y, b.min.z};
  m.uniforms["mesh.bounds_extent"] = {b.extent.x, b.extent.y, b.extent.z};
}

// The bounds `addBounds` put in the mesh; none for an encoding that reads no bounds.
PositionBounds boundsFor(const VertexEncoding& e, const rt::Mesh& m) { return e.uniforms.empty() ? PositionBounds{} : meshBounds(m); }

// Each target's delta scale as a uniform array, from its float deltas, for a rig that reads
// them (a target without deltas: 0).
void addDeltaScales(const Rig& rig, rt::Mesh& m) {
  for (const auto& e : vertexEncodings()) {
    if (e.name != "scaled" || !declaresUniform(rig, e.uniforms[0]) || m.uniforms.count(e.uniforms[0])) continue;
    std::vector<double> scales;
    for (int t = 0; t < rig.morphTargets(); ++t) {
      const std::string source = indexedName(e.sources[0], t);
      scales.push_back(m.has(source) ? deltaScale(m.at(source)) : 0.0f);
    }
    m.uniforms[e.uniforms[0]] = std::move(scales);
  }
}

// The uniforms an encoding's decode reads, as the mesh has them: the bounds `addBounds`
// put there, a target's scale `addDeltaScales` did.
struct DecodeUniforms {
  PositionBounds bounds;
  float scale = 0;
};
DecodeUniforms decodeUniformsFor(const StoredEncoding& se, const rt::Mesh& m) {
  const VertexEncoding& e = *se.e;
  DecodeUniforms out;
  if (e.name == "scaled") out.scale = static_cast<float>(m.uniforms.at(e.uniforms[0]).at(static_cast<size_t>(se.target)));
  if (e.name == "bounds") out.bounds = boundsFor(e, m);
  return out;
}

// Every vertex's code from the mesh's float values (each one the encoding decodes).
std::vector<glm::vec4> encodeFrom(const StoredEncoding& se, const DecodeUniforms& u, const rt::Mesh& m) {
  const VertexEncoding& e = *se.e;
  std::vector<const std::vector<glm::vec4>*> in;
  for (const std::string& sem : se.values()) in.push_back(&m.at(sem));
  std::vector<glm::vec4> code(m.vertexCount, glm::vec4(0));
  for (size_t v = 0; v < m.vertexCount; ++v) {
    const glm::dvec3 first((*in[0])[v]);
    if (e.name == "bounds")
      code[v] = glm::vec4(glm::vec3(boundsEncode(u.bounds, first)), 0);
    else if (e.name == "scaled")
      code[v] = glm::vec4(glm::vec3(scaledEncode(u.scale, first)), 0);
    else if (e.name == "qtangent")  // normal, tangent, handedness
      code[v] = glm::vec4(qtangentEncode(first, glm::dvec3((*in[1])[v]), (*in[2])[v].x, qtangentBias(se.format)));
    else
      code[v] = glm::vec4(glm::vec2(octahedralEncode(first)), 0, 0);
  }
  return code;
}

// The decode of every vertex's code written over the values it encodes, in their first
// components (the streams looked up once, not per vertex).
void decodeInto(const StoredEncoding& se, const DecodeUniforms& u, const std::vector<glm::vec4>& code, rt::Mesh& m) {
  const VertexEncoding& e = *se.e;
  std::vector<std::vector<glm::vec4>*> out;
  for (const std::string& sem : se.values()) {
    out.push_back(&m.streams[sem]);
    out.back()->resize(m.vertexCount, glm::vec4(0));
  }
  auto put = [](glm::vec4& dst, const glm::dvec3& x, int n) {
    for (int k = 0; k < n; ++k) dst[k] = static_cast<float>(x[k]);
  };
  for (size_t v = 0; v < m.vertexCount; ++v) {
    if (e.name == "bounds") {
      put((*out[0])[v], boundsDecode(u.bounds, glm::dvec3(code[v])), 3);
    } else if (e.name == "scaled") {
      put((*out[0])[v], scaledDecode(u.scale, glm::dvec3(code[v])), 3);
    } else if (e.name == "qtangent") {  // normal, tangent, handedness
      const QTangentFrame f = qtangentDecode(glm::dvec4(code[v]));
      put((*out[0])[v], f.normal, 3);
      put((*out[1])[v], f.tangent, 3);
      put((*out[2])[v], glm::dvec3(f.handedness), 1);
    } else {
      put((*out[0])[v], octahedralDecode(glm::dvec2(code[v])), 3);
    }
  }
}

rt::Mesh quantizedMesh(const Rig& rig, const rt::Mesh& mesh) {
  rt::Mesh m = mesh;
  addBounds(rig, m);
  addDeltaScales(rig, m);
  // An encoded stream the mesh lacks is encoded from its float source; after rounding to
  // the stored format, the source becomes the decode of what the device reads. So the
  // reference, the GPU's decode and a float attribute the rig offers beside the code all
  // carry one value, and a decode rule is checked exactly (its rounding is the budget's
  // business, not validation's).
  const auto encodings = storedEncodings(rig);
  for (const StoredEncoding& se : encodings) {
    const std::vector<std::string> values = se.values();
    if (m.has(se.name(se.e->encoded)) || !std::all_of(values.begin(), values.end(), [&](const auto& s) {
          return m.has(s) && m.at(s).size() >= m.vertexCount;
        }))
      continue;
    m.streams[se.name(se.e->encoded)] = encodeFrom(se, decodeUniformsFor(se, m), m);
  }
  renormaliseWeights(rig, m);
  quantizeStreams(rig, m);
  fillWidened(rig, m);
  if (encodings.empty()) return m;
  for (const StoredEncoding& se : encodings)
    if (m.has(se.name(se.e->encoded))) decodeInto(se, decodeUniformsFor(se, m), m.at(se.name(se.e->encoded)), m);
  quantizeStreams(rig, m);  // a source the rig stores too, in a rounded format
  fillWidened(rig, m);
  return m;
}

// The largest error of each input quantizedMesh changes, as the formats and encodings state
// it. A stream the mesh lacks (codes given without their float source) has no float data to
// differ from and gets none.
std::vector<InputErrorBound> errorBounds(const Rig& rig, const rt::Mesh& mesh) {
  std::vector<InputErrorBound> out;
  const WeightSets weights = renormalisedWeights(rig, mesh);
  std::vector<const std::vector<glm::vec4>*> weightStreams;
  for (const auto& s : weights.sets) weightStreams.push_back(&mesh.at(s));
  // Plain values in a format that rounds them.
  for (const auto& a : rig.attributes) {
    for (int t = 0; t < (a.perMorphTarget ? rig.morphTargets() : 1); ++t)
      for (const auto& p : a.provides) {
        const VertexFormat format = partFormat(a, p);
        const int n = formatComponents(format);
        if (formatIsFloat32(format) || formatIsInteger(format)) continue;
        if (encodingOf(p.semantic)) continue;  // below
        InputErrorBound b;
        b.semantic = partSemantic(a, p, a.perMorphTarget ? t : -1);
        if (!mesh.has(b.semantic)) continue;
        const auto& x = mesh.at(b.semantic);
        b.bound.assign(mesh.vertexCount, glm::dvec4(0));
        const bool renormalised = std::count(weights.sets.begin(), weights.sets.end(), p.semantic) != 0;
        const double step = 1 / (std::ldexp(1.0, weights.bits) - 1);
        const std::string swz = p.swizzle.empty() ? std::string("xyzw").substr(0, static_cast<size_t>(n)) : p.swizzle;
        for (size_t v = 0; v < mesh.vertexCount && v < x.size(); ++v) {
          // Renormalised weights: each code is the floor of w / sum in steps, or one more.
          const double sum = renormalised ? partitionSum(weightStreams, v) : NAN;
          for (size_t k = 0; k < swz.size(); ++k) {
            const double xv = x[v][static_cast<int>(k)];
            // Past a widened attribute's format: the device's fill, exact (fillWidened).
            if (swizzleIndex(swz[k]) >= n) continue;
            b.bound[v][static_cast<int>(k)] =
                std::isnan(sum) ? storedValueMaxError(format, swizzleIndex(swz[k]), xv)
                                : step + std::ldexp(1.0, -24) + std::abs(xv) * std::abs(1 - 1 / sum);
          }
        }
        out.push_back(std::move(b));
      }
  }
  // Encoded values: each value a code decodes within its stated error (a QTangent's
  // handedness, decoded exactly, has none).
  const double rounding = std::ldexp(1.0, -24);
  for (const StoredEncoding& se : storedEncodings(rig)) {
    const VertexEncoding& e = *se.e;
    const double stated = *encodingMaxError(e, se.format);
    const std::vector<std::string> values = se.values();
    for (size_t i = 0; i < e.sources.size(); ++i) {
      InputErrorBound b;
      b.semantic = values[i];
      if (!mesh.has(b.semantic)) continue;
      const auto& x = mesh.at(b.semantic);
      b.bound.assign(mesh.vertexCount, glm::dvec4(0));
      if (e.angular()) {
        // Within the stated angle of the direction the encoder stores: at most its chord
        // 2 sin(angle / 2) from that unit vector, which is itself |ideal - x| from x (the data
        // normalised; a QTangent's frame also orthonormalised, its tangent made perpendicular
        // to the normal). The decode is rounded to float: sqrt(3) 2^-24 more.
        b.ball = true;
        const double chord = 2 * std::sin(glm::radians(stated) / 2) + std::sqrt(3.0) * rounding;
        const bool frame = e.name == "qtangent" && mesh.has(values[0]) && mesh.has(values[1]);
        for (size_t v = 0; v < mesh.vertexCount && v < x.size(); ++v) {
          const glm::dvec3 xv(x[v]);
          glm::dvec3 ideal = glm::length(xv) > 0 ? glm::normalize(xv) : xv;
          if (frame) {
            const double h = mesh.has(values[2]) ? double(mesh.at(values[2])[v].x) : 1.0;
            const QTangentFrame f = qtangentDecode(qtangentEncode(glm::dvec3(mesh.at(values[0])[v]), glm::dvec3(mesh.at(values[1])[v]), h, 0));
            ideal = i == 0 ? f.normal : f.tangent;
          }
          b.bound[v] = glm::dvec4(chord + glm::length(ideal - xv));
        }
      } else if (e.name == "bounds") {
        // Each coordinate within the stated fraction of its axis's extent, and the float
        // rounding of the decoded coordinate (2^-24 of it).
        const PositionBounds box = meshBounds(mesh);
        for (size_t v = 0; v < mesh.vertexCount && v < x.size(); ++v)
          b.bound[v] = glm::dvec4(stated * glm::dvec3(box.extent) + glm::abs(glm::dvec3(x[v])) * rounding, 0);
      } else {
        // Scaled deltas: the delta within the stated fraction of its target's scale (a bound
        // on its length, so on each coordinate), and the float rounding of code x scale.
        const double scale = deltaScale(x);
        for (size_t v = 0; v < mesh.vertexCount && v < x.size(); ++v)
          b.bound[v] = glm::dvec4(glm::dvec3(stated * scale + rounding * scale) + glm::abs(glm::dvec3(x[v])) * rounding, 0);
      }
      out.push_back(std::move(b));
    }
  }
  return out;
}

// Element bytes of a buffer element from up to 16 float components.
void putElement(std::vector<uint8_t>& out, size_t at, Type element, const float* comps, int n) {
  for (int c = 0; c < n; ++c) {
    if (element == Type::UVec4 || element == Type::IVec4) {
      auto u = static_cast<uint32_t>(static_cast<int64_t>(std::lround(comps[c])));
      std::memcpy(out.data() + at + 4 * static_cast<size_t>(c), &u, 4);
    } else {
      std::memcpy(out.data() + at + 4 * static_cast<size_t>(c), &comps[c], 4);
    }
  }
}

// The sparse-morph protocol (docs/buffers.md): the targets with a non-zero weight, in
// increasing order, and their count, for rigs that read them.
void addActiveTargets(const Rig& rig, const rt::Pose& pose, UniformValues& values) {
  std::vector<double> active;
  for (size_t i = 0; i < pose.morphWeights.size(); ++i)
    if (pose.morphWeights[i] != 0.0f) active.push_back(static_cast<double>(i));
  for (const auto& u : rig.uniforms) {
    if (u.semantic == "morph.active_count") values[u.semantic] = {static_cast<double>(active.size())};
    if (u.semantic != "morph.active_targets") continue;
    if (active.size() > static_cast<size_t>(u.arraySize))
      throw InputError(u.loc, fmt::format("the pose has {} targets with a non-zero weight; the active-target list "
                                          "holds {}", active.size(), u.arraySize));
    std::vector<double> list = active;
    list.resize(static_cast<size_t>(u.arraySize), 0.0);
    values[u.semantic] = std::move(list);
  }
}

// Storage buffers of a generated shader (docs/buffers.md layout): per-vertex ones from
// the mesh's streams (one zero vertex of padding: the harness draws an even count), the
// palette from the pose.
std::vector<rt::StorageBufferData> buildStorageBuffers(const Problem& p, const EmittedGlsl& glsl, const rt::Mesh& mesh,
                                                       const rt::Pose& pose, bool perVertex) {
  std::vector<rt::StorageBufferData> out;
  for (const auto& e : glsl.buffers) {
    const BufferSource& b = p.buffers[e.buffer];
    rt::StorageBufferData sb;
    sb.binding = static_cast<uint32_t>(e.binding);
    if (b.kind == BufferSource::Kind::Array) {
      if (!perVertex) {
        sb.data.assign(static_cast<size_t>(b.count) * e.strideBytes, 0);
        for (int64_t j = 0; j < b.count && j < static_cast<int64_t>(pose.bones.size()); ++j)
          putElement(sb.data, static_cast<size_t>(j) * e.strideBytes, e.element, &pose.bones[static_cast<size_t>(j)][0][0], 16);
        out.push_back(std::move(sb));
      }
      continue;
    }
    if (!perVertex) continue;
    const size_t count = static_cast<size_t>(b.count);
    sb.data.assign((mesh.vertexCount + 1) * count * e.strideBytes, 0);
    for (const auto& part : b.parts)
      for (size_t i = 0; i < count; ++i) {
        const std::string sem = p.facts[part.facts[i]].name;
        if (!mesh.has(sem)) throw InputError(SourceLoc{}, fmt::format("mesh '{}' has no data for '{}' (buffer {})", mesh.name, sem, e.name));
        const auto& src = mesh.at(sem);
        for (size_t v = 0; v < mesh.vertexCount; ++v)
          putElement(sb.data, ((v * count + i) * e.strideBytes) + 4 * static_cast<size_t>(part.firstComponent), e.element,
                     &src[v][0], part.components);
      }
    out.push_back(std::move(sb));
  }
  return out;
}

// The uniform block of one pose: every uniform of the rig from its semantic's values
// (UniformValues: flat column-major, arrays element after element), laid out as reflected.
std::vector<uint8_t> buildUniforms(const Rig& rig, const EmittedGlsl& glsl, const SpirvModule& spv,
                                   const UniformValues& values) {
  std::vector<uint8_t> block(spv.uniformBlockSize, 0);
  for (const auto& u : glsl.uniforms) {
    const RigUniform& ru = rig.uniforms[u.uniform];
    auto layout = std::find_if(spv.uniforms.begin(), spv.uniforms.end(), [&](const UniformLayout& l) { return l.name == u.name; });
    if (layout == spv.uniforms.end()) throw std::logic_error("no reflected layout for uniform " + u.name);
    const UniformLayout& l = *layout;
    auto v = values.find(ru.semantic);
    if (v == values.end())
      throw InputError(ru.loc, fmt::format("validation has no value for uniform semantic '{}'", ru.semantic));
    const int comps = componentCount(ru.type);
    const int elements = std::max(1, ru.arraySize);
    if (v->second.size() < static_cast<size_t>(elements * comps))
      throw InputError(ru.loc, fmt::format("the pose has {} values for uniform '{}' ({}), the rig needs {}", v->second.size(),
                                           ru.name, ru.semantic, elements * comps));
    const int cols = ru.type == Type::Mat3 ? 3 : ru.type == Type::Mat4 ? 4 : 1;
    const int rows = comps / cols;
    const uint32_t colStride = l.matrixStride ? l.matrixStride : 16;
    for (int e = 0; e < elements; ++e)
      for (int c = 0; c < cols; ++c)
        for (int r = 0; r < rows; ++r) {
          double x = v->second[static_cast<size_t>(e * comps + c * rows + r)];
          uint32_t off = l.offset + static_cast<uint32_t>(e) * l.arrayStride + static_cast<uint32_t>(c) * colStride +
                         static_cast<uint32_t>(r) * 4;
          if (off + 4 > block.size()) throw std::logic_error("uniform write past the block");
          if (scalarKind(ru.type) == ScalarKind::Float) {
            float f = static_cast<float>(x);
            std::memcpy(block.data() + off, &f, 4);
          } else {
            int32_t i = static_cast<int32_t>(x);
            std::memcpy(block.data() + off, &i, 4);
          }
        }
  }
  return block;
}

}  // namespace

UniformValues uniformValues(const Rig& rig, const RuleSet& rules, const RigShape& shape, const rt::Mesh& mesh,
                            const rt::Pose& pose) {
  UniformValues uniforms = poseUniforms(rig, pose);
  for (const auto& u : mesh.uniforms) uniforms.insert(u);
  for (auto& u : definitionInputs(rig, rules, pose)) uniforms.insert(std::move(u));
  for (const auto& u : rig.uniforms) {
    const SemanticDecl* d = rules.findSemantic(u.semantic);
    if (uniforms.count(u.semantic) || !d || !d->definition) continue;
    Interpreter ui(rules, shape, mesh, uniforms);
    std::vector<double> v;
    try {
      v = ui.evaluateUniform(u.semantic);
    } catch (const std::exception& e) {
      throw InputError(u.loc, fmt::format("cannot compute uniform '{}' ({}) from its definition: {}", u.name, u.semantic, e.what()));
    }
    for (double& x : v) x = static_cast<float>(x);
    uniforms[u.semantic] = std::move(v);
  }
  return uniforms;
}

rt::Mesh quantizeForRig(const Rig& rig, const rt::Mesh& mesh) { return quantizedMesh(rig, mesh); }

void fillWidenedComponents(const Rig& rig, rt::Mesh& mesh) { fillWidened(rig, mesh); }

std::vector<InputErrorBound> quantizationErrorBounds(const Rig& rig, const rt::Mesh& mesh) { return errorBounds(rig, mesh); }

rt::VertexStream vertexStream(const Rig& rig, const EmittedInput& in, const rt::Mesh& mesh) {
  const RigAttribute& a = rig.attributes[in.attribute];
  const int n = formatComponents(a.format);
  rt::VertexStream s;
  s.location = static_cast<uint32_t>(in.location);
  s.format = vkFormat(a.format);
  s.stride = static_cast<uint32_t>(formatBytes(a.format));
  s.data.resize(mesh.vertexCount * s.stride);
  if (!a.fields.empty()) {  // bit-packed: each field's components rounded to its format, into its bits
    for (size_t f = 0; f < a.fields.size(); ++f) {
      const PackedField& field = a.fields[f];
      const int fn = formatComponents(field.format);
      std::vector<float> comps(mesh.vertexCount * static_cast<size_t>(fn), 0.0f);
      bool any = false;
      for (const auto& p : a.provides)
        if (p.field == static_cast<int>(f)) gatherPart(a, p, in.target, mesh, fn, comps), any = true;
      if (!any) continue;  // a field no value of this rig reads: its bits stay 0
      for (size_t v = 0; v < mesh.vertexCount; ++v)
        packField(field, comps.data() + v * static_cast<size_t>(fn), s.data.data() + v * s.stride);
    }
    return s;
  }
  // Gather the parts into one flat array of n components per vertex, then encode.
  std::vector<float> comps(mesh.vertexCount * static_cast<size_t>(n), 0.0f);
  for (const auto& p : a.provides) gatherPart(a, p, in.target, mesh, n, comps);
  for (size_t v = 0; v < mesh.vertexCount; ++v)
    encodeElement(a.format, comps.data() + v * static_cast<size_t>(n), s.data.data() + v * s.stride);
  return s;
}

std::vector<rt::DescriptorBinding> declaredDescriptors(const std::vector<ShaderDescriptor>& reflected) {
  std::vector<rt::DescriptorBinding> out;
  for (const auto& d : reflected)
    out.push_back({d.set, d.binding,
                   d.kind == ShaderDescriptor::Kind::UniformBlock   ? rt::DescriptorKind::UniformBuffer
                   : d.kind == ShaderDescriptor::Kind::StorageBlock ? rt::DescriptorKind::StorageBuffer
                                                                    : rt::DescriptorKind::CombinedImageSampler,
                   d.name});
  return out;
}

UniformValues feedPose(const GenerateResult& r, const rt::Mesh& mesh, const rt::Pose& pose, rt::ProgramInputs& inputs) {
  const Rig& rig = r.in.rig;
  std::vector<rt::Pose> poses{pose};
  drawDeclaredUniforms(poses, rig, r.in.rules);  // a no-op for poses whose uniforms are drawn already
  UniformValues values = uniformValues(rig, r.in.rules, shapeOfRig(rig, r.in.rules), mesh, poses[0]);
  addActiveTargets(rig, poses[0], values);
  inputs.uniformData = buildUniforms(rig, r.glsl, r.spirv, values);
  // Palettes follow the pose; per-vertex buffers stay.
  std::vector<rt::StorageBufferData> palettes = buildStorageBuffers(r.in.problem, r.glsl, mesh, poses[0], false);
  auto& buffers = inputs.storageBuffers;
  for (const auto& p : palettes)
    buffers.erase(std::remove_if(buffers.begin(), buffers.end(), [&](const auto& b) { return b.binding == p.binding; }),
                  buffers.end());
  for (auto& p : palettes) buffers.push_back(std::move(p));
  std::sort(buffers.begin(), buffers.end(), [](const auto& a, const auto& b) { return a.binding < b.binding; });
  return values;
}

std::vector<rt::StorageBufferData> perVertexBuffers(const GenerateResult& r, const rt::Mesh& mesh) {
  return buildStorageBuffers(r.in.problem, r.glsl, mesh, rt::Pose{}, true);
}

rt::ProgramInputs programInputs(const GenerateResult& r, const rt::Mesh& mesh, const rt::Pose& pose) {
  rt::ProgramInputs in;
  in.vertexCount = static_cast<uint32_t>(mesh.vertexCount);
  for (const auto& i : r.glsl.inputs) in.streams.push_back(vertexStream(r.in.rig, i, mesh));
  in.storageBuffers = perVertexBuffers(r, mesh);
  in.declared = declaredDescriptors(r.spirv.descriptors);
  feedPose(r, mesh, pose, in);
  return in;
}

}  // namespace sg

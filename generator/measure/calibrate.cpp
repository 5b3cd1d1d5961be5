#include "measure/calibrate.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <unistd.h>
#include <map>
#include <numeric>
#include <set>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "analysis/cost.h"
#include "common/content_hash.h"
#include "common/glsl_compile.h"
#include "common/input_file.h"
#include "measure/corpus.h"
#include "measure/fit.h"
#include "measure/workload.h"
#include "rig/gltf_import.h"
#include "runtime/procedural.h"
#include "runtime/vk_render.h"
#include "validate/program_inputs.h"

namespace sg {
namespace {

// ---- Probe programs -------------------------------------------------------------------

// How a probe's extra attributes are stored (location 0, the position, is always float32x4).
struct Encoding {
  const char* name;
  VkFormat format;
  uint32_t bytes;
  double (*decode)(uint32_t raw);  // raw: the stored integer of one component (float: bits)
};
double decodeFloat(uint32_t raw) {
  float f;
  std::memcpy(&f, &raw, 4);
  return f;
}
const Encoding kFloat32x4{"float32x4", VK_FORMAT_R32G32B32A32_SFLOAT, 16, decodeFloat};
const Encoding kUnorm16x4{"unorm16x4", VK_FORMAT_R16G16B16A16_UNORM, 8, [](uint32_t r) { return r / 65535.0; }};
const Encoding kUnorm8x4{"unorm8x4", VK_FORMAT_R8G8B8A8_UNORM, 4, [](uint32_t r) { return r / 255.0; }};

// Deterministic data: a hash of (stream, vertex, component) in [0, 1).
uint32_t mix(uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352dU;
  x ^= x >> 15;
  x *= 0x846ca68bU;
  return x ^ (x >> 16);
}
double unit(uint32_t stream, uint32_t v, uint32_t c) { return (mix(stream * 0x9e3779b9U ^ mix(v * 4 + c)) >> 8) / 16777216.0; }

struct Probe {
  std::string label;
  TermAmounts amounts{};
  std::string decl, body;  // GLSL: declarations after the position input; main's statements
  int outputs = 1;         // vec4 outputs o0..o{n-1} (gl_Position is also captured)
  rt::ProgramInputs inputs;  // streams (location 0 first), uniform block, storage buffers
  std::vector<double> expected;  // per vertex: gl_Position then the outputs, 4 components each
  double tolerance = 1e-5;       // relative to max(1, |expected| of that output)
  // A palette probe's addresses: load i's index per vertex in skin.joints[i / 4] component i % 4
  // (weight 1), so measureWorkload counts the distinct entries its warps read, per load and over
  // all loads, as it counts a skin's. Empty for probes that read no palette.
  rt::Mesh addresses;
};

struct ProbeMesh {
  std::string name;
  rt::Mesh mesh;
  std::vector<uint32_t> indices;
};

ProbeMesh probeMesh(const std::string& name) {
  rt::MeshOptions mo;
  // The Dawn face's skin (98 bones, 4 influences, each vertex to its nearest bone centres):
  // the palette probe indexes by it, so its indices diverge within a warp as a skin's do.
  mo.influences = 4;
  mo.bones = 98;
  mo.tangents = false;
  mo.occlusion = false;
  ProbeMesh m;
  m.name = name;
  int rings = 40, segments = 48;  // validate's head: 2,009 vertices (cached on a GPU)
  if (name == "dawn") rings = 299, segments = 599;  // 180,000 vertices
  else if (name == "limb") rings = 24, segments = 32;  // 825 vertices, as the limb's: a small draw, latency-bound
  else if (name == "small") rings = 8, segments = 8;  // tests
  else if (name != "head") throw std::invalid_argument(fmt::format("calibration mesh '{}': head, dawn, limb or small", name));
  m.mesh = rt::makeHead(rings, segments, mo);
  m.indices = gridIndices(rings, segments);
  return m;
}

// Where the probe puts a vertex: the head's positions scaled into the clip volume.
glm::dvec4 clipPosition(const glm::vec4& p) { return {p.x * 0.45, -p.y * 0.45, 0.5 + 0.2 * p.z, 1.0}; }
const char* kClipPosition = "  gl_Position = vec4(a0.x * 0.45, -a0.y * 0.45, 0.5 + 0.2 * a0.z, 1.0);\n";

// Common parts: the position stream at location 0 and the expected gl_Position.
Probe baseProbe(const ProbeMesh& m, const std::string& label, int outputs) {
  Probe p;
  p.label = label;
  p.outputs = outputs;
  const auto& pos = m.mesh.streams.at("vertex.position");
  rt::VertexStream s;
  s.location = 0;
  s.format = VK_FORMAT_R32G32B32A32_SFLOAT;
  s.stride = 16;
  s.data.resize(pos.size() * 16);
  std::memcpy(s.data.data(), pos.data(), s.data.size());
  p.inputs.streams.push_back(std::move(s));
  p.expected.assign(m.mesh.vertexCount * size_t(4 * (1 + outputs)), 0.0);
  for (size_t v = 0; v < m.mesh.vertexCount; ++v) {
    glm::dvec4 c = clipPosition(pos[v]);
    for (int k = 0; k < 4; ++k) p.expected[v * size_t(4 * (1 + outputs)) + size_t(k)] = c[k];
  }
  p.amounts[kTermLocations] = 1;
  p.amounts[kTermAttributeBytes] = 16;
  p.amounts[kTermOutputs] = 4 + 4 * outputs;
  p.amounts[kTermVertices] = 1;
  p.amounts[kTermFragments] = 1;
  return p;
}

double& expectedAt(Probe& p, size_t v, int output, int c) {
  return p.expected[v * size_t(4 * (1 + p.outputs)) + size_t(4 * (1 + output) + c)];
}

// A stream of decoded values at `location` (4 components) with the encoding; returns them.
std::vector<glm::dvec4> addStream(Probe& p, const ProbeMesh& m, uint32_t location, const Encoding& e, double lo, double hi) {
  rt::VertexStream s;
  s.location = location;
  s.format = e.format;
  s.stride = e.bytes;
  s.data.resize(m.mesh.vertexCount * e.bytes);
  std::vector<glm::dvec4> values(m.mesh.vertexCount);
  for (uint32_t v = 0; v < m.mesh.vertexCount; ++v)
    for (uint32_t c = 0; c < 4; ++c) {
      double x = lo + (hi - lo) * unit(location, v, c);
      uint8_t* at = s.data.data() + size_t(v) * e.bytes + c * (e.bytes / 4);
      if (e.bytes == 16) {
        float f = static_cast<float>(x);
        std::memcpy(at, &f, 4);
        values[v][int(c)] = f;
      } else {
        const uint32_t max = e.bytes == 8 ? 65535 : 255;
        uint32_t raw = static_cast<uint32_t>(std::lround(std::clamp(x, 0.0, 1.0) * max));
        if (e.bytes == 8) {
          uint16_t r16 = static_cast<uint16_t>(raw);
          std::memcpy(at, &r16, 2);
        } else {
          *at = static_cast<uint8_t>(raw);
        }
        values[v][int(c)] = e.decode(raw);
      }
    }
  p.decl += fmt::format("layout(location = {}) in vec4 a{};\n", location, location);
  p.amounts[kTermLocations] += 1;
  p.amounts[kTermAttributeBytes] += e.bytes;
  p.inputs.streams.push_back(std::move(s));
  return values;
}

// k locations in all (the position and k - 1 streams of `e`), summed into o0.
Probe fetchProbe(const ProbeMesh& m, int k, const Encoding& e) {
  Probe p = baseProbe(m, fmt::format("locations {} ({} after the position)", k, e.name), 1);
  p.body = "  o0 = vec4(0.0)";
  for (int l = 1; l < k; ++l) {
    auto values = addStream(p, m, uint32_t(l), e, 0.0, 1.0);
    p.body += fmt::format(" + a{}", l);
    for (size_t v = 0; v < values.size(); ++v)
      for (int c = 0; c < 4; ++c) expectedAt(p, v, 0, c) += values[v][c];
  }
  p.body += ";\n";
  return p;
}

// A chain of n dependent multiply-adds: x = x * a1 + a2, x starting at the position.
Probe chainProbe(const ProbeMesh& m, int n) {
  Probe p = baseProbe(m, fmt::format("arithmetic chain {}", n), 1);
  auto y = addStream(p, m, 1, kFloat32x4, 0.5, 0.9);
  auto z = addStream(p, m, 2, kFloat32x4, 0.0, 0.1);
  p.body = "  vec4 x = a0;\n";
  for (int i = 0; i < n; ++i) p.body += "  x = x * a1 + a2;\n";
  p.body += "  o0 = x;\n";
  const auto& pos = m.mesh.streams.at("vertex.position");
  for (size_t v = 0; v < pos.size(); ++v) {
    glm::dvec4 x(pos[v]);
    for (int i = 0; i < n; ++i) x = x * y[v] + z[v];
    for (int c = 0; c < 4; ++c) expectedAt(p, v, 0, c) = x[c];
  }
  p.tolerance = 1e-6 * (4 + n);  // float rounding per step, fused or not
  return p;
}

// n storage-buffer loads per vertex (vec4 elements v[vertex * n + i]) summed into o0.
Probe bufferProbe(const ProbeMesh& m, int n) {
  Probe p = baseProbe(m, fmt::format("storage-buffer loads {}", n), 1);
  p.decl += "layout(std430, set = 0, binding = 1) readonly buffer Elements { vec4 v[]; } elements;\n";
  p.body = "  o0 = vec4(0.0);\n";
  for (int i = 0; i < n; ++i) p.body += fmt::format("  o0 += elements.v[gl_VertexIndex * {} + {}];\n", n, i);
  const size_t padded = m.mesh.vertexCount + (m.mesh.vertexCount & 1);
  rt::StorageBufferData b;
  b.binding = 1;
  b.data.resize(padded * size_t(n) * 16);
  for (size_t v = 0; v < padded; ++v)
    for (int i = 0; i < n; ++i)
      for (int c = 0; c < 4; ++c) {
        float f = static_cast<float>(unit(100 + uint32_t(i), uint32_t(v), uint32_t(c)));
        std::memcpy(b.data.data() + (v * size_t(n) + size_t(i)) * 16 + size_t(c) * 4, &f, 4);
        if (v < m.mesh.vertexCount) expectedAt(p, v, 0, c) += f;
      }
  p.inputs.storageBuffers.push_back(std::move(b));
  p.amounts[kTermBufferLoads] = p.amounts[kTermBufferVec4Loads] = n;
  p.amounts[kTermBufferBytes] = 16 * n;
  return p;
}

// n loads of a mat4 palette (128 entries, std140) at indices read per vertex (the mesh's skin
// joints, a uint attribute: load i reads palette[joint[i % 4] + 7 (i / 4)], as a skin with n
// influences does: each group of four spans as many joints per warp as the skin), or at as many
// distinct indices taken from the uniform block; each times the position.
// The per-vertex indices diverge within a warp as much as the skin's nearest bones do: on
// the 2,009-vertex head a warp spans several bones, at Dawn scale mostly one. (Hashed
// indices, every vertex of a warp a different joint, took 29.6 ns per vertex for four
// loads on the H200 at Dawn scale, 15x their uniform-index twin: a case no skinned mesh
// has, which made the fit overprice a plan's palette loads.)
// `apart`: load i reads palette[joint[i % 4] + 32 i] instead, so the loads share no entries: as
// many distinct addresses per load as the skin's, and a warp's palette footprint the sum of its
// loads' (on the head about 2.6x the shared form's), to time the constant cache's capacity apart
// from its per-address price (docs/device-profiles.md, "The constant cache's capacity").
// In a storage buffer (`inBuffer`), the same loads are gathers through the memory pipe.
Probe paletteProbe(const ProbeMesh& m, int n, bool perVertex, bool inBuffer = false, bool apart = false) {
  Probe p = baseProbe(m, fmt::format("{}palette loads {} at a {} index{}", inBuffer ? "buffer " : "", n, perVertex ? "per-vertex" : "uniform",
                                     apart ? ", loads apart" : ""),
                      1);
  constexpr uint32_t kEntries = 128;
  if (inBuffer)
    p.decl += "layout(std140, set = 0, binding = 0) uniform Block { uint base; } u;\n"
              "layout(std430, set = 0, binding = 1) readonly buffer Palette { mat4 palette[]; } b;\n";
  else
    p.decl += fmt::format("layout(std140, set = 0, binding = 0) uniform Block {{ mat4 palette[{}]; uint base; }} u;\n", kEntries);
  // Both variants read the index attribute (same locations and bytes); only the first uses it.
  p.decl += "layout(location = 1) in uvec4 joint;\n";
  const auto& joints = m.mesh.streams.at("skin.joints[0]");
  rt::VertexStream s;
  s.location = 1;
  s.format = VK_FORMAT_R8G8B8A8_UINT;
  s.stride = 4;
  s.data.resize(m.mesh.vertexCount * 4);
  for (size_t v = 0; v < m.mesh.vertexCount; ++v)
    for (int c = 0; c < 4; ++c) s.data[v * 4 + size_t(c)] = static_cast<uint8_t>(joints[v][c]);
  p.inputs.streams.push_back(s);
  p.amounts[kTermLocations] += 1;
  p.amounts[kTermAttributeBytes] += 4;
  const uint32_t base = 5;
  std::vector<glm::dmat4> palette(kEntries);
  std::vector<uint8_t> bytes(kEntries * 64);  // mat4 entries: the same layout in std140 and std430
  for (uint32_t e = 0; e < kEntries; ++e)
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) {
        float f = static_cast<float>(2 * unit(200 + e, uint32_t(c), uint32_t(r)) - 1);
        palette[e][c][r] = f;
        std::memcpy(bytes.data() + size_t(e) * 64 + size_t(c) * 16 + size_t(r) * 4, &f, 4);
      }
  if (inBuffer) p.inputs.storageBuffers.push_back(rt::StorageBufferData{1, std::move(bytes)});
  else p.inputs.uniformData = std::move(bytes);
  const size_t baseAt = p.inputs.uniformData.size();  // `base` follows the palette, if any
  p.inputs.uniformData.resize(baseAt + 16, 0);
  std::memcpy(p.inputs.uniformData.data() + baseAt, &base, 4);
  const char* array = inBuffer ? "b.palette" : "u.palette";
  p.body = "  o0 = vec4(joint) * 0.001;\n";
  auto offset = [&](int i) { return uint32_t(apart ? 32 * i : 7 * (i / 4)); };
  for (int i = 0; i < n; ++i)
    p.body += perVertex ? fmt::format("  o0 += {}[(joint[{}] + {}u) & {}u] * a0;\n", array, i % 4, offset(i), kEntries - 1)
                        : fmt::format("  o0 += {}[(u.base + {}u) & {}u] * a0;\n", array, i, kEntries - 1);
  const auto& pos = m.mesh.streams.at("vertex.position");
  p.addresses.vertexCount = m.mesh.vertexCount;
  std::vector<std::vector<glm::vec4>*> addressJoints, addressWeights;
  for (int k = 0; k < (n + 3) / 4; ++k) {
    addressJoints.push_back(&p.addresses.streams[fmt::format("skin.joints[{}]", k)]);
    addressWeights.push_back(&p.addresses.streams[fmt::format("skin.weights[{}]", k)]);
    addressJoints.back()->resize(m.mesh.vertexCount, glm::vec4(0));
    addressWeights.back()->resize(m.mesh.vertexCount, glm::vec4(0));
  }
  for (size_t v = 0; v < m.mesh.vertexCount; ++v) {
    const uint8_t* j = &s.data[v * 4];
    glm::dvec4 o = glm::dvec4(j[0], j[1], j[2], j[3]) * 0.001;
    for (int i = 0; i < n; ++i) {
      const uint32_t idx = perVertex ? (j[i % 4] + offset(i)) & (kEntries - 1) : (base + uint32_t(i)) & (kEntries - 1);
      o += palette[idx] * glm::dvec4(pos[v]);
      (*addressJoints[size_t(i / 4)])[v][i % 4] = float(idx);
      (*addressWeights[size_t(i / 4)])[v][i % 4] = 1.0f;
    }
    for (int c = 0; c < 4; ++c) expectedAt(p, v, 0, c) = o[c];
  }
  if (inBuffer) {  // a table's storage-buffer loads, as the search counts a buffer palette's
    p.amounts[kTermBufferTableLoads] = n;
    p.amounts[kTermBufferTableVec4Loads] = 4 * n;  // a mat4: 4 vec4 loads
    p.amounts[kTermBufferBytes] = 64 * n;
  } else {
    p.amounts[kTermIndexedUniformLoads] = perVertex ? n : 0;
    p.amounts[kTermIndexedUniformVec4Loads] = perVertex ? 4 * n : 0;
  }
  return p;
}

// n vec4 outputs, output i = position * (i + 1).
Probe outputProbe(const ProbeMesh& m, int n) {
  Probe p = baseProbe(m, fmt::format("outputs {} x vec4", n), n);
  const auto& pos = m.mesh.streams.at("vertex.position");
  for (int i = 0; i < n; ++i) {
    p.body += fmt::format("  o{} = a0 * {}.0;\n", i, i + 1);
    for (size_t v = 0; v < m.mesh.vertexCount; ++v)
      for (int c = 0; c < 4; ++c) expectedAt(p, v, i, c) = double(pos[v][c]) * (i + 1);
  }
  return p;
}

std::vector<Probe> makeProbes(const ProbeMesh& m) {
  std::vector<Probe> probes;
  for (int k : {1, 2, 4, 6, 8, 12, 16}) probes.push_back(fetchProbe(m, k, kFloat32x4));  // locations
  probes.push_back(fetchProbe(m, 8, kUnorm8x4));   // bytes at 8 locations: 16 + 7 x 4
  probes.push_back(fetchProbe(m, 8, kUnorm16x4));  // 16 + 7 x 8
  probes.push_back(fetchProbe(m, 16, kUnorm8x4));  // 16 locations at 76 bytes (4 float32x4: 64)
  for (int n : {0, 16, 64, 256}) probes.push_back(chainProbe(m, n));
  for (int n : {1, 4, 8, 16}) probes.push_back(bufferProbe(m, n));
  for (int n : {1, 2, 4, 8, 16})
    for (bool perVertex : {true, false}) probes.push_back(paletteProbe(m, n, perVertex));
  // A palette in a storage buffer (a plan form the buffer rules offer), at the skin's joints
  // only: at a uniform index its loads are broadcasts, cheaper per vec4 than any per-vertex
  // stream (on the H200, 64 vec4s took 3.2 ns against 4.6 for 16 streamed), a case no plan has
  // that drove the fit to price elements and not vec4s (docs/device-profiles.md).
  for (int n : {4, 16}) probes.push_back(paletteProbe(m, n, true, true));
  // The same loads with a larger footprint: the constant cache's capacity (from session 21).
  for (int n : {2, 3, 4}) probes.push_back(paletteProbe(m, n, true, false, true));
  for (int n : {1, 4, 8, 15}) probes.push_back(outputProbe(m, n));
  return probes;
}

std::string probeGlsl(const Probe& p, bool capture) {
  const int stride = 16 * (1 + p.outputs);
  std::string s = "#version 450\nlayout(location = 0) in vec4 a0;\n" + p.decl;
  if (capture)
    s += fmt::format("out gl_PerVertex {{\n  layout(xfb_buffer = 0, xfb_offset = 0, xfb_stride = {}) vec4 gl_Position;\n}};\n", stride);
  for (int i = 0; i < p.outputs; ++i)
    s += capture ? fmt::format("layout(location = {}, xfb_buffer = 0, xfb_offset = {}, xfb_stride = {}) out vec4 o{};\n", i,
                               16 * (1 + i), stride, i)
                 : fmt::format("layout(location = {}) out vec4 o{};\n", i, i);
  return s + "void main() {\n" + kClipPosition + p.body + "}\n";
}

// A fragment shader that reads every output of the probe: a driver links the stages and
// would otherwise drop outputs nothing reads, and with them the work that feeds them.
std::string probeFragmentGlsl(const Probe& p) {
  std::string s = "#version 450\nlayout(location = 0) out vec4 color;\n";
  std::string sum = "vec4(0.0)";
  for (int i = 0; i < p.outputs; ++i) {
    s += fmt::format("layout(location = {}) in vec4 o{};\n", i, i);
    sum += fmt::format(" + o{}", i);
  }
  return s + "void main() { color = vec4(0.5) + 1e-6 * (" + sum + "); }\n";
}

GlslShader compileProbe(Stage stage, const std::string& text, const std::string& label) {
  GlslShader s(GlslUnit{stage, text, "calibration probe '" + label + "'", {}}, TargetEnv::Vulkan1_1);
  if (!s.ok()) throwDiagnostics(s.diagnostics(), "calibration probe", "a calibration probe does not compile");
  return s;
}

// "" when the captured outputs agree with the expected values, else where they first differ.
std::string compareCapture(const Probe& p, const std::vector<uint8_t>& captured, size_t vertices) {
  const size_t n = size_t(4 * (1 + p.outputs));
  if (captured.size() < vertices * n * 4) return "captured fewer bytes than the outputs need";
  for (size_t v = 0; v < vertices; ++v)
    for (size_t o = 0; o <= size_t(p.outputs); ++o) {
      double scale = 1;
      for (size_t c = 0; c < 4; ++c) scale = std::max(scale, std::abs(p.expected[v * n + o * 4 + c]));
      for (size_t c = 0; c < 4; ++c) {
        float g;
        std::memcpy(&g, captured.data() + (v * n + o * 4 + c) * 4, 4);
        double want = p.expected[v * n + o * 4 + c];
        if (!(std::abs(g - want) <= p.tolerance * scale))
          return fmt::format("vertex {}, {} component {}: device {} , expected {}", v, o ? fmt::format("o{}", o - 1) : "gl_Position",
                             c, g, want);
      }
    }
  return "";
}

// Bench's floors of a rig ("floor (pass-through)", "floor + every input fetched").
bool isFloorSample(const CalibrationSample& s) { return !s.rig.empty() && s.label.find("floor") != std::string::npos; }

}  // namespace

DeviceProfile fitDeviceProfile(const std::vector<CalibrationSample>& samples, const std::string& deviceName,
                               double workloadVertices, double nearBestPower, const FitOptions& fit) {
  std::map<std::pair<std::string, std::string>, double> fastest;  // (rig, mesh) -> ns per vertex
  std::vector<const CalibrationSample*> used;
  for (const auto& s : samples)
    if (s.fitted && s.validated && s.measuredNs > 0 && s.vertices > 0 && (fit.floors || !isFloorSample(s))) {
      used.push_back(&s);
      auto [it, added] = fastest.emplace(std::make_pair(s.rig, s.mesh), s.measuredNs);
      if (!added) it->second = std::min(it->second, s.measuredNs);
    }
  // A probe varies one term and weighs 1; a rig's programs weigh more the nearer they come
  // to its fastest. The GPU hides some costs under others (a 16-location plan's palette loads
  // under its fetch): the fit favours the plans the search must order right, those near the fastest.
  std::vector<FitRow> rows;
  for (const CalibrationSample* s : used) {
    FitRow r{s->amounts, s->vertices, s->workload, s->measuredNs, 1.0};
    if (!s->rig.empty() && nearBestPower > 0) r.weight = std::pow(fastest.at({s->rig, s->mesh}) / s->measuredNs, nearBestPower);
    rows.push_back(r);
  }
  DeviceProfile profile = fitProfile(rows, fit).profile;
  profile.device = deviceName;
  if (!profile.drawSizes.empty()) profile = profile.atDrawSize(workloadVertices);
  if (profile.hasDrawWeights()) profile.verticesPerDraw = workloadVertices;
  return profile;
}

std::vector<CalibrationFit> evaluateFit(std::vector<CalibrationSample>& samples, const DeviceProfile& profile,
                                        const std::vector<std::string>& meshes) {
  std::vector<CalibrationFit> fits;
  for (const auto& mesh : meshes) {
    CalibrationFit f;
    f.mesh = mesh;
    std::vector<double> predicted, measured, predictedAll, measuredAll;
    double sq = 0;
    for (auto& s : samples) {
      if (s.mesh != mesh) continue;
      s.predictedNs = profile.predictNanoseconds(s.amounts, s.vertices);
      if (!s.validated || s.measuredNs <= 0) continue;
      predictedAll.push_back(s.predictedNs);
      measuredAll.push_back(s.measuredNs);
      if (!s.fitted) continue;
      double rel = (s.predictedNs - s.measuredNs) / s.measuredNs;
      sq += rel * rel;
      f.maxRelativeError = std::max(f.maxRelativeError, std::abs(rel));
      predicted.push_back(s.predictedNs);
      measured.push_back(s.measuredNs);
    }
    f.samples = measured.size();
    f.rmsRelativeError = f.samples ? std::sqrt(sq / double(f.samples)) : 0;
    f.spearman = spearmanWithinSpread(predicted, measured, 0.005);
    f.allSamples = measuredAll.size();
    f.spearmanAll = spearmanWithinSpread(predictedAll, measuredAll, 0.005);
    fits.push_back(f);
  }
  return fits;
}

namespace {

bool isPlanSample(const CalibrationSample& s) { return !s.rig.empty() && !isFloorSample(s); }

double medianOfFinite(std::vector<double> v) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

std::string heldOutSummary(const LeaveOneRigOut& loo, const char* what = "leave-one-rig-out") {
  return fmt::format("{} over {} (rig, mesh) pairs: median Spearman {:.3f}, worst chosen / fastest {:.3f} (within 5 % "
                     "in {}, within 10 % in {}), RMS relative error median {:.1f} %, max {:.1f} %, each pair's level divided "
                     "out: median {:.1f} %{}",
                     what, loo.rows.size(), loo.medianSpearman, loo.worstChosenOverFastest, loo.within5Percent,
                     loo.within10Percent, 100 * loo.medianRms, 100 * loo.maxRms,
                     100 * loo.medianRmsWithinPair,
                     loo.pairsWithATieForLeast == 0 ? ""
                                                 : fmt::format("; in {} the least prediction is shared (the slowest of those "
                                                               "plans counted)",
                                                               loo.pairsWithATieForLeast)) +
         (loo.pairsWithOwnPlan == 0 ? ""
                                    : fmt::format("; in {} the profile's own plan was timed (calibrate --plans-under) and is "
                                                  "the one counted{}",
                                                  loo.pairsWithOwnPlan,
                                                  loo.ownPlansByNameOnly == 0
                                                      ? ""
                                                      : fmt::format(" ({} of them found by the profile's name only, in logs "
                                                                    "written before the fingerprint)",
                                                                    loo.ownPlansByNameOnly))) +
         (loo.ownPlanNotLeast == 0 ? ""
                                   : fmt::format("; in {} the log's plan under that name is not the least predicted "
                                                 "(searched under another profile of that name): the least predicted counted",
                                                 loo.ownPlanNotLeast));
}

// Predicted times this close (relative) are one time: sums of the same prices in another order.
constexpr double kPredictedTie = 1e-9;

// Each (rig, mesh) of `rig` ("" = every rig) in `samples`: its plans predicted by `profile`.
// A pair with a plan labelled as one of `ownPlanLabels` counts that plan where it is among the
// least predicted; where it is not, the pair is counted in *ownPlanNotLeast.
std::vector<HeldOutRig> predictRigs(const std::vector<CalibrationSample>& samples, const std::string& rig,
                                    const DeviceProfile& profile, const std::vector<std::string>& ownPlanLabels = {},
                                    size_t* ownPlanNotLeast = nullptr) {
  // One choice per (rig, request, mesh), in the samples' order; a rig timed under several
  // requests names the request in its row.
  std::vector<std::tuple<std::string, std::string, std::string>> keys;
  std::map<std::string, std::set<std::string>> requestsOf;
  for (const auto& s : samples)
    if (!s.rig.empty() && (rig.empty() || s.rig == rig)) {
      requestsOf[s.rig].insert(s.request);
      if (std::find(keys.begin(), keys.end(), std::make_tuple(s.rig, s.request, s.mesh)) == keys.end())
        keys.emplace_back(s.rig, s.request, s.mesh);
    }
  std::vector<HeldOutRig> rows;
  for (const auto& [r, request, mesh] : keys) {
    HeldOutRig h;
    h.rig = requestsOf[r].size() > 1 ? fmt::format("{} ({})", r, request) : r;
    h.mesh = mesh;
    // Plans of the same term amounts (one plan timed twice, or two programs the model cannot tell
    // apart) are predicted and ranked once, at their first timing: their index. The fastest and the
    // profile's own plan are taken from every timing.
    std::map<TermAmounts, size_t> seen;
    constexpr size_t kNone = size_t(-1);
    size_t own = kNone;  // the profile's own plan, where the log timed it
    bool ownByNameOnly = false;  // found by a label after the first of ownPlanLabels
    double ownNs = NAN, fastestNs = INFINITY;
    std::string ownLabel, ownProgram;
    // A program the log timed in several runs (each plan's alternatives are one run) counts at its
    // best: on a CPU device a whole run can drift 20-60 % (bench/data/lavapipe-many-inputs30), and
    // the own plan at its run's time against the fastest of every run would read drift as a miss.
    std::map<std::string, double> bestOfProgram;
    // (Structured bindings are named through references: clang cannot capture them before C++20.)
    const std::string &pairRig = r, &pairRequest = request, &pairMesh = mesh;
    auto isPlanOfPair = [&](const CalibrationSample& s) {
      return s.rig == pairRig && s.request == pairRequest && s.mesh == pairMesh && isPlanSample(s) && s.validated &&
             s.measuredNs > 0;
    };
    for (const auto& s : samples)
      if (isPlanOfPair(s) && !s.program.empty()) {
        auto [it, added] = bestOfProgram.emplace(s.program, s.measuredNs);
        if (!added) it->second = std::min(it->second, s.measuredNs);
      }
    for (const auto& s : samples) {
      if (!isPlanOfPair(s)) continue;
      const auto [kept, added] = seen.emplace(s.amounts, h.measured.size());
      if (s.measuredNs < fastestNs) fastestNs = s.measuredNs, h.fastest = kept->second;
      if (const auto label = std::find(ownPlanLabels.begin(), ownPlanLabels.end(), s.label);
          own == kNone && label != ownPlanLabels.end()) {
        own = kept->second;
        ownNs = s.program.empty() ? s.measuredNs : bestOfProgram.at(s.program);
        ownLabel = s.label;
        ownProgram = s.program;
        ownByNameOnly = label != ownPlanLabels.begin();
      }
      if (!added) {
        ++h.timings[kept->second];
        continue;
      }
      h.labels.push_back(s.label);
      h.programs.push_back(s.program);
      h.timings.push_back(1);
      DeviceProfile at = profile;
      at.workload = s.workload;
      h.predicted.push_back(at.predictNanoseconds(s.amounts, s.vertices));
      h.measured.push_back(s.program.empty() ? s.measuredNs : bestOfProgram.at(s.program));
    }
    h.plans = h.measured.size();
    if (h.plans == 0) continue;
    double sq = 0;
    for (size_t i = 0; i < h.plans; ++i) {
      const double rel = (h.predicted[i] - h.measured[i]) / h.measured[i];
      sq += rel * rel;
    }
    h.rmsRelativeError = std::sqrt(sq / double(h.plans));
    double logLevel = 0;
    for (size_t i = 0; i < h.plans; ++i) logLevel += std::log(h.predicted[i] / h.measured[i]);
    h.level = std::exp(logLevel / double(h.plans));
    double within = 0;
    for (size_t i = 0; i < h.plans; ++i) {
      const double rel = (h.predicted[i] / h.level - h.measured[i]) / h.measured[i];
      within += rel * rel;
    }
    h.rmsWithinPair = std::sqrt(within / double(h.plans));
    // The chosen plan: the least predicted; where several share it, the slowest of them (which
    // one the search returns depends on the order it meets them, not on the profile).
    const double least = *std::min_element(h.predicted.begin(), h.predicted.end());
    size_t chosen = 0;
    for (size_t i = 0; i < h.plans; ++i)
      if (h.predicted[i] <= least * (1 + kPredictedTie)) {
        if (h.tiedForLeast++ == 0 || h.measured[i] > h.measured[chosen]) chosen = i;
      }
    // The log timed the plan the profile's search returned: that one, unless another profile of
    // the same name chose it (then it need not be the least predicted here).
    double chosenNs = h.measured[chosen];
    if (own != kNone) {
      if (h.predicted[own] <= least * (1 + kPredictedTie)) {
        chosen = own;
        chosenNs = ownNs;
        h.labels[own] = ownLabel;
        h.programs[own] = ownProgram;
        h.ownPlan = true;
        h.ownPlanByNameOnly = ownByNameOnly;
      } else if (ownPlanNotLeast) {
        ++*ownPlanNotLeast;
      }
    }
    h.chosen = chosen;
    h.chosenNs = chosenNs;
    h.chosenOverFastest = chosenNs / fastestNs;
    h.spearman = spearmanWithinSpread(h.predicted, h.measured, 0.005);
    rows.push_back(std::move(h));
  }
  return rows;
}

LeaveOneRigOut summarise(std::vector<HeldOutRig> rows) {
  LeaveOneRigOut out;
  out.rows = std::move(rows);
  std::vector<double> rho, rms, within;
  for (const auto& h : out.rows) {
    within.push_back(h.rmsWithinPair);
    if (h.ownPlan) ++out.pairsWithOwnPlan, out.ownPlansByNameOnly += h.ownPlanByNameOnly;
    else if (h.tiedForLeast > 1) ++out.pairsWithATieForLeast;
    rho.push_back(h.spearman);
    rms.push_back(h.rmsRelativeError);
    if (!(out.worstChosenOverFastest >= h.chosenOverFastest)) out.worstChosenOverFastest = h.chosenOverFastest;
    out.within5Percent += h.chosenOverFastest <= 1.05;
    out.within10Percent += h.chosenOverFastest <= 1.10;
    if (!(out.maxRms >= h.rmsRelativeError)) out.maxRms = h.rmsRelativeError;
  }
  out.medianSpearman = medianOfFinite(rho);
  out.medianRms = medianOfFinite(rms);
  out.medianRmsWithinPair = medianOfFinite(within);
  return out;
}

}  // namespace

LeaveOneRigOut leaveOneRigOut(const std::vector<CalibrationSample>& samples, const std::string& deviceName,
                              double workloadVertices, double nearBestPower, const FitOptions& fit) {
  std::set<std::string> rigs;
  for (const auto& s : samples)
    if (!s.rig.empty()) rigs.insert(s.rig);
  if (rigs.size() < 2) return {};
  std::vector<HeldOutRig> rows;
  for (const auto& rig : rigs) {
    std::vector<CalibrationSample> rest;
    for (const auto& s : samples)
      if (s.rig != rig) rest.push_back(s);
    const DeviceProfile profile = fitDeviceProfile(rest, deviceName, workloadVertices, nearBestPower, fit);
    for (auto& h : predictRigs(samples, rig, profile)) rows.push_back(std::move(h));
  }
  return summarise(std::move(rows));
}

LeaveOneRigOut checkHeldOut(const std::vector<CalibrationSample>& heldOut, const DeviceProfile& profile,
                            const std::vector<std::string>& ownPlanLabels) {
  size_t notLeast = 0;
  LeaveOneRigOut out = summarise(predictRigs(heldOut, "", profile, ownPlanLabels, &notLeast));
  out.ownPlanNotLeast = notLeast;
  return out;
}

std::string planUnderLabel(const std::string& profilePath) {
  return fmt::format("plan under {}@{}: ", std::filesystem::path(profilePath).stem().string(),
                     sha256Hex(readInputFile(profilePath)).substr(0, kProfileFingerprintDigits));
}

std::vector<std::string> ownPlanLabels(const std::string& profilePath) {
  const std::string exact = planUnderLabel(profilePath);
  return {exact + "generated", exact.substr(0, exact.rfind('@')) + ": generated"};
}

namespace {

// One table of held-out predictions (rig, mesh, plans and the figures), then its summary.
std::string heldOutTable(const LeaveOneRigOut& t, const char* what, const char* meaning, const char* rigColumn) {
  if (t.rows.empty()) return "";
  std::string s = fmt::format("\n{}: {}\n\n| {} | mesh | plans | Spearman | chosen / fastest | RMS relative error | "
                              "level (predicted / measured) | RMS, the level divided out |\n"
                              "|---|---|---:|---:|---:|---:|---:|---:|\n",
                              what, meaning, rigColumn);
  for (const auto& h : t.rows)
    s += fmt::format("| {} | {} | {} | {:.3f} | {:.3f}{} | {:.1f} % | {:.3f} | {:.1f} % |\n", h.rig, h.mesh, h.plans, h.spearman,
                     h.chosenOverFastest,
                     h.ownPlan            ? std::string(" (its plan)")
                     : h.tiedForLeast > 1 ? fmt::format(" ({} tied)", h.tiedForLeast)
                                          : std::string(),
                     100 * h.rmsRelativeError, h.level, 100 * h.rmsWithinPair);
  return s + heldOutSummary(t, what) + "\n";
}

}  // namespace

std::string formatLeaveOneRigOut(const LeaveOneRigOut& loo) {
  return heldOutTable(loo, "leave-one-rig-out", "each rig's plans predicted by the profile fitted without that rig",
                      "held-out rig");
}

std::string formatHeldOutCheck(const LeaveOneRigOut& check) {
  return heldOutTable(check, "held-out check", "rigs and requests no fit saw, their plans predicted by the profile", "rig");
}

std::string formatHeldOutPlans(const LeaveOneRigOut& check, const char* what) {
  if (check.rows.empty()) return "";
  std::string s = fmt::format(
      "\n{}, every plan: each pair's plans by predicted time; predicted / measured over the pair's level is the error a "
      "choice turns on\n\n| rig | mesh | plan | program | predicted ns | measured ns | predicted / measured | over the level "
      "| |\n|---|---|---|---|---:|---:|---:|---:|---|\n",
      what);
  for (const auto& h : check.rows) {
    std::vector<size_t> order(h.plans);
    std::iota(order.begin(), order.end(), size_t(0));
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return h.predicted[a] < h.predicted[b]; });
    for (size_t i : order) {
      std::string marks = i == h.chosen ? (h.ownPlan ? "chosen (its plan)" : "chosen") : "";
      if (i == h.fastest) marks += marks.empty() ? "fastest" : ", fastest";
      if (h.timings[i] > 1) marks += fmt::format("{}{} timings alike", marks.empty() ? "" : ", ", h.timings[i]);
      const double measured = i == h.chosen ? h.chosenNs : h.measured[i];
      const double ratio = h.predicted[i] / measured;
      s += fmt::format("| {} | {} | {} | {} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | {} |\n", h.rig, h.mesh, h.labels[i],
                       h.programs[i].empty() ? "—" : h.programs[i], h.predicted[i], measured, ratio, ratio / h.level,
                       marks);
    }
  }
  return s;
}

std::vector<CalibrationSample> parseCalibrationSamples(std::istream& table, const std::map<std::string, double>& meshVertices,
                                                       const std::string& request) {
  std::vector<CalibrationSample> samples;
  // Columns are found by their header ("| mesh | rig | program | arithmetic | ... |"), so logs
  // written before a term or the workload columns existed still read (an absent term: 0).
  std::map<std::string, size_t> column;
  auto at = [&](const std::vector<std::string>& cells, const std::string& name) -> const std::string* {
    auto c = column.find(name);
    return c == column.end() || c->second >= cells.size() ? nullptr : &cells[c->second];
  };
  std::string line;
  while (std::getline(table, line)) {
    std::vector<std::string> cells;
    std::stringstream row(line);
    for (std::string cell; std::getline(row, cell, '|');) {
      const size_t a = cell.find_first_not_of(' '), b = cell.find_last_not_of(' ');
      cells.push_back(a == std::string::npos ? "" : cell.substr(a, b - a + 1));
    }
    if (cells.size() > 4 && cells[1] == "mesh" && cells[2] == "rig" && cells[3] == "program") {
      column.clear();
      for (size_t i = 1; i < cells.size(); ++i) column[cells[i]] = i;
      continue;
    }
    const std::string* measured = at(cells, "measured ns/vertex");
    if (!measured || cells.size() < 4) continue;
    const std::string* jpw = at(cells, "joints per warp");
    const std::string* perDraw = at(cells, "vertices per draw");
    if (!perDraw && !meshVertices.count(cells[1])) continue;
    CalibrationSample s;
    s.mesh = cells[1];
    try {
      s.vertices = perDraw ? std::stod(*perDraw) : meshVertices.at(s.mesh);
      if (jpw) s.workload.jointsPerWarp = std::stod(*jpw);
    } catch (const std::exception&) {
      continue;
    }
    if (perDraw) s.workload.verticesPerDraw = s.vertices;
    s.rig = cells[2] == "—" ? "" : cells[2];
    s.request = request;
    s.label = cells[3];
    s.fitted = s.label.rfind("checked plan", 0) != 0;
    // A fixed term a log predates is every program's: 1 (`fragments`, since session 18).
    s.amounts[kTermFragments] = 1;
    try {
      for (int t = 0; t < kTermCount; ++t)
        if (const std::string* amount = at(cells, termName(t))) s.amounts[size_t(t)] = std::stoll(*amount);
      s.measuredNs = std::stod(*measured);
    } catch (const std::exception&) {
      continue;  // a row that failed ("FAILED, not timed")
    }
    if (!std::isfinite(s.vertices) || !std::isfinite(s.workload.jointsPerWarp) || !std::isfinite(s.measuredNs)) continue;
    // Optional columns (later logs): "—" or absent reads as not recorded.
    auto optional = [&](const char* name, double& into) {
      if (const std::string* v = at(cells, name); v && *v != "—") {
        try {  // a figure that is not a finite number reads as not recorded
          const double x = std::stod(*v);
          if (std::isfinite(x)) into = x;
        } catch (const std::exception&) {
        }
      }
    };
    optional("median round ns/vertex", s.medianRoundNs);
    optional("shaded vertices per vertex", s.shadedPerVertex);
    optional("fragments per vertex", s.workload.fragmentsPerVertex);
    optional("palette entries per warp", s.workload.paletteEntriesPerWarp);
    if (const std::string* id = at(cells, "SPIR-V SHA-256"); id && *id != "—") s.program = *id;
    if (const std::string* st = at(cells, "driver statistics"); st && *st != "—") s.driverStatistics = *st;
    s.validated = true;
    samples.push_back(s);
  }
  return samples;
}

// A rig as the samples name it: its file name, with a glTF rig's "#mesh/primitive".
std::string rigLabel(const std::string& rig) {
  const size_t hash = isGltfPath(rig) ? rig.rfind('#') : std::string::npos;
  const std::string file = hash == std::string::npos ? rig : rig.substr(0, hash);
  return std::filesystem::path(file).filename().string() + (hash == std::string::npos ? "" : rig.substr(hash));
}

std::vector<std::string> rigMeshes(const std::string& rig, const std::vector<std::string>& meshes) {
  if (isGltfPath(rig)) return {kOwnMesh};
  return meshes;
}

GpuBenchOptions rigBenchOptions(const CalibrationOptions& opts, const RigTiming& t) {
  GpuBenchOptions bo;
  bo.render.gen = opts.plans;
  bo.render.gen.rigPath = t.rig;
  if (!t.fragment.empty()) bo.render.gen.fragmentPath = t.fragment;
  bo.render.gen.deviceProfilePath = t.profilePath;
  bo.render.device = opts.device;
  // The plans this device's limits allow (as bench --device and validate --device use):
  // a palette that only fits the device's larger uniform block is a plan users get there.
  bo.render.limits.fromDevice = true;
  bo.render.validationLayers = opts.validationLayers;
  bo.render.mesh = t.mesh == "small" ? "head" : t.mesh;
  bo.render.width = opts.width;
  bo.render.height = opts.height;
  bo.floor = t.fitted;  // the floors are the same programs under any profile
  bo.rasterOn = !t.cpuDevice;
  bo.rasterOff = t.cpuDevice;
  bo.drawsPerFrame = opts.drawsPerFrame;
  bo.minVerticesPerFrame = opts.minVerticesPerFrame;
  bo.frames = opts.frames;
  bo.rounds = opts.rounds;
  bo.inputMemory = opts.inputMemory;
  return bo;
}

CalibrationReport calibrateDevice(const CalibrationOptions& opts) {
  if (opts.meshes.empty()) throw std::invalid_argument("calibration: no mesh");
  timeCpuDevicesSingleThreaded();
  rt::HarnessOptions ho;
  ho.deviceName = opts.device;
  ho.validation = opts.validationLayers;
  rt::Harness harness(ho);
  rt::Renderer renderer(harness);
  CalibrationReport rep;
  rep.device = harness.deviceName();
  rep.driver = renderer.driver();
  const bool hostClock = isCpuDevice(rep.device);
  // A CPU device (lavapipe) runs work outside the timestamps' reach (deferred binning,
  // rasterizer threads), and its wall time counts whatever else the machine runs: the
  // process's CPU time over submit-to-fence counts the work itself. Its programs draw with
  // the rasterizer discarded, every output captured: on a CPU the target's fragment work
  // would otherwise bury the vertex stage (the Dawn face's plans on the head: ~8 us per vertex
  // raster on, bench/data/lavapipe-calibrate-busy.log).
  rep.clock = hostClock ? "process CPU time over submit-to-fence, rasterizer discarded (a CPU device)" : "GPU timestamps";
  rep.clock += fmt::format(" over {} draws per frame (a smaller mesh more: at least {} vertices), median of {} frames, best of {} rounds{}",
                           opts.drawsPerFrame, opts.minVerticesPerFrame, opts.frames, std::max<uint32_t>(1, opts.rounds),
                           opts.processes > 1 ? fmt::format(" in each of {} processes", opts.processes) : "");
  double GpuBenchRow::*const clock = hostClock ? &GpuBenchRow::rasterOffCpuNsPerVertex : &GpuBenchRow::rasterOnNsPerVertex;
  std::string inputMemory;  // inputMemoryLine of the first timing, for the clock's line

  const auto stopped = [&] { return opts.stop && opts.stop->load(); };
  for (const auto& meshName : opts.meshes) {
    if (stopped()) break;
    ProbeMesh m = probeMesh(meshName);
    std::vector<Probe> probes = opts.probes ? makeProbes(m) : std::vector<Probe>{};
    // The probes' per-vertex palette indices are this mesh's skin: its workload is theirs.
    const Workload probeWorkload =
        measureWorkload(m.mesh, m.indices, true, -1, fmt::format("probe mesh '{}' ({} vertices)", meshName, m.mesh.vertexCount));
    for (auto& p : probes) {
      if (stopped()) break;
      CalibrationSample s;
      s.label = p.label;
      s.mesh = meshName;
      s.vertices = double(m.mesh.vertexCount);
      s.workload = probeWorkload;
      if (p.addresses.vertexCount) {  // a palette probe: the addresses it reads, counted as a skin's are
        const Workload a = measureWorkload(p.addresses, m.indices, false, -1, "");
        s.workload.jointsPerWarp = a.jointsPerWarp;
        s.workload.paletteEntriesPerWarp = a.paletteEntriesPerWarp;
      }
      s.amounts = p.amounts;
      try {
        GlslShader renderShader = compileProbe(Stage::Vertex, probeGlsl(p, false), p.label);
        std::vector<uint32_t> render = renderShader.spirv();
        std::vector<uint32_t> capture = compileProbe(Stage::Vertex, probeGlsl(p, true), p.label).spirv();
        s.amounts[kTermArithmetic] = measureSpirv(optimizeSpirv(render, TargetEnv::Vulkan1_1)).total;
        p.inputs.vertexCount = static_cast<uint32_t>(m.mesh.vertexCount);
        p.inputs.declared = declaredDescriptors(renderShader.descriptors());
        rt::RunRequest run;
        static_cast<rt::ProgramInputs&>(run) = p.inputs;
        run.spirv = capture;
        run.capture.strideBytes = uint32_t(16 * (1 + p.outputs));
        s.failure = compareCapture(p, harness.run(run).captured, m.mesh.vertexCount);
        s.validated = s.failure.empty();
        if (s.validated) {
          rt::DrawRequest req;
          static_cast<rt::ProgramInputs&>(req) = p.inputs;
          req.memory = opts.inputMemory;
          req.vertexSpirv = hostClock ? capture : render;
          req.fragmentSpirv = compileProbe(Stage::Fragment, probeFragmentGlsl(p), p.label).spirv();
          req.indices = m.indices;
          req.width = opts.width;
          req.height = opts.height;
          rt::TimingRequest t;
          t.drawsPerFrame = drawsPerFrame(opts.drawsPerFrame, opts.minVerticesPerFrame, m.mesh.vertexCount);
          t.frames = opts.frames + 1;
          t.rasterize = !hostClock;
          t.captureStride = run.capture.strideBytes;
          std::vector<double> rounds;
          for (uint32_t r = 0; r < std::max<uint32_t>(1, opts.rounds); ++r) {
            rt::Timing tm = renderer.time(req, t);
            if (inputMemory.empty()) inputMemory = inputMemoryLine(opts.inputMemory, tm.inputMemory);
            const std::vector<double>& clock = hostClock ? tm.cpuNs : tm.frameNs;
            std::vector<double> frames(clock.begin() + 1, clock.end());
            rounds.push_back(medianOf(frames) / (double(t.drawsPerFrame) * double(tm.verticesPerDraw)));
            if (s.driverStatistics.empty()) s.driverStatistics = describeDriverStatistics(tm.vertexStatistics);
          }
          s.measuredNs = *std::min_element(rounds.begin(), rounds.end());
          s.medianRoundNs = medianOf(rounds);
          if (auto st = renderer.statistics(req)) {
            s.shadedPerVertex = double(st->vertexInvocations) / s.vertices;
            s.workload.fragmentsPerVertex = double(st->fragmentInvocations) / s.vertices;
          }
        }
      } catch (const std::exception& e) {
        s.validated = false;
        s.failure = e.what();
      }
      rep.samples.push_back(std::move(s));
    }
  }
  // Generated plans and the floors: bench's programs (each plan validated on the device
  // before it is timed). Without a profile a generation does not count its plans' buffer and
  // indexed loads; one that prices arithmetic alone chooses the slot model's plans
  // (docs/device-profiles.md) and counts them.
  auto temporaryProfile = [](const std::string& tag, const std::string& yaml) {
    std::string path = (std::filesystem::temp_directory_path() / fmt::format("shadergen-{}-{}.yaml", tag, ::getpid())).string();
    std::ofstream(path) << yaml;
    return path;
  };
  struct Remove {
    std::vector<std::string> paths;
    ~Remove() {
      for (const auto& p : paths) std::filesystem::remove_all(p);
    }
  } remove;
  // The rigs: the given ones, then the corpus's random rigs, each with its own request.
  std::vector<std::string> rigs = opts.rigs;
  std::map<std::string, std::string> fragmentOf;
  if (opts.corpus > 0) {
    const std::string dir =
        (std::filesystem::temp_directory_path() / fmt::format("shadergen-corpus-{}", ::getpid())).string();
    remove.paths.push_back(dir);
    for (const CorpusCase& c : randomCorpus(opts.corpus, opts.corpusSeed)) {
      const CorpusFiles f = writeCorpusCase(c, dir);
      rigs.push_back(f.rig);
      fragmentOf[f.rig] = f.fragment;
    }
  }
  auto benchRigs = [&](const std::string& profilePath, bool fitted, const std::string& prefix) {
    for (const auto& rig : rigs)
      for (const auto& meshName : rigMeshes(rig, opts.meshes)) {
        if (stopped()) return;
        const RigTiming timing{rig, fragmentOf.count(rig) ? fragmentOf.at(rig) : "", meshName, profilePath, fitted, hostClock};
        GpuBenchReport br;
        try {
          br = opts.timeRig ? opts.timeRig(timing) : runGpuBench(rigBenchOptions(opts, timing));
        } catch (const InputError& e) {
          if (!fragmentOf.count(rig)) throw;  // a given rig's error is the user's to see
          rep.notes.push_back(fmt::format("{} on '{}' left out: {}", std::filesystem::path(rig).filename().string(),
                                          meshName, e.what()));
          continue;
        }
        if (inputMemory.empty()) inputMemory = br.inputMemory;
        // Each rig's own: with a memory budget it says what the process held in the inputs' heap
        // then, so a many-rig run shows whether anything accumulates from one rig to the next.
        if (!br.inputMemory.empty()) rep.inputMemoryByRig.push_back(fmt::format("{} on '{}', {}", rigLabel(rig), meshName, br.inputMemory));
        if (!fitted) {  // the plans' predicted against measured time, by this calibration's clock
          const PredictionCheck pc = checkPredictions(br.rows, clock);
          CalibrationCheck c;
          c.rig = rigLabel(rig);
          c.mesh = meshName;
          c.plans = pc.plans;
          c.spearman = pc.spearman;
          c.generatedOverFastest = pc.generatedOverFastest;
          if (!std::isnan(pc.generatedOverFastest)) c.byRound = generatedOverFastestByRound(br.rows);
          rep.checks.push_back(c);
        }
        for (const auto& row : br.rows) {
          if (!row.hasAmounts) continue;
          CalibrationSample s;
          s.label = (row.hasCost ? prefix : "") + row.label;
          s.mesh = meshName;
          s.vertices = double(br.vertices);
          s.rig = rigLabel(rig);
          s.workload = br.workload;
          s.fitted = fitted;
          s.amounts = row.amounts;
          s.validated = row.validation == "pass" || (!row.hasCost && row.*clock > 0);
          s.failure = s.validated ? "" : row.validation;
          s.measuredNs = !s.validated ? -1 : row.*clock;
          // bench keeps each round by its prediction clock, which the raster modes above make `clock`
          if (s.validated && !row.roundNsPerVertex.empty()) s.medianRoundNs = medianOf(row.roundNsPerVertex);
          s.shadedPerVertex = br.shadedVerticesPerVertex;
          s.program = row.program;
          s.driverStatistics = describeDriverStatistics(row.driverStatistics);
          rep.samples.push_back(std::move(s));
        }
      }
  };
  if (!rigs.empty()) {
    std::string slots = opts.plans.deviceProfilePath;
    if (slots.empty()) {
      slots = temporaryProfile("slots", "device: instruction slots\nweights:\n  arithmetic: 0.000001\n");
      remove.paths.push_back(slots);
    }
    benchRigs(slots, true, "plan: ");
    for (const auto& profile : opts.plansUnder)
      benchRigs(profile, true, planUnderLabel(profile));
  }
  if (!inputMemory.empty()) rep.clock += "; " + inputMemory;
  double workload = 0;
  for (const auto& s : rep.samples)
    if (s.mesh == opts.meshes.front()) workload = s.vertices;
  rep.nearBestPower = rigs.empty() ? 0 : opts.nearBestPower;
  rep.outsidePipes = opts.fit.outsidePipes.value_or(outsidePipesOf(opts.fit.form));
  rep.floors = opts.fit.floors;
  if (stopped() && std::none_of(rep.samples.begin(), rep.samples.end(), [](const CalibrationSample& s) { return s.validated; }))
    throw std::runtime_error("calibration: interrupted before anything was timed: nothing to fit");
  rep.profile =
      fitDeviceProfile(rep.samples, rep.device + " (" + rep.driver + ")", workload, opts.nearBestPower, opts.fit);
  // The check: each rig's plans under the fitted profile. The plans a profile chooses are
  // where its errors cost time, so each refit adds them to the fit; the last check's plans
  // are never fitted.
  for (uint32_t round = 0; opts.check && !rigs.empty() && !stopped(); ++round) {
    const std::string fitted = temporaryProfile(fmt::format("fit{}", round + 1), deviceProfileYaml(rep));
    remove.paths.push_back(fitted);
    rep.checks.clear();
    const bool last = round == opts.refits;
    benchRigs(fitted, false, last ? "checked plan: " : fmt::format("plan under fit {}: ", round + 1));
    if (last) break;
    for (auto& s : rep.samples) s.fitted = true;
    rep.profile = fitDeviceProfile(rep.samples, rep.profile.device, workload, opts.nearBestPower, opts.fit);
  }
  std::vector<std::string> fitMeshes = opts.meshes;
  for (const auto& rig : rigs)
    if (isGltfPath(rig) && std::find(fitMeshes.begin(), fitMeshes.end(), kOwnMesh) == fitMeshes.end())
      fitMeshes.push_back(kOwnMesh);
  rep.fits = evaluateFit(rep.samples, rep.profile, fitMeshes);
  rep.heldOut = leaveOneRigOut(rep.samples, rep.profile.device, workload, rep.nearBestPower, opts.fit);
  if (stopped())
    rep.notes.push_back(fmt::format("interrupted: {} samples were timed and are fitted; the probes, rigs and checks after "
                                    "the interruption were not timed",
                                    rep.samples.size()));
  return rep;
}

namespace {

// A roofline's pipes (none for an additive profile).
std::string pipeLines(const std::vector<DeviceProfile::Pipe>& pipes) {
  if (pipes.empty()) return "";
  std::string s = "pipes:  # overlapped: a program takes the additive part plus its slowest pipe\n";
  for (const auto& pipe : pipes) {
    s += fmt::format("  {}:\n", pipe.name);
    bool any = false;
    for (int t = 0; t < kTermCount; ++t)
      if (pipe.nanoseconds[size_t(t)] > 0) s += fmt::format("    {}: {:.6g}\n", termName(t), pipe.nanoseconds[size_t(t)]), any = true;
    if (!any) s.replace(s.size() - 1, 1, " {}\n");
  }
  return s;
}

std::string additiveLines(const std::array<double, kTermCount>& nanoseconds) {
  std::string s = "weights:\n";
  for (int t = 0; t < kTermCount; ++t) s += fmt::format("  {}: {:.6g}\n", termName(t), nanoseconds[size_t(t)]);
  return s;
}

// The workload scaling, its defaults, the pipes' sum share, the constant cache and the thresholds, shared by every draw size (none
// for an additive profile without scaling: the file then reads as every profile before them).
std::string workloadLines(const DeviceProfile& p) {
  std::string s;
  bool scaled = false;
  for (int t = 0; t < kTermCount; ++t)
    if (p.scaledBy[size_t(t)] != kFeatureNone) {
      if (!scaled) s += "scaled_by:  # a term's weights times the mesh's workload feature\n";
      s += fmt::format("  {}: {}\n", termName(t), featureName(p.scaledBy[size_t(t)]));
      scaled = true;
    }
  bool defaults = false;
  for (int f = 1; f < kFeatureCount; ++f)
    if (p.workloadDefaults[size_t(f)] > 0) {
      if (!defaults) s += "workload_defaults:  # where the mesh is unknown\n";
      s += fmt::format("  {}: {:g}\n", featureName(f), p.workloadDefaults[size_t(f)]);
      defaults = true;
    }
  if (p.pipeSumShare > 0)
    s += fmt::format("pipe_sum_share: {:.4g}  # besides its slowest pipe a program pays this share of the others\n", p.pipeSumShare);
  if (p.constantCacheEntries > 0)
    s += fmt::format("constant_cache:  # past this palette footprint per warp, a distinct address costs miss_factor times as much\n"
                     "  entries: {:.10g}\n  miss_factor: {:.6g}\n",
                     p.constantCacheEntries, p.constantCacheMissFactor);
  if (!p.thresholds.empty()) {
    s += "thresholds:  # past `at` units of a term, each unit costs `ns` more per vertex\n";
    for (const DeviceProfile::Threshold& h : p.thresholds) s += fmt::format("  {}: {{ at: {:g}, ns: {:.6g} }}\n", termName(h.term), h.at, h.nanoseconds);
  }
  return s;
}

// Each draw size's weights and pipes (DeviceProfile::drawSizes), indented under it.
std::string drawSizeLines(const DeviceProfile& p) {
  std::string s = fmt::format("vertices_per_draw: {:g}  # where a generation's mesh is unknown\n"
                              "draw_sizes:  # weights fitted at each mesh size; between two, interpolated in log(vertices per draw)\n",
                              p.verticesPerDraw);
  for (const DeviceProfile::DrawSize& d : p.drawSizes) {
    s += fmt::format("  {:g}:\n", d.vertices);
    const std::string lines = additiveLines(d.nanoseconds) + pipeLines(d.pipes);
    for (size_t start = 0, end; start < lines.size(); start = end + 1) {
      end = lines.find('\n', start);
      s += "    " + lines.substr(start, end - start + 1);
    }
  }
  return s;
}

std::string weightLines(const DeviceProfile& p) {
  if (!p.drawSizes.empty()) return drawSizeLines(p) + workloadLines(p);
  std::string s = additiveLines(p.nanoseconds);
  if (p.hasDrawWeights()) {
    s += fmt::format("vertices_per_draw: {:g}\ndraw_weights:\n", p.verticesPerDraw);
    for (int t = 0; t < kTermCount; ++t)
      if (p.drawNanoseconds[size_t(t)] > 0) s += fmt::format("  {}: {:.6g}\n", termName(t), p.drawNanoseconds[size_t(t)]);
  }
  // Pipes and the workload scaling are written whether or not the fit found per-draw costs
  // (before session 17 a profile without them lost its pipes and scaled_by lines).
  return s + pipeLines(p.pipes) + workloadLines(p);
}

std::string fitLine(const CalibrationFit& f) {
  std::string s = fmt::format("fit on '{}': {} samples, RMS relative error {:.1f} %, max {:.1f} %, Spearman {:.3f}", f.mesh,
                              f.samples, 100 * f.rmsRelativeError, 100 * f.maxRelativeError, f.spearman);
  if (f.allSamples > f.samples)
    s += fmt::format("; with the check's plans: {} programs, Spearman {:.3f}", f.allSamples, f.spearmanAll);
  return s;
}

}  // namespace

std::string formatCalibration(const CalibrationReport& r) {
  std::string s = fmt::format("device: {} (driver: {}); clock: {}\n\n| mesh | rig | program | ", r.device, r.driver, r.clock);
  for (int t = 0; t < kTermCount; ++t) s += fmt::format("{} | ", termName(t));
  s += "measured ns/vertex | predicted | joints per warp | vertices per draw | median round ns/vertex | "
       "shaded vertices per vertex | fragments per vertex | palette entries per warp | SPIR-V SHA-256 | driver statistics |\n|---|---|---|";
  for (int t = 0; t < kTermCount; ++t) s += "---:|";
  s += "---:|---:|---:|---:|---:|---:|---:|---:|---|---|\n";
  for (const auto& x : r.samples) {
    s += fmt::format("| {} | {} | {} | ", x.mesh, x.rig.empty() ? "—" : x.rig, x.label);
    for (int t = 0; t < kTermCount; ++t) s += fmt::format("{} | ", x.amounts[size_t(t)]);
    s += x.validated ? fmt::format("{:.4f} | {:.4f} | ", x.measuredNs, x.predictedNs)
                     : fmt::format("FAILED, not timed: {} | — | ", x.failure);
    // The workload it was timed on: the fit scales terms by it, so a log refits (--from-log).
    s += fmt::format("{:.4f} | {:g} | ", x.workload.jointsPerWarp, x.vertices);
    // Its spread: the best round is the measured figure, the median round this one.
    s += x.medianRoundNs >= 0 ? fmt::format("{:.4f} | ", x.medianRoundNs) : "— | ";
    // What the device shaded for one draw of its mesh (raster on): the harness's share of the time.
    s += x.shadedPerVertex >= 0 ? fmt::format("{:.4f} | ", x.shadedPerVertex) : "— | ";
    s += x.workload.fragmentsPerVertex > 0 ? fmt::format("{:.4f} | ", x.workload.fragmentsPerVertex) : "— | ";
    // A warp's palette footprint (shown, not priced): a later fit's feature, kept with the timing.
    s += x.workload.paletteEntriesPerWarp > 0 ? fmt::format("{:.4f} | ", x.workload.paletteEntriesPerWarp) : "— | ";
    // Which SPIR-V was timed: one program timed in two runs (two plans' alternatives) is matched by it.
    s += x.program.empty() ? "— | " : x.program + " | ";
    // What the driver compiled it into, where it says (registers: its occupancy).
    s += x.driverStatistics.empty() ? "— |\n" : x.driverStatistics + " |\n";
  }
  s += "\nfitted (ns per unit per vertex; draw weights: ns per unit per draw):\n" + weightLines(r.profile);
  for (const auto& f : r.fits) s += fitLine(f) + "\n";
  for (const auto& c : r.checks)
    s += fmt::format("check of {} on '{}' under the fitted profile: {} plans, predicted vs measured Spearman {:.3f}; "
                     "the chosen plan takes {:.3f}x the fastest{}\n",
                     c.rig, c.mesh, c.plans, c.spearman, c.generatedOverFastest, describeRoundSpread(c.byRound));
  s += formatLeaveOneRigOut(r.heldOut);
  s += formatHeldOutCheck(r.check);
  for (const auto& m : r.inputMemoryByRig) s += m + "\n";
  for (const auto& n : r.notes) s += "note: " + n + "\n";
  return s;
}

std::string deviceProfileYaml(const CalibrationReport& r) {
  std::string s = "# Measured by `shadergen calibrate` (docs/device-profiles.md): ns per vertex per unit of each\n"
                  "# term (and, under draw_weights, ns per draw), the least-squares fit (Ceres Solver, weights >= 0)\n";
  s += r.floors ? "# of every validated probe's, plan's and floor's time.\n" : "# of every validated probe's and plan's time (not the floors': --no-floors).\n";
  if (r.nearBestPower > 0)
    s += fmt::format("# A rig's plans and floors weighed (its fastest on that mesh / their time)^{:g}.\n", r.nearBestPower);
  s += fmt::format("# clock: {}; driver: {}\n", r.clock, r.driver);
  for (const auto& f : r.fits) s += "# " + fitLine(f) + "\n";
  for (const auto& c : r.checks)
    s += fmt::format("# check of {} on '{}': {} plans, Spearman {:.3f}, chosen plan {:.3f}x the fastest\n", c.rig, c.mesh, c.plans,
                     c.spearman, c.generatedOverFastest);
  if (!r.heldOut.rows.empty()) s += "# " + heldOutSummary(r.heldOut) + "\n";
  if (!r.check.rows.empty()) s += "# " + heldOutSummary(r.check, "held-out check") + "\n";
  if (!r.profile.pipes.empty() || r.nearBestPower >= 0) {
    const ProfileForm form = r.profile.pipes.empty()                                           ? ProfileForm::Additive
                             : r.profile.scaledBy[kTermFragments] == kFeatureFragmentsPerVertex ? ProfileForm::Raster
                                                                                                 : ProfileForm::Roofline;
    std::string outside;
    if (!r.profile.pipes.empty())
      for (int t : r.outsidePipes) outside += (outside.empty() ? " (outside the pipes too: " : ", ") + std::string(termName(t));
    s += fmt::format("# form: {}{}\n", profileFormName(form), outside.empty() ? "" : outside + ")");
  }
  s += fmt::format("device: \"{}\"\nunit: ns\n", r.profile.device);
  return s + weightLines(r.profile);
}

}  // namespace sg

#include "validate/validate.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <map>
#include <random>
#include <set>

#include "runtime/procedural.h"
#include "validate/interpreter.h"
#include "validate/poses.h"

namespace sg {
namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

VkFormat vkFormat(VertexFormat f) {
  switch (f) {
    case VertexFormat::Float32x1: return VK_FORMAT_R32_SFLOAT;
    case VertexFormat::Float32x2: return VK_FORMAT_R32G32_SFLOAT;
    case VertexFormat::Float32x3: return VK_FORMAT_R32G32B32_SFLOAT;
    case VertexFormat::Float32x4: return VK_FORMAT_R32G32B32A32_SFLOAT;
    case VertexFormat::Unorm8x4: return VK_FORMAT_R8G8B8A8_UNORM;
    case VertexFormat::Uint8x4: return VK_FORMAT_R8G8B8A8_UINT;
    case VertexFormat::Unorm16x4: return VK_FORMAT_R16G16B16A16_UNORM;
    case VertexFormat::Uint16x4: return VK_FORMAT_R16G16B16A16_UINT;
    case VertexFormat::Uint32x4: return VK_FORMAT_R32G32B32A32_UINT;
  }
  return VK_FORMAT_UNDEFINED;
}

// The value a format stores for v (what the GPU will read back), as a float.
float quantize(VertexFormat f, float v) {
  switch (f) {
    case VertexFormat::Unorm8x4: return std::round(std::clamp(v, 0.0f, 1.0f) * 255.0f) / 255.0f;
    case VertexFormat::Unorm16x4: return std::round(std::clamp(v, 0.0f, 1.0f) * 65535.0f) / 65535.0f;
    case VertexFormat::Uint8x4: return std::clamp(std::round(v), 0.0f, 255.0f);
    case VertexFormat::Uint16x4: return std::clamp(std::round(v), 0.0f, 65535.0f);
    case VertexFormat::Uint32x4: return std::max(0.0f, std::round(v));
    default: return v;
  }
}

// Writes v in format f at `dst`; returns the bytes written.
size_t putComponent(uint8_t* dst, VertexFormat f, float v) {
  auto put = [&](auto x) {
    std::memcpy(dst, &x, sizeof(x));
    return sizeof(x);
  };
  switch (f) {
    case VertexFormat::Unorm8x4: return put(static_cast<uint8_t>(std::lround(v * 255.0f)));
    case VertexFormat::Uint8x4: return put(static_cast<uint8_t>(v));
    case VertexFormat::Unorm16x4: return put(static_cast<uint16_t>(std::lround(v * 65535.0f)));
    case VertexFormat::Uint16x4: return put(static_cast<uint16_t>(v));
    case VertexFormat::Uint32x4: return put(static_cast<uint32_t>(v));
    default: return put(v);
  }
}

std::string partSemantic(const RigAttribute& a, const ProvidedPart& p, int target) {
  return target >= 0 ? fmt::format("{}[{}]", p.semantic, target) : p.semantic;
}

int swizzleIndex(char c) { return c == 'x' ? 0 : c == 'y' ? 1 : c == 'z' ? 2 : 3; }

// Quantizes, in the mesh, every stream an integer/normalized attribute carries, so the
// reference sees exactly the values the GPU reads.
rt::Mesh quantizedMesh(const Rig& rig, const rt::Mesh& mesh) {
  rt::Mesh m = mesh;
  for (const auto& a : rig.attributes) {
    if (a.format == VertexFormat::Float32x1 || a.format == VertexFormat::Float32x2 ||
        a.format == VertexFormat::Float32x3 || a.format == VertexFormat::Float32x4)
      continue;
    int targets = a.perMorphTarget ? rig.morphTargets() : 1;
    for (int t = 0; t < targets; ++t)
      for (const auto& p : a.provides) {
        auto it = m.streams.find(partSemantic(a, p, a.perMorphTarget ? t : -1));
        if (it == m.streams.end()) continue;
        for (auto& v : it->second)
          for (int c = 0; c < 4; ++c) v[c] = quantize(a.format, v[c]);
      }
  }
  return m;
}

rt::VertexStream buildStream(const Rig& rig, const EmittedInput& in, const rt::Mesh& mesh) {
  const RigAttribute& a = rig.attributes[in.attribute];
  const int n = formatComponents(a.format);
  rt::VertexStream s;
  s.location = static_cast<uint32_t>(in.location);
  s.format = vkFormat(a.format);
  s.stride = static_cast<uint32_t>(formatBytes(a.format));
  // Gather the parts into one flat array of n components per vertex, then encode.
  std::vector<float> comps(mesh.vertexCount * static_cast<size_t>(n), 0.0f);
  for (const auto& p : a.provides) {
    std::string sem = partSemantic(a, p, in.target);
    if (!mesh.has(sem))
      throw InputError(a.loc, fmt::format("mesh '{}' has no data for '{}' (attribute '{}')", mesh.name, sem, a.name));
    const auto& src = mesh.at(sem);
    std::string swz = p.swizzle.empty() ? std::string("xyzw").substr(0, static_cast<size_t>(n)) : p.swizzle;
    for (size_t v = 0; v < mesh.vertexCount; ++v)
      for (size_t k = 0; k < swz.size(); ++k)
        comps[v * static_cast<size_t>(n) + static_cast<size_t>(swizzleIndex(swz[k]))] = src[v][static_cast<int>(k)];
  }
  s.data.resize(mesh.vertexCount * s.stride);
  uint8_t* dst = s.data.data();
  for (float x : comps) dst += putComponent(dst, a.format, x);
  return s;
}

// Copies `count` floats of `src` to the block at `offset`.
void putFloats(std::vector<uint8_t>& block, uint32_t offset, const float* src, size_t count) {
  if (offset + count * 4 > block.size()) throw std::logic_error("uniform write past the block");
  std::memcpy(block.data() + offset, src, count * 4);
}

void putMat4(std::vector<uint8_t>& block, uint32_t offset, const glm::mat4& m, uint32_t matrixStride) {
  for (int c = 0; c < 4; ++c) putFloats(block, offset + static_cast<uint32_t>(c) * matrixStride, &m[c][0], 4);
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

}  // namespace

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

namespace {

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

namespace {

// Which side produced a NaN or infinity, where, and the provided values it was computed from.
std::string nonFiniteReport(Interpreter& reference, const EmittedOutput& o, size_t v, int c, double gpu, double ref) {
  bool g = !std::isfinite(gpu), r = !std::isfinite(ref);
  std::string side = g && r ? "GPU and reference" : g ? "GPU" : "reference";
  auto show = [](double x) { return std::isnan(x) ? std::string("nan") : fmt::format("{}", x); };  // no "-nan"
  std::string s = fmt::format("{} gives {} at vertex {}, output {} component {} (GPU {}, reference {})", side,
                              show(g ? gpu : ref), v, o.name, c, show(gpu), show(ref));
  for (const auto& sem : o.semantics) {
    try {
      auto inputs = reference.inputsAt(sem, v);
      s += fmt::format("\n      inputs of {}:", sem);
      for (const auto& in : inputs) s += "\n        " + in;
    } catch (const std::exception&) {
    }
  }
  return s;
}

}  // namespace

void limitActiveTargets(const Rig& rig, std::vector<rt::Pose>& poses, uint32_t seed) {
  for (const auto& u : rig.uniforms) {
    if (u.semantic != "morph.active_targets") continue;
    for (size_t k = 0; k < poses.size(); ++k) {
      auto& w = poses[k].morphWeights;
      std::vector<size_t> order(w.size());
      for (size_t i = 0; i < order.size(); ++i) order[i] = i;
      std::mt19937 rng(seed * 7919u + static_cast<uint32_t>(k));
      for (size_t i = order.size(); i > 1; --i) std::swap(order[i - 1], order[rng() % i]);  // portable shuffle
      const auto keep = static_cast<size_t>(std::clamp<int64_t>(rig.param("max_active_targets", u.arraySize), 0, u.arraySize));
      for (size_t i = keep; i < order.size(); ++i) w[order[i]] = 0.0f;
    }
  }
}

rt::Mesh quantizeForRig(const Rig& rig, const rt::Mesh& mesh) { return quantizedMesh(rig, mesh); }

rt::VertexStream vertexStream(const Rig& rig, const EmittedInput& in, const rt::Mesh& mesh) {
  return buildStream(rig, in, mesh);
}

std::vector<uint8_t> uniformBlock(const Rig& rig, const RuleSet& rules, const EmittedGlsl& glsl, const SpirvModule& spv,
                                  const rt::Mesh& mesh, const rt::Pose& pose) {
  std::vector<rt::Pose> poses{pose};
  drawDeclaredUniforms(poses, rig, rules);
  UniformValues values = uniformValues(rig, rules, shapeOfRig(rig, rules), mesh, poses[0]);
  addActiveTargets(rig, poses[0], values);
  return buildUniforms(rig, glsl, spv, values);
}

ValidationScene proceduralScene(const Rig& rig, const std::string& mesh, uint32_t seed, int poses) {
  rt::MeshOptions mo;
  mo.morphTargets = rig.morphTargets();
  auto moved = [&](const char* a) {
    return std::find(rig.morphedAttributes.begin(), rig.morphedAttributes.end(), a) != rig.morphedAttributes.end();
  };
  mo.morphNormals = moved("normal");
  mo.morphTangents = moved("tangent");
  mo.influences = static_cast<int>(rig.param("influences"));
  mo.bones = std::max<int>(1, static_cast<int>(rig.param("bones")));
  ValidationScene s;
  if (mesh == "head") {
    s.mesh = rt::makeHead(40, 48, mo);
  } else if (mesh == "limb") {
    s.mesh = rt::makeLimb(32, 24, mo);
  } else if (mesh == "dawn") {
    s.mesh = rt::makeHead(299, 599, mo);
    s.mesh.name = "dawn";  // makeHead names it "head"
  } else {
    throw InputError(SourceLoc{}, fmt::format("unknown mesh '{}' (head, limb, dawn)", mesh));
  }
  s.shape = rt::rigShapeFor(mo);
  for (const auto& u : rig.uniforms)
    if (u.semantic == "model.matrix") s.shape.hasModelMatrix = true;
  s.shape.uniformScale = rig.param("uniform_scale") != 0;
  // Hostile by default: non-uniform scale unless the rig declares it never scales so.
  const rt::PoseOptions po = rt::hostilePoseOptions(rig.param("uniform_scale") != 0);
  for (int i = 0; i < poses; ++i) s.poses.push_back(rt::makeRandomPose(s.shape, seed + static_cast<uint32_t>(i), po));
  limitActiveTargets(rig, s.poses, seed);
  return s;
}

Validator::Validator(const ValidateOptions& opts) : opts_(opts) {
  rt::HarnessOptions ho;
  ho.deviceName = opts.device;
  ho.validation = opts.validationLayers;
  harness_ = std::make_unique<rt::Harness>(ho);
}

Validator::~Validator() = default;

RunReport Validator::runOne(const GenerateResult& r, const ValidationScene& scene, const std::string& label) {
  std::vector<rt::Pose> poses = scene.poses;
  drawDeclaredUniforms(poses, r.in.rig, r.in.rules);
  return runQuantized(r, quantizedMesh(r.in.rig, scene.mesh), scene, poses, label);
}

RunReport Validator::runQuantized(const GenerateResult& r, const rt::Mesh& mesh, const ValidationScene& scene,
                                  const std::vector<rt::Pose>& poses, const std::string& label) {
  (void)scene;
  RunReport rep;
  rep.label = label;
  rep.planCost = r.plan.cost;
  for (int a : r.plan.actions) rep.rules.push_back(r.in.problem.actions[a].name);
  const Rig& rig = r.in.rig;
  rep.vertices = mesh.vertexCount;

  rt::RunRequest req;
  req.spirv = r.spirv.words;
  req.vertexCount = static_cast<uint32_t>(mesh.vertexCount);
  req.capture.strideBytes = r.glsl.captureStride;
  for (const auto& in : r.glsl.inputs) req.streams.push_back(buildStream(rig, in, mesh));
  const std::vector<rt::StorageBufferData> perVertexBuffers =
      buildStorageBuffers(r.in.problem, r.glsl, mesh, rt::Pose{}, true);

  for (const auto& o : r.glsl.outputs) {
    OutputReport out;
    out.name = o.name;
    out.semantics = o.semantics;
    rep.outputs.push_back(out);
  }
  // Messages since the last run, so those of the harness setup (instance, device) count too.
  size_t before = reportedMessages_;
  const RigShape shape = shapeOfRig(rig, r.in.rules);
  const RuleSet& rules = r.in.rules;
  for (const rt::Pose& pose : poses) {
    // Uniforms: the pose's values, then those defined by a formula over them (a normal
    // matrix), rounded to float as the GPU gets them.
    UniformValues uniforms = uniformValues(rig, rules, shape, mesh, pose);
    addActiveTargets(rig, pose, uniforms);
    req.uniformData = buildUniforms(rig, r.glsl, r.spirv, uniforms);
    req.storageBuffers = perVertexBuffers;
    for (auto& sb : buildStorageBuffers(r.in.problem, r.glsl, mesh, pose, false)) req.storageBuffers.push_back(std::move(sb));
    std::sort(req.storageBuffers.begin(), req.storageBuffers.end(),
              [](const auto& a, const auto& b) { return a.binding < b.binding; });
    rt::RunResult res = harness_->run(req);
    rep.timings.setupMs += res.timings.setupMs;
    rep.timings.uploadMs += res.timings.uploadMs;
    rep.timings.runMs += res.timings.runMs;
    rep.timings.readbackMs += res.timings.readbackMs;
    Interpreter reference(rules, shape, mesh, uniforms);  // shares intermediates across outputs
    for (size_t oi = 0; oi < r.glsl.outputs.size(); ++oi) {
      const EmittedOutput& o = r.glsl.outputs[oi];
      OutputReport& out = rep.outputs[oi];
      // Reference of each packed semantic, laid out component after component.
      auto t0 = Clock::now();
      std::vector<int> widths;
      for (const auto& sem : o.semantics) {
        std::string why;
        try {
          why = reference.uncheckedReason(sem);
          if (why.empty()) widths.push_back(reference.components(sem));
        } catch (const std::exception& e) {
          throw InputError(SourceLoc{}, fmt::format("cannot validate output '{}': {}", o.name, e.what()));
        }
        if (!why.empty() && !out.unchecked) {
          out.unchecked = true;
          out.uncheckedReason = why;
        }
      }
      if (out.unchecked) {
        rep.referenceMs += msSince(t0);
        continue;
      }
      std::vector<std::vector<double>> refs;
      try {
        refs = reference.evaluate(o.semantics);
      } catch (const std::exception& e) {
        throw InputError(SourceLoc{}, fmt::format("cannot validate output '{}': {}", o.name, e.what()));
      }
      rep.referenceMs += msSince(t0);
      // Matrices: columns in order; arrays: elements in order (both as their semantics list them).
      int comps = componentCount(o.type) * std::max(1, o.arraySize);
      bool isFloat = scalarKind(o.type) == ScalarKind::Float;
      std::vector<double> ref(static_cast<size_t>(comps)), gpu(static_cast<size_t>(comps));
      for (size_t v = 0; v < mesh.vertexCount; ++v) {
        size_t k = 0;
        for (size_t si = 0; si < refs.size(); ++si)
          for (int c = 0; c < widths[si] && k < ref.size(); ++c) ref[k++] = refs[si][v * static_cast<size_t>(widths[si]) + static_cast<size_t>(c)];
        const uint8_t* rec = res.captured.data() + v * r.glsl.captureStride + o.captureOffset;
        double scale = 1.0;
        for (int c = 0; c < comps; ++c) {
          if (isFloat) {
            float f;
            std::memcpy(&f, rec + 4 * c, 4);
            gpu[static_cast<size_t>(c)] = f;
          } else {
            uint32_t u;
            std::memcpy(&u, rec + 4 * c, 4);
            gpu[static_cast<size_t>(c)] = scalarKind(o.type) == ScalarKind::Int ? static_cast<int32_t>(u) : u;
          }
          if (std::isfinite(ref[static_cast<size_t>(c)])) scale = std::max(scale, std::abs(ref[static_cast<size_t>(c)]));
        }
        for (int c = 0; c < comps; ++c) {
          const double g = gpu[static_cast<size_t>(c)], x = ref[static_cast<size_t>(c)];
          double err = std::abs(g - x);
          if (!std::isfinite(g) && !std::isfinite(x) && opts_.tolerance.nonFiniteAgrees) continue;
          if (!std::isfinite(g) || !std::isfinite(x)) {
            err = INFINITY;
            if (out.nonFinite.empty()) out.nonFinite = nonFiniteReport(reference, o, v, c, g, x);
          }
          double rel = err / scale;
          if (rel > out.maxRelError || (err > out.maxAbsError && out.maxRelError == 0)) {
            out.worstVertex = v;
            out.worstComponent = c;
            out.worstGpu = gpu;
            out.worstReference = ref;
          }
          out.maxAbsError = std::max(out.maxAbsError, err);
          out.maxRelError = std::max(out.maxRelError, rel);
          if (err > opts_.tolerance.abs + opts_.tolerance.rel * scale) out.pass = false;
        }
      }
    }
  }
  const auto& msgs = harness_->validationMessages();
  rep.validationMessages.assign(msgs.begin() + static_cast<long>(before), msgs.end());
  reportedMessages_ = msgs.size();
  rep.pass = rep.validationMessages.empty();
  for (auto& o : rep.outputs)
    if (o.unchecked && opts_.strict) o.pass = false;
  for (const auto& o : rep.outputs) rep.pass = rep.pass && o.pass;
  return rep;
}

ValidateReport Validator::run(const ValidationScene& scene) {
  ValidateReport report;
  report.device = harness_->deviceName();
  report.validationLayers = harness_->validationEnabled();
  GenerateOptions gen = opts_.gen;
  gen.capture = true;
  // The buffer forms must fit this mesh (+1: the harness draws an even count).
  if (gen.maxVertices == 0) gen.maxVertices = static_cast<int64_t>(scene.mesh.vertexCount) + 1;
  LoadedInputs in = loadInputs(gen);
  auto t0 = Clock::now();
  GenerateResult chosen = generateFrom(in, gen);
  double genMs = msSince(t0);
  // Every run shares the rig's attribute formats: quantize the mesh once.
  const rt::Mesh mesh = quantizedMesh(chosen.in.rig, scene.mesh);
  report.poses = scene.poses;
  drawDeclaredUniforms(report.poses, chosen.in.rig, chosen.in.rules);
  report.runs.push_back(runQuantized(chosen, mesh, scene, report.poses, "chosen plan"));
  report.runs.back().generateMs = genMs;

  if (opts_.crossCheck) {
    // Every semantic the plan computes that another rule could also produce: force each
    // alternative (ban every other producer) and check it computes the same outputs.
    const Problem& p = chosen.in.problem;
    std::set<std::vector<std::string>> seenPlans{report.runs.front().rules};
    for (int a : chosen.plan.actions) {
      int fact = p.actions[a].add;
      std::vector<std::string> producers;
      for (const auto& act : p.actions)
        if (act.add == fact) producers.push_back(act.name);
      for (const auto& alt : producers) {
        if (alt == p.actions[a].name) continue;
        GenerateOptions forced = gen;
        for (const auto& other : producers)
          if (other != alt) forced.bannedRules.push_back(other);
        GenerateResult r;
        auto tg = Clock::now();
        try {
          r = generateFrom(in, forced);
        } catch (const InputError&) {
          continue;  // the alternative needs something this rig cannot provide
        }
        double ms = msSince(tg);
        // Banning the other producers may make the plan avoid the value altogether (another
        // route to what needs it); that plan checks nothing about this rule.
        bool uses = false;
        for (int b : r.plan.actions) uses = uses || r.in.problem.actions[b].name == alt;
        if (!uses) continue;
        RunReport rr = runQuantized(r, mesh, scene, report.poses, fmt::format("forced {} for {}", alt, p.facts[fact].name));
        rr.generateMs = ms;
        if (!seenPlans.insert(rr.rules).second) continue;
        report.runs.push_back(std::move(rr));
      }
    }
  }
  for (const auto& r : report.runs) report.pass = report.pass && r.pass;
  return report;
}

std::string formatReport(const ValidateReport& report) {
  std::string s = fmt::format("device: {} (validation layers {})\n", report.device,
                              report.validationLayers ? "on" : "not available");
  for (const auto& run : report.runs) {
    s += fmt::format("{}: plan cost {}, {} vertices: {}\n", run.label, run.planCost, run.vertices,
                     run.pass ? "PASS" : "FAIL");
    for (const auto& o : run.outputs) {
      std::string sems;
      for (const auto& x : o.semantics) sems += (sems.empty() ? "" : ", ") + x;
      if (o.unchecked) {
        s += fmt::format("  {:<4} {:<20} unchecked: {}  ({})\n", o.pass ? "--" : "FAIL", o.name,
                         o.uncheckedReason, sems);
        continue;
      }
      s += fmt::format("  {:<4} {:<20} max abs {:.3e}  max rel {:.3e}  worst vertex {} [{}]  ({})\n",
                       o.pass ? "ok" : "FAIL", o.name, o.maxAbsError, o.maxRelError, o.worstVertex, o.worstComponent, sems);
      if (!o.nonFinite.empty()) s += "       " + o.nonFinite + "\n";
    }
    for (const auto& m : run.validationMessages) s += "  validation layer: " + m + "\n";
    s += fmt::format("  time: generate {:.1f} ms, setup {:.1f} ms, upload {:.1f} ms, run {:.1f} ms, readback {:.1f} ms, "
                     "reference {:.1f} ms\n",
                     run.generateMs, run.timings.setupMs, run.timings.uploadMs, run.timings.runMs,
                     run.timings.readbackMs, run.referenceMs);
  }
  s += fmt::format("{}: {} run(s)\n", report.pass ? "PASS" : "FAIL", report.runs.size());
  return s;
}

}  // namespace sg

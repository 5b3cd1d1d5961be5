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
#include "runtime/reference.h"

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
// increasing order, and their count.
void putActiveTargets(std::vector<uint8_t>& block, const UniformLayout& l, const RigUniform& ru, const rt::Pose& pose) {
  std::vector<uint32_t> active;
  for (size_t i = 0; i < pose.morphWeights.size(); ++i)
    if (pose.morphWeights[i] != 0.0f) active.push_back(static_cast<uint32_t>(i));
  if (ru.semantic == "morph.active_count") {
    uint32_t n = static_cast<uint32_t>(active.size());
    if (l.offset + 4 > block.size()) throw std::logic_error("uniform write past the block");
    std::memcpy(block.data() + l.offset, &n, 4);
    return;
  }
  if (active.size() > static_cast<size_t>(ru.arraySize))
    throw InputError(ru.loc, fmt::format("the pose has {} targets with a non-zero weight; the active-target list "
                                         "holds {}", active.size(), ru.arraySize));
  for (size_t i = 0; i < active.size(); ++i) {
    uint32_t off = l.offset + static_cast<uint32_t>(i) * l.arrayStride;
    if (off + 4 > block.size()) throw std::logic_error("uniform write past the block");
    std::memcpy(block.data() + off, &active[i], 4);
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

std::vector<uint8_t> buildUniforms(const Rig& rig, const EmittedGlsl& glsl, const SpirvModule& spv,
                                   const rt::Pose& pose) {
  std::vector<uint8_t> block(spv.uniformBlockSize, 0);
  for (const auto& u : glsl.uniforms) {
    const RigUniform& ru = rig.uniforms[u.uniform];
    auto layout = std::find_if(spv.uniforms.begin(), spv.uniforms.end(), [&](const UniformLayout& l) { return l.name == u.name; });
    if (layout == spv.uniforms.end()) throw std::logic_error("no reflected layout for uniform " + u.name);
    const UniformLayout& l = *layout;
    const std::string& s = ru.semantic;
    uint32_t ms = l.matrixStride ? l.matrixStride : 16;
    if (s == "skin.bones") {
      if (pose.bones.size() < static_cast<size_t>(ru.arraySize))
        throw InputError(ru.loc, fmt::format("the pose has {} bones, the rig's palette {}", pose.bones.size(), ru.arraySize));
      for (int i = 0; i < ru.arraySize; ++i) putMat4(block, l.offset + static_cast<uint32_t>(i) * l.arrayStride, pose.bones[i], ms);
    } else if (s == "morph.weights") {
      for (int i = 0; i < ru.arraySize; ++i) {
        float w = i < static_cast<int>(pose.morphWeights.size()) ? pose.morphWeights[i] : 0.0f;
        putFloats(block, l.offset + static_cast<uint32_t>(i) * l.arrayStride, &w, 1);
      }
    } else if (s == "morph.active_targets" || s == "morph.active_count") {
      putActiveTargets(block, l, ru, pose);
    } else if (s == "camera.position") {
      putFloats(block, l.offset, &pose.cameraPosition[0], 3);
    } else {
      glm::mat4 m;
      if (s == "camera.view") m = pose.view;
      else if (s == "camera.projection") m = pose.projection;
      else if (s == "camera.view_projection") m = pose.viewProjection();
      else if (s == "model.matrix") m = pose.model;
      else if (s == "dapple.matrix") m = pose.dapple;
      else throw InputError(ru.loc, fmt::format("validation has no value for uniform semantic '{}'", s));
      putMat4(block, l.offset, m, ms);
    }
  }
  return block;
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
  for (int i = 0; i < poses; ++i) s.poses.push_back(rt::makeRandomPose(s.shape, seed + static_cast<uint32_t>(i)));
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
  return runQuantized(r, quantizedMesh(r.in.rig, scene.mesh), scene, label);
}

RunReport Validator::runQuantized(const GenerateResult& r, const rt::Mesh& mesh, const ValidationScene& scene,
                                  const std::string& label) {
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
  for (const rt::Pose& pose : scene.poses) {
    req.uniformData = buildUniforms(rig, r.glsl, r.spirv, pose);
    req.storageBuffers = perVertexBuffers;
    for (auto& sb : buildStorageBuffers(r.in.problem, r.glsl, mesh, pose, false)) req.storageBuffers.push_back(std::move(sb));
    std::sort(req.storageBuffers.begin(), req.storageBuffers.end(),
              [](const auto& a, const auto& b) { return a.binding < b.binding; });
    rt::RunResult res = harness_->run(req);
    rep.timings.setupMs += res.timings.setupMs;
    rep.timings.uploadMs += res.timings.uploadMs;
    rep.timings.runMs += res.timings.runMs;
    rep.timings.readbackMs += res.timings.readbackMs;
    rt::ReferenceEvaluator reference(mesh, pose, scene.shape);  // shares intermediates across outputs
    for (size_t oi = 0; oi < r.glsl.outputs.size(); ++oi) {
      const EmittedOutput& o = r.glsl.outputs[oi];
      OutputReport& out = rep.outputs[oi];
      // Reference of each packed semantic, laid out component after component.
      auto t0 = Clock::now();
      std::vector<std::pair<std::vector<glm::vec4>, int>> refs;
      for (const auto& sem : o.semantics) {
        const SemanticDecl* d = r.in.rules.findSemantic(sem);
        int n = d ? componentCount(d->type) : rt::referenceComponents(sem);
        try {
          refs.emplace_back(reference.values(sem), n);
        } catch (const std::exception& e) {
          throw InputError(SourceLoc{}, fmt::format("cannot validate output '{}': {}", o.name, e.what()));
        }
      }
      rep.referenceMs += msSince(t0);
      int comps = componentCount(o.type);
      bool isFloat = scalarKind(o.type) == ScalarKind::Float;
      std::vector<double> ref(static_cast<size_t>(comps)), gpu(static_cast<size_t>(comps));
      for (size_t v = 0; v < mesh.vertexCount; ++v) {
        size_t k = 0;
        for (const auto& [vals, n] : refs)
          for (int c = 0; c < n; ++c) ref[k++] = vals[v][c];
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
          scale = std::max(scale, std::abs(ref[static_cast<size_t>(c)]));
        }
        for (int c = 0; c < comps; ++c) {
          double err = std::abs(gpu[static_cast<size_t>(c)] - ref[static_cast<size_t>(c)]);
          if (std::isnan(gpu[static_cast<size_t>(c)]) || std::isnan(ref[static_cast<size_t>(c)])) err = INFINITY;
          double rel = err / scale;
          if (rel > out.maxRelError || (err > out.maxAbsError && out.maxRelError == 0)) {
            out.worstVertex = v;
            out.worstComponent = c;
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
  report.runs.push_back(runQuantized(chosen, mesh, scene, "chosen plan"));
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
        RunReport rr = runQuantized(r, mesh, scene, fmt::format("forced {} for {}", alt, p.facts[fact].name));
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
      s += fmt::format("  {:<4} {:<20} max abs {:.3e}  max rel {:.3e}  worst vertex {} [{}]  ({})\n",
                       o.pass ? "ok" : "FAIL", o.name, o.maxAbsError, o.maxRelError, o.worstVertex, o.worstComponent, sems);
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

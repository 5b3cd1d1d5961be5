#include "validate/validate.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstring>
#include <map>
#include <optional>
#include <type_traits>
#include <random>
#include <set>

#include "common/content_hash.h"
#include "rig/rig_lod.h"
#include "runtime/procedural.h"
#include "validate/float_check.h"
#include "validate/interpreter.h"
#include "validate/poses.h"

namespace sg {
namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

// Which side produced a NaN or infinity, where, and the provided values it was computed from.
std::string nonFiniteReport(Interpreter& reference, const EmittedOutput& o, size_t v, int c, double gpu, double ref) {
  bool g = !std::isfinite(gpu), r = !std::isfinite(ref);
  std::string side = g && r ? "GPU and reference" : g ? "GPU" : "reference";
  auto show = [](double x) { return std::isnan(x) ? std::string("nan") : fmt::format("{}", x); };  // no "-nan"
  std::string s = fmt::format("{} {} {} at vertex {}, output {} component {} (GPU {}, reference {})", side,
                              g && r ? "give" : "gives", show(g ? gpu : ref), v, o.name, c, show(gpu), show(ref));
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


// Folds one pose's comparison of an output into the union over the poses: the worst error
// (by relative error, as the vertex loop picks it) and where, every check's pass.
void mergeOutputReport(OutputReport& all, const OutputReport& pose) {
  if (pose.maxRelError > all.maxRelError || (pose.maxAbsError > all.maxAbsError && all.maxRelError == 0)) {
    all.worstVertex = pose.worstVertex;
    all.worstComponent = pose.worstComponent;
    all.worstGpu = pose.worstGpu;
    all.worstReference = pose.worstReference;
  }
  all.maxAbsError = std::max(all.maxAbsError, pose.maxAbsError);
  all.maxRelError = std::max(all.maxRelError, pose.maxRelError);
  all.storedPass = all.storedPass && pose.storedPass;
  if (all.nonFinite.empty()) all.nonFinite = pose.nonFinite;
  OutputReport::FloatCheck& f = all.floatCheck;
  const OutputReport::FloatCheck& p = pose.floatCheck;
  if (p.ratio < f.ratio) {
    f.ratio = p.ratio;
    f.tolerance = p.tolerance;
    f.deviation = p.deviation;
    f.worstVertex = p.worstVertex;
    f.worstComponent = p.worstComponent;
  }
  f.maxDeviation = std::max(f.maxDeviation, p.maxDeviation);
  f.pass = f.pass && p.pass;
  f.notCompared += p.notCompared;
}

// Every output of a capture as floats, `components` per vertex (integers converted).
std::vector<std::vector<float>> capturedOutputs(const GenerateResult& r, const std::vector<uint8_t>& captured,
                                                size_t vertices) {
  std::vector<std::vector<float>> out;
  for (const EmittedOutput& o : r.glsl.outputs) {
    const size_t comps = static_cast<size_t>(componentCount(o.type) * std::max(1, o.arraySize));
    const ScalarKind kind = scalarKind(o.type);
    std::vector<float> values(vertices * comps);
    for (size_t v = 0; v < vertices; ++v)
      for (size_t c = 0; c < comps; ++c) {
        const uint8_t* at = captured.data() + v * r.glsl.captureStride + o.captureOffset + 4 * c;
        uint32_t u;
        std::memcpy(&u, at, 4);
        float f;
        std::memcpy(&f, at, 4);
        values[v * comps + c] = kind == ScalarKind::Float ? f
                                : kind == ScalarKind::Int ? static_cast<float>(static_cast<int32_t>(u))
                                                          : static_cast<float>(u);
      }
    out.push_back(std::move(values));
  }
  return out;
}

}  // namespace

std::string withoutIntegerMatrices(const std::string& hlsl) {
  // asfloat(uintRxC(a, b, ...)) -> floatRxC(asfloat(a), asfloat(b), ...): both reinterpret
  // each component, and the constructors place the components alike.
  std::string out;
  size_t from = 0;
  for (size_t at; (at = hlsl.find("asfloat(uint", from)) != std::string::npos;) {
    size_t p = at + 12;
    const bool matrix = p + 4 <= hlsl.size() && std::isdigit(static_cast<unsigned char>(hlsl[p])) && hlsl[p + 1] == 'x' &&
                        std::isdigit(static_cast<unsigned char>(hlsl[p + 2])) && hlsl[p + 3] == '(';
    if (!matrix) {
      out.append(hlsl, from, p - from);
      from = p;
      continue;
    }
    std::vector<std::string> args(1);
    int depth = 0;
    size_t q = p + 4;
    for (; q < hlsl.size(); ++q) {
      const char c = hlsl[q];
      if (depth == 0 && c == ')') break;
      if (depth == 0 && c == ',') {
        args.emplace_back();
        continue;
      }
      depth += c == '(' ? 1 : c == ')' ? -1 : 0;
      args.back() += c;
    }
    if (q + 1 >= hlsl.size() || hlsl[q + 1] != ')') {  // not the whole argument of asfloat: keep it
      out.append(hlsl, from, p - from);
      from = p;
      continue;
    }
    out.append(hlsl, from, at - from);
    out += "float" + hlsl.substr(p, 3) + "(";
    for (size_t i = 0; i < args.size(); ++i) out += (i ? ", asfloat(" : "asfloat(") + args[i].substr(args[i].find_first_not_of(' ')) + ")";
    out += ")";
    from = q + 2;
  }
  return out + hlsl.substr(from);
}

std::vector<uint32_t> hlslCaptureModule(const GenerateResult& r, TargetEnv env) {
  if (!r.hlsl) throw std::logic_error("hlslCaptureModule: the result has no HLSL");
  const std::string name = r.hlsl->entryPoint + " (HLSL of " + r.in.fragment.file + ")";
  // Storage buffers are registers t0, t1, ... for bindings 1, 2, ... (emit/cross_compile.h).
  // glslang's HLSL front end turns integer matrices (valid HLSL, which SPIRV-Cross writes
  // to load a matrix from a ByteAddressBuffer) into SPIR-V that Vulkan forbids: that one
  // form is rewritten to its equivalent first (docs/hlsl-msl.md).
  GlslUnit unit{Stage::Vertex, withoutIntegerMatrices(r.hlsl->text), name, {}, SourceLanguage::Hlsl, 1};
  CompileResult c = compileGlsl(unit, env);
  if (!c.ok) throwDiagnostics(c.diagnostics, name, "the HLSL does not compile");
  std::map<std::string, int> inputs, outputs;
  for (const auto& v : r.hlsl->inputs) inputs[v.binding] = v.location;
  for (const auto& v : r.hlsl->outputs)
    if (v.location >= 0) outputs[v.binding] = v.location;
  std::map<int, uint32_t> offsets;
  for (const auto& o : r.glsl.outputs) offsets[o.location] = o.captureOffset;
  std::vector<uint32_t> words = withCapture(bindSemantics(c.spirv, inputs, outputs, name), r.glsl.captureStride, offsets);
  if (std::string err = validateSpirv(words, env); !err.empty())
    throw InputError(SourceLoc{name, 0, 0}, "the SPIR-V compiled from the HLSL fails validation: " + err);
  return words;
}

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
  s.shape.uniformScale = rig.param("uniform_scale") != 0;
  // Hostile by default: non-uniform scale unless the rig declares it never scales so.
  const rt::PoseOptions po = rt::hostilePoseOptions(rig.param("uniform_scale") != 0);
  for (int i = 0; i < poses; ++i) s.poses.push_back(rt::makeRandomPose(s.shape, seed + static_cast<uint32_t>(i), po));
  limitActiveTargets(rig, s.poses, seed);
  return s;
}

ValidationScene proceduralScene(const std::string& rigPath, const std::map<std::string, int64_t>& params,
                                const std::string& mesh, uint32_t seed, int poses) {
  Rig rig = loadRigFile(rigPath);
  if (!params.empty()) rig = rigWithParameters(rig, params, SourceLoc{});
  return proceduralScene(rig, mesh, seed, poses);
}

// The reference values of one pose, kept across the runs of one validation: the chosen plan
// and every forced alternative check the same semantics on the same mesh and poses.
struct PoseReference {
  UniformValues uniforms;  // what they were computed with
  std::map<std::string, std::vector<double>> values;
  std::map<std::string, std::string> unchecked;  // why a semantic cannot be evaluated ("" if it can)
  // The reference on the float data and its tolerances (float_check.h), for the second check.
  std::map<std::string, std::vector<double>> floatValues, floatTolerance;
};

struct Validator::ReferenceCache {
  static constexpr size_t kMaxBytes = size_t{1} << 30;  // beyond, poses are recomputed per run
  std::vector<PoseReference> poses;

  // The entry of pose i, emptied if it was computed with other uniforms.
  PoseReference& pose(size_t i, const UniformValues& uniforms) {
    if (poses.size() <= i) poses.resize(i + 1);
    PoseReference& p = poses[i];
    if (p.uniforms != uniforms) {
      p = PoseReference{};
      p.uniforms = uniforms;
    }
    return p;
  }
  void trim(size_t i) {
    size_t bytes = 0;
    for (const auto& p : poses)
      for (const auto* m : {&p.values, &p.floatValues, &p.floatTolerance})
        for (const auto& [sem, v] : *m) bytes += v.size() * sizeof(double);
    if (bytes > kMaxBytes) poses[i].values.clear(), poses[i].floatValues.clear(), poses[i].floatTolerance.clear();
  }
};

Validator::Validator(const ValidateOptions& opts) : opts_(opts) {
  rt::HarnessOptions ho;
  ho.deviceName = opts.device;
  ho.validation = opts.validationLayers;
  harness_ = std::make_unique<rt::Harness>(ho);
  limits_ = applyDeviceLimits(opts_.gen, opts.limits, *harness_);
}

std::string applyDeviceLimits(GenerateOptions& gen, const DeviceLimitsOptions& o, const rt::Harness& device) {
  if (!o.fromDevice) return "";
  const VkPhysicalDeviceLimits& lim = device.limits();
  std::vector<std::string> parts, clamped;
  // A given limit stays when the device allows it, else the device's; not given: the device's.
  auto set = [&](auto& value, uint64_t deviceValue, uint64_t cap, bool given, const char* flag, const char* vkName,
                 const char* what) {
    using T = std::remove_reference_t<decltype(value)>;
    const uint64_t dv = std::min(deviceValue, cap);
    if (!given) {
      value = static_cast<T>(dv);
    } else if (static_cast<uint64_t>(value) > dv) {
      clamped.push_back(fmt::format("{} {} clamped to the device's {} {}", flag, value, vkName, dv));
      value = static_cast<T>(dv);
    }
    parts.push_back(fmt::format("{} {}{}", value, what, given ? " (given)" : ""));
  };
  set(gen.maxAttributes, lim.maxVertexInputAttributes, 4096, o.attributesGiven, "--max-attributes",
      "maxVertexInputAttributes", "vertex attributes");
  set(gen.maxUniformBlockBytes, lim.maxUniformBufferRange, uint64_t{1} << 30, o.uniformBytesGiven,
      "--max-uniform-bytes", "maxUniformBufferRange", "uniform bytes");
  set(gen.maxStorageBuffers, lim.maxPerStageDescriptorStorageBuffers, 4096, false, "", "", "storage buffers");
  set(gen.maxStorageBufferBytes, lim.maxStorageBufferRange, uint64_t{1} << 40, false, "", "", "bytes per storage buffer");
  std::string line = "limits of " + device.deviceName() + ": ";
  for (size_t i = 0; i < parts.size(); ++i) line += (i ? ", " : "") + parts[i];
  for (const auto& c : clamped) line += "; " + c;
  return line;
}

Validator::~Validator() = default;

RunReport Validator::runOne(const GenerateResult& r, const ValidationScene& scene, const std::string& label) {
  std::vector<rt::Pose> poses = scene.poses;
  drawDeclaredUniforms(poses, r.in.rig, r.in.rules);
  return runQuantized(r, quantizeForRig(r.in.rig, scene.mesh), scene, poses, label);
}

RunReport Validator::runQuantized(const GenerateResult& r, const rt::Mesh& mesh, const ValidationScene& scene,
                                  const std::vector<rt::Pose>& poses, const std::string& label, ReferenceCache* cache,
                                  bool keepOutputs) {
  RunReport rep;
  rep.label = label;
  rep.planCost = r.plan.cost;
  for (int a : r.plan.actions) rep.rules.push_back(r.in.problem.actions[a].name);
  const Rig& rig = r.in.rig;
  rep.vertices = mesh.vertexCount;

  rt::RunRequest req;
  req.spirv = opts_.via == ValidateVia::Hlsl ? hlslCaptureModule(r, opts_.gen.targetEnv) : r.spirv.words;
  req.capture.strideBytes = r.glsl.captureStride;
  if (!poses.empty()) static_cast<rt::ProgramInputs&>(req) = programInputs(r, mesh, poses.front());

  for (const auto& o : r.glsl.outputs) {
    OutputReport out;
    out.name = o.name;
    out.semantics = o.semantics;
    out.type = std::string(glslName(o.type));
    out.components = componentCount(o.type) * std::max(1, o.arraySize);
    rep.outputs.push_back(out);
  }
  // Messages since the last run, so those of the harness setup (instance, device) count too.
  size_t before = reportedMessages_;
  const RigShape shape = shapeOfRig(rig, r.in.rules);
  const RuleSet& rules = r.in.rules;
  // The second check (float_check.h): the reference on the original float data where the
  // scene has it, on what the device reads elsewhere (codes given without their source, the
  // mesh's bounds). It costs two reference evaluations per bounded input component, so it
  // compares every floatStride-th vertex of a large mesh.
  const size_t cap = opts_.floatCheckVertices;
  const size_t floatStride = cap == 0 ? 1 : std::max<size_t>(1, (mesh.vertexCount + cap - 1) / cap);
  std::vector<InputErrorBound> bounds;
  if (opts_.checkFloatData) bounds = quantizationErrorBounds(rig, scene.mesh);
  for (InputErrorBound& b : bounds)
    for (size_t v = 0; v < b.bound.size(); v += floatStride) b.bound[v / floatStride] = b.bound[v];
  for (InputErrorBound& b : bounds) b.bound.resize((b.bound.size() + floatStride - 1) / floatStride);
  std::optional<rt::Mesh> floatMesh;  // built when a pose first needs it
  std::map<std::string, std::vector<glm::vec4>> storedInputs;  // the bounded inputs as the device's data holds them
  rep.floatCheckStride = floatStride;
  for (size_t pi = 0; pi < poses.size(); ++pi) {
    const rt::Pose& pose = poses[pi];
    // The pose's uniforms (and those defined over them, as floats) and palettes; the
    // reference evaluates with the same values.
    const UniformValues uniforms = feedPose(r, mesh, pose, req);
    rt::RunResult res = harness_->run(req);
    rep.timings.setupMs += res.timings.setupMs;
    rep.timings.uploadMs += res.timings.uploadMs;
    rep.timings.runMs += res.timings.runMs;
    rep.timings.readbackMs += res.timings.readbackMs;
    // The reference of every checked output at once (outputs share their intermediates),
    // or what an earlier run of this validation computed for the same pose.
    auto t0 = Clock::now();
    PoseReference local;
    PoseReference& pr = cache ? cache->pose(pi, uniforms) : local;
    if (!cache) pr.uniforms = uniforms;
    Interpreter reference(rules, shape, mesh, pr.uniforms);
    std::vector<std::string> missing;
    for (size_t oi = 0; oi < r.glsl.outputs.size(); ++oi) {
      const EmittedOutput& o = r.glsl.outputs[oi];
      OutputReport& out = rep.outputs[oi];
      for (const auto& sem : o.semantics) {
        auto why = pr.unchecked.find(sem);
        if (why == pr.unchecked.end()) {
          try {
            why = pr.unchecked.emplace(sem, reference.uncheckedReason(sem)).first;
          } catch (const std::exception& e) {
            throw InputError(SourceLoc{}, fmt::format("cannot validate output '{}': {}", o.name, e.what()));
          }
        }
        if (!why->second.empty() && !out.unchecked) {
          out.unchecked = true;
          out.uncheckedReason = why->second;
        }
      }
      if (out.unchecked) continue;
      for (const auto& sem : o.semantics)
        if (!pr.values.count(sem) && std::find(missing.begin(), missing.end(), sem) == missing.end()) missing.push_back(sem);
    }
    if (!missing.empty()) {
      std::vector<std::vector<double>> values;
      try {
        values = reference.evaluate(missing);
      } catch (const std::exception& e) {
        // Name the first output whose semantics cannot be evaluated.
        for (size_t oi = 0; oi < r.glsl.outputs.size(); ++oi) {
          if (rep.outputs[oi].unchecked) continue;
          try {
            reference.evaluate(r.glsl.outputs[oi].semantics);
          } catch (const std::exception& first) {
            throw InputError(SourceLoc{}, fmt::format("cannot validate output '{}': {}", r.glsl.outputs[oi].name, first.what()));
          }
        }
        throw InputError(SourceLoc{}, fmt::format("cannot validate: {}", e.what()));
      }
      for (size_t k = 0; k < missing.size(); ++k) pr.values[missing[k]] = std::move(values[k]);
    }
    rep.referenceMs += msSince(t0);
    // This pose's comparison, merged into rep.outputs (the worst over the poses) at its end.
    std::vector<OutputReport> poseOut(rep.outputs.size());
    for (size_t oi = 0; oi < rep.outputs.size(); ++oi) {
      const OutputReport& all = rep.outputs[oi];
      OutputReport& po = poseOut[oi];
      po.name = all.name;
      po.semantics = all.semantics;
      po.type = all.type;
      po.components = all.components;
      po.unchecked = all.unchecked;
      po.uncheckedReason = all.uncheckedReason;
    }
    if (!bounds.empty()) {
      auto tf = Clock::now();
      std::vector<std::string> floatMissing;
      for (size_t oi = 0; oi < r.glsl.outputs.size(); ++oi)
        if (!rep.outputs[oi].unchecked)
          for (const auto& sem : r.glsl.outputs[oi].semantics)
            if (!pr.floatValues.count(sem) &&
                std::find(floatMissing.begin(), floatMissing.end(), sem) == floatMissing.end())
              floatMissing.push_back(sem);
      if (!floatMissing.empty()) {
        if (!floatMesh) {
          floatMesh = rt::everyNthVertex(mesh, floatStride);
          for (const InputErrorBound& b : bounds)
            if (floatMesh->has(b.semantic)) storedInputs[b.semantic] = floatMesh->at(b.semantic);
          for (auto& [sem, stream] : rt::everyNthVertex(scene.mesh, floatStride).streams) floatMesh->streams[sem] = std::move(stream);
          fillWidenedComponents(rig, *floatMesh);
        }
        FloatReference f = floatReference(rules, shape, *floatMesh, pr.uniforms, bounds, floatMissing, storedInputs);
        for (size_t k = 0; k < floatMissing.size(); ++k) {
          pr.floatValues[floatMissing[k]] = std::move(f.values[k]);
          pr.floatTolerance[floatMissing[k]] = std::move(f.tolerance[k]);
        }
      }
      rep.floatCheckMs += msSince(tf);
    }
    // Compare vertex by vertex, every output of a captured record together (one pass over
    // the capture). Matrices: columns in order; arrays: elements in order (both as their
    // semantics list them).
    struct Compared {
      const EmittedOutput* o;
      OutputReport* out;
      std::vector<std::pair<const double*, size_t>> refs;  // values, components
      size_t comps;
      std::vector<std::pair<const double*, const double*>> floatRefs;  // float values and tolerances, as refs
    };
    std::vector<Compared> compared;
    size_t widest = 0;
    for (size_t oi = 0; oi < r.glsl.outputs.size(); ++oi) {
      if (rep.outputs[oi].unchecked) continue;
      const EmittedOutput& o = r.glsl.outputs[oi];
      Compared c{&o, &poseOut[oi], {}, static_cast<size_t>(componentCount(o.type) * std::max(1, o.arraySize))};
      for (const auto& sem : o.semantics) {
        c.refs.emplace_back(pr.values.at(sem).data(), static_cast<size_t>(reference.components(sem)));
        if (!bounds.empty()) c.floatRefs.emplace_back(pr.floatValues.at(sem).data(), pr.floatTolerance.at(sem).data());
      }
      rep.outputs[oi].floatCheck.ran = poseOut[oi].floatCheck.ran = !bounds.empty();
      widest = std::max(widest, c.comps);
      compared.push_back(std::move(c));
    }
    std::vector<double> ref(widest), gpu(widest), floatRef(widest), floatTol(widest);
    for (size_t v = 0; v < mesh.vertexCount; ++v) {
      const uint8_t* record = res.captured.data() + v * r.glsl.captureStride;
      for (Compared& cmp : compared) {
        const EmittedOutput& o = *cmp.o;
        OutputReport& out = *cmp.out;
        const size_t comps = cmp.comps;
        size_t k = 0;
        for (const auto& [values, width] : cmp.refs)
          for (size_t c = 0; c < width && k < comps; ++c) ref[k++] = values[v * width + c];
        k = 0;
        for (size_t si = 0; si < cmp.floatRefs.size(); ++si) {
          const size_t width = cmp.refs[si].second;
          for (size_t c = 0; c < width && k < comps; ++c, ++k) {
            floatRef[k] = cmp.floatRefs[si].first[v / floatStride * width + c];
            floatTol[k] = cmp.floatRefs[si].second[v / floatStride * width + c];
          }
        }
        const uint8_t* rec = record + o.captureOffset;
        const ScalarKind kind = scalarKind(o.type);
        double scale = 1.0;
        for (size_t c = 0; c < comps; ++c) {
          if (kind == ScalarKind::Float) {
            float f;
            std::memcpy(&f, rec + 4 * c, 4);
            gpu[c] = f;
          } else {
            uint32_t u;
            std::memcpy(&u, rec + 4 * c, 4);
            gpu[c] = kind == ScalarKind::Int ? static_cast<int32_t>(u) : u;
          }
          if (std::isfinite(ref[c])) scale = std::max(scale, std::abs(ref[c]));
        }
        for (size_t c = 0; c < comps; ++c) {
          const double g = gpu[c], x = ref[c];
          double err = std::abs(g - x);
          if (!std::isfinite(g) && !std::isfinite(x) && opts_.tolerance.nonFiniteAgrees) continue;
          if (!std::isfinite(g) || !std::isfinite(x)) {
            err = INFINITY;
            if (out.nonFinite.empty()) out.nonFinite = nonFiniteReport(reference, o, v, static_cast<int>(c), g, x);
          }
          double rel = err / scale;
          if (rel > out.maxRelError || (err > out.maxAbsError && out.maxRelError == 0)) {
            out.worstVertex = v;
            out.worstComponent = static_cast<int>(c);
            out.worstGpu.assign(gpu.begin(), gpu.begin() + static_cast<long>(comps));
            out.worstReference.assign(ref.begin(), ref.begin() + static_cast<long>(comps));
          }
          out.maxAbsError = std::max(out.maxAbsError, err);
          out.maxRelError = std::max(out.maxRelError, rel);
          if (err > opts_.tolerance.abs + opts_.tolerance.rel * scale) out.storedPass = false;
        }
        if (cmp.floatRefs.empty() || v % floatStride != 0) continue;
        // Second check: the float tolerance (at the float reference's scale) plus the derived
        // bound of what storing the inputs changes.
        double floatScale = 1.0;
        for (size_t c = 0; c < comps; ++c)
          if (std::isfinite(floatRef[c])) floatScale = std::max(floatScale, std::abs(floatRef[c]));
        OutputReport::FloatCheck& fc = out.floatCheck;
        for (size_t c = 0; c < comps; ++c) {
          if (!std::isfinite(floatRef[c]) || !std::isfinite(floatTol[c])) {
            ++fc.notCompared;
            continue;
          }
          const double dev = std::isfinite(gpu[c]) ? std::abs(gpu[c] - floatRef[c]) : INFINITY;
          const double tol = opts_.tolerance.abs + opts_.tolerance.rel * floatScale + floatTol[c];
          const double ratio = tol / dev;
          if (ratio < fc.ratio) {
            fc.ratio = ratio;
            fc.tolerance = tol;
            fc.deviation = dev;
            fc.worstVertex = v;
            fc.worstComponent = static_cast<int>(c);
          }
          fc.maxDeviation = std::max(fc.maxDeviation, dev);
          if (!(dev <= tol)) fc.pass = false;
        }
      }
    }
    for (size_t oi = 0; oi < rep.outputs.size(); ++oi) {
      OutputReport& po = poseOut[oi];
      po.pass = po.storedPass && po.floatCheck.pass && !(po.unchecked && opts_.strict);
      mergeOutputReport(rep.outputs[oi], po);
    }
    rep.poseOutputs.push_back(std::move(poseOut));
    if (keepOutputs) rep.captured.push_back(capturedOutputs(r, res.captured, mesh.vertexCount));
    if (cache) cache->trim(pi);
  }
  const auto& msgs = harness_->validationMessages();
  rep.validationMessages.assign(msgs.begin() + static_cast<long>(before), msgs.end());
  reportedMessages_ = msgs.size();
  rep.pass = rep.validationMessages.empty();
  for (auto& o : rep.outputs) o.pass = o.storedPass && o.floatCheck.pass && !(o.unchecked && opts_.strict);
  for (const auto& o : rep.outputs) rep.pass = rep.pass && o.pass;
  return rep;
}

ValidateReport Validator::run(const ValidationScene& scene) { return run(scene, opts_.gen); }

ValidateReport Validator::run(const ValidationScene& scene, const GenerateOptions& options) {
  ValidateReport report;
  report.device = harness_->deviceName();
  report.driver = harness_->driver();
  report.limits = limits_;
  report.validationLayers = harness_->validationEnabled();
  GenerateOptions gen = options;
  // A whole model's primitives arrive with the command line's options: the device's limits
  // apply to each as to a single rig (idempotent for opts_.gen, which has them already).
  applyDeviceLimits(gen, opts_.limits, *harness_);
  // Through HLSL: the shipped build is translated (its text is what `generate --emit hlsl`
  // writes) and the capture is added to the module compiled back from it.
  gen.capture = opts_.via == ValidateVia::Spirv;
  gen.maxCaptureBytes = harness_->maxCaptureBytes();  // either way, the record is captured on this device
  if (opts_.via == ValidateVia::Hlsl && !gen.hlsl) gen.hlsl = HlslOptions{};
  if (opts_.via == ValidateVia::Hlsl)
    report.via = fmt::format("HLSL {} (compiled back by glslang)", shaderModelName(gen.hlsl->shaderModel));
  // The buffer forms must fit this mesh (+1: the harness draws an even count).
  if (gen.maxVertices == 0) gen.maxVertices = static_cast<int64_t>(scene.mesh.vertexCount) + 1;
  LoadedInputs in = loadInputs(gen);
  auto t0 = Clock::now();
  GenerateResult chosen = generateFrom(in, gen);
  double genMs = msSince(t0);
  report.notes = chosen.in.notes;
  if (gen.pin)
    if (auto changed = pinInputsChanged(*gen.pin, sha256OfFiles(chosen.pinnedInputs))) report.notes.push_back(*changed);
  // Every run shares the rig's attribute formats: quantize the mesh once.
  const rt::Mesh mesh = quantizeForRig(chosen.in.rig, scene.mesh);
  report.poses = scene.poses;
  drawDeclaredUniforms(report.poses, chosen.in.rig, chosen.in.rules);
  ReferenceCache cache;
  report.runs.push_back(runQuantized(chosen, mesh, scene, report.poses, "chosen plan", &cache, opts_.keepOutputs));
  report.runs.back().generateMs = genMs;

  if (opts_.crossCheck) {
    // Every semantic the plan computes that another rule could also produce: force each
    // alternative (ban every other producer) and check it computes the same outputs.
    const Problem& p = chosen.in.problem;
    std::set<std::vector<std::string>> seenPlans{report.runs.front().rules};
    // A portable choice's alternatives: the least regret against the unbanned optima, the
    // programs bench times (LoadedInputs::portableBest).
    in.portableBest = chosen.in.portableBest;
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
        RunReport rr =
            runQuantized(r, mesh, scene, report.poses, fmt::format("forced {} for {}", alt, p.facts[fact].name), &cache);
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
  std::string s = fmt::format("device: {} (validation layers {}), running {}\n", report.device,
                              report.validationLayers ? "on" : "not available", report.via);
  if (!report.limits.empty()) s += report.limits + "\n";
  for (const auto& n : report.notes) s += formatDiagnostic(n) + "\n";
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
                       o.storedPass ? "ok" : "FAIL", o.name, o.maxAbsError, o.maxRelError, o.worstVertex, o.worstComponent, sems);
      if (!o.nonFinite.empty()) s += "       " + o.nonFinite + "\n";
      if (const auto& f = o.floatCheck; f.ran) {
        s += fmt::format("  {:<4} {:<20} vs float data: max dev {:.3e}  tolerance/observed {:.3g} at vertex {} [{}] "
                         "(tolerance {:.3e}, dev {:.3e})",
                         f.pass ? "ok" : "FAIL", "", f.maxDeviation, f.ratio, f.worstVertex, f.worstComponent,
                         f.tolerance, f.deviation);
        s += f.notCompared ? fmt::format(", {} component(s) not compared: not finite\n", f.notCompared) : "\n";
      }
    }
    for (const auto& m : run.validationMessages) s += "  validation layer: " + m + "\n";
    s += fmt::format("  time: generate {:.1f} ms, setup {:.1f} ms, upload {:.1f} ms, run {:.1f} ms, readback {:.1f} ms, "
                     "reference {:.1f} ms",
                     run.generateMs, run.timings.setupMs, run.timings.uploadMs, run.timings.runMs,
                     run.timings.readbackMs, run.referenceMs);
    bool floatChecked = false;
    for (const auto& o : run.outputs) floatChecked = floatChecked || o.floatCheck.ran;
    s += !floatChecked ? "\n"
         : run.floatCheckStride > 1
             ? fmt::format(", float check {:.1f} ms (1 vertex in {})\n", run.floatCheckMs, run.floatCheckStride)
             : fmt::format(", float check {:.1f} ms\n", run.floatCheckMs);
  }
  s += fmt::format("{}: {} run(s)\n", report.pass ? "PASS" : "FAIL", report.runs.size());
  return s;
}

}  // namespace sg

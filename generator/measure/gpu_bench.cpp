#include "measure/gpu_bench.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <numeric>
#include <regex>
#include <set>

#include "analysis/cost.h"
#include "common/content_hash.h"
#include "common/glsl_compile.h"
#include "common/input_file.h"
#include "measure/fit.h"
#include "measure/workload.h"
#include "rig/packed_fields.h"
#include "rig/vertex_format.h"
#include "runtime/procedural.h"
#include "runtime/vk_render.h"

namespace sg {
namespace {

// GpuBenchRow::program: the module's bytes as a .spv file holds them (generate, build's cache).
std::string programId(const std::vector<uint32_t>& words) {
  return sha256Hex(std::string_view(reinterpret_cast<const char*>(words.data()), words.size() * 4)).substr(0, 16);
}

// One program to time: its render and capture builds (fed by programInputs).
struct Program {
  GpuBenchRow row;
  GenerateResult render, capture;
  bool validate = true;  // the floors write constants on purpose
};

std::vector<double> ranks(const std::vector<double>& v) {
  std::vector<size_t> order(v.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return v[a] < v[b]; });
  std::vector<double> r(v.size());
  for (size_t i = 0; i < order.size();) {  // ties share their mean rank
    size_t j = i;
    while (j + 1 < order.size() && v[order[j + 1]] == v[order[i]]) ++j;
    for (size_t k = i; k <= j; ++k) r[order[k]] = 0.5 * double(i + j);
    i = j + 1;
  }
  return r;
}

GlslShader parseVertex(const std::string& text, const std::string& path, TargetEnv env, uint32_t maxCaptureBytes) {
  GlslUnit unit{Stage::Vertex, text, path, {}};
  unit.maxCaptureStrideBytes = maxCaptureBytes;
  GlslShader s(unit, env);
  if (!s.ok()) throwDiagnostics(s.diagnostics(), path, "the vertex shader does not compile");
  return s;
}

// The floor: reads the position, writes it as gl_Position and a constant to every other
// output of the generated program's interface.
// With allInputs, it also reads every input the generated program reads (summed into
// gl_Position with a factor the compiler cannot fold away), separating the cost of vertex
// fetch from the cost of the arithmetic.
std::string floorShader(const GenerateResult& g, bool capture, bool allInputs) {
  std::string pos;
  int location = -1;
  for (const auto& in : g.glsl.inputs) {
    const RigAttribute& a = g.in.rig.attributes[in.attribute];
    for (const auto& part : a.provides)
      // The stored position in whichever form the rig keeps it (a bounds-relative code is a
      // position too, for a floor): without it the floor would read no input at all.
      if ((part.semantic == "vertex.position" || part.semantic == "vertex.position_in_bounds") && location < 0) {
        location = in.location;
        if (part.field >= 0) {  // in a bit-packed attribute's words: unpacked as the plan would
          const PackedField& f = a.fields[static_cast<size_t>(part.field)];
          pos = formatComponents(f.format) < 3 ? ""
                                                : "(" + unpackField(f, part.swizzle.empty() ? "xyz" : part.swizzle, in.name,
                                                                    componentCount(in.type)).glsl + ").xyz";
        } else {
          pos = in.name + (componentCount(in.type) > 3 ? ".xyz" : "");
          if (componentCount(in.type) < 3) pos = "";
        }
      }
  }
  std::string text = "#version 450\n";
  for (const auto& in : g.glsl.inputs)
    if (in.location == location || allInputs)
      text += fmt::format("layout(location = {}) in {} {};\n", in.location, glslName(in.type), in.name);
  std::string body = pos.empty() ? "  gl_Position = vec4(0.0, 0.0, 0.5, 1.0);\n"
                                 : fmt::format("  gl_Position = vec4({}, 1.0);\n", pos);
  if (allInputs) {
    body += "  vec4 fetched = vec4(0.0);\n";
    for (const auto& in : g.glsl.inputs) {
      const int n = componentCount(in.type);
      const char* pad = n == 1 ? "" : n == 2 ? ", 0.0, 0.0" : n == 3 ? ", 0.0" : "";
      std::string v = scalarKind(in.type) == ScalarKind::Float ? in.name : fmt::format("{}({})", n == 1 ? "float" : fmt::format("vec{}", n), in.name);
      body += n == 1 ? fmt::format("  fetched += vec4({});\n", v) : fmt::format("  fetched += vec4({}{});\n", v, pad);
    }
    body += "  gl_Position += 1e-30 * fetched;\n";
  }
  for (const auto& o : g.glsl.outputs) {
    if (o.location < 0) {
      if (capture)
        text += fmt::format("out gl_PerVertex {{\n  layout(xfb_buffer = 0, xfb_offset = 0, xfb_stride = {}) vec4 gl_Position;\n}};\n",
                            g.glsl.captureStride);
      continue;
    }
    std::string xfb = capture ? fmt::format(", xfb_buffer = 0, xfb_offset = {}, xfb_stride = {}", o.captureOffset, g.glsl.captureStride) : "";
    bool integral = scalarKind(o.type) != ScalarKind::Float;
    text += fmt::format("layout(location = {}{}) {}out {} {};\n", o.location, xfb, integral ? "flat " : "", glslName(o.type), o.name);
    body += fmt::format("  {} = {}(0);\n", o.name, glslName(o.type));
  }
  return text + "void main() {\n" + body + "}\n";
}

// What a floor pays per term: its arithmetic measured on its optimised SPIR-V (as cost: auto
// and the calibration's probes are), each input it reads (a location and its format's bytes),
// and the generated program's outputs. It reads no buffer and no uniform.
TermAmounts floorAmounts(const GenerateResult& floor, const Problem& generated, TargetEnv env) {
  TermAmounts a{};
  a[kTermArithmetic] = measureSpirv(optimizeSpirv(floor.spirv.words, env)).total;
  for (const auto& in : floor.glsl.inputs) {
    const RigAttribute& ra = floor.in.rig.attributes[static_cast<size_t>(in.attribute)];
    a[kTermLocations] += vertexInputLocations(ra.shaderType);
    a[kTermAttributeBytes] += formatBytes(ra.format);
  }
  a[kTermOutputs] = generated.fixedTerms[kTermOutputs];
  a[kTermVertices] = 1;
  a[kTermFragments] = 1;
  return a;
}

}  // namespace

std::string addCaptureQualifiers(const std::string& glsl, const std::string& path, const EmittedGlsl& capture) {
  static const std::regex out(R"(layout\s*\(\s*location\s*=\s*(\d+)\s*\)(\s*(?:flat\s+)?out\s+\w+\s+(\w+)\s*;))");
  std::string result;
  auto begin = std::sregex_iterator(glsl.begin(), glsl.end(), out);
  size_t last = 0;
  for (auto it = begin; it != std::sregex_iterator(); ++it) {
    const std::smatch& m = *it;
    auto o = std::find_if(capture.outputs.begin(), capture.outputs.end(), [&](const EmittedOutput& e) { return e.name == m[3].str(); });
    if (o == capture.outputs.end()) {
      int line = 1 + static_cast<int>(std::count(glsl.begin(), glsl.begin() + m.position(0), '\n'));
      throw InputError(SourceLoc{path, line, 1}, fmt::format("output '{}' is not an output of the generated shader", m[3].str()));
    }
    result += glsl.substr(last, static_cast<size_t>(m.position(0)) - last);
    result += fmt::format("layout(location = {}, xfb_buffer = 0, xfb_offset = {}, xfb_stride = {}){}", m[1].str(),
                          o->captureOffset, capture.captureStride, m[2].str());
    last = static_cast<size_t>(m.position(0) + m.length(0));
  }
  result += glsl.substr(last);
  size_t main = result.find("void main(");
  if (main == std::string::npos) throw InputError(SourceLoc{path, 0, 0}, "no 'void main(' in the vertex shader");
  result.insert(main, fmt::format("out gl_PerVertex {{\n  layout(xfb_buffer = 0, xfb_offset = 0, xfb_stride = {}) vec4 gl_Position;\n}};\n",
                                  capture.captureStride));
  return result;
}

GenerateResult handWrittenProgram(const std::string& text, const std::string& path, const GenerateResult& like,
                                  TargetEnv env) {
  // A capture build declares the record of the program it stands in for, which generating
  // that program checked against the device (GenerateOptions::maxCaptureBytes).
  GlslShader s = parseVertex(text, path, env, like.glsl.captureStride);
  const Rig& rig = like.in.rig;
  GenerateResult r = like;
  r.glsl.text = text;
  r.glsl.inputs.clear();
  r.glsl.uniforms.clear();
  r.glsl.buffers.clear();
  for (const auto& in : s.inputs()) {
    if (in.name.rfind("gl_", 0) == 0) continue;  // gl_VertexIndex: a built-in, not an attribute
    EmittedInput e;
    e.name = in.name;
    e.location = in.location;
    for (size_t a = 0; a < rig.attributes.size() && e.attribute < 0; ++a) {
      const RigAttribute& ra = rig.attributes[a];
      const std::string base = "a_" + ra.name;
      if (!ra.perMorphTarget && in.name == base) e.attribute = static_cast<int>(a);
      if (ra.perMorphTarget && in.name.size() > base.size() && in.name.compare(0, base.size(), base) == 0 &&
          in.name.find_first_not_of("0123456789", base.size()) == std::string::npos) {
        e.attribute = static_cast<int>(a);
        e.target = std::stoi(in.name.substr(base.size()));
      }
    }
    if (e.attribute < 0 || in.location < 0)
      throw InputError(SourceLoc{path, 0, 0}, fmt::format("input '{}' names no attribute of rig '{}' (a_<attribute>[target] "
                                                          "with a location)", in.name, rig.name));
    r.glsl.inputs.push_back(e);
  }
  r.spirv = SpirvModule{};
  r.spirv.words = s.spirv();
  for (const auto& b : s.uniformBlocks()) r.spirv.uniformBlockSize = std::max(r.spirv.uniformBlockSize, b.size);
  for (const auto& m : s.uniformMembers()) {
    r.spirv.uniforms.push_back(UniformLayout{m.name, m.offset, m.arrayStride, m.matrixStride, m.size});
    for (size_t u = 0; u < rig.uniforms.size(); ++u)
      if (m.name == "u_" + rig.uniforms[u].name) r.glsl.uniforms.push_back(EmittedUniform{m.name, static_cast<int>(u)});
  }
  r.spirv.descriptors = s.descriptors();
  // A hand port of a buffer-fed program reads the generated program's storage buffers at their
  // bindings; they are filled as for the program it is compared with.
  for (const auto& d : r.spirv.descriptors) {
    if (d.kind != ShaderDescriptor::Kind::StorageBlock) continue;
    auto b = std::find_if(like.glsl.buffers.begin(), like.glsl.buffers.end(),
                          [&](const EmittedBuffer& e) { return d.set == 0 && int(d.binding) == e.binding; });
    if (b == like.glsl.buffers.end())
      throw InputError(SourceLoc{path, 0, 0}, fmt::format("storage buffer '{}' (set {}, binding {}) is not one the generated "
                                                          "program reads", d.name, d.set, d.binding));
    r.glsl.buffers.push_back(*b);
  }
  return r;
}

double pearson(const std::vector<double>& x, const std::vector<double>& y) {
  const size_t n = std::min(x.size(), y.size());
  if (n < 3) return NAN;
  double mx = std::accumulate(x.begin(), x.begin() + long(n), 0.0) / double(n);
  double my = std::accumulate(y.begin(), y.begin() + long(n), 0.0) / double(n);
  double sxy = 0, sxx = 0, syy = 0;
  for (size_t i = 0; i < n; ++i) {
    sxy += (x[i] - mx) * (y[i] - my);
    sxx += (x[i] - mx) * (x[i] - mx);
    syy += (y[i] - my) * (y[i] - my);
  }
  if (sxx == 0 || syy == 0) return NAN;
  return sxy / std::sqrt(sxx * syy);
}

double spearman(const std::vector<double>& x, const std::vector<double>& y) { return pearson(ranks(x), ranks(y)); }

double spearmanWithinSpread(const std::vector<double>& x, const std::vector<double>& y, double spread) {
  std::vector<size_t> order(y.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return y[a] < y[b]; });
  std::vector<double> tied(y.size());
  for (size_t i = 0; i < order.size();) {
    size_t j = i;
    while (j + 1 < order.size() && y[order[j + 1]] <= y[order[i]] * (1 + spread)) ++j;
    for (size_t k = i; k <= j; ++k) tied[order[k]] = y[order[i]];
    i = j + 1;
  }
  return spearman(x, tied);
}

// Two timings of one program on one device differ by up to this much (relative): docs/performance.md.
constexpr double kRunToRunSpread = 0.005;

uint32_t drawsPerFrame(uint32_t draws, uint32_t minVertices, size_t vertices) {
  const uint64_t needed = vertices == 0 ? 0 : (uint64_t(minVertices) + vertices - 1) / vertices;
  return uint32_t(std::min<uint64_t>(kMostDrawsPerFrame, std::max<uint64_t>({1, draws, needed})));
}

double medianRound(const GpuBenchRow& row) {
  if (row.roundNsPerVertex.empty()) return NAN;
  return medianOf(row.roundNsPerVertex);
}

bool weighedPlan(const GpuBenchRow& row) { return row.hasCost && row.validation == "pass" && !std::isnan(medianRound(row)); }

int pinnedPlan(const GpuBenchReport& r) {
  int best = -1;
  for (size_t i = 0; i < r.rows.size(); ++i) {
    const GpuBenchRow& row = r.rows[i];
    if (!weighedPlan(row)) continue;
    if (best < 0 || medianRound(row) < medianRound(r.rows[size_t(best)])) best = int(i);
  }
  return best;
}

CandidateRanking rankCandidates(const GpuBenchReport& r) {
  CandidateRanking c;
  double leastCost = INFINITY, mostCost = -INFINITY, leastTime = INFINITY, mostTime = -INFINITY;
  for (const auto& row : r.rows) {
    if (!weighedPlan(row)) continue;
    ++c.plans;
    leastCost = std::min(leastCost, double(row.planCost));
    mostCost = std::max(mostCost, double(row.planCost));
    leastTime = std::min(leastTime, medianRound(row));
    mostTime = std::max(mostTime, medianRound(row));
  }
  if (c.plans < 2 || !(leastCost > 0) || !(leastTime > 0)) return c;
  c.predictedSpread = mostCost / leastCost - 1;
  c.measuredSpread = mostTime / leastTime - 1;
  c.cannotRank = c.predictedSpread >= kRankedSpread && c.measuredSpread < kShownFraction * c.predictedSpread;
  return c;
}

bool isCpuDevice(const std::string& deviceName) { return deviceName.find("llvmpipe") != std::string::npos; }

void timeCpuDevicesSingleThreaded() { setenv("LP_NUM_THREADS", "0", /*overwrite=*/0); }

PredictionCheck checkPredictions(const std::vector<GpuBenchRow>& rows, double GpuBenchRow::*clock) {
  PredictionCheck c;
  std::vector<double> predicted, measured;
  double fastest = INFINITY;
  for (const auto& r : rows)
    if (r.hasCost && r.validation == "pass" && r.*clock > 0) {
      ++c.plans;
      if (r.*clock < fastest) c.fastest = static_cast<int>(&r - rows.data());
      fastest = std::min(fastest, r.*clock);
      if (r.predictedNsPerVertex >= 0) predicted.push_back(r.predictedNsPerVertex), measured.push_back(r.*clock);
    }
  c.spearman = spearmanWithinSpread(predicted, measured, kRunToRunSpread);
  if (!rows.empty() && rows.front().label == "generated" && rows.front().*clock > 0 && !predicted.empty())
    c.generatedOverFastest = rows.front().*clock / fastest;
  return c;
}

RoundSpread generatedOverFastestByRound(const std::vector<GpuBenchRow>& rows) {
  RoundSpread r;
  if (rows.empty() || rows.front().label != "generated" || !rows.front().hasCost || rows.front().validation != "pass") return r;
  std::vector<const GpuBenchRow*> plans;
  size_t rounds = SIZE_MAX;
  for (const auto& row : rows)
    if (row.hasCost && row.validation == "pass") {
      plans.push_back(&row);
      rounds = std::min(rounds, row.roundNsPerVertex.size());
    }
  if (rounds == SIZE_MAX || rounds < 2) return r;
  r.rounds = rounds;
  r.least = INFINITY;
  r.most = -INFINITY;
  for (size_t k = 0; k < rounds; ++k) {
    double fastest = INFINITY;
    for (const GpuBenchRow* p : plans) fastest = std::min(fastest, p->roundNsPerVertex[k]);
    const double ratio = rows.front().roundNsPerVertex[k] / fastest;
    r.least = std::min(r.least, ratio);
    r.most = std::max(r.most, ratio);
  }
  return r;
}

std::string describeRoundSpread(const RoundSpread& spread) {
  if (std::isnan(spread.least)) return "";
  return fmt::format(" (within one round: {:.3f}x to {:.3f}x over {} rounds)", spread.least, spread.most, spread.rounds);
}

GpuBenchReport runGpuBench(const GpuBenchOptions& opts) {
  const TargetEnv env = opts.render.gen.targetEnv;
  timeCpuDevicesSingleThreaded();
  // Every program is validated on the device that times it, which is opened first: a named
  // device's own limits constrain the search.
  ValidateOptions vo;
  vo.device = opts.render.device;
  vo.validationLayers = opts.render.validationLayers;
  vo.checkFloatData = false;  // the timed program's correctness is the first check; the second is validate's
  Validator validator(vo);
  GenerateOptions gen = opts.render.gen;
  const std::string limits = applyDeviceLimits(gen, opts.render.limits, validator.harness());
  gen.capture = false;
  LoadedInputs in = loadInputs(gen);
  RenderScene scene = renderScene(in.rig, opts.render);
  // As validate does: the buffer forms must fit this mesh (+1: the capture draws an even
  // count), and a device profile's per-draw weights are spread over its vertices. The plans
  // are priced for the workload of the mesh and pose timed (measure/workload.h).
  if (gen.maxVertices == 0) gen.maxVertices = static_cast<int64_t>(scene.mesh.vertexCount) + 1;
  gen.workload = sceneWorkload(scene, isGltfPath(gen.rigPath) ? gen.rigPath : "procedural mesh '" + opts.render.mesh + "'");
  FragmentProgram frag = compileFragmentFile(gen.fragmentPath, env);
  std::vector<rt::Texture> textures = texturesFor(frag, opts.render.lighting);
  // The fragments a draw covers are part of the workload too (a profile may price them): counted,
  // where the device can, on one draw of a plan priced without the workload. Every plan that
  // validates writes the same positions, so covers the same pixels.
  rt::Renderer renderer(validator.harness());
  double shadedPerVertex = -1;
  if (scene.mesh.vertexCount > 0) {
    rt::DrawRequest req = drawRequest(generateFrom(in, gen), frag, textures, scene);
    req.width = opts.render.width;
    req.height = opts.render.height;
    if (auto st = renderer.statistics(req)) {
      shadedPerVertex = double(st->vertexInvocations) / double(scene.mesh.vertexCount);
      gen.workload.fragmentsPerVertex = double(st->fragmentInvocations) / double(scene.mesh.vertexCount);
    }
  }
  in = loadInputs(gen);
  scene = renderScene(in.rig, opts.render);
  const Rig& rig = in.rig;

  // The programs: generated, its forced alternatives, the hand port, the floor.
  std::vector<Program> programs;
  // A plan of the options with `bans` added: "generated" has none, a forced alternative the
  // other rules producing its fact (the row keeps them: generate --ban writes the same plan).
  auto addGenerated = [&](const std::string& label, std::vector<std::string> bans = {}) -> bool {
    GenerateOptions render = gen;
    render.bannedRules.insert(render.bannedRules.end(), bans.begin(), bans.end());
    GenerateOptions capture = render;
    render.capture = false;
    capture.capture = true;
    capture.maxCaptureBytes = validator.harness().maxCaptureBytes();
    Program p;
    p.render = generateFrom(in, render);
    p.row.label = label;
    p.row.bans = std::move(bans);
    for (int a : p.render.plan.actions) p.row.rules.push_back(p.render.in.problem.actions[a].name);
    p.row.pin = bansPinning(p.render.in.problem, p.render.plan, render.bannedRules);
    for (const auto& q : programs)  // the same plan again, its rules found in any order
      if (q.row.hasCost && std::is_permutation(q.row.rules.begin(), q.row.rules.end(), p.row.rules.begin(), p.row.rules.end()))
        return false;
    p.capture = generateFrom(in, capture);
    p.row.hasCost = p.row.hasAmounts = true;
    p.row.planCost = p.render.plan.cost;
    p.row.amounts = planTermAmounts(p.render.plan, p.render.in.problem);
    if (p.render.in.profile)
      p.row.predictedNsPerVertex = predictPlanCost(p.render.plan, p.render.in.problem, *p.render.in.profile).totalNanoseconds;
    p.row.spirvInstructions = countInstructions(p.render.spirv.words);
    p.row.program = programId(p.render.spirv.words);
    programs.push_back(std::move(p));
    return true;
  };
  addGenerated("generated");
  const GenerateResult chosen = programs.front().render, chosenCapture = programs.front().capture;  // programs grows
  // A portable choice's alternatives are priced by their regret against each device's optimum
  // of the unbanned problem, as the chosen plan is: comparable plan costs.
  in.portableBest = chosen.in.portableBest;
  if (opts.candidates > 0) {
    const std::vector<RankedPlan> ranked = cheapestPlans(in, gen, opts.candidates);
    for (size_t i = 0; i < ranked.size(); ++i)
      if (!ranked[i].bans.empty()) addGenerated(fmt::format("cheapest plan #{}", i + 1), ranked[i].bans);
    // A portable objective's list is a prediction for every device: each device's own cheapest
    // joins it (a plan already listed is not timed twice), so that pin merge can weigh it.
    const std::vector<RankedPlan> own = eachDevicesCheapest(in, gen);
    for (size_t d = 0; d < own.size(); ++d)
      addGenerated(fmt::format("cheapest on {}", d == 0 ? in.profile->device : in.portable[d - 1].device), own[d].bans);
  } else if (opts.alternatives) {
    const Problem& p = chosen.in.problem;
    for (int a : chosen.plan.actions) {
      std::vector<std::string> producers;
      for (const auto& act : p.actions)
        if (act.add == p.actions[a].add) producers.push_back(act.name);
      for (const auto& alt : producers) {
        if (alt == p.actions[a].name) continue;
        std::vector<std::string> bans;
        for (const auto& other : producers)
          if (other != alt) bans.push_back(other);
        try {
          addGenerated(fmt::format("forced {} for {}", alt, p.facts[p.actions[a].add].name), std::move(bans));
        } catch (const InputError&) {
          // the alternative needs something this rig cannot provide
        }
      }
    }
  }
  if (!opts.handPortPath.empty()) {
    const std::string text = readInputFile(opts.handPortPath);
    Program p;
    p.row.label = "hand port (" + std::filesystem::path(opts.handPortPath).filename().string() + ")";
    p.render = handWrittenProgram(text, opts.handPortPath, chosen, env);
    p.capture = handWrittenProgram(addCaptureQualifiers(text, opts.handPortPath, chosenCapture.glsl), opts.handPortPath,
                                   chosenCapture, env);
    p.row.spirvInstructions = countInstructions(p.render.spirv.words);
    p.row.program = programId(p.render.spirv.words);
    programs.push_back(std::move(p));
  }
  for (bool allInputs : {false, true}) {
    if (!opts.floor) break;
    Program p;
    p.row.label = allInputs ? "floor + every input fetched" : "floor (pass-through)";
    p.render = handWrittenProgram(floorShader(chosen, false, allInputs), "floor.vert", chosen, env);
    p.capture = handWrittenProgram(floorShader(chosenCapture, true, allInputs), "floor.vert", chosenCapture, env);
    p.row.spirvInstructions = countInstructions(p.render.spirv.words);
    p.row.program = programId(p.render.spirv.words);
    p.row.hasAmounts = true;
    p.row.amounts = floorAmounts(p.render, chosen.in.problem, env);
    if (chosen.in.profile)
      p.row.predictedNsPerVertex = chosen.in.profile->predictNanoseconds(p.row.amounts, chosen.in.profile->verticesPerDraw);
    p.validate = false;
    programs.push_back(std::move(p));
  }

  // Validated on the device that times them, fed exactly as timed: the timed pose and a
  // hostile random one (a rest pose hides a wrong bone index).
  ValidationScene vscene{scene.mesh, {scene.pose}, scene.shape};
  vscene.poses.push_back(rt::makeRandomPose(scene.shape, 1, rt::hostilePoseOptions(scene.shape.uniformScale)));
  limitActiveTargets(rig, vscene.poses, 1);
  for (Program& p : programs) {
    if (!p.validate) continue;
    RunReport v = validator.runOne(p.capture, vscene, p.row.label);
    p.row.validation = v.pass ? "pass" : "FAIL";
    for (const auto& o : v.outputs)
      if (!o.pass) p.row.validation += fmt::format(": {} (max rel {:.2e})", o.name, o.maxRelError);
    if (!v.validationMessages.empty()) p.row.validation += ": validation layer: " + v.validationMessages.front();
  }

  GpuBenchReport rep;
  rep.notes = in.notes;
  rep.inputs = sha256OfFiles(chosen.pinnedInputs);
  if (opts.render.gen.pin)
    if (auto changed = pinInputsChanged(*opts.render.gen.pin, rep.inputs)) rep.notes.push_back(*changed);
  rep.device = validator.harness().deviceName();
  rep.limits = limits;
  rep.driver = renderer.driver();
  rep.workload = gen.workload;
  rep.vertices = scene.mesh.vertexCount;
  rep.triangles = scene.indices.size() / 3;
  rep.shadedVerticesPerVertex = shadedPerVertex;
  const uint32_t draws = drawsPerFrame(opts.drawsPerFrame, opts.minVerticesPerFrame, scene.mesh.vertexCount);
  rep.drawsPerFrame = draws;
  rep.frames = opts.frames;
  rep.rounds = std::max<uint32_t>(1, opts.rounds);
  rep.width = opts.render.width;
  rep.height = opts.render.height;
  // Rounds over all programs, the order rotated each round; a program's number is its best
  // round's median frame, so another process stealing a round (lavapipe shares the CPU)
  // does not pick the winner. A program that failed validation is not timed.
  // The clock predictions are checked by: raster on, timestamps on a GPU; on a CPU device the
  // one calibrate fits there (isCpuDevice). Each round's figure by it is kept.
  double GpuBenchRow::*clock = &GpuBenchRow::rasterOnNsPerVertex;
  rep.predictionClock = kClockTimestamps;
  if (isCpuDevice(rep.device)) {
    clock = opts.rasterOff ? &GpuBenchRow::rasterOffCpuNsPerVertex : &GpuBenchRow::rasterOnWallNsPerVertex;
    rep.predictionClock = opts.rasterOff ? kClockCpuRasterOff : kClockCpuRasterOn;
  }
  auto best = [&](GpuBenchRow& row, double GpuBenchRow::*field, double v) {
    row.*field = row.*field < 0 ? v : std::min(row.*field, v);
    if (field == clock) row.roundNsPerVertex.push_back(v);
  };
  const size_t n = programs.size();
  for (uint32_t round = 0; round < std::max<uint32_t>(1, opts.rounds); ++round)
    for (size_t k = 0; k < n; ++k) {
      Program& p = programs[(k + round) % n];
      if (p.validate && p.row.validation != "pass") continue;
      rt::TimingRequest t;
      t.drawsPerFrame = draws;
      t.frames = opts.frames + 1;
      auto noteMemory = [&](const rt::Timing& tm) {
        if (rep.inputMemory.empty()) rep.inputMemory = inputMemoryLine(opts.inputMemory, tm.inputMemory);
      };
      auto perVertex = [&](const std::vector<double>& ns, uint32_t vertices) {
        std::vector<double> frames(ns.begin() + 1, ns.end());  // the first warms up
        return medianOf(frames) / (double(draws) * double(vertices));
      };
      if (opts.rasterOn) {
        rt::DrawRequest req = drawRequest(p.render, frag, textures, scene);
        req.memory = opts.inputMemory;
        req.width = opts.render.width;
        req.height = opts.render.height;
        t.rasterize = true;
        rt::Timing tm = renderer.time(req, t);
        noteMemory(tm);
        if (p.row.driverStatistics.empty()) p.row.driverStatistics = tm.vertexStatistics;
        best(p.row, &GpuBenchRow::rasterOnNsPerVertex, perVertex(tm.frameNs, tm.verticesPerDraw));
        best(p.row, &GpuBenchRow::rasterOnWallNsPerVertex, perVertex(tm.wallNs, tm.verticesPerDraw));
      }
      if (opts.rasterOff) {
        rt::DrawRequest req = drawRequest(p.capture, frag, textures, scene);
        req.memory = opts.inputMemory;
        t.rasterize = false;
        t.captureStride = p.capture.glsl.captureStride;
        rt::Timing tm = renderer.time(req, t);
        noteMemory(tm);
        if (!opts.rasterOn && p.row.driverStatistics.empty()) p.row.driverStatistics = tm.vertexStatistics;
        best(p.row, &GpuBenchRow::rasterOffNsPerVertex, perVertex(tm.frameNs, tm.verticesPerDraw));
        best(p.row, &GpuBenchRow::rasterOffWallNsPerVertex, perVertex(tm.wallNs, tm.verticesPerDraw));
        best(p.row, &GpuBenchRow::rasterOffCpuNsPerVertex, perVertex(tm.cpuNs, tm.verticesPerDraw));
      }
    }
  for (const auto& p : programs) rep.rows.push_back(p.row);
  summarize(rep);
  const auto& msgs = validator.harness().validationMessages();
  if (!msgs.empty()) throw std::runtime_error("validation layer: " + msgs.front());
  return rep;
}

GpuBenchReport mergeProcessRuns(const std::vector<GpuBenchReport>& runs) {
  if (runs.empty()) throw std::runtime_error("no timed process to merge");
  GpuBenchReport rep = runs.front();
  for (size_t i = 1; i < runs.size(); ++i) {
    const GpuBenchReport& other = runs[i];
    if (other.rows.size() != rep.rows.size() || other.predictionClock != rep.predictionClock || other.device != rep.device)
      throw std::runtime_error(fmt::format("process {} of {} timed other programs or another clock", i + 1, runs.size()));
    for (size_t k = 0; k < rep.rows.size(); ++k) {
      GpuBenchRow& row = rep.rows[k];
      const GpuBenchRow& o = other.rows[k];
      if (o.label != row.label || o.program != row.program)
        throw std::runtime_error(fmt::format("process {} of {} timed '{}' ({}) where the first timed '{}' ({})", i + 1,
                                             runs.size(), o.label, o.program, row.label, row.program));
      if (o.validation != "pass" && !o.validation.empty()) row.validation = o.validation;  // a failure anywhere is one
      for (double GpuBenchRow::*f : {&GpuBenchRow::rasterOnNsPerVertex, &GpuBenchRow::rasterOffNsPerVertex,
                                     &GpuBenchRow::rasterOnWallNsPerVertex, &GpuBenchRow::rasterOffCpuNsPerVertex,
                                     &GpuBenchRow::rasterOffWallNsPerVertex})
        if (o.*f >= 0) row.*f = row.*f < 0 ? o.*f : std::min(row.*f, o.*f);
      row.roundNsPerVertex.insert(row.roundNsPerVertex.end(), o.roundNsPerVertex.begin(), o.roundNsPerVertex.end());
    }
    rep.rounds += other.rounds;  // the notes are loading's: the same in every process
  }
  rep.processes = uint32_t(runs.size());
  summarize(rep);
  return rep;
}

namespace {

double GpuBenchRow::*predictionClockOf(const GpuBenchReport& rep) {
  if (rep.predictionClock == kClockCpuRasterOff) return &GpuBenchRow::rasterOffCpuNsPerVertex;
  if (rep.predictionClock == kClockCpuRasterOn) return &GpuBenchRow::rasterOnWallNsPerVertex;
  return &GpuBenchRow::rasterOnNsPerVertex;
}

}  // namespace

void summarize(GpuBenchReport& rep) {
  double GpuBenchRow::*clock = predictionClockOf(rep);
  std::vector<double> cost, on, off, offWall;
  for (const auto& r : rep.rows)
    if (r.hasCost && r.validation == "pass") {
      cost.push_back(double(r.planCost));
      on.push_back(r.rasterOnNsPerVertex);
      off.push_back(r.rasterOffNsPerVertex);
      offWall.push_back(r.rasterOffWallNsPerVertex);
    }
  rep.pearsonOffWall = pearson(cost, offWall);
  rep.spearmanOffWall = spearman(cost, offWall);
  rep.pearsonOn = pearson(cost, on);
  rep.spearmanOn = spearman(cost, on);
  rep.pearsonOff = pearson(cost, off);
  rep.spearmanOff = spearman(cost, off);
  const PredictionCheck predictedOn = checkPredictions(rep.rows, clock);
  rep.spearmanPredictedOn = predictedOn.spearman;
  rep.generatedOverFastestOn = predictedOn.generatedOverFastest;
  if (!std::isnan(rep.generatedOverFastestOn)) rep.byRound = generatedOverFastestByRound(rep.rows);
  rep.fastestPlan = predictedOn.fastest;
  if (rep.fastestPlan >= 0 && rep.rows.front().*clock > 0)
    rep.fastestOverGenerated = rep.rows[size_t(rep.fastestPlan)].*clock / rep.rows.front().*clock;
}

std::string inputMemoryLine(rt::InputMemory placement, const std::string& memoryTypes) {
  return fmt::format("inputs: {}, in {}",
                     placement == rt::InputMemory::DeviceLocal ? "device-local (a staging copy)" : "mapped (written in place)",
                     memoryTypes.empty() ? "no buffer" : memoryTypes);
}

namespace {
// A program's statistics as (name, value) cells: a statistic of a second compiled vertex
// executable named "<its name>: <statistic>"; the tables' separator '|' never in a name.
std::vector<std::pair<std::string, double>> statisticCells(const std::vector<rt::ShaderStatistic>& all) {
  std::vector<std::pair<std::string, double>> cells;
  for (const auto& st : all) {
    std::string name = st.executable == all.front().executable ? st.name : st.executable + ": " + st.name;
    std::replace(name.begin(), name.end(), '|', '/');
    std::replace(name.begin(), name.end(), '\n', ' ');
    cells.emplace_back(std::move(name), st.value);
  }
  return cells;
}
// A statistic's value as the driver gave it: whole numbers without a fraction.
std::string statisticValue(double v) {
  return v == std::floor(v) && std::fabs(v) < 1e15 ? fmt::format("{:.0f}", v) : fmt::format("{:.6g}", v);
}
}  // namespace

std::string describeDriverStatistics(const std::vector<rt::ShaderStatistic>& statistics) {
  std::string s;
  for (auto [name, value] : statisticCells(statistics)) {
    std::replace(name.begin(), name.end(), ';', ',');
    std::replace(name.begin(), name.end(), '=', '-');
    s += (s.empty() ? "" : "; ") + name + "=" + statisticValue(value);
  }
  return s;
}

std::string formatGpuBench(const GpuBenchReport& r) {
  std::string s = fmt::format("device: {} (driver: {})\n{}mesh: {} vertices, {} triangles; {} draws per frame, median of {} frames, best of {} rounds{}; "
                              "rasterization on: {}x{} target\n\n",
                              r.device, r.driver, r.limits.empty() ? "" : r.limits + "\n", r.vertices, r.triangles,
                              r.drawsPerFrame, r.frames, r.rounds,
                              r.processes > 1 ? fmt::format(" in {} processes", r.processes) : "", r.width, r.height);
  s.insert(s.size() - 1, "workload: " + describeWorkload(r.workload) + "\n");
  if (!r.inputMemory.empty()) s.insert(s.size() - 1, r.inputMemory + "\n");
  if (r.shadedVerticesPerVertex >= 0)
    s.insert(s.size() - 1, fmt::format("one draw, counted by the device: {:.3f} vertex shader invocations per vertex (its fragments: the workload's)\n",
                                       r.shadedVerticesPerVertex));
  const GpuBenchRow* gen = nullptr;
  for (const auto& row : r.rows)
    if (row.label == "generated") gen = &row;
  auto cell = [](double ns, double ref) {
    if (ns < 0) return std::string("—");
    return ref > 0 ? fmt::format("{:.4f} ({:.2f}x)", ns, ns / ref) : fmt::format("{:.4f}", ns);
  };
  s += "ns per vertex (x: relative to the generated program); timestamps = GPU timestamp queries, "
       "host = submit-to-fence wall time\n\n";
  // A CPU device's own clock (calibrate's there) gets its column.
  const bool cpuClock = std::any_of(r.rows.begin(), r.rows.end(), [](const GpuBenchRow& x) { return x.rasterOffCpuNsPerVertex > 0; });
  s += "| program | on device | plan cost | locations | bytes | predicted | SPIR-V instr. | raster on, timestamps | raster off (xfb), timestamps | raster on, host | raster off, host |";
  s += cpuClock ? " raster off, process CPU |\n|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n" : "\n|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const auto& row : r.rows)
    s += fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |{}\n", row.label, row.validation.empty() ? "—" : row.validation,
                     row.hasCost ? std::to_string(row.planCost) : "—",
                     row.hasAmounts ? std::to_string(row.amounts[kTermLocations]) : "—",
                     row.hasAmounts ? std::to_string(row.amounts[kTermAttributeBytes] + row.amounts[kTermBufferBytes]) : "—",
                     row.predictedNsPerVertex >= 0 ? fmt::format("{:.4f}", row.predictedNsPerVertex) : "—",
                     row.spirvInstructions, cell(row.rasterOnNsPerVertex, gen ? gen->rasterOnNsPerVertex : -1),
                     cell(row.rasterOffNsPerVertex, gen ? gen->rasterOffNsPerVertex : -1),
                     cell(row.rasterOnWallNsPerVertex, gen ? gen->rasterOnWallNsPerVertex : -1),
                     cell(row.rasterOffWallNsPerVertex, gen ? gen->rasterOffWallNsPerVertex : -1),
                     cpuClock ? " " + cell(row.rasterOffCpuNsPerVertex, gen ? gen->rasterOffCpuNsPerVertex : -1) + " |" : "");
  // Only the modes that were timed; a correlation needs 3 programs (pearson() is NaN below).
  const auto passed =
      std::count_if(r.rows.begin(), r.rows.end(), [](const GpuBenchRow& x) { return x.hasCost && x.validation == "pass"; });
  auto timed = [&](double GpuBenchRow::*clock) {
    return std::any_of(r.rows.begin(), r.rows.end(), [&](const GpuBenchRow& x) { return x.*clock >= 0; });
  };
  auto corr = [](const char* what, double p, double sp) {
    return std::isnan(p) && std::isnan(sp) ? fmt::format("{} n/a", what)
                                           : fmt::format("{} Pearson {:.2f}, Spearman {:.2f}", what, p, sp);
  };
  std::vector<std::string> modes;
  if (timed(&GpuBenchRow::rasterOnNsPerVertex)) modes.push_back(corr("raster on (timestamps)", r.pearsonOn, r.spearmanOn));
  if (timed(&GpuBenchRow::rasterOffNsPerVertex)) modes.push_back(corr("raster off (timestamps)", r.pearsonOff, r.spearmanOff));
  if (timed(&GpuBenchRow::rasterOffWallNsPerVertex))
    modes.push_back(corr("raster off (host)", r.pearsonOffWall, r.spearmanOffWall));
  s += fmt::format("\nplan cost vs time over the {} generated programs that passed{}: {}\n", passed,
                   passed < 3 ? " (a correlation needs 3)" : "", fmt::join(modes, "; "));
  if (!std::isnan(r.spearmanPredictedOn) || !std::isnan(r.generatedOverFastestOn))
    s += fmt::format("device profile: predicted vs measured ({}; within 0.5 %: ties) Spearman {:.2f}; the generated program takes "
                     "{:.3f}x the fastest generated one{}\n",
                     r.predictionClock, r.spearmanPredictedOn, r.generatedOverFastestOn, describeRoundSpread(r.byRound));
  // What the driver compiled each vertex stage into, where it says (one column per statistic,
  // in the order the driver first gave them).
  std::vector<std::vector<std::pair<std::string, double>>> cells;
  std::vector<std::string> names;
  for (const auto& row : r.rows) {
    cells.push_back(statisticCells(row.driverStatistics));
    for (const auto& cell : cells.back())
      if (std::find(names.begin(), names.end(), cell.first) == names.end()) names.push_back(cell.first);
  }
  if (!names.empty()) {
    s += "\nthe driver's statistics of each program's vertex stage (VK_KHR_pipeline_executable_properties)\n\n| program |";
    for (const auto& n : names) s += " " + n + " |";
    s += "\n|---|";
    for (size_t i = 0; i < names.size(); ++i) s += "---:|";
    s += "\n";
    for (size_t i = 0; i < r.rows.size(); ++i) {
      s += "| " + r.rows[i].label + " |";
      for (const auto& n : names) {
        auto it = std::find_if(cells[i].begin(), cells[i].end(), [&](const auto& cell) { return cell.first == n; });
        s += " " + (it == cells[i].end() ? std::string("—") : statisticValue(it->second)) + " |";
      }
      s += "\n";
    }
    s += "\n";
  }
  // The device's own answer, for a build that wants it: which plan to pin, and how.
  if (r.fastestPlan > 0) {
    const GpuBenchRow& f = r.rows[size_t(r.fastestPlan)];
    std::string flags;
    for (const auto& b : f.bans) flags += " --ban " + b;
    s += fmt::format("fastest validated plan ({}): {}{}; generate writes it with{} added\n", r.predictionClock, f.label,
                     std::isnan(r.fastestOverGenerated) ? "" : fmt::format(", {:.3f}x the generated one's time", r.fastestOverGenerated),
                     flags);
  } else if (r.fastestPlan == 0) {
    s += fmt::format("fastest validated plan ({}): the generated one\n", r.predictionClock);
  }
  return s;
}

}  // namespace sg

// Benchmarks of validation at Dawn scale and of the search. Not part of ctest: run
// bench/run.sh (numbers and the command in docs/validation.md).
//
// BM_ValidateDawn: one Validator::runOne of the Dawn face's chosen plan over the
//   180,000-vertex mesh (proceduralScene(rig, "dawn", 1, 1)), validation layer on. Counters:
//   the share of the wall time spent in Vulkan setup, upload, run, readback and the GLM
//   reference (RunReport timings), the rest ("other": building the vertex streams and
//   uniforms, comparing), and ratios against two baselines measured in the same iterations
//   (timing paused): the reference alone (the Dawn outputs' semantics on the same mesh and
//   pose), and a minimal shader (gl_Position from a position and one matrix) validated on a
//   mesh of the same size.
// BM_ValidateMinimal, BM_ReferenceDawn: those baselines on their own.
// BM_Definitions/<threads>: the reference validation computes, the definitions of the Dawn
//   face's outputs (Interpreter::evaluate: compiled, on `threads` threads, 0 = every core) on
//   the 180,000-vertex mesh in one pose, as ratios to what it checks and replaced, measured
//   in the same iterations: the device run of the same plan on the same mesh (lavapipe, draw
//   + transform feedback: RunReport::timings.runMs), the hand-written GLM reference, and the
//   tree walker (timed on every 60th vertex, scaled to the mesh).
// BM_Search/<heuristic>: A* on the Dawn problem (blind, hmax, lmcut), with expansions and
//   time as ratios against blind search (uniform cost), measured in the same iterations.
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdlib>
#include <memory>
#include <string>

#include "rules/instantiate.h"
#include "runtime/mesh.h"
#include "runtime/reference.h"
#include "validate/interpreter.h"
#include "validate/poses.h"
#include "validate/validate.h"

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

std::string src(const std::string& rel) { return std::string(SG_SOURCE_DIR) + "/" + rel; }

sg::GenerateOptions dawnOptions() {
  sg::GenerateOptions g;
  g.rigPath = src("examples/dawn/face.rig.yaml");
  g.fragmentPath = src("examples/dawn/face.frag");
  g.rulesPaths = {src("examples/dawn/rules.yaml")};
  return g;
}

// A generated capture build and its 180k-vertex scene (built once per process).
struct Case {
  sg::GenerateResult gen;
  sg::ValidationScene scene;
};

std::unique_ptr<Case> makeCase(sg::GenerateOptions g) {
  g.capture = true;
  auto c = std::make_unique<Case>();
  c->gen = sg::generate(g);
  c->scene = sg::proceduralScene(c->gen.in.rig, "dawn", 1, 1);
  return c;
}

Case& dawnCase() {
  static std::unique_ptr<Case> c = makeCase(dawnOptions());
  return *c;
}

Case& minimalCase() {
  static std::unique_ptr<Case> c = [] {
    sg::GenerateOptions g;
    g.rigPath = src("bench/data/minimal.rig.yaml");
    g.fragmentPath = src("bench/data/minimal.frag");
    g.rulesPaths = {src("rules/standard.yaml")};
    return makeCase(g);
  }();
  return *c;
}

// One Vulkan instance/device for the process (as a validation session would have).
sg::Validator& validator() {
  static sg::Validator v(sg::ValidateOptions{});
  return v;
}

// The GLM reference of every semantic the shader outputs (what runOne computes), alone.
double referenceOnlyMs(const Case& c) {
  auto t0 = Clock::now();
  sg::rt::ReferenceEvaluator ref(c.scene.mesh, c.scene.poses[0], c.scene.shape);
  for (const auto& o : c.gen.glsl.outputs)
    for (const auto& s : o.semantics) benchmark::DoNotOptimize(ref.values(s));
  return msSince(t0);
}

double validateMs(const Case& c, sg::RunReport* out = nullptr) {
  auto t0 = Clock::now();
  sg::RunReport r = validator().runOne(c.gen, c.scene, "bench");
  double ms = msSince(t0);
  if (!r.pass) throw std::runtime_error("validation failed in the benchmark");
  if (out) *out = std::move(r);
  return ms;
}

void BM_ValidateDawn(benchmark::State& state) {
  Case& dawn = dawnCase();
  Case& minimal = minimalCase();
  validateMs(dawn);  // warm-up: first pipeline build, page faults
  validateMs(minimal);
  double wall = 0, setup = 0, upload = 0, run = 0, readback = 0, reference = 0;
  double baseReference = 0, baseMinimal = 0;
  for (auto _ : state) {
    sg::RunReport r;
    wall += validateMs(dawn, &r);
    setup += r.timings.setupMs;
    upload += r.timings.uploadMs;
    run += r.timings.runMs;
    readback += r.timings.readbackMs;
    reference += r.referenceMs;
    state.PauseTiming();
    baseReference += referenceOnlyMs(dawn);
    baseMinimal += validateMs(minimal);
    state.ResumeTiming();
  }
  state.counters["vertices"] = static_cast<double>(dawn.scene.mesh.vertexCount);
  state.counters["setup"] = setup / wall;
  state.counters["upload"] = upload / wall;
  state.counters["run"] = run / wall;
  state.counters["readback"] = readback / wall;
  state.counters["reference"] = reference / wall;
  state.counters["other"] = 1.0 - (setup + upload + run + readback + reference) / wall;
  state.counters["x_ref_only"] = wall / baseReference;
  state.counters["x_minimal"] = wall / baseMinimal;
  state.counters["vert/s"] = benchmark::Counter(static_cast<double>(dawn.scene.mesh.vertexCount),
                                                benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_ValidateDawn)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);

void BM_ValidateMinimal(benchmark::State& state) {
  Case& minimal = minimalCase();
  validateMs(minimal);
  for (auto _ : state) validateMs(minimal);
  state.counters["vertices"] = static_cast<double>(minimal.scene.mesh.vertexCount);
}
BENCHMARK(BM_ValidateMinimal)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);

void BM_ReferenceDawn(benchmark::State& state) {
  Case& dawn = dawnCase();
  for (auto _ : state) referenceOnlyMs(dawn);
  state.counters["vertices"] = static_cast<double>(dawn.scene.mesh.vertexCount);
}
BENCHMARK(BM_ReferenceDawn)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);

void BM_Definitions(benchmark::State& state) {
  Case& dawn = dawnCase();
  const sg::Rig& rig = dawn.gen.in.rig;
  const sg::RuleSet& rules = dawn.gen.in.rules;
  const sg::RigShape shape = sg::shapeOfRig(rig, rules);
  const sg::rt::Mesh mesh = sg::quantizeForRig(rig, dawn.scene.mesh);
  const sg::UniformValues uniforms = sg::poseUniforms(rig, dawn.scene.poses[0]);
  std::vector<std::string> semantics;
  for (const auto& o : dawn.gen.glsl.outputs) semantics.insert(semantics.end(), o.semantics.begin(), o.semantics.end());
  sg::Interpreter interp(rules, shape, mesh, uniforms);
  interp.setThreads(static_cast<unsigned>(state.range(0)));
  // The tree walker on every 60th vertex (it takes seconds on the whole mesh).
  const sg::rt::Mesh sample = sg::rt::everyNthVertex(mesh, 60);
  sg::Interpreter tree(rules, shape, sample, uniforms);
  auto t0 = Clock::now();
  tree.evaluateByTree(semantics);
  const double treeMs = msSince(t0) * static_cast<double>(mesh.vertexCount) / static_cast<double>(sample.vertexCount);
  interp.evaluate(semantics);  // warm-up
  double ms = 0, runMs = 0, glmMs = 0;
  for (auto _ : state) {
    auto t = Clock::now();
    benchmark::DoNotOptimize(interp.evaluate(semantics));
    ms += msSince(t);
    state.PauseTiming();
    sg::RunReport r;
    validateMs(dawn, &r);
    runMs += r.timings.runMs;
    glmMs += referenceOnlyMs(dawn);
    state.ResumeTiming();
  }
  const double n = static_cast<double>(state.iterations());
  state.counters["ms"] = ms / n;
  state.counters["run_ms"] = runMs / n;
  state.counters["ref_vs_run"] = ms / runMs;
  state.counters["vs_glm"] = ms / glmMs;
  state.counters["tree_ms"] = treeMs;
  state.counters["vs_tree"] = ms / n / treeMs;
}
BENCHMARK(BM_Definitions)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

// A* on the Dawn problem with the heuristic given by the argument (0 blind, 1 hmax, 2 lmcut).
const char* const kHeuristics[] = {"blind", "hmax", "lmcut"};

struct SearchRun {
  double ms = 0;
  sg::SearchStats stats;
  int64_t cost = 0;
};

SearchRun search(const sg::Problem& p, const char* heuristic) {
  SearchRun r;
  auto t0 = Clock::now();
  auto h = sg::makeHeuristic(heuristic, p);
  auto plan = sg::astarSearch(p, *h, &r.stats);
  r.ms = msSince(t0);
  if (!plan) throw std::runtime_error("no plan");
  r.cost = plan->cost;
  return r;
}

void BM_Search(benchmark::State& state) {
  static const sg::LoadedInputs in = sg::loadInputs(dawnOptions());
  const char* heuristic = kHeuristics[state.range(0)];
  state.SetLabel(heuristic);
  double ms = 0, blindMs = 0;
  SearchRun last, blind;
  for (auto _ : state) {
    last = search(in.problem, heuristic);
    ms += last.ms;
    state.PauseTiming();
    blind = search(in.problem, "blind");
    blindMs += blind.ms;
    state.ResumeTiming();
  }
  if (last.cost != blind.cost) state.SkipWithError("heuristic search found a different plan cost than blind search");
  state.counters["cost"] = static_cast<double>(last.cost);
  state.counters["expanded"] = static_cast<double>(last.stats.expanded);
  state.counters["generated"] = static_cast<double>(last.stats.generated);
  state.counters["h0"] = static_cast<double>(last.stats.initialH);
  state.counters["exp_vs_blind"] =
      static_cast<double>(last.stats.expanded) / static_cast<double>(std::max<int64_t>(1, blind.stats.expanded));
  state.counters["time_vs_blind"] = ms / blindMs;
}
BENCHMARK(BM_Search)->DenseRange(0, 2)->Unit(benchmark::kMicrosecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();

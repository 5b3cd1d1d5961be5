// Buffer-fed deformation on lavapipe (issue 14, docs/buffers.md): time per vertex of the
// vertex shader and SPIR-V size, for the 52-target face (dense buffer loop, sparse over 6
// active targets) and, where attributes fit, the Dawn face's 5 targets as attributes
// against the same targets from a buffer. All plans run in one process on the same
// 180,000-vertex mesh and device; bench/buffers.sh prints the table of docs/buffers.md.
//
// The reported time is the harness's run time (submit to fence: the draw with transform
// feedback), set as manual time; ns_per_vertex divides it by the vertex count, and
// vs_dawn_attributes is the ratio to the Dawn face's attribute plan measured in the same run.
#include <benchmark/benchmark.h>

#include <map>
#include <memory>
#include <string>

#include "validate/validate.h"

namespace {

std::string src(const std::string& rel) { return std::string(SG_SOURCE_DIR) + "/" + rel; }

struct Case {
  sg::GenerateResult gen;
  sg::ValidationScene scene;
};

struct Plan {
  const char* rig;
  std::vector<std::string> ban;  // force the buffer form where attributes would be chosen
};

const std::map<std::string, Plan>& plans() {
  static const std::map<std::string, Plan> p{
      {"dawn5_attributes", {"examples/dawn/face.rig.yaml", {}}},
      {"dawn5_dense_buffer", {"examples/dawn/face.rig.yaml", {"object_position_morphed", "normal_occlusion_morphed"}}},
      {"face52_dense_buffer", {"tests/validate/data/face52.rig.yaml", {}}},
      {"face52_sparse6", {"tests/validate/data/face52_sparse.rig.yaml", {}}},
  };
  return p;
}

Case& caseOf(const std::string& name) {
  static std::map<std::string, std::unique_ptr<Case>> cache;
  auto& c = cache[name];
  if (!c) {
    const Plan& p = plans().at(name);
    sg::GenerateOptions g;
    g.rigPath = src(p.rig);
    g.fragmentPath = src("examples/dawn/face.frag");
    g.rulesPaths = {src("examples/dawn/rules.yaml")};
    g.bannedRules = p.ban;
    g.capture = true;
    g.maxVertices = 180001;  // the mesh below (+1: even draw count), as validate sets it
    c = std::make_unique<Case>();
    c->gen = sg::generate(g);
    c->scene = sg::proceduralScene(c->gen.in.rig, "dawn", 1, 1);
  }
  return *c;
}

sg::Validator& validator() {
  static sg::Validator v([] {
    sg::ValidateOptions o;
    o.validationLayers = false;  // timing, not checking (the tests run with the layer on)
    return o;
  }());
  return v;
}

double runSeconds(const std::string& name) {
  Case& c = caseOf(name);
  sg::RunReport r = validator().runOne(c.gen, c.scene, name);
  if (!r.pass) throw std::runtime_error(name + " fails validation");
  return r.timings.runMs / 1e3;
}

void BM_Plan(benchmark::State& state, const std::string& name) {
  Case& c = caseOf(name);
  double base = 0, mine = 0;
  int64_t n = 0;
  for (auto _ : state) {
    double s = runSeconds(name);
    state.SetIterationTime(s);
    mine += s;
    base += name == "dawn5_attributes" ? s : runSeconds("dawn5_attributes");
    ++n;
  }
  const double vertices = static_cast<double>(c.scene.mesh.vertexCount);
  state.counters["ns_per_vertex"] = mine / static_cast<double>(n) / vertices * 1e9;
  state.counters["vs_dawn_attributes"] = mine / base;
  state.counters["spirv_bytes"] = static_cast<double>(c.gen.spirv.words.size() * 4);
  state.counters["plan_cost"] = static_cast<double>(c.gen.plan.cost);
  state.counters["attributes"] = static_cast<double>(c.gen.glsl.inputs.size());
  state.counters["storage_buffers"] = static_cast<double>(c.gen.glsl.buffers.size());
}

const bool registered = [] {
  for (const auto& [name, plan] : plans())
    benchmark::RegisterBenchmark(("BM_Plan/" + name).c_str(), BM_Plan, name)->UseManualTime()->Iterations(2)->Unit(benchmark::kMillisecond);
  return true;
}();

}  // namespace

BENCHMARK_MAIN();

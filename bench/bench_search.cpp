// Benchmarks of the search engines (issue 12). Not part of ctest except a smoke run:
// bench/search_table.sh runs them and prints the table of docs/search.md.
//
// BM_Dawn/<solver>: one search on the Dawn face problem (examples/dawn), search alone;
//   BM_DawnProfiled: the same under devices/example.yaml (issue 21).
// BM_LibraryProfiled/<rules>/<solver>: the libraries below under a random device profile
//   (tests/support addRandomProfile), against the IP on the same priced instances.
// BM_Library/<rules>/<solver>: the seeded synthetic libraries of tests/support
//   (random_library.h), 10 seeds (1..10) per size, each solved once per iteration with a
//   per-search time limit. Counters: median and worst time (ms), the median time as a
//   ratio to the integer program's on the same instances in the same run (vs_ip),
//   median and largest expansion counts, the largest peak memory (KiB), and how many
//   seeds hit the limit. Every plan's cost is checked against the integer program's.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "pipeline/generate.h"
#include "random_library.h"
#include "search/search.h"

namespace {

using Clock = std::chrono::steady_clock;

struct Solver {
  const char* name;
  const char* engine;
  const char* heuristic;
  double limitSeconds;  // per search; the weak configurations stop early
};

const Solver kSolvers[] = {
    {"regression/lmcut", "regression", "lmcut", 120},  {"regression/landmarks", "regression", "landmarks", 2},
    {"regression/hmax", "regression", "hmax", 2},      {"regression/blind", "regression", "blind", 2},
    {"forward/lmcut", "forward", "lmcut", 2},          {"forward/hmax", "forward", "hmax", 2},
    {"forward/blind", "forward", "blind", 2},          {"ip", "ip", "lmcut", 300},
};
constexpr int kSeeds = 10;

struct Outcome {
  double ms = 0;
  bool limitHit = false;
  int64_t cost = -1, expanded = 0, peakBytes = 0;
};

Outcome solve(const sg::Problem& p, const Solver& s) {
  sg::SearchOptions o{s.engine, s.heuristic};
  o.limits.maxSeconds = s.limitSeconds;
  Outcome r;
  sg::SearchStats st;
  auto t0 = Clock::now();
  try {
    auto plan = sg::findPlan(p, o, &st);
    r.cost = plan ? plan->cost : -1;
  } catch (const sg::SearchLimitError&) {
    r.limitHit = true;
  }
  r.ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  r.expanded = st.expanded;
  r.peakBytes = st.peakBytes;
  return r;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  size_t n = v.size();
  return n % 2 ? v[n / 2] : (v[n / 2 - 1] + v[n / 2]) / 2;
}

// profiled: the same libraries under a random device profile (sgtest::addRandomProfile:
// inputs priced once per plan, so the items read join the regression state).
const std::vector<sg::Problem>& library(int rules, bool profiled = false) {
  static std::map<std::pair<int, bool>, std::vector<sg::Problem>> cache;
  auto& v = cache[{rules, profiled}];
  if (v.empty())
    for (int seed = 1; seed <= kSeeds; ++seed) {
      v.push_back(sgtest::randomLibrary(sgtest::LibraryShape{rules, static_cast<uint64_t>(seed)}));
      if (profiled) sgtest::addRandomProfile(v.back(), static_cast<uint64_t>(seed));
    }
  return v;
}

// The integer program's outcomes per size: the cost oracle and the time baseline.
const std::vector<Outcome>& oracle(int rules, bool profiled = false) {
  static std::map<std::pair<int, bool>, std::vector<Outcome>> cache;
  auto& v = cache[{rules, profiled}];
  if (v.empty())
    for (const auto& p : library(rules, profiled)) v.push_back(solve(p, kSolvers[7]));
  return v;
}

void BM_Library(benchmark::State& state, int rules, Solver solver, bool profiled) {
  const auto& problems = library(rules, profiled);
  const auto& ip = oracle(rules, profiled);
  std::vector<Outcome> out;
  for (auto _ : state) {
    out.clear();
    for (const auto& p : problems) out.push_back(solve(p, solver));
  }
  std::vector<double> ms, ipMs, expanded;
  double worst = 0, peak = 0, hits = 0;
  for (size_t i = 0; i < out.size(); ++i) {
    const Outcome& o = out[i];
    ipMs.push_back(ip[i].ms);
    ms.push_back(o.ms);
    worst = std::max(worst, o.ms);
    if (o.limitHit) {
      ++hits;
      continue;
    }
    if (o.cost != ip[i].cost) state.SkipWithError("a plan's cost differs from the integer program's optimum");
    expanded.push_back(static_cast<double>(o.expanded));
    peak = std::max(peak, static_cast<double>(o.peakBytes) / 1024);
  }
  state.counters["median_ms"] = median(ms);
  state.counters["worst_ms"] = worst;
  state.counters["vs_ip"] = median(ms) / std::max(1e-9, median(ipMs));
  state.counters["median_expanded"] = median(expanded);
  state.counters["max_expanded"] = expanded.empty() ? 0 : *std::max_element(expanded.begin(), expanded.end());
  state.counters["peak_KiB"] = peak;
  state.counters["limit_hits"] = hits;
  state.counters["limit_s"] = solver.limitSeconds;
}

// profiled: under devices/example.yaml (input locations dear, arithmetic nearly free).
void BM_Dawn(benchmark::State& state, Solver solver, bool profiled) {
  auto load = [](bool withProfile) {
    sg::GenerateOptions g;
    const std::string dir = std::string(SG_SOURCE_DIR) + "/examples/dawn/";
    g.rigPath = dir + "face.rig.yaml";
    g.fragmentPath = dir + "face.frag";
    g.rulesPaths = {dir + "rules.yaml"};
    if (withProfile) g.deviceProfilePath = std::string(SG_SOURCE_DIR) + "/devices/example.yaml";
    return sg::loadInputs(g);
  };
  static const sg::LoadedInputs plain = load(false), priced = load(true);
  const sg::LoadedInputs& in = profiled ? priced : plain;
  const int64_t optimum = solve(in.problem, kSolvers[7]).cost;
  Outcome o;
  for (auto _ : state) o = solve(in.problem, solver);
  if (o.cost != optimum) state.SkipWithError("plan cost differs from the integer program's optimum");
  state.counters["expanded"] = static_cast<double>(o.expanded);
  state.counters["peak_KiB"] = static_cast<double>(o.peakBytes) / 1024;
}

// Which solvers run at which size: the weak ones only where they can finish or show
// that they cannot (they stop at their limit).
bool runs(int rules, const std::string& name) {
  if (rules <= 100) return true;
  if (name == "regression/lmcut" || name == "regression/landmarks" || name == "ip") return true;
  if (rules <= 300) return name != "forward/hmax" && name != "forward/blind";
  if (rules <= 1000) return name == "regression/hmax" || name == "forward/lmcut";
  return false;
}

// --write-library DIR RULES SEED: the same library as files `shadergen generate` reads
// (lib.rules.yaml on top of the standard rules, lib.rig.yaml, lib.frag), for the whole
// generate wall time (bench/generate_wall.sh). Every semantic is a float; the rig's
// inputs are uniforms (a library has more of them than a vertex has attributes).
int writeLibrary(const std::string& dir, int rules, uint64_t seed) {
  sg::Problem p = sgtest::randomLibrary(sgtest::LibraryShape{rules, seed});
  auto sem = [&](int f) { return "lib." + p.facts[f].name; };
  std::ofstream r(dir + "/lib.rules.yaml"), g(dir + "/lib.rig.yaml"), fr(dir + "/lib.frag");
  r << "# Synthetic library: " << rules << " rules, seed " << seed << " (bench/bench_search.cpp)\nsemantics:\n";
  for (size_t f = 0; f < p.facts.size(); ++f) r << "  " << sem(static_cast<int>(f)) << ": float\n";
  r << "varyings:\n";
  for (size_t i = 0; i < p.goals.size(); ++i) r << "  G" << i << ": " << sem(p.goals[i]) << "\n";
  r << "rules:\n";
  for (const auto& a : p.actions) {
    r << "  - name: " << a.name << "\n    produces: " << sem(a.add) << "\n    needs: [";
    std::string expr;
    for (size_t i = 0; i < a.pre.size(); ++i) {
      r << (i ? ", " : "") << sem(a.pre[i]);
      expr += (i ? " + " : "") + std::string("${") + sem(a.pre[i]) + "}";
    }
    r << "]\n    cost: " << a.cost << "\n    glsl: |\n      ${out} = 0.5 * (" << expr << ");\n";
  }
  g << "rig: library\nattributes:\n  position: { format: float32x3, provides: vertex.position }\nuniforms:\n"
    << "  model: { type: mat4, semantic: model.matrix }\n  view_proj: { type: mat4, semantic: camera.view_projection }\n";
  for (int f : p.init) g << "  " << p.facts[f].name << ": { type: float, semantic: " << sem(f) << " }\n";
  fr << "#version 450\n";
  for (size_t i = 0; i < p.goals.size(); ++i) fr << "layout(location = " << i << ") in float G" << i << ";\n";
  fr << "layout(location = 0) out vec4 color;\nvoid main() {\n  color = vec4(0.0";
  for (size_t i = 0; i < p.goals.size(); ++i) fr << " + G" << i;
  fr << ");\n}\n";
  return r && g && fr ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 5 && std::string(argv[1]) == "--write-library")
    return writeLibrary(argv[2], std::atoi(argv[3]), std::strtoull(argv[4], nullptr, 10));
  for (bool profiled : {false, true})
    for (const Solver& s : kSolvers)
      benchmark::RegisterBenchmark((std::string(profiled ? "BM_DawnProfiled/" : "BM_Dawn/") + s.name).c_str(), BM_Dawn,
                                   s, profiled)
          ->Unit(benchmark::kMicrosecond)
          ->UseRealTime();
  for (int rules : {100, 300, 1000, 3000})
    for (const Solver& s : kSolvers)
      if (runs(rules, s.name))
        benchmark::RegisterBenchmark((std::string("BM_Library/") + std::to_string(rules) + "/" + s.name).c_str(),
                                     BM_Library, rules, s, false)
            ->Iterations(1)
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
  // Under a random device profile: the exact engines only (forward hands priced problems to the IP).
  for (int rules : {100, 300, 1000, 3000})
    for (const Solver& s : kSolvers)
      if (std::string(s.name) == "regression/lmcut" || std::string(s.name) == "ip")
        benchmark::RegisterBenchmark(
            (std::string("BM_LibraryProfiled/") + std::to_string(rules) + "/" + s.name).c_str(), BM_Library, rules, s,
            true)
            ->Iterations(1)
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

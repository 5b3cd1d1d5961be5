// Benchmarks of the occlusion baker (docs/bake.md; run bench/bake.sh).
//
// BM_Rays/<triangles>: one thread casting the same occlusion rays (16 points × 64 rays on a
//   plane under a UV sphere of about that many triangles) through Embree and through the
//   plain loop over every triangle (Möller–Trumbore), both measured in every iteration.
//   Iteration time is Embree's; counters: Mrays/s of each and the speed-up (brute / Embree).
//   The two must agree on every ray's verdict up to grazing hits (checked, not timed).
// BM_BakeModel/<model>: `shadergen bake occlusion` on a shared model with the defaults (256
//   uniform rays per vertex, all threads), in memory: decode, pose, every pass, serialise.
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>

#include "bake/gltf_bake.h"
#include "bake/occlusion.h"

namespace {

using Clock = std::chrono::steady_clock;
using namespace sg::bake;

TriangleSoup sphereOverPlane(int targetTriangles) {
  TriangleSoup s;
  s.positions = {{-10, -10, 0}, {10, -10, 0}, {10, 10, 0}, {-10, 10, 0}};
  s.triangles = {{0, 1, 2}, {0, 2, 3}};
  int rings = std::max(2, static_cast<int>(std::sqrt(targetTriangles / 4.0)));
  int segments = 2 * rings;
  uint32_t base = static_cast<uint32_t>(s.positions.size());
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j <= segments; ++j) {
      double th = M_PI * i / rings, ph = 2 * M_PI * j / segments;
      s.positions.push_back({float(std::sin(th) * std::cos(ph)), float(std::sin(th) * std::sin(ph)),
                             float(2 + std::cos(th))});
    }
  auto at = [&](int i, int j) { return base + static_cast<uint32_t>(i * (segments + 1) + j); };
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      s.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      s.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  return s;
}

void BM_Rays(benchmark::State& state) {
  TriangleSoup scene = sphereOverPlane(static_cast<int>(state.range(0)));
  auto embree = makeEmbreeCaster(scene);
  auto brute = makeBruteForceCaster(scene);
  std::vector<BakePoint> points;
  for (int i = 0; i < 16; ++i) points.push_back({{0.1f * float(i % 4) - 0.15f, 0.1f * float(i / 4) - 0.15f, 0}, {0, 0, 1}, uint64_t(i)});
  OcclusionOptions o;
  o.rays = 64;
  o.threads = 1;
  double embreeS = 0, bruteS = 0;
  double mismatch = 0;
  for (auto _ : state) {
    auto t0 = Clock::now();
    auto a = bakeOcclusion(*embree, points, o, 1e-5);
    auto t1 = Clock::now();
    auto b = bakeOcclusion(*brute, points, o, 1e-5);
    auto t2 = Clock::now();
    double e = std::chrono::duration<double>(t1 - t0).count(), f = std::chrono::duration<double>(t2 - t1).count();
    embreeS += e;
    bruteS += f;
    state.SetIterationTime(e);
    for (size_t i = 0; i < a.size(); ++i) mismatch += std::fabs(a[i] - b[i]) * o.rays;
  }
  double rays = static_cast<double>(state.iterations()) * static_cast<double>(points.size()) * o.rays;
  state.counters["triangles"] = static_cast<double>(scene.triangles.size());
  state.counters["embree_Mrays_s"] = rays / embreeS * 1e-6;
  state.counters["brute_Mrays_s"] = rays / bruteS * 1e-6;
  state.counters["speedup"] = bruteS / embreeS;
  state.counters["rays_disagreeing"] = mismatch;
}
BENCHMARK(BM_Rays)->Arg(1000)->Arg(10000)->Arg(100000)->UseManualTime()->Iterations(5)->Unit(benchmark::kMillisecond);

std::string shared(const std::string& rel) {
  const char* env = std::getenv("SHADERGEN_SHARED_DIR");
  return std::string(env && *env ? env : SG_SHARED_DIR) + "/models/" + rel;
}

void BM_BakeModel(benchmark::State& state, const std::string& model) {
  std::string file = shared(model);
  if (!std::filesystem::exists(file)) {
    state.SkipWithError(("no shared model " + file).c_str());
    return;
  }
  GltfBakeOptions o;
  GltfBakeResult r;
  double seconds = 0;
  for (auto _ : state) {
    auto t0 = Clock::now();
    r = bakeGltfOcclusion(file, o);
    seconds += std::chrono::duration<double>(Clock::now() - t0).count();
  }
  size_t vertices = 0;
  for (const auto& p : r.primitives) vertices += p.vertices;
  state.counters["vertices"] = static_cast<double>(vertices);
  state.counters["triangles"] = static_cast<double>(r.triangles);
  state.counters["passes"] = r.passes;
  state.counters["rays"] = static_cast<double>(r.rays);
  state.counters["Mrays_s"] = static_cast<double>(r.rays) * static_cast<double>(state.iterations()) / seconds * 1e-6;
  state.counters["threads"] = std::thread::hardware_concurrency();
}
BENCHMARK_CAPTURE(BM_BakeModel, Fox, std::string("Fox/Fox.glb"))->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();
BENCHMARK_CAPTURE(BM_BakeModel, AnimatedMorphSphere, std::string("AnimatedMorphSphere/AnimatedMorphSphere.gltf"))
    ->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();
BENCHMARK_CAPTURE(BM_BakeModel, MorphStressTest, std::string("MorphStressTest/MorphStressTest.gltf"))
    ->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();
BENCHMARK_CAPTURE(BM_BakeModel, MorphPrimitivesTest, std::string("MorphPrimitivesTest/MorphPrimitivesTest.gltf"))
    ->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();
BENCHMARK_CAPTURE(BM_BakeModel, SimpleMorph, std::string("SimpleMorph/SimpleMorph.gltf"))->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();
BENCHMARK_CAPTURE(BM_BakeModel, SimpleSkin, std::string("SimpleSkin/SimpleSkin.gltf"))->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();

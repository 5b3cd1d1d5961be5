#include "bake/occlusion.h"

#include <embree3/rtcore.h>
#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <thread>

namespace sg::bake {
namespace {

constexpr double kTwoPi = 6.283185307179586476925286766559;

uint64_t splitmix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}
// Uniform in [0, 1) from the top 53 bits.
double unit(uint64_t h) { return static_cast<double>(h >> 11) * 0x1.0p-53; }

Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
float dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// --- Embree ---------------------------------------------------------------------------
class EmbreeCaster final : public RayCaster {
 public:
  explicit EmbreeCaster(const TriangleSoup& s) {
    device_ = rtcNewDevice(nullptr);
    if (!device_) throw std::runtime_error(fmt::format("cannot create an Embree device (error {})",
                                                       static_cast<int>(rtcGetDeviceError(nullptr))));
    scene_ = rtcNewScene(device_);
    rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST);  // no cracks between neighbouring triangles
    rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);
    if (!s.triangles.empty()) {
      RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
      auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                            3 * sizeof(float), s.positions.size()));
      auto* ix = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                3 * sizeof(uint32_t), s.triangles.size()));
      if (!v || !ix) throw std::runtime_error("Embree could not allocate the geometry buffers");
      for (size_t i = 0; i < s.positions.size(); ++i)
        for (int c = 0; c < 3; ++c) v[3 * i + static_cast<size_t>(c)] = s.positions[i][static_cast<size_t>(c)];
      for (size_t i = 0; i < s.triangles.size(); ++i)
        for (int c = 0; c < 3; ++c) ix[3 * i + static_cast<size_t>(c)] = s.triangles[i][static_cast<size_t>(c)];
      rtcCommitGeometry(g);
      rtcAttachGeometry(scene_, g);
      rtcReleaseGeometry(g);
    }
    rtcCommitScene(scene_);
    if (RTCError e = rtcGetDeviceError(device_); e != RTC_ERROR_NONE) {
      release();
      throw std::runtime_error(fmt::format("Embree failed to build the scene (error {})", static_cast<int>(e)));
    }
  }
  ~EmbreeCaster() override { release(); }
  EmbreeCaster(const EmbreeCaster&) = delete;
  EmbreeCaster& operator=(const EmbreeCaster&) = delete;

  bool occluded(const Vec3& o, const Vec3& d, float tnear, float tfar) const override {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay r{};
    r.org_x = o[0], r.org_y = o[1], r.org_z = o[2];
    r.dir_x = d[0], r.dir_y = d[1], r.dir_z = d[2];
    r.tnear = tnear;
    r.tfar = tfar;
    r.mask = 0xFFFFFFFFu;
    rtcOccluded1(scene_, &ctx, &r);
    return r.tfar < 0;  // Embree sets tfar to -inf on a hit
  }
  int countOccluded(const Vec3& o, const std::vector<Vec3>& dirs, float tnear, float tfar) const override {
    thread_local std::vector<RTCRay> rays;
    rays.resize(dirs.size());
    for (size_t i = 0; i < dirs.size(); ++i) {
      RTCRay& r = rays[i];
      r = RTCRay{};
      r.org_x = o[0], r.org_y = o[1], r.org_z = o[2];
      r.dir_x = dirs[i][0], r.dir_y = dirs[i][1], r.dir_z = dirs[i][2];
      r.tnear = tnear;
      r.tfar = tfar;
      r.mask = 0xFFFFFFFFu;
    }
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;  // one origin: Embree packs the stream into packets
    rtcOccluded1M(scene_, &ctx, rays.data(), static_cast<unsigned>(rays.size()), sizeof(RTCRay));
    int hits = 0;
    for (const RTCRay& r : rays) hits += r.tfar < 0;
    return hits;
  }
  const char* name() const override { return "embree"; }

 private:
  void release() {
    if (scene_) rtcReleaseScene(scene_);
    if (device_) rtcReleaseDevice(device_);
    scene_ = nullptr;
    device_ = nullptr;
  }
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
};

// --- brute force: Möller–Trumbore against every triangle, both sides ---------------------
class BruteForceCaster final : public RayCaster {
 public:
  explicit BruteForceCaster(const TriangleSoup& s) {
    tris_.reserve(s.triangles.size());
    for (const auto& t : s.triangles) {
      const Vec3& a = s.positions[t[0]];
      tris_.push_back({a, sub(s.positions[t[1]], a), sub(s.positions[t[2]], a)});
    }
  }
  bool occluded(const Vec3& o, const Vec3& d, float tnear, float tfar) const override {
    for (const Tri& t : tris_) {
      Vec3 p = cross(d, t.e2);
      float det = dot(t.e1, p);
      if (std::fabs(det) < 1e-20f) continue;  // parallel (or degenerate)
      float inv = 1.0f / det;
      Vec3 s = sub(o, t.a);
      float u = dot(s, p) * inv;
      if (u < 0.0f || u > 1.0f) continue;
      Vec3 q = cross(s, t.e1);
      float v = dot(d, q) * inv;
      if (v < 0.0f || u + v > 1.0f) continue;
      float dist = dot(t.e2, q) * inv;
      if (dist > tnear && dist < tfar) return true;
    }
    return false;
  }
  const char* name() const override { return "brute force"; }

 private:
  struct Tri {
    Vec3 a, e1, e2;
  };
  std::vector<Tri> tris_;
};

}  // namespace

// Orthonormal basis around a unit normal (Duff et al. 2017, "Building an orthonormal basis,
// revisited"): continuous everywhere but the sign flip at z = 0, no normalisation needed.
void orthonormalBasis(const Vec3& n, Vec3& t, Vec3& b) {
  float sign = std::copysign(1.0f, n[2]);
  float a = -1.0f / (sign + n[2]);
  float c = n[0] * n[1] * a;
  t = {1.0f + sign * n[0] * n[0] * a, sign * c, -sign * n[0]};
  b = {c, sign + n[1] * n[1] * a, -n[1]};
}


int RayCaster::countOccluded(const Vec3& origin, const std::vector<Vec3>& dirs, float tnear, float tfar) const {
  int hits = 0;
  for (const Vec3& d : dirs) hits += occluded(origin, d, tnear, tfar);
  return hits;
}

void TriangleSoup::append(const TriangleSoup& o) {
  uint32_t base = static_cast<uint32_t>(positions.size());
  positions.insert(positions.end(), o.positions.begin(), o.positions.end());
  for (const auto& t : o.triangles) triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
}

std::unique_ptr<RayCaster> makeEmbreeCaster(const TriangleSoup& scene) { return std::make_unique<EmbreeCaster>(scene); }
std::unique_ptr<RayCaster> makeBruteForceCaster(const TriangleSoup& scene) {
  return std::make_unique<BruteForceCaster>(scene);
}

double defaultOffset(const TriangleSoup& scene) {
  if (scene.positions.empty()) return 1e-6;
  Vec3 lo = scene.positions[0], hi = lo;
  for (const auto& p : scene.positions)
    for (size_t c = 0; c < 3; ++c) lo[c] = std::min(lo[c], p[c]), hi[c] = std::max(hi[c], p[c]);
  double sq = 0;  // in double: float coordinates near 1e20 would overflow the square
  for (size_t c = 0; c < 3; ++c) sq += (double(hi[c]) - lo[c]) * (double(hi[c]) - lo[c]);
  double diag = std::sqrt(sq);
  return diag > 0 && std::isfinite(diag) ? 1e-5 * diag : 1e-6;
}

Vec3 hemisphereDirection(const Vec3& n, Distribution dist, uint64_t seed, uint64_t stream, int i) {
  // Counter-based: direction i of a stream is a hash of (seed, stream, i), so any subset of
  // points or rays can be computed in any order, on any thread, with the same result.
  uint64_t h = splitmix64(splitmix64(seed ^ 0x6f63636c7573696full) ^ stream);
  uint64_t h1 = splitmix64(h ^ (2 * static_cast<uint64_t>(i)));
  uint64_t h2 = splitmix64(h ^ (2 * static_cast<uint64_t>(i) + 1));
  double u1 = unit(h1), u2 = unit(h2);
  // Uniform: cos θ uniform in [0, 1] (Archimedes). Cosine: sin²θ uniform (Malley's method).
  double cosT = dist == Distribution::Uniform ? 1.0 - u1 : std::sqrt(1.0 - u1);
  double sinT = std::sqrt(std::max(0.0, 1.0 - cosT * cosT));
  double phi = kTwoPi * u2;
  double x = sinT * std::cos(phi), y = sinT * std::sin(phi);
  Vec3 t, b;
  orthonormalBasis(n, t, b);
  Vec3 d;
  for (size_t c = 0; c < 3; ++c) d[c] = static_cast<float>(x * t[c] + y * b[c] + cosT * n[c]);
  return d;
}

std::vector<float> bakeOcclusion(const RayCaster& caster, const std::vector<BakePoint>& points,
                                 const OcclusionOptions& opts, double offset) {
  if (opts.rays < 1) throw std::invalid_argument("the ray count must be at least 1");
  std::vector<float> out(points.size(), 0.0f);
  const float tfar = std::isfinite(opts.maxDistance) ? static_cast<float>(opts.maxDistance)
                                                     : std::numeric_limits<float>::infinity();
  auto bakeOne = [&](size_t k) {
    const BakePoint& p = points[k];
    Vec3 n = p.normal;
    float len = std::sqrt(dot(n, n));
    if (!(len > 0) || !std::isfinite(len)) return;  // no hemisphere: reported by the caller
    for (auto& c : n) c /= len;
    Vec3 o;
    for (size_t c = 0; c < 3; ++c) o[c] = p.position[c] + static_cast<float>(offset) * n[c];
    thread_local std::vector<Vec3> dirs;
    dirs.resize(static_cast<size_t>(opts.rays));
    for (int i = 0; i < opts.rays; ++i)
      dirs[static_cast<size_t>(i)] = hemisphereDirection(n, opts.distribution, opts.seed, p.stream, i);
    int blocked = caster.countOccluded(o, dirs, 0.0f, tfar);
    out[k] = static_cast<float>(blocked) / static_cast<float>(opts.rays);
  };

  unsigned hw = std::max(1u, std::thread::hardware_concurrency());
  unsigned threads = opts.threads > 0 ? static_cast<unsigned>(opts.threads) : hw;
  constexpr size_t kChunk = 16;  // points per work item: small enough to balance, large enough to not contend
  threads = static_cast<unsigned>(std::min<size_t>(threads, (points.size() + kChunk - 1) / kChunk));
  std::atomic<size_t> next{0}, done{0};
  auto work = [&] {
    for (size_t begin; (begin = next.fetch_add(kChunk)) < points.size();) {
      size_t end = std::min(points.size(), begin + kChunk);
      for (size_t k = begin; k < end; ++k) bakeOne(k);
      done.fetch_add(end - begin);
    }
  };
  if (threads <= 1) {
    work();
  } else {
    std::vector<std::thread> pool;
    for (unsigned t = 0; t < threads; ++t) pool.emplace_back(work);
    if (opts.progress)
      while (done.load() < points.size()) {
        opts.progress(done.load(), points.size());
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
      }
    for (auto& t : pool) t.join();
  }
  if (opts.progress) opts.progress(points.size(), points.size());
  return out;
}

std::vector<float> bakeOcclusion(const TriangleSoup& scene, const std::vector<BakePoint>& points,
                                 const OcclusionOptions& opts) {
  double offset = opts.offset >= 0 ? opts.offset : defaultOffset(scene);
  return bakeOcclusion(*makeEmbreeCaster(scene), points, opts, offset);
}

}  // namespace sg::bake

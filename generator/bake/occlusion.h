// Occlusion baking (docs/bake.md): the fraction of the hemisphere above a point that scene
// geometry blocks, estimated by casting rays stochastically over the hemisphere around the
// point's normal (GPU Gems 3, ch. 3, section 3.3.2). Plain data in, plain data out: the glTF
// side lives in gltf_bake.h.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace sg::bake {

using Vec3 = std::array<float, 3>;

// World-space triangles, the occluders. Orientation does not matter: back faces block too.
struct TriangleSoup {
  std::vector<Vec3> positions;
  std::vector<std::array<uint32_t, 3>> triangles;
  void append(const TriangleSoup& other);
};

// Directions are drawn over the hemisphere around the normal either uniformly in solid
// angle (the estimate is the blocked fraction of the hemisphere, Dawn's "fraction of the
// visible hemisphere") or with density cos(θ)/π (the estimate is the blocked fraction of
// the irradiance from a uniform sky: classic ambient occlusion).
enum class Distribution { Uniform, Cosine };

struct OcclusionOptions {
  int rays = 256;
  Distribution distribution = Distribution::Uniform;
  // Ray origins are moved this far along the normal (scene units) so the surface the point
  // lies on does not hit itself. <0: 1e-5 × the scene's bounding-box diagonal.
  double offset = -1;
  double maxDistance = std::numeric_limits<double>::infinity();  // hits further away do not block
  uint64_t seed = 1;
  int threads = 0;  // 0: all hardware threads
  // Called from the calling thread about 10 times a second and once at the end.
  std::function<void(size_t done, size_t total)> progress;
};

// One point to bake. `stream` picks its random sequence: the estimate depends only on
// (seed, stream, geometry), never on the thread that computes it or on the other points.
struct BakePoint {
  Vec3 position{};
  Vec3 normal{};  // need not be unit length; a zero normal gives occlusion 0
  uint64_t stream = 0;
};

// Answers "does a segment hit any triangle?". Two implementations: Embree (the baker) and a
// plain loop over every triangle (the benchmark's baseline and the tests' cross-check).
class RayCaster {
 public:
  virtual ~RayCaster() = default;
  // True if the ray origin + t·dir, t in (tnear, tfar), hits a triangle.
  virtual bool occluded(const Vec3& origin, const Vec3& dir, float tnear, float tfar) const = 0;
  // How many of the rays from one origin are occluded (Embree casts them as one stream).
  virtual int countOccluded(const Vec3& origin, const std::vector<Vec3>& dirs, float tnear, float tfar) const;
  virtual const char* name() const = 0;
};
std::unique_ptr<RayCaster> makeEmbreeCaster(const TriangleSoup& scene);  // throws std::runtime_error
std::unique_ptr<RayCaster> makeBruteForceCaster(const TriangleSoup& scene);

// The default offset for a scene (1e-5 × its bounding-box diagonal; 1e-6 for an empty one).
double defaultOffset(const TriangleSoup& scene);

// Occlusion in [0, 1] per point (k blocked rays out of n: k/n).
std::vector<float> bakeOcclusion(const RayCaster& caster, const std::vector<BakePoint>& points,
                                 const OcclusionOptions& opts, double offset);
// Builds the Embree scene and bakes.
std::vector<float> bakeOcclusion(const TriangleSoup& scene, const std::vector<BakePoint>& points,
                                 const OcclusionOptions& opts);

// Orthonormal basis (t, b) around a unit normal (Duff et al. 2017, "Building an orthonormal
// basis, revisited"): continuous everywhere but the sign flip at z = 0.
void orthonormalBasis(const Vec3& unitNormal, Vec3& t, Vec3& b);

// The i-th direction of a point's hemisphere (exposed for tests): unit length, dot(d, n) >= 0.
Vec3 hemisphereDirection(const Vec3& unitNormal, Distribution d, uint64_t seed, uint64_t stream, int i);

}  // namespace sg::bake

// Headless drawing on the harness's device: a vertex + fragment pipeline into a colour and
// a depth image read back to the host (shadergen render), and GPU timing of vertex
// programs with timestamp queries (shadergen bench). Like the harness it knows bytes,
// formats and bindings, never semantics.
#pragma once
#include <vulkan/vulkan.h>

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "runtime/vk_harness.h"

namespace sg::rt {

// A program's inputs (vk_program.h: streams, uniform block, storage buffers, textures,
// declared descriptors) and the shaders and triangles that draw them.
struct DrawRequest : ProgramInputs {
  std::vector<uint32_t> vertexSpirv;
  std::vector<uint32_t> fragmentSpirv;  // writes location 0 (vec4)
  std::vector<uint32_t> indices;        // triangle list
  uint32_t width = 256, height = 256;
  std::array<float, 4> clearColor{0, 0, 0, 1};
};

// The colour attachment (RGBA8 UNORM, row 0 at the top) and the depth (1 = nothing drawn).
struct Image {
  uint32_t width = 0, height = 0;
  std::vector<uint8_t> rgba;
  std::vector<float> depth;
};

struct TimingRequest {
  uint32_t drawsPerFrame = 16;  // the mesh drawn this many times between two timestamps
  uint32_t frames = 5;
  // true: indexed triangles into the colour/depth targets (depth test LESS, so repeated draws
  // are rejected early and the vertex stage dominates). false: rasterizer discard, every
  // vertex once with its outputs captured by transform feedback (the vertex shader must be a
  // capture build with this xfb stride), so no output can be optimised away.
  bool rasterize = true;
  uint32_t captureStride = 0;
};

struct Timing {
  std::vector<double> frameNs;  // GPU time of each frame's draws (timestamps)
  // Host time of each frame's submit + wait: on a CPU device (lavapipe) work may run outside
  // the timestamps' reach (deferred binning, rasterizer threads), so this is the honest one there.
  std::vector<double> wallNs;
  // This process's CPU time over the same span, every thread's: a CPU device's threads do
  // the work here, so this counts the work itself, not what other processes took meanwhile.
  std::vector<double> cpuNs;
  uint32_t verticesPerDraw = 0;  // vertex shader invocations asked for per draw (unique vertices)
  std::string inputMemory;       // the memory types the inputs were in ("type 1 (device-local) of heap 0 (...)")
  // What the driver says it compiled the vertex stage into (registers, instructions, ...),
  // where it offers VK_KHR_pipeline_executable_properties; empty elsewhere (lavapipe 22.3).
  std::vector<ShaderStatistic> vertexStatistics;
};

// What one draw of a request made the device do (a pipeline statistics query): vertex shader
// invocations (each vertex the post-transform cache did not hold shaded again) and fragment
// shader invocations (the pixels its triangles cover that pass the depth test LESS in a
// cleared target: the fragment work a frame's first draw does).
struct DrawStatistics {
  uint64_t vertexInvocations = 0, fragmentInvocations = 0;
};

class Renderer {
 public:
  // Draws with the harness's device and queue; the harness must outlive the renderer.
  explicit Renderer(const Harness& harness);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Throws std::runtime_error on a bad request or a Vulkan error.
  Image draw(const DrawRequest& request);
  Timing time(const DrawRequest& request, const TimingRequest& timing);
  // One draw, rasterized, counted; std::nullopt where the device has no pipelineStatisticsQuery.
  std::optional<DrawStatistics> statistics(const DrawRequest& request);
  // "<driver name> <driver info>" (VkPhysicalDeviceDriverProperties), or the driver version number.
  std::string driver() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sg::rt

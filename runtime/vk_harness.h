// Headless Vulkan harness: runs a vertex shader over N vertices and captures its
// outputs with VK_EXT_transform_feedback. Generic on purpose: it knows bytes, formats
// and strides, never semantics, so the validator and applications share it.
#pragma once
#include <vulkan/vulkan.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace sg::rt {

// One vertex buffer binding per stream, per-vertex rate, attribute at offset 0.
struct VertexStream {
  uint32_t location = 0;
  VkFormat format = VK_FORMAT_UNDEFINED;
  uint32_t stride = 0;
  std::vector<uint8_t> data;  // at least vertexCount * stride bytes
};

// A read-only storage buffer at set 0, `binding` (std430 data as the shader declares it).
// Per-vertex buffers must cover the drawn vertices: vertexCount rounded up to even.
struct StorageBufferData {
  uint32_t binding = 1;
  std::vector<uint8_t> data;  // non-empty
};

// The shader's xfb_stride (a single capture buffer, xfb_buffer 0).
struct CaptureLayout {
  uint32_t strideBytes = 0;
};

struct RunRequest {
  // Vertex shader with xfb_buffer/xfb_offset/xfb_stride on every captured output
  // (gl_Position through a redeclared gl_PerVertex).
  std::vector<uint32_t> spirv;
  std::vector<VertexStream> streams;
  // Contents of the uniform block at set 0, binding 0; empty = no descriptor set.
  std::vector<uint8_t> uniformData;
  // Storage buffers at set 0 (bindings distinct from 0, the uniform block's).
  std::vector<StorageBufferData> storageBuffers;
  uint32_t vertexCount = 0;
  CaptureLayout capture;
};

struct RunTimings {
  double setupMs = 0, uploadMs = 0, runMs = 0, readbackMs = 0;
};

struct RunResult {
  std::vector<uint8_t> captured;  // vertexCount * capture.strideBytes; bytes no output wrote are 0
  RunTimings timings;
};

struct HarnessOptions {
  std::string deviceName;   // substring of the device name; empty = lavapipe (VK_DRIVER_ID_MESA_LLVMPIPE)
  bool validation = true;   // enable VK_LAYER_KHRONOS_validation if it is installed
};

class Harness {
 public:
  // Throws std::runtime_error if there is no Vulkan, no matching device, or no transform feedback.
  explicit Harness(const HarnessOptions& options = {});
  ~Harness();
  Harness(const Harness&) = delete;
  Harness& operator=(const Harness&) = delete;

  // Throws std::runtime_error on failure (bad request or Vulkan error).
  RunResult run(const RunRequest& request);

  // Every debug-utils message (warning and error severities, all types) since construction.
  const std::vector<std::string>& validationMessages() const;
  std::string deviceName() const;
  bool validationEnabled() const;  // whether the layer was found and enabled

  // The device the harness set up, for code that draws with it (runtime/vk_render.h).
  struct Handles {
    VkPhysicalDevice physicalDevice;
    VkDevice device;
    uint32_t queueFamily;
    VkQueue queue;
  };
  Handles handles() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sg::rt

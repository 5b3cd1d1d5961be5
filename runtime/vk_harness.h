// Headless Vulkan harness: runs a vertex shader over N vertices and captures its
// outputs with VK_EXT_transform_feedback. Generic on purpose: it knows bytes, formats
// and strides, never semantics, so the validator and applications share it.
#pragma once
#include <vulkan/vulkan.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "runtime/vk_program.h"

namespace sg::rt {

// The shader's xfb_stride (a single capture buffer, xfb_buffer 0).
struct CaptureLayout {
  uint32_t strideBytes = 0;
};

// The program's inputs (vk_program.h; textures are ignored: nothing is rasterized) and
// the shader that reads them.
struct RunRequest : ProgramInputs {
  // Vertex shader with xfb_buffer/xfb_offset/xfb_stride on every captured output
  // (gl_Position through a redeclared gl_PerVertex).
  std::vector<uint32_t> spirv;
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
  std::string deviceName;   // substring of the device name; empty or "lavapipe" = VK_DRIVER_ID_MESA_LLVMPIPE
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
  // "<driver name> <driver info>" (VkPhysicalDeviceDriverProperties), or the driver version number.
  std::string driver() const;
  bool validationEnabled() const;  // whether the layer was found and enabled
  // The physical device's limits (maxVertexInputAttributes, maxUniformBufferRange, ...).
  const VkPhysicalDeviceLimits& limits() const;
  // The bytes a vertex's capture record may take in the one transform-feedback buffer run()
  // binds: the least of maxTransformFeedbackBufferDataStride, maxTransformFeedbackBufferDataSize
  // and maxTransformFeedbackStreamDataSize (VK_EXT_transform_feedback).
  uint32_t maxCaptureBytes() const;

  // The device the harness set up, for code that draws with it (runtime/vk_render.h).
  struct Handles {
    VkPhysicalDevice physicalDevice;
    VkDevice device;
    uint32_t queueFamily;
    VkQueue queue;
    bool memoryBudget;  // VK_EXT_memory_budget enabled: heaps' usage and budget can be asked
    // VK_KHR_pipeline_executable_properties enabled: the driver's statistics of a compiled
    // pipeline (registers, instructions, ...) can be asked (ProgramObjects::vertexStatistics)
    bool executableStatistics = false;
  };
  Handles handles() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sg::rt

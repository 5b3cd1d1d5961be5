// What a program reads on a device, as plain data: vertex streams, the uniform block,
// storage buffers and textures by binding, and the descriptors its shaders declare. The
// capture harness (vk_harness.h) and the renderer (vk_render.h) bind it the one same way
// (vk_setup.h); a declared descriptor that nothing feeds is an error naming it, never an
// unbound read. Like the harness it knows bytes, formats and bindings, never semantics.
#pragma once
#include <vulkan/vulkan.h>

#include <cstdint>
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

// A sampled texture at set 1, `binding` (combined image sampler, trilinear filtering: the
// runtime makes the full mip chain from `data`, each level a linear blit of the one above).
struct Texture {
  uint32_t binding = 0;
  bool cube = false;  // 6 faces in Vulkan order +X, -X, +Y, -Y, +Z, -Z
  uint32_t size = 0;  // width = height
  VkFormat format = VK_FORMAT_R8G8B8A8_UNORM;  // or VK_FORMAT_R16G16B16A16_SFLOAT (HDR)
  std::vector<uint8_t> data;  // faces x size x size texels, rows top to bottom
};

enum class DescriptorKind { UniformBuffer, StorageBuffer, CombinedImageSampler };

// A descriptor a shader uses, as its reflection names it.
struct DescriptorBinding {
  uint32_t set = 0;
  uint32_t binding = 0;
  DescriptorKind kind = DescriptorKind::UniformBuffer;
  std::string name;  // for messages
};

// Where a program's inputs (streams, uniform block, storage buffers, indices) live.
// DeviceLocal: memory only the device reads, filled by a staging copy, as an engine keeps a
// static mesh. Mapped: host-visible coherent memory the host writes in place (device-local
// where the device has such a type: on a discrete GPU without resizable BAR a window of a
// few hundred MiB, shared by every allocation of that type).
enum class InputMemory { DeviceLocal, Mapped };

struct ProgramInputs {
  uint32_t vertexCount = 0;
  std::vector<VertexStream> streams;
  std::vector<uint8_t> uniformData;               // set 0, binding 0 (vertex stage); empty = none
  std::vector<StorageBufferData> storageBuffers;  // set 0 (vertex stage), bindings other than 0
  std::vector<Texture> textures;                  // set 1 (fragment stage), bound when a fragment shader runs
  // The descriptors the program's shaders use (set 0: vertex stage, set 1: fragment stage).
  // A run refuses one that the fields above do not feed, naming it.
  std::vector<DescriptorBinding> declared;
  InputMemory memory = InputMemory::DeviceLocal;  // where the buffers above live on the device
};

// One statistic a driver reports of the vertex stage it compiled a program into
// (VK_KHR_pipeline_executable_properties): "Register Count" = 32. Each driver names its own;
// `executable` is the driver's name of the compiled stage where it has several for one.
struct ShaderStatistic {
  std::string executable, name;
  double value = 0;
};

}  // namespace sg::rt

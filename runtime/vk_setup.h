// The one way a program is set up on the harness's device, shared by the capture harness
// (Harness::run) and the renderer (Renderer::draw/time): inputs checked against the device
// and against the descriptors the shaders declare, buffers and textures uploaded,
// descriptor sets, vertex input state, render pass and pipeline. Internal to runtime/.
#pragma once
#include <vulkan/vulkan.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "runtime/vk_harness.h"
#include "runtime/vk_program.h"

namespace sg::rt::setup {

// Throws std::runtime_error "vulkan: <what> failed: <VkResult name>".
void check(VkResult r, const char* what);

// What set-up needs to know about the harness's device.
struct Device {
  Harness::Handles h{};
  VkPhysicalDeviceProperties props{};
  VkPhysicalDeviceMemoryProperties memProps{};
  VkPhysicalDeviceTransformFeedbackPropertiesEXT xfbProps{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_TRANSFORM_FEEDBACK_PROPERTIES_EXT};
  uint32_t timestampBits = 0;
  bool pipelineStatistics = false;  // the harness enables pipelineStatisticsQuery wherever the device has it
  PFN_vkCmdBindTransformFeedbackBuffersEXT bindXfb = nullptr;
  PFN_vkCmdBeginTransformFeedbackEXT beginXfb = nullptr;
  PFN_vkCmdEndTransformFeedbackEXT endXfb = nullptr;
  // Set where the harness enabled VK_KHR_pipeline_executable_properties (Handles::executableStatistics).
  PFN_vkGetPipelineExecutablePropertiesKHR executableProperties = nullptr;
  PFN_vkGetPipelineExecutableStatisticsKHR executableStatistics = nullptr;

  explicit Device(const Harness::Handles& handles);
  // Memory of the type chooseMemoryType picks; `type` (optional) receives its index.
  VkDeviceMemory allocate(const VkMemoryRequirements& requirements, VkMemoryPropertyFlags required,
                          VkMemoryPropertyFlags preferred, uint32_t* type = nullptr) const;
};

// The first memory type of `allowed` (a VkMemoryRequirements::memoryTypeBits) with the
// `required` and `preferred` flags, else the first with the `required` ones; UINT32_MAX if none.
// The Vulkan spec orders types so that, of two with the flags asked for, the one with fewer
// extra flags comes first: asking for device-local alone never lands in a host-visible window.
uint32_t chooseMemoryType(const VkPhysicalDeviceMemoryProperties& memory, uint32_t allowed, VkMemoryPropertyFlags required,
                          VkMemoryPropertyFlags preferred);
// "type 1 (device-local) of heap 0 (80 GiB, device-local)": where an allocation lives.
std::string describeMemoryType(const VkPhysicalDeviceMemoryProperties& memory, uint32_t type);

struct Buffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  void* mapped = nullptr;  // host-visible buffers only
  uint32_t memoryType = UINT32_MAX;
};
struct ImageObj {
  VkImage image = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;
};

// How a program is drawn. With a fragment shader: indexed triangles into an RGBA8 colour and
// a D32 depth target (depth test LESS, no culling). Without: a capture pass, every vertex
// once as a line list (points would need gl_PointSize) with the rasterizer discarded and
// the outputs going to transform feedback; an odd count gets one zeroed padding vertex.
struct PassDesc {
  const std::vector<uint32_t>* vertexSpirv = nullptr;
  const std::vector<uint32_t>* fragmentSpirv = nullptr;  // null: capture pass
  const std::vector<uint32_t>* indices = nullptr;        // triangle list (with a fragment shader)
  uint32_t width = 1, height = 1;
  std::array<float, 4> clearColor{0, 0, 0, 1};
};

// Where a buffer lives: device only, or mapped host-coherent memory written by the host
// (device-local preferred) or read by it (host-cached preferred).
enum class Memory { Device, Upload, Readback };

// One program on the device; every object is released in the destructor, also on throw.
class ProgramObjects {
 public:
  // Checks the inputs (limits, strides, formats, every declared descriptor fed) and creates
  // every object; the command buffer is left recording the texture uploads.
  ProgramObjects(const Device& device, const ProgramInputs& inputs, const PassDesc& pass);
  ~ProgramObjects();
  ProgramObjects(const ProgramObjects&) = delete;
  ProgramObjects& operator=(const ProgramObjects&) = delete;

  // Writes the inputs (streams, uniform block, storage buffers, indices) into their buffers:
  // mapped ones in place, device-local ones through staging buffers whose copies this records,
  // with the barrier that makes them visible to the vertex stage. Call it before recording a draw.
  void upload();
  // Where the inputs live (describeMemoryType of each distinct type, "; "-separated).
  std::string inputMemory() const;
  // The driver's statistics of the vertex stage's compiled executables, in the driver's
  // order; empty where the device does not offer them (Device::executableStatistics).
  std::vector<ShaderStatistic> vertexStatistics() const;
  // Starts recording again after a submit (a new frame).
  void restart();
  // Begins the render pass and binds the pipeline, the descriptor sets and the vertex/index buffers.
  void beginPass();
  void endPass();
  // One capture draw of every vertex into `xfb` (size bytes).
  void drawCapture(VkBuffer xfb, VkDeviceSize size);
  void drawIndexed();
  // Ends recording, submits and waits.
  void submitAndWait();

  // A buffer owned by this program (host-visible ones mapped).
  Buffer& buffer(VkDeviceSize size, VkBufferUsageFlags usage, Memory memory);

  VkCommandBuffer cmd() const { return cmd_; }
  uint32_t drawCount() const { return drawCount_; }  // vertices of a capture draw (even)
  const ImageObj* color() const { return color_; }
  const ImageObj* depth() const { return depth_; }

 private:
  ImageObj& image(VkFormat format, uint32_t w, uint32_t h, uint32_t layers, bool cube, VkImageUsageFlags usage,
                  VkImageAspectFlags aspect, uint32_t mipLevels = 1);
  void uploadTexture(const Texture& t);
  void checkInputs() const;
  void release();
  void createDescriptors();
  void createTargets();
  void createPipeline();

  const Device& d_;
  const ProgramInputs& in_;
  PassDesc pass_;
  bool rasterize_ = false;
  uint32_t drawCount_ = 0;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkCommandBuffer cmd_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  bool submitted_ = false;
  std::vector<Buffer> buffers_;  // reserved up front: references into it are kept
  std::vector<ImageObj> images_;
  std::vector<VkBuffer> vertexBuffers_;
  size_t firstStream_ = 0, firstStorage_ = 0;  // indices into buffers_
  Buffer* uniform_ = nullptr;
  Buffer* index_ = nullptr;
  std::vector<ImageObj*> textures_;
  ImageObj *color_ = nullptr, *depth_ = nullptr;
  std::vector<VkShaderModule> shaders_;
  VkSampler samplerRepeat_ = VK_NULL_HANDLE, samplerClamp_ = VK_NULL_HANDLE;
  VkDescriptorSetLayout setLayouts_[2] = {VK_NULL_HANDLE, VK_NULL_HANDLE};
  VkDescriptorPool descriptorPool_ = VK_NULL_HANDLE;
  VkDescriptorSet sets_[2] = {VK_NULL_HANDLE, VK_NULL_HANDLE};
  VkPipelineLayout pipelineLayout_ = VK_NULL_HANDLE;
  VkRenderPass renderPass_ = VK_NULL_HANDLE;
  VkFramebuffer framebuffer_ = VK_NULL_HANDLE;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
};

}  // namespace sg::rt::setup

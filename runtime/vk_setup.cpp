#include "runtime/vk_setup.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstring>
#include <set>
#include <stdexcept>

namespace sg::rt::setup {
namespace {

constexpr VkFormat kColorFormat = VK_FORMAT_R8G8B8A8_UNORM;
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;

const char* resultName(VkResult r) {
  switch (r) {
    case VK_NOT_READY: return "VK_NOT_READY";
    case VK_TIMEOUT: return "VK_TIMEOUT";
    case VK_INCOMPLETE: return "VK_INCOMPLETE";
    case VK_ERROR_OUT_OF_HOST_MEMORY: return "VK_ERROR_OUT_OF_HOST_MEMORY";
    case VK_ERROR_OUT_OF_DEVICE_MEMORY: return "VK_ERROR_OUT_OF_DEVICE_MEMORY";
    case VK_ERROR_INITIALIZATION_FAILED: return "VK_ERROR_INITIALIZATION_FAILED";
    case VK_ERROR_DEVICE_LOST: return "VK_ERROR_DEVICE_LOST";
    case VK_ERROR_MEMORY_MAP_FAILED: return "VK_ERROR_MEMORY_MAP_FAILED";
    case VK_ERROR_LAYER_NOT_PRESENT: return "VK_ERROR_LAYER_NOT_PRESENT";
    case VK_ERROR_EXTENSION_NOT_PRESENT: return "VK_ERROR_EXTENSION_NOT_PRESENT";
    case VK_ERROR_FEATURE_NOT_PRESENT: return "VK_ERROR_FEATURE_NOT_PRESENT";
    case VK_ERROR_INCOMPATIBLE_DRIVER: return "VK_ERROR_INCOMPATIBLE_DRIVER";
    case VK_ERROR_TOO_MANY_OBJECTS: return "VK_ERROR_TOO_MANY_OBJECTS";
    case VK_ERROR_FORMAT_NOT_SUPPORTED: return "VK_ERROR_FORMAT_NOT_SUPPORTED";
    case VK_ERROR_INVALID_SHADER_NV: return "VK_ERROR_INVALID_SHADER_NV";
    default: return "VkResult error";
  }
}

uint32_t texelBytes(VkFormat f) {
  if (f == VK_FORMAT_R8G8B8A8_UNORM) return 4;
  if (f == VK_FORMAT_R16G16B16A16_SFLOAT) return 8;
  throw std::runtime_error(fmt::format("vulkan: texture format {} is not supported", static_cast<int>(f)));
}

bool isSpirv(const std::vector<uint32_t>* w) { return w && !w->empty() && (*w)[0] == 0x07230203u; }

const char* kindName(DescriptorKind k) {
  switch (k) {
    case DescriptorKind::UniformBuffer: return "uniform block";
    case DescriptorKind::StorageBuffer: return "storage buffer";
    case DescriptorKind::CombinedImageSampler: return "sampler";
  }
  return "descriptor";
}

// Moves mip levels [baseMip, baseMip + mips) of every layer from one layout to another.
void imageBarrier(VkCommandBuffer cmd, VkImage image, uint32_t layers, VkImageLayout from, VkImageLayout to,
                  VkAccessFlags srcAccess, VkAccessFlags dstAccess, VkPipelineStageFlags srcStage,
                  VkPipelineStageFlags dstStage, uint32_t baseMip = 0, uint32_t mips = 1) {
  VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
  b.srcAccessMask = srcAccess;
  b.dstAccessMask = dstAccess;
  b.oldLayout = from;
  b.newLayout = to;
  b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = image;
  b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, baseMip, mips, 0, layers};
  vkCmdPipelineBarrier(cmd, srcStage, dstStage, 0, 0, nullptr, 0, nullptr, 1, &b);
}

}  // namespace

void check(VkResult r, const char* what) {
  if (r != VK_SUCCESS)
    throw std::runtime_error(fmt::format("vulkan: {} failed: {} ({})", what, resultName(r), static_cast<int>(r)));
}

Device::Device(const Harness::Handles& handles) : h(handles) {
  vkGetPhysicalDeviceProperties(h.physicalDevice, &props);
  vkGetPhysicalDeviceMemoryProperties(h.physicalDevice, &memProps);
  VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
  p2.pNext = &xfbProps;
  vkGetPhysicalDeviceProperties2(h.physicalDevice, &p2);  // the harness only picks devices with xfb
  xfbProps.pNext = nullptr;
  uint32_t n = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(h.physicalDevice, &n, nullptr);
  std::vector<VkQueueFamilyProperties> families(n);
  vkGetPhysicalDeviceQueueFamilyProperties(h.physicalDevice, &n, families.data());
  timestampBits = h.queueFamily < n ? families[h.queueFamily].timestampValidBits : 0;
  VkPhysicalDeviceFeatures features{};
  vkGetPhysicalDeviceFeatures(h.physicalDevice, &features);
  pipelineStatistics = features.pipelineStatisticsQuery;
  bindXfb = reinterpret_cast<PFN_vkCmdBindTransformFeedbackBuffersEXT>(
      vkGetDeviceProcAddr(h.device, "vkCmdBindTransformFeedbackBuffersEXT"));
  beginXfb = reinterpret_cast<PFN_vkCmdBeginTransformFeedbackEXT>(vkGetDeviceProcAddr(h.device, "vkCmdBeginTransformFeedbackEXT"));
  endXfb = reinterpret_cast<PFN_vkCmdEndTransformFeedbackEXT>(vkGetDeviceProcAddr(h.device, "vkCmdEndTransformFeedbackEXT"));
  if (!bindXfb || !beginXfb || !endXfb) throw std::runtime_error("vulkan: transform feedback entry points are missing");
  if (h.executableStatistics) {
    executableProperties = reinterpret_cast<PFN_vkGetPipelineExecutablePropertiesKHR>(
        vkGetDeviceProcAddr(h.device, "vkGetPipelineExecutablePropertiesKHR"));
    executableStatistics = reinterpret_cast<PFN_vkGetPipelineExecutableStatisticsKHR>(
        vkGetDeviceProcAddr(h.device, "vkGetPipelineExecutableStatisticsKHR"));
    if (!executableProperties || !executableStatistics) executableProperties = nullptr, executableStatistics = nullptr;
  }
}

uint32_t chooseMemoryType(const VkPhysicalDeviceMemoryProperties& memory, uint32_t allowed, VkMemoryPropertyFlags required,
                          VkMemoryPropertyFlags preferred) {
  for (VkMemoryPropertyFlags want : {required | preferred, required})
    for (uint32_t i = 0; i < memory.memoryTypeCount && i < 32; ++i)
      if ((allowed & (1u << i)) && (memory.memoryTypes[i].propertyFlags & want) == want) return i;
  return UINT32_MAX;
}

namespace {
std::string bytes(VkDeviceSize n) {
  const double mib = double(n) / (1024.0 * 1024.0);
  if (mib < 1) return fmt::format("{:.0f} KiB", mib * 1024);
  return mib >= 1024 ? fmt::format("{:.1f} GiB", mib / 1024) : fmt::format("{:.0f} MiB", mib);
}
}  // namespace

std::string describeMemoryType(const VkPhysicalDeviceMemoryProperties& memory, uint32_t type) {
  if (type >= memory.memoryTypeCount) return "no memory type";
  auto flagNames = [](uint32_t flags, std::initializer_list<std::pair<uint32_t, const char*>> names) {
    std::string s;
    for (const auto& [bit, name] : names)
      if (flags & bit) s += (s.empty() ? "" : ", ") + std::string(name);
    return s.empty() ? std::string("no flags") : s;
  };
  const VkMemoryType& t = memory.memoryTypes[type];
  const std::string typeFlags =
      flagNames(t.propertyFlags, {{VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, "device-local"},
                                  {VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT, "host-visible"},
                                  {VK_MEMORY_PROPERTY_HOST_COHERENT_BIT, "host-coherent"},
                                  {VK_MEMORY_PROPERTY_HOST_CACHED_BIT, "host-cached"}});
  if (t.heapIndex >= memory.memoryHeapCount) return fmt::format("type {} ({})", type, typeFlags);
  const VkMemoryHeap& h = memory.memoryHeaps[t.heapIndex];
  return fmt::format("type {} ({}) of heap {} ({}, {})", type, typeFlags, t.heapIndex, bytes(h.size),
                     h.flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT ? "device-local" : "host");
}

VkDeviceMemory Device::allocate(const VkMemoryRequirements& mr, VkMemoryPropertyFlags required,
                                VkMemoryPropertyFlags preferred, uint32_t* type) const {
  VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  ai.allocationSize = mr.size;
  ai.memoryTypeIndex = chooseMemoryType(memProps, mr.memoryTypeBits, required, preferred);
  if (ai.memoryTypeIndex == UINT32_MAX) throw std::runtime_error("vulkan: no suitable memory type");
  VkDeviceMemory m = VK_NULL_HANDLE;
  check(vkAllocateMemory(h.device, &ai, nullptr, &m), "vkAllocateMemory");
  if (type) *type = ai.memoryTypeIndex;
  return m;
}

void ProgramObjects::checkInputs() const {
  const ProgramInputs& r = in_;
  const VkPhysicalDeviceLimits& lim = d_.props.limits;
  if (!isSpirv(pass_.vertexSpirv)) throw std::runtime_error("vulkan: the vertex SPIR-V is empty or lacks the SPIR-V magic number");
  if (rasterize_ && !isSpirv(pass_.fragmentSpirv))
    throw std::runtime_error("vulkan: the fragment SPIR-V is empty or lacks the SPIR-V magic number");
  if (r.vertexCount == 0 || r.vertexCount >= (1u << 30))
    throw std::runtime_error(fmt::format("vulkan: vertexCount {} is out of range", r.vertexCount));
  if (rasterize_) {
    if (pass_.width == 0 || pass_.height == 0 || pass_.width > lim.maxFramebufferWidth || pass_.height > lim.maxFramebufferHeight)
      throw std::runtime_error(fmt::format("vulkan: image size {}x{} is out of range (1..{} x 1..{})", pass_.width,
                                           pass_.height, lim.maxFramebufferWidth, lim.maxFramebufferHeight));
    if (!pass_.indices || pass_.indices->empty()) throw std::runtime_error("vulkan: nothing to draw (no indices)");
    if (pass_.indices->size() % 3 != 0) throw std::runtime_error("vulkan: the index count is not a multiple of 3");
    for (uint32_t i : *pass_.indices)
      if (i >= r.vertexCount) throw std::runtime_error(fmt::format("vulkan: index {} >= vertexCount {}", i, r.vertexCount));
  }
  if (r.streams.size() > lim.maxVertexInputBindings || r.streams.size() > lim.maxVertexInputAttributes)
    throw std::runtime_error(fmt::format("vulkan: {} streams exceed the device limit of {}", r.streams.size(),
                                         std::min(lim.maxVertexInputBindings, lim.maxVertexInputAttributes)));
  std::set<uint32_t> locations;
  for (const VertexStream& s : r.streams) {
    if (!locations.insert(s.location).second)
      throw std::runtime_error(fmt::format("vulkan: two streams use location {}", s.location));
    if (s.stride == 0 || s.stride > lim.maxVertexInputBindingStride)
      throw std::runtime_error(fmt::format("vulkan: stream at location {} has stride {} (must be 1..{})", s.location,
                                           s.stride, lim.maxVertexInputBindingStride));
    if (s.data.size() < VkDeviceSize(r.vertexCount) * s.stride)
      throw std::runtime_error(fmt::format("vulkan: stream at location {} holds {} bytes, {} vertices x {} bytes needed",
                                           s.location, s.data.size(), r.vertexCount, s.stride));
    VkFormatProperties fp{};
    vkGetPhysicalDeviceFormatProperties(d_.h.physicalDevice, s.format, &fp);
    if (!(fp.bufferFeatures & VK_FORMAT_FEATURE_VERTEX_BUFFER_BIT))
      throw std::runtime_error(fmt::format("vulkan: format {} of the stream at location {} is not a vertex format on this device",
                                           static_cast<int>(s.format), s.location));
  }
  if (r.uniformData.size() > lim.maxUniformBufferRange)
    throw std::runtime_error(fmt::format("vulkan: uniform data of {} bytes exceeds maxUniformBufferRange {}",
                                         r.uniformData.size(), lim.maxUniformBufferRange));
  std::set<uint32_t> storageBindings, textureBindings;
  for (const StorageBufferData& sb : r.storageBuffers)
    if (sb.data.empty() || sb.binding == 0 || sb.data.size() > lim.maxStorageBufferRange || !storageBindings.insert(sb.binding).second)
      throw std::runtime_error(fmt::format("vulkan: storage buffer at binding {} has {} bytes (1..{} allowed, one buffer "
                                           "per binding, binding 0 is the uniform block's)",
                                           sb.binding, sb.data.size(), lim.maxStorageBufferRange));
  for (const Texture& t : r.textures) {
    const uint32_t faces = t.cube ? 6 : 1;
    if (t.size == 0 || t.size > 4096 || t.data.size() != size_t(faces) * t.size * t.size * texelBytes(t.format) ||
        !textureBindings.insert(t.binding).second)
      throw std::runtime_error(fmt::format("vulkan: texture at binding {} has the wrong size or shares its binding", t.binding));
  }
  // Every descriptor the shaders use must be fed: an unbound one is undefined behaviour
  // (lavapipe crashes on it).
  for (const DescriptorBinding& b : r.declared) {
    bool fed = false;
    if (b.set == 0 && b.kind == DescriptorKind::UniformBuffer)
      fed = b.binding == 0 && !r.uniformData.empty();
    else if (b.set == 0 && b.kind == DescriptorKind::StorageBuffer)
      fed = storageBindings.count(b.binding) > 0;
    else if (b.set == 1 && b.kind == DescriptorKind::CombinedImageSampler)
      fed = !rasterize_ || textureBindings.count(b.binding) > 0;  // set 1 belongs to the fragment stage
    if (!fed)
      throw std::runtime_error(fmt::format("vulkan: the program reads {} '{}' at set {}, binding {}, which nothing feeds",
                                           kindName(b.kind), b.name, b.set, b.binding));
  }
}

Buffer& ProgramObjects::buffer(VkDeviceSize size, VkBufferUsageFlags usage, Memory memory) {
  const bool hostVisible = memory != Memory::Device;
  if (buffers_.size() == buffers_.capacity()) throw std::logic_error("vulkan: ProgramObjects buffer reserve exceeded");
  Buffer& b = buffers_.emplace_back();
  VkBufferCreateInfo ci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  ci.size = std::max<VkDeviceSize>(size, 4);
  ci.usage = usage;
  ci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  check(vkCreateBuffer(d_.h.device, &ci, nullptr, &b.buffer), "vkCreateBuffer");
  VkMemoryRequirements mr{};
  vkGetBufferMemoryRequirements(d_.h.device, b.buffer, &mr);
  // Host-visible memory is coherent: vkQueueSubmit makes earlier host writes visible to the
  // device, so what the host writes in place needs no flush.
  b.memory = d_.allocate(mr, hostVisible ? VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT : 0,
                         memory == Memory::Readback ? VK_MEMORY_PROPERTY_HOST_CACHED_BIT : VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT,
                         &b.memoryType);
  check(vkBindBufferMemory(d_.h.device, b.buffer, b.memory, 0), "vkBindBufferMemory");
  if (hostVisible) check(vkMapMemory(d_.h.device, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped), "vkMapMemory");
  return b;
}

ImageObj& ProgramObjects::image(VkFormat format, uint32_t w, uint32_t h, uint32_t layers, bool cube, VkImageUsageFlags usage,
                                VkImageAspectFlags aspect, uint32_t mipLevels) {
  ImageObj& img = images_.emplace_back();
  VkImageCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  ci.flags = cube ? VK_IMAGE_CREATE_CUBE_COMPATIBLE_BIT : 0;
  ci.imageType = VK_IMAGE_TYPE_2D;
  ci.format = format;
  ci.extent = {w, h, 1};
  ci.mipLevels = mipLevels;
  ci.arrayLayers = layers;
  ci.samples = VK_SAMPLE_COUNT_1_BIT;
  ci.tiling = VK_IMAGE_TILING_OPTIMAL;
  ci.usage = usage;
  ci.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  check(vkCreateImage(d_.h.device, &ci, nullptr, &img.image), "vkCreateImage");
  VkMemoryRequirements mr{};
  vkGetImageMemoryRequirements(d_.h.device, img.image, &mr);
  img.memory = d_.allocate(mr, 0, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  check(vkBindImageMemory(d_.h.device, img.image, img.memory, 0), "vkBindImageMemory");
  VkImageViewCreateInfo vci{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  vci.image = img.image;
  vci.viewType = cube ? VK_IMAGE_VIEW_TYPE_CUBE : VK_IMAGE_VIEW_TYPE_2D;
  vci.format = format;
  vci.subresourceRange = {aspect, 0, mipLevels, 0, layers};
  check(vkCreateImageView(d_.h.device, &vci, nullptr, &img.view), "vkCreateImageView");
  return img;
}

// A texture with its full mip chain, made shader-readable in this command buffer: level 0
// is copied from a staging buffer, each further level is a linear blit of the one above
// (half the size, so each texel averages a 2x2 block of its parent). Without the chain a
// minified map aliases: each pixel shows whichever texels its centre happens to hit.
void ProgramObjects::uploadTexture(const Texture& t) {
  const uint32_t faces = t.cube ? 6 : 1;
  uint32_t mips = 1;
  while ((t.size >> mips) > 0) ++mips;  // floor(log2(size)) + 1
  VkFormatProperties fp{};
  vkGetPhysicalDeviceFormatProperties(d_.h.physicalDevice, t.format, &fp);
  const VkFormatFeatureFlags need =
      VK_FORMAT_FEATURE_BLIT_SRC_BIT | VK_FORMAT_FEATURE_BLIT_DST_BIT | VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT;
  if ((fp.optimalTilingFeatures & need) != need)  // required for both formats by the Vulkan spec
    throw std::runtime_error(fmt::format("vulkan: texture format {} cannot be blitted and filtered linearly on this device",
                                         static_cast<int>(t.format)));
  ImageObj& img = image(t.format, t.size, t.size, faces, t.cube,
                        VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_SAMPLED_BIT,
                        VK_IMAGE_ASPECT_COLOR_BIT, mips);
  Buffer& staging = buffer(t.data.size(), VK_BUFFER_USAGE_TRANSFER_SRC_BIT, Memory::Upload);
  std::memcpy(staging.mapped, t.data.data(), t.data.size());
  imageBarrier(cmd_, img.image, faces, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0,
               VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, mips);
  VkBufferImageCopy copy{};
  copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, faces};
  copy.imageExtent = {t.size, t.size, 1};
  vkCmdCopyBufferToImage(cmd_, staging.buffer, img.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &copy);
  for (uint32_t m = 1; m < mips; ++m) {
    imageBarrier(cmd_, img.image, faces, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                 VK_ACCESS_TRANSFER_WRITE_BIT, VK_ACCESS_TRANSFER_READ_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                 VK_PIPELINE_STAGE_TRANSFER_BIT, m - 1, 1);
    const int32_t from = static_cast<int32_t>(t.size >> (m - 1)), to = static_cast<int32_t>(t.size >> m);
    VkImageBlit blit{};
    blit.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, m - 1, 0, faces};
    blit.srcOffsets[1] = {from, from, 1};
    blit.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, m, 0, faces};
    blit.dstOffsets[1] = {to, to, 1};
    vkCmdBlitImage(cmd_, img.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, img.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1,
                   &blit, VK_FILTER_LINEAR);
  }
  // Levels above the last were blit sources; the last is still a copy/blit destination.
  if (mips > 1)
    imageBarrier(cmd_, img.image, faces, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                 VK_ACCESS_TRANSFER_READ_BIT, VK_ACCESS_SHADER_READ_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                 VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT, 0, mips - 1);
  imageBarrier(cmd_, img.image, faces, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
               VK_ACCESS_TRANSFER_WRITE_BIT, VK_ACCESS_SHADER_READ_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
               VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT, mips - 1, 1);
  textures_.push_back(&img);
}

ProgramObjects::ProgramObjects(const Device& device, const ProgramInputs& inputs, const PassDesc& pass)
    : d_(device), in_(inputs), pass_(pass), rasterize_(pass.fragmentSpirv != nullptr) {
  checkInputs();
  drawCount_ = in_.vertexCount + (in_.vertexCount & 1u);  // line lists need an even count
  try {
    VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pci.queueFamilyIndex = d_.h.queueFamily;
    check(vkCreateCommandPool(d_.h.device, &pci, nullptr, &pool_), "vkCreateCommandPool");
    VkCommandBufferAllocateInfo cbai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    cbai.commandPool = pool_;
    cbai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cbai.commandBufferCount = 1;
    check(vkAllocateCommandBuffers(d_.h.device, &cbai, &cmd_), "vkAllocateCommandBuffers");
    VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    check(vkCreateFence(d_.h.device, &fci, nullptr, &fence_), "vkCreateFence");
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    check(vkBeginCommandBuffer(cmd_, &bi), "vkBeginCommandBuffer");

    // Streams, uniform block, storage buffers and the index buffer (filled by upload(), with a
    // staging buffer each where they are device-local), texture staging, and room for the
    // caller's capture/readback buffers.
    const bool staged = in_.memory == InputMemory::DeviceLocal;
    const Memory inputs = staged ? Memory::Device : Memory::Upload;
    const VkBufferUsageFlags dst = staged ? VK_BUFFER_USAGE_TRANSFER_DST_BIT : 0;
    const size_t inputBuffers = in_.streams.size() + in_.storageBuffers.size() + 2;
    buffers_.reserve(inputBuffers * (staged ? 2 : 1) + in_.textures.size() + 8);
    images_.reserve(in_.textures.size() + 2);
    firstStream_ = buffers_.size();
    for (const VertexStream& s : in_.streams)
      vertexBuffers_.push_back(buffer(VkDeviceSize(drawCount_) * s.stride, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | dst, inputs).buffer);
    firstStorage_ = buffers_.size();
    for (const StorageBufferData& sb : in_.storageBuffers) buffer(sb.data.size(), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | dst, inputs);
    if (!in_.uniformData.empty()) uniform_ = &buffer(in_.uniformData.size(), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT | dst, inputs);
    if (rasterize_) {
      index_ = &buffer(pass_.indices->size() * 4, VK_BUFFER_USAGE_INDEX_BUFFER_BIT | dst, inputs);
      for (const Texture& t : in_.textures) uploadTexture(t);
    }
    createDescriptors();
    createTargets();
    createPipeline();
  } catch (...) {
    release();
    throw;
  }
}

ProgramObjects::~ProgramObjects() { release(); }

void ProgramObjects::release() {
  VkDevice dev = d_.h.device;
  if (submitted_) vkQueueWaitIdle(d_.h.queue);  // never destroy what the device may still use
  if (fence_) vkDestroyFence(dev, fence_, nullptr);
  if (pool_) vkDestroyCommandPool(dev, pool_, nullptr);
  if (pipeline_) vkDestroyPipeline(dev, pipeline_, nullptr);
  if (framebuffer_) vkDestroyFramebuffer(dev, framebuffer_, nullptr);
  if (renderPass_) vkDestroyRenderPass(dev, renderPass_, nullptr);
  if (pipelineLayout_) vkDestroyPipelineLayout(dev, pipelineLayout_, nullptr);
  if (descriptorPool_) vkDestroyDescriptorPool(dev, descriptorPool_, nullptr);
  for (auto l : setLayouts_)
    if (l) vkDestroyDescriptorSetLayout(dev, l, nullptr);
  if (samplerRepeat_) vkDestroySampler(dev, samplerRepeat_, nullptr);
  if (samplerClamp_) vkDestroySampler(dev, samplerClamp_, nullptr);
  for (auto s : shaders_) vkDestroyShaderModule(dev, s, nullptr);
  for (auto& i : images_) {
    if (i.view) vkDestroyImageView(dev, i.view, nullptr);
    if (i.image) vkDestroyImage(dev, i.image, nullptr);
    if (i.memory) vkFreeMemory(dev, i.memory, nullptr);
  }
  for (auto& b : buffers_) {
    if (b.buffer) vkDestroyBuffer(dev, b.buffer, nullptr);
    if (b.memory) vkFreeMemory(dev, b.memory, nullptr);  // also unmaps
  }
  fence_ = VK_NULL_HANDLE;
  pool_ = VK_NULL_HANDLE;
  pipeline_ = VK_NULL_HANDLE;
  framebuffer_ = VK_NULL_HANDLE;
  renderPass_ = VK_NULL_HANDLE;
  pipelineLayout_ = VK_NULL_HANDLE;
  descriptorPool_ = VK_NULL_HANDLE;
  setLayouts_[0] = setLayouts_[1] = VK_NULL_HANDLE;
  samplerRepeat_ = samplerClamp_ = VK_NULL_HANDLE;
  shaders_.clear();
  images_.clear();
  buffers_.clear();
  submitted_ = false;
}

// Set 0 (vertex stage): the uniform block at binding 0 and the storage buffers; set 1
// (fragment stage): the textures.
void ProgramObjects::createDescriptors() {
  VkDevice dev = d_.h.device;
  std::vector<VkDescriptorSetLayoutBinding> b0, b1;
  if (uniform_) b0.push_back({0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1, VK_SHADER_STAGE_VERTEX_BIT, nullptr});
  for (const auto& sb : in_.storageBuffers)
    b0.push_back({sb.binding, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_VERTEX_BIT, nullptr});
  for (size_t i = 0; i < textures_.size(); ++i)
    b1.push_back({in_.textures[i].binding, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, VK_SHADER_STAGE_FRAGMENT_BIT, nullptr});
  for (int s = 0; s < 2; ++s) {
    const auto& b = s == 0 ? b0 : b1;
    VkDescriptorSetLayoutCreateInfo ci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    ci.bindingCount = static_cast<uint32_t>(b.size());
    ci.pBindings = b.data();
    check(vkCreateDescriptorSetLayout(dev, &ci, nullptr, &setLayouts_[s]), "vkCreateDescriptorSetLayout");
  }
  auto atLeastOne = [](size_t n) { return std::max<uint32_t>(1, static_cast<uint32_t>(n)); };
  VkDescriptorPoolSize sizes[3] = {{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1},
                                   {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, atLeastOne(in_.storageBuffers.size())},
                                   {VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, atLeastOne(textures_.size())}};
  VkDescriptorPoolCreateInfo dpci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  dpci.maxSets = 2;
  dpci.poolSizeCount = 3;
  dpci.pPoolSizes = sizes;
  check(vkCreateDescriptorPool(dev, &dpci, nullptr, &descriptorPool_), "vkCreateDescriptorPool");
  VkDescriptorSetAllocateInfo dsai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  dsai.descriptorPool = descriptorPool_;
  dsai.descriptorSetCount = 2;
  dsai.pSetLayouts = setLayouts_;
  check(vkAllocateDescriptorSets(dev, &dsai, sets_), "vkAllocateDescriptorSets");

  if (rasterize_) {
    VkSamplerCreateInfo sci{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
    sci.magFilter = sci.minFilter = VK_FILTER_LINEAR;
    sci.mipmapMode = VK_SAMPLER_MIPMAP_MODE_LINEAR;  // trilinear over the chain uploadTexture makes
    sci.addressModeU = sci.addressModeV = sci.addressModeW = VK_SAMPLER_ADDRESS_MODE_REPEAT;
    sci.maxLod = VK_LOD_CLAMP_NONE;
    check(vkCreateSampler(dev, &sci, nullptr, &samplerRepeat_), "vkCreateSampler");
    sci.addressModeU = sci.addressModeV = sci.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
    check(vkCreateSampler(dev, &sci, nullptr, &samplerClamp_), "vkCreateSampler");
  }
  std::vector<VkDescriptorBufferInfo> bufferInfos;
  std::vector<VkDescriptorImageInfo> imageInfos;
  bufferInfos.reserve(b0.size());  // writes point into both
  imageInfos.reserve(b1.size());
  std::vector<VkWriteDescriptorSet> writes;
  auto write = [&](VkDescriptorSet set, uint32_t binding, VkDescriptorType type) -> VkWriteDescriptorSet& {
    VkWriteDescriptorSet& w = writes.emplace_back(VkWriteDescriptorSet{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET});
    w.dstSet = set;
    w.dstBinding = binding;
    w.descriptorCount = 1;
    w.descriptorType = type;
    return w;
  };
  if (uniform_) {
    bufferInfos.push_back({uniform_->buffer, 0, VK_WHOLE_SIZE});
    write(sets_[0], 0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER).pBufferInfo = &bufferInfos.back();
  }
  for (size_t i = 0; i < in_.storageBuffers.size(); ++i) {
    bufferInfos.push_back({buffers_[firstStorage_ + i].buffer, 0, VK_WHOLE_SIZE});
    write(sets_[0], in_.storageBuffers[i].binding, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER).pBufferInfo = &bufferInfos.back();
  }
  for (size_t i = 0; i < textures_.size(); ++i) {
    imageInfos.push_back({in_.textures[i].cube ? samplerClamp_ : samplerRepeat_, textures_[i]->view,
                          VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL});
    write(sets_[1], in_.textures[i].binding, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER).pImageInfo = &imageInfos.back();
  }
  vkUpdateDescriptorSets(dev, static_cast<uint32_t>(writes.size()), writes.data(), 0, nullptr);
  VkPipelineLayoutCreateInfo plci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  plci.setLayoutCount = 2;
  plci.pSetLayouts = setLayouts_;
  check(vkCreatePipelineLayout(dev, &plci, nullptr, &pipelineLayout_), "vkCreatePipelineLayout");
}

// The colour and depth targets and the render pass (attachment-less, 1x1, for a capture pass).
void ProgramObjects::createTargets() {
  const uint32_t w = rasterize_ ? pass_.width : 1, ht = rasterize_ ? pass_.height : 1;
  VkSubpassDescription sub{};
  sub.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  VkAttachmentReference colorRef{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
  VkAttachmentReference depthRef{1, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
  VkAttachmentDescription att[2]{};
  VkImageView views[2]{};
  VkRenderPassCreateInfo rpci{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
  VkSubpassDependency dep{};
  if (rasterize_) {
    color_ = &image(kColorFormat, w, ht, 1, false, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                    VK_IMAGE_ASPECT_COLOR_BIT);
    depth_ = &image(kDepthFormat, w, ht, 1, false, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                    VK_IMAGE_ASPECT_DEPTH_BIT);
    for (int i = 0; i < 2; ++i)
      att[i] = {0, i == 0 ? kColorFormat : kDepthFormat, VK_SAMPLE_COUNT_1_BIT, VK_ATTACHMENT_LOAD_OP_CLEAR,
                VK_ATTACHMENT_STORE_OP_STORE, VK_ATTACHMENT_LOAD_OP_DONT_CARE, VK_ATTACHMENT_STORE_OP_DONT_CARE,
                VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL};
    views[0] = color_->view;
    views[1] = depth_->view;
    sub.colorAttachmentCount = 1;
    sub.pColorAttachments = &colorRef;
    sub.pDepthStencilAttachment = &depthRef;
    rpci.attachmentCount = 2;
    rpci.pAttachments = att;
    // The copies after the pass wait for its attachment writes.
    dep.srcSubpass = 0;
    dep.dstSubpass = VK_SUBPASS_EXTERNAL;
    dep.srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
    dep.srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
    dep.dstStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
    dep.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
    rpci.dependencyCount = 1;
    rpci.pDependencies = &dep;
  }
  rpci.subpassCount = 1;
  rpci.pSubpasses = &sub;
  check(vkCreateRenderPass(d_.h.device, &rpci, nullptr, &renderPass_), "vkCreateRenderPass");
  VkFramebufferCreateInfo fbci{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
  fbci.renderPass = renderPass_;
  fbci.attachmentCount = rasterize_ ? 2 : 0;
  fbci.pAttachments = views;
  fbci.width = w;
  fbci.height = ht;
  fbci.layers = 1;
  check(vkCreateFramebuffer(d_.h.device, &fbci, nullptr, &framebuffer_), "vkCreateFramebuffer");
}

void ProgramObjects::createPipeline() {
  auto module = [&](const std::vector<uint32_t>& words) {
    VkShaderModuleCreateInfo ci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    ci.codeSize = words.size() * 4;
    ci.pCode = words.data();
    VkShaderModule m = VK_NULL_HANDLE;
    check(vkCreateShaderModule(d_.h.device, &ci, nullptr, &m), "vkCreateShaderModule");
    shaders_.push_back(m);
    return m;
  };
  VkPipelineShaderStageCreateInfo stages[2]{};
  stages[0] = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, nullptr, 0, VK_SHADER_STAGE_VERTEX_BIT,
               module(*pass_.vertexSpirv), "main", nullptr};
  if (rasterize_)
    stages[1] = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, nullptr, 0, VK_SHADER_STAGE_FRAGMENT_BIT,
                 module(*pass_.fragmentSpirv), "main", nullptr};
  std::vector<VkVertexInputBindingDescription> bindings;
  std::vector<VkVertexInputAttributeDescription> attributes;
  for (uint32_t i = 0; i < in_.streams.size(); ++i) {
    bindings.push_back({i, in_.streams[i].stride, VK_VERTEX_INPUT_RATE_VERTEX});
    attributes.push_back({in_.streams[i].location, i, in_.streams[i].format, 0});
  }
  VkPipelineVertexInputStateCreateInfo vi{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
  vi.vertexBindingDescriptionCount = static_cast<uint32_t>(bindings.size());
  vi.pVertexBindingDescriptions = bindings.data();
  vi.vertexAttributeDescriptionCount = static_cast<uint32_t>(attributes.size());
  vi.pVertexAttributeDescriptions = attributes.data();
  VkPipelineInputAssemblyStateCreateInfo ia{VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
  // Lines without rasterization: a point list needs the shader to write gl_PointSize
  // (VUID-VkGraphicsPipelineCreateInfo-Vertex-07722) even with rasterizer discard; line
  // lists keep vertex order in the capture.
  ia.topology = rasterize_ ? VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST : VK_PRIMITIVE_TOPOLOGY_LINE_LIST;
  const uint32_t w = rasterize_ ? pass_.width : 1, ht = rasterize_ ? pass_.height : 1;
  VkViewport viewport{0, 0, float(w), float(ht), 0, 1};
  VkRect2D scissor{{0, 0}, {w, ht}};
  VkPipelineViewportStateCreateInfo vp{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
  vp.viewportCount = vp.scissorCount = 1;
  vp.pViewports = &viewport;
  vp.pScissors = &scissor;
  VkPipelineRasterizationStateCreateInfo rs{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
  rs.rasterizerDiscardEnable = rasterize_ ? VK_FALSE : VK_TRUE;
  rs.polygonMode = VK_POLYGON_MODE_FILL;
  rs.cullMode = VK_CULL_MODE_NONE;  // rigs carry no winding convention
  rs.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
  rs.lineWidth = 1.0f;
  VkPipelineMultisampleStateCreateInfo ms{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
  ms.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
  VkPipelineDepthStencilStateCreateInfo ds{VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
  ds.depthTestEnable = ds.depthWriteEnable = VK_TRUE;
  ds.depthCompareOp = VK_COMPARE_OP_LESS;
  VkPipelineColorBlendAttachmentState cba{};
  cba.colorWriteMask = 0xF;
  VkPipelineColorBlendStateCreateInfo cb{VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
  cb.attachmentCount = 1;
  cb.pAttachments = &cba;
  VkGraphicsPipelineCreateInfo gp{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
  gp.stageCount = rasterize_ ? 2 : 1;
  gp.pStages = stages;
  gp.pVertexInputState = &vi;
  gp.pInputAssemblyState = &ia;
  gp.pViewportState = &vp;
  gp.pRasterizationState = &rs;
  gp.pMultisampleState = &ms;
  gp.pDepthStencilState = rasterize_ ? &ds : nullptr;
  gp.pColorBlendState = rasterize_ ? &cb : nullptr;
  gp.layout = pipelineLayout_;
  gp.renderPass = renderPass_;
  if (d_.executableStatistics) gp.flags |= VK_PIPELINE_CREATE_CAPTURE_STATISTICS_BIT_KHR;
  check(vkCreateGraphicsPipelines(d_.h.device, VK_NULL_HANDLE, 1, &gp, nullptr, &pipeline_), "vkCreateGraphicsPipelines");
}

namespace {
// Vulkan's two-call enumeration (count, then fill `out` from `blank`, whose sType is set);
// false where the driver refuses either call.
template <typename T, typename Query>
bool enumerate(Query query, const T& blank, std::vector<T>& out) {
  uint32_t n = 0;
  if (query(&n, nullptr) != VK_SUCCESS) return false;
  out.assign(n, blank);
  if (query(&n, out.data()) != VK_SUCCESS) return false;
  out.resize(n);
  return true;
}
}  // namespace

std::vector<ShaderStatistic> ProgramObjects::vertexStatistics() const {
  // Best effort: statistics describe a timing and never fail it, so a query the driver refuses
  // gives none (a bench row then says nothing of what was compiled).
  std::vector<ShaderStatistic> out;
  if (!d_.executableStatistics) return out;
  VkPipelineInfoKHR pipeline{VK_STRUCTURE_TYPE_PIPELINE_INFO_KHR};
  pipeline.pipeline = pipeline_;
  std::vector<VkPipelineExecutablePropertiesKHR> executables;
  if (!enumerate([&](uint32_t* n, VkPipelineExecutablePropertiesKHR* p) { return d_.executableProperties(d_.h.device, &pipeline, n, p); },
                 {VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_PROPERTIES_KHR}, executables))
    return {};
  for (uint32_t e = 0; e < executables.size(); ++e) {
    if (!(executables[e].stages & VK_SHADER_STAGE_VERTEX_BIT)) continue;
    VkPipelineExecutableInfoKHR which{VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_INFO_KHR};
    which.pipeline = pipeline_;
    which.executableIndex = e;
    std::vector<VkPipelineExecutableStatisticKHR> stats;
    if (!enumerate([&](uint32_t* n, VkPipelineExecutableStatisticKHR* p) { return d_.executableStatistics(d_.h.device, &which, n, p); },
                   {VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_STATISTIC_KHR}, stats))
      return {};
    for (const auto& st : stats) {
      double v = 0;
      switch (st.format) {
        case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_BOOL32_KHR: v = st.value.b32 ? 1 : 0; break;
        case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_INT64_KHR: v = double(st.value.i64); break;
        case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_UINT64_KHR: v = double(st.value.u64); break;
        case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_FLOAT64_KHR: v = st.value.f64; break;
        default: continue;
      }
      out.push_back({executables[e].name, st.name, v});
    }
  }
  return out;
}

void ProgramObjects::upload() {
  const bool staged = in_.memory == InputMemory::DeviceLocal;
  // Where the host writes `target`'s bytes: its mapping, or a staging buffer copied into it.
  auto destination = [&](Buffer& target, VkDeviceSize size) -> uint8_t* {
    if (!staged) return static_cast<uint8_t*>(target.mapped);
    Buffer& staging = buffer(size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, Memory::Upload);
    const VkBufferCopy region{0, 0, std::max<VkDeviceSize>(size, 4)};
    vkCmdCopyBuffer(cmd_, staging.buffer, target.buffer, 1, &region);
    return static_cast<uint8_t*>(staging.mapped);
  };
  for (size_t i = 0; i < in_.streams.size(); ++i) {
    const VertexStream& s = in_.streams[i];
    const VkDeviceSize used = VkDeviceSize(in_.vertexCount) * s.stride, padded = VkDeviceSize(drawCount_) * s.stride;
    uint8_t* dst = destination(buffers_[firstStream_ + i], padded);
    std::memcpy(dst, s.data.data(), used);
    std::memset(dst + used, 0, padded - used);  // the padding vertex reads zeros, never garbage
  }
  for (size_t i = 0; i < in_.storageBuffers.size(); ++i) {
    const StorageBufferData& sb = in_.storageBuffers[i];
    std::memcpy(destination(buffers_[firstStorage_ + i], sb.data.size()), sb.data.data(), sb.data.size());
  }
  if (uniform_) std::memcpy(destination(*uniform_, in_.uniformData.size()), in_.uniformData.data(), in_.uniformData.size());
  if (index_) std::memcpy(destination(*index_, pass_.indices->size() * 4), pass_.indices->data(), pass_.indices->size() * 4);
  if (staged) {
    VkMemoryBarrier b{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    b.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_VERTEX_ATTRIBUTE_READ_BIT | VK_ACCESS_INDEX_READ_BIT | VK_ACCESS_UNIFORM_READ_BIT |
                      VK_ACCESS_SHADER_READ_BIT;
    vkCmdPipelineBarrier(cmd_, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_VERTEX_INPUT_BIT | VK_PIPELINE_STAGE_VERTEX_SHADER_BIT,
                         0, 1, &b, 0, nullptr, 0, nullptr);
  }
}

std::string ProgramObjects::inputMemory() const {
  std::vector<uint32_t> types;
  auto add = [&](const Buffer& b) {
    if (std::find(types.begin(), types.end(), b.memoryType) == types.end()) types.push_back(b.memoryType);
  };
  for (size_t i = firstStream_; i < firstStorage_ + in_.storageBuffers.size(); ++i) add(buffers_[i]);
  if (uniform_) add(*uniform_);
  if (index_) add(*index_);
  // With the memory budget: what this process holds in each such heap now (its buffers
  // allocated) against what the driver would let it hold, so a run of many timings shows
  // whether something accumulates in the heap its inputs share.
  VkPhysicalDeviceMemoryBudgetPropertiesEXT budget{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MEMORY_BUDGET_PROPERTIES_EXT};
  if (d_.h.memoryBudget) {
    VkPhysicalDeviceMemoryProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MEMORY_PROPERTIES_2};
    p2.pNext = &budget;
    vkGetPhysicalDeviceMemoryProperties2(d_.h.physicalDevice, &p2);
  }
  std::string s;
  for (uint32_t t : types) {
    s += (s.empty() ? "" : "; ") + describeMemoryType(d_.memProps, t);
    if (d_.h.memoryBudget && t < d_.memProps.memoryTypeCount) {
      const uint32_t heap = d_.memProps.memoryTypes[t].heapIndex;
      s += fmt::format(", the process using {} of a {} budget", bytes(budget.heapUsage[heap]), bytes(budget.heapBudget[heap]));
    }
  }
  return s;
}

void ProgramObjects::restart() {
  check(vkResetCommandPool(d_.h.device, pool_, 0), "vkResetCommandPool");
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  check(vkBeginCommandBuffer(cmd_, &bi), "vkBeginCommandBuffer");
}

void ProgramObjects::beginPass() {
  VkClearValue clears[2]{};
  std::memcpy(clears[0].color.float32, pass_.clearColor.data(), sizeof(float) * 4);
  clears[1].depthStencil = {1.0f, 0};
  VkRenderPassBeginInfo rp{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
  rp.renderPass = renderPass_;
  rp.framebuffer = framebuffer_;
  rp.renderArea = {{0, 0}, {rasterize_ ? pass_.width : 1, rasterize_ ? pass_.height : 1}};
  rp.clearValueCount = rasterize_ ? 2 : 0;
  rp.pClearValues = clears;
  vkCmdBeginRenderPass(cmd_, &rp, VK_SUBPASS_CONTENTS_INLINE);
  vkCmdBindPipeline(cmd_, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline_);
  vkCmdBindDescriptorSets(cmd_, VK_PIPELINE_BIND_POINT_GRAPHICS, pipelineLayout_, 0, 2, sets_, 0, nullptr);
  if (!vertexBuffers_.empty()) {
    std::vector<VkDeviceSize> offsets(vertexBuffers_.size(), 0);
    vkCmdBindVertexBuffers(cmd_, 0, static_cast<uint32_t>(vertexBuffers_.size()), vertexBuffers_.data(), offsets.data());
  }
  if (index_) vkCmdBindIndexBuffer(cmd_, index_->buffer, 0, VK_INDEX_TYPE_UINT32);
}

void ProgramObjects::endPass() { vkCmdEndRenderPass(cmd_); }

void ProgramObjects::drawCapture(VkBuffer xfb, VkDeviceSize size) {
  VkDeviceSize offset = 0;
  d_.bindXfb(cmd_, 0, 1, &xfb, &offset, &size);
  d_.beginXfb(cmd_, 0, 0, nullptr, nullptr);
  vkCmdDraw(cmd_, drawCount_, 1, 0, 0);
  d_.endXfb(cmd_, 0, 0, nullptr, nullptr);
}

void ProgramObjects::drawIndexed() { vkCmdDrawIndexed(cmd_, static_cast<uint32_t>(pass_.indices->size()), 1, 0, 0, 0); }

void ProgramObjects::submitAndWait() {
  check(vkEndCommandBuffer(cmd_), "vkEndCommandBuffer");
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd_;
  check(vkResetFences(d_.h.device, 1, &fence_), "vkResetFences");
  check(vkQueueSubmit(d_.h.queue, 1, &si, fence_), "vkQueueSubmit");
  submitted_ = true;
  check(vkWaitForFences(d_.h.device, 1, &fence_, VK_TRUE, UINT64_MAX), "vkWaitForFences");
  submitted_ = false;
}

}  // namespace sg::rt::setup

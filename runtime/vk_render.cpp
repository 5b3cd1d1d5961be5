#include "runtime/vk_render.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <functional>
#include <stdexcept>

namespace sg::rt {
namespace {

constexpr VkFormat kColorFormat = VK_FORMAT_R8G8B8A8_UNORM;
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;

void check(VkResult r, const char* what) {
  if (r != VK_SUCCESS) throw std::runtime_error(fmt::format("vk render: {} failed (VkResult {})", what, static_cast<int>(r)));
}

uint32_t texelBytes(VkFormat f) {
  if (f == VK_FORMAT_R8G8B8A8_UNORM) return 4;
  if (f == VK_FORMAT_R16G16B16A16_SFLOAT) return 8;
  throw std::runtime_error(fmt::format("vk render: texture format {} is not supported", static_cast<int>(f)));
}

struct Buffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  void* mapped = nullptr;
};
struct ImageObj {
  VkImage image = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;
};

// Everything one draw or timing run creates; released in the destructor, also on throw.
struct Objects {
  VkDevice device;
  VkQueue queue;
  VkCommandPool pool = VK_NULL_HANDLE;
  std::vector<Buffer> buffers;
  std::vector<ImageObj> images;
  std::vector<VkShaderModule> shaders;
  VkSampler samplerRepeat = VK_NULL_HANDLE, samplerClamp = VK_NULL_HANDLE;
  VkDescriptorSetLayout setLayouts[2] = {VK_NULL_HANDLE, VK_NULL_HANDLE};
  VkDescriptorPool descriptorPool = VK_NULL_HANDLE;
  VkDescriptorSet sets[2] = {VK_NULL_HANDLE, VK_NULL_HANDLE};
  VkPipelineLayout pipelineLayout = VK_NULL_HANDLE;
  VkRenderPass renderPass = VK_NULL_HANDLE;
  VkFramebuffer framebuffer = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
  VkQueryPool queries = VK_NULL_HANDLE;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
  bool submitted = false;

  Objects(VkDevice d, VkQueue q) : device(d), queue(q) {}
  Objects(const Objects&) = delete;
  Objects& operator=(const Objects&) = delete;
  ~Objects() {
    if (submitted) vkQueueWaitIdle(queue);
    if (fence) vkDestroyFence(device, fence, nullptr);
    if (pool) vkDestroyCommandPool(device, pool, nullptr);
    if (queries) vkDestroyQueryPool(device, queries, nullptr);
    if (pipeline) vkDestroyPipeline(device, pipeline, nullptr);
    if (framebuffer) vkDestroyFramebuffer(device, framebuffer, nullptr);
    if (renderPass) vkDestroyRenderPass(device, renderPass, nullptr);
    if (pipelineLayout) vkDestroyPipelineLayout(device, pipelineLayout, nullptr);
    if (descriptorPool) vkDestroyDescriptorPool(device, descriptorPool, nullptr);
    for (auto l : setLayouts)
      if (l) vkDestroyDescriptorSetLayout(device, l, nullptr);
    if (samplerRepeat) vkDestroySampler(device, samplerRepeat, nullptr);
    if (samplerClamp) vkDestroySampler(device, samplerClamp, nullptr);
    for (auto s : shaders) vkDestroyShaderModule(device, s, nullptr);
    for (auto& i : images) {
      if (i.view) vkDestroyImageView(device, i.view, nullptr);
      if (i.image) vkDestroyImage(device, i.image, nullptr);
      if (i.memory) vkFreeMemory(device, i.memory, nullptr);
    }
    for (auto& b : buffers) {
      if (b.buffer) vkDestroyBuffer(device, b.buffer, nullptr);
      if (b.memory) vkFreeMemory(device, b.memory, nullptr);
    }
  }
};

}  // namespace

struct Renderer::Impl {
  Harness::Handles h;
  VkPhysicalDeviceProperties props{};
  VkPhysicalDeviceMemoryProperties memProps{};
  VkPhysicalDeviceTransformFeedbackPropertiesEXT xfbProps{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_TRANSFORM_FEEDBACK_PROPERTIES_EXT};
  uint32_t timestampBits = 0;
  PFN_vkCmdBindTransformFeedbackBuffersEXT bindXfb = nullptr;
  PFN_vkCmdBeginTransformFeedbackEXT beginXfb = nullptr;
  PFN_vkCmdEndTransformFeedbackEXT endXfb = nullptr;

  uint32_t memoryType(uint32_t bits, VkMemoryPropertyFlags required, VkMemoryPropertyFlags preferred) const {
    for (VkMemoryPropertyFlags want : {required | preferred, required})
      for (uint32_t i = 0; i < memProps.memoryTypeCount; ++i)
        if ((bits & (1u << i)) && (memProps.memoryTypes[i].propertyFlags & want) == want) return i;
    throw std::runtime_error("vk render: no suitable memory type");
  }

  Buffer& buffer(Objects& o, VkDeviceSize size, VkBufferUsageFlags usage, bool hostVisible) {
    Buffer& b = o.buffers.emplace_back();
    VkBufferCreateInfo ci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    ci.size = std::max<VkDeviceSize>(size, 4);
    ci.usage = usage;
    check(vkCreateBuffer(h.device, &ci, nullptr, &b.buffer), "vkCreateBuffer");
    VkMemoryRequirements mr{};
    vkGetBufferMemoryRequirements(h.device, b.buffer, &mr);
    VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    ai.allocationSize = mr.size;
    ai.memoryTypeIndex = hostVisible ? memoryType(mr.memoryTypeBits,
                                                  VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
                                                  VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT)
                                     : memoryType(mr.memoryTypeBits, 0, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    check(vkAllocateMemory(h.device, &ai, nullptr, &b.memory), "vkAllocateMemory");
    check(vkBindBufferMemory(h.device, b.buffer, b.memory, 0), "vkBindBufferMemory");
    if (hostVisible) check(vkMapMemory(h.device, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped), "vkMapMemory");
    return b;
  }

  ImageObj& image(Objects& o, VkFormat format, uint32_t w, uint32_t hgt, uint32_t layers, bool cube,
                  VkImageUsageFlags usage, VkImageAspectFlags aspect) {
    ImageObj& img = o.images.emplace_back();
    VkImageCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    ci.flags = cube ? VK_IMAGE_CREATE_CUBE_COMPATIBLE_BIT : 0;
    ci.imageType = VK_IMAGE_TYPE_2D;
    ci.format = format;
    ci.extent = {w, hgt, 1};
    ci.mipLevels = 1;
    ci.arrayLayers = layers;
    ci.samples = VK_SAMPLE_COUNT_1_BIT;
    ci.tiling = VK_IMAGE_TILING_OPTIMAL;
    ci.usage = usage;
    ci.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    check(vkCreateImage(h.device, &ci, nullptr, &img.image), "vkCreateImage");
    VkMemoryRequirements mr{};
    vkGetImageMemoryRequirements(h.device, img.image, &mr);
    VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    ai.allocationSize = mr.size;
    ai.memoryTypeIndex = memoryType(mr.memoryTypeBits, 0, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    check(vkAllocateMemory(h.device, &ai, nullptr, &img.memory), "vkAllocateMemory");
    check(vkBindImageMemory(h.device, img.image, img.memory, 0), "vkBindImageMemory");
    VkImageViewCreateInfo vci{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    vci.image = img.image;
    vci.viewType = cube ? VK_IMAGE_VIEW_TYPE_CUBE : VK_IMAGE_VIEW_TYPE_2D;
    vci.format = format;
    vci.subresourceRange = {aspect, 0, 1, 0, layers};
    check(vkCreateImageView(h.device, &vci, nullptr, &img.view), "vkCreateImageView");
    return img;
  }

  static void imageBarrier(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect, uint32_t layers,
                           VkImageLayout from, VkImageLayout to, VkAccessFlags srcAccess, VkAccessFlags dstAccess,
                           VkPipelineStageFlags srcStage, VkPipelineStageFlags dstStage) {
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.srcAccessMask = srcAccess;
    b.dstAccessMask = dstAccess;
    b.oldLayout = from;
    b.newLayout = to;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image;
    b.subresourceRange = {aspect, 0, 1, 0, layers};
    vkCmdPipelineBarrier(cmd, srcStage, dstStage, 0, 0, nullptr, 0, nullptr, 1, &b);
  }

  void validate(const DrawRequest& r, bool needFragment) const {
    auto isSpirv = [](const std::vector<uint32_t>& w) { return !w.empty() && w[0] == 0x07230203u; };
    if (!isSpirv(r.vertexSpirv)) throw std::runtime_error("vk render: the vertex SPIR-V is empty or not SPIR-V");
    if (needFragment && !isSpirv(r.fragmentSpirv))
      throw std::runtime_error("vk render: the fragment SPIR-V is empty or not SPIR-V");
    const auto& lim = props.limits;
    if (r.vertexCount == 0 || r.vertexCount >= (1u << 30))
      throw std::runtime_error(fmt::format("vk render: vertexCount {} is out of range", r.vertexCount));
    if (r.width == 0 || r.height == 0 || r.width > lim.maxFramebufferWidth || r.height > lim.maxFramebufferHeight)
      throw std::runtime_error(fmt::format("vk render: image size {}x{} is out of range (1..{} x 1..{})", r.width, r.height,
                                           lim.maxFramebufferWidth, lim.maxFramebufferHeight));
    if (r.indices.size() % 3 != 0) throw std::runtime_error("vk render: the index count is not a multiple of 3");
    for (uint32_t i : r.indices)
      if (i >= r.vertexCount) throw std::runtime_error(fmt::format("vk render: index {} >= vertexCount {}", i, r.vertexCount));
    if (r.streams.size() > lim.maxVertexInputBindings || r.streams.size() > lim.maxVertexInputAttributes)
      throw std::runtime_error(fmt::format("vk render: {} streams exceed the device's limit", r.streams.size()));
    for (const auto& s : r.streams)
      if (s.stride == 0 || s.stride > lim.maxVertexInputBindingStride || s.data.size() < VkDeviceSize(r.vertexCount) * s.stride)
        throw std::runtime_error(fmt::format("vk render: stream at location {} is too short or has a bad stride", s.location));
    if (r.uniformData.size() > lim.maxUniformBufferRange)
      throw std::runtime_error(fmt::format("vk render: uniform data of {} bytes exceeds maxUniformBufferRange {}",
                                           r.uniformData.size(), lim.maxUniformBufferRange));
    for (const auto& t : r.textures) {
      uint32_t faces = t.cube ? 6 : 1;
      if (t.size == 0 || t.size > 4096 || t.data.size() != size_t(faces) * t.size * t.size * texelBytes(t.format))
        throw std::runtime_error(fmt::format("vk render: texture at binding {} has the wrong size", t.binding));
    }
  }

  // Buffers, textures, descriptors, targets, pipeline and a command buffer in recording state;
  // `rasterize` false builds the rasterizer-discard, vertex-only pipeline (line list, xfb).
  void setup(Objects& o, const DrawRequest& r, bool rasterize, std::vector<VkBuffer>& vertexBuffers, Buffer*& indexBuffer,
             ImageObj*& color, ImageObj*& depth) {
    VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pci.queueFamilyIndex = h.queueFamily;
    check(vkCreateCommandPool(h.device, &pci, nullptr, &o.pool), "vkCreateCommandPool");
    VkCommandBufferAllocateInfo cbai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    cbai.commandPool = o.pool;
    cbai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cbai.commandBufferCount = 1;
    check(vkAllocateCommandBuffers(h.device, &cbai, &o.cmd), "vkAllocateCommandBuffers");
    VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    check(vkCreateFence(h.device, &fci, nullptr, &o.fence), "vkCreateFence");

    o.buffers.reserve(r.streams.size() + r.textures.size() + 8);  // references into it are kept
    o.images.reserve(r.textures.size() + 2);
    const uint32_t padded = r.vertexCount + (r.vertexCount & 1u);  // line lists need an even count
    for (const auto& s : r.streams) {
      Buffer& b = buffer(o, VkDeviceSize(padded) * s.stride, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT, true);
      std::memset(b.mapped, 0, VkDeviceSize(padded) * s.stride);
      std::memcpy(b.mapped, s.data.data(), VkDeviceSize(r.vertexCount) * s.stride);
      vertexBuffers.push_back(b.buffer);
    }
    indexBuffer = nullptr;
    if (!r.indices.empty()) {
      indexBuffer = &buffer(o, r.indices.size() * 4, VK_BUFFER_USAGE_INDEX_BUFFER_BIT, true);
      std::memcpy(indexBuffer->mapped, r.indices.data(), r.indices.size() * 4);
    }
    Buffer* uniform = nullptr;
    if (!r.uniformData.empty()) {
      uniform = &buffer(o, r.uniformData.size(), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, true);
      std::memcpy(uniform->mapped, r.uniformData.data(), r.uniformData.size());
    }

    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    check(vkBeginCommandBuffer(o.cmd, &bi), "vkBeginCommandBuffer");

    // Textures: staged, copied, made shader-readable in this command buffer.
    std::vector<ImageObj*> textureImages;
    if (rasterize) {
      for (const auto& t : r.textures) {
        uint32_t faces = t.cube ? 6 : 1;
        ImageObj& img = image(o, t.format, t.size, t.size, faces, t.cube,
                              VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_SAMPLED_BIT, VK_IMAGE_ASPECT_COLOR_BIT);
        Buffer& staging = buffer(o, t.data.size(), VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true);
        std::memcpy(staging.mapped, t.data.data(), t.data.size());
        imageBarrier(o.cmd, img.image, VK_IMAGE_ASPECT_COLOR_BIT, faces, VK_IMAGE_LAYOUT_UNDEFINED,
                     VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0, VK_ACCESS_TRANSFER_WRITE_BIT,
                     VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT);
        VkBufferImageCopy copy{};
        copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, faces};
        copy.imageExtent = {t.size, t.size, 1};
        vkCmdCopyBufferToImage(o.cmd, staging.buffer, img.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &copy);
        imageBarrier(o.cmd, img.image, VK_IMAGE_ASPECT_COLOR_BIT, faces, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                     VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_ACCESS_TRANSFER_WRITE_BIT, VK_ACCESS_SHADER_READ_BIT,
                     VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT);
        textureImages.push_back(&img);
      }
      VkSamplerCreateInfo sci{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
      sci.magFilter = sci.minFilter = VK_FILTER_LINEAR;
      sci.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
      sci.addressModeU = sci.addressModeV = sci.addressModeW = VK_SAMPLER_ADDRESS_MODE_REPEAT;
      sci.maxLod = 0;
      check(vkCreateSampler(h.device, &sci, nullptr, &o.samplerRepeat), "vkCreateSampler");
      sci.addressModeU = sci.addressModeV = sci.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
      check(vkCreateSampler(h.device, &sci, nullptr, &o.samplerClamp), "vkCreateSampler");
    }

    // Set 0: the vertex uniform block; set 1: the fragment textures.
    VkDescriptorSetLayoutBinding ub{0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1, VK_SHADER_STAGE_VERTEX_BIT, nullptr};
    VkDescriptorSetLayoutCreateInfo l0{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    l0.bindingCount = uniform ? 1 : 0;
    l0.pBindings = &ub;
    check(vkCreateDescriptorSetLayout(h.device, &l0, nullptr, &o.setLayouts[0]), "vkCreateDescriptorSetLayout");
    std::vector<VkDescriptorSetLayoutBinding> tb;
    if (rasterize)
      for (const auto& t : r.textures)
        tb.push_back({t.binding, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, VK_SHADER_STAGE_FRAGMENT_BIT, nullptr});
    VkDescriptorSetLayoutCreateInfo l1{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    l1.bindingCount = static_cast<uint32_t>(tb.size());
    l1.pBindings = tb.data();
    check(vkCreateDescriptorSetLayout(h.device, &l1, nullptr, &o.setLayouts[1]), "vkCreateDescriptorSetLayout");
    VkDescriptorPoolSize sizes[2] = {{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1},
                                     {VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, std::max<uint32_t>(1, static_cast<uint32_t>(tb.size()))}};
    VkDescriptorPoolCreateInfo dpci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    dpci.maxSets = 2;
    dpci.poolSizeCount = 2;
    dpci.pPoolSizes = sizes;
    check(vkCreateDescriptorPool(h.device, &dpci, nullptr, &o.descriptorPool), "vkCreateDescriptorPool");
    VkDescriptorSetAllocateInfo dsai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    dsai.descriptorPool = o.descriptorPool;
    dsai.descriptorSetCount = 2;
    dsai.pSetLayouts = o.setLayouts;
    check(vkAllocateDescriptorSets(h.device, &dsai, o.sets), "vkAllocateDescriptorSets");
    std::vector<VkWriteDescriptorSet> writes;
    VkDescriptorBufferInfo dbi{};
    if (uniform) {
      dbi = {uniform->buffer, 0, VK_WHOLE_SIZE};
      VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
      w.dstSet = o.sets[0];
      w.descriptorCount = 1;
      w.descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
      w.pBufferInfo = &dbi;
      writes.push_back(w);
    }
    std::vector<VkDescriptorImageInfo> dii(textureImages.size());
    for (size_t i = 0; i < textureImages.size(); ++i) {
      dii[i] = {r.textures[i].cube ? o.samplerClamp : o.samplerRepeat, textureImages[i]->view,
                VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
      VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
      w.dstSet = o.sets[1];
      w.dstBinding = r.textures[i].binding;
      w.descriptorCount = 1;
      w.descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
      w.pImageInfo = &dii[i];
      writes.push_back(w);
    }
    vkUpdateDescriptorSets(h.device, static_cast<uint32_t>(writes.size()), writes.data(), 0, nullptr);
    VkPipelineLayoutCreateInfo plci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    plci.setLayoutCount = 2;
    plci.pSetLayouts = o.setLayouts;
    check(vkCreatePipelineLayout(h.device, &plci, nullptr, &o.pipelineLayout), "vkCreatePipelineLayout");

    // Targets and render pass (none but a 1x1 attachment-less pass without rasterization).
    const uint32_t w = rasterize ? r.width : 1, ht = rasterize ? r.height : 1;
    VkSubpassDescription sub{};
    sub.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    VkAttachmentReference colorRef{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
    VkAttachmentReference depthRef{1, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
    VkAttachmentDescription att[2]{};
    VkImageView views[2]{};
    VkRenderPassCreateInfo rpci{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
    VkSubpassDependency dep{};
    color = depth = nullptr;
    if (rasterize) {
      color = &image(o, kColorFormat, w, ht, 1, false, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                     VK_IMAGE_ASPECT_COLOR_BIT);
      depth = &image(o, kDepthFormat, w, ht, 1, false,
                     VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT, VK_IMAGE_ASPECT_DEPTH_BIT);
      att[0] = {0, kColorFormat, VK_SAMPLE_COUNT_1_BIT, VK_ATTACHMENT_LOAD_OP_CLEAR, VK_ATTACHMENT_STORE_OP_STORE,
                VK_ATTACHMENT_LOAD_OP_DONT_CARE, VK_ATTACHMENT_STORE_OP_DONT_CARE, VK_IMAGE_LAYOUT_UNDEFINED,
                VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL};
      att[1] = {0, kDepthFormat, VK_SAMPLE_COUNT_1_BIT, VK_ATTACHMENT_LOAD_OP_CLEAR, VK_ATTACHMENT_STORE_OP_STORE,
                VK_ATTACHMENT_LOAD_OP_DONT_CARE, VK_ATTACHMENT_STORE_OP_DONT_CARE, VK_IMAGE_LAYOUT_UNDEFINED,
                VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL};
      views[0] = color->view;
      views[1] = depth->view;
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
    check(vkCreateRenderPass(h.device, &rpci, nullptr, &o.renderPass), "vkCreateRenderPass");
    VkFramebufferCreateInfo fbci{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
    fbci.renderPass = o.renderPass;
    fbci.attachmentCount = rasterize ? 2 : 0;
    fbci.pAttachments = views;
    fbci.width = w;
    fbci.height = ht;
    fbci.layers = 1;
    check(vkCreateFramebuffer(h.device, &fbci, nullptr, &o.framebuffer), "vkCreateFramebuffer");

    // Pipeline.
    auto module = [&](const std::vector<uint32_t>& words) {
      VkShaderModuleCreateInfo ci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
      ci.codeSize = words.size() * 4;
      ci.pCode = words.data();
      VkShaderModule m = VK_NULL_HANDLE;
      check(vkCreateShaderModule(h.device, &ci, nullptr, &m), "vkCreateShaderModule");
      o.shaders.push_back(m);
      return m;
    };
    VkPipelineShaderStageCreateInfo stages[2]{};
    stages[0] = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, nullptr, 0, VK_SHADER_STAGE_VERTEX_BIT,
                 module(r.vertexSpirv), "main", nullptr};
    if (rasterize)
      stages[1] = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, nullptr, 0, VK_SHADER_STAGE_FRAGMENT_BIT,
                   module(r.fragmentSpirv), "main", nullptr};
    std::vector<VkVertexInputBindingDescription> bindings;
    std::vector<VkVertexInputAttributeDescription> attributes;
    for (uint32_t i = 0; i < r.streams.size(); ++i) {
      bindings.push_back({i, r.streams[i].stride, VK_VERTEX_INPUT_RATE_VERTEX});
      attributes.push_back({r.streams[i].location, i, r.streams[i].format, 0});
    }
    VkPipelineVertexInputStateCreateInfo vi{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
    vi.vertexBindingDescriptionCount = static_cast<uint32_t>(bindings.size());
    vi.pVertexBindingDescriptions = bindings.data();
    vi.vertexAttributeDescriptionCount = static_cast<uint32_t>(attributes.size());
    vi.pVertexAttributeDescriptions = attributes.data();
    VkPipelineInputAssemblyStateCreateInfo ia{VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
    // Lines without rasterization: points would need gl_PointSize (see vk_harness.cpp).
    ia.topology = rasterize ? VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST : VK_PRIMITIVE_TOPOLOGY_LINE_LIST;
    VkViewport viewport{0, 0, float(w), float(ht), 0, 1};
    VkRect2D scissor{{0, 0}, {w, ht}};
    VkPipelineViewportStateCreateInfo vp{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
    vp.viewportCount = vp.scissorCount = 1;
    vp.pViewports = &viewport;
    vp.pScissors = &scissor;
    VkPipelineRasterizationStateCreateInfo rs{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
    rs.rasterizerDiscardEnable = rasterize ? VK_FALSE : VK_TRUE;
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
    gp.stageCount = rasterize ? 2 : 1;
    gp.pStages = stages;
    gp.pVertexInputState = &vi;
    gp.pInputAssemblyState = &ia;
    gp.pViewportState = &vp;
    gp.pRasterizationState = &rs;
    gp.pMultisampleState = &ms;
    gp.pDepthStencilState = rasterize ? &ds : nullptr;
    gp.pColorBlendState = rasterize ? &cb : nullptr;
    gp.layout = o.pipelineLayout;
    gp.renderPass = o.renderPass;
    check(vkCreateGraphicsPipelines(h.device, VK_NULL_HANDLE, 1, &gp, nullptr, &o.pipeline), "vkCreateGraphicsPipelines");
  }

  void beginPass(Objects& o, const DrawRequest& r, bool rasterize, const std::vector<VkBuffer>& vertexBuffers,
                 const Buffer* indexBuffer) {
    VkClearValue clears[2]{};
    std::memcpy(clears[0].color.float32, r.clearColor.data(), sizeof(float) * 4);
    clears[1].depthStencil = {1.0f, 0};
    VkRenderPassBeginInfo rp{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
    rp.renderPass = o.renderPass;
    rp.framebuffer = o.framebuffer;
    rp.renderArea = {{0, 0}, {rasterize ? r.width : 1, rasterize ? r.height : 1}};
    rp.clearValueCount = rasterize ? 2 : 0;
    rp.pClearValues = clears;
    vkCmdBeginRenderPass(o.cmd, &rp, VK_SUBPASS_CONTENTS_INLINE);
    vkCmdBindPipeline(o.cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, o.pipeline);
    vkCmdBindDescriptorSets(o.cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, o.pipelineLayout, 0, 2, o.sets, 0, nullptr);
    if (!vertexBuffers.empty()) {
      std::vector<VkDeviceSize> offsets(vertexBuffers.size(), 0);
      vkCmdBindVertexBuffers(o.cmd, 0, static_cast<uint32_t>(vertexBuffers.size()), vertexBuffers.data(), offsets.data());
    }
    if (indexBuffer) vkCmdBindIndexBuffer(o.cmd, indexBuffer->buffer, 0, VK_INDEX_TYPE_UINT32);
  }

  void submitAndWait(Objects& o) {
    check(vkEndCommandBuffer(o.cmd), "vkEndCommandBuffer");
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &o.cmd;
    check(vkResetFences(h.device, 1, &o.fence), "vkResetFences");
    check(vkQueueSubmit(h.queue, 1, &si, o.fence), "vkQueueSubmit");
    o.submitted = true;
    check(vkWaitForFences(h.device, 1, &o.fence, VK_TRUE, UINT64_MAX), "vkWaitForFences");
    o.submitted = false;
  }
};

Renderer::Renderer(const Harness& harness) : impl_(new Impl) {
  Impl& m = *impl_;
  m.h = harness.handles();
  vkGetPhysicalDeviceProperties(m.h.physicalDevice, &m.props);
  vkGetPhysicalDeviceMemoryProperties(m.h.physicalDevice, &m.memProps);
  VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
  p2.pNext = &m.xfbProps;
  vkGetPhysicalDeviceProperties2(m.h.physicalDevice, &p2);  // the harness only picks devices with xfb
  m.xfbProps.pNext = nullptr;
  uint32_t n = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(m.h.physicalDevice, &n, nullptr);
  std::vector<VkQueueFamilyProperties> families(n);
  vkGetPhysicalDeviceQueueFamilyProperties(m.h.physicalDevice, &n, families.data());
  m.timestampBits = m.h.queueFamily < n ? families[m.h.queueFamily].timestampValidBits : 0;
  m.bindXfb = reinterpret_cast<PFN_vkCmdBindTransformFeedbackBuffersEXT>(
      vkGetDeviceProcAddr(m.h.device, "vkCmdBindTransformFeedbackBuffersEXT"));
  m.beginXfb = reinterpret_cast<PFN_vkCmdBeginTransformFeedbackEXT>(vkGetDeviceProcAddr(m.h.device, "vkCmdBeginTransformFeedbackEXT"));
  m.endXfb = reinterpret_cast<PFN_vkCmdEndTransformFeedbackEXT>(vkGetDeviceProcAddr(m.h.device, "vkCmdEndTransformFeedbackEXT"));
}

Renderer::~Renderer() { delete impl_; }

std::string Renderer::driver() const {
  const Impl& m = *impl_;
  if (m.props.apiVersion >= VK_API_VERSION_1_2) {
    VkPhysicalDeviceDriverProperties drv{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
    VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
    p2.pNext = &drv;
    vkGetPhysicalDeviceProperties2(m.h.physicalDevice, &p2);
    return fmt::format("{} {}", drv.driverName, drv.driverInfo);
  }
  return fmt::format("driver version {:#x}", m.props.driverVersion);
}

Image Renderer::draw(const DrawRequest& r) {
  Impl& m = *impl_;
  m.validate(r, true);
  if (r.indices.empty()) throw std::runtime_error("vk render: nothing to draw (no indices)");
  Objects o(m.h.device, m.h.queue);
  std::vector<VkBuffer> vertexBuffers;
  Buffer* indexBuffer = nullptr;
  ImageObj *color = nullptr, *depth = nullptr;
  m.setup(o, r, true, vertexBuffers, indexBuffer, color, depth);
  m.beginPass(o, r, true, vertexBuffers, indexBuffer);
  vkCmdDrawIndexed(o.cmd, static_cast<uint32_t>(r.indices.size()), 1, 0, 0, 0);
  vkCmdEndRenderPass(o.cmd);

  const VkDeviceSize pixels = VkDeviceSize(r.width) * r.height;
  Buffer& colorOut = m.buffer(o, pixels * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
  Buffer& depthOut = m.buffer(o, pixels * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
  VkBufferImageCopy copy{};
  copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  copy.imageExtent = {r.width, r.height, 1};
  vkCmdCopyImageToBuffer(o.cmd, color->image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, colorOut.buffer, 1, &copy);
  copy.imageSubresource.aspectMask = VK_IMAGE_ASPECT_DEPTH_BIT;
  vkCmdCopyImageToBuffer(o.cmd, depth->image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, depthOut.buffer, 1, &copy);
  VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  mb.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  mb.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(o.cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &mb, 0, nullptr, 0, nullptr);
  m.submitAndWait(o);

  Image img;
  img.width = r.width;
  img.height = r.height;
  const auto* c = static_cast<const uint8_t*>(colorOut.mapped);
  img.rgba.assign(c, c + pixels * 4);
  const auto* d = static_cast<const float*>(depthOut.mapped);
  img.depth.assign(d, d + pixels);
  return img;
}

Timing Renderer::time(const DrawRequest& r, const TimingRequest& t) {
  Impl& m = *impl_;
  m.validate(r, t.rasterize);
  if (m.timestampBits == 0) throw std::runtime_error("vk render: the queue family has no timestamps (timestampValidBits = 0)");
  if (t.drawsPerFrame == 0 || t.frames == 0) throw std::runtime_error("vk render: drawsPerFrame and frames must be > 0");
  if (t.rasterize && r.indices.empty()) throw std::runtime_error("vk render: nothing to draw (no indices)");
  const uint32_t padded = r.vertexCount + (r.vertexCount & 1u);
  const VkDeviceSize xfbSize = VkDeviceSize(padded) * t.captureStride;
  if (!t.rasterize && (t.captureStride == 0 || t.captureStride % 4 != 0 || xfbSize > m.xfbProps.maxTransformFeedbackBufferSize))
    throw std::runtime_error(fmt::format("vk render: capture stride {} is invalid for this device", t.captureStride));

  Objects o(m.h.device, m.h.queue);
  std::vector<VkBuffer> vertexBuffers;
  Buffer* indexBuffer = nullptr;
  ImageObj *color = nullptr, *depth = nullptr;
  m.setup(o, r, t.rasterize, vertexBuffers, indexBuffer, color, depth);
  Buffer* capture = nullptr;
  if (!t.rasterize) capture = &m.buffer(o, xfbSize, VK_BUFFER_USAGE_TRANSFORM_FEEDBACK_BUFFER_BIT_EXT, false);
  VkQueryPoolCreateInfo qci{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  qci.queryType = VK_QUERY_TYPE_TIMESTAMP;
  qci.queryCount = 2;
  check(vkCreateQueryPool(m.h.device, &qci, nullptr, &o.queries), "vkCreateQueryPool");

  // One command buffer per frame: the setup copies (textures) in the first, then only draws.
  Timing out;
  out.verticesPerDraw = r.vertexCount;
  for (uint32_t f = 0; f < t.frames; ++f) {
    if (f > 0) {
      check(vkResetCommandPool(m.h.device, o.pool, 0), "vkResetCommandPool");
      VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
      check(vkBeginCommandBuffer(o.cmd, &bi), "vkBeginCommandBuffer");
    }
    vkCmdResetQueryPool(o.cmd, o.queries, 0, 2);
    m.beginPass(o, r, t.rasterize, vertexBuffers, indexBuffer);
    vkCmdWriteTimestamp(o.cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, o.queries, 0);
    for (uint32_t d = 0; d < t.drawsPerFrame; ++d) {
      if (t.rasterize) {
        vkCmdDrawIndexed(o.cmd, static_cast<uint32_t>(r.indices.size()), 1, 0, 0, 0);
      } else {
        VkDeviceSize offset = 0;
        m.bindXfb(o.cmd, 0, 1, &capture->buffer, &offset, &xfbSize);
        m.beginXfb(o.cmd, 0, 0, nullptr, nullptr);
        vkCmdDraw(o.cmd, padded, 1, 0, 0);
        m.endXfb(o.cmd, 0, 0, nullptr, nullptr);
      }
    }
    vkCmdWriteTimestamp(o.cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, o.queries, 1);
    vkCmdEndRenderPass(o.cmd);
    auto t0 = std::chrono::steady_clock::now();
    m.submitAndWait(o);
    out.wallNs.push_back(std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count());
    uint64_t ts[2] = {0, 0};
    check(vkGetQueryPoolResults(m.h.device, o.queries, 0, 2, sizeof(ts), ts, sizeof(uint64_t),
                                VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
          "vkGetQueryPoolResults");
    const uint64_t mask = m.timestampBits >= 64 ? ~uint64_t(0) : ((uint64_t(1) << m.timestampBits) - 1);
    out.frameNs.push_back(double((ts[1] - ts[0]) & mask) * m.props.limits.timestampPeriod);
  }
  return out;
}

}  // namespace sg::rt

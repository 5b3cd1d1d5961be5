#include "runtime/vk_harness.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <set>
#include <stdexcept>

namespace sg::rt {
namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

const char* resultName(VkResult r) {
  switch (r) {
    case VK_SUCCESS: return "VK_SUCCESS";
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

void check(VkResult r, const char* what) {
  if (r != VK_SUCCESS) throw std::runtime_error(fmt::format("vk harness: {} failed: {} ({})", what, resultName(r), static_cast<int>(r)));
}

double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

bool hasDeviceExtension(VkPhysicalDevice pd, const char* name) {
  uint32_t n = 0;
  vkEnumerateDeviceExtensionProperties(pd, nullptr, &n, nullptr);
  std::vector<VkExtensionProperties> exts(n);
  vkEnumerateDeviceExtensionProperties(pd, nullptr, &n, exts.data());
  return std::any_of(exts.begin(), exts.end(), [&](const auto& e) { return std::strcmp(e.extensionName, name) == 0; });
}

// What device selection needs to know about one physical device.
struct DeviceInfo {
  VkPhysicalDevice pd = VK_NULL_HANDLE;
  VkPhysicalDeviceProperties props{};
  VkDriverId driverID{};
  bool xfb = false;
  bool dynamicRendering = false;
  VkPhysicalDeviceTransformFeedbackPropertiesEXT xfbProps{};
};

DeviceInfo describe(VkPhysicalDevice pd) {
  DeviceInfo info;
  info.pd = pd;
  vkGetPhysicalDeviceProperties(pd, &info.props);
  const uint32_t api = info.props.apiVersion;
  const bool hasXfbExt = hasDeviceExtension(pd, VK_EXT_TRANSFORM_FEEDBACK_EXTENSION_NAME);

  // Chain only structs the device knows; the validation layer flags the rest.
  VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
  VkPhysicalDeviceDriverProperties drv{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
  info.xfbProps = {VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_TRANSFORM_FEEDBACK_PROPERTIES_EXT};
  if (api >= VK_API_VERSION_1_2 || hasDeviceExtension(pd, VK_KHR_DRIVER_PROPERTIES_EXTENSION_NAME)) {
    drv.pNext = p2.pNext;
    p2.pNext = &drv;
  }
  if (hasXfbExt) {
    info.xfbProps.pNext = p2.pNext;
    p2.pNext = &info.xfbProps;
  }
  vkGetPhysicalDeviceProperties2(pd, &p2);
  info.xfbProps.pNext = nullptr;
  info.driverID = drv.driverID;

  VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  VkPhysicalDeviceTransformFeedbackFeaturesEXT xfbFeat{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_TRANSFORM_FEEDBACK_FEATURES_EXT};
  VkPhysicalDeviceVulkan13Features v13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  if (hasXfbExt) {
    xfbFeat.pNext = f2.pNext;
    f2.pNext = &xfbFeat;
  }
  if (api >= VK_API_VERSION_1_3) {
    v13.pNext = f2.pNext;
    f2.pNext = &v13;
  }
  vkGetPhysicalDeviceFeatures2(pd, &f2);
  info.xfb = hasXfbExt && xfbFeat.transformFeedback;
  info.dynamicRendering = api >= VK_API_VERSION_1_3 && v13.dynamicRendering;
  return info;
}

}  // namespace

struct Harness::Impl {
  HarnessOptions options;
  bool validation = false;
  std::mutex messagesMutex;  // the layer may call back from any thread
  std::vector<std::string> messages;

  VkInstance instance = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  DeviceInfo dev;
  VkPhysicalDeviceMemoryProperties memProps{};
  VkDevice device = VK_NULL_HANDLE;
  uint32_t queueFamily = 0;
  VkQueue queue = VK_NULL_HANDLE;
  VkCommandPool commandPool = VK_NULL_HANDLE;

  PFN_vkCmdBindTransformFeedbackBuffersEXT cmdBindXfbBuffers = nullptr;
  PFN_vkCmdBeginTransformFeedbackEXT cmdBeginXfb = nullptr;
  PFN_vkCmdEndTransformFeedbackEXT cmdEndXfb = nullptr;

  static VKAPI_ATTR VkBool32 VKAPI_CALL onMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                  VkDebugUtilsMessageTypeFlagsEXT types,
                                                  const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
    auto* self = static_cast<Impl*>(user);
    const char* sev = severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT ? "error" : "warning";
    const char* type = types & VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT    ? "validation"
                       : types & VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT ? "performance"
                                                                                  : "general";
    std::string text = fmt::format("{} {}: {}", type, sev, data && data->pMessage ? data->pMessage : "(no message)");
    std::lock_guard<std::mutex> lock(self->messagesMutex);
    self->messages.push_back(std::move(text));
    return VK_FALSE;  // never abort the call: we want the run to complete and report
  }

  VkDebugUtilsMessengerCreateInfoEXT messengerInfo() {
    VkDebugUtilsMessengerCreateInfoEXT ci{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    ci.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    ci.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                     VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    ci.pfnUserCallback = &onMessage;
    ci.pUserData = this;
    return ci;
  }

  void createInstance() {
    uint32_t loaderVersion = VK_API_VERSION_1_0;
    auto enumerateVersion = reinterpret_cast<PFN_vkEnumerateInstanceVersion>(
        vkGetInstanceProcAddr(VK_NULL_HANDLE, "vkEnumerateInstanceVersion"));
    if (enumerateVersion) enumerateVersion(&loaderVersion);
    if (loaderVersion < VK_API_VERSION_1_1)
      throw std::runtime_error("vk harness: the Vulkan loader is older than 1.1 (vkGetPhysicalDeviceProperties2 is needed)");

    if (options.validation) {
      uint32_t n = 0;
      vkEnumerateInstanceLayerProperties(&n, nullptr);
      std::vector<VkLayerProperties> layers(n);
      vkEnumerateInstanceLayerProperties(&n, layers.data());
      bool haveLayer = std::any_of(layers.begin(), layers.end(),
                                   [](const auto& l) { return std::strcmp(l.layerName, kValidationLayer) == 0; });
      // Without debug utils the messages could not be collected, so "no messages" would mean nothing.
      bool haveDebugUtils = false;
      for (const char* layer : {static_cast<const char*>(nullptr), kValidationLayer}) {
        if (layer && !haveLayer) break;
        uint32_t m = 0;
        vkEnumerateInstanceExtensionProperties(layer, &m, nullptr);
        std::vector<VkExtensionProperties> exts(m);
        vkEnumerateInstanceExtensionProperties(layer, &m, exts.data());
        for (const auto& e : exts) haveDebugUtils |= std::strcmp(e.extensionName, VK_EXT_DEBUG_UTILS_EXTENSION_NAME) == 0;
      }
      validation = haveLayer && haveDebugUtils;
    }

    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = "shadergen";
    app.pEngineName = "shadergen";
    app.apiVersion = std::min(VK_MAKE_API_VERSION(0, VK_API_VERSION_MAJOR(loaderVersion), VK_API_VERSION_MINOR(loaderVersion), 0),
                              VK_API_VERSION_1_3);

    const char* layer = kValidationLayer;
    const char* ext = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
    VkDebugUtilsMessengerCreateInfoEXT mci = messengerInfo();
    VkInstanceCreateInfo ci{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ci.pApplicationInfo = &app;
    if (validation) {
      ci.pNext = &mci;  // also catches messages from vkCreateInstance/vkDestroyInstance
      ci.enabledLayerCount = 1;
      ci.ppEnabledLayerNames = &layer;
      ci.enabledExtensionCount = 1;
      ci.ppEnabledExtensionNames = &ext;
    }
    VkResult r = vkCreateInstance(&ci, nullptr, &instance);
    if (r == VK_ERROR_INCOMPATIBLE_DRIVER)
      throw std::runtime_error("vk harness: no Vulkan driver found (vkCreateInstance: VK_ERROR_INCOMPATIBLE_DRIVER); "
                               "install mesa-vulkan-drivers for lavapipe");
    check(r, "vkCreateInstance");

    if (validation) {
      auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
          vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"));
      if (!create) throw std::runtime_error("vk harness: vkCreateDebugUtilsMessengerEXT is missing");
      check(create(instance, &mci, nullptr, &messenger), "vkCreateDebugUtilsMessengerEXT");
    }
  }

  void pickDevice() {
    uint32_t n = 0;
    check(vkEnumeratePhysicalDevices(instance, &n, nullptr), "vkEnumeratePhysicalDevices");
    std::vector<VkPhysicalDevice> pds(n);
    check(vkEnumeratePhysicalDevices(instance, &n, pds.data()), "vkEnumeratePhysicalDevices");

    std::string available;
    const DeviceInfo* chosen = nullptr;
    const DeviceInfo* matchedWithoutXfb = nullptr;
    std::vector<DeviceInfo> infos;
    for (VkPhysicalDevice pd : pds) infos.push_back(describe(pd));
    for (const DeviceInfo& info : infos) {
      std::string name = info.props.deviceName;
      available += (available.empty() ? "'" : ", '") + name + "'";
      bool match = options.deviceName.empty() ? info.driverID == VK_DRIVER_ID_MESA_LLVMPIPE
                                              : name.find(options.deviceName) != std::string::npos;
      if (!match) continue;
      if (!info.xfb) {
        if (!matchedWithoutXfb) matchedWithoutXfb = &info;
        continue;
      }
      if (!chosen) chosen = &info;
    }
    if (available.empty()) available = "none";
    if (!chosen && matchedWithoutXfb)
      throw std::runtime_error(fmt::format("vk harness: device '{}' does not support transform feedback "
                                           "(VK_EXT_transform_feedback with the transformFeedback feature)",
                                           matchedWithoutXfb->props.deviceName));
    if (!chosen) {
      if (options.deviceName.empty())
        throw std::runtime_error(fmt::format("vk harness: no lavapipe device (VK_DRIVER_ID_MESA_LLVMPIPE) found; "
                                             "available devices: {}. Install mesa-vulkan-drivers or choose a device by name",
                                             available));
      throw std::runtime_error(fmt::format("vk harness: no Vulkan device matching '{}'; available devices: {}",
                                           options.deviceName, available));
    }
    dev = *chosen;
    vkGetPhysicalDeviceMemoryProperties(dev.pd, &memProps);
  }

  void createDevice() {
    uint32_t n = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(dev.pd, &n, nullptr);
    std::vector<VkQueueFamilyProperties> families(n);
    vkGetPhysicalDeviceQueueFamilyProperties(dev.pd, &n, families.data());
    auto it = std::find_if(families.begin(), families.end(),
                           [](const auto& f) { return (f.queueFlags & VK_QUEUE_GRAPHICS_BIT) && f.queueCount > 0; });
    if (it == families.end())
      throw std::runtime_error(fmt::format("vk harness: device '{}' has no graphics queue", dev.props.deviceName));
    queueFamily = static_cast<uint32_t>(it - families.begin());

    float priority = 1.0f;
    VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    qci.queueFamilyIndex = queueFamily;
    qci.queueCount = 1;
    qci.pQueuePriorities = &priority;

    VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
    VkPhysicalDeviceTransformFeedbackFeaturesEXT xfbFeat{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_TRANSFORM_FEEDBACK_FEATURES_EXT};
    VkPhysicalDeviceVulkan13Features v13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
    xfbFeat.transformFeedback = VK_TRUE;
    f2.pNext = &xfbFeat;
    if (dev.dynamicRendering) {
      v13.dynamicRendering = VK_TRUE;
      xfbFeat.pNext = &v13;
    }
    const char* ext = VK_EXT_TRANSFORM_FEEDBACK_EXTENSION_NAME;
    VkDeviceCreateInfo ci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    ci.pNext = &f2;
    ci.queueCreateInfoCount = 1;
    ci.pQueueCreateInfos = &qci;
    ci.enabledExtensionCount = 1;
    ci.ppEnabledExtensionNames = &ext;
    check(vkCreateDevice(dev.pd, &ci, nullptr, &device), "vkCreateDevice");
    vkGetDeviceQueue(device, queueFamily, 0, &queue);

    cmdBindXfbBuffers = reinterpret_cast<PFN_vkCmdBindTransformFeedbackBuffersEXT>(
        vkGetDeviceProcAddr(device, "vkCmdBindTransformFeedbackBuffersEXT"));
    cmdBeginXfb = reinterpret_cast<PFN_vkCmdBeginTransformFeedbackEXT>(vkGetDeviceProcAddr(device, "vkCmdBeginTransformFeedbackEXT"));
    cmdEndXfb = reinterpret_cast<PFN_vkCmdEndTransformFeedbackEXT>(vkGetDeviceProcAddr(device, "vkCmdEndTransformFeedbackEXT"));
    if (!cmdBindXfbBuffers || !cmdBeginXfb || !cmdEndXfb)
      throw std::runtime_error("vk harness: transform feedback entry points are missing");

    VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pci.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
    pci.queueFamilyIndex = queueFamily;
    check(vkCreateCommandPool(device, &pci, nullptr, &commandPool), "vkCreateCommandPool");
  }

  void destroy() {
    if (device) {
      vkDeviceWaitIdle(device);
      if (commandPool) vkDestroyCommandPool(device, commandPool, nullptr);
      vkDestroyDevice(device, nullptr);
    }
    if (messenger) {
      auto destroyMessenger = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
          vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
      if (destroyMessenger) destroyMessenger(instance, messenger, nullptr);
    }
    if (instance) vkDestroyInstance(instance, nullptr);
    commandPool = VK_NULL_HANDLE;
    device = VK_NULL_HANDLE;
    messenger = VK_NULL_HANDLE;
    instance = VK_NULL_HANDLE;
  }

  // Prefers memory with `preferred` flags, falls back to any type with `required`.
  uint32_t memoryType(uint32_t typeBits, VkMemoryPropertyFlags required, VkMemoryPropertyFlags preferred) const {
    for (VkMemoryPropertyFlags want : {required | preferred, required}) {
      for (uint32_t i = 0; i < memProps.memoryTypeCount; ++i)
        if ((typeBits & (1u << i)) && (memProps.memoryTypes[i].propertyFlags & want) == want) return i;
    }
    throw std::runtime_error("vk harness: no suitable memory type");
  }
};

namespace {

// Every per-run object; the destructor releases them even when run() throws.
struct RunObjects {
  struct Buffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    void* mapped = nullptr;
  };
  VkDevice device;
  VkQueue queue;
  VkCommandPool pool;
  std::vector<Buffer> buffers;
  VkShaderModule shader = VK_NULL_HANDLE;
  VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
  VkDescriptorPool descriptorPool = VK_NULL_HANDLE;
  VkPipelineLayout pipelineLayout = VK_NULL_HANDLE;
  VkRenderPass renderPass = VK_NULL_HANDLE;
  VkFramebuffer framebuffer = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
  bool submitted = false;

  RunObjects(VkDevice d, VkQueue q, VkCommandPool p) : device(d), queue(q), pool(p) {}
  RunObjects(const RunObjects&) = delete;
  RunObjects& operator=(const RunObjects&) = delete;
  ~RunObjects() {
    if (submitted) vkQueueWaitIdle(queue);  // never destroy what the device may still use
    if (fence) vkDestroyFence(device, fence, nullptr);
    if (cmd) vkFreeCommandBuffers(device, pool, 1, &cmd);
    if (pipeline) vkDestroyPipeline(device, pipeline, nullptr);
    if (framebuffer) vkDestroyFramebuffer(device, framebuffer, nullptr);
    if (renderPass) vkDestroyRenderPass(device, renderPass, nullptr);
    if (pipelineLayout) vkDestroyPipelineLayout(device, pipelineLayout, nullptr);
    if (descriptorPool) vkDestroyDescriptorPool(device, descriptorPool, nullptr);
    if (setLayout) vkDestroyDescriptorSetLayout(device, setLayout, nullptr);
    if (shader) vkDestroyShaderModule(device, shader, nullptr);
    for (Buffer& b : buffers) {
      if (b.buffer) vkDestroyBuffer(device, b.buffer, nullptr);
      if (b.memory) vkFreeMemory(device, b.memory, nullptr);  // also unmaps
    }
  }
};


// Set 0: the uniform block at binding 0 (if any) and each storage buffer at its binding;
// VK_NULL_HANDLE when the shader reads neither.
VkDescriptorSet createDescriptorSet(VkDevice device, VkDescriptorSetLayout& layout, VkDescriptorPool& pool,
                                    VkBuffer uniform, const std::vector<StorageBufferData>& storageData,
                                    const std::vector<RunObjects::Buffer*>& storage) {
  std::vector<VkDescriptorSetLayoutBinding> bindings;
  std::vector<VkDescriptorPoolSize> sizes;
  if (uniform) {
    bindings.push_back({0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1, VK_SHADER_STAGE_VERTEX_BIT, nullptr});
    sizes.push_back({VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1});
  }
  for (const auto& sb : storageData)
    bindings.push_back({sb.binding, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_VERTEX_BIT, nullptr});
  if (!storageData.empty())
    sizes.push_back({VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, static_cast<uint32_t>(storageData.size())});
  if (bindings.empty()) return VK_NULL_HANDLE;
  VkDescriptorSetLayoutCreateInfo dslci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  dslci.bindingCount = static_cast<uint32_t>(bindings.size());
  dslci.pBindings = bindings.data();
  check(vkCreateDescriptorSetLayout(device, &dslci, nullptr, &layout), "vkCreateDescriptorSetLayout");
  VkDescriptorPoolCreateInfo dpci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  dpci.maxSets = 1;
  dpci.poolSizeCount = static_cast<uint32_t>(sizes.size());
  dpci.pPoolSizes = sizes.data();
  check(vkCreateDescriptorPool(device, &dpci, nullptr, &pool), "vkCreateDescriptorPool");
  VkDescriptorSetAllocateInfo dsai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  dsai.descriptorPool = pool;
  dsai.descriptorSetCount = 1;
  dsai.pSetLayouts = &layout;
  VkDescriptorSet set = VK_NULL_HANDLE;
  check(vkAllocateDescriptorSets(device, &dsai, &set), "vkAllocateDescriptorSets");
  std::vector<VkDescriptorBufferInfo> infos;
  infos.reserve(bindings.size());
  std::vector<VkWriteDescriptorSet> writes;
  auto write = [&](uint32_t binding, VkDescriptorType type, VkBuffer buffer) {
    infos.push_back({buffer, 0, VK_WHOLE_SIZE});
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstSet = set;
    w.dstBinding = binding;
    w.descriptorCount = 1;
    w.descriptorType = type;
    w.pBufferInfo = &infos.back();
    writes.push_back(w);
  };
  if (uniform) write(0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, uniform);
  for (size_t i = 0; i < storageData.size(); ++i)
    write(storageData[i].binding, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, storage[i]->buffer);
  vkUpdateDescriptorSets(device, static_cast<uint32_t>(writes.size()), writes.data(), 0, nullptr);
  return set;
}

}  // namespace

Harness::Harness(const HarnessOptions& options) : impl_(std::make_unique<Impl>()) {
  impl_->options = options;
  try {
    impl_->createInstance();
    impl_->pickDevice();
    impl_->createDevice();
  } catch (...) {
    impl_->destroy();
    throw;
  }
}

Harness::~Harness() {
  size_t before = impl_->messages.size();
  impl_->destroy();
  // Leak reports arrive during destruction, when nobody can ask for them any more.
  for (size_t i = before; i < impl_->messages.size(); ++i) std::fprintf(stderr, "vk harness: %s\n", impl_->messages[i].c_str());
}

const std::vector<std::string>& Harness::validationMessages() const { return impl_->messages; }
std::string Harness::deviceName() const { return impl_->dev.props.deviceName; }
bool Harness::validationEnabled() const { return impl_->validation; }
Harness::Handles Harness::handles() const { return {impl_->dev.pd, impl_->device, impl_->queueFamily, impl_->queue}; }

RunResult Harness::run(const RunRequest& req) {
  Impl& h = *impl_;
  const VkPhysicalDeviceLimits& limits = h.dev.props.limits;
  const uint32_t stride = req.capture.strideBytes;
  // Lines, not points: a point list needs the shader to write gl_PointSize
  // (VUID-VkGraphicsPipelineCreateInfo-Vertex-07722) even with rasterizer discard.
  // Line lists keep vertex order in the capture; an odd count gets one zeroed
  // padding vertex whose record is dropped.
  const uint32_t drawCount = req.vertexCount + (req.vertexCount & 1u);
  const VkDeviceSize captureSize = VkDeviceSize(req.vertexCount) * stride;
  const VkDeviceSize xfbSize = VkDeviceSize(drawCount) * stride;

  // Reject requests that would make the driver read or write out of bounds.
  if (req.spirv.empty() || req.spirv[0] != 0x07230203u)
    throw std::runtime_error("vk harness: the request's SPIR-V is empty or lacks the SPIR-V magic number");
  if (req.vertexCount == 0 || req.vertexCount == UINT32_MAX)  // UINT32_MAX: drawCount would wrap
    throw std::runtime_error(fmt::format("vk harness: vertexCount {} is out of range", req.vertexCount));
  if (stride == 0 || stride % 4 != 0 || stride > h.dev.xfbProps.maxTransformFeedbackBufferDataStride)
    throw std::runtime_error(fmt::format("vk harness: capture stride {} must be a non-zero multiple of 4 and at most {}",
                                         stride, h.dev.xfbProps.maxTransformFeedbackBufferDataStride));
  if (xfbSize > h.dev.xfbProps.maxTransformFeedbackBufferSize)
    throw std::runtime_error(fmt::format("vk harness: capture of {} bytes exceeds the device's transform feedback buffer size {}",
                                         xfbSize, h.dev.xfbProps.maxTransformFeedbackBufferSize));
  if (req.streams.size() > limits.maxVertexInputBindings || req.streams.size() > limits.maxVertexInputAttributes)
    throw std::runtime_error(fmt::format("vk harness: {} streams exceed the device limit of {}", req.streams.size(),
                                         std::min(limits.maxVertexInputBindings, limits.maxVertexInputAttributes)));
  std::set<uint32_t> locations;
  for (const VertexStream& s : req.streams) {
    if (!locations.insert(s.location).second)
      throw std::runtime_error(fmt::format("vk harness: two streams use location {}", s.location));
    if (s.stride == 0 || s.stride > limits.maxVertexInputBindingStride)
      throw std::runtime_error(fmt::format("vk harness: stream at location {} has stride {} (must be 1..{})", s.location,
                                           s.stride, limits.maxVertexInputBindingStride));
    if (s.data.size() < VkDeviceSize(req.vertexCount) * s.stride)
      throw std::runtime_error(fmt::format("vk harness: stream at location {} holds {} bytes, {} vertices x {} bytes needed",
                                           s.location, s.data.size(), req.vertexCount, s.stride));
    VkFormatProperties fp{};
    vkGetPhysicalDeviceFormatProperties(h.dev.pd, s.format, &fp);
    if (!(fp.bufferFeatures & VK_FORMAT_FEATURE_VERTEX_BUFFER_BIT))
      throw std::runtime_error(fmt::format("vk harness: format {} of the stream at location {} is not a vertex format on this device",
                                           static_cast<int>(s.format), s.location));
  }
  if (req.uniformData.size() > limits.maxUniformBufferRange)
    throw std::runtime_error(fmt::format("vk harness: uniform data of {} bytes exceeds maxUniformBufferRange {}",
                                         req.uniformData.size(), limits.maxUniformBufferRange));

  using Clock = std::chrono::steady_clock;
  RunResult result;
  auto t0 = Clock::now();
  RunObjects o(h.device, h.queue, h.commandPool);

  auto makeBuffer = [&](VkDeviceSize size, VkBufferUsageFlags usage, VkMemoryPropertyFlags required,
                        VkMemoryPropertyFlags preferred) -> RunObjects::Buffer& {
    RunObjects::Buffer& b = o.buffers.emplace_back();
    VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    bci.size = size;
    bci.usage = usage;
    bci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    check(vkCreateBuffer(h.device, &bci, nullptr, &b.buffer), "vkCreateBuffer");
    VkMemoryRequirements mr{};
    vkGetBufferMemoryRequirements(h.device, b.buffer, &mr);
    VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    mai.allocationSize = mr.size;
    mai.memoryTypeIndex = h.memoryType(mr.memoryTypeBits, required, preferred);
    check(vkAllocateMemory(h.device, &mai, nullptr, &b.memory), "vkAllocateMemory");
    check(vkBindBufferMemory(h.device, b.buffer, b.memory, 0), "vkBindBufferMemory");
    if (required & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT)
      check(vkMapMemory(h.device, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped), "vkMapMemory");
    return b;
  };
  // Inputs live in mapped coherent memory: vkQueueSubmit makes earlier host writes
  // visible to the device, so no staging copy or upload barrier is needed.
  constexpr VkMemoryPropertyFlags hostCoherent = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;

  // Reserved up front: makeBuffer hands out references into o.buffers.
  o.buffers.reserve(req.streams.size() + req.storageBuffers.size() + 3);
  std::vector<VkBuffer> vertexBuffers;
  for (const VertexStream& s : req.streams)
    vertexBuffers.push_back(makeBuffer(std::max<VkDeviceSize>(s.data.size(), VkDeviceSize(drawCount) * s.stride),
                                       VK_BUFFER_USAGE_VERTEX_BUFFER_BIT, hostCoherent,
                                       VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT).buffer);
  RunObjects::Buffer* uniform = nullptr;
  if (!req.uniformData.empty())
    uniform = &makeBuffer(req.uniformData.size(), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, hostCoherent, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  std::vector<RunObjects::Buffer*> storage;
  for (const StorageBufferData& sb : req.storageBuffers) {
    if (sb.data.empty() || sb.binding == 0 || sb.data.size() > limits.maxStorageBufferRange)
      throw std::runtime_error(fmt::format("vk harness: storage buffer at binding {} has {} bytes (1..{} allowed, "
                                           "binding 0 is the uniform block's)",
                                           sb.binding, sb.data.size(), limits.maxStorageBufferRange));
    storage.push_back(&makeBuffer(sb.data.size(), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, hostCoherent,
                                  VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT));
  }
  RunObjects::Buffer& capture = makeBuffer(
      xfbSize, VK_BUFFER_USAGE_TRANSFORM_FEEDBACK_BUFFER_BIT_EXT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
      0, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  RunObjects::Buffer& readback = makeBuffer(captureSize, VK_BUFFER_USAGE_TRANSFER_DST_BIT, hostCoherent, VK_MEMORY_PROPERTY_HOST_CACHED_BIT);

  // Shader, layouts, descriptors.
  VkShaderModuleCreateInfo smci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  smci.codeSize = req.spirv.size() * sizeof(uint32_t);
  smci.pCode = req.spirv.data();
  check(vkCreateShaderModule(h.device, &smci, nullptr, &o.shader), "vkCreateShaderModule");

  VkDescriptorSet descriptorSet =
      createDescriptorSet(h.device, o.setLayout, o.descriptorPool, uniform ? uniform->buffer : VK_NULL_HANDLE,
                          req.storageBuffers, storage);

  VkPipelineLayoutCreateInfo plci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  plci.setLayoutCount = o.setLayout ? 1 : 0;
  plci.pSetLayouts = &o.setLayout;
  check(vkCreatePipelineLayout(h.device, &plci, nullptr, &o.pipelineLayout), "vkCreatePipelineLayout");

  // Without dynamic rendering, an attachment-less render pass and 1x1 framebuffer.
  if (!h.dev.dynamicRendering) {
    VkSubpassDescription subpass{};
    subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    VkRenderPassCreateInfo rpci{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
    rpci.subpassCount = 1;
    rpci.pSubpasses = &subpass;
    check(vkCreateRenderPass(h.device, &rpci, nullptr, &o.renderPass), "vkCreateRenderPass");
    VkFramebufferCreateInfo fci{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
    fci.renderPass = o.renderPass;
    fci.width = fci.height = fci.layers = 1;
    check(vkCreateFramebuffer(h.device, &fci, nullptr, &o.framebuffer), "vkCreateFramebuffer");
  }

  // Pipeline: vertex stage only, lines, rasterizer discarded (outputs go to transform feedback only).
  VkPipelineShaderStageCreateInfo stage{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  stage.stage = VK_SHADER_STAGE_VERTEX_BIT;
  stage.module = o.shader;
  stage.pName = "main";

  std::vector<VkVertexInputBindingDescription> bindings;
  std::vector<VkVertexInputAttributeDescription> attributes;
  for (uint32_t i = 0; i < req.streams.size(); ++i) {
    bindings.push_back({i, req.streams[i].stride, VK_VERTEX_INPUT_RATE_VERTEX});
    attributes.push_back({req.streams[i].location, i, req.streams[i].format, 0});
  }
  VkPipelineVertexInputStateCreateInfo vi{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
  vi.vertexBindingDescriptionCount = static_cast<uint32_t>(bindings.size());
  vi.pVertexBindingDescriptions = bindings.data();
  vi.vertexAttributeDescriptionCount = static_cast<uint32_t>(attributes.size());
  vi.pVertexAttributeDescriptions = attributes.data();

  VkPipelineInputAssemblyStateCreateInfo ia{VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
  ia.topology = VK_PRIMITIVE_TOPOLOGY_LINE_LIST;  // see drawCount

  // Ignored with rasterizer discard, but given (1x1, 1 sample) in case a driver reads them.
  VkViewport viewport{0, 0, 1, 1, 0, 1};
  VkRect2D scissor{{0, 0}, {1, 1}};
  VkPipelineViewportStateCreateInfo vp{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
  vp.viewportCount = 1;
  vp.pViewports = &viewport;
  vp.scissorCount = 1;
  vp.pScissors = &scissor;
  VkPipelineMultisampleStateCreateInfo ms{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
  ms.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;

  VkPipelineRasterizationStateCreateInfo rs{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
  rs.rasterizerDiscardEnable = VK_TRUE;
  rs.polygonMode = VK_POLYGON_MODE_FILL;
  rs.cullMode = VK_CULL_MODE_NONE;
  rs.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
  rs.lineWidth = 1.0f;

  VkPipelineRenderingCreateInfo rendering{VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO};  // no attachments
  VkGraphicsPipelineCreateInfo gpci{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
  gpci.pNext = h.dev.dynamicRendering ? &rendering : nullptr;
  gpci.stageCount = 1;
  gpci.pStages = &stage;
  gpci.pVertexInputState = &vi;
  gpci.pInputAssemblyState = &ia;
  gpci.pViewportState = &vp;
  gpci.pRasterizationState = &rs;
  gpci.pMultisampleState = &ms;
  gpci.layout = o.pipelineLayout;
  gpci.renderPass = o.renderPass;
  gpci.subpass = 0;
  check(vkCreateGraphicsPipelines(h.device, VK_NULL_HANDLE, 1, &gpci, nullptr, &o.pipeline), "vkCreateGraphicsPipelines");

  // Command buffer.
  VkCommandBufferAllocateInfo cbai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  cbai.commandPool = h.commandPool;
  cbai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cbai.commandBufferCount = 1;
  check(vkAllocateCommandBuffers(h.device, &cbai, &o.cmd), "vkAllocateCommandBuffers");
  VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  check(vkCreateFence(h.device, &fci, nullptr, &o.fence), "vkCreateFence");

  VkCommandBufferBeginInfo cbbi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  cbbi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  check(vkBeginCommandBuffer(o.cmd, &cbbi), "vkBeginCommandBuffer");

  auto barrier = [&](VkBuffer buffer, VkPipelineStageFlags srcStage, VkAccessFlags srcAccess, VkPipelineStageFlags dstStage,
                     VkAccessFlags dstAccess) {
    VkBufferMemoryBarrier b{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER};
    b.srcAccessMask = srcAccess;
    b.dstAccessMask = dstAccess;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.buffer = buffer;
    b.offset = 0;
    b.size = VK_WHOLE_SIZE;
    vkCmdPipelineBarrier(o.cmd, srcStage, dstStage, 0, 0, nullptr, 1, &b, 0, nullptr);
  };

  // Zero the capture first so bytes no output writes (stride padding) are deterministic.
  vkCmdFillBuffer(o.cmd, capture.buffer, 0, VK_WHOLE_SIZE, 0);
  barrier(capture.buffer, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
          VK_PIPELINE_STAGE_TRANSFORM_FEEDBACK_BIT_EXT, VK_ACCESS_TRANSFORM_FEEDBACK_WRITE_BIT_EXT);

  if (h.dev.dynamicRendering) {
    VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
    ri.renderArea = scissor;
    ri.layerCount = 1;
    vkCmdBeginRendering(o.cmd, &ri);
  } else {
    VkRenderPassBeginInfo rpbi{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
    rpbi.renderPass = o.renderPass;
    rpbi.framebuffer = o.framebuffer;
    rpbi.renderArea = scissor;
    vkCmdBeginRenderPass(o.cmd, &rpbi, VK_SUBPASS_CONTENTS_INLINE);
  }
  vkCmdBindPipeline(o.cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, o.pipeline);
  if (descriptorSet)
    vkCmdBindDescriptorSets(o.cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, o.pipelineLayout, 0, 1, &descriptorSet, 0, nullptr);
  if (!vertexBuffers.empty()) {
    std::vector<VkDeviceSize> offsets(vertexBuffers.size(), 0);
    vkCmdBindVertexBuffers(o.cmd, 0, static_cast<uint32_t>(vertexBuffers.size()), vertexBuffers.data(), offsets.data());
  }
  VkDeviceSize xfbOffset = 0;
  h.cmdBindXfbBuffers(o.cmd, 0, 1, &capture.buffer, &xfbOffset, &xfbSize);
  h.cmdBeginXfb(o.cmd, 0, 0, nullptr, nullptr);
  vkCmdDraw(o.cmd, drawCount, 1, 0, 0);
  h.cmdEndXfb(o.cmd, 0, 0, nullptr, nullptr);
  if (h.dev.dynamicRendering)
    vkCmdEndRendering(o.cmd);
  else
    vkCmdEndRenderPass(o.cmd);

  barrier(capture.buffer, VK_PIPELINE_STAGE_TRANSFORM_FEEDBACK_BIT_EXT, VK_ACCESS_TRANSFORM_FEEDBACK_WRITE_BIT_EXT,
          VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
  VkBufferCopy region{0, 0, captureSize};
  vkCmdCopyBuffer(o.cmd, capture.buffer, readback.buffer, 1, &region);
  barrier(readback.buffer, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
          VK_ACCESS_HOST_READ_BIT);
  check(vkEndCommandBuffer(o.cmd), "vkEndCommandBuffer");
  result.timings.setupMs = msSince(t0);

  // Upload.
  t0 = Clock::now();
  for (size_t i = 0; i < req.streams.size(); ++i) {
    const VertexStream& s = req.streams[i];
    std::memcpy(o.buffers[i].mapped, s.data.data(), s.data.size());
    VkDeviceSize padded = VkDeviceSize(drawCount) * s.stride;
    if (padded > s.data.size())  // the padding vertex reads zeros, never garbage
      std::memset(static_cast<uint8_t*>(o.buffers[i].mapped) + s.data.size(), 0, padded - s.data.size());
  }
  if (uniform) std::memcpy(uniform->mapped, req.uniformData.data(), req.uniformData.size());
  for (size_t i = 0; i < storage.size(); ++i)
    std::memcpy(storage[i]->mapped, req.storageBuffers[i].data.data(), req.storageBuffers[i].data.size());
  result.timings.uploadMs = msSince(t0);

  // Run.
  t0 = Clock::now();
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &o.cmd;
  check(vkQueueSubmit(h.queue, 1, &si, o.fence), "vkQueueSubmit");
  o.submitted = true;
  check(vkWaitForFences(h.device, 1, &o.fence, VK_TRUE, UINT64_MAX), "vkWaitForFences");
  o.submitted = false;
  result.timings.runMs = msSince(t0);

  // Readback (coherent memory: the HOST_READ barrier above is all the visibility needed).
  t0 = Clock::now();
  const auto* bytes = static_cast<const uint8_t*>(readback.mapped);
  result.captured.assign(bytes, bytes + captureSize);
  result.timings.readbackMs = msSince(t0);
  return result;
}

}  // namespace sg::rt

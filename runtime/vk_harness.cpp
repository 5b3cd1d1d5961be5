#include "runtime/vk_harness.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <stdexcept>

#include "runtime/vk_setup.h"

namespace sg::rt {
namespace {

using setup::check;

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

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
  std::string driver;  // "<driver name> <driver info>", or the driver version number
  bool xfb = false;
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
  const bool driverProps = api >= VK_API_VERSION_1_2 || hasDeviceExtension(pd, VK_KHR_DRIVER_PROPERTIES_EXTENSION_NAME);
  if (driverProps) {
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
  info.driver = driverProps ? fmt::format("{} {}", drv.driverName, drv.driverInfo)
                    : fmt::format("driver version {:#x}", info.props.driverVersion);

  VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  VkPhysicalDeviceTransformFeedbackFeaturesEXT xfbFeat{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_TRANSFORM_FEEDBACK_FEATURES_EXT};
  if (hasXfbExt) f2.pNext = &xfbFeat;
  vkGetPhysicalDeviceFeatures2(pd, &f2);
  info.xfb = hasXfbExt && xfbFeat.transformFeedback;
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
  VkDevice device = VK_NULL_HANDLE;
  uint32_t queueFamily = 0;
  VkQueue queue = VK_NULL_HANDLE;
  bool memoryBudget = false;  // VK_EXT_memory_budget enabled
  bool executableStatistics = false;  // VK_KHR_pipeline_executable_properties enabled
  std::unique_ptr<setup::Device> setup;  // what program set-up needs (vk_setup.h)

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
      // "lavapipe" is the Mesa driver's name, not its device's ("llvmpipe (LLVM ...)").
      const bool lavapipe = options.deviceName.empty() || options.deviceName == "lavapipe";
      bool match = lavapipe ? info.driverID == VK_DRIVER_ID_MESA_LLVMPIPE
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
    xfbFeat.transformFeedback = VK_TRUE;
    f2.pNext = &xfbFeat;
    // Where the device has it (setup::Device reads the same feature back): bench's count of
    // what one draw shaded (rt::Renderer::statistics).
    VkPhysicalDeviceFeatures supported{};
    vkGetPhysicalDeviceFeatures(dev.pd, &supported);
    f2.features.pipelineStatisticsQuery = supported.pipelineStatisticsQuery;
    // Where the device has it, the memory budget: timings say what the process holds in the
    // heap their inputs are in (docs/device-profiles.md, "Where the inputs live").
    std::vector<const char*> exts{VK_EXT_TRANSFORM_FEEDBACK_EXTENSION_NAME};
    memoryBudget = hasDeviceExtension(dev.pd, VK_EXT_MEMORY_BUDGET_EXTENSION_NAME);
    if (memoryBudget) exts.push_back(VK_EXT_MEMORY_BUDGET_EXTENSION_NAME);
    // Where the device has it, the compiler's statistics of each timed program (bench's
    // "driver statistics"). Capturing them must not change the compiled pipeline (the
    // extension's VK_PIPELINE_CREATE_CAPTURE_STATISTICS_BIT_KHR), so timings stay comparable.
    VkPhysicalDevicePipelineExecutablePropertiesFeaturesKHR execFeat{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_EXECUTABLE_PROPERTIES_FEATURES_KHR};
    if (hasDeviceExtension(dev.pd, VK_KHR_PIPELINE_EXECUTABLE_PROPERTIES_EXTENSION_NAME)) {
      VkPhysicalDeviceFeatures2 query{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
      query.pNext = &execFeat;
      vkGetPhysicalDeviceFeatures2(dev.pd, &query);
      execFeat.pNext = nullptr;
      executableStatistics = execFeat.pipelineExecutableInfo == VK_TRUE;
      if (executableStatistics) {
        exts.push_back(VK_KHR_PIPELINE_EXECUTABLE_PROPERTIES_EXTENSION_NAME);
        xfbFeat.pNext = &execFeat;
      }
    }
    VkDeviceCreateInfo ci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    ci.pNext = &f2;
    ci.queueCreateInfoCount = 1;
    ci.pQueueCreateInfos = &qci;
    ci.enabledExtensionCount = static_cast<uint32_t>(exts.size());
    ci.ppEnabledExtensionNames = exts.data();
    check(vkCreateDevice(dev.pd, &ci, nullptr, &device), "vkCreateDevice");
    vkGetDeviceQueue(device, queueFamily, 0, &queue);

    setup = std::make_unique<setup::Device>(Harness::Handles{dev.pd, device, queueFamily, queue, memoryBudget, executableStatistics});
  }

  void destroy() {
    if (device) {
      vkDeviceWaitIdle(device);
      vkDestroyDevice(device, nullptr);
    }
    if (messenger) {
      auto destroyMessenger = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
          vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
      if (destroyMessenger) destroyMessenger(instance, messenger, nullptr);
    }
    if (instance) vkDestroyInstance(instance, nullptr);
    setup.reset();
    device = VK_NULL_HANDLE;
    messenger = VK_NULL_HANDLE;
    instance = VK_NULL_HANDLE;
  }

};

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
std::string Harness::driver() const { return impl_->dev.driver; }
bool Harness::validationEnabled() const { return impl_->validation; }
const VkPhysicalDeviceLimits& Harness::limits() const { return impl_->dev.props.limits; }
uint32_t Harness::maxCaptureBytes() const {
  const auto& x = impl_->dev.xfbProps;
  return std::min({x.maxTransformFeedbackBufferDataStride, x.maxTransformFeedbackBufferDataSize, x.maxTransformFeedbackStreamDataSize});
}
Harness::Handles Harness::handles() const {
  return {impl_->dev.pd, impl_->device, impl_->queueFamily, impl_->queue, impl_->memoryBudget, impl_->executableStatistics};
}

RunResult Harness::run(const RunRequest& req) {
  Impl& h = *impl_;
  const uint32_t stride = req.capture.strideBytes;
  const VkDeviceSize captureSize = VkDeviceSize(req.vertexCount) * stride;
  const VkDeviceSize xfbSize = VkDeviceSize(req.vertexCount + (req.vertexCount & 1u)) * stride;
  if (stride == 0 || stride % 4 != 0 || stride > maxCaptureBytes())
    throw std::runtime_error(fmt::format("vk harness: capture stride {} must be a non-zero multiple of 4 and at most {} "
                                         "(the device's transform-feedback limits)",
                                         stride, maxCaptureBytes()));
  if (xfbSize > h.dev.xfbProps.maxTransformFeedbackBufferSize)
    throw std::runtime_error(fmt::format("vk harness: capture of {} bytes exceeds the device's transform feedback buffer size {}",
                                         xfbSize, h.dev.xfbProps.maxTransformFeedbackBufferSize));

  using Clock = std::chrono::steady_clock;
  RunResult result;
  auto t0 = Clock::now();
  setup::PassDesc pass;
  pass.vertexSpirv = &req.spirv;
  setup::ProgramObjects o(*h.setup, req, pass);  // checks the request, every declared descriptor fed
  result.timings.setupMs = msSince(t0);

  t0 = Clock::now();
  o.upload();  // device-local inputs: their staging copies come first in the command buffer
  result.timings.uploadMs = msSince(t0);

  t0 = Clock::now();
  setup::Buffer& capture = o.buffer(xfbSize, VK_BUFFER_USAGE_TRANSFORM_FEEDBACK_BUFFER_BIT_EXT |
                                                 VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                    setup::Memory::Device);
  setup::Buffer& readback = o.buffer(captureSize, VK_BUFFER_USAGE_TRANSFER_DST_BIT, setup::Memory::Readback);
  auto barrier = [&](VkBuffer buffer, VkPipelineStageFlags srcStage, VkAccessFlags srcAccess, VkPipelineStageFlags dstStage,
                     VkAccessFlags dstAccess) {
    VkBufferMemoryBarrier b{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER};
    b.srcAccessMask = srcAccess;
    b.dstAccessMask = dstAccess;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.buffer = buffer;
    b.offset = 0;
    b.size = VK_WHOLE_SIZE;
    vkCmdPipelineBarrier(o.cmd(), srcStage, dstStage, 0, 0, nullptr, 1, &b, 0, nullptr);
  };
  // Zero the capture first so bytes no output writes (stride padding) are deterministic.
  vkCmdFillBuffer(o.cmd(), capture.buffer, 0, VK_WHOLE_SIZE, 0);
  barrier(capture.buffer, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
          VK_PIPELINE_STAGE_TRANSFORM_FEEDBACK_BIT_EXT, VK_ACCESS_TRANSFORM_FEEDBACK_WRITE_BIT_EXT);
  o.beginPass();
  o.drawCapture(capture.buffer, xfbSize);
  o.endPass();
  barrier(capture.buffer, VK_PIPELINE_STAGE_TRANSFORM_FEEDBACK_BIT_EXT, VK_ACCESS_TRANSFORM_FEEDBACK_WRITE_BIT_EXT,
          VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
  VkBufferCopy region{0, 0, captureSize};
  vkCmdCopyBuffer(o.cmd(), capture.buffer, readback.buffer, 1, &region);
  barrier(readback.buffer, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
          VK_ACCESS_HOST_READ_BIT);
  result.timings.setupMs += msSince(t0);

  t0 = Clock::now();
  o.submitAndWait();
  result.timings.runMs = msSince(t0);

  // Readback (coherent memory: the HOST_READ barrier above is all the visibility needed).
  t0 = Clock::now();
  const auto* bytes = static_cast<const uint8_t*>(readback.mapped);
  result.captured.assign(bytes, bytes + captureSize);
  result.timings.readbackMs = msSince(t0);
  return result;
}

}  // namespace sg::rt

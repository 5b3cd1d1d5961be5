#include "runtime/vk_render.h"

#include <fmt/format.h>

#include <time.h>

#include <chrono>
#include <stdexcept>

#include "runtime/vk_setup.h"

namespace sg::rt {

using setup::check;

struct Renderer::Impl {
  setup::Device device;
  std::string driver;
  Impl(const Harness::Handles& h, std::string drv) : device(h), driver(std::move(drv)) {}
};

Renderer::Renderer(const Harness& harness) : impl_(std::make_unique<Impl>(harness.handles(), harness.driver())) {}

Renderer::~Renderer() = default;

std::string Renderer::driver() const { return impl_->driver; }

namespace {

double processCpuNs() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) * 1e9 + double(t.tv_nsec);
}

setup::PassDesc passOf(const DrawRequest& r, bool rasterize) {
  setup::PassDesc p;
  p.vertexSpirv = &r.vertexSpirv;
  p.fragmentSpirv = rasterize ? &r.fragmentSpirv : nullptr;
  p.indices = &r.indices;
  p.width = r.width;
  p.height = r.height;
  p.clearColor = r.clearColor;
  return p;
}

}  // namespace

Image Renderer::draw(const DrawRequest& r) {
  setup::ProgramObjects o(impl_->device, r, passOf(r, true));
  o.upload();
  o.beginPass();
  o.drawIndexed();
  o.endPass();

  const VkDeviceSize pixels = VkDeviceSize(r.width) * r.height;
  setup::Buffer& colorOut = o.buffer(pixels * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, setup::Memory::Readback);
  setup::Buffer& depthOut = o.buffer(pixels * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, setup::Memory::Readback);
  VkBufferImageCopy copy{};
  copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  copy.imageExtent = {r.width, r.height, 1};
  vkCmdCopyImageToBuffer(o.cmd(), o.color()->image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, colorOut.buffer, 1, &copy);
  copy.imageSubresource.aspectMask = VK_IMAGE_ASPECT_DEPTH_BIT;
  vkCmdCopyImageToBuffer(o.cmd(), o.depth()->image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, depthOut.buffer, 1, &copy);
  VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  mb.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  mb.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(o.cmd(), VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &mb, 0, nullptr, 0, nullptr);
  o.submitAndWait();

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
  const setup::Device& dev = impl_->device;
  if (dev.timestampBits == 0) throw std::runtime_error("vk render: the queue family has no timestamps (timestampValidBits = 0)");
  if (t.drawsPerFrame == 0 || t.frames == 0) throw std::runtime_error("vk render: drawsPerFrame and frames must be > 0");
  const VkDeviceSize xfbSize = VkDeviceSize(r.vertexCount + (r.vertexCount & 1u)) * t.captureStride;
  if (!t.rasterize && (t.captureStride == 0 || t.captureStride % 4 != 0 || xfbSize > dev.xfbProps.maxTransformFeedbackBufferSize))
    throw std::runtime_error(fmt::format("vk render: capture stride {} is invalid for this device", t.captureStride));

  VkQueryPool queries = VK_NULL_HANDLE;
  VkQueryPoolCreateInfo qci{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  qci.queryType = VK_QUERY_TYPE_TIMESTAMP;
  qci.queryCount = 2;
  check(vkCreateQueryPool(dev.h.device, &qci, nullptr, &queries), "vkCreateQueryPool");
  struct PoolGuard {  // outlives `o`, whose destructor waits for the device after a failed submit
    VkDevice d;
    VkQueryPool q;
    ~PoolGuard() { vkDestroyQueryPool(d, q, nullptr); }
  } guard{dev.h.device, queries};
  setup::ProgramObjects o(dev, r, passOf(r, t.rasterize));
  o.upload();
  setup::Buffer* capture = nullptr;
  if (!t.rasterize) capture = &o.buffer(xfbSize, VK_BUFFER_USAGE_TRANSFORM_FEEDBACK_BUFFER_BIT_EXT, setup::Memory::Device);

  // One command buffer per frame: the texture uploads in the first, then only draws.
  Timing out;
  out.verticesPerDraw = r.vertexCount;
  out.inputMemory = o.inputMemory();
  out.vertexStatistics = o.vertexStatistics();
  for (uint32_t f = 0; f < t.frames; ++f) {
    if (f > 0) o.restart();
    vkCmdResetQueryPool(o.cmd(), queries, 0, 2);
    o.beginPass();
    vkCmdWriteTimestamp(o.cmd(), VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, queries, 0);
    for (uint32_t d = 0; d < t.drawsPerFrame; ++d) {
      if (t.rasterize)
        o.drawIndexed();
      else
        o.drawCapture(capture->buffer, xfbSize);
    }
    vkCmdWriteTimestamp(o.cmd(), VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queries, 1);
    o.endPass();
    auto t0 = std::chrono::steady_clock::now();
    const double cpu0 = processCpuNs();
    o.submitAndWait();
    out.wallNs.push_back(std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count());
    out.cpuNs.push_back(processCpuNs() - cpu0);
    uint64_t ts[2] = {0, 0};
    check(vkGetQueryPoolResults(dev.h.device, queries, 0, 2, sizeof(ts), ts, sizeof(uint64_t),
                                VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
          "vkGetQueryPoolResults");
    const uint64_t mask = dev.timestampBits >= 64 ? ~uint64_t(0) : ((uint64_t(1) << dev.timestampBits) - 1);
    out.frameNs.push_back(double((ts[1] - ts[0]) & mask) * dev.props.limits.timestampPeriod);
  }
  return out;
}

std::optional<DrawStatistics> Renderer::statistics(const DrawRequest& r) {
  const setup::Device& dev = impl_->device;
  if (!dev.pipelineStatistics) return std::nullopt;
  VkQueryPool query = VK_NULL_HANDLE;
  VkQueryPoolCreateInfo qci{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  qci.queryType = VK_QUERY_TYPE_PIPELINE_STATISTICS;
  qci.queryCount = 1;
  // Results come back in the order of the bits: vertex shader, then fragment shader.
  qci.pipelineStatistics =
      VK_QUERY_PIPELINE_STATISTIC_VERTEX_SHADER_INVOCATIONS_BIT | VK_QUERY_PIPELINE_STATISTIC_FRAGMENT_SHADER_INVOCATIONS_BIT;
  check(vkCreateQueryPool(dev.h.device, &qci, nullptr, &query), "vkCreateQueryPool");
  struct PoolGuard {
    VkDevice d;
    VkQueryPool q;
    ~PoolGuard() { vkDestroyQueryPool(d, q, nullptr); }
  } guard{dev.h.device, query};
  setup::ProgramObjects o(dev, r, passOf(r, true));
  o.upload();
  vkCmdResetQueryPool(o.cmd(), query, 0, 1);
  o.beginPass();
  vkCmdBeginQuery(o.cmd(), query, 0, 0);
  o.drawIndexed();
  vkCmdEndQuery(o.cmd(), query, 0);
  o.endPass();
  o.submitAndWait();
  uint64_t v[2] = {0, 0};
  check(vkGetQueryPoolResults(dev.h.device, query, 0, 1, sizeof(v), v, sizeof(v), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
        "vkGetQueryPoolResults");
  return DrawStatistics{v[0], v[1]};
}

}  // namespace sg::rt

#include "rig/vertex_format.h"

#include <glm/gtc/packing.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

namespace sg {
namespace {

using Kind = FormatKind;

struct FormatInfo {
  VertexFormat format;
  const char* name;
  int components;
  int bytes;
  Kind kind;
  std::array<int, 4> bits;  // per component
  VulkanFormat vulkan;
};
constexpr std::array<FormatInfo, kVertexFormatCount> kFormats{{
    {VertexFormat::Float32x1, "float32", 1, 4, Kind::Float32, {32, 0, 0, 0}, {"VK_FORMAT_R32_SFLOAT", 100}},
    {VertexFormat::Float32x2, "float32x2", 2, 8, Kind::Float32, {32, 32, 0, 0}, {"VK_FORMAT_R32G32_SFLOAT", 103}},
    {VertexFormat::Float32x3, "float32x3", 3, 12, Kind::Float32, {32, 32, 32, 0}, {"VK_FORMAT_R32G32B32_SFLOAT", 106}},
    {VertexFormat::Float32x4, "float32x4", 4, 16, Kind::Float32, {32, 32, 32, 32}, {"VK_FORMAT_R32G32B32A32_SFLOAT", 109}},
    {VertexFormat::Unorm8x4, "unorm8x4", 4, 4, Kind::Unorm, {8, 8, 8, 8}, {"VK_FORMAT_R8G8B8A8_UNORM", 37}},
    {VertexFormat::Uint8x4, "uint8x4", 4, 4, Kind::Uint, {8, 8, 8, 8}, {"VK_FORMAT_R8G8B8A8_UINT", 41}},
    {VertexFormat::Unorm16x4, "unorm16x4", 4, 8, Kind::Unorm, {16, 16, 16, 16}, {"VK_FORMAT_R16G16B16A16_UNORM", 91}},
    {VertexFormat::Uint16x4, "uint16x4", 4, 8, Kind::Uint, {16, 16, 16, 16}, {"VK_FORMAT_R16G16B16A16_UINT", 95}},
    {VertexFormat::Uint32x4, "uint32x4", 4, 16, Kind::Uint, {32, 32, 32, 32}, {"VK_FORMAT_R32G32B32A32_UINT", 107}},
    {VertexFormat::Float16x2, "float16x2", 2, 4, Kind::Float16, {16, 16, 0, 0}, {"VK_FORMAT_R16G16_SFLOAT", 83}},
    {VertexFormat::Float16x4, "float16x4", 4, 8, Kind::Float16, {16, 16, 16, 16}, {"VK_FORMAT_R16G16B16A16_SFLOAT", 97}},
    {VertexFormat::Snorm8x2, "snorm8x2", 2, 2, Kind::Snorm, {8, 8, 0, 0}, {"VK_FORMAT_R8G8_SNORM", 17}},
    {VertexFormat::Snorm8x4, "snorm8x4", 4, 4, Kind::Snorm, {8, 8, 8, 8}, {"VK_FORMAT_R8G8B8A8_SNORM", 38}},
    {VertexFormat::Snorm16x2, "snorm16x2", 2, 4, Kind::Snorm, {16, 16, 0, 0}, {"VK_FORMAT_R16G16_SNORM", 78}},
    {VertexFormat::Snorm16x4, "snorm16x4", 4, 8, Kind::Snorm, {16, 16, 16, 16}, {"VK_FORMAT_R16G16B16A16_SNORM", 92}},
    {VertexFormat::Unorm8x2, "unorm8x2", 2, 2, Kind::Unorm, {8, 8, 0, 0}, {"VK_FORMAT_R8G8_UNORM", 16}},
    {VertexFormat::Unorm16x2, "unorm16x2", 2, 4, Kind::Unorm, {16, 16, 0, 0}, {"VK_FORMAT_R16G16_UNORM", 77}},
    {VertexFormat::Unorm10_10_10_2, "unorm10-10-10-2", 4, 4, Kind::Unorm, {10, 10, 10, 2}, {"VK_FORMAT_A2B10G10R10_UNORM_PACK32", 64}},
    {VertexFormat::Snorm10_10_10_2, "snorm10-10-10-2", 4, 4, Kind::Snorm, {10, 10, 10, 2}, {"VK_FORMAT_A2B10G10R10_SNORM_PACK32", 65}},
    {VertexFormat::Uint8x2, "uint8x2", 2, 2, Kind::Uint, {8, 8, 0, 0}, {"VK_FORMAT_R8G8_UINT", 20}},
    {VertexFormat::Uint16x2, "uint16x2", 2, 4, Kind::Uint, {16, 16, 0, 0}, {"VK_FORMAT_R16G16_UINT", 81}},
    {VertexFormat::Uint32x1, "uint32", 1, 4, Kind::Uint, {32, 0, 0, 0}, {"VK_FORMAT_R32_UINT", 98}},
    {VertexFormat::Uint32x2, "uint32x2", 2, 8, Kind::Uint, {32, 32, 0, 0}, {"VK_FORMAT_R32G32_UINT", 101}},
}};
const FormatInfo& info(VertexFormat f) { return kFormats[static_cast<size_t>(f)]; }
static_assert([] {
  for (size_t i = 0; i < kFormats.size(); ++i)
    if (static_cast<size_t>(kFormats[i].format) != i) return false;
  return true;
}(), "kFormats is in enum order");

// The stored integer of a fixed-point or integer component (two's complement for snorm).
int64_t storedInteger(Kind kind, int bits, float v) {
  if (std::isnan(v)) return 0;
  const double x = v;
  switch (kind) {
    case Kind::Unorm: {
      const double top = std::ldexp(1.0, bits) - 1;
      return std::llround(std::clamp(x, 0.0, 1.0) * top);
    }
    case Kind::Snorm: {
      const double top = std::ldexp(1.0, bits - 1) - 1;
      return std::llround(std::clamp(x, -1.0, 1.0) * top);
    }
    case Kind::Uint: return std::llround(std::clamp(x, 0.0, std::ldexp(1.0, bits) - 1));
    default: return 0;
  }
}

}  // namespace

const char* formatName(VertexFormat f) { return info(f).name; }
int formatComponents(VertexFormat f) { return info(f).components; }
int formatBytes(VertexFormat f) { return info(f).bytes; }
bool formatIsInteger(VertexFormat f) { return info(f).kind == Kind::Uint; }
bool formatIsFloat32(VertexFormat f) { return info(f).kind == Kind::Float32; }
VulkanFormat vulkanFormat(VertexFormat f) { return info(f).vulkan; }
FormatKind formatKind(VertexFormat f) { return info(f).kind; }
int formatComponentBits(VertexFormat f, int c) { return info(f).bits[static_cast<size_t>(c)]; }
bool parseFormat(const std::string& name, VertexFormat& out) {
  for (const auto& i : kFormats)
    if (name == i.name) {
      out = i.format;
      return true;
    }
  return false;
}
std::string formatNames() {
  std::string all;
  for (const auto& f : kFormats) all += (all.empty() ? "" : ", ") + std::string(f.name);
  return all;
}

float storedValue(VertexFormat f, int c, float v) {
  const FormatInfo& i = info(f);
  const int bits = i.bits[static_cast<size_t>(c)];
  switch (i.kind) {
    case Kind::Float32: return v;
    case Kind::Float16: return glm::unpackHalf1x16(glm::packHalf1x16(v));
    case Kind::Unorm:
      return static_cast<float>(static_cast<double>(storedInteger(i.kind, bits, v)) / (std::ldexp(1.0, bits) - 1));
    case Kind::Snorm: {
      const double q = static_cast<double>(storedInteger(i.kind, bits, v)) / (std::ldexp(1.0, bits - 1) - 1);
      return static_cast<float>(std::max(q, -1.0));
    }
    case Kind::Uint: return static_cast<float>(storedInteger(i.kind, bits, v));
  }
  return v;
}

double storedValueMaxError(VertexFormat f, int c, double v) {
  const FormatInfo& i = info(f);
  const int bits = i.bits[static_cast<size_t>(c)];
  switch (i.kind) {
    case Kind::Float16: return std::abs(v) <= 65504 ? std::max(std::ldexp(std::abs(v), -11), std::ldexp(1.0, -25)) : INFINITY;
    case Kind::Unorm: return 0.5 / (std::ldexp(1.0, bits) - 1) + std::ldexp(1.0, -24);
    case Kind::Snorm: return 0.5 / (std::ldexp(1.0, bits - 1) - 1) + std::ldexp(1.0, -24);
    case Kind::Float32: case Kind::Uint: return 0;
  }
  return 0;
}

void encodeElement(VertexFormat f, const float* components, uint8_t* dst) {
  const FormatInfo& i = info(f);
  if (f == VertexFormat::Unorm10_10_10_2 || f == VertexFormat::Snorm10_10_10_2) {
    // One little-endian 32-bit word: x in bits 0-9, y 10-19, z 20-29, w 30-31.
    uint32_t word = 0;
    for (int c = 0, shift = 0; c < 4; shift += i.bits[static_cast<size_t>(c)], ++c) {
      const int bits = i.bits[static_cast<size_t>(c)];
      const auto q = static_cast<uint32_t>(storedInteger(i.kind, bits, components[c]));
      word |= (q & ((1u << bits) - 1u)) << shift;
    }
    std::memcpy(dst, &word, 4);
    return;
  }
  for (int c = 0; c < i.components; ++c) {
    const int bits = i.bits[static_cast<size_t>(c)];
    auto put = [&](auto x) { std::memcpy(dst + static_cast<size_t>(c) * sizeof(x), &x, sizeof(x)); };
    switch (i.kind) {
      case Kind::Float32: put(components[c]); break;
      case Kind::Float16: put(static_cast<uint16_t>(glm::packHalf1x16(components[c]))); break;
      default: {
        const int64_t q = storedInteger(i.kind, bits, components[c]);
        if (bits == 8) put(static_cast<uint8_t>(q & 0xff));
        else if (bits == 16) put(static_cast<uint16_t>(q & 0xffff));
        else put(static_cast<uint32_t>(q & 0xffffffff));
      }
    }
  }
}

}  // namespace sg

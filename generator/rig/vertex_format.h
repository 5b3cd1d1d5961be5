// Vertex formats: how the application stores one attribute of a vertex (each maps 1:1 to a
// VkFormat; names are WebGPU's GPUVertexFormat names where it has one), and the exact
// value the device reads back from what is stored (Vulkan spec, "Fixed-Point Data
// Conversions" and "16-Bit Floating-Point Numbers"). Validation feeds the reference these
// read-back values, so a quantized input is checked as the GPU sees it.
#pragma once
#include <cstdint>
#include <string>

namespace sg {

enum class VertexFormat {
  Float32x1, Float32x2, Float32x3, Float32x4,
  Unorm8x4, Uint8x4, Unorm16x4, Uint16x4, Uint32x4,
  Float16x2, Float16x4,
  Snorm8x2, Snorm8x4, Snorm16x2, Snorm16x4,
  Unorm8x2, Unorm16x2,
  Unorm10_10_10_2, Snorm10_10_10_2,  // x, y, z in 10 bits, w in 2 (A2B10G10R10_*_PACK32)
  Uint8x2, Uint16x2,
  Uint32x1, Uint32x2,
};
constexpr int kVertexFormatCount = 23;

const char* formatName(VertexFormat f);  // "float32x3", "unorm8x4", "unorm10-10-10-2", ...
bool parseFormat(const std::string& name, VertexFormat& out);
// Every format's name, in enum order, comma-separated (for "expected one of" messages).
std::string formatNames();
int formatComponents(VertexFormat f);
int formatBytes(VertexFormat f);       // bytes per vertex (the stride of a stream of it)
bool formatIsInteger(VertexFormat f);  // read as uint in the shader (uint8/16/32)
bool formatIsFloat32(VertexFormat f);  // stored exactly: nothing to quantize
// The conversion the device applies to a component, and the component's bits (10-10-10-2:
// 10, 10, 10, 2), for the shader that unpacks a field of a bit-packed attribute itself.
enum class FormatKind { Float32, Float16, Unorm, Snorm, Uint };
FormatKind formatKind(VertexFormat f);
int formatComponentBits(VertexFormat f, int c);
// The VkFormat a format is read as: its name and enum value (so that the reflection and
// the C header can name it without a Vulkan header; the runtime casts the value).
struct VulkanFormat {
  const char* name;  // "VK_FORMAT_R16G16B16A16_UNORM"
  uint32_t value;    // 91
};
VulkanFormat vulkanFormat(VertexFormat f);

// The value the device reads for component `c` of an element whose value is v.
// Error bounds, for v inside the format's range: unorm b bits |e| <= 0.5 / (2^b - 1) on
// [0, 1]; snorm b bits |e| <= 0.5 / (2^(b-1) - 1) on [-1, 1] (outside the range, clamped);
// float16 (GLM) nearest, ties away from 0: |e| <= 2^-11 |v| on [2^-14, 65504], above: inf;
// uint: rounded and clamped to the type. NaN is stored as 0 by the fixed-point formats.
float storedValue(VertexFormat f, int c, float v);
// Those bounds as a number: how far storedValue(f, c, v) may be from v, for v inside the
// format's range (fixed point: half a step plus the float rounding of the read-back, 2^-24;
// float16: 2^-11 |v|, at least half its smallest step, 2^-25; float32 and the integer
// formats, which hold integers exactly: 0). Outside the range it is still the in-range
// bound: a value the format cannot hold is the data's error, not rounding.
double storedValueMaxError(VertexFormat f, int c, double v);
// Writes one element of `f` (formatBytes(f) bytes, little-endian) from its components.
void encodeElement(VertexFormat f, const float* components, uint8_t* dst);

}  // namespace sg

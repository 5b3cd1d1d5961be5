// glTF accessor decoding (gltf_accessor.h).
#include "rig/gltf_accessor.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>

#include "common/diagnostics.h"
#include "rig/gltf_import.h"

namespace sg::gltf {

std::string lower(std::string s) {
  for (auto& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

[[noreturn]] void fail(const std::string& file, const std::string& msg) { throw InputError(SourceLoc{file, 0, 0}, msg); }

const char* componentTypeName(int ct) {
  switch (ct) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: return "byte";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return "unsigned byte";
    case TINYGLTF_COMPONENT_TYPE_SHORT: return "short";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return "unsigned short";
    case TINYGLTF_COMPONENT_TYPE_INT: return "int";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return "unsigned int";
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return "float";
    case TINYGLTF_COMPONENT_TYPE_DOUBLE: return "double";
  }
  return "unknown";
}

const char* typeName(int t) {
  switch (t) {
    case TINYGLTF_TYPE_SCALAR: return "SCALAR";
    case TINYGLTF_TYPE_VEC2: return "VEC2";
    case TINYGLTF_TYPE_VEC3: return "VEC3";
    case TINYGLTF_TYPE_VEC4: return "VEC4";
    case TINYGLTF_TYPE_MAT2: return "MAT2";
    case TINYGLTF_TYPE_MAT3: return "MAT3";
    case TINYGLTF_TYPE_MAT4: return "MAT4";
  }
  return "unknown";
}

// One component as the GPU reads it: integers as their value, normalized integers converted
// with the Vulkan/glTF rules (unorm c / (2^b − 1), snorm max(c / (2^(b−1) − 1), −1)).
float readComponent(const unsigned char* p, int ct, bool normalized) {
  switch (ct) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
      float f;
      std::memcpy(&f, p, 4);
      return f;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
      uint8_t v = *p;
      return normalized ? static_cast<float>(v) / 255.0f : static_cast<float>(v);
    }
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      int8_t v;
      std::memcpy(&v, p, 1);
      return normalized ? std::max(static_cast<float>(v) / 127.0f, -1.0f) : static_cast<float>(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? static_cast<float>(v) / 65535.0f : static_cast<float>(v);
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      int16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? std::max(static_cast<float>(v) / 32767.0f, -1.0f) : static_cast<float>(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      uint32_t v;
      std::memcpy(&v, p, 4);
      return static_cast<float>(v);
    }
  }
  return 0.0f;
}

uint32_t readIndex(const unsigned char* p, int ct) {
  switch (ct) {
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return *p;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return v;
    }
    default: {
      uint32_t v;
      std::memcpy(&v, p, 4);
      return v;
    }
  }
}

// a + b, or nullopt when it does not fit in size_t (offsets and lengths come from the file).
std::optional<size_t> addSize(size_t a, size_t b) {
  if (a > SIZE_MAX - b) return std::nullopt;
  return a + b;
}
std::optional<size_t> mulSize(size_t a, size_t b) {
  if (b != 0 && a > SIZE_MAX / b) return std::nullopt;
  return a * b;
}

std::string mib(size_t bytes) { return fmt::format("{:.1f} MiB", static_cast<double>(bytes) / (1024.0 * 1024.0)); }

size_t decodedBudget(size_t inputBytes, size_t maxBytes) {
  inputBytes = std::min(inputBytes, kMaxGltfDecodedBytes);  // keeps the product below in range
  return std::min(maxBytes, kMinGltfDecodedBudget + inputBytes * kGltfDecodedPerInputByte);
}

void Reader::charge(size_t count, size_t bytesEach, const std::string& what) {
  auto bytes = mulSize(count, bytesEach);
  if (!bytes || *bytes > budget_ - used_)
    fail(file_, fmt::format("{}: decoding {} elements would take the decoded data past this model's limit of {} "
                            "({} already; the limit is {} plus {} per byte of the file and its buffers, at most {})",
                            what, count, mib(budget_), mib(used_), mib(kMinGltfDecodedBudget),
                            fmt::format("{} bytes", kGltfDecodedPerInputByte), mib(kMaxGltfDecodedBytes)));
  used_ += *bytes;
}

const unsigned char* Reader::at(int bv, size_t offset, size_t bytes, const std::string& what) const {
  if (bv < 0 || static_cast<size_t>(bv) >= m_.bufferViews.size())
    fail(file_, fmt::format("{} refers to buffer view {}, which does not exist", what, bv));
  const auto& view = m_.bufferViews[static_cast<size_t>(bv)];
  if (view.buffer < 0 || static_cast<size_t>(view.buffer) >= m_.buffers.size())
    fail(file_, fmt::format("{}: buffer view {} refers to buffer {}, which does not exist", what, bv, view.buffer));
  const auto& buf = m_.buffers[static_cast<size_t>(view.buffer)].data;
  auto viewEnd = addSize(view.byteOffset, view.byteLength);
  if (!viewEnd || *viewEnd > buf.size())
    fail(file_, fmt::format("{}: buffer view {} (bytes {}..+{}) lies outside buffer {} ({} bytes)", what, bv,
                            view.byteOffset, view.byteLength, view.buffer, buf.size()));
  auto end = addSize(offset, bytes);
  if (!end || *end > view.byteLength)
    fail(file_, fmt::format("{} reads bytes {}..+{} of buffer view {}, which has {} bytes", what, offset, bytes, bv,
                            view.byteLength));
  return buf.data() + view.byteOffset + offset;
}

AccessorData Reader::read(int index, const std::string& what) {
  if (index < 0 || static_cast<size_t>(index) >= m_.accessors.size())
    fail(file_, fmt::format("{} refers to accessor {}, which does not exist", what, index));
  const tinygltf::Accessor& a = m_.accessors[static_cast<size_t>(index)];
  std::string accName = fmt::format("{} (accessor {})", what, index);
  AccessorData d;
  d.components = tinygltf::GetNumComponentsInType(static_cast<uint32_t>(a.type));
  int csize = tinygltf::GetComponentSizeInBytes(static_cast<uint32_t>(a.componentType));
  if (d.components <= 0 || csize <= 0 || a.componentType == TINYGLTF_COMPONENT_TYPE_DOUBLE)
    fail(file_, fmt::format("{}: accessor {} has an invalid type or component type", what, index));
  if ((a.type == TINYGLTF_TYPE_MAT2 || a.type == TINYGLTF_TYPE_MAT3) && csize < 4)
    fail(file_, fmt::format("{}: accessor {} is a padded 8/16-bit matrix, which is not supported", what, index));
  if (a.count > kMaxGltfElements)
    fail(file_, fmt::format("{} has {} elements; the limit is {}", accName, a.count, kMaxGltfElements));
  d.count = a.count;
  d.componentType = a.componentType;
  d.type = a.type;
  d.normalized = a.normalized;
  const size_t comps = static_cast<size_t>(d.components);
  const size_t elem = static_cast<size_t>(csize) * comps;
  // Bounds first, allocation after: every byte the accessor reads must lie in its view.
  const unsigned char* base = nullptr;
  size_t stride = elem;
  if (a.bufferView >= 0) {
    at(a.bufferView, 0, 0, accName);  // validates the view index
    const auto& view = m_.bufferViews[static_cast<size_t>(a.bufferView)];
    if (view.byteStride != 0) {
      if (view.byteStride < elem)
        fail(file_, fmt::format("{}: buffer view {} has byteStride {}, less than the {}-byte element", accName,
                                a.bufferView, view.byteStride, elem));
      stride = view.byteStride;
    }
    if (d.count > 0) {
      // count <= kMaxGltfElements and stride <= 252 (tinygltf checks it): no overflow here.
      base = at(a.bufferView, a.byteOffset, (d.count - 1) * stride + elem, accName);
    }
  }
  size_t n = 0;
  const unsigned char* idx = nullptr;
  const unsigned char* val = nullptr;
  int ict = 0;
  size_t isize = 0;
  if (a.sparse.isSparse) {
    d.sparse = true;
    if (a.sparse.count < 0 || static_cast<size_t>(a.sparse.count) > d.count)
      fail(file_, fmt::format("{}: sparse count {} is not between 0 and the accessor's count {}", accName,
                              a.sparse.count, d.count));
    if (a.sparse.indices.byteOffset < 0 || a.sparse.values.byteOffset < 0)
      fail(file_, fmt::format("{}: sparse byteOffset is negative", accName));
    n = static_cast<size_t>(a.sparse.count);
    ict = a.sparse.indices.componentType;
    if (ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
      fail(file_, fmt::format("{}: sparse indices must be unsigned byte, short or int", accName));
    isize = static_cast<size_t>(tinygltf::GetComponentSizeInBytes(static_cast<uint32_t>(ict)));
    if (n > 0) {
      idx = at(a.sparse.indices.bufferView, static_cast<size_t>(a.sparse.indices.byteOffset), n * isize,
               accName + " sparse indices");
      val = at(a.sparse.values.bufferView, static_cast<size_t>(a.sparse.values.byteOffset), n * elem,
               accName + " sparse values");
    }
  }
  charge(d.count, comps * sizeof(float), accName);
  d.values.assign(d.count * comps, 0.0f);
  for (size_t i = 0; base && i < d.count; ++i)
    for (size_t c = 0; c < comps; ++c)
      d.values[i * comps + c] = readComponent(base + i * stride + c * static_cast<size_t>(csize), a.componentType,
                                              a.normalized);
  for (size_t k = 0; k < n; ++k) {
    uint32_t i = readIndex(idx + k * isize, ict);
    if (i >= d.count)
      fail(file_, fmt::format("{}: sparse index {} is out of range (count {})", accName, i, d.count));
    for (size_t c = 0; c < comps; ++c)
      d.values[i * comps + c] =
          readComponent(val + k * elem + c * static_cast<size_t>(csize), a.componentType, a.normalized);
  }
  for (float v : d.values)
    if (!std::isfinite(v))
      throw InputError(Diagnostic{Severity::Error, SourceLoc{file_, 0, 0},
                                  fmt::format("{} holds a non-finite value (/accessors/{})", accName, index),
                                  "ACCESSOR_INVALID_FLOAT"});
  return d;
}

std::vector<std::array<float, 4>> Reader::stream(const AccessorData& d, int from, int n, const std::string& what) {
  charge(d.count, sizeof(std::array<float, 4>), what);
  std::vector<std::array<float, 4>> s(d.count, std::array<float, 4>{0, 0, 0, 0});
  for (size_t i = 0; i < d.count; ++i)
    for (int c = 0; c < n; ++c)
      s[i][static_cast<size_t>(c)] = d.values[i * static_cast<size_t>(d.components) + static_cast<size_t>(from + c)];
  return s;
}
std::vector<std::array<float, 4>> Reader::zeros(size_t count, const std::string& what) {
  charge(count, sizeof(std::array<float, 4>), what);
  return std::vector<std::array<float, 4>>(count, std::array<float, 4>{0, 0, 0, 0});
}

}  // namespace sg::gltf

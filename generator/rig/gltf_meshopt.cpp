// EXT_meshopt_compression decoding (gltf_meshopt.h), with meshoptimizer's decoder.
#include "rig/gltf_meshopt.h"

#include <fmt/format.h>
#include <meshoptimizer.h>

#include <algorithm>
#include <vector>

#include "rig/gltf_accessor.h"
#include "rig/gltf_import.h"

namespace sg::gltf {
namespace {

const char* kExt = "EXT_meshopt_compression";

// A non-negative integer property of the extension object; `fallback` when absent and optional.
size_t sizeProperty(const tinygltf::Value& ext, const char* name, bool required, const std::string& what,
                    const std::string& file) {
  if (!ext.Has(name)) {
    if (required) fail(file, fmt::format("{}: {} has no '{}'", what, kExt, name));
    return 0;
  }
  const tinygltf::Value& v = ext.Get(name);
  if (!v.IsNumber() && !v.IsInt()) fail(file, fmt::format("{}: {} '{}' is not a number", what, kExt, name));
  double d = v.GetNumberAsDouble();
  if (!(d >= 0) || d > 9007199254740992.0 || d != static_cast<double>(static_cast<uint64_t>(d)))
    fail(file, fmt::format("{}: {} '{}' is not a non-negative integer", what, kExt, name));
  return static_cast<size_t>(d);
}

std::string stringProperty(const tinygltf::Value& ext, const char* name, const char* dflt, const std::string& what,
                           const std::string& file) {
  if (!ext.Has(name)) {
    if (!dflt) fail(file, fmt::format("{}: {} has no '{}'", what, kExt, name));
    return dflt;
  }
  const tinygltf::Value& v = ext.Get(name);
  if (!v.IsString()) fail(file, fmt::format("{}: {} '{}' is not a string", what, kExt, name));
  return v.Get<std::string>();
}

}  // namespace

size_t decodeMeshopt(tinygltf::Model& model, const std::map<int, size_t>& fallbackLengths, size_t budget,
                     const std::string& file) {
  // Fallback buffers are allocated first, each against the budget.
  size_t allocated = 0;
  for (const auto& [index, length] : fallbackLengths) {
    if (length > budget - allocated)
      fail(file, fmt::format("buffer {}: decompressing into its {} bytes would take the decoded data past this "
                             "model's limit of {} ({} already)",
                             index, length, mib(budget), mib(allocated)));
    allocated += length;
    model.buffers[static_cast<size_t>(index)].data.assign(length, 0);
  }
  for (size_t bv = 0; bv < model.bufferViews.size(); ++bv) {
    tinygltf::BufferView& view = model.bufferViews[bv];
    auto it = view.extensions.find(kExt);
    if (it == view.extensions.end()) continue;
    const tinygltf::Value& ext = it->second;
    const std::string what = fmt::format("buffer view {}", bv);
    if (!ext.IsObject()) fail(file, fmt::format("{}: {} is not an object", what, kExt));
    size_t source = sizeProperty(ext, "buffer", true, what, file);
    size_t offset = sizeProperty(ext, "byteOffset", false, what, file);
    size_t length = sizeProperty(ext, "byteLength", true, what, file);
    size_t stride = sizeProperty(ext, "byteStride", true, what, file);
    size_t count = sizeProperty(ext, "count", true, what, file);
    std::string mode = stringProperty(ext, "mode", nullptr, what, file);
    std::string filter = stringProperty(ext, "filter", "NONE", what, file);

    if (source >= model.buffers.size() || fallbackLengths.count(static_cast<int>(source)))
      fail(file, fmt::format("{}: the compressed data is in buffer {}, which {}", what, source,
                             source >= model.buffers.size() ? "does not exist" : "is a fallback buffer without data"));
    const auto& src = model.buffers[source].data;
    auto srcEnd = addSize(offset, length);
    if (!srcEnd || *srcEnd > src.size())
      fail(file, fmt::format("{}: the compressed bytes {}..+{} lie outside buffer {} ({} bytes)", what, offset, length,
                             source, src.size()));
    if (count > kMaxGltfElements)
      fail(file, fmt::format("{}: {} elements; the limit is {}", what, count, kMaxGltfElements));
    if (mode != "ATTRIBUTES" && mode != "TRIANGLES" && mode != "INDICES")
      fail(file, fmt::format("{}: unknown {} mode '{}' (ATTRIBUTES, TRIANGLES or INDICES)", what, kExt, mode));
    // Strides the extension allows: ATTRIBUTES 4..256 in steps of 4; TRIANGLES/INDICES 2 or 4.
    const bool attributes = mode == "ATTRIBUTES";
    if (attributes ? (stride == 0 || stride > 256 || stride % 4 != 0) : (stride != 2 && stride != 4))
      fail(file, fmt::format("{}: byteStride {} is not valid for mode {}", what, stride, mode));
    if (!attributes && filter != "NONE")
      fail(file, fmt::format("{}: filter {} applies to ATTRIBUTES only, not {}", what, filter, mode));
    if (mode == "TRIANGLES" && count % 3 != 0)
      fail(file, fmt::format("{}: TRIANGLES needs a multiple of 3 indices, not {}", what, count));
    // The decoded bytes go to the view's own range of its buffer.
    if (view.buffer < 0 || static_cast<size_t>(view.buffer) >= model.buffers.size())
      fail(file, fmt::format("{} refers to buffer {}, which does not exist", what, view.buffer));
    auto& dst = model.buffers[static_cast<size_t>(view.buffer)].data;
    const size_t bytes = count * stride;  // count <= 2^24, stride <= 256: no overflow
    auto dstEnd = addSize(view.byteOffset, view.byteLength);
    if (bytes != view.byteLength || !dstEnd || *dstEnd > dst.size())
      fail(file, fmt::format("{}: {} elements of {} bytes do not fill the view's {} bytes at {} of buffer {} ({} bytes)",
                             what, count, stride, view.byteLength, view.byteOffset, view.buffer, dst.size()));
    // meshoptimizer decodes into memory of exactly count × stride bytes (it may not write past it).
    std::vector<unsigned char> out(bytes);
    const unsigned char* in = src.data() + offset;
    int rc = attributes            ? meshopt_decodeVertexBuffer(out.data(), count, stride, in, length)
             : mode == "TRIANGLES" ? meshopt_decodeIndexBuffer(out.data(), count, stride, in, length)
             : mode == "INDICES"   ? meshopt_decodeIndexSequence(out.data(), count, stride, in, length)
                                   : 1;
    if (rc != 0) fail(file, fmt::format("{}: the {} data ({} bytes) is malformed (meshoptimizer error {})", what, mode, length, rc));
    if (filter == "OCTAHEDRAL") {
      if (stride != 4 && stride != 8) fail(file, fmt::format("{}: OCTAHEDRAL needs byteStride 4 or 8, not {}", what, stride));
      meshopt_decodeFilterOct(out.data(), count, stride);
    } else if (filter == "QUATERNION") {
      if (stride != 8) fail(file, fmt::format("{}: QUATERNION needs byteStride 8, not {}", what, stride));
      meshopt_decodeFilterQuat(out.data(), count, stride);
    } else if (filter == "EXPONENTIAL") {
      meshopt_decodeFilterExp(out.data(), count, stride);
    } else if (filter != "NONE") {
      fail(file, fmt::format("{}: unknown {} filter '{}' (NONE, OCTAHEDRAL, QUATERNION or EXPONENTIAL)", what, kExt,
                             filter));
    }
    std::copy(out.begin(), out.end(), dst.begin() + static_cast<std::ptrdiff_t>(view.byteOffset));
  }
  return allocated;
}

size_t fallbackBytes(const tinygltf::Model& model) {
  size_t bytes = 0;
  for (const auto& b : model.buffers) {
    auto it = b.extensions.find(kExt);
    if (it != b.extensions.end() && it->second.Has("fallback") && it->second.Get("fallback").IsBool() &&
        it->second.Get("fallback").Get<bool>())
      bytes += b.data.size();
  }
  return bytes;
}

}  // namespace sg::gltf

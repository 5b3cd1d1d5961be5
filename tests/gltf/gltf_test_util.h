// Helpers for the glTF tests: paths of the shared models and a builder for tiny glTF
// files (JSON text with one data-URI buffer) for cases the sample models do not cover.
#pragma once
#include <fmt/format.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace sg::test {

inline std::string modelPath(const std::string& rel) { return std::string(SG_SHARED_DIR) + "/models/" + rel; }
inline std::string sourcePath(const std::string& rel) { return std::string(SG_SOURCE_DIR) + "/" + rel; }
inline std::string dataPath(const std::string& rel) { return std::string(SG_SOURCE_DIR) + "/tests/gltf/data/" + rel; }

inline std::string base64(const std::vector<uint8_t>& in) {
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    uint32_t v = (uint32_t(in[i]) << 16) | (uint32_t(in[i + 1]) << 8) | in[i + 2];
    out += t[(v >> 18) & 63];
    out += t[(v >> 12) & 63];
    out += t[(v >> 6) & 63];
    out += t[v & 63];
  }
  if (i + 1 == in.size()) {
    uint32_t v = uint32_t(in[i]) << 16;
    out += t[(v >> 18) & 63];
    out += t[(v >> 12) & 63];
    out += "==";
  } else if (i + 2 == in.size()) {
    uint32_t v = (uint32_t(in[i]) << 16) | (uint32_t(in[i + 1]) << 8);
    out += t[(v >> 18) & 63];
    out += t[(v >> 12) & 63];
    out += t[(v >> 6) & 63];
    out += '=';
  }
  return out;
}

// Accumulates one binary buffer; each chunk becomes a buffer view (4-byte aligned).
struct GltfBuilder {
  std::vector<uint8_t> bytes;
  std::vector<std::string> views, accessors;

  template <typename T>
  int view(const std::vector<T>& data) {
    while (bytes.size() % 4) bytes.push_back(0);
    size_t off = bytes.size();
    bytes.resize(off + data.size() * sizeof(T));
    std::memcpy(bytes.data() + off, data.data(), data.size() * sizeof(T));
    views.push_back(fmt::format(R"({{"buffer":0,"byteOffset":{},"byteLength":{}}})", off, data.size() * sizeof(T)));
    return static_cast<int>(views.size()) - 1;
  }
  // `extra` is appended inside the accessor object (e.g. R"("normalized":true)").
  int accessor(int view, int componentType, size_t count, const std::string& type, const std::string& extra = "") {
    std::string s = fmt::format(R"({{"componentType":{},"count":{},"type":"{}")", componentType, count, type);
    if (view >= 0) s += fmt::format(R"(,"bufferView":{})", view);
    if (!extra.empty()) s += "," + extra;
    accessors.push_back(s + "}");
    return static_cast<int>(accessors.size()) - 1;
  }
  // Everything but buffers/bufferViews/accessors comes from `rest` (JSON members, no braces).
  std::string json(const std::string& rest) const {
    std::string v, a;
    for (const auto& x : views) v += (v.empty() ? "" : ",") + x;
    for (const auto& x : accessors) a += (a.empty() ? "" : ",") + x;
    return fmt::format(
        R"({{"asset":{{"version":"2.0"}},"buffers":[{{"byteLength":{},"uri":"data:application/octet-stream;base64,{}"}}],)"
        R"("bufferViews":[{}],"accessors":[{}],{}}})",
        bytes.size(), base64(bytes), v, a, rest);
  }
};

}  // namespace sg::test

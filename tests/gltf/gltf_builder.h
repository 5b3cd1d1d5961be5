// Tiny glTF files for tests: JSON text with one data-URI buffer, built from typed arrays.
#pragma once
#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace sg::test {

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

// A tiny skinned triangle: joints as unsigned bytes, normalized weights (ubyte) and
// colours (ushort), a sparse morph target without a buffer view, sparse UVs over a base
// buffer view, and a CUBICSPLINE + STEP animation.
inline std::string tinySkinnedModel(int extraJointSets = 0) {
  GltfBuilder b;
  int pos = b.accessor(b.view(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}), 5126, 3, "VEC3",
                       R"("min":[0,0,0],"max":[1,1,0])");
  int joints = b.accessor(b.view(std::vector<uint8_t>{0, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 0}), 5121, 3, "VEC4");
  int weights = b.accessor(b.view(std::vector<uint8_t>{255, 0, 0, 0, 128, 127, 0, 0, 51, 204, 0, 0}), 5121, 3,
                           "VEC4", R"("normalized":true)");
  int color = b.accessor(b.view(std::vector<uint16_t>{65535, 0, 32768, 65535, 1, 2, 3, 4, 0, 65535, 0, 65535}), 5123,
                         3, "VEC4", R"("normalized":true)");
  int sparseIdx = b.view(std::vector<uint16_t>{1, 0});  // one index (padded)
  int sparseVal = b.view(std::vector<float>{0, 0.5f, 0});
  int morph = b.accessor(-1, 5126, 3, "VEC3",
                         fmt::format(R"("sparse":{{"count":1,"indices":{{"bufferView":{},"componentType":5123}},)"
                                     R"("values":{{"bufferView":{}}}}})",
                                     sparseIdx, sparseVal));
  int uvBase = b.view(std::vector<float>{0, 0, 1, 0, 0, 1});
  int uvIdx = b.view(std::vector<uint8_t>{2, 0, 0, 0});
  int uvVal = b.view(std::vector<float>{0.25f, 0.75f});
  int uv = b.accessor(uvBase, 5126, 3, "VEC2",
                      fmt::format(R"("sparse":{{"count":1,"indices":{{"bufferView":{},"componentType":5121}},)"
                                  R"("values":{{"bufferView":{}}}}})",
                                  uvIdx, uvVal));
  int ibm = b.accessor(b.view(std::vector<float>{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1,  //
                                                 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -1, 0, 0, 1}),
                       5126, 2, "MAT4");
  int times = b.accessor(b.view(std::vector<float>{0, 2}), 5126, 2, "SCALAR", R"("min":[0],"max":[2])");
  // CUBICSPLINE translation of joint 1 (node 1): in-tangent, value, out-tangent per key.
  int cubic = b.accessor(b.view(std::vector<float>{0, 0, 0, 0, 0, 0, 1, 0, 0,  //
                                                   0, 0, 0, 0, 2, 0, 0, 0, 0}),
                         5126, 6, "VEC3");
  // STEP rotation of joint 2: identity, then 90° about Z.
  float h = std::sqrt(0.5f);
  int step = b.accessor(b.view(std::vector<float>{0, 0, 0, 1, 0, 0, h, h}), 5126, 2, "VEC4");
  std::string attrs = fmt::format(R"("POSITION":{},"JOINTS_0":{},"WEIGHTS_0":{},"COLOR_0":{},"TEXCOORD_0":{})", pos,
                                  joints, weights, color, uv);
  for (int s = 1; s <= extraJointSets; ++s) attrs += fmt::format(R"(,"JOINTS_{}":{},"WEIGHTS_{}":{})", s, joints, s, weights);
  return b.json(fmt::format(
      R"("meshes":[{{"name":"tri","primitives":[{{"attributes":{{{}}},"targets":[{{"POSITION":{}}}]}}],"weights":[0.25]}}],)"
      R"("skins":[{{"joints":[1,2],"inverseBindMatrices":{}}}],)"
      R"("nodes":[{{"name":"skinned","mesh":0,"skin":0,"translation":[5,5,5]}},{{"name":"root","children":[2]}},)"
      R"({{"name":"tip","translation":[1,0,0]}}],)"
      R"("scenes":[{{"nodes":[0,1]}}],"scene":0,)"
      R"("animations":[{{"name":"wave","samplers":[{{"input":{},"output":{},"interpolation":"CUBICSPLINE"}},)"
      R"({{"input":{},"output":{},"interpolation":"STEP"}}],)"
      R"("channels":[{{"sampler":0,"target":{{"node":1,"path":"translation"}}}},{{"sampler":1,"target":{{"node":2,"path":"rotation"}}}}]}}])",
      attrs, morph, ibm, times, cubic, times, step));
}

// A 5×5 grid with normals and tangents, two morph targets moving position, normal and
// tangent (non-zero deltas, unlike the sample models), weights animated with CUBICSPLINE,
// under a parent node whose rotation is animated (LINEAR) and a child with its own TRS.
inline std::string tinyMorphFrameModel() {
  GltfBuilder b;
  const int n = 5;
  std::vector<float> pos, nrm, tan, d0p, d0n, d0t, d1p, d1n, d1t;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      float u = x / float(n - 1), v = y / float(n - 1);
      pos.insert(pos.end(), {u - 0.5f, 0.1f * std::sin(3 * u + 2 * v), v - 0.5f});
      float nx = -0.3f * std::cos(3 * u + 2 * v), nz = -0.2f * std::cos(3 * u + 2 * v), ny = 1.0f;
      float l = std::sqrt(nx * nx + ny * ny + nz * nz);
      nrm.insert(nrm.end(), {nx / l, ny / l, nz / l});
      tan.insert(tan.end(), {1.0f, 0.3f * std::cos(3 * u + 2 * v), 0.0f, (x + y) % 2 ? 1.0f : -1.0f});
      d0p.insert(d0p.end(), {0.0f, 0.3f * u * v, 0.05f * u});
      d0n.insert(d0n.end(), {0.2f * v, 0.0f, -0.1f * u});
      d0t.insert(d0t.end(), {0.0f, 0.1f * v, 0.2f * u});
      d1p.insert(d1p.end(), {0.1f * v, -0.2f * u, 0.0f});
      d1n.insert(d1n.end(), {-0.1f, 0.05f * u, 0.15f * v});
      d1t.insert(d1t.end(), {0.05f * u, 0.0f, -0.1f});
    }
  size_t count = static_cast<size_t>(n * n);
  int P = b.accessor(b.view(pos), 5126, count, "VEC3");
  int N = b.accessor(b.view(nrm), 5126, count, "VEC3");
  int T = b.accessor(b.view(tan), 5126, count, "VEC4");
  int t0p = b.accessor(b.view(d0p), 5126, count, "VEC3"), t0n = b.accessor(b.view(d0n), 5126, count, "VEC3"),
      t0t = b.accessor(b.view(d0t), 5126, count, "VEC3");
  int t1p = b.accessor(b.view(d1p), 5126, count, "VEC3"), t1n = b.accessor(b.view(d1n), 5126, count, "VEC3"),
      t1t = b.accessor(b.view(d1t), 5126, count, "VEC3");
  int wt = b.accessor(b.view(std::vector<float>{0, 1, 3}), 5126, 3, "SCALAR");
  // CUBICSPLINE weights: per key [in-tangents(2), values(2), out-tangents(2)].
  int wv = b.accessor(b.view(std::vector<float>{0, 0, 0, 0, 1.5f, 0,  //
                                                0.5f, 0, 0.8f, 0.2f, -0.5f, 1,  //
                                                0, 0, 0.1f, 0.9f, 0, 0}),
                      5126, 18, "SCALAR");
  float s = std::sin(0.6f), c = std::cos(0.6f);
  int rt = b.accessor(b.view(std::vector<float>{0, 3}), 5126, 2, "SCALAR");
  int rv = b.accessor(b.view(std::vector<float>{0, 0, 0, 1, 0, s, 0, c}), 5126, 2, "VEC4");
  return b.json(fmt::format(
      R"("meshes":[{{"name":"sheet","weights":[0.5,0.5],"primitives":[{{"attributes":{{"POSITION":{},"NORMAL":{},"TANGENT":{}}},)"
      R"("targets":[{{"POSITION":{},"NORMAL":{},"TANGENT":{}}},{{"POSITION":{},"NORMAL":{},"TANGENT":{}}}]}}]}}],)"
      R"("nodes":[{{"name":"pivot","children":[1],"translation":[0,1,0]}},)"
      R"({{"name":"sheet","mesh":0,"translation":[0.5,0,0.2],"rotation":[0.1,0.2,0,0.9746794],"scale":[2,1,1.5]}}],)"
      R"("scenes":[{{"nodes":[0]}}],)"
      R"("animations":[{{"name":"breathe","samplers":[{{"input":{},"output":{},"interpolation":"CUBICSPLINE"}},)"
      R"({{"input":{},"output":{}}}],)"
      R"("channels":[{{"sampler":0,"target":{{"node":1,"path":"weights"}}}},{{"sampler":1,"target":{{"node":0,"path":"rotation"}}}}]}}])",
      P, N, T, t0p, t0n, t0t, t1p, t1n, t1t, wt, wv, rt, rv));
}

}  // namespace sg::test

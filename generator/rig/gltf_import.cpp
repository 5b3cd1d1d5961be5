// glTF 2.0 → rig (docs/gltf.md). The only translation unit that sees tinygltf.
#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>

#include "rig/gltf_import.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <set>

namespace sg {
namespace {

std::string lower(std::string s) {
  for (auto& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

[[noreturn]] void fail(const std::string& file, const std::string& msg) { throw InputError(SourceLoc{file, 0, 0}, msg); }

// Textures are not needed (and the test models ship without them): accept every image as is.
bool skipImage(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int, void*) {
  return true;
}

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

struct AccessorData {
  int components = 0;
  size_t count = 0;
  int componentType = 0;
  int type = 0;
  bool normalized = false;
  bool sparse = false;
  std::vector<float> values;  // count * components
};

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

class Reader {
 public:
  Reader(const tinygltf::Model& m, std::string file, size_t budget)
      : m_(m), file_(std::move(file)), budget_(budget) {}

  // Counts `bytes` of decoded data against the budget before they are allocated: the counts
  // in a small file must not make the reader allocate gigabytes.
  void charge(size_t count, size_t bytesEach, const std::string& what) {
    auto bytes = mulSize(count, bytesEach);
    if (!bytes || *bytes > budget_ - used_)
      fail(file_, fmt::format("{}: decoding {} elements would take the decoded data past this model's limit of {} "
                              "({} already; the limit is {} plus {} per byte of the file and its buffers, at most {})",
                              what, count, mib(budget_), mib(used_), mib(kMinGltfDecodedBudget),
                              fmt::format("{} bytes", kGltfDecodedPerInputByte), mib(kMaxGltfDecodedBytes)));
    used_ += *bytes;
  }

  // Pointer to `bytes` bytes at `offset` of buffer view `bv`, bounds-checked without overflow.
  const unsigned char* at(int bv, size_t offset, size_t bytes, const std::string& what) const {
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

  AccessorData read(int index, const std::string& what) {
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
      if (!std::isfinite(v)) fail(file_, fmt::format("{} holds a non-finite value", accName));
    return d;
  }

  // Accessor data (d.components each) as a per-vertex stream of components [from, from+n).
  std::vector<std::array<float, 4>> stream(const AccessorData& d, int from, int n, const std::string& what) {
    charge(d.count, sizeof(std::array<float, 4>), what);
    std::vector<std::array<float, 4>> s(d.count, std::array<float, 4>{0, 0, 0, 0});
    for (size_t i = 0; i < d.count; ++i)
      for (int c = 0; c < n; ++c)
        s[i][static_cast<size_t>(c)] = d.values[i * static_cast<size_t>(d.components) + static_cast<size_t>(from + c)];
    return s;
  }
  std::vector<std::array<float, 4>> zeros(size_t count, const std::string& what) {
    charge(count, sizeof(std::array<float, 4>), what);
    return std::vector<std::array<float, 4>>(count, std::array<float, 4>{0, 0, 0, 0});
  }

 private:
  const tinygltf::Model& m_;
  std::string file_;
  size_t budget_;
  size_t used_ = 0;
};

std::string kibText(int bones) {
  int bytes = bones * 64;
  if (bytes % 1024 == 0) return fmt::format("{} KiB", bytes / 1024);
  return fmt::format("{} bytes", bytes);
}

RigAttribute makeAttribute(const std::string& name, VertexFormat f, std::vector<ProvidedPart> provides,
                           const std::string& file, bool perTarget = false) {
  RigAttribute a;
  a.name = name;
  a.format = f;
  int n = formatComponents(f);
  a.shaderType = *vectorType(formatIsInteger(f) ? ScalarKind::UInt : ScalarKind::Float, n);
  a.perMorphTarget = perTarget;
  a.provides = std::move(provides);
  a.loc = SourceLoc{file, 0, 0};
  return a;
}

RigUniform makeUniform(const std::string& name, const std::string& semantic, Type t, const std::string& array,
                       int size, const std::string& file) {
  RigUniform u;
  u.name = name;
  u.semantic = semantic;
  u.type = t;
  u.arraySizeParam = array;
  u.arraySize = size;
  u.loc = SourceLoc{file, 0, 0};
  return u;
}

// Parses "N/P" after '#'.
bool parseSelection(const std::string& s, int& mesh, int& prim) {
  auto slash = s.find('/');
  if (slash == std::string::npos || slash == 0 || slash + 1 == s.size()) return false;
  auto num = [](const std::string& t, int& out) {
    if (t.empty() || t.size() > 6) return false;
    for (char c : t)
      if (!std::isdigit(static_cast<unsigned char>(c))) return false;
    out = std::stoi(t);
    return true;
  };
  return num(s.substr(0, slash), mesh) && num(s.substr(slash + 1), prim);
}

// Is the upper 3x3 of a column-major matrix a similarity (rotation times a uniform scale)?
// Columns of equal length and mutually orthogonal, to 1e-4 relative.
bool isSimilarity(const double* m, int stride) {
  double c[3][3];
  for (int i = 0; i < 3; ++i)
    for (int r = 0; r < 3; ++r) c[i][r] = m[i * stride + r];
  auto dot = [&](int a, int b) { return c[a][0] * c[b][0] + c[a][1] * c[b][1] + c[a][2] * c[b][2]; };
  double l = std::max({dot(0, 0), dot(1, 1), dot(2, 2)});
  if (l == 0) return true;
  const double tol = 2e-4 * l;
  return std::abs(dot(0, 0) - dot(1, 1)) <= tol && std::abs(dot(1, 1) - dot(2, 2)) <= tol && std::abs(dot(0, 1)) <= tol &&
         std::abs(dot(1, 2)) <= tol && std::abs(dot(0, 2)) <= tol;
}

bool uniformScale3(double x, double y, double z) {
  double m = std::max({std::abs(x), std::abs(y), std::abs(z)});
  return std::abs(x - y) <= 1e-4 * m && std::abs(y - z) <= 1e-4 * m;
}

// uniform_scale (docs/rig-format.md) when no node, scale animation or inverse bind matrix of
// the model scales per axis: then mat3(M) is a valid normal matrix.
bool modelScalesUniformly(const GltfModelData& d) {
  for (const auto& n : d.nodes) {
    if (n.hasMatrix ? !isSimilarity(n.matrix.data(), 4) : !uniformScale3(n.scale[0], n.scale[1], n.scale[2])) return false;
  }
  for (const auto& a : d.animations)
    for (const auto& ch : a.channels)
      if (ch.path == GltfPath::Scale)
        for (size_t i = 0; i + 2 < ch.values.size(); i += 3)
          if (!uniformScale3(ch.values[i], ch.values[i + 1], ch.values[i + 2])) return false;
  for (const auto& sk : d.skins)
    for (const auto& ib : sk.inverseBind) {
      double m[16];
      for (int i = 0; i < 16; ++i) m[i] = ib[static_cast<size_t>(i)];
      if (!isSimilarity(m, 4)) return false;
    }
  return true;
}

// Warnings for vertices whose frame is degenerate (docs/semantics.md, object.tangent).
void noteDegenerateFrames(GltfImport& imp) {
  const auto& st = imp.data.streams;
  auto n = st.find("vertex.normal");
  if (n == st.end()) return;
  size_t zeroNormals = 0, badTangents = 0;
  auto t = st.find("vertex.tangent");
  for (size_t v = 0; v < n->second.size(); ++v) {
    const auto& N = n->second[v];
    double nn = double(N[0]) * N[0] + double(N[1]) * N[1] + double(N[2]) * N[2];
    if (nn < 1e-12) ++zeroNormals;
    if (t == st.end() || v >= t->second.size()) continue;
    const auto& T = t->second[v];
    double tt = double(T[0]) * T[0] + double(T[1]) * T[1] + double(T[2]) * T[2];
    double tn = nn > 0 ? (double(T[0]) * N[0] + double(T[1]) * N[1] + double(T[2]) * N[2]) / std::sqrt(nn) : 0;
    if (tt - tn * tn <= 1e-6 * tt || tt == 0) ++badTangents;
  }
  const size_t total = n->second.size();
  if (zeroNormals)
    imp.notes.push_back(fmt::format("{} of {} vertices have a zero-length NORMAL: their normal (and frame) is NaN",
                                    zeroNormals, total));
  if (badTangents)
    imp.notes.push_back(fmt::format("{} of {} vertices have a TANGENT that is zero or parallel to the NORMAL: the "
                                    "shader falls back to the orthonormal basis of the normal there",
                                    badTangents, total));
}

GltfImport importModel(const tinygltf::Model& model, const std::string& file, const GltfImportOptions& opts) {
  GltfImport imp;
  GltfModelData& data = imp.data;
  data.file = file;
  data.stem = std::filesystem::path(file).stem().string();
  Reader reader(model, file, opts.maxDecodedBytes);

  if (opts.mesh < 0 || static_cast<size_t>(opts.mesh) >= model.meshes.size())
    fail(file, fmt::format("the model has {} mesh(es); there is no mesh {}", model.meshes.size(), opts.mesh));
  const tinygltf::Mesh& mesh = model.meshes[static_cast<size_t>(opts.mesh)];
  data.mesh = opts.mesh;
  data.meshName = mesh.name.empty() ? std::to_string(opts.mesh) : mesh.name;
  const std::string meshDesc = fmt::format("mesh '{}'", data.meshName);
  if (opts.primitive < 0 || static_cast<size_t>(opts.primitive) >= mesh.primitives.size())
    fail(file, fmt::format("{} has {} primitive(s); there is no primitive {}", meshDesc, mesh.primitives.size(),
                           opts.primitive));
  const tinygltf::Primitive& prim = mesh.primitives[static_cast<size_t>(opts.primitive)];
  data.primitive = opts.primitive;
  data.mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
  const std::string where = fmt::format("{} primitive {}", meshDesc, opts.primitive);

  // --- nodes, scene, skins, animations (plain data) ---
  for (const auto& n : model.nodes) {
    GltfNode g;
    g.name = n.name;
    g.children = n.children;
    g.mesh = n.mesh;
    g.skin = n.skin;
    if (n.matrix.size() == 16) {
      g.hasMatrix = true;
      std::copy(n.matrix.begin(), n.matrix.end(), g.matrix.begin());
    }
    if (n.translation.size() == 3) std::copy(n.translation.begin(), n.translation.end(), g.translation.begin());
    if (n.rotation.size() == 4) std::copy(n.rotation.begin(), n.rotation.end(), g.rotation.begin());
    if (n.scale.size() == 3) std::copy(n.scale.begin(), n.scale.end(), g.scale.begin());
    g.weights = n.weights;
    for (int c : g.children)
      if (c < 0 || static_cast<size_t>(c) >= model.nodes.size())
        fail(file, fmt::format("node '{}' has a child {} that does not exist", n.name, c));
    data.nodes.push_back(std::move(g));
  }
  {
    // Parents (and a cycle check: glTF node graphs are forests).
    std::vector<int> parent(model.nodes.size(), -1);
    for (size_t i = 0; i < model.nodes.size(); ++i)
      for (int c : model.nodes[i].children) {
        if (parent[static_cast<size_t>(c)] >= 0)
          fail(file, fmt::format("node {} has two parents; glTF node hierarchies are trees", c));
        parent[static_cast<size_t>(c)] = static_cast<int>(i);
      }
    // Every node has at most one parent, so following parents either ends at a root or
    // comes back: one linear pass with three colours (a long chain costs O(n), not O(n²)).
    std::vector<char> state(parent.size(), 0);  // 0 unvisited, 1 on the current walk, 2 done
    for (size_t i = 0; i < parent.size(); ++i) {
      int p = static_cast<int>(i);
      while (p >= 0 && state[static_cast<size_t>(p)] == 0) {
        state[static_cast<size_t>(p)] = 1;
        p = parent[static_cast<size_t>(p)];
      }
      if (p >= 0 && state[static_cast<size_t>(p)] == 1)
        fail(file, fmt::format("node {} is part of a cycle in the node hierarchy", p));
      for (int q = static_cast<int>(i); q >= 0 && state[static_cast<size_t>(q)] == 1; q = parent[static_cast<size_t>(q)])
        state[static_cast<size_t>(q)] = 2;
    }
    int sceneIndex = model.defaultScene >= 0 ? model.defaultScene : (model.scenes.empty() ? -1 : 0);
    if (sceneIndex >= 0 && static_cast<size_t>(sceneIndex) < model.scenes.size()) {
      data.sceneRoots = model.scenes[static_cast<size_t>(sceneIndex)].nodes;
    } else {
      for (size_t i = 0; i < parent.size(); ++i)
        if (parent[i] < 0) data.sceneRoots.push_back(static_cast<int>(i));
    }
    for (int r : data.sceneRoots)
      if (r < 0 || static_cast<size_t>(r) >= model.nodes.size())
        fail(file, fmt::format("the scene refers to node {}, which does not exist", r));
    // The node that instantiates the mesh: first in the scene (depth first, pre-order), else
    // any. Iterative: a chain of nodes as long as the file allows must not overflow the stack.
    std::vector<int> todo(data.sceneRoots.rbegin(), data.sceneRoots.rend());
    std::vector<char> seen(data.nodes.size(), 0);  // a scene may list a root twice
    while (!todo.empty() && data.meshNode < 0) {
      int n = todo.back();
      todo.pop_back();
      if (seen[static_cast<size_t>(n)]) continue;
      seen[static_cast<size_t>(n)] = 1;
      const GltfNode& node = data.nodes[static_cast<size_t>(n)];
      if (node.mesh == opts.mesh) data.meshNode = n;
      todo.insert(todo.end(), node.children.rbegin(), node.children.rend());
    }
    if (data.meshNode < 0)
      for (size_t i = 0; i < data.nodes.size(); ++i)
        if (data.nodes[i].mesh == opts.mesh) {
          data.meshNode = static_cast<int>(i);
          break;
        }
    if (data.meshNode < 0) imp.notes.push_back(fmt::format("no node instantiates {}; it is posed at the origin", meshDesc));
  }
  for (size_t si = 0; si < model.skins.size(); ++si) {
    const auto& s = model.skins[si];
    GltfSkin g;
    g.name = s.name;
    g.joints = s.joints;
    for (int j : g.joints)
      if (j < 0 || static_cast<size_t>(j) >= model.nodes.size())
        fail(file, fmt::format("skin {} has joint node {}, which does not exist", si, j));
    if (s.inverseBindMatrices >= 0) {
      AccessorData ibm = reader.read(s.inverseBindMatrices, fmt::format("skin {} inverseBindMatrices", si));
      if (ibm.type != TINYGLTF_TYPE_MAT4 || ibm.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT ||
          ibm.count < g.joints.size())
        fail(file, fmt::format("skin {}: inverseBindMatrices must be {} float MAT4", si, g.joints.size()));
      for (size_t j = 0; j < g.joints.size(); ++j) {
        std::array<float, 16> m{};
        std::copy(ibm.values.begin() + static_cast<long>(j * 16), ibm.values.begin() + static_cast<long>(j * 16 + 16),
                  m.begin());
        g.inverseBind.push_back(m);
      }
    } else {
      std::array<float, 16> id{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
      g.inverseBind.assign(g.joints.size(), id);
    }
    data.skins.push_back(std::move(g));
  }
  for (size_t ai = 0; ai < model.animations.size(); ++ai) {
    const auto& a = model.animations[ai];
    GltfAnimation g;
    g.name = a.name.empty() ? std::to_string(ai) : a.name;
    bool first = true;
    for (size_t ci = 0; ci < a.channels.size(); ++ci) {
      const auto& c = a.channels[ci];
      std::string what = fmt::format("animation '{}' channel {}", g.name, ci);
      if (c.target_node < 0) continue;  // e.g. KHR_animation_pointer targets: not posed here
      if (static_cast<size_t>(c.target_node) >= model.nodes.size())
        fail(file, fmt::format("{} targets node {}, which does not exist", what, c.target_node));
      GltfChannel ch;
      ch.node = c.target_node;
      if (c.target_path == "translation") ch.path = GltfPath::Translation;
      else if (c.target_path == "rotation") ch.path = GltfPath::Rotation;
      else if (c.target_path == "scale") ch.path = GltfPath::Scale;
      else if (c.target_path == "weights") ch.path = GltfPath::Weights;
      else continue;
      if (c.sampler < 0 || static_cast<size_t>(c.sampler) >= a.samplers.size())
        fail(file, fmt::format("{} uses sampler {}, which does not exist", what, c.sampler));
      const auto& smp = a.samplers[static_cast<size_t>(c.sampler)];
      if (smp.interpolation == "STEP") ch.interpolation = GltfInterpolation::Step;
      else if (smp.interpolation == "CUBICSPLINE") ch.interpolation = GltfInterpolation::CubicSpline;
      else if (smp.interpolation.empty() || smp.interpolation == "LINEAR") ch.interpolation = GltfInterpolation::Linear;
      else fail(file, fmt::format("{}: unknown interpolation '{}'", what, smp.interpolation));
      AccessorData in = reader.read(smp.input, what + " input");
      AccessorData out = reader.read(smp.output, what + " output");
      if (in.components != 1 || in.count == 0) fail(file, fmt::format("{}: the input must be non-empty SCALAR times", what));
      ch.times = in.values;
      for (size_t k = 1; k < ch.times.size(); ++k)
        if (!(ch.times[k] > ch.times[k - 1])) fail(file, fmt::format("{}: keyframe times must increase", what));
      size_t perKey = ch.interpolation == GltfInterpolation::CubicSpline ? 3 : 1;
      size_t total = out.values.size();
      if (ch.path == GltfPath::Weights) {
        if (total == 0 || total % (ch.times.size() * perKey) != 0)
          fail(file, fmt::format("{}: {} output values do not divide into {} keyframes", what, total, ch.times.size()));
        ch.components = static_cast<int>(total / (ch.times.size() * perKey));
      } else {
        ch.components = ch.path == GltfPath::Rotation ? 4 : 3;
        if (out.components != ch.components || out.count != ch.times.size() * perKey)
          fail(file, fmt::format("{}: expected {} {} output elements, found {} {}", what, ch.times.size() * perKey,
                                 ch.components == 4 ? "VEC4" : "VEC3", out.count, typeName(out.type)));
      }
      ch.values = std::move(out.values);
      g.start = first ? ch.times.front() : std::min(g.start, ch.times.front());
      g.end = first ? ch.times.back() : std::max(g.end, ch.times.back());
      first = false;
      g.channels.push_back(std::move(ch));
    }
    data.animations.push_back(std::move(g));
  }

  // --- the primitive's attributes ---
  auto accessorOf = [&](const std::string& name) -> const tinygltf::Accessor* {
    auto it = prim.attributes.find(name);
    if (it == prim.attributes.end()) return nullptr;
    if (it->second < 0 || static_cast<size_t>(it->second) >= model.accessors.size())
      fail(file, fmt::format("{}: attribute {} refers to accessor {}, which does not exist", where, name, it->second));
    return &model.accessors[static_cast<size_t>(it->second)];
  };
  const tinygltf::Accessor* posAcc = accessorOf("POSITION");
  if (!posAcc) fail(file, fmt::format("{} has no POSITION attribute", where));
  data.vertexCount = posAcc->count;

  Rig& rig = imp.rig;
  rig.file = file;
  rig.name = fmt::format("{}/{}/{}", data.stem, data.meshName, opts.primitive);
  rig.params = {{"bones", 0}, {"influences", 0}, {"morph_targets", 0}};

  auto info = [&](const std::string& name, const tinygltf::Accessor& a) {
    GltfAttributeInfo i;
    i.gltfName = name;
    i.componentType = componentTypeName(a.componentType);
    i.type = typeName(a.type);
    i.normalized = a.normalized;
    i.sparse = a.sparse.isSparse;
    i.count = a.count;
    return i;
  };
  auto formatText = [](const GltfAttributeInfo& i) {
    return fmt::format("{}{} {}", i.normalized ? "normalized " : "", i.componentType, i.type);
  };
  std::map<std::string, size_t> infoIndex;
  for (const auto& [name, idx] : prim.attributes) {
    const tinygltf::Accessor* a = accessorOf(name);
    infoIndex[name] = imp.attributes.size();
    imp.attributes.push_back(info(name, *a));
    if (a->count != data.vertexCount)
      fail(file, fmt::format("{}: attribute {} has {} elements but POSITION has {}", where, name, a->count,
                             data.vertexCount));
  }
  auto readAttr = [&](const std::string& name) {
    return reader.read(prim.attributes.at(name), fmt::format("{} attribute {}", where, name));
  };
  auto isFloat = [](const tinygltf::Accessor* a, int type) {
    return a->componentType == TINYGLTF_COMPONENT_TYPE_FLOAT && a->type == type;
  };
  auto carried = [&](const std::string& name, const std::string& rigName, VertexFormat f) {
    auto& i = imp.attributes[infoIndex.at(name)];
    i.rigAttribute = rigName;
    i.format = formatName(f);
    if (i.sparse)
      imp.notes.push_back(fmt::format("{} is a sparse accessor: the application must expand it to a dense {} stream",
                                      name, formatName(f)));
  };
  auto skip = [&](const std::string& name, const std::string& why) {
    imp.notes.push_back(fmt::format("{} ({}) is not carried by the rig: {}", name,
                                    formatText(imp.attributes[infoIndex.at(name)]), why));
  };

  // Indices, for drawing (shadergen render). Shaders run per vertex, so generation and
  // validation never needed them: a bad index accessor is recorded, not an import error.
  if (prim.indices >= 0) {
    try {
      AccessorData idx = reader.read(prim.indices, where + " indices");
      if (idx.components != 1 || (idx.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
                                  idx.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
                                  idx.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT))
        fail(file, fmt::format("{}: indices must be unsigned byte, short or int scalars", where));
      for (float v : idx.values)
        if (!(v >= 0.0f) || static_cast<size_t>(v) >= data.vertexCount)
          fail(file, fmt::format("{}: index {} is out of range ({} vertices)", where, v, data.vertexCount));
      data.indices.assign(idx.values.begin(), idx.values.end());
    } catch (const InputError& e) {
      data.indices.clear();
      data.indicesError = e.diagnostic().message;
    }
  }

  // POSITION
  if (!isFloat(posAcc, TINYGLTF_TYPE_VEC3))
    fail(file, fmt::format("{}: POSITION is {}; only float VEC3 positions are supported (KHR_mesh_quantization is not)",
                           where, formatText(imp.attributes[infoIndex.at("POSITION")])));
  rig.attributes.push_back(makeAttribute("position", VertexFormat::Float32x3, {{"vertex.position", ""}}, file));
  carried("POSITION", "position", VertexFormat::Float32x3);
  data.streams["vertex.position"] = reader.stream(readAttr("POSITION"), 0, 3, where + " attribute POSITION");

  bool hasNormal = false, hasTangent = false;
  if (const auto* a = accessorOf("NORMAL")) {
    if (isFloat(a, TINYGLTF_TYPE_VEC3)) {
      hasNormal = true;
      rig.attributes.push_back(makeAttribute("normal", VertexFormat::Float32x3, {{"vertex.normal", ""}}, file));
      carried("NORMAL", "normal", VertexFormat::Float32x3);
      data.streams["vertex.normal"] = reader.stream(readAttr("NORMAL"), 0, 3, where + " attribute NORMAL");
    } else {
      skip("NORMAL", "only float VEC3 normals are supported");
    }
  }
  if (const auto* a = accessorOf("TANGENT")) {
    if (isFloat(a, TINYGLTF_TYPE_VEC4)) {
      hasTangent = true;
      rig.attributes.push_back(makeAttribute("tangent", VertexFormat::Float32x4,
                                             {{"vertex.tangent", "xyz"}, {"vertex.handedness", "w"}}, file));
      carried("TANGENT", "tangent", VertexFormat::Float32x4);
      AccessorData d = readAttr("TANGENT");
      data.streams["vertex.tangent"] = reader.stream(d, 0, 3, where + " attribute TANGENT");
      data.streams["vertex.handedness"] = reader.stream(d, 3, 1, where + " attribute TANGENT");
    } else {
      skip("TANGENT", "only float VEC4 tangents are supported");
    }
  }
  for (int t = 0; t < 2; ++t) {
    std::string name = fmt::format("TEXCOORD_{}", t);
    if (const auto* a = accessorOf(name)) {
      if (isFloat(a, TINYGLTF_TYPE_VEC2)) {
        std::string rn = fmt::format("texcoord{}", t);
        rig.attributes.push_back(
            makeAttribute(rn, VertexFormat::Float32x2, {{fmt::format("vertex.texcoord{}", t), ""}}, file));
        carried(name, rn, VertexFormat::Float32x2);
        data.streams[fmt::format("vertex.texcoord{}", t)] = reader.stream(readAttr(name), 0, 2, where + " attribute " + name);
      } else {
        skip(name, "the rig formats have no normalized 2-component format (expand to float32x2)");
      }
    }
  }
  if (const auto* a = accessorOf("COLOR_0")) {
    std::optional<VertexFormat> f;
    if (a->type == TINYGLTF_TYPE_VEC4) {
      if (a->componentType == TINYGLTF_COMPONENT_TYPE_FLOAT) f = VertexFormat::Float32x4;
      else if (a->componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && a->normalized) f = VertexFormat::Unorm8x4;
      else if (a->componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT && a->normalized) f = VertexFormat::Unorm16x4;
    }
    if (f) {
      rig.attributes.push_back(makeAttribute("color0", *f, {{"vertex.color0", ""}}, file));
      carried("COLOR_0", "color0", *f);
      data.streams["vertex.color0"] = reader.stream(readAttr("COLOR_0"), 0, 4, where + " attribute COLOR_0");
    } else {
      skip("COLOR_0", "vertex.color0 is a vec4 (RGB colours must be widened to RGBA by the application)");
    }
  }

  // _OCCLUSION: baked by `shadergen bake occlusion` (docs/bake.md).
  bool hasOcclusion = false;
  if (const auto* a = accessorOf("_OCCLUSION")) {
    if (isFloat(a, TINYGLTF_TYPE_SCALAR)) {
      hasOcclusion = true;
      rig.attributes.push_back(makeAttribute("occlusion", VertexFormat::Float32x1, {{"vertex.occlusion", ""}}, file));
      carried("_OCCLUSION", "occlusion", VertexFormat::Float32x1);
      data.streams["vertex.occlusion"] = reader.stream(readAttr("_OCCLUSION"), 0, 1, where + " attribute _OCCLUSION");
    } else {
      skip("_OCCLUSION", "occlusion is a float SCALAR (as shadergen bake occlusion writes it)");
    }
  }

  // Skinning: JOINTS_n / WEIGHTS_n sets.
  int sets = 0;
  for (const auto& [name, idx] : prim.attributes) {
    for (const char* prefix : {"JOINTS_", "WEIGHTS_"}) {
      if (name.rfind(prefix, 0) != 0) continue;
      // The set number, saturated (atoi overflows on "JOINTS_99999999999", and 4·(s+1) below
      // must not); a name without digits ("JOINTS_x") counts as set 0, like atoi did.
      int s = 0;
      for (const char* p = name.c_str() + std::strlen(prefix); *p >= '0' && *p <= '9'; ++p)
        s = std::min(s * 10 + (*p - '0'), 1000000);
      if (s >= kMaxInfluenceSets) {
        int infl = 0;
        while (prim.attributes.count(fmt::format("JOINTS_{}", infl / 4))) infl += 4;
        fail(file, fmt::format("{} has {} ({} influences per vertex); the rules serve at most {} "
                               "(JOINTS_0..JOINTS_{})",
                               where, name, std::max(infl, 4 * (s + 1)), 4 * kMaxInfluenceSets,
                               kMaxInfluenceSets - 1));
      }
    }
  }
  while (sets < kMaxInfluenceSets && prim.attributes.count(fmt::format("JOINTS_{}", sets))) ++sets;
  for (int s = 0; s < kMaxInfluenceSets; ++s) {
    bool j = prim.attributes.count(fmt::format("JOINTS_{}", s)) != 0;
    bool w = prim.attributes.count(fmt::format("WEIGHTS_{}", s)) != 0;
    if (j != w)
      fail(file, fmt::format("{} has {}_{} without {}_{}", where, j ? "JOINTS" : "WEIGHTS", s, j ? "WEIGHTS" : "JOINTS", s));
    if (j && s >= sets) fail(file, fmt::format("{} has JOINTS_{} without JOINTS_{}", where, s, s - 1));
  }
  int skinIndex = data.meshNode >= 0 ? data.nodes[static_cast<size_t>(data.meshNode)].skin : -1;
  if (skinIndex >= static_cast<int>(data.skins.size()))
    fail(file, fmt::format("the node of {} uses skin {}, which does not exist", meshDesc, skinIndex));
  if (sets > 0 && skinIndex < 0) {
    imp.notes.push_back(fmt::format("{} has JOINTS_0/WEIGHTS_0 but no node gives it a skin: imported unskinned", where));
    sets = 0;
  }
  if (sets == 0 && skinIndex >= 0) {
    imp.notes.push_back(fmt::format("{} is instantiated with a skin but has no JOINTS_0/WEIGHTS_0: imported unskinned", where));
    skinIndex = -1;
  }
  if (sets > 0) {
    const GltfSkin& skin = data.skins[static_cast<size_t>(skinIndex)];
    int joints = static_cast<int>(skin.joints.size());
    if (joints == 0) fail(file, fmt::format("the skin of {} has no joints", meshDesc));
    if (joints > opts.maxBones)
      fail(file, fmt::format("{}: {} uses {} joints; the bone palette holds at most {} (kMaxBones)",
                             std::filesystem::path(file).filename().string(), meshDesc, joints, opts.maxBones));
    data.skin = skinIndex;
    imp.joints = joints;
    imp.influences = 4 * sets;
    rig.params["bones"] = joints;
    rig.params["influences"] = imp.influences;
    for (int s = 0; s < sets; ++s) {
      std::string jn = fmt::format("JOINTS_{}", s), wn = fmt::format("WEIGHTS_{}", s);
      const auto* ja = accessorOf(jn);
      const auto* wa = accessorOf(wn);
      VertexFormat jf{}, wf{};
      if (ja->type == TINYGLTF_TYPE_VEC4 && !ja->normalized && ja->componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE)
        jf = VertexFormat::Uint8x4;
      else if (ja->type == TINYGLTF_TYPE_VEC4 && !ja->normalized &&
               ja->componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT)
        jf = VertexFormat::Uint16x4;
      else
        fail(file, fmt::format("{}: {} is {}; glTF joints are unsigned byte or unsigned short VEC4", where, jn,
                               formatText(imp.attributes[infoIndex.at(jn)])));
      if (wa->type == TINYGLTF_TYPE_VEC4 && wa->componentType == TINYGLTF_COMPONENT_TYPE_FLOAT)
        wf = VertexFormat::Float32x4;
      else if (wa->type == TINYGLTF_TYPE_VEC4 && wa->normalized && wa->componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE)
        wf = VertexFormat::Unorm8x4;
      else if (wa->type == TINYGLTF_TYPE_VEC4 && wa->normalized &&
               wa->componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT)
        wf = VertexFormat::Unorm16x4;
      else
        fail(file, fmt::format("{}: {} is {}; glTF weights are float or normalized unsigned byte/short VEC4", where,
                               wn, formatText(imp.attributes[infoIndex.at(wn)])));
      std::string jr = fmt::format("joints{}", s), wr = fmt::format("weights{}", s);
      rig.attributes.push_back(makeAttribute(jr, jf, {{fmt::format("skin.joints[{}]", s), ""}}, file));
      rig.attributes.push_back(makeAttribute(wr, wf, {{fmt::format("skin.weights[{}]", s), ""}}, file));
      carried(jn, jr, jf);
      carried(wn, wr, wf);
      AccessorData jd = readAttr(jn);
      for (size_t v = 0; v < jd.count; ++v)
        for (int c = 0; c < 4; ++c) {
          float j = jd.values[v * 4 + static_cast<size_t>(c)];
          if (j >= static_cast<float>(joints))
            fail(file, fmt::format("{}: {} of vertex {} is joint {}, but the skin has {} joints", where, jn, v,
                                   static_cast<long>(j), joints));
        }
      data.streams[fmt::format("skin.joints[{}]", s)] = reader.stream(jd, 0, 4, where + " attribute " + jn);
      data.streams[fmt::format("skin.weights[{}]", s)] = reader.stream(readAttr(wn), 0, 4, where + " attribute " + wn);
    }
  }

  // Every other attribute is reported as left out.
  for (const auto& [name, idx] : prim.attributes) {
    const auto& i = imp.attributes[infoIndex.at(name)];
    if (!i.rigAttribute.empty()) continue;
    if (name == "NORMAL" || name == "TANGENT" || name == "TEXCOORD_0" || name == "TEXCOORD_1" || name == "COLOR_0" ||
        name == "_OCCLUSION")
      continue;  // already reported
    if (name.rfind("JOINTS_", 0) == 0 || name.rfind("WEIGHTS_", 0) == 0) continue;  // unskinned (reported)
    skip(name, "the vocabulary has no semantic for it");
  }

  // Morph targets.
  int targets = static_cast<int>(prim.targets.size());
  imp.morphTargets = targets;
  std::set<std::string> moved;
  for (int t = 0; t < targets; ++t) {
    std::vector<std::string> names;
    for (const auto& [name, idx] : prim.targets[static_cast<size_t>(t)]) names.push_back(name);
    imp.targetAttributes.push_back(names);
    for (const auto& n : names) moved.insert(n);
  }
  struct MorphKind {
    const char* gltf;
    const char* rigName;  // "position" in rig.morphedAttributes
    const char* semantic;
    bool baseCarried;
    VertexFormat format = VertexFormat::Float32x3;  // of the deltas (float VEC3, or SCALAR)
  };
  std::vector<std::string> morphed;
  bool occlusionMorphed = false;  // baked occlusion deltas (docs/bake.md), like listing 3-3's normal.w
  for (const MorphKind& k : {MorphKind{"POSITION", "position", "morph.position", true},
                             MorphKind{"NORMAL", "normal", "morph.normal", hasNormal},
                             MorphKind{"TANGENT", "tangent", "morph.tangent", hasTangent},
                             MorphKind{"_OCCLUSION", "occlusion", "morph.occlusion", hasOcclusion,
                                       VertexFormat::Float32x1}}) {
    if (!moved.count(k.gltf)) continue;
    if (!k.baseCarried) {
      imp.notes.push_back(fmt::format("morph target {} deltas are left out: the rig does not carry {}", k.gltf, k.gltf));
      continue;
    }
    const int n = formatComponents(k.format);
    if (n == 1) occlusionMorphed = true;  // rig.morphedAttributes lists position, normal and tangent only
    else morphed.push_back(k.rigName);
    for (int t = 0; t < targets; ++t) {
      const auto& tm = prim.targets[static_cast<size_t>(t)];
      std::string key = fmt::format("{}[{}]", k.semantic, t);
      auto it = tm.find(k.gltf);
      if (it == tm.end()) {
        data.streams[key] = reader.zeros(data.vertexCount, where + " " + key);
        continue;
      }
      std::string what = fmt::format("{} morph target {} {}", where, t, k.gltf);
      if (it->second < 0 || static_cast<size_t>(it->second) >= model.accessors.size())
        fail(file, fmt::format("{} refers to accessor {}, which does not exist", what, it->second));
      const auto& a = model.accessors[static_cast<size_t>(it->second)];
      int type = n == 1 ? TINYGLTF_TYPE_SCALAR : TINYGLTF_TYPE_VEC3;
      if (a.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT || a.type != type)
        fail(file, fmt::format("{} is {}{} {}; only float {} deltas are supported", what,
                               a.normalized ? "normalized " : "", componentTypeName(a.componentType), typeName(a.type),
                               typeName(type)));
      if (a.count != data.vertexCount)
        fail(file, fmt::format("{} has {} elements but POSITION has {}", what, a.count, data.vertexCount));
      AccessorData d = reader.read(it->second, what);
      if (d.sparse)
        imp.notes.push_back(fmt::format("morph target {} {} is a sparse accessor: the application must expand it to "
                                        "a dense {} stream",
                                        t, k.gltf, formatName(k.format)));
      data.streams[key] = reader.stream(d, 0, n, what);
    }
    rig.attributes.push_back(makeAttribute(fmt::format("{}_morph", k.rigName), k.format, {{k.semantic, ""}}, file, true));
  }
  for (const auto& n : moved)
    if (n != "POSITION" && n != "NORMAL" && n != "TANGENT" && n != "_OCCLUSION")
      imp.notes.push_back(fmt::format("morph target {} deltas are left out: the vocabulary morphs position, normal "
                                      "and tangent only",
                                      n));
  int rigTargets = morphed.empty() && !occlusionMorphed ? 0 : targets;
  if (targets > 0 && rigTargets == 0)
    imp.notes.push_back(fmt::format("{} has {} morph target(s) but none moves an attribute the rig carries: imported "
                                    "without morphing",
                                    where, targets));
  rig.params["morph_targets"] = rigTargets;
  rig.morphedAttributes = morphed;
  data.meshWeights.assign(static_cast<size_t>(targets), 0.0);
  for (size_t i = 0; i < mesh.weights.size() && i < data.meshWeights.size(); ++i) data.meshWeights[i] = mesh.weights[i];

  // Dawn's layout (listing 3-1): occlusion in normal.w and its deltas in the normal deltas' w.
  if (opts.packOcclusionInNormal) {
    if (!hasOcclusion || !hasNormal)
      fail(file, fmt::format("{}: packing occlusion into normal.w needs NORMAL and _OCCLUSION (bake them with "
                             "'shadergen bake occlusion')",
                             where));
    auto merge = [&](const std::string& into, const std::string& from, const char* xyz, const char* w) {
      auto named = [&](const std::string& n) {
        return std::find_if(rig.attributes.begin(), rig.attributes.end(), [&](const RigAttribute& a) { return a.name == n; });
      };
      auto a = named(into);
      if (a == rig.attributes.end() || named(from) == rig.attributes.end()) return false;
      a->format = VertexFormat::Float32x4;
      a->shaderType = *vectorType(ScalarKind::Float, 4);
      a->provides = {{xyz, "xyz"}, {w, "w"}};
      rig.attributes.erase(named(from));
      return true;
    };
    merge("normal", "occlusion", "vertex.normal", "vertex.occlusion");
    imp.attributes[infoIndex.at("NORMAL")].format = formatName(VertexFormat::Float32x4);
    imp.attributes[infoIndex.at("_OCCLUSION")].rigAttribute = "normal (w)";
    imp.attributes[infoIndex.at("_OCCLUSION")].format = formatName(VertexFormat::Float32x4);
    if (occlusionMorphed && !merge("normal_morph", "occlusion_morph", "morph.normal", "morph.occlusion"))
      imp.notes.push_back("occlusion deltas stay a separate attribute: no morph target moves NORMAL");
  }

  // Uniforms.
  if (sets > 0) rig.uniforms.push_back(makeUniform("bones", "skin.bones", Type::Mat4, "bones", imp.joints, file));
  if (rigTargets > 0)
    rig.uniforms.push_back(makeUniform("morph_weights", "morph.weights", Type::Float, "morph_targets", rigTargets, file));
  rig.uniforms.push_back(makeUniform("camera_position", "camera.position", Type::Vec3, "", 0, file));
  rig.uniforms.push_back(makeUniform("view", "camera.view", Type::Mat4, "", 0, file));
  rig.uniforms.push_back(makeUniform("projection", "camera.projection", Type::Mat4, "", 0, file));
  if (sets == 0) rig.uniforms.push_back(makeUniform("model", "model.matrix", Type::Mat4, "", 0, file));
  noteDegenerateFrames(imp);
  if (modelScalesUniformly(imp.data)) rig.params["uniform_scale"] = 1;
  checkRig(rig);
  return imp;
}

// --- loading: the file, its JSON and its buffer files, checked before tinygltf sees them ---

// The first bracket nested deeper than kMaxGltfJsonDepth (1-based line and column), if any.
// tinygltf copies extras and extensions recursively, so depth is checked before parsing.
std::optional<std::pair<int, int>> tooDeep(const char* p, size_t n) {
  int depth = 0, line = 1, col = 1;
  bool inString = false, escaped = false;
  for (size_t i = 0; i < n; ++i) {
    char c = p[i];
    if (inString) {
      if (escaped) escaped = false;
      else if (c == '\\') escaped = true;
      else if (c == '"') inString = false;
    } else if (c == '"') {
      inString = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxGltfJsonDepth) return std::make_pair(line, col);
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
    if (c == '\n') {
      ++line;
      col = 1;
    } else {
      ++col;
    }
  }
  return std::nullopt;
}

// Reads a model or buffer file: regular files only (a FIFO or /dev/zero would block or never
// end), at most kMaxGltfFileBytes.
bool readBounded(const std::string& path, std::string& out, std::string& why) {
  std::error_code ec;
  auto st = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(st)) return why = "no such file", false;
  if (!std::filesystem::is_regular_file(st)) return why = "not a regular file", false;
  if (std::filesystem::file_size(path, ec) > kMaxGltfFileBytes)
    return why = fmt::format("larger than the limit of {}", mib(kMaxGltfFileBytes)), false;
  std::ifstream in(path, std::ios::binary);
  if (!in) return why = std::strerror(errno), false;
  out.clear();
  char chunk[65536];
  while (in) {
    in.read(chunk, sizeof chunk);
    out.append(chunk, static_cast<size_t>(in.gcount()));
    if (out.size() > kMaxGltfFileBytes)
      return why = fmt::format("larger than the limit of {}", mib(kMaxGltfFileBytes)), false;
  }
  if (in.bad()) return why = "read error", false;
  return true;
}

// Buffer files (uri: "x.bin") must resolve, symlinks followed, inside the model's folder: a
// model from elsewhere must not read /etc/passwd or ../../secrets into a shader's inputs.
struct BufferFiles {
  std::filesystem::path root;  // canonical model folder; empty: no buffer files at all
  std::string refused;         // the first refusal, reported instead of "File not found"
  size_t bytesRead = 0;        // all buffer files together stay under kMaxGltfFileBytes too
  std::vector<std::string> read;  // the buffer files read, in order (depfiles, cache keys)
};

bool insideRoot(BufferFiles& ctx, const std::string& path) {
  std::error_code ec;
  auto c = std::filesystem::weakly_canonical(path, ec);
  bool inside = !ec && !ctx.root.empty() &&
                std::mismatch(ctx.root.begin(), ctx.root.end(), c.begin(), c.end()).first == ctx.root.end();
  if (!inside && ctx.refused.empty())
    ctx.refused = ctx.root.empty()
                      ? fmt::format("buffer file '{}' refused: this model has no folder to read files from", path)
                      : fmt::format("buffer file '{}' lies outside the model's folder '{}'", path, ctx.root.string());
  return inside;
}

bool bufferFileExists(const std::string& path, void* user) {
  auto& ctx = *static_cast<BufferFiles*>(user);
  std::error_code ec;
  return (ctx.root.empty() || std::filesystem::exists(path, ec)) && insideRoot(ctx, path);
}
std::string keepPath(const std::string& path, void*) { return path; }
bool readBufferFile(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
  auto& ctx = *static_cast<BufferFiles*>(user);
  if (!insideRoot(ctx, path)) return false;
  std::string bytes, why;
  if (!readBounded(path, bytes, why)) {
    if (err) *err += why;
    return false;
  }
  ctx.bytesRead += bytes.size();
  ctx.read.push_back(path);
  if (ctx.bytesRead > kMaxGltfFileBytes) {
    if (err) *err += fmt::format("the buffer files together are larger than the limit of {}", mib(kMaxGltfFileBytes));
    return false;
  }
  out->assign(bytes.begin(), bytes.end());
  return true;
}
bool writeNothing(std::string*, const std::string&, const std::vector<unsigned char>&, void*) { return false; }

uint32_t le32(const std::string& b, size_t at) {
  uint32_t v;
  std::memcpy(&v, b.data() + at, 4);
  return v;  // glTF is little-endian, as is every host this builds for
}

// GLB layout checked with 64-bit arithmetic (tinygltf 2.7 lets a BIN chunk header run 8
// bytes past the end). Returns the JSON chunk.
std::pair<size_t, size_t> checkGlb(const std::string& b, const std::string& file) {
  if (b.size() < 20 || b.compare(0, 4, "glTF") != 0)
    fail(file, "not a binary glTF file (no 'glTF' header); a .glb must start with the GLB header");
  uint64_t length = le32(b, 8), json = le32(b, 12);
  if (le32(b, 4) != 2) fail(file, fmt::format("GLB version {} is not supported (only 2)", le32(b, 4)));
  if (length > b.size())
    fail(file, fmt::format("the GLB header claims {} bytes but the file has {}", length, b.size()));
  if (le32(b, 16) != 0x4E4F534A || json == 0 || 20 + json > length)
    fail(file, fmt::format("the GLB's first chunk must be JSON of at most {} bytes", length - 20));
  uint64_t bin = 20 + json;
  if (bin < length) {
    if (bin + 8 > length || bin + 8 + le32(b, static_cast<size_t>(bin)) > length)
      fail(file, fmt::format("the GLB's BIN chunk at byte {} runs past the end of the file ({} bytes)", bin, length));
  }
  return {20, static_cast<size_t>(json)};
}

// tinygltf's message, with nlohmann's "parse error at line L, column C" made a location.
[[noreturn]] void failLoad(const std::string& file, std::string err, bool glb, const BufferFiles& files) {
  if (!files.refused.empty()) fail(file, files.refused);
  while (!err.empty() && (err.back() == '\n' || err.back() == '\r')) err.pop_back();
  std::replace(err.begin(), err.end(), '\n', ' ');
  if (err.empty()) err = "unknown error";
  int line = 0, col = 0;
  auto at = err.find("parse error at line ");
  if (at != std::string::npos && std::sscanf(err.c_str() + at, "parse error at line %d, column %d", &line, &col) == 2) {
    auto colon = err.find(": ", at);
    std::string what = colon == std::string::npos ? err : err.substr(colon + 2);
    if (!glb) throw InputError(SourceLoc{file, line, col}, "invalid JSON: " + what);
    fail(file, fmt::format("invalid JSON in the GLB's JSON chunk at line {}, column {}: {}", line, col, what));
  }
  fail(file, "cannot load the glTF model: " + err);
}

// Reads and parses the model with every check; returns the bytes of the file and its buffers.
size_t loadChecked(const std::string& file, const std::string* text, const std::string& baseDir,
                   tinygltf::Model& model, std::vector<std::string>* buffersRead = nullptr) {
  std::string bytes, why;
  if (!text && !readBounded(file, bytes, why)) fail(file, "cannot read the glTF model: " + why);
  const std::string& b = text ? *text : bytes;
  if (b.size() > kMaxGltfFileBytes) fail(file, fmt::format("the glTF model is larger than {}", mib(kMaxGltfFileBytes)));
  bool glb = !text && lower(std::filesystem::path(file).extension().string()) == ".glb";
  auto [jsonAt, jsonSize] = glb ? checkGlb(b, file) : std::make_pair(size_t{0}, b.size());
  if (auto deep = tooDeep(b.data() + jsonAt, jsonSize)) {
    std::string msg = fmt::format("JSON nested deeper than {} levels", kMaxGltfJsonDepth);
    if (!glb) throw InputError(SourceLoc{file, deep->first, deep->second}, msg);
    fail(file, fmt::format("{} in the GLB's JSON chunk (line {}, column {})", msg, deep->first, deep->second));
  }

  BufferFiles files;
  std::string dir = text ? baseDir : std::filesystem::path(file).parent_path().string();
  if (!text && dir.empty()) dir = ".";
  std::error_code ec;
  if (!dir.empty()) files.root = std::filesystem::canonical(dir, ec);
  if (ec) files.root.clear();
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(skipImage, nullptr);
  loader.SetFsCallbacks(tinygltf::FsCallbacks{bufferFileExists, keepPath, readBufferFile, writeNothing, &files});
  std::string err, warn;
  const auto* data = reinterpret_cast<const unsigned char*>(b.data());
  std::string base = files.root.string();
  bool ok = glb ? loader.LoadBinaryFromMemory(&model, &err, &warn, data, static_cast<unsigned int>(b.size()), base)
                : loader.LoadASCIIFromString(&model, &err, &warn, b.data(), static_cast<unsigned int>(b.size()), base);
  if (!ok) failLoad(file, err, glb, files);
  if (buffersRead) *buffersRead = files.read;
  size_t input = b.size();
  for (const auto& buf : model.buffers) input += buf.data.size();
  return input;
}

// Decoded data in proportion to the input: what a few KB can claim stays small.
GltfImport importLoaded(const tinygltf::Model& model, const std::string& file, const GltfImportOptions& opts,
                        size_t inputBytes) {
  GltfImportOptions o = opts;
  inputBytes = std::min(inputBytes, kMaxGltfDecodedBytes);  // keeps the product below in range
  o.maxDecodedBytes = std::min(opts.maxDecodedBytes, kMinGltfDecodedBudget + inputBytes * kGltfDecodedPerInputByte);
  return importModel(model, file, o);
}

GltfImport loadAndImport(const std::string& file, const GltfImportOptions& opts, const std::string* text,
                         const std::string& baseDir) {
  tinygltf::Model model;
  std::vector<std::string> buffers;
  size_t input = loadChecked(file, text, baseDir, model, &buffers);
  GltfImport imp = importLoaded(model, file, opts, input);
  if (!text) imp.rig.sourceFiles.push_back(file);
  imp.rig.sourceFiles.insert(imp.rig.sourceFiles.end(), buffers.begin(), buffers.end());
  return imp;
}

std::string yamlQuote(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    unsigned char u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (u < 0x20) {
      out += fmt::format("\\x{:02x}", u);
    } else {
      out += c;
    }
  }
  return out + "\"";
}

}  // namespace

bool isGltfPath(const std::string& path) {
  std::string p = path;
  auto hash = p.rfind('#');
  if (hash != std::string::npos) p = p.substr(0, hash);
  std::string ext = lower(std::filesystem::path(p).extension().string());
  return ext == ".gltf" || ext == ".glb";
}

GltfRef parseGltfRef(const std::string& path) {
  GltfRef r;
  auto hash = path.rfind('#');
  std::string base = hash == std::string::npos ? path : path.substr(0, hash);
  std::string ext = lower(std::filesystem::path(base).extension().string());
  if (hash != std::string::npos && (ext == ".gltf" || ext == ".glb")) {
    r.file = base;
    if (!parseSelection(path.substr(hash + 1), r.mesh, r.primitive))
      fail(base, fmt::format("'{}' does not select a primitive: expected MODEL{}#MESH/PRIMITIVE, e.g. '{}#0/0'",
                             path.substr(hash), ext, base));
  } else {
    r.file = path;
  }
  return r;
}

size_t loadGltfModel(const std::string& file, tinygltf::Model& model) { return loadChecked(file, nullptr, "", model); }

GltfImport importGltfModel(const tinygltf::Model& model, size_t inputBytes, const std::string& file,
                           const GltfImportOptions& opts) {
  return importLoaded(model, file, opts, inputBytes);
}

GltfImport importGltf(const std::string& file, const GltfImportOptions& opts) {
  return loadAndImport(file, opts, nullptr, "");
}

GltfImport importGltfText(const std::string& json, const std::string& fileName, const GltfImportOptions& opts,
                          const std::string& baseDir) {
  return loadAndImport(fileName, opts, &json, baseDir);
}

Rig loadRig(const std::string& path) {
  if (!isGltfPath(path)) return loadRigFile(path);
  GltfRef ref = parseGltfRef(path);
  GltfImportOptions o;
  o.mesh = ref.mesh;
  o.primitive = ref.primitive;
  return importGltf(ref.file, o).rig;
}

std::string rigToYaml(const Rig& rig, const std::vector<std::string>& header) {
  std::string s;
  for (std::string h : header) {
    std::replace(h.begin(), h.end(), '\n', ' ');
    std::replace(h.begin(), h.end(), '\r', ' ');
    s += h.empty() ? "#\n" : "# " + h + "\n";
  }
  s += "rig: " + yamlQuote(rig.name) + "\n";
  s += "deformers:\n";
  std::vector<std::string> order{"bones", "influences", "morph_targets"};
  for (const auto& [k, v] : rig.params)
    if (std::find(order.begin(), order.end(), k) == order.end()) order.push_back(k);
  for (const auto& k : order) s += fmt::format("  {}: {}\n", k, rig.param(k));
  if (!rig.morphedAttributes.empty()) {
    std::string list;
    for (const auto& m : rig.morphedAttributes) list += (list.empty() ? "" : ", ") + m;
    s += "  morphs: [" + list + "]\n";
  }
  s += "attributes:\n";
  for (const auto& a : rig.attributes) {
    std::string prov;
    if (a.provides.size() == 1 && a.provides[0].swizzle.empty()) {
      prov = yamlQuote(a.provides[0].semantic);
    } else {
      for (const auto& p : a.provides)
        prov += (prov.empty() ? "{ " : ", ") + yamlQuote(p.semantic) + ": " +
                (p.swizzle.empty() ? std::string("xyzw").substr(0, static_cast<size_t>(formatComponents(a.format)))
                                   : p.swizzle);
      prov += " }";
    }
    s += fmt::format("  {}: {{ format: {}{}, provides: {} }}\n", a.name, formatName(a.format),
                     a.perMorphTarget ? ", per_target: true" : "", prov);
  }
  if (!rig.uniforms.empty()) {
    s += "uniforms:\n";
    for (const auto& u : rig.uniforms)
      s += fmt::format("  {}: {{ type: {}{}, semantic: {} }}\n", u.name, glslName(u.type),
                       u.arraySizeParam.empty() ? "" : ", array: " + u.arraySizeParam, yamlQuote(u.semantic));
  }
  return s;
}

}  // namespace sg

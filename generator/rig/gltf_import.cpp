// glTF 2.0 → rig (docs/gltf.md): derives the rig of one primitive from the decoded model.
// Loading is gltf_load.cpp, accessor decoding gltf_accessor.cpp, the scene gltf_scene.cpp.
#include "rig/gltf_import.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <optional>
#include <set>

#include "rig/gltf_accessor.h"
#include "rig/gltf_load.h"
#include "rig/gltf_meshopt.h"
#include "rig/gltf_scene.h"
#include "rig/skin_weights.h"

namespace sg {
namespace {

// The rig's name, "<stem>/<mesh>/<primitive>", as a rig file must spell it (rig_loader.cpp:
// one printable line of at most kMaxRigNameBytes), since `rig import` writes it into YAML
// that is read back: glTF names may hold control characters and be any length. Control
// characters become '?'; a long name is cut at a UTF-8 character boundary.
std::string gltfRigName(const std::string& stem, const std::string& mesh, int primitive) {
  std::string name = stem + "/" + mesh;
  for (char& c : name)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  const std::string tail = fmt::format("/{}", primitive);
  if (name.size() + tail.size() > kMaxRigNameBytes) {
    size_t cut = kMaxRigNameBytes - tail.size();
    while (cut > 0 && (static_cast<unsigned char>(name[cut]) & 0xC0) == 0x80) --cut;  // a continuation byte
    name.resize(cut);
  }
  return name + tail;
}

using gltf::AccessorData;
using gltf::componentTypeName;
using gltf::fail;
using gltf::loadChecked;
using gltf::lower;
using gltf::Reader;
using gltf::typeName;

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

// uniform_scale (docs/rig-format.md) when no node, GPU instance, scale animation or inverse
// bind matrix of the model scales per axis: then mat3(M) is a valid normal matrix.
bool modelScalesUniformly(const GltfModelData& d) {
  for (const auto& n : d.nodes) {
    if (n.hasMatrix ? !isSimilarity(n.matrix.data(), 4) : !uniformScale3(n.scale[0], n.scale[1], n.scale[2])) return false;
    for (const auto& m : n.instances)
      if (!isSimilarity(m.data(), 4)) return false;
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

// ---- import diagnostics (docs/gltf.md#import-diagnostics-and-weights) ----------------------
// What changes a vertex program's result, with the Khronos glTF-Validator's code and threshold
// where it has one, so a finding of the validator on a model is a finding of the import too.

// Where an attribute is, in the validator's terms: "WEIGHTS_0 (accessor 12,
// /meshes/3/primitives/1/attributes/WEIGHTS_0)".
std::string attributeText(const tinygltf::Primitive& prim, int mesh, int primitive, const std::string& name) {
  return fmt::format("{} (accessor {}, /meshes/{}/primitives/{}/attributes/{})", name, prim.attributes.at(name), mesh,
                     primitive, name);
}

void warn(Rig& rig, const std::string& file, const char* code, std::string message, Severity s = Severity::Warning) {
  rig.importDiagnostics.push_back(Diagnostic{s, SourceLoc{file, 0, 0}, std::move(message), code});
}

// The validator's unit-length tolerance for a normal or tangent (ACCESSOR_VECTOR3_NON_UNIT).
constexpr double kUnitVectorTolerance = 0.00674;

// NORMAL and TANGENT of unit length, TANGENT.w exactly +1 or -1 (ACCESSOR_VECTOR3_NON_UNIT,
// ACCESSOR_INVALID_SIGN). The program reads them as stored.
void checkFrames(GltfImport& imp, const tinygltf::Primitive& prim, const std::string& where) {
  const auto& st = imp.data.streams;
  auto text = [&](const std::string& name) { return attributeText(prim, imp.data.mesh, imp.data.primitive, name); };
  for (const auto& [semantic, name] : {std::pair<const char*, const char*>{"vertex.normal", "NORMAL"},
                                       std::pair<const char*, const char*>{"vertex.tangent", "TANGENT"}}) {
    auto it = st.find(semantic);
    if (it == st.end()) continue;
    size_t bad = 0, first = 0;
    double worst = 1;
    for (size_t v = 0; v < it->second.size(); ++v) {
      const auto& x = it->second[v];
      const double len = std::sqrt(double(x[0]) * x[0] + double(x[1]) * x[1] + double(x[2]) * x[2]);
      if (std::abs(len - 1) <= kUnitVectorTolerance) continue;
      if (bad++ == 0) first = v;
      if (std::abs(len - 1) > std::abs(worst - 1)) worst = len;
    }
    if (bad)
      warn(imp.rig, imp.data.file, "ACCESSOR_VECTOR3_NON_UNIT",
           fmt::format("{}, {}: {} of {} vertices are not of unit length (first: vertex {}; the farthest from 1: "
                       "length {:.6g}); the program reads them as stored, so a {} of length 0 has no direction",
                       where, text(name), bad, it->second.size(), first, worst, name));
  }
  auto w = st.find("vertex.handedness");
  if (w == st.end()) return;
  size_t bad = 0, first = 0;
  float value = 0;
  for (size_t v = 0; v < w->second.size(); ++v)
    if (w->second[v][0] != 1.0f && w->second[v][0] != -1.0f)
      if (bad++ == 0) first = v, value = w->second[v][0];
  if (bad)
    warn(imp.rig, imp.data.file, "ACCESSOR_INVALID_SIGN",
         fmt::format("{}, {}: TANGENT.w of {} of {} vertices is not +1 or -1 (first: vertex {}, {}); it is the "
                     "bitangent's sign, and the program scales the bitangent by it",
                     where, text("TANGENT"), bad, w->second.size(), first, value));
}

// The skin's JOINTS_n/WEIGHTS_n of every vertex (`sets` sets, streams read): negative weights,
// one joint weighted twice, weights that do not sum to one (renormalised when `normalize`),
// with the validator's test (rig/skin_weights.h). `steps`: 2^bits - 1 when every weight set is
// unorm of that many bits (the renormalised codes then sum to exactly that), else 0.
void checkSkinWeights(GltfImport& imp, const tinygltf::Primitive& prim, const std::string& where, int sets,
                      double steps, bool normalize) {
  GltfModelData& d = imp.data;
  std::vector<std::vector<std::array<float, 4>>*> joints, weights;
  std::string jointNames, weightNames;
  for (int s = 0; s < sets; ++s) {
    joints.push_back(&d.streams.at(fmt::format("skin.joints[{}]", s)));
    weights.push_back(&d.streams.at(fmt::format("skin.weights[{}]", s)));
    const std::string sep = s ? ", " : "";
    jointNames += sep + attributeText(prim, d.mesh, d.primitive, fmt::format("JOINTS_{}", s));
    weightNames += sep + attributeText(prim, d.mesh, d.primitive, fmt::format("WEIGHTS_{}", s));
  }
  const size_t n = static_cast<size_t>(sets) * 4;
  std::vector<float> w(n);
  std::vector<double> renormalised(n);
  size_t negative = 0, firstNegative = 0, twice = 0, firstTwice = 0, off = 0, firstOff = 0;
  double worstSum = 1;
  float twiceJoint = 0;
  for (size_t v = 0; v < d.vertexCount; ++v) {
    for (size_t k = 0; k < n; ++k) w[k] = (*weights[k / 4])[v][k % 4];
    bool neg = false, dup = false;
    for (size_t k = 0; k < n; ++k) {
      neg = neg || w[k] < 0;
      if (w[k] == 0) continue;
      for (size_t e = 0; e < k; ++e)
        if (w[e] != 0 && (*joints[e / 4])[v][e % 4] == (*joints[k / 4])[v][k % 4]) {
          if (!dup && twice == 0) twiceJoint = (*joints[k / 4])[v][k % 4];
          dup = true;
        }
    }
    if (neg && negative++ == 0) firstNegative = v;
    if (dup && twice++ == 0) firstTwice = v;
    if (skinWeightsNormalized(w.data(), n)) continue;
    double sum = 0;
    for (float x : w) sum += x;
    if (off++ == 0) firstOff = v;
    if (std::abs(sum - 1) > std::abs(worstSum - 1)) worstSum = sum;
    if (!normalize) continue;
    for (size_t k = 0; k < n; ++k) renormalised[k] = w[k];
    normalizeSkinWeights(renormalised.data(), n, steps);
    for (size_t k = 0; k < n; ++k) (*weights[k / 4])[v][k % 4] = static_cast<float>(renormalised[k]);
  }
  if (negative)
    warn(imp.rig, d.file, "ACCESSOR_WEIGHTS_NEGATIVE",
         fmt::format("{}, {}: {} of {} vertices have a negative weight (first: vertex {}); the program blends "
                     "with it as stored",
                     where, weightNames, negative, d.vertexCount, firstNegative));
  if (twice)
    warn(imp.rig, d.file, "ACCESSOR_JOINTS_INDEX_DUPLICATE",
         fmt::format("{}, {}: {} of {} vertices weight one joint twice (first: vertex {}, joint {}); a linear "
                     "blend adds the two weights",
                     where, jointNames, twice, d.vertexCount, firstTwice, twiceJoint));
  if (off)
    warn(imp.rig, d.file, "ACCESSOR_WEIGHTS_NON_NORMALIZED",
         fmt::format("{}, {}: the weights of {} of {} vertices do not sum to 1 (first: vertex {}; the farthest "
                     "from 1: {:.6g}); {}",
                     where, weightNames, off, d.vertexCount, firstOff, worstSum,
                     normalize ? "renormalised to sum to 1, as three.js and Filament's viewers do "
                                 "(--no-normalize-weights keeps them)"
                               : "kept as stored (--no-normalize-weights): the skin there is scaled by the sum, "
                                 "where three.js and Filament's viewers renormalise"));
}

// The mesh's skinned nodes ignore their own and their parents' transforms (glTF 2.0, 3.7.3):
// posed as the spec says, which engines that apply them do not (NODE_SKINNED_MESH_NON_ROOT,
// NODE_SKINNED_MESH_LOCAL_TRANSFORMS). Notes: the data is valid.
void noteSkinnedNodeTransforms(GltfImport& imp, const tinygltf::Model& model, const std::string& meshDesc) {
  std::vector<char> child(model.nodes.size(), 0);
  for (const auto& n : model.nodes)
    for (int c : n.children) child[static_cast<size_t>(c)] = 1;
  for (size_t i = 0; i < model.nodes.size(); ++i) {
    const GltfNode& n = imp.data.nodes[i];
    if (n.mesh != imp.data.mesh || n.skin < 0) continue;
    if (child[i])
      warn(imp.rig, imp.data.file, "NODE_SKINNED_MESH_NON_ROOT",
           fmt::format("node {} (/nodes/{}) instantiates {} with a skin and has a parent: the parent's transform "
                       "does not move a skinned mesh (glTF 2.0), and it is posed without it",
                       i, i, meshDesc),
           Severity::Note);
    const tinygltf::Node& t = model.nodes[i];
    if (!t.matrix.empty() || !t.translation.empty() || !t.rotation.empty() || !t.scale.empty())
      warn(imp.rig, imp.data.file, "NODE_SKINNED_MESH_LOCAL_TRANSFORMS",
           fmt::format("node {} (/nodes/{}) instantiates {} with a skin and has a transform: it does not move a "
                       "skinned mesh (glTF 2.0), and it is posed without it",
                       i, i, meshDesc),
           Severity::Note);
  }
}

// -Werror: every warning of the import as one error.
void throwWarnings(const Rig& rig) {
  std::vector<Diagnostic> errors;
  for (Diagnostic d : rig.importDiagnostics)
    if (d.severity == Severity::Warning) {
      d.severity = Severity::Error;
      d.message += " (-Werror)";
      errors.push_back(std::move(d));
    }
  if (errors.empty()) return;
  InputError e(errors.front());
  e.related.assign(errors.begin() + 1, errors.end());
  throw e;
}

// The storage KHR_mesh_quantization's table allows an attribute (float always). Integers are
// read as the GPU reads them (gltf_accessor.cpp) and re-expanded to float for the shader.
enum class Storage {
  Float,             // float only (core glTF)
  SignedNormalized,  // + normalized byte/short (NORMAL, TANGENT and their deltas)
  Signed,            // + byte/short, normalized or not (POSITION and TEXCOORD deltas)
  Any,               // + (unsigned) byte/short, normalized or not (POSITION, TEXCOORD_n)
};
bool storageAllowed(const tinygltf::Accessor& a, int type, Storage s) {
  if (a.type != type) return false;
  const int ct = a.componentType;
  if (ct == TINYGLTF_COMPONENT_TYPE_FLOAT) return true;
  const bool isSigned = ct == TINYGLTF_COMPONENT_TYPE_BYTE || ct == TINYGLTF_COMPONENT_TYPE_SHORT;
  const bool isUnsigned = ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE || ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
  switch (s) {
    case Storage::Float: return false;
    case Storage::SignedNormalized: return isSigned && a.normalized;
    case Storage::Signed: return isSigned;
    case Storage::Any: return isSigned || isUnsigned;
  }
  return false;
}

// The vertex format that holds a normalized integer accessor as stored (a VEC3 in the x4
// form: glTF aligns each element to 4 bytes, so the fourth component is the padding), or
// none: float, and integers read unnormalized, which need a decode the rig cannot state yet.
std::optional<VertexFormat> storedFormat(const tinygltf::Accessor& a) {
  if (!a.normalized || (a.type != TINYGLTF_TYPE_VEC2 && a.type != TINYGLTF_TYPE_VEC3 && a.type != TINYGLTF_TYPE_VEC4))
    return std::nullopt;
  const bool two = a.type == TINYGLTF_TYPE_VEC2;
  switch (a.componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: return two ? VertexFormat::Snorm8x2 : VertexFormat::Snorm8x4;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return two ? VertexFormat::Unorm8x2 : VertexFormat::Unorm8x4;
    case TINYGLTF_COMPONENT_TYPE_SHORT: return two ? VertexFormat::Snorm16x2 : VertexFormat::Snorm16x4;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return two ? VertexFormat::Unorm16x2 : VertexFormat::Unorm16x4;
    default: return std::nullopt;
  }
}
const char* storageText(Storage s) {
  switch (s) {
    case Storage::Float: return "float";
    case Storage::SignedNormalized: return "float, or normalized byte or short (KHR_mesh_quantization)";
    case Storage::Signed: return "float, or byte or short, normalized or not (KHR_mesh_quantization)";
    case Storage::Any: return "float, or (unsigned) byte or short, normalized or not (KHR_mesh_quantization)";
  }
  return "";
}

GltfImport importModel(const tinygltf::Model& model, const std::string& file, const GltfImportOptions& opts) {
  GltfImport imp;
  GltfModelData& data = imp.data;
  data.file = file;
  data.stem = std::filesystem::path(file).stem().string();
  Reader reader(model, file, opts.maxDecodedBytes);
  if (size_t decompressed = gltf::fallbackBytes(model))
    reader.charge(decompressed, 1, "the buffers EXT_meshopt_compression decompressed into");

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
  gltf::readScene(model, file, opts.mesh, meshDesc, reader, data, imp.notes, imp.rig.importDiagnostics);


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
  rig.name = gltfRigName(data.stem, data.meshName, opts.primitive);
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
  // Quantized storage the table allows: noted, then read (dequantized) as float. `asStored`:
  // the rig's format for it when a vertex format holds it as stored (storedFormat), else float.
  auto stored = [&](const std::string& name, const tinygltf::Accessor* a, int type, Storage st,
                    std::optional<VertexFormat> asStored = std::nullopt) {
    if (!storageAllowed(*a, type, st)) return false;
    if (a->componentType != TINYGLTF_COMPONENT_TYPE_FLOAT)
      imp.notes.push_back(
          asStored ? fmt::format("{} is stored {} (KHR_mesh_quantization): fed to the shader as stored, {}", name,
                                 formatText(imp.attributes[infoIndex.at(name)]), formatName(*asStored))
                   : fmt::format("{} is stored {} (KHR_mesh_quantization): expanded to float for the shader", name,
                                 formatText(imp.attributes[infoIndex.at(name)])));
    return true;
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
      for (size_t i = 0; i < idx.values.size(); ++i)
        if (const float v = idx.values[i]; !(v >= 0.0f) || static_cast<size_t>(v) >= data.vertexCount)
          fail(file, fmt::format("{}: index {} (element {}) is out of range ({} vertices)", where, v, i, data.vertexCount));
      data.indices.assign(idx.values.begin(), idx.values.end());
    } catch (const InputError& e) {
      data.indices.clear();
      data.indicesError = e.diagnostic().message;
    }
  }

  // POSITION
  if (!stored("POSITION", posAcc, TINYGLTF_TYPE_VEC3, Storage::Any))
    fail(file, fmt::format("{}: POSITION is {}; positions are VEC3 of {}", where,
                           formatText(imp.attributes[infoIndex.at("POSITION")]), storageText(Storage::Any)));
  rig.attributes.push_back(makeAttribute("position", VertexFormat::Float32x3, {{"vertex.position", ""}}, file));
  carried("POSITION", "position", VertexFormat::Float32x3);
  data.streams["vertex.position"] = reader.stream(readAttr("POSITION"), 0, 3, where + " attribute POSITION");

  bool hasNormal = false, hasTangent = false;
  if (const auto* a = accessorOf("NORMAL")) {
    const std::optional<VertexFormat> asStored = storedFormat(*a);
    if (stored("NORMAL", a, TINYGLTF_TYPE_VEC3, Storage::SignedNormalized, asStored)) {
      hasNormal = true;
      const VertexFormat f = asStored.value_or(VertexFormat::Float32x3);
      rig.attributes.push_back(makeAttribute("normal", f, {{"vertex.normal", asStored ? "xyz" : ""}}, file));
      carried("NORMAL", "normal", f);
      data.streams["vertex.normal"] = reader.stream(readAttr("NORMAL"), 0, 3, where + " attribute NORMAL");
    } else {
      skip("NORMAL", fmt::format("normals are VEC3 of {}", storageText(Storage::SignedNormalized)));
    }
  }
  if (const auto* a = accessorOf("TANGENT")) {
    const std::optional<VertexFormat> asStored = storedFormat(*a);
    if (stored("TANGENT", a, TINYGLTF_TYPE_VEC4, Storage::SignedNormalized, asStored)) {
      hasTangent = true;
      const VertexFormat f = asStored.value_or(VertexFormat::Float32x4);
      rig.attributes.push_back(makeAttribute("tangent", f, {{"vertex.tangent", "xyz"}, {"vertex.handedness", "w"}}, file));
      carried("TANGENT", "tangent", f);
      AccessorData d = readAttr("TANGENT");
      data.streams["vertex.tangent"] = reader.stream(d, 0, 3, where + " attribute TANGENT");
      data.streams["vertex.handedness"] = reader.stream(d, 3, 1, where + " attribute TANGENT");
    } else {
      skip("TANGENT", fmt::format("tangents are VEC4 of {}", storageText(Storage::SignedNormalized)));
    }
  }
  for (int t = 0; t < 2; ++t) {
    std::string name = fmt::format("TEXCOORD_{}", t);
    if (const auto* a = accessorOf(name)) {
      const std::optional<VertexFormat> asStored = storedFormat(*a);
      if (stored(name, a, TINYGLTF_TYPE_VEC2, Storage::Any, asStored)) {
        std::string rn = fmt::format("texcoord{}", t);
        const VertexFormat f = asStored.value_or(VertexFormat::Float32x2);
        rig.attributes.push_back(makeAttribute(rn, f, {{fmt::format("vertex.texcoord{}", t), ""}}, file));
        carried(name, rn, f);
        data.streams[fmt::format("vertex.texcoord{}", t)] = reader.stream(readAttr(name), 0, 2, where + " attribute " + name);
      } else {
        skip(name, fmt::format("texture coordinates are VEC2 of {}", storageText(Storage::Any)));
      }
    }
  }
  if (const auto* a = accessorOf("COLOR_0")) {
    std::optional<VertexFormat> f;
    const bool rgb = a->type == TINYGLTF_TYPE_VEC3;
    if (a->type == TINYGLTF_TYPE_VEC4) {
      if (a->componentType == TINYGLTF_COMPONENT_TYPE_FLOAT) f = VertexFormat::Float32x4;
      else if (a->componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && a->normalized) f = VertexFormat::Unorm8x4;
      else if (a->componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT && a->normalized) f = VertexFormat::Unorm16x4;
    } else if (rgb && a->componentType == TINYGLTF_COMPONENT_TYPE_FLOAT) {
      f = VertexFormat::Float32x3;  // read as a vec4: the device supplies alpha 1, as glTF means
    }
    if (f) {
      RigAttribute attr = makeAttribute("color0", *f, {{"vertex.color0", ""}}, file);
      attr.shaderType = Type::Vec4;
      attr.widened = rgb;
      rig.attributes.push_back(std::move(attr));
      carried("COLOR_0", "color0", *f);
      auto colours = reader.stream(readAttr("COLOR_0"), 0, rgb ? 3 : 4, where + " attribute COLOR_0");
      if (rgb)
        for (auto& c : colours) c[3] = 1.0f;
      data.streams["vertex.color0"] = std::move(colours);
    } else {
      // Normalized RGB bytes or shorts are padded to 4 bytes per element: no 3-component format reads them.
      skip("COLOR_0", rgb ? "vertex.color0 is a vec4; RGB colours are read as float VEC3 (alpha 1), not as normalized "
                            "integers (their alignment padding would read as alpha)"
                          : "vertex.color0 is a vec4 of float, or of normalized unsigned byte or short");
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
  // Every other node instantiating the mesh with a skin: the joints must fit each skin.
  std::vector<std::pair<int, int>> instanceSkins;  // (node, skin)
  for (size_t n = 0; n < data.nodes.size(); ++n) {
    const GltfNode& node = data.nodes[n];
    if (node.mesh != data.mesh || node.skin < 0 || static_cast<int>(n) == data.meshNode) continue;
    if (static_cast<size_t>(node.skin) >= data.skins.size())
      fail(file, fmt::format("node {} instantiates {} with skin {}, which does not exist", n, meshDesc, node.skin));
    instanceSkins.emplace_back(static_cast<int>(n), node.skin);
  }
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
      fail(file, fmt::format("{} uses {} joints; the bone palette holds at most {} (kMaxBones)", meshDesc, joints,
                             opts.maxBones));
    data.skin = skinIndex;
    imp.joints = joints;
    imp.influences = 4 * sets;
    rig.params["bones"] = joints;
    rig.params["influences"] = imp.influences;
    std::set<int> unormBits;  // of the weight sets (0: float)
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
            throw InputError(Diagnostic{Severity::Error, SourceLoc{file, 0, 0},
                                        fmt::format("{}: {} of vertex {} is joint {}, but the skin has {} joints", where,
                                                    attributeText(prim, data.mesh, data.primitive, jn), v,
                                                    static_cast<long>(j), joints),
                                        "ACCESSOR_JOINTS_INDEX_OOB"});
          for (const auto& [node, skin] : instanceSkins) {
            const size_t size = data.skins[static_cast<size_t>(skin)].joints.size();
            if (j >= static_cast<float>(size))
              throw InputError(Diagnostic{
                  Severity::Error, SourceLoc{file, 0, 0},
                  fmt::format("{}: {} of vertex {} is joint {}, but skin {} (of node {}) has {} joints", where,
                              attributeText(prim, data.mesh, data.primitive, jn), v, static_cast<long>(j), skin, node,
                              size),
                  "ACCESSOR_JOINTS_INDEX_OOB"});
          }
        }
      data.streams[fmt::format("skin.joints[{}]", s)] = reader.stream(jd, 0, 4, where + " attribute " + jn);
      data.streams[fmt::format("skin.weights[{}]", s)] = reader.stream(readAttr(wn), 0, 4, where + " attribute " + wn);
      unormBits.insert(wf == VertexFormat::Unorm8x4 ? 8 : wf == VertexFormat::Unorm16x4 ? 16 : 0);
    }
    const int bits = unormBits.size() == 1 ? *unormBits.begin() : 0;
    checkSkinWeights(imp, prim, where, sets, bits ? std::ldexp(1.0, bits) - 1 : 0, opts.read.normalizeWeights);
    rig.skinWeights = opts.read.normalizeWeights ? "normalized" : "stored";
    noteSkinnedNodeTransforms(imp, model, meshDesc);
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
    Storage storage = Storage::Float;                // quantized deltas the table allows
  };
  std::vector<std::string> morphed;
  bool occlusionMorphed = false;  // baked occlusion deltas (docs/bake.md), like listing 3-3's normal.w
  for (const MorphKind& k :
       {MorphKind{"POSITION", "position", "morph.position", true, VertexFormat::Float32x3, Storage::Signed},
        MorphKind{"NORMAL", "normal", "morph.normal", hasNormal, VertexFormat::Float32x3, Storage::SignedNormalized},
        MorphKind{"TANGENT", "tangent", "morph.tangent", hasTangent, VertexFormat::Float32x3, Storage::SignedNormalized},
        MorphKind{"_OCCLUSION", "occlusion", "morph.occlusion", hasOcclusion, VertexFormat::Float32x1}}) {
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
      if (!storageAllowed(a, type, k.storage))
        fail(file, fmt::format("{} is {}{} {}; deltas are {} of {}", what, a.normalized ? "normalized " : "",
                               componentTypeName(a.componentType), typeName(a.type), typeName(type),
                               storageText(k.storage)));
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
  checkFrames(imp, prim, where);
  if (modelScalesUniformly(imp.data)) rig.params["uniform_scale"] = 1;
  checkRig(rig);
  if (opts.read.warningsAsErrors) throwWarnings(rig);
  return imp;
}


// Decoded data in proportion to the input: what a few KB can claim stays small.
GltfImport importLoaded(const tinygltf::Model& model, const std::string& file, const GltfImportOptions& opts,
                        size_t inputBytes) {
  GltfImportOptions o = opts;
  o.maxDecodedBytes = gltf::decodedBudget(inputBytes, opts.maxDecodedBytes);
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

bool isWholeModelRef(const std::string& path) { return path.size() >= 2 && path.compare(path.size() - 2, 2, "#*") == 0; }

GltfRef parseGltfRef(const std::string& path, bool allowWholeModel) {
  GltfRef r;
  auto hash = path.rfind('#');
  std::string base = hash == std::string::npos ? path : path.substr(0, hash);
  std::string ext = lower(std::filesystem::path(base).extension().string());
  if (hash != std::string::npos && (ext == ".gltf" || ext == ".glb")) {
    r.file = base;
    if (path.substr(hash) == "#*") {
      if (!allowWholeModel)
        fail(base, fmt::format("'{}' names every primitive of the model; this command takes one: {}#MESH/PRIMITIVE, "
                               "e.g. '{}#0/0' (validate, generate, render, rig import and build take the whole model)",
                               path, base, base));
      r.wholeModel = true;
    } else if (!parseSelection(path.substr(hash + 1), r.mesh, r.primitive)) {
      fail(base, fmt::format("'{}' does not select a primitive: expected MODEL{}#MESH/PRIMITIVE (e.g. '{}#0/0') or "
                             "MODEL{}#* (every primitive)",
                             path.substr(hash), ext, base, ext));
    }
  } else {
    r.file = path;
  }
  return r;
}

std::vector<int> gltfSceneNodes(const GltfModelData& data) {
  std::vector<int> order;
  std::vector<int> todo(data.sceneRoots.rbegin(), data.sceneRoots.rend());
  std::vector<char> seen(data.nodes.size(), 0);
  while (!todo.empty()) {
    int n = todo.back();
    todo.pop_back();
    if (seen[static_cast<size_t>(n)]) continue;
    seen[static_cast<size_t>(n)] = 1;
    order.push_back(n);
    const auto& children = data.nodes[static_cast<size_t>(n)].children;
    todo.insert(todo.end(), children.rbegin(), children.rend());
  }
  return order;
}

std::string gltfPartName(int mesh, int primitive, const std::string& meshName) {
  std::string name = fmt::format("m{}p{}", mesh, primitive);
  if (meshName.empty()) return name;
  std::string safe = meshName.substr(0, 48);
  for (char& c : safe)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '_' && c != '-') c = '_';
  return name + "-" + safe;
}

std::vector<GltfPart> gltfParts(const std::string& file) {
  tinygltf::Model model;
  loadChecked(file, nullptr, "", model);
  std::vector<GltfPart> parts;
  size_t total = 0;
  for (const auto& m : model.meshes) total += m.primitives.size();
  if (total == 0)
    fail(file, fmt::format("'{}#*' names every mesh primitive of the model, and it has none ({} mesh(es))", file,
                           model.meshes.size()));
  if (total > kMaxGltfParts)
    fail(file, fmt::format("the model has {} mesh primitives; a whole model (#*) takes at most {} (kMaxGltfParts)",
                           total, kMaxGltfParts));
  for (size_t m = 0; m < model.meshes.size(); ++m)
    for (size_t p = 0; p < model.meshes[m].primitives.size(); ++p) {
      GltfPart part;
      part.mesh = static_cast<int>(m);
      part.primitive = static_cast<int>(p);
      part.meshName = model.meshes[m].name;
      part.name = gltfPartName(part.mesh, part.primitive, part.meshName);
      part.ref = fmt::format("{}#{}/{}", file, m, p);
      parts.push_back(std::move(part));
    }
  return parts;
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

GltfImport importGltfRef(const std::string& refText, const GltfReadOptions& read) {
  const GltfRef ref = parseGltfRef(refText);
  GltfImportOptions o;
  o.read = read;
  o.mesh = ref.mesh;
  o.primitive = ref.primitive;
  return importGltf(ref.file, o);
}

Rig loadRig(const std::string& path, const GltfReadOptions& read) {
  if (!isGltfPath(path)) return loadRigFile(path);
  GltfImport imp = importGltfRef(path, read);
  imp.rig.importNotes = std::move(imp.notes);
  return std::move(imp.rig);
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
                (p.swizzle.empty() ? std::string("xyzw").substr(0, static_cast<size_t>(a.widened ? componentCount(a.shaderType)
                                                                                          : formatComponents(a.format)))
                                   : p.swizzle);
      prov += " }";
    }
    s += fmt::format("  {}: {{ format: {}{}{}, provides: {} }}\n", a.name, formatName(a.format),
                     a.widened ? ", shader_type: " + std::string(glslName(a.shaderType)) : "",
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

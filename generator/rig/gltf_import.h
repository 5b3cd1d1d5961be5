// Rigs from real glTF 2.0 models (docs/gltf.md): derive the rig of one mesh primitive
// (attributes and formats, skin size, influences, morph targets) and decode everything the
// validator needs to pose it (vertex data with sparse accessors applied and normalized
// formats dequantized, node hierarchy, skins, animations). The decoded model is plain data:
// nothing here exposes tinygltf, which stays private to the reader (rig/gltf_*.cpp:
// gltf_load loads, gltf_accessor decodes accessors, gltf_scene reads the scene and
// animations, gltf_import derives the rig).
#pragma once
#include <array>
#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "rig/rig.h"

namespace tinygltf {
class Model;
}

namespace sg {

// Joints of a skin: kMaxBones (1024). Up to 256 fit the uniform block (16 KiB, Vulkan's
// guaranteed maxUniformBufferRange); larger palettes go through a storage buffer
// (rules/buffers.yaml), chosen by the search. Skins with more joints are rejected.
constexpr int kMaxBonePalette = kMaxBones;
// Influences per vertex the rules serve: four JOINTS_n/WEIGHTS_n sets of 4 (kMaxInfluences).
constexpr int kMaxInfluenceSets = kMaxInfluences / 4;

// Hostile-input limits (docs/limits.md), each checked before the memory it guards is used.
// The model file and each buffer file it names.
constexpr size_t kMaxGltfFileBytes = size_t{1} << 30;
// JSON nesting ({ and [); real models nest under 10 deep.
constexpr int kMaxGltfJsonDepth = 64;
// Elements of one accessor (vertices, keyframes, matrices).
constexpr size_t kMaxGltfElements = size_t{1} << 24;
// Decoded data of one import (accessor values and per-vertex streams, zeros included):
// at most min(kMaxGltfDecodedBytes, kMinGltfDecodedBudget + kGltfDecodedPerInputByte × bytes
// of the file and its buffers), so a 2 KB file claiming a billion vertices allocates nothing.
constexpr size_t kMaxGltfDecodedBytes = size_t{1} << 30;
constexpr size_t kMinGltfDecodedBudget = size_t{64} << 20;
constexpr size_t kGltfDecodedPerInputByte = 256;

// "model.glb", "model.gltf", "model.glb#1/0" (mesh 1, primitive 0), "model.glb#*" (every
// primitive of every mesh: the model as a whole).
struct GltfRef {
  std::string file;
  int mesh = 0;
  int primitive = 0;
  bool wholeModel = false;
};
// True if the path names a glTF model (extension .gltf/.glb, case-insensitive, optionally
// followed by "#mesh/primitive" or "#*").
bool isGltfPath(const std::string& path);
// True if the path ends in "#*" (any file: a YAML rig with "#*" is refused by the callers
// that take whole models, with the reason).
bool isWholeModelRef(const std::string& path);
// Splits the optional "#m/p" or "#*" suffix. Throws InputError on a malformed suffix, and on
// "#*" unless `allowWholeModel` (the command takes one primitive).
GltfRef parseGltfRef(const std::string& path, bool allowWholeModel = false);

// Primitives of a whole model (MODEL.glb#*), at most kMaxGltfParts: real exports reach past a
// thousand (a voxel character of 1,168 primitives validates whole in under 3 minutes on
// lavapipe), and the bound keeps a hostile file's parts to minutes of work.
constexpr size_t kMaxGltfParts = 4096;
// One primitive of a whole model and its name: "m<mesh>p<primitive>" plus "-<mesh name>"
// when the mesh is named, the name's characters outside [A-Za-z0-9._-] replaced by '_' and
// cut to 48 bytes ("m2p1-Head", "m0p0-fox1", "m3p0"). The index prefix keeps names unique,
// stable across runs and in the file's order; they are safe file stems.
struct GltfPart {
  int mesh = 0, primitive = 0;
  std::string meshName;  // as in the file ("" when unnamed)
  std::string name;      // "m2p1-Head"
  std::string ref;       // "MODEL.glb#2/1", for every command that takes one primitive
};
std::string gltfPartName(int mesh, int primitive, const std::string& meshName);
// Every primitive of every mesh of the model, in the file's order (meshes, then primitives).
// Reads the model with every check of importGltf. Throws InputError for a model without
// mesh primitives and for more than kMaxGltfParts.
std::vector<GltfPart> gltfParts(const std::string& file);

// The user's choices for reading a model's data, the same on every command that imports a glTF
// rig (docs/gltf.md#import-diagnostics-and-weights).
struct GltfReadOptions {
  // Skin weights that do not sum to one are renormalised (rig/skin_weights.h), as three.js and
  // Filament's viewers do; false (--no-normalize-weights) keeps them as stored.
  bool normalizeWeights = true;
  // The import's warnings are errors (-Werror): the import throws them all.
  bool warningsAsErrors = false;
};

struct GltfImportOptions {
  int mesh = 0;
  int primitive = 0;
  int maxBones = kMaxBonePalette;  // tests lower it to exercise the diagnostic
  size_t maxDecodedBytes = kMaxGltfDecodedBytes;  // likewise
  // Dawn's layout: _OCCLUSION in normal.w (float32x4), target deltas in the normal deltas' w.
  bool packOcclusionInNormal = false;
  GltfReadOptions read;
};

// One attribute of the primitive as the file stores it, and what the rig made of it.
struct GltfAttributeInfo {
  std::string gltfName;       // "JOINTS_0"
  std::string componentType;  // "float", "unsigned byte", "unsigned short", ...
  std::string type;           // "VEC4"
  bool normalized = false;
  bool sparse = false;
  size_t count = 0;
  std::string rigAttribute;  // "" when the rig does not carry it (see GltfImport::notes)
  std::string format;        // rig vertex format ("uint16x4"), "" when skipped
};

// A node of the hierarchy (local transform as stored).
struct GltfNode {
  std::string name;
  std::vector<int> children;
  int mesh = -1;
  int skin = -1;
  bool hasMatrix = false;
  std::array<double, 16> matrix{};  // column-major, when hasMatrix
  std::array<double, 3> translation{0, 0, 0};
  std::array<double, 4> rotation{0, 0, 0, 1};  // quaternion x, y, z, w
  std::array<double, 3> scale{1, 1, 1};
  std::vector<double> weights;  // node-level default morph weights (overrides the mesh's)
  // EXT_mesh_gpu_instancing: the node draws its mesh once per element, at global(node) ·
  // instance (T·R·S of the element, column-major, in the node's local space). Empty: once.
  std::vector<std::array<double, 16>> instances;
};

struct GltfSkin {
  std::string name;
  std::vector<int> joints;                      // node indices
  std::vector<std::array<float, 16>> inverseBind;  // one per joint (identity if absent), column-major
};

enum class GltfInterpolation { Linear, Step, CubicSpline };
enum class GltfPath { Translation, Rotation, Scale, Weights };

struct GltfChannel {
  int node = -1;
  GltfPath path = GltfPath::Translation;
  GltfInterpolation interpolation = GltfInterpolation::Linear;
  std::vector<float> times;   // keyframe inputs (seconds, increasing)
  std::vector<float> values;  // outputs, `components` floats per element; CUBICSPLINE: 3 elements
                              // (in-tangent, value, out-tangent) per keyframe
  int components = 0;         // 3 (T/S), 4 (R), morph target count (weights)
};

struct GltfAnimation {
  std::string name;
  std::vector<GltfChannel> channels;
  float start = 0, end = 0;  // time range over all channels
};

// Everything decoded from the file for one primitive.
struct GltfModelData {
  std::string file;  // as given (without "#m/p")
  std::string stem;  // "Fox"
  int mesh = 0, primitive = 0;
  std::string meshName;  // name, or the index as text when unnamed
  int mode = 4;          // primitive mode (any mode is fine: shaders run per vertex)
  size_t vertexCount = 0;
  std::vector<uint32_t> indices;  // the primitive's indices as stored (empty: none)
  std::string indicesError;       // why they could not be read ("": fine); only drawing needs them
  // Per-vertex values by semantic (docs/semantics.md), with sparse accessors applied and
  // normalized integers dequantized as the GPU reads them: "vertex.position", "vertex.normal",
  // "vertex.tangent" (xyz), "vertex.handedness" (.x = TANGENT.w), "vertex.texcoord0/1",
  // "vertex.color0", "skin.joints[s]" (integers as floats), "skin.weights[s]",
  // "morph.position[i]", "morph.normal[i]", "morph.tangent[i]" (zeros for targets that do
  // not move that attribute). Only attributes the rig carries are present.
  std::map<std::string, std::vector<std::array<float, 4>>> streams;
  std::vector<GltfNode> nodes;
  std::vector<int> sceneRoots;  // default scene (or scene 0, or every parentless node)
  std::vector<GltfSkin> skins;
  std::vector<GltfAnimation> animations;
  std::vector<double> meshWeights;  // default morph weights of the mesh (padded with 0)
  int meshNode = -1;  // the node instantiating the mesh (-1: none; identity transform)
  int skin = -1;      // the skin it uses (-1: unskinned)
};

// The nodes of the model's scene (sceneRoots), depth first, pre-order, each once (a scene may
// list a root twice), without recursion: node chains can be as long as the file.
std::vector<int> gltfSceneNodes(const GltfModelData& data);

struct GltfImport {
  Rig rig;
  GltfModelData data;
  std::vector<GltfAttributeInfo> attributes;  // in the file's order
  int joints = 0;                             // joint count of the skin (0 = unskinned)
  int influences = 0;
  int morphTargets = 0;
  // Per target: the glTF attributes it moves ("POSITION", "NORMAL", "TANGENT", ...).
  std::vector<std::vector<std::string>> targetAttributes;
  std::vector<std::string> notes;  // warnings: attributes the rig leaves out, sparse data, ...
};

// Loads the model and derives the rig of one primitive. Throws InputError naming the model,
// the mesh and the limit for anything the rules cannot serve (too many joints, JOINTS_2+,
// quantized positions, ...), and for malformed files.
GltfImport importGltf(const std::string& file, const GltfImportOptions& opts = {});
// Same, from glTF JSON text (buffers as data URIs; buffer files only inside baseDir, none
// when it is empty).
GltfImport importGltfText(const std::string& json, const std::string& fileName, const GltfImportOptions& opts = {},
                          const std::string& baseDir = "");

// The checked loader behind importGltf (bounded read, JSON depth, GLB layout, buffer files
// confined to the model's folder), for tools that rewrite a model (bake/gltf_bake.cpp). The
// caller includes tiny_gltf.h with the configuration of rig/gltf_tinygltf.h.
// Returns the bytes read (the model and its buffer files), for importGltfModel's budget.
size_t loadGltfModel(const std::string& file, tinygltf::Model& model);
// importGltf on a model loadGltfModel loaded: tools that import every primitive parse the
// file once (a file of many primitives re-read per primitive took quadratic time).
GltfImport importGltfModel(const tinygltf::Model& model, size_t inputBytes, const std::string& file,
                           const GltfImportOptions& opts = {});

// One primitive of a model by its reference, "model.glb[#m/p]" (importGltf with `read`).
GltfImport importGltfRef(const std::string& ref, const GltfReadOptions& read = {});
// Any rig path: "rig.yaml" (loadRigFile) or "model.glb[#m/p]" (importGltfRef).
Rig loadRig(const std::string& path, const GltfReadOptions& read = {});

// The rig as YAML that loadRigText reads back to the same rig. `header` lines become
// comments at the top.
std::string rigToYaml(const Rig& rig, const std::vector<std::string>& header = {});

// A node's (or a GPU instance's) local transform T·R·S, column-major, from glTF's translation,
// rotation quaternion (x, y, z, w; normalised here) and scale.
std::array<double, 16> gltfTrs(const double* t, const double* q, const double* s);

}  // namespace sg

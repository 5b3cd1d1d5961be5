// The character rig: what every vertex carries, what the deformers are, and
// which uniforms the application provides. Loaded from YAML (rig_loader) or
// derived from a glTF model (gltf_import).
#pragma once
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "common/diagnostics.h"
#include "common/types.h"
#include "rig/vertex_format.h"

namespace sg {

// Limits of a rig file (docs/limits.md); deformer parameters are 0..65535.
constexpr size_t kMaxRigNameBytes = 256;
constexpr int kMaxMorphTargets = 256;
// Bone influences per vertex (four JOINTS_n/WEIGHTS_n sets) and joints in a skin: the
// storage-buffer forms of rules/buffers.yaml serve these (docs/buffers.md).
constexpr int kMaxInfluences = 16;
constexpr int kMaxBones = 1024;
constexpr size_t kMaxRigAttributes = 64;
constexpr size_t kMaxRigUniforms = 256;


// A semantic provided by (part of) an attribute: e.g. "vertex.occlusion" is the "w" of "normal".
struct ProvidedPart {
  std::string semantic;  // may carry an index: "skin.joints[1]"
  std::string swizzle;   // "" = whole attribute, else "xyz", "w", ...
};

struct RigAttribute {
  std::string name;       // base of the GLSL input name (a_<name>, a_<name><target>)
  VertexFormat format = VertexFormat::Float32x4;
  Type shaderType = Type::Vec4;  // type declared in the shader (derived from format)
  bool perMorphTarget = false;   // one stream per morph target; semantics get "[target]"
  std::vector<ProvidedPart> provides;
  SourceLoc loc;
};

struct RigUniform {
  std::string name;      // GLSL member name in the uniform block
  std::string semantic;  // "skin.bones"
  Type type = Type::Mat4;
  std::string arraySizeParam;  // "" = not an array; else a rig parameter ("bones")
  int arraySize = 0;           // resolved from arraySizeParam (0 = not an array)
  SourceLoc loc;
};

struct Rig {
  std::string name;
  std::string file;                            // where it came from (for diagnostics)
  // Every file read to make it (a glTF model and its buffer files): depfiles, cache keys,
  // and the outputs that must never overwrite an input.
  std::vector<std::string> sourceFiles;
  std::map<std::string, int64_t> params;       // bones, influences, morph_targets, ...
  std::map<std::string, SourceLoc> paramLocs;
  std::vector<std::string> morphedAttributes;  // "position", "normal", "tangent"
  std::vector<RigAttribute> attributes;
  std::vector<RigUniform> uniforms;

  int64_t param(const std::string& key, int64_t fallback = 0) const;
  int morphTargets() const { return static_cast<int>(param("morph_targets")); }
};

// Throws InputError with file:line:col for malformed or inconsistent rigs.
Rig loadRigFile(const std::string& path);
Rig loadRigText(const std::string& text, const std::string& fileName);

// Checks internal consistency (formats vs types, per-target streams vs morph count,
// bone palette size vs params). Throws InputError.
void checkRig(const Rig& rig);

}  // namespace sg

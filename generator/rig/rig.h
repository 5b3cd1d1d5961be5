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
  std::string swizzle;   // "" = whole attribute (or field), else "xyz", "w", ...
  int field = -1;        // index in RigAttribute::fields; -1: a part of the attribute itself
};

// A field of a bit-packed attribute (docs/rig-format.md, "Bit-packed attributes"): a value
// in one of the vertex formats, stored in the attribute's 32-bit words at the place the
// loader computed (rig/packed_fields.h) and unpacked by the shader.
struct PackedField {
  VertexFormat format = VertexFormat::Unorm8x4;
  int word = 0;  // the 32-bit word holding its first component
  int bit = 0;   // that component's first bit in the word
  SourceLoc loc;
};

struct RigAttribute {
  std::string name;       // base of the GLSL input name (a_<name>, a_<name><target>)
  VertexFormat format = VertexFormat::Float32x4;
  Type shaderType = Type::Vec4;  // type declared in the shader (derived from format, unless widened)
  bool widened = false;          // `shader_type`: wider than the format; the device fills the rest
  bool perMorphTarget = false;   // one stream per morph target; semantics get "[target]"
  std::vector<ProvidedPart> provides;
  std::vector<PackedField> fields;  // non-empty: bit-packed (format uint32x4, uint32x2 or uint32)
  SourceLoc loc;
};

// The format a part is stored in: its field's, else the attribute's.
inline VertexFormat partFormat(const RigAttribute& a, const ProvidedPart& p) {
  return p.field >= 0 ? a.fields[static_cast<size_t>(p.field)].format : a.format;
}

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
  SourceLoc nameLoc;                           // its `rig:` name (line 0 for a glTF rig)
  // Every file read to make it (a glTF model and its buffer files): depfiles, cache keys,
  // and the outputs that must never overwrite an input.
  std::vector<std::string> sourceFiles;
  std::map<std::string, int64_t> params;       // bones, influences, morph_targets, ...
  std::map<std::string, SourceLoc> paramLocs;
  std::vector<std::string> morphedAttributes;  // "position", "normal", "tangent"
  std::vector<RigAttribute> attributes;
  std::vector<RigUniform> uniforms;
  // A glTF import (docs/gltf.md#import-diagnostics-and-weights): what it found suspect in the
  // model's data (warnings, each with the glTF-Validator's code), which loading passes on with
  // its notes; and the skin weights its data holds: "normalized" (renormalised to sum to one,
  // the default), "stored" (--no-normalize-weights), "" (not a skinned glTF primitive).
  std::vector<Diagnostic> importDiagnostics;
  // A glTF import's notes (attributes it left out, data fed as stored): an unmet request
  // names them, since a value the model holds but the rig does not carry reads as missing.
  std::vector<std::string> importNotes;
  // Semantics the rig stores that this generation withholds from the search, and why
  // ("--max-error"): an unmet request must not suggest providing them.
  std::map<std::string, std::string> withheld;
  std::string skinWeights;

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

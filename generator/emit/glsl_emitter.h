// Plan → Vulkan GLSL 450 text, filled from templates/vertex.glsl. Every snippet line
// is preceded by a `#line L S` directive mapping it to its rules file (S indexes
// EmittedGlsl::sourceFiles), so compiler errors land on the rule's YAML line.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "common/types.h"
#include "emit/templates.h"
#include "interface/fragment_interface.h"
#include "rig/rig.h"
#include "search/plan.h"
#include "search/problem.h"

namespace sg {

struct EmitOptions {
  bool capture = false;  // add transform-feedback qualifiers (validation builds only)
  std::string heuristic = "lmcut";
  // The search that found the plan, as the header names it ("lmcut A*", "integer program").
  std::string search = "lmcut A*";
  std::string version;  // shadergen version printed in the header
};

struct EmittedInput {
  std::string name;  // a_normal, a_morph_position3
  int location = 0;
  int attribute = -1;  // index in Rig::attributes
  int target = -1;     // morph target for per-target attributes
  Type type = Type::Vec4;
};

struct EmittedUniform {
  std::string name;  // u_bones
  int uniform = -1;  // index in Rig::uniforms
};

// A storage buffer the shader reads (set 0, std430, readonly; docs/buffers.md).
struct EmittedBuffer {
  std::string name;      // accessor function b_<semantic>; the array is <name>_data
  std::string semantic;  // "morph.position_deltas"
  int binding = 1;       // set 0; the uniform block has binding 0
  int buffer = -1;       // index in Problem::buffers
  Type element = Type::Vec4;  // std430 array element
  uint32_t strideBytes = 16;  // of one element
  bool perVertex = true;      // element (v, i) at v * count + i; else element i (a palette)
  int64_t count = 0;          // instances per vertex, or elements
  // What each element holds: (semantic with [i], components of the element), in order.
  std::vector<std::pair<std::string, std::string>> packs;
};

struct EmittedOutput {
  std::string name;
  int location = -1;  // -1: gl_Position
  Type type = Type::Vec4;  // the element type of an array
  int arraySize = 0;       // 0 = not an array (one semantic per element otherwise)
  std::vector<std::string> semantics;
  uint32_t captureOffset = 0;  // byte offset in the transform-feedback record
};

struct EmittedGlsl {
  std::string text;
  std::vector<std::string> sourceFiles;  // #line source string S → sourceFiles[S-1]
  std::vector<EmittedInput> inputs;      // by location
  std::vector<EmittedUniform> uniforms;  // in block order
  std::vector<EmittedBuffer> buffers;    // by binding
  std::vector<EmittedOutput> outputs;    // gl_Position first, then by location
  uint32_t captureStride = 0;
};

EmittedGlsl emitGlsl(const Rig& rig, const Problem& p, const Plan& plan, const std::vector<Varying>& varyings,
                     const TemplateSet& templates, const std::string& fragmentName, const EmitOptions& opts);

// A semantic as an identifier: "world.normal" → "world_normal", "a[2]" → "a_2" (storage
// buffers are b_<this>; locals are this, made unique, docs/design.md "Generated names").
std::string semanticIdentifier(const std::string& fact);
// Text safe inside a `//` comment: control bytes and '\\' become '?' (names from the rig,
// the glTF mesh or a file name must not end the comment or splice the next line).
std::string commentSafe(const std::string& text);

}  // namespace sg

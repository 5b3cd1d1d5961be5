// The one glslang / SPIRV-Tools wrapper. Every stage that compiles, reflects, links,
// validates or optimises shader code goes through here; nothing else sets up glslang or
// SPIRV-Tools (analysis/cost.cpp only reads opcode numbers from the SPIR-V headers).
// A shader is parsed once (GlslShader); that parse serves code generation, reflection
// and cross-stage linking. The target environment sets both
// the Vulkan client version and the SPIR-V version (vulkan1.1 → SPIR-V 1.3, ...).
// HLSL (SPIRV-Cross's output, entry point "main") goes through glslang's HLSL front end the
// same way, so a translated program can be run where the GLSL runs (validate --via hlsl).
// Messages become located diagnostics: `#line L S` directives in the source map
// locations back to sourceFiles[S - 1] (S = 0 is the GLSL file itself).
#pragma once
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/diagnostics.h"
#include "common/types.h"

namespace sg {

enum class Stage { Vertex, Fragment };

enum class TargetEnv { Vulkan1_0, Vulkan1_1, Vulkan1_2, Vulkan1_3 };
bool parseTargetEnv(const std::string& s, TargetEnv& out);  // "vulkan1.0".."vulkan1.3"
const char* targetEnvName(TargetEnv e);

enum class SourceLanguage { Glsl, Hlsl };

struct GlslUnit {
  Stage stage = Stage::Vertex;
  std::string text;
  std::string fileName;                 // reported for source string 0
  std::vector<std::string> sourceFiles;  // reported for source string S >= 1
  SourceLanguage language = SourceLanguage::Glsl;
  // HLSL: register bN is binding N, tN is binding N + this (the storage buffers follow the
  // uniform block); set = space. The SPIR-V keeps each input's and output's semantic
  // (SPV_GOOGLE_hlsl_functionality1) for bindSemantics.
  uint32_t hlslTextureBindingShift = 0;
  // A transform-feedback capture build: the largest xfb_stride accepted, in bytes (the capture
  // device's limit). glslang's default, gl_MaxTransformFeedbackInterleavedComponents = 64, is
  // OpenGL's minimum, not a Vulkan limit. 0: that default.
  uint32_t maxCaptureStrideBytes = 0;
};

// A user input or output of one stage, as reflected from the parse.
struct StageVariable {
  std::string name;
  std::optional<Type> type;  // the element type for 1-D arrays; none for structs and other unsupported types
  int arraySize = 0;         // elements of a 1-D array, 0 = not an array
  std::string typeText;      // glslang's spelling of the type (for messages)
  int location = -1;         // -1: no layout(location)
  int component = -1;        // -1: no layout(component)
  bool flat = false;
  bool block = false;        // an interface block, or a member of one
  std::string blockName;     // the block's type name (`in Block { ... } instance;`)
};

// A member of a uniform block, laid out as the compiler laid it out (std140).
struct UniformMember {
  std::string name;          // without array brackets
  uint32_t offset = 0;
  uint32_t arrayStride = 0;  // 0 if not an array
  uint32_t matrixStride = 0; // 16 for std140 matrices, 0 otherwise
  uint32_t size = 0;         // bytes of one element
};

struct UniformBlock {
  std::string name;
  uint32_t size = 0;
};

// A descriptor the stage uses (statically, so a pipeline must bind it): a uniform block, a
// storage block or a sampler, at its set and binding.
struct ShaderDescriptor {
  enum class Kind { UniformBlock, StorageBlock, Sampler };
  std::string name;  // block or sampler name
  Kind kind = Kind::UniformBlock;
  uint32_t set = 0, binding = 0;
  bool cube = false;  // a samplerCube
};

// One stage parsed (and linked alone) once. Movable, not copyable; not shared
// between threads (each thread parses its own).
class GlslShader {
 public:
  GlslShader(const GlslUnit& unit, TargetEnv env);
  ~GlslShader();
  GlslShader(GlslShader&&) noexcept;
  GlslShader& operator=(GlslShader&&) noexcept;

  bool ok() const;  // parsed and linked without errors
  const std::vector<Diagnostic>& diagnostics() const;  // errors and warnings, located
  const GlslUnit& unit() const;
  TargetEnv env() const;

  std::vector<uint32_t> spirv() const;  // unoptimised SPIR-V (requires ok())
  std::vector<StageVariable> inputs() const;
  std::vector<StageVariable> outputs() const;
  std::vector<UniformBlock> uniformBlocks() const;
  std::vector<UniformMember> uniformMembers() const;
  std::vector<ShaderDescriptor> descriptors() const;  // in glslang's reflection order

  // glslang's cross-stage link of this stage with `next` (both ok()). Returns "" when
  // they link, else glslang's log.
  std::string linkWith(const GlslShader& next) const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

struct CompileResult {
  bool ok = false;
  std::vector<uint32_t> spirv;
  std::vector<Diagnostic> diagnostics;  // errors and warnings, located
};

// Compiles one stage to SPIR-V (no optimisation): GlslShader, then spirv().
CompileResult compileGlsl(const GlslUnit& unit, TargetEnv env);

// Parses glslang's info log ("ERROR: S:L: msg") into diagnostics.
std::vector<Diagnostic> parseGlslangLog(const std::string& log, const GlslUnit& unit);

// Throws the first error of `diags` (others attached as related); `what` if none.
[[noreturn]] void throwDiagnostics(std::vector<Diagnostic> diags, const std::string& fallbackFile, const char* what);

// SPIRV-Tools validator; returns "" when valid, else the validator's message.
std::string validateSpirv(const std::vector<uint32_t>& words, TargetEnv env);

// spirv-opt -O (performance passes). Throws std::runtime_error on optimiser failure.
// unrollLoops: also unroll every loop with a constant trip count, then -O again (how the
// cost model counts the loads a rule's loop makes, analysis/cost.h).
std::vector<uint32_t> optimizeSpirv(const std::vector<uint32_t>& words, TargetEnv env, bool unrollLoops = false);

// A vertex module compiled from HLSL, bound the way a Direct3D host binds it, by semantic:
// each user input and output takes the location its semantic has in `inputs` / `outputs`
// (semantics compare case-insensitively), then the semantic decorations and their
// extensions are removed (Vulkan drivers need not know them). Throws InputError (at
// `name`) for a semantic the tables do not list.
std::vector<uint32_t> bindSemantics(const std::vector<uint32_t>& words, const std::map<std::string, int>& inputs,
                                    const std::map<std::string, int>& outputs, const std::string& name);

// The module with transform feedback capture (xfb buffer 0, `stride` bytes a vertex): the
// output at each location of `offsets`, and the position (key -1), at its byte offset.
// What the GLSL capture build declares in its source, added to a module compiled without it.
std::vector<uint32_t> withCapture(const std::vector<uint32_t>& words, uint32_t stride,
                                  const std::map<int, uint32_t>& offsets);

// Number of instructions in a module (header excluded).
size_t countInstructions(const std::vector<uint32_t>& words);

}  // namespace sg

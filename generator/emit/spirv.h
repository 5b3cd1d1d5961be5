// SPIR-V stage: compile emitted GLSL with glslang, validate with SPIRV-Tools,
// optionally optimise, and check the vertex/fragment interface links.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "common/glsl_compile.h"
#include "emit/glsl_emitter.h"

namespace sg {

struct UniformLayout {
  std::string name;
  uint32_t offset = 0;
  uint32_t arrayStride = 0;  // 0 if not an array
  uint32_t matrixStride = 0; // 16 for std140 matrices, 0 otherwise
  uint32_t size = 0;         // bytes of one element
};

struct SpirvModule {
  std::vector<uint32_t> words;
  uint32_t uniformBlockSize = 0;
  std::vector<UniformLayout> uniforms;  // glslang's reflection of the compiled shader
};

// Compiles `glsl`; errors become InputErrors located through its #line map.
SpirvModule compileVertexShader(const EmittedGlsl& glsl, const std::string& glslFileName, TargetEnv env);

// SPIRV-Tools validator; returns "" when valid, else the validator's message.
std::string validateSpirv(const std::vector<uint32_t>& words, TargetEnv env);

// spirv-opt -O (performance passes). Throws std::runtime_error on optimiser failure.
std::vector<uint32_t> optimizeSpirv(const std::vector<uint32_t>& words, TargetEnv env);

// Links the vertex shader with the fragment shader in glslang (cross-stage checks) and
// checks every fragment input has a vertex output of the same location and type.
// Throws InputError naming the mismatch.
void checkLink(const EmittedGlsl& vertex, const std::string& fragmentSource, const std::string& fragmentFile,
               TargetEnv env);

// Number of instructions in a module (header excluded).
size_t countInstructions(const std::vector<uint32_t>& words);

}  // namespace sg

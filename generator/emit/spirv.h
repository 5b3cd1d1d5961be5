// SPIR-V stage: compile emitted GLSL (parsed once, through common/glsl_compile.h), read
// the uniform layout from that parse, and check the vertex/fragment interface links.
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
  std::vector<ShaderDescriptor> descriptors;  // what a run must bind (glslang's reflection)
};

// The vertex shader as parsed once: its SPIR-V and layout, and the parse itself (for the
// link check).
struct CompiledVertexShader {
  SpirvModule module;
  GlslShader parsed;
};

// Compiles `glsl`; errors become InputErrors located through its #line map. A capture build's
// record may take up to `maxCaptureBytes` a vertex (its device's; 0: none known, so its own
// stride: the harness checks it against the device that runs it).
CompiledVertexShader compileVertex(const EmittedGlsl& glsl, const std::string& glslFileName, TargetEnv env,
                                   uint32_t maxCaptureBytes = 0);
SpirvModule compileVertexShader(const EmittedGlsl& glsl, const std::string& glslFileName, TargetEnv env);

// Links the vertex shader with the fragment shader in glslang (cross-stage checks) and
// checks every fragment input has a vertex output of the same location and type.
// Throws InputError (at the fragment file) naming the mismatch.
void checkLink(const GlslShader& vertex, const GlslShader& fragment);
// Same, parsing both from text.
void checkLink(const EmittedGlsl& vertex, const std::string& fragmentSource, const std::string& fragmentFile,
               TargetEnv env);

}  // namespace sg

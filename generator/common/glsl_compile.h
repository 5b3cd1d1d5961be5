// In-process glslang: GLSL 450 (Vulkan) → SPIR-V, with compiler messages turned
// into located diagnostics. `#line L S` directives in the source map message
// locations back to sourceFiles[S - 1] (S = 0 is the GLSL file itself).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "common/diagnostics.h"

namespace sg {

enum class Stage { Vertex, Fragment };

enum class TargetEnv { Vulkan1_0, Vulkan1_1, Vulkan1_2, Vulkan1_3 };
bool parseTargetEnv(const std::string& s, TargetEnv& out);  // "vulkan1.0".."vulkan1.3"
const char* targetEnvName(TargetEnv e);

struct GlslUnit {
  Stage stage = Stage::Vertex;
  std::string text;
  std::string fileName;                 // reported for source string 0
  std::vector<std::string> sourceFiles;  // reported for source string S >= 1
};

struct CompileResult {
  bool ok = false;
  std::vector<uint32_t> spirv;
  std::vector<Diagnostic> diagnostics;  // errors and warnings, located
};

// Compiles one stage to SPIR-V (no optimisation).
CompileResult compileGlsl(const GlslUnit& unit, TargetEnv env);

// Parses glslang's info log ("ERROR: S:L: msg") into diagnostics.
std::vector<Diagnostic> parseGlslangLog(const std::string& log, const GlslUnit& unit);

// Process-wide glslang initialisation (idempotent, thread-safe).
void ensureGlslangInitialized();

}  // namespace sg

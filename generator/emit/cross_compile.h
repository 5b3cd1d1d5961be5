// HLSL and MSL from the checked SPIR-V (the module `--emit spv` writes), translated by
// SPIRV-Cross's library, with the interface a Direct3D or Metal host binds: each vertex
// input's and output's semantic or attribute index, each resource's register or buffer
// index. The bindings are chosen here, passed to SPIRV-Cross and checked against what it
// reports after compiling, so the reflection (emit/reflection.h) never guesses them.
// docs/hlsl-msl.md.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "emit/glsl_emitter.h"

namespace sg {

struct HlslOptions {
  int shaderModel = 50;  // 50 = 5.0; 5.0 (default), 5.1, 6.0 .. 6.7
};

enum class MslPlatform { MacOS, IOS };

struct MslOptions {
  int major = 2, minor = 0;  // Metal Shading Language version (default 2.0)
  MslPlatform platform = MslPlatform::MacOS;
};

// "5.0" → 50 (false for an unsupported model); "2.1" → {2, 1}; "macos"/"ios".
bool parseShaderModel(const std::string& s, int& out);
bool parseMslVersion(const std::string& s, MslOptions& out);
bool parseMslPlatform(const std::string& s, MslPlatform& out);
std::string shaderModelName(int shaderModel);                 // 50 → "5.0"
std::string mslVersionName(const MslOptions& o);              // "2.0"
const char* mslPlatformName(MslPlatform p);                   // "macos"
// What each accepts, for messages.
extern const char* const kShaderModels;   // "5.0, 5.1, 6.0 .. 6.7"
extern const char* const kMslVersions;    // "1.2, 2.0 .. 2.4, 3.0"

// A vertex input or output of the translated program.
struct CrossVariable {
  std::string name;     // as in the GLSL and the reflection's inputs/outputs
  int location = -1;    // the Vulkan location; -1 = the clip position
  int slots = 1;        // locations it occupies (matrices and arrays: one per column or element)
  // HLSL: the semantic ("TEXCOORD3", "SV_Position"); a variable of several slots takes
  // TEXCOORD<location> .. TEXCOORD<location + slots - 1>.
  // MSL: the attribute ("attribute(3)", "user(locn3)", "position").
  std::string binding;
};

// A buffer the program reads: the uniform block or a storage buffer.
struct CrossResource {
  std::string name;      // the GLSL block name (ShadergenUniforms, ShadergenBuffer1, ...)
  std::string variable;  // the name the translated source gives it
  bool uniformBlock = true;  // else a read-only storage buffer
  uint32_t set = 0, binding = 0;  // Vulkan
  // HLSL: register "b0" / "t0" (space 0); MSL: [[buffer(n)]] index.
  std::string slot;
  uint32_t index = 0;
};

struct CrossShader {
  bool hlsl = true;     // else MSL
  std::string version;  // HLSL shader model "5.0"; MSL version "2.0"
  std::string profile;  // HLSL: the compile target ("vs_5_0"); MSL: the platform ("macos", "ios")
  std::string text;
  std::string entryPoint;  // "main" (HLSL), "main0" (MSL: main is reserved)
  std::vector<CrossVariable> inputs;   // by location
  std::vector<CrossVariable> outputs;  // the position first, then by location
  std::vector<CrossResource> resources;  // by binding
  // MSL: the first [[buffer(n)]] index the host may use for vertex buffers (resources take
  // the ones below). HLSL: 0.
  uint32_t firstVertexBuffer = 0;
};

// Each throws InputError (at `name`) if SPIRV-Cross refuses the module or assigns a binding
// other than the one asked for.
CrossShader translateToHlsl(const std::vector<uint32_t>& spirv, const EmittedGlsl& glsl, const HlslOptions& opts,
                            const std::string& name);
CrossShader translateToMsl(const std::vector<uint32_t>& spirv, const EmittedGlsl& glsl, const MslOptions& opts,
                           const std::string& name);

}  // namespace sg

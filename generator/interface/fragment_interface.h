// What the fragment shader asks for: its `in` variables, by glslang reflection,
// and how each maps to semantics (by name, or by an explicit mapping that may pack
// several scalar semantics into one vector input).
#pragma once
#include <string>
#include <vector>

#include "common/diagnostics.h"
#include "common/glsl_compile.h"
#include "common/types.h"

namespace sg {

struct RuleSet;

struct FragmentInput {
  std::string name;
  Type type = Type::Vec4;  // the element type of an array
  int arraySize = 0;       // 0 = not an array
  int location = -1;       // the first of locationCount(*this)
  bool flat = false;
  SourceLoc loc;  // the declaration in the fragment shader
};

// Locations an input takes: one per matrix column, times the array size.
int locationCount(Type type, int arraySize);

struct FragmentInterface {
  std::string file;
  std::string source;  // the fragment shader text (for the link check)
  std::vector<FragmentInput> inputs;  // sorted by location
};

// Compiles the fragment shader with glslang and reflects its inputs: scalars, vectors,
// mat3/mat4 and 1-D arrays of them. Throws InputError (compile errors at file:line, inputs
// without locations or with overlapping location ranges, input blocks, unsupported types).
FragmentInterface reflectFragmentFile(const std::string& path, TargetEnv env = TargetEnv::Vulkan1_0);
FragmentInterface reflectFragmentSource(const std::string& source, const std::string& fileName,
                                        TargetEnv env = TargetEnv::Vulkan1_0);

// A vertex output to produce: one semantic, or several packed into a vector.
// A matrix is filled column by column from its semantics (mat3 TBN = tangent, binormal,
// normal); an array takes one semantic per element, in element order.
struct Varying {
  std::string name;  // GLSL name ("gl_Position" for the clip position)
  Type type = Type::Vec4;  // the element type of an array
  int arraySize = 0;       // 0 = not an array
  int location = -1;  // -1 for gl_Position
  bool flat = false;
  std::vector<std::string> semantics;  // size 1 = direct, > 1 = packed in component order
  SourceLoc loc;
  std::string via;  // how it was mapped: "--map", "rules 'varyings:'", "its name", "convention 'threejs'"
};

// The generated vertex shader names its inputs a_<name> (attributes), its uniforms
// u_<name> and its block kUniformBlockName; its outputs take the fragment inputs' names,
// so an input with such a name would collide. (Its locals are named around the outputs:
// emit/glsl_emitter.h.) Returns why `name` is reserved, or nullptr.
inline constexpr const char* kUniformBlockName = "ShadergenUniforms";
const char* reservedNameUse(const std::string& name);

// Command-line override "Name=sem" or "Name=sem1,sem2,...".
struct VaryingOverride {
  std::string name;
  std::vector<std::string> semantics;
};

// Maps every fragment input to semantics, first match wins: --map overrides, the rules'
// `varyings:`, the input's own name (world_eye_dir, worldEyeDir or WorldEyeDir →
// world.eye_dir), then the naming conventions (`conventions`: the names of the ones to
// use, earlier first; empty = all of them where they agree; {"none"} = none).
// gl_Position (clip.position) is always added first.
struct VaryingBinding {
  std::vector<Varying> varyings;  // gl_Position, then every input that could be mapped
  std::vector<Diagnostic> errors; // one per input that could not, in declaration order,
                                  // each with the closest semantics ("did you mean ...")
};
VaryingBinding bindVaryingsCollect(const FragmentInterface& frag, const RuleSet& rules,
                                   const std::vector<VaryingOverride>& overrides,
                                   const std::vector<std::string>& conventions = {});
// The same, throwing every error together (InputError: the first, the rest in `related`).
std::vector<Varying> bindVaryings(const FragmentInterface& frag, const RuleSet& rules,
                                  const std::vector<VaryingOverride>& overrides,
                                  const std::vector<std::string>& conventions = {});

// What the conventions say about an input name and type.
struct ConventionMatch {
  std::vector<std::string> semantics;  // empty: no convention maps it
  std::string convention;              // the one that did
  SourceLoc loc;                       // its entry in the rules file
  std::vector<std::string> notes;      // why others did not ("vColor in threejs is for vec4")
};
ConventionMatch matchConvention(const RuleSet& rules, const std::string& name, Type type, int arraySize,
                                const std::vector<std::string>& conventions);
// Throws InputError for a --conventions name no rules file defines.
void checkConventionNames(const RuleSet& rules, const std::vector<std::string>& conventions);

}  // namespace sg

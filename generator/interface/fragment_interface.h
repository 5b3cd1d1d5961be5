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
  Type type = Type::Vec4;
  int location = -1;
  bool flat = false;
  SourceLoc loc;  // the declaration in the fragment shader
};

struct FragmentInterface {
  std::string file;
  std::string source;  // the fragment shader text (for the link check)
  std::vector<FragmentInput> inputs;  // sorted by location
};

// Compiles the fragment shader with glslang and reflects its inputs. Throws InputError
// (compile errors at file:line, inputs without locations, input blocks, unsupported types).
FragmentInterface reflectFragmentFile(const std::string& path, TargetEnv env = TargetEnv::Vulkan1_0);
FragmentInterface reflectFragmentSource(const std::string& source, const std::string& fileName,
                                        TargetEnv env = TargetEnv::Vulkan1_0);

// A vertex output to produce: one semantic, or several packed into a vector.
struct Varying {
  std::string name;  // GLSL name ("gl_Position" for the clip position)
  Type type = Type::Vec4;
  int location = -1;  // -1 for gl_Position
  bool flat = false;
  std::vector<std::string> semantics;  // size 1 = direct, > 1 = packed in component order
  SourceLoc loc;
};

// The generated vertex shader names its own declarations t_<fact> (temporaries), a_<name>
// (attributes), u_<name> (uniforms) and kUniformBlockName; its outputs take the fragment
// inputs' names, so an input with such a name would collide. Returns why `name` is
// reserved, or nullptr.
inline constexpr const char* kUniformBlockName = "ShadergenUniforms";
const char* reservedNameUse(const std::string& name);

// Command-line override "Name=sem" or "Name=sem1,sem2,...".
struct VaryingOverride {
  std::string name;
  std::vector<std::string> semantics;
};

// Maps every fragment input to semantics: --map overrides, then the rules' `varyings:`,
// then the input's own name with '_' for '.' (world_eye_dir → world.eye_dir).
// gl_Position (clip.position) is always added first. Throws InputError on unknown names
// and type mismatches, located at the fragment input or the mapping.
std::vector<Varying> bindVaryings(const FragmentInterface& frag, const RuleSet& rules,
                                  const std::vector<VaryingOverride>& overrides);

}  // namespace sg

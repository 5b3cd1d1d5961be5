// The generator as named stages, each taking and returning plain data:
//
//   load ─► instantiate ─► search ─► emit ─► compile ─► check ─► translate
//
// load reads files (rig, rules, fragment shader, templates); nothing after it reads a
// file. instantiate binds the fragment inputs to semantics, measures `cost: auto` for
// the rig and builds the Problem (the one instantiation, search/problem.h). generate()
// (pipeline/generate.h) runs them in order; the variant builder (variants/) loads each
// file once and runs the later stages per variant; explain, graph, check and validate
// call the stages they need.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "common/glsl_compile.h"
#include "emit/glsl_emitter.h"
#include "emit/spirv.h"
#include "emit/templates.h"
#include "interface/fragment_interface.h"
#include "rig/gltf_import.h"
#include "rig/rig.h"
#include "rules/rules.h"
#include "search/astar.h"
#include "search/instance.h"
#include "search/plan.h"
#include "search/search.h"

namespace sg {

// ---- load -------------------------------------------------------------------------------
// Each throws InputError (file:line:col) for bad input.
// YAML, or a glTF model "model.glb#mesh/primitive" read as `gltf` says.
Rig loadRigStage(const std::string& path, const GltfReadOptions& gltf = {});
RuleSet loadRulesStage(const std::vector<std::string>& paths);
FragmentInterface loadFragmentStage(const std::string& path, TargetEnv env);
TemplateSet loadTemplatesStage(const std::string& dir);  // "" = defaultTemplateDir()

// ---- instantiate ------------------------------------------------------------------------
// Varyings from the fragment inputs (overrides first, naming conventions last: see
// bindVaryings), `cost: auto` measured for the rig, the Problem built. The inputs are copied
// into the context (auto costs are per rig). Throws one InputError carrying every unmapped
// input and every mapped one that cannot be produced, each at its declaration.
LoadedInputs instantiateStage(Rig rig, RuleSet rules, FragmentInterface fragment,
                              const std::vector<VaryingOverride>& overrides,
                              const std::vector<std::string>& conventions = {});

// ---- price (with a device profile only) ------------------------------------------------
// Measures the buffer and indexed uniform loads of each rule that can make them and prices
// the problem's terms with the profile's weights (docs/device-profiles.md). Without it the
// costs are the rules' instruction slots, as they always were.
DeviceProfile loadDeviceProfileStage(const std::string& path);
void priceStage(LoadedInputs& in, const DeviceProfile& profile);

// ---- search -----------------------------------------------------------------------------
// The optimal plan (to force alternatives, remove rules first: withoutRules). Throws
// InputError at every fragment input whose request cannot be met, explaining why;
// and for an unknown engine or heuristic name.
Plan searchStage(const LoadedInputs& in, const SearchOptions& opts, SearchStats* stats = nullptr);

// ---- emit -------------------------------------------------------------------------------
EmittedGlsl emitStage(const LoadedInputs& in, const Plan& plan, const TemplateSet& templates,
                      const EmitOptions& opts);

// ---- compile ----------------------------------------------------------------------------
// Parses the GLSL once (SPIR-V + uniform layout + the parse for the link check). Compile
// errors are located at the rules' snippet lines, columns refined. `maxCaptureBytes`: as
// compileVertex's.
CompiledVertexShader compileStage(const LoadedInputs& in, const Plan& plan, const EmittedGlsl& glsl,
                                  const std::string& glslName, TargetEnv env, uint32_t maxCaptureBytes = 0);

// ---- check ------------------------------------------------------------------------------
struct ShaderCheckOptions {
  std::string glslName;  // how the GLSL is named in diagnostics
  TargetEnv env = TargetEnv::Vulkan1_0;
  bool optimize = false;
  uint32_t maxUniformBlockBytes = 16384;  // maxUniformBufferRange every Vulkan device has
};
// spirv-val, the uniform block against maxUniformBlockBytes (located at the largest
// uniform the plan reads), the link with the fragment shader, and (optimize) spirv-opt -O
// + spirv-val again. Returns the final SPIR-V words.
std::vector<uint32_t> checkStage(const LoadedInputs& in, const EmittedGlsl& glsl, const CompiledVertexShader& vertex,
                                 const ShaderCheckOptions& opts);

// ---- translate (when HLSL or MSL is asked for) -------------------------------------------
// The checked SPIR-V (what `--emit spv` writes) through SPIRV-Cross, with the bindings the
// reflection records: emit/cross_compile.h.

// Every file the stages read for this context (rig, fragment shader, rules files and their
// includes, templates): the depfile's prerequisites.
std::vector<std::string> inputsRead(const LoadedInputs& in, const TemplateSet& templates);

}  // namespace sg

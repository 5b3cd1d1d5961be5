// shadergen::core — the generator as a library, for an engine that makes its vertex
// shaders at load time. Standard-library types only; installed as <shadergen/shadergen.h>
// and linked as shadergen::core (find_package(shadergen)). Example: examples/engine/.
//
//   shadergen::Options o;
//   o.rig = "face.rig.yaml";  o.fragment = "face.frag";  o.rules = {rulesDir + "/standard.yaml"};
//   shadergen::Result r = shadergen::generate(o);
//   if (!r.ok) for (auto& d : r.diagnostics) std::cerr << d.text() << "\n";
//   else upload(r.spirv);
#pragma once
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace shadergen {

// What the mesh the program will draw looks like to the device (docs/device-profiles.md,
// "Workload"): a device profile's weights may depend on it. `shadergen explain --device-profile`
// prints these figures for a glTF rig's own mesh or a procedural one; the library prices the
// ones it is given (a glTF rig is not measured here: that takes the measuring stage). Each
// left at its default is unknown, priced at the profile's default.
struct Workload {
  double verticesPerDraw = 0;       // vertices of one draw
  double jointsPerWarp = 0;         // distinct joints a warp's palette load reads, per influence slot
  double activeMorphTargets = -1;   // morph targets with a non-zero weight at once (-1: all)
  double invocationsPerVertex = 0;  // vertex-shader runs per vertex (post-transform cache)
  double fragmentsPerVertex = 0;    // fragments one draw covers, per vertex
  double paletteEntriesPerWarp = 0; // distinct joints a warp reads over all its influences
};

struct Options {
  std::string rig;                   // rig YAML, or a glTF model "model.glb#mesh/primitive"
  std::string fragment;              // the fragment shader to feed (GLSL 450)
  std::vector<std::string> rules;    // rules files
  std::map<std::string, int64_t> rigParameters;  // deformer parameters to set (LODs)
  std::map<std::string, std::vector<std::string>> maps;  // fragment input -> semantics
  std::vector<std::string> conventions;  // naming conventions (like --conventions): empty = all where they agree
  std::string targetEnv = "vulkan1.0";  // .. "vulkan1.3"
  bool optimize = false;             // spirv-opt -O
  std::string templates;             // "" = the templates installed with shadergen
  std::string deviceProfile;         // device profile YAML (docs/device-profiles.md); "" = instruction slots
  // More devices' profiles: with deviceProfile, the portable plan, least worst-case regret
  // across all of them (like --device-profile given several times); `cost` is then that regret
  // times 10^9.
  std::vector<std::string> portableProfiles;
  Workload workload;                 // with a profile: the mesh it prices (like --mesh)
  std::vector<std::string> bannedRules;  // rules the search may not use (like --ban): pin a plan
  // Also the program for Direct3D / Metal, translated from the SPIR-V (docs/hlsl-msl.md);
  // their bindings go into `reflection`. "" = not made.
  std::string hlslShaderModel;       // "5.0", "5.1", "6.0" .. "6.7"
  std::string mslVersion;            // "1.2", "2.0" .. "2.4", "3.0"
  std::string mslPlatform = "macos";  // with mslVersion: "macos" or "ios"
  // A glTF rig (docs/gltf.md#import-diagnostics-and-weights): skin weights renormalised to sum
  // to 1 (as three.js does; false: kept as stored), and the import's warnings as errors.
  bool normalizeSkinWeights = true;
  bool warningsAsErrors = false;
};

struct Diagnostic {
  std::string file;
  int line = 0, column = 0;
  std::string severity;  // "error", "warning", "note"
  std::string message;
  std::string code;          // the glTF-Validator's code of a glTF import finding ("" = none)
  std::string text() const;  // "file:line:col: error: message [code]"
};

struct Result {
  bool ok = false;
  std::string glsl;                   // the vertex shader (Vulkan GLSL 450)
  std::vector<uint32_t> spirv;        // validated SPIR-V
  std::string reflection;             // JSON: vertex inputs, uniform layout, outputs (+ HLSL/MSL bindings)
  std::string hlsl, msl;              // when asked for (Options::hlslShaderModel, mslVersion)
  // Plan cost: instruction slots, or femtoseconds per vertex with a profile (with portable
  // profiles: the plan's worst regret, times 10^9).
  int64_t cost = 0;
  // With a device profile: the plan's amount and predicted nanoseconds per vertex of each
  // cost term ("arithmetic", "locations", ...), and their sum (on Options::deviceProfile's device).
  std::map<std::string, int64_t> termAmounts;
  std::map<std::string, double> termNanoseconds;
  double predictedNanoseconds = 0;
  std::vector<std::string> rules;     // the plan's rules, in order
  std::vector<Diagnostic> diagnostics;  // why it failed (when !ok); the glTF import's warnings (when ok)
};

// Never throws for bad input: failures come back as diagnostics.
Result generate(const Options& options);

const char* version();

}  // namespace shadergen

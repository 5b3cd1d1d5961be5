// The whole generator as one call: the stages of pipeline/stages.h in order
// (load → instantiate → search → emit → compile → check).
#pragma once
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/glsl_compile.h"
#include "emit/cross_compile.h"
#include "emit/glsl_emitter.h"
#include "emit/spirv.h"
#include "interface/fragment_interface.h"
#include "rig/rig.h"
#include "rules/rules.h"
#include "search/astar.h"
#include "search/instance.h"
#include "search/search.h"
#include "search/plan.h"
#include "search/problem.h"
#include "pipeline/pin.h"
#include "pipeline/stages.h"

namespace sg {

constexpr uint32_t kVulkanMinUniformBufferRange = 16384;

struct GenerateOptions {
  std::string rigPath;
  std::string fragmentPath;
  std::vector<std::string> rulesPaths;
  std::vector<VaryingOverride> overrides;
  std::vector<std::string> conventions;  // naming conventions (--conventions): empty = all, unambiguous names
  std::map<std::string, int64_t> rigParams;  // deformer parameters set on the rig (--set)
  // How a glTF rig's data is read (--no-normalize-weights, -Werror; rig/gltf_import.h).
  GltfReadOptions gltf;
  // Error budgets per encoded source semantic, in its encodings' unit: degrees for a direction, a
  // fraction of the bounds diagonal for a position (--max-error; rig/vertex_encoding.h).
  std::map<std::string, double> maxError;
  std::vector<std::string> bannedRules;  // force alternatives (cross-check, explain)
  // A measured choice (--pin, pipeline/pin.h): its bans are searched with as bannedRules are,
  // and the plan found must be the one it pins.
  std::optional<Pin> pin;
  std::string heuristic = "lmcut";
  std::string searchEngine = "auto";  // auto, regression, forward, ip (search/search.h)
  SearchLimits searchLimits;
  std::string templateDir;  // "" = defaultTemplateDir()
  TargetEnv targetEnv = TargetEnv::Vulkan1_0;
  bool optimize = false;
  bool capture = false;  // transform-feedback build for validation
  // The bytes a vertex's capture record (gl_Position and every output) may take on the device
  // that validates the program (rt::Harness::maxCaptureBytes); a record past it is a located
  // error. 0: no device known, not checked here (the harness checks what it runs).
  uint32_t maxCaptureBytes = 0;
  std::string outputName = "shader.vert";  // how the GLSL is named in diagnostics
  // The uniform block must fit the device's maxUniformBufferRange; 16384 bytes is what
  // every Vulkan device guarantees (docs/limits.md). A known device may raise it.
  uint32_t maxUniformBlockBytes = kVulkanMinUniformBufferRange;
  // Vertex input attributes the plan may read (maxVertexInputAttributes; 16 guaranteed).
  // Like the uniform block, a constraint of the search (docs/search.md, "Resource limits").
  int maxAttributes = static_cast<int>(kVulkanMinVertexAttributes);
  int maxStorageBuffers = static_cast<int>(kVulkanMinStorageBuffers);  // maxPerStageDescriptorStorageBuffers
  // The most vertices one draw has (0 = unknown): per-vertex storage buffers larger than
  // maxStorageBufferBytes for that many vertices are not used (docs/buffers.md), and a device
  // profile's per-draw weights are spread over that many (its vertices_per_draw otherwise).
  int64_t maxVertices = 0;
  int64_t maxStorageBufferBytes = int64_t{1} << 27;  // maxStorageBufferRange every device has
  // A device profile (docs/device-profiles.md): the plan is the cheapest in predicted time
  // on that device. "" = the instruction-slot model.
  std::string deviceProfilePath;
  // A portable choice (docs/device-profiles.md, "Portable plans"): more devices' profiles; the
  // plan then has the least worst-case regret (its predicted time over each device's best)
  // across deviceProfilePath and these.
  std::vector<std::string> portableProfilePaths;
  // What the mesh the program will draw looks like (search/workload.h): measured by the caller
  // (measure/workload.h: the CLI, bench, calibrate), unknown by default. A device profile's
  // weights may depend on it; explain shows it, the reflection records it with a profile.
  Workload workload;
  // Also translate the checked SPIR-V to HLSL / MSL (emit/cross_compile.h, docs/hlsl-msl.md).
  std::optional<HlslOptions> hlsl;
  std::optional<MslOptions> msl;
};

struct GenerateResult {
  LoadedInputs in;
  Plan plan;
  SearchStats stats;
  EmittedGlsl glsl;
  SpirvModule spirv;
  std::optional<CrossShader> hlsl, msl;  // translated from spirv.words when asked for
  std::vector<std::string> inputsRead;  // every file read (for depfiles)
  // The files a pin's digest covers (pipeline/pin.h): those read but the device profiles and the
  // pin (generate --pin needs no profile: the bans fix the plan).
  std::vector<std::string> pinnedInputs;
};

const char* shadergenVersion();

LoadedInputs loadInputs(const GenerateOptions& opts);
// The search generate runs: opts' bans and engine, the device limits (attributes, uniform block,
// storage buffers; per-vertex buffers past maxStorageBufferBytes dropped) and, with several device
// profiles, the least worst-case regret. `in.problem` is left as searched, so that `explain`
// re-searches each choice's alternative under the same limits. Throws the located error when no
// plan fits.
Plan searchUnderOptions(LoadedInputs& in, const GenerateOptions& opts, SearchStats* stats = nullptr);
// The k plans cheapest under the search's objective (a device profile's predicted time, a
// portable choice's worst regret, or instruction slots), cheapest first (ties: by rule names),
// each with the rules to ban, beside opts' own, that make the search return it. Found best
// first over sets of bans: each plan's set spawns one set per rule of the plan, that rule
// added (Lawler's partition without its inclusion constraints; a plan found twice still
// spawns). Every plan is reached whose rule names are not a superset of a cheaper plan's.
// Fewer than k where fewer exist; at most `maxSearches` searches.
struct RankedPlan {
  std::vector<std::string> bans;   // sorted
  std::vector<std::string> rules;  // the plan's rule names, sorted, each once
  int64_t cost = 0;                // the search's objective
};
std::vector<RankedPlan> cheapestPlans(const LoadedInputs& in, const GenerateOptions& opts, size_t k,
                                      size_t maxSearches = 512);
// A portable choice's devices (in.profile, then in.portable): each one's cheapest plan under its
// own profile alone, with the bans beside opts' own that leave it the only derivation of its facts
// (bansPinning), so the portable search returns it. A measured portable choice times them beside
// the cheapest under the worst regret: where a profile mispredicts another device, the plan one
// device runs best can be the least worst regret (bench/data/pin41). Empty without several profiles.
std::vector<RankedPlan> eachDevicesCheapest(const LoadedInputs& in, const GenerateOptions& opts);
// The bans that leave `plan` the only derivation its facts have: every other rule producing a
// fact the plan produces, and the bans it was searched with (`p` no longer has those rules). A
// plan pinned by them stays the plan whatever the costs (the workload, the profile) it is
// searched under (bench --pin-out, generate --pin). Sorted.
// The checks a pin gets wherever it is read: the plan found under its bans must have its rules
// (else a located error at `rules:`: the inputs changed what the bans leave), and the files its
// digest covers (inputsRead less the device profiles and the pin).
void checkPin(const Pin& pin, const Problem& problem, const Plan& plan);
std::vector<std::string> pinnedInputs(const LoadedInputs& in, const TemplateSet& templates);
std::vector<std::string> bansPinning(const Problem& p, const Plan& plan, const std::vector<std::string>& searchedWith);
// The stages after loading, for a rig already loaded (loadInputs and `build` share them):
// the error budgets (opts.maxError) take over-budget encodings out of the rig; a value the
// rig stores both as itself and encoded is read in the form whose plan is cheapest; then
// instantiation (opts.overrides, opts.conventions) and, with a profile, pricing. The
// result's notes are the rig's import diagnostics (taken out of the rig), then what the
// budgets removed and which stored form is read.
// `portable`: the
// other devices of a portable choice (each plan is then priced by its worst regret).
LoadedInputs prepareInputs(Rig rig, const RuleSet& rules, const FragmentInterface& fragment, const GenerateOptions& opts,
                           const std::optional<DeviceProfile>& profile, const std::vector<DeviceProfile>& portable = {});

// Throws InputError for bad inputs or unsatisfiable requests (naming the missing values).
GenerateResult generate(const GenerateOptions& opts);
// Same, from already loaded inputs (cross-check runs reuse one load).
GenerateResult generateFrom(LoadedInputs in, const GenerateOptions& opts);
// Same, with templates already loaded (batch builds load them once).
GenerateResult generateWith(LoadedInputs in, const TemplateSet& templates, const GenerateOptions& opts);

// The reflection JSON of a generated shader (emit/reflection.h), with the plan's predicted
// cost per term when the inputs were priced with a device profile.
std::string reflectionOf(const GenerateResult& r);

// For an unsolvable problem: why each unreachable goal cannot be produced.
std::string explainUnreachable(const Problem& p, const RuleSet& rules);

}  // namespace sg

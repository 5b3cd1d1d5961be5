// Subcommands of the CLI. Each registers its options and sets CliState::run.
#pragma once
#include <CLI/CLI.hpp>

#include <functional>
#include <string>
#include <vector>

#include "cli/output_files.h"
#include "pipeline/generate.h"
#include "runtime/vk_program.h"

namespace sg {

struct CliState {
  std::function<int()> run;
  // The command line as main received it (its glslc spellings normalised): what a command that
  // times each rig in a fresh process runs again (cli/fresh_process.h).
  std::vector<std::string> commandLine;
};

const char* shadergenVersionString();

// Options shared by every command that generates: --rig, --fragment, --rules, --map...
struct GenerateArgs {
  GenerateOptions opts;
  std::vector<std::string> maps;  // "Name=sem[,sem...]"
  std::vector<std::string> sets;  // "param=value" (rig deformer parameters)
  std::vector<std::string> maxErrors;  // "semantic=0.1deg" (error budgets)
  std::vector<std::string> profiles;   // --device-profile, once per device (several: a portable plan)
  std::string targetEnv = "vulkan1.0";
  std::string pin;  // --pin: a measured choice (pipeline/pin.h), read by resolve
  CLI::Option* maxAttributes = nullptr;  // whether the device limits were given (applyDeviceLimits)
  CLI::Option* maxUniformBytes = nullptr;
  std::vector<CLI::Option*> generateOptions;  // every option add() registers but the glTF reading ones
  void add(CLI::App& cmd, bool inputsRequired = true);  // false: the command checks --rig, -f, -r itself
  GenerateOptions resolve() const;  // parses --map and --target-env (throws CLI::ValidationError), reads --pin
};

// --hlsl-shader-model, --msl-version, --msl-platform (generate; validate --via hlsl takes
// the shader model). Empty = not given (the defaults of emit/cross_compile.h).
struct CrossArgs {
  std::string shaderModel, mslVersion, mslPlatform;
  void add(CLI::App& cmd, bool msl);
  // Sets o.hlsl / o.msl for the languages asked for. A value no translation supports, or an
  // option for a language not asked for, throws CLI::ValidationError.
  void resolve(bool hlsl, bool msl, GenerateOptions& o) const;
};

// --no-normalize-weights and (werror) --Werror (-Werror), for every command that imports a
// glTF rig (docs/gltf.md#import-diagnostics-and-weights).
void addGltfReadOptions(CLI::App& cmd, GltfReadOptions& o, bool werror = true);

// --input-memory device-local|mapped, for every command that times programs (bench, calibrate).
void addInputMemoryOption(CLI::App& cmd, rt::InputMemory& memory);
// --one-process, for every command that times several rigs (bench MODEL.glb#*, calibrate): time
// them all in this process instead of each in a fresh one (cli/fresh_process.h). `what`: "rig", "part".
void addOneProcessFlag(CLI::App& cmd, bool& oneProcess, const std::string& what);
// --processes N, beside --one-process (which it excludes): each `what` timed in N fresh processes,
// their rounds merged (cli/fresh_process.h benchInFreshProcesses).
void addProcessesOption(CLI::App& cmd, uint32_t& processes, const std::string& what);

// Every file `in` was loaded from (plus `extra`), named for refuseClobbering (output_files.h).
std::vector<InputFile> inputFiles(const LoadedInputs& in, const std::vector<std::string>& extra = {});

// Options that do not apply to the inputs given are usage errors, not silence: throws
// CLI::ValidationError("--mesh does not apply ...: why") when `option` was given on `cmd`.
void refuseOption(const CLI::App& cmd, const std::string& option, const std::string& why);

// CLI11's NonNegativeNumber/PositiveNumber let "nan" and "inf" through (every comparison
// with NaN is false); this refuses them: "must be a finite number >= 0, got 'nan'".
CLI::Validator finiteNumber(bool positive);

// The workload a generation is priced for (measure/workload.h): a glTF rig's own mesh, or
// for a YAML rig the procedural mesh `mesh` ("" = unknown). Sets o.workload.
void measureWorkloadOf(GenerateOptions& o, const std::string& mesh);
// One primitive of a whole model (MODEL.glb#*) as its own rig: `base` with rigPath = partRef,
// priced for that primitive's own mesh under a device profile, as MODEL.glb#m/p is.
GenerateOptions partOptions(const GenerateOptions& base, const std::string& partRef);

void registerCommands(CLI::App& app, CliState& state);
void registerGenerate(CLI::App& app, CliState& state);
void registerValidate(CLI::App& app, CliState& state);
void registerCheck(CLI::App& app, CliState& state);    // cmd_check.cpp
void registerExplain(CLI::App& app, CliState& state);  // cmd_explain.cpp: explain + graph
void registerRig(CLI::App& app, CliState& state);      // cmd_rig.cpp: rig import
void registerBuild(CLI::App& app, CliState& state);    // cmd_build.cpp: variant manifests
void registerPack(CLI::App& app, CliState& state);     // cmd_pack.cpp: vertex streams from float data
void registerPin(CLI::App& app, CliState& state);      // cmd_pin.cpp: pin merge (several devices' measured choices)
void registerBake(CLI::App& app, CliState& state);     // cmd_bake.cpp: bake occlusion
void registerRender(CLI::App& app, CliState& state);   // cmd_render.cpp: render + bench (GPU timing)
void registerCalibrate(CLI::App& app, CliState& state);  // cmd_calibrate.cpp: device profiles

}  // namespace sg

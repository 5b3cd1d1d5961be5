// Validation: run a generated shader on a Vulkan device (lavapipe by default) over a
// mesh in given poses and compare every output with the GLM reference of its
// semantics. Tolerances and their justification: docs/validation.md.
#pragma once
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "pipeline/generate.h"
#include "runtime/mesh.h"
#include "runtime/vk_harness.h"
#include "validate/program_inputs.h"
#include "validate/interpreter.h"

namespace sg {

struct Tolerance {
  // A component passes if |gpu - ref| <= abs + rel * max(1, |ref|_max), where |ref|_max is
  // the largest reference component of that output at that vertex.
  double abs = 1e-6;
  double rel = 1e-5;
  // Both sides non-finite (NaN or infinity) at a component counts as agreement: rule checking
  // (validate/rule_check.h) feeds inputs where a definition is undefined, and a rule agrees
  // with it there when it is undefined too.
  bool nonFiniteAgrees = false;
};

struct OutputReport {
  std::string name;                    // "gl_Position", "WorldEyeDir", ...
  std::vector<std::string> semantics;  // what it carries
  std::string type;                    // GLSL type of an element ("vec3")
  int components = 0;                  // per vertex (all elements of an array)
  double maxAbsError = 0;
  double maxRelError = 0;  // |gpu - ref| / max(1, |ref|_max)
  size_t worstVertex = 0;
  int worstComponent = 0;
  std::vector<double> worstGpu, worstReference;  // the output's components at the worst vertex
  bool pass = true;        // every check below
  bool storedPass = true;  // the first check alone: within the tolerance of the reference on the data as stored
  // A semantic it carries has no definition (and the rig does not provide it): not compared.
  bool unchecked = false;
  std::string uncheckedReason;
  // The first NaN or infinity seen, on which side, where, and the inputs that produced it.
  std::string nonFinite;
  // The second check, for a rig that stores encoded or quantized streams: the device against
  // the reference on the original float data, within the float tolerance plus the derived
  // bound of what storing the inputs may change (validate/float_check.h).
  struct FloatCheck {
    bool ran = false;
    bool pass = true;
    double maxDeviation = 0;  // max |gpu - float reference|
    double ratio = INFINITY;  // the smallest tolerance / |gpu - float reference| (< 1 fails)
    double tolerance = 0, deviation = 0;  // where the ratio is smallest
    size_t worstVertex = 0;
    int worstComponent = 0;
    size_t notCompared = 0;  // components whose float reference or tolerance is not finite
  } floatCheck;
};

struct RunReport {
  std::string label;  // "chosen plan" or "forced: <rule> for <semantic>"
  std::vector<std::string> rules;  // plan rules in order
  int64_t planCost = 0;
  size_t vertices = 0;
  std::vector<OutputReport> outputs;
  std::vector<std::string> validationMessages;
  rt::RunTimings timings;
  double referenceMs = 0;
  double floatCheckMs = 0;  // the float reference and its tolerances
  size_t floatCheckStride = 1;  // the second check compared every this-th vertex
  double generateMs = 0;
  bool pass = true;
  // Per pose (as the scene lists them), every output compared on that pose alone; `outputs`
  // above is their union (worst over the poses).
  std::vector<std::vector<OutputReport>> poseOutputs;
  // What the device computed, when ValidateOptions::keepOutputs (the chosen plan only):
  // [pose][output], `components` values per vertex (integers converted to float).
  std::vector<std::vector<std::vector<float>>> captured;
};

struct ValidateReport {
  std::string device;
  std::string driver;  // "<driver name> <driver info>"
  std::string via = "SPIR-V";  // what ran: "SPIR-V", or "HLSL 5.0 (compiled back by glslang)"
  std::string limits;  // the device limits the plans were searched under (applyDeviceLimits)
  bool validationLayers = false;
  std::vector<RunReport> runs;
  bool pass = true;
  std::vector<rt::Pose> poses;  // as run (declared uniforms drawn): what --save-poses writes
  std::vector<Diagnostic> notes;  // what loading decided (stored forms, error budgets)
};

// What to run the shader on.
struct ValidationScene {
  rt::Mesh mesh;
  std::vector<rt::Pose> poses;
  rt::RigShape shape;
};

// A procedural scene matching the rig: "head" (default), "limb", or "dawn" (180k vertices).
// Throws InputError if the rig asks for something the procedural meshes can't supply.
ValidationScene proceduralScene(const Rig& rig, const std::string& mesh, uint32_t seed, int poses);
// The same for a rig file as the program is generated for it: with the deformer parameters set
// (--set, a variant's level of detail), so the poses hold the targets and influences it reads.
ValidationScene proceduralScene(const std::string& rigPath, const std::map<std::string, int64_t>& params,
                                const std::string& mesh, uint32_t seed, int poses);

// For rigs with an active-target list (morph.active_targets, docs/buffers.md): keeps, per
// pose, a seeded choice of as many non-zero morph weights as the list holds.
void limitActiveTargets(const Rig& rig, std::vector<rt::Pose>& poses, uint32_t seed);

// What runs on the device: the SPIR-V (its GLSL's capture build), or the HLSL translated
// from the shipped SPIR-V, compiled back by glslang's HLSL front end (docs/hlsl-msl.md).
enum class ValidateVia { Spirv, Hlsl };

// The search's device limits when a plan is run on a named device (docs/limits.md, "Device
// limits"): `validate`, `render` and `bench --device` read them from the Vulkan physical
// device; a limit given on the command line is kept below the device's and clamped to it
// above (a plan over the device's limits could not run there).
struct DeviceLimitsOptions {
  bool fromDevice = false;
  bool attributesGiven = false;    // --max-attributes
  bool uniformBytesGiven = false;  // --max-uniform-bytes
};
// Sets gen's maxAttributes, maxUniformBlockBytes, maxStorageBuffers and
// maxStorageBufferBytes from `device` as `o` says; returns one line saying what was used
// and where from ("" when o.fromDevice is false: gen is left as it is).
std::string applyDeviceLimits(GenerateOptions& gen, const DeviceLimitsOptions& o, const rt::Harness& device);

struct ValidateOptions {
  GenerateOptions gen;
  ValidateVia via = ValidateVia::Spirv;
  DeviceLimitsOptions limits;
  bool crossCheck = false;  // also force each alternative derivation and check it
  Tolerance tolerance;
  std::string device;       // "" = lavapipe
  bool validationLayers = true;
  bool strict = false;  // an unchecked output (no definition) fails the run
  // Also check against the original float data (OutputReport::FloatCheck) when the rig
  // stores encoded or quantized streams.
  bool checkFloatData = true;
  // At most this many vertices (every k-th) in the second check; 0: all.
  size_t floatCheckVertices = 20000;
  // Keep the chosen plan's captured outputs (RunReport::captured), for --save-outputs.
  bool keepOutputs = false;
};

class Validator {
 public:
  explicit Validator(const ValidateOptions& opts);
  ~Validator();
  // Generates (capture build), runs every pose, compares. With crossCheck, repeats for
  // every alternative derivation of each semantic in the plan.
  ValidateReport run(const ValidationScene& scene);
  // Same with other generation options (another primitive of a whole model, on this device).
  ValidateReport run(const ValidationScene& scene, const GenerateOptions& gen);
  // One generation result on the scene (no cross-check); exposed for tests and benchmarks.
  RunReport runOne(const GenerateResult& r, const ValidationScene& scene, const std::string& label);
  // The device it runs on (render and bench draw on the same one).
  const rt::Harness& harness() const { return *harness_; }
  std::string deviceName() const { return harness_->deviceName(); }

 private:
  struct ReferenceCache;  // reference values by pose, shared by the runs of one validation
  // runOne on a mesh already quantized to the rig's attribute formats.
  RunReport runQuantized(const GenerateResult& r, const rt::Mesh& mesh, const ValidationScene& scene,
                         const std::vector<rt::Pose>& poses, const std::string& label, ReferenceCache* cache = nullptr,
                         bool keepOutputs = false);

  ValidateOptions opts_;
  std::unique_ptr<rt::Harness> harness_;
  std::string limits_;  // applyDeviceLimits's line
  size_t reportedMessages_ = 0;  // layer messages already attributed to a run (setup's go to the first)
};

std::string formatReport(const ValidateReport& report);

// The HLSL of `r` (r.hlsl, as `generate --emit hlsl` writes it) compiled back to SPIR-V by
// glslang's HLSL front end, its inputs and outputs bound by the semantics r.hlsl's
// reflection gives them (as a Direct3D input layout and pixel shader bind them), registers
// to the Vulkan bindings, and captured at the GLSL capture build's offsets. Throws
// InputError if it does not compile or validate.
std::vector<uint32_t> hlslCaptureModule(const GenerateResult& r, TargetEnv env);
// `asfloat(uintRxC(a, ...))` rewritten as `floatRxC(asfloat(a), ...)`, the same value:
// glslang cannot compile integer matrices to valid Vulkan SPIR-V (hlslCaptureModule).
std::string withoutIntegerMatrices(const std::string& hlsl);

}  // namespace sg

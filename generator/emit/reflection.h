// The interface the application must bind, as JSON: vertex inputs (location, format,
// semantics), the uniform block (std140 offsets as compiled), and the outputs.
#pragma once
#include <string>

#include "emit/cross_compile.h"
#include "emit/glsl_emitter.h"
#include "emit/spirv.h"
#include "rig/rig.h"
#include "search/device_profile.h"
#include "search/workload.h"

namespace sg {

// With a device profile, also the plan's predicted cost per term ("predicted_cost") and the
// workload it was priced for ("workload", when given); with
// translations, how a Direct3D ("hlsl") or Metal ("msl") host binds them (docs/hlsl-msl.md).
std::string reflectionJson(const Rig& rig, const EmittedGlsl& glsl, const SpirvModule& spirv,
                           const DeviceProfile* profile = nullptr, const PlanCostPrediction* predicted = nullptr,
                           const CrossShader* hlsl = nullptr, const CrossShader* msl = nullptr,
                           const Workload* workload = nullptr);

// A C/C++ header defining `static const uint32_t <symbol>[]` with the SPIR-V words.
std::string spirvHeader(const std::vector<uint32_t>& words, const std::string& symbol);
// #defines of every storage buffer's binding, stride and count ("" when there are none),
// appended to the SPIR-V header.
std::string buffersHeader(const EmittedGlsl& glsl, const std::string& symbol);
// The vertex inputs' part of the same header: `<SYMBOL>_INPUT_COUNT`, and per input
// `<SYMBOL>_<INPUT>_LOCATION`, `_FORMAT` (the VkFormat's value) and `_STRIDE` (bytes).
std::string vertexInputsHeader(const Rig& rig, const EmittedGlsl& glsl, const std::string& symbol);

}  // namespace sg

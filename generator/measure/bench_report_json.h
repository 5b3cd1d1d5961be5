// A bench report as JSON and back: how a rig timed in a process of its own hands its rows to the
// process that asked for them (cli/fresh_process.h; docs/device-profiles.md, "One process per rig").
// Every field round-trips exactly (NaN as null); notes keep their severity, place and code.
#pragma once
#include <string>

#include "common/diagnostics.h"
#include "measure/gpu_bench.h"

namespace sg {

std::string benchReportJson(const GpuBenchReport& report);
// An input error in place of a report (a rig that cannot be generated), with its related findings.
std::string inputErrorJson(const InputError& error);
// Throws the InputError where the text holds one, std::runtime_error where it is neither.
GpuBenchReport benchReportFromJson(const std::string& json);

}  // namespace sg

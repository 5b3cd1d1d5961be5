// One process per rig (docs/device-profiles.md, "One process per rig"): within one process NVIDIA's
// timings of a rig depend, reproducibly and by up to 30 % per program, on the rigs the process timed
// before it, while a fresh process times each rig alike every time (bench/data/h100-order25). So
// `bench MODEL.glb#*` and `calibrate` time each rig in a fresh shadergen process: this executable
// again, with the command line it was started with and the options that name the one rig.
#pragma once
#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "measure/gpu_bench.h"

namespace sg {

// Runs /proc/self/exe with `commandLine` (this process's, as main received it) plus
// `--child-report FILE` and `extra`, waits for it and returns the report it wrote there. Its standard
// output and error are this process's. The child's input error is rethrown here as that
// InputError; a child that wrote nothing (a crash, a kill) is a std::runtime_error naming `what`.
// `finishOnInterrupt`: the child starts with SIGINT blocked, so an interrupt sent to the whole
// process group (Ctrl-C, `timeout -s INT`) lets it finish its rig while the parent stops after it
// (calibrate's rule); otherwise an interrupt ends the child with its parent (bench).
GpuBenchReport benchInFreshProcess(const std::vector<std::string>& commandLine, const std::vector<std::string>& extra,
                                   const std::string& what, bool finishOnInterrupt);

// `processes` such children, one after another, as one report (measure/gpu_bench.h
// mergeProcessRuns; one: that child's report as it is). Once `stop` is set (calibrate's
// interrupt) no further child starts, and the ones timed are merged.
GpuBenchReport benchInFreshProcesses(const std::vector<std::string>& commandLine, const std::vector<std::string>& extra,
                                     const std::string& what, bool finishOnInterrupt, uint32_t processes,
                                     const std::atomic<bool>* stop = nullptr);

// In the child: times with `time` and writes its report, or the input error it threw, to `path`
// for the parent.
void writeFreshProcessReport(const std::string& path, const std::function<GpuBenchReport()>& time);

}  // namespace sg

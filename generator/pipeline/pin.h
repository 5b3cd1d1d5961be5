// A pin: the plan a device timed fastest among the cheapest candidates (bench --candidates
// --pin-out), kept as the bans that leave it the only derivation of its facts, so that
// generate --pin writes that plan on any machine, with or without the device. The file also
// says where and how it was measured, the plan's rules (generate checks it still gets them)
// and a digest of the inputs' bytes (a change is reported). docs/performance.md, "A measured
// choice".
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "common/diagnostics.h"

namespace sg {

struct Pin {
  std::string file;                   // where it was read from (read pins; a depfile lists it)
  std::string device, driver, clock;  // where and by which clock it was timed
  std::string label;                  // bench's row: "generated", "cheapest plan #3"
  std::string program;                // the SPIR-V timed (bench's GpuBenchRow::program)
  std::vector<std::string> rules;     // the pinned plan's rule names, sorted, each once
  std::vector<std::string> bans;      // sorted
  std::string inputs;                 // sha256OfFiles (common/content_hash.h) of GenerateResult::pinnedInputs
  double nsPerVertex = -1;            // the pinned plan's median round (measure/gpu_bench.h pinnedPlan)
  double generatedNsPerVertex = -1;   // the search's own choice's, in the same run
  size_t candidates = 0;              // how many validated plans were timed
  SourceLoc rulesLoc, banLoc, inputsLoc;  // where a check against them points (read pins)
};


// Pin files: YAML, one document; every key required. A malformed one is a located error.
std::string formatPin(const Pin& pin);
Pin parsePin(const std::string& text, const std::string& file);
Pin loadPin(const std::string& path);
// The warning, at the pin's `inputs:`, when `inputsDigest` (sha256OfFiles of
// GenerateResult::pinnedInputs: the rig, request, rules and templates) is not the digest of the
// bytes the pin was measured with; the pin still gives its plan. Every command that reads a pin
// says it through this. (The caller hashes: libcrypto stays out of shadergen_core.)
std::optional<Diagnostic> pinInputsChanged(const Pin& pin, const std::string& inputsDigest);

}  // namespace sg

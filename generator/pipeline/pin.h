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

// One device's timing of a pin's plan. A pin from bench has one; `shadergen pin merge` writes one
// per device it weighed.
struct PinTiming {
  std::string device, driver, clock;  // where and by which clock it was timed
  double nsPerVertex = -1;            // the pinned plan's median round (measure/gpu_bench.h pinnedPlan)
  double fastestNsPerVertex = -1;     // the fastest plan this device timed (bench's own pin: the pinned plan)
  double generatedNsPerVertex = -1;   // the search's own choice's, in the same run
  bool operator==(const PinTiming&) const = default;
};

// A plan bench weighed, as its pin records it for `pin merge`.
struct TimedPlan {
  std::string label, program;
  std::vector<std::string> rules, bans;  // sorted, as Pin's
  double nsPerVertex = -1;               // its median round
  bool operator==(const TimedPlan&) const = default;
};

struct Pin {
  std::string file;                   // where it was read from (read pins; a depfile lists it)
  std::vector<PinTiming> devices;     // one (bench --pin-out), or two or more (pin merge)
  std::string label;                  // bench's row: "generated", "cheapest plan #3"
  std::string program;                // the SPIR-V timed (bench's GpuBenchRow::program)
  std::vector<std::string> rules;     // the pinned plan's rule names, sorted, each once
  std::vector<std::string> bans;      // sorted
  std::string inputs;                 // sha256OfFiles (common/content_hash.h) of GenerateResult::pinnedInputs
  size_t candidates = 0;              // how many validated plans were timed (merged: timed on every device)
  std::vector<TimedPlan> timed;       // bench's pins since session 41: every plan it weighed (pin merge reads them)
  SourceLoc rulesLoc, banLoc, inputsLoc;  // where a check against them points (read pins)
  SourceLoc loc;                          // the pin's first key (read pins)
  std::string deviceNames() const;        // "A" or "A + B"
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

// A portable measured choice (docs/performance.md, "Several devices"): of the plans every pin
// timed (the same rules and the same program), the one whose worst regret, its time on a device
// over the fastest plan that device timed, is least; ties go to the first pin's order (its
// objective's). Each pin is bench's own for one device, with its `timed` plans, all of the same
// inputs; anything else, or no plan timed on every device, is an InputError at the pin.
Pin mergePins(const std::vector<Pin>& pins);

}  // namespace sg

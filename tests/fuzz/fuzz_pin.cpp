// libFuzzer: the pin loader (YAML text → Pin; pipeline/pin.h). Besides crashes and sanitizer
// reports, a finding is a pin that does not survive its own writer: formatPin of a parsed pin
// parse back to the same fields, every one (bench --pin-out writes what generate --pin reads).
#include <cstdio>
#include <cstdlib>

#include "fuzz_util.h"
#include "pipeline/pin.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  sg::fuzz::expectInputErrorsOnly([&] {
    const sg::Pin a = sg::parsePin(sg::fuzz::text(data, size), "fuzz.pin.yaml");
    sg::Pin b;
    try {
      b = sg::parsePin(sg::formatPin(a), "again.pin.yaml");
    } catch (const sg::InputError& e) {
      std::fprintf(stderr, "formatPin wrote a pin parsePin refuses: %s\n%s", sg::formatDiagnostic(e.diagnostic()).c_str(),
                   sg::formatPin(a).c_str());
      std::abort();
    }
    const bool same = a.devices == b.devices && a.label == b.label && a.program == b.program && a.rules == b.rules &&
                      a.bans == b.bans && a.inputs == b.inputs && a.candidates == b.candidates && a.timed == b.timed;
    if (!same) {
      std::fprintf(stderr, "a pin does not survive formatPin:\n%s", sg::formatPin(a).c_str());
      std::abort();
    }
  });
  return 0;
}

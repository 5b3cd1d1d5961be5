// libFuzzer: fragment shader reflection (GLSL text → the inputs it requests).
#include "fuzz_util.h"
#include "interface/fragment_interface.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  sg::fuzz::expectInputErrorsOnly([&] { sg::reflectFragmentSource(sg::fuzz::text(data, size), "fuzz.frag"); });
  return 0;
}

// libFuzzer: the rig loader (YAML text → Rig, checkRig).
#include "fuzz_util.h"
#include "rig/rig.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  sg::fuzz::expectInputErrorsOnly([&] { sg::loadRigText(sg::fuzz::text(data, size), "fuzz.rig.yaml"); });
  return 0;
}

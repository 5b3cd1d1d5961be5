// Tests that drive the Vulkan runtime call this before making their Harness: the validation
// layer then also reports synchronization hazards (a staging copy read without its barrier,
// frames drawn into one target), which the tests refuse like any other message. The layer
// reads the variable when an instance is made; one the environment already sets is kept.
//
// Not in the sanitizer builds: the layer (1.3.239) never frees its synchronization state, and
// once the loader unloads it LeakSanitizer reports that as leaks in an unknown module, which
// no suppression by module can name. The plain build runs the checks.
#pragma once
#include <stdlib.h>

namespace sgtest {

inline void enableSynchronizationValidation() {
#if !defined(SG_SANITIZED)  // tests/CMakeLists.txt: the sanitizer builds define it
  setenv("VK_LAYER_ENABLES", "VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT", /*overwrite=*/0);
#endif
}

}  // namespace sgtest

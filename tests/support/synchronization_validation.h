// Tests that drive the Vulkan runtime call this before making their Harness: the validation
// layer then also reports synchronization hazards (a staging copy read without its barrier,
// frames drawn into one target), which the tests refuse like any other message. The layer
// reads the variable when an instance is made; one the environment already sets is kept.
//
// The layer (1.3.239) never frees its synchronization state. In the sanitizer builds the test
// keeps the layer's library mapped after the loader unloads it, so that LeakSanitizer names
// the module and cmake/sanitizers/lsan.supp can suppress it, as it does the driver's.
#pragma once
#include <dlfcn.h>
#include <stdlib.h>

namespace sgtest {

inline void enableSynchronizationValidation() {
#if defined(SG_SANITIZED)  // tests/CMakeLists.txt: the sanitizer builds define it
  static void* const kept = dlopen("libVkLayer_khronos_validation.so", RTLD_NOW | RTLD_LOCAL);
  (void)kept;
#endif
  setenv("VK_LAYER_ENABLES", "VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT", /*overwrite=*/0);
}

}  // namespace sgtest

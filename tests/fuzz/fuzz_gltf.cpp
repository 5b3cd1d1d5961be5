// libFuzzer: glTF import. Inputs starting with "glTF" go through a .glb file (the GLB
// reader works on files), others are JSON text without a folder (no buffer files). What
// imports is then posed: node globals at a few times of its first animation.
#include "fuzz_util.h"
#include "rig/gltf_import.h"
#include "validate/gltf_scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string bytes = sg::fuzz::text(data, size);
  sg::fuzz::expectInputErrorsOnly([&] {
    sg::GltfImport imp = bytes.rfind("glTF", 0) == 0
                             ? sg::importGltf(sg::fuzz::writeScratch("fuzz.glb", bytes))
                             : sg::importGltfText(bytes, "fuzz.gltf");
    int anim = imp.data.animations.empty() ? -1 : 0;
    std::vector<double> weights;
    for (double t : {-1.0, 0.0, 0.37, 1e6}) (void)sg::gltfNodeGlobals(imp.data, anim, t, &weights);
  });
  return 0;
}

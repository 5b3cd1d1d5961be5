// The embedded face shader. Kept in its own small translation unit: a regenerated
// shader recompiles this file only, not the program.
#include "face.spv.h"  // generated (EMBED): static const uint32_t face_spv[]; face_spv_size (bytes)

#include <cstdint>
#include <vector>

std::vector<uint32_t> faceShaderWords() { return std::vector<uint32_t>(face_spv, face_spv + face_spv_size / sizeof(uint32_t)); }

// EXT_meshopt_compression (docs/gltf.md#compressed-models): buffer views stored compressed
// in another buffer, decoded with meshoptimizer's decoder into the view's own buffer (the
// "fallback" buffer, which gltfpack writes without data) before any accessor reads them.
#pragma once
#include <cstddef>
#include <map>
#include <string>

#include "rig/gltf_tinygltf.h"

namespace sg::gltf {

// Decodes every compressed buffer view of the loaded model. `fallbackLengths`: buffers the
// loader gave tinygltf as empty (index → the byteLength the file declares); they are
// allocated here. Every offset, length, stride, count, mode and filter is checked, and the
// bytes allocated are charged to `budget` (the import's decoded-data budget) before they are.
// Returns the bytes allocated.
size_t decodeMeshopt(tinygltf::Model& model, const std::map<int, size_t>& fallbackLengths, size_t budget,
                     const std::string& file);

// Bytes of the buffers decodeMeshopt decompressed into (those marked as fallback buffers),
// which the import charges to its decoded-data budget.
size_t fallbackBytes(const tinygltf::Model& model);

}  // namespace sg::gltf

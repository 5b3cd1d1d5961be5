// Loading a glTF model (docs/gltf.md#hostile-models): the file, its JSON and its buffer
// files, checked before tinygltf sees them (bounded reads, JSON depth, GLB layout, buffer
// files confined to the model's folder).
#pragma once
#include <cstddef>
#include <string>
#include <vector>

#include "rig/gltf_tinygltf.h"

namespace sg::gltf {

// Reads and parses the model with every check, refuses required extensions it cannot read,
// and decodes EXT_meshopt_compression views; returns the bytes of the file and its buffers
// as stored (compressed), which set the decoded-data budget.
// `text`: the JSON itself (file only names it; buffer files only inside baseDir).
size_t loadChecked(const std::string& file, const std::string* text, const std::string& baseDir,
                   tinygltf::Model& model, std::vector<std::string>* buffersRead = nullptr);

}  // namespace sg::gltf

// The packer: the vertex streams a generated program reads, written from a mesh's float
// data in the formats its rig stores (encoded semantics derived from their sources, values
// rounded as the device reads them), through the same path validation feeds the device.
// What an application uploads, with a layout that needs none of this code to read.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "pipeline/generate.h"
#include "runtime/mesh.h"

namespace sg {

struct PackedVertices {
  size_t vertexCount = 0;
  std::vector<uint8_t> bytes;  // every stream, then every per-vertex storage buffer, each at a 16-byte aligned offset
  size_t storageBuffers = 0;   // per-vertex storage buffers among them
  // {"vertex_count", "bytes", "streams": [{"input", "location", "attribute", "target",
  //  "format", "offset", "stride", "size", "provides": [{semantic, components[, encodes,
  //  encoding, max_error_deg]}]}] in location order, "storage_buffers": [the reflection's
  //  entry plus "offset", "size"], "palettes" (the reflection's entries: written each
  //  frame), "uniforms"}; written with nlohmann::json.
  std::string layoutJson;
};

// Throws InputError when the mesh lacks a semantic an input carries.
PackedVertices packVertices(const GenerateResult& r, const rt::Mesh& mesh);

}  // namespace sg

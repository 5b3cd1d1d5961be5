#include "validate/pack.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>

#include "rig/packed_fields.h"
#include "rig/vertex_encoding.h"
#include "validate/program_inputs.h"

namespace sg {
namespace {

// Data from another file (`pack --rig rig.yaml --model M.glb#m/p`) was never checked against
// the rig as its own import is: a joint index past the rig's palette would be packed as is
// (the program reads outside `bones`) or saturated by a narrower format (joint 299 stored as
// 255 in uint8x4, another bone). Sets the rig does not read are left out on purpose (a
// level-of-detail rig reads fewer influences).
void checkJoints(const Rig& rig, const rt::Mesh& mesh) {
  const int64_t bones = rig.param("bones");
  for (const RigAttribute& a : rig.attributes)
    for (const ProvidedPart& p : a.provides) {
      if (p.semantic.rfind("skin.joints[", 0) != 0 || !mesh.has(p.semantic)) continue;
      const VertexFormat format = partFormat(a, p);
      const auto& joints = mesh.at(p.semantic);
      for (size_t v = 0; v < mesh.vertexCount; ++v)
        for (int c = 0; c < formatComponents(format) && c < 4; ++c) {
          const float j = joints[v][c];
          if (j >= static_cast<float>(bones) || storedValue(format, c, j) != j)
            throw InputError(a.loc, fmt::format("mesh '{}' vertex {} uses joint {} ({}), but rig '{}' has {} bones in "
                                                "'{}' stored as {}: the model's skin is not the rig's",
                                                mesh.name, v, j, p.semantic, rig.name, bones, a.name, formatName(format)));
        }
    }
}

}  // namespace

PackedVertices packVertices(const GenerateResult& r, const rt::Mesh& mesh) {
  const Rig& rig = r.in.rig;
  checkJoints(rig, mesh);
  const rt::Mesh quantized = quantizeForRig(rig, mesh);
  PackedVertices out;
  out.vertexCount = mesh.vertexCount;
  // Appends `n` bytes at a 16-byte aligned offset (any API's buffer-offset alignment); returns it.
  auto append = [&](const uint8_t* data, size_t n) {
    const size_t offset = (out.bytes.size() + 15) / 16 * 16;
    out.bytes.resize(offset);
    out.bytes.insert(out.bytes.end(), data, data + n);
    return offset;
  };
  nlohmann::json streams = nlohmann::json::array();
  for (const EmittedInput& in : r.glsl.inputs) {
    const RigAttribute& a = rig.attributes[static_cast<size_t>(in.attribute)];
    rt::VertexStream s = vertexStream(rig, in, quantized);
    const size_t offset = append(s.data.data(), s.data.size());
    nlohmann::json provides = nlohmann::json::array();
    for (const auto& p : a.provides) {
      const VertexFormat format = partFormat(a, p);
      nlohmann::json part = {{"semantic", in.target >= 0 ? p.semantic + "[" + std::to_string(in.target) + "]" : p.semantic},
                             {"components", p.swizzle.empty() ? std::string("xyzw").substr(0, formatComponents(format))
                                                              : p.swizzle}};
      if (p.field >= 0) part["field"] = p.field;  // components of that field of `fields`
      if (const VertexEncoding* e = encodingOf(p.semantic)) {
        part["encodes"] = e->decodes();
        part["encoding"] = e->name;
        if (e->angular()) {
          part["max_error_deg"] = *encodingMaxError(*e, format);
        } else if (e->perTarget) {  // scaled deltas: delta = code * scale, the target's own
          part["max_error_of_target_scale"] = *encodingMaxError(*e, format);
          part["scale"] = quantized.uniforms.at(e->uniforms.at(0)).at(static_cast<size_t>(in.target));
        } else {  // bounds: source = bias + code * scale, the code as the format reads it
          part["max_error_of_bounds_diagonal"] = *encodingMaxError(*e, format);
          part["bias"] = quantized.uniforms.at(e->uniforms.at(0));
          part["scale"] = quantized.uniforms.at(e->uniforms.at(1));
        }
      }
      provides.push_back(std::move(part));
    }
    streams.push_back({{"input", in.name},
                       {"location", in.location},
                       {"attribute", a.name},
                       {"target", in.target},
                       {"format", formatName(a.format)},
                       {"offset", offset},
                       {"stride", s.stride},
                       {"size", s.data.size()},
                       {"provides", std::move(provides)}});
    if (!a.fields.empty()) streams.back()["fields"] = nlohmann::json::parse(packedFieldsJson(a));
  }
  // The per-vertex storage buffers after the streams, each described as the reflection
  // describes it (docs/buffers.md) plus its offset and size: vertex_count * count elements
  // (the device's copy may be longer). The palettes are the pose's, written each frame like
  // the uniform block: listed, not packed.
  nlohmann::json buffers = nlohmann::json::array(), palettes = nlohmann::json::array();
  const std::vector<rt::StorageBufferData> data = perVertexBuffers(r, quantized);
  for (nlohmann::json b : nlohmann::json::parse(reflectionOf(r)).value("storage_buffers", nlohmann::json::array())) {
    if (b["indexing"] != "per_vertex") {
      palettes.push_back(std::move(b));
      continue;
    }
    const auto it = std::find_if(data.begin(), data.end(), [&](const auto& d) { return d.binding == b["binding"]; });
    const size_t size = out.vertexCount * b["count"].get<size_t>() * b["stride"].get<size_t>();
    const size_t offset = append(it->data.data(), size);
    b["offset"] = offset;
    b["size"] = size;
    buffers.push_back(std::move(b));
  }
  out.storageBuffers = buffers.size();
  const nlohmann::json layout = {{"rig", rig.name},
                                 {"vertex_count", out.vertexCount},
                                 {"bytes", out.bytes.size()},
                                 {"streams", std::move(streams)},
                                 {"storage_buffers", std::move(buffers)},
                                 {"palettes", std::move(palettes)},
                                 // the values the mesh gives its uniforms (the bounds), by semantic
                                 {"uniforms", quantized.uniforms}};
  out.layoutJson = layout.dump(2) + "\n";
  return out;
}

}  // namespace sg

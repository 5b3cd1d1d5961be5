#include "emit/reflection.h"

#include <fmt/format.h>

#include <cctype>

#include "rig/packed_fields.h"

namespace sg {
namespace {

std::string jsonQuote(const std::string& s) {
  std::string o = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    if (static_cast<unsigned char>(c) < 0x20) {
      o += fmt::format("\\u{:04x}", static_cast<int>(c));
      continue;
    }
    o += c;
  }
  return o + "\"";
}

// Storage buffers (docs/buffers.md) and, when the plan reads an active-target list, the
// sparse-morph protocol.
std::string buffersJson(const EmittedGlsl& glsl) {
  std::string j = "  \"storage_buffers\": [";
  for (size_t i = 0; i < glsl.buffers.size(); ++i) {
    const auto& b = glsl.buffers[i];
    std::string packs;
    for (const auto& [sem, comps] : b.packs)
      packs += fmt::format("{}{{\"semantic\": {}, \"components\": {}}}", packs.empty() ? "" : ", ", jsonQuote(sem), jsonQuote(comps));
    j += fmt::format("{}\n    {{\"name\": {}, \"semantic\": {}, \"set\": 0, \"binding\": {}, \"layout\": \"std430\", "
                     "\"element\": {}, \"stride\": {}, \"indexing\": {}, \"count\": {}, \"element_index\": {}, "
                     "\"size_bytes\": {}, \"holds\": [{}]}}",
                     i ? "," : "", jsonQuote(b.name + "_data"), jsonQuote(b.semantic), b.binding,
                     jsonQuote(std::string(glslName(b.element))), b.strideBytes, jsonQuote(b.perVertex ? "per_vertex" : "array"),
                     b.count, jsonQuote(b.perVertex ? fmt::format("vertex * {} + i", b.count) : "i"),
                     jsonQuote(b.perVertex ? fmt::format("vertex_count * {}", b.count * b.strideBytes)
                                       : std::to_string(b.count * b.strideBytes)),
                     packs);
  }
  j += glsl.buffers.empty() ? "],\n" : "\n  ],\n";
  return j;
}

// A translation's interface: semantics or attribute indices by variable, registers or
// buffer indices by resource.
std::string crossJson(const CrossShader& c) {
  const bool hlsl = c.hlsl;
  std::string j = fmt::format("  {}: {{\n    {}: {}, {}: {}, \"entry_point\": {},\n    \"inputs\": [", jsonQuote(hlsl ? "hlsl" : "msl"),
                              jsonQuote(hlsl ? "shader_model" : "version"), jsonQuote(c.version),
                              jsonQuote(hlsl ? "profile" : "platform"), jsonQuote(c.profile), jsonQuote(c.entryPoint));
  auto variables = [&](const std::vector<CrossVariable>& vars) {
    std::string v;
    for (size_t i = 0; i < vars.size(); ++i) {
      const CrossVariable& x = vars[i];
      std::string slots = x.slots > 1 ? fmt::format(", \"{}\": {}", hlsl ? "semantic_count" : "locations", x.slots) : "";
      v += fmt::format("{}\n      {{\"name\": {}, \"location\": {}, {}: {}{}}}", i ? "," : "", jsonQuote(x.name), x.location,
                       jsonQuote(hlsl ? "semantic" : "attribute"), jsonQuote(x.binding), slots);
    }
    return v + (vars.empty() ? "]" : "\n    ]");
  };
  j += variables(c.inputs) + ",\n    \"outputs\": [" + variables(c.outputs) + ",\n    \"resources\": [";
  for (size_t i = 0; i < c.resources.size(); ++i) {
    const CrossResource& r = c.resources[i];
    std::string where = hlsl ? fmt::format("\"register\": {}, \"space\": 0", jsonQuote(r.slot))
                             : fmt::format("\"buffer\": {}", r.index);
    j += fmt::format("{}\n      {{\"name\": {}, \"variable\": {}, \"kind\": {}, {}, \"set\": {}, \"binding\": {}}}",
                     i ? "," : "", jsonQuote(r.name), jsonQuote(r.variable),
                     jsonQuote(r.uniformBlock ? (hlsl ? "cbuffer" : "constant") : (hlsl ? "ByteAddressBuffer" : "device const")),
                     where, r.set, r.binding);
  }
  j += c.resources.empty() ? "]" : "\n    ]";
  if (!hlsl) j += fmt::format(",\n    \"first_vertex_buffer\": {}", c.firstVertexBuffer);
  return j + "\n  },\n";
}

// A bit-packed attribute's fields (docs/rig-format.md, "Bit-packed attributes"): per field,
// the VkFormat whose conversion the shader's unpack reproduces (encode each field as an
// attribute of that format would be), the word and bit it starts at, its components and
// the bits of each.
std::string packedFieldsHeader(const RigAttribute& a, const std::string& name) {
  if (a.fields.empty()) return "";
  std::string h = fmt::format("#define {}_FIELD_COUNT {}u\n", name, a.fields.size());
  for (size_t i = 0; i < a.fields.size(); ++i) {
    const PackedField& f = a.fields[i];
    std::string sems;
    for (const auto& p : a.provides)
      if (p.field == static_cast<int>(i)) sems += fmt::format("{}{}{}", sems.empty() ? "" : ", ", p.semantic, p.swizzle.empty() ? "" : "." + p.swizzle);
    std::string bits;
    for (int c = 0; c < formatComponents(f.format); ++c) bits += fmt::format("{}{}", c ? ", " : "", formatComponentBits(f.format, c));
    const std::string field = fmt::format("{}_FIELD{}", name, i);
    h += fmt::format("/* field {}: {} ({}), bits per component {} */\n", i, formatName(f.format), sems, bits);
    h += fmt::format("#define {}_FORMAT {}u /* {} */\n#define {}_WORD {}u\n#define {}_BIT {}u\n#define {}_COMPONENTS {}u\n"
                     "#define {}_BITS {}u\n",
                     field, vulkanFormat(f.format).value, vulkanFormat(f.format).name, field, f.word, field, f.bit, field,
                     formatComponents(f.format), field, formatComponentBits(f.format, 0));
    if (formatComponentBits(f.format, 3) != formatComponentBits(f.format, 0) && formatComponents(f.format) == 4)
      h += fmt::format("#define {}_BITS_W {}u\n", field, formatComponentBits(f.format, 3));  // 10-10-10-2
  }
  return h;
}

}  // namespace

std::string vertexInputsHeader(const Rig& rig, const EmittedGlsl& glsl, const std::string& symbol) {
  std::string prefix;
  for (char c : symbol) prefix += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  std::string h = "\n// Vertex inputs (docs/rig-format.md): per input, its location, the VkFormat of the attribute\n"
                  "// that feeds it (the enum's value) and the stride in bytes of a tightly packed stream of it.\n";
  h += fmt::format("#define {}_INPUT_COUNT {}u\n", prefix, glsl.inputs.size());
  for (const auto& in : glsl.inputs) {
    const VertexFormat f = rig.attributes[in.attribute].format;
    std::string name = prefix + "_";
    for (char c : in.name) name += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    h += fmt::format("#define {}_LOCATION {}u\n#define {}_FORMAT {}u /* {} */\n#define {}_STRIDE {}u\n", name, in.location,
                     name, vulkanFormat(f).value, vulkanFormat(f).name, name, formatBytes(f));
    h += packedFieldsHeader(rig.attributes[in.attribute], name);
  }
  return h;
}

std::string buffersHeader(const EmittedGlsl& glsl, const std::string& symbol) {
  std::string h;
  if (glsl.buffers.empty()) return h;
  h += "\n// Storage buffers (set 0, std430; docs/buffers.md): binding, element stride in bytes,\n"
       "// elements per vertex (per-vertex buffers: element (vertex, i) at vertex * COUNT + i)\n"
       "// or elements (palettes: element i at i).\n";
  std::string prefix;
  for (char c : symbol) prefix += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  for (const auto& b : glsl.buffers) {
    std::string name = prefix + "_";
    for (char c : b.semantic) name += c == '.' ? '_' : static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    h += fmt::format("#define {}_BINDING {}u\n#define {}_STRIDE {}u\n#define {}_COUNT {}u\n", name, b.binding, name,
                     b.strideBytes, name, b.count);
  }
  return h;
}

std::string reflectionJson(const Rig& rig, const EmittedGlsl& glsl, const SpirvModule& spirv,
                           const DeviceProfile* profile, const PlanCostPrediction* predicted, const CrossShader* hlsl,
                           const CrossShader* msl, const Workload* workload) {
  std::string j = "{\n  \"rig\": " + jsonQuote(rig.name) + ",\n";
  // A skinned glTF rig: the weights the program was validated with, which the host must feed
  // (docs/gltf.md#import-diagnostics-and-weights).
  if (!rig.skinWeights.empty()) j += "  \"skin_weights\": " + jsonQuote(rig.skinWeights) + ",\n";
  j += "  \"inputs\": [";
  for (size_t i = 0; i < glsl.inputs.size(); ++i) {
    const auto& in = glsl.inputs[i];
    const RigAttribute& a = rig.attributes[in.attribute];
    std::string sems;
    for (const auto& p : a.provides) {
      std::string s = in.target >= 0 ? fmt::format("{}[{}]", p.semantic, in.target) : p.semantic;
      const int n = formatComponents(partFormat(a, p));
      sems += fmt::format("{}{{\"semantic\": {}, \"components\": {}{}}}", sems.empty() ? "" : ", ", jsonQuote(s),
                          jsonQuote(p.swizzle.empty() ? std::string("xyzw").substr(0, static_cast<size_t>(n)) : p.swizzle),
                          p.field >= 0 ? fmt::format(", \"field\": {}", p.field) : "");
    }
    // A bit-packed attribute: where each field sits in its words (rig/packed_fields.h).
    const std::string fields = a.fields.empty() ? "" : ", \"fields\": " + packedFieldsJson(a);
    j += fmt::format("{}\n    {{\"name\": {}, \"location\": {}, \"attribute\": {}, \"target\": {}, \"format\": {}, "
                     "\"vk_format\": {}, \"stride\": {}, \"type\": {}, \"provides\": [{}]{}}}",
                     i ? "," : "", jsonQuote(in.name), in.location, jsonQuote(a.name), in.target, jsonQuote(formatName(a.format)),
                     jsonQuote(vulkanFormat(a.format).name), formatBytes(a.format), jsonQuote(std::string(glslName(in.type))),
                     sems, fields);
  }
  j += "\n  ],\n";
  j += fmt::format("  \"uniform_block\": {{\"name\": \"ShadergenUniforms\", \"set\": 0, \"binding\": 0, \"size\": {}, "
                   "\"layout\": \"std140\", \"members\": [",
                   spirv.uniformBlockSize);
  for (size_t i = 0; i < glsl.uniforms.size(); ++i) {
    const auto& u = glsl.uniforms[i];
    const RigUniform& ru = rig.uniforms[u.uniform];
    const UniformLayout* l = nullptr;
    for (const auto& x : spirv.uniforms)
      if (x.name == u.name) l = &x;
    j += fmt::format("{}\n    {{\"name\": {}, \"semantic\": {}, \"type\": {}, \"array\": {}, \"offset\": {}, "
                     "\"array_stride\": {}, \"matrix_stride\": {}}}",
                     i ? "," : "", jsonQuote(u.name), jsonQuote(ru.semantic), jsonQuote(std::string(glslName(ru.type))),
                     ru.arraySize, l ? l->offset : 0, l ? l->arrayStride : 0, l ? l->matrixStride : 0);
  }
  j += "\n  ]},\n";
  j += buffersJson(glsl);
  if (profile && predicted) {
    j += fmt::format("  \"predicted_cost\": {{\"device\": {}, \"ns_per_vertex\": {:.6f}, {}\"terms\": {{",
                     jsonQuote(profile->device), predicted->totalNanoseconds,
                     profile->hasDrawWeights() ? fmt::format("\"vertices_per_draw\": {:g}, ", profile->verticesPerDraw) : "");
    for (size_t t = 0; t < kTermCount; ++t)
      j += fmt::format("{}\n    {}: {{\"amount\": {}, \"ns\": {:.6f}}}", t ? "," : "", jsonQuote(termName(static_cast<int>(t))),
                       predicted->amounts[t], predicted->nanoseconds[t]);
    j += "\n  }},\n";
    // What the prediction was priced for (search/workload.h; 0 or -1: unknown).
    if (workload)
      j += fmt::format("  \"workload\": {{\"vertices_per_draw\": {:g}, \"joints_per_warp\": {:.6g}, "
                       "\"active_morph_targets\": {:g}, \"invocations_per_vertex\": {:.6g}, {}{}\"source\": {}}},\n",
                       workload->verticesPerDraw, workload->jointsPerWarp, workload->activeMorphTargets,
                       workload->invocationsPerVertex,
                       workload->fragmentsPerVertex > 0 ? fmt::format("\"fragments_per_vertex\": {:.6g}, ", workload->fragmentsPerVertex) : "",
                       workload->paletteEntriesPerWarp > 0
                           ? fmt::format("\"palette_entries_per_warp\": {:.6g}, ", workload->paletteEntriesPerWarp)
                           : "",
                       jsonQuote(workload->source));
  }
  if (hlsl) j += crossJson(*hlsl);
  if (msl) j += crossJson(*msl);
  j += "  \"outputs\": [";
  for (size_t i = 0; i < glsl.outputs.size(); ++i) {
    const auto& o = glsl.outputs[i];
    std::string sems;
    for (const auto& s : o.semantics) sems += (sems.empty() ? "" : ", ") + jsonQuote(s);
    std::string array = o.arraySize ? fmt::format(", \"array_size\": {}", o.arraySize) : "";
    j += fmt::format("{}\n    {{\"name\": {}, \"location\": {}, \"type\": {}{}, \"semantics\": [{}]}}", i ? "," : "",
                     jsonQuote(o.name), o.location, jsonQuote(std::string(glslName(o.type))), array, sems);
  }
  j += "\n  ]\n}\n";
  return j;
}

std::string spirvHeader(const std::vector<uint32_t>& words, const std::string& symbol) {
  std::string h = fmt::format("// Generated by shadergen: SPIR-V words of the vertex shader.\n#pragma once\n#include "
                              "<stdint.h>\n#include <stddef.h>\n\nstatic const uint32_t {}[] = {{",
                              symbol);
  for (size_t i = 0; i < words.size(); ++i) h += fmt::format("{}0x{:08x},", i % 8 ? " " : "\n  ", words[i]);
  h += fmt::format("\n}};\nstatic const size_t {}_size = sizeof({});\n", symbol, symbol);
  return h;
}

}  // namespace sg

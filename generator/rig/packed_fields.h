// Bit-packed attributes (docs/rig-format.md, "Bit-packed attributes"): several fields, each
// a value in one of the vertex formats, in the 32-bit words of one uint32x4 (uint32x2, uint32)
// attribute. The layout rule, the shader's unpack of a field (what the fixed-function
// conversion of the field's format would return) and the host's packing of one field.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "rig/rig.h"

namespace sg {

// Whether an attribute of format `f` can hold fields (its words are read as uint).
bool formatHoldsFields(VertexFormat f);
// Bits a field of format f occupies (its bytes x 8), and the boundary it starts on: its
// component size (8, 16 or 32; 10-10-10-2 takes a whole word), so no component crosses a
// 32-bit word.
int fieldBits(VertexFormat f);
int fieldAlignment(VertexFormat f);
// Places `fields` in order, each at the first position aligned as above after the one
// before; false when they need more than `words` words.
bool layoutFields(std::vector<PackedField>& fields, int words);
// The bit of component c from the attribute's bit 0 (word w's bit b is 32 w + b).
int fieldComponentBit(const PackedField& f, int c);

// The GLSL expression of a field's components `swizzle` ("" = all), read from `input`, an
// input of `inputComponents` uint words (uvec4: `input.x`..; uint: `input`), with the
// builtins (unpackUnorm2x16, unpackSnorm4x8, unpackHalf2x16, bitfieldExtract, ...), and
// its cost in instruction slots counted as `cost: auto` counts them (docs/cost-model.md:
// an unpack, an extract, a conversion, a min or max 1, a division by a constant 1 (spirv-opt
// multiplies by the reciprocal), a bit cast 0, and one move per unpacked register when the
// value gathers several; tests/validate/test_bitpacked.cpp measures them).
struct FieldUnpack {
  std::string glsl;
  int64_t slots = 0;
};
FieldUnpack unpackField(const PackedField& f, const std::string& swizzle, const std::string& input, int inputComponents);

// Writes one field of one vertex into its attribute's element (words little-endian), from
// the field's components, rounded as encodeElement does for its format.
void packField(const PackedField& f, const float* components, uint8_t* element);

// What an engine needs to fill an attribute's words without our code, field by field:
// format (and the VkFormat whose conversion the unpack reproduces), word, bit, the bits of
// each component and where each starts (from the attribute's bit 0), the conversion. A JSON
// array, compact text (the reflection and the pack layout embed it).
std::string packedFieldsJson(const RigAttribute& a);

}  // namespace sg

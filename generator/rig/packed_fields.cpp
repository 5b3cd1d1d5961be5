#include "rig/packed_fields.h"

#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include <array>
#include <cstring>
#include <set>

#include "common/types.h"

namespace sg {
namespace {

bool isTenTenTenTwo(VertexFormat f) { return f == VertexFormat::Unorm10_10_10_2 || f == VertexFormat::Snorm10_10_10_2; }

// One component's read: a lane of a vector unpack (`lanes` of `call`), or a scalar.
struct FieldComponentRead {
  std::string call;
  int lanes = 0;  // lanes the call returns; 0: a scalar expression
  int lane = 0;
  int64_t slots = 0;
  std::string reg;  // the register it lands in (a whole uint word: the input itself)
};

FieldComponentRead readFieldComponent(const PackedField& f, int c, const std::string& input, int inputComponents) {
  const int at = fieldComponentBit(f, c);
  const int bit = at % 32;
  const std::string word = inputComponents == 1 ? input : input + "." + std::string(1, "xyzw"[at / 32]);
  const int bits = formatComponentBits(f.format, c);
  const FormatKind kind = formatKind(f.format);
  FieldComponentRead r;
  if (isTenTenTenTwo(f.format)) {
    // The fixed-function conversion: c / (2^b - 1), snorm clamped to -1 (Vulkan "Fixed-Point
    // Data Conversions"); the 2-bit snorm w is c itself.
    if (kind == FormatKind::Unorm) {
      r.call = fmt::format("(float(bitfieldExtract({}, {}, {})) / {}.0)", word, bit, bits, (1 << bits) - 1);
      r.slots = 3;  // extract, convert, divide (by a constant: spirv-opt multiplies by its reciprocal)
    } else if (bits == 2) {
      r.call = fmt::format("max(float(bitfieldExtract(int({}), {}, {})), -1.0)", word, bit, bits);
      r.slots = 3;  // extract, convert, max
    } else {
      r.call = fmt::format("max(float(bitfieldExtract(int({}), {}, {})) / {}.0, -1.0)", word, bit, bits,
                           (1 << (bits - 1)) - 1);
      r.slots = 4;  // extract, convert, divide (a multiply, as above), max
    }
  } else if (kind == FormatKind::Uint) {
    r.call = bits == 32 ? word : fmt::format("bitfieldExtract({}, {}, {})", word, bit, bits);
    r.slots = bits == 32 ? 0 : 1;
    if (bits == 32) r.reg = input;
  } else if (kind == FormatKind::Float32) {
    r.call = fmt::format("uintBitsToFloat({})", word);
  } else {
    const char* fn = kind == FormatKind::Float16 ? "unpackHalf2x16"
                     : bits == 8                ? (kind == FormatKind::Unorm ? "unpackUnorm4x8" : "unpackSnorm4x8")
                                                : (kind == FormatKind::Unorm ? "unpackUnorm2x16" : "unpackSnorm2x16");
    r.call = fmt::format("{}({})", fn, word);
    r.lanes = 32 / bits;
    r.lane = bit / bits;
    r.slots = 1;
  }
  if (r.reg.empty()) r.reg = r.call;
  return r;
}

}  // namespace

bool formatHoldsFields(VertexFormat f) {
  return f == VertexFormat::Uint32x4 || f == VertexFormat::Uint32x2 || f == VertexFormat::Uint32x1;
}

int fieldBits(VertexFormat f) { return 8 * formatBytes(f); }

int fieldAlignment(VertexFormat f) { return isTenTenTenTwo(f) ? 32 : formatComponentBits(f, 0); }

bool layoutFields(std::vector<PackedField>& fields, int words) {
  int next = 0;
  for (PackedField& f : fields) {
    const int align = fieldAlignment(f.format);
    const int start = (next + align - 1) / align * align;
    f.word = start / 32;
    f.bit = start % 32;
    next = start + fieldBits(f.format);
  }
  return next <= 32 * words;
}

int fieldComponentBit(const PackedField& f, int c) {
  static constexpr std::array<int, 4> k1010102{0, 10, 20, 30};
  const int within = isTenTenTenTwo(f.format) ? k1010102[static_cast<size_t>(c)] : c * formatComponentBits(f.format, 0);
  return 32 * f.word + f.bit + within;
}

FieldUnpack unpackField(const PackedField& f, const std::string& swizzle, const std::string& input, int inputComponents) {
  const int n = swizzle.empty() ? formatComponents(f.format) : static_cast<int>(swizzle.size());
  auto component = [&](int k) {
    return swizzle.empty() ? k : static_cast<int>(std::string("xyzw").find(swizzle[static_cast<size_t>(k)]));
  };
  // Small unsigned integers, several: one shift and one mask of the words, each repeated per
  // component (a gather of one register, which costs no move).
  if (formatKind(f.format) == FormatKind::Uint && formatComponentBits(f.format, 0) < 32 && n > 1) {
    const auto type = vectorType(ScalarKind::UInt, n);
    std::vector<std::string> words, shifts;
    for (int k = 0; k < n; ++k) {
      const int at = fieldComponentBit(f, component(k));
      words.push_back(inputComponents == 1 ? input : input + "." + std::string(1, "xyzw"[at / 32]));
      shifts.push_back(fmt::format("{}u", at % 32));
    }
    const std::string t(type ? glslName(*type) : "?");
    FieldUnpack out;
    out.glsl = fmt::format("({}({}) >> {}({})) & {}u", t, fmt::join(words, ", "), t, fmt::join(shifts, ", "),
                           (1u << formatComponentBits(f.format, 0)) - 1u);
    out.slots = 2;  // shift, and
    return out;
  }
  // Consecutive lanes of one unpack stay one swizzle of it: unpackUnorm2x16(w).xy.
  struct Piece {
    FieldComponentRead read;
    std::string lanes;
  };
  std::vector<Piece> pieces;
  std::set<std::string> calls, regs;
  int64_t slots = 0;
  for (int k = 0; k < n; ++k) {
    FieldComponentRead r = readFieldComponent(f, component(k), input, inputComponents);
    if (calls.insert(r.call).second) slots += r.slots;  // the compiler reads a repeated unpack once
    regs.insert(r.reg);
    const char lane = "xyzw"[r.lane];
    if (r.lanes && !pieces.empty() && pieces.back().read.call == r.call) {
      pieces.back().lanes += lane;
      continue;
    }
    pieces.push_back(Piece{r, r.lanes ? std::string(1, lane) : ""});
  }
  std::vector<std::string> parts;
  for (const Piece& p : pieces)
    parts.push_back(p.read.lanes == 0 || p.lanes == std::string("xyzw").substr(0, static_cast<size_t>(p.read.lanes))
                        ? p.read.call
                        : p.read.call + "." + p.lanes);
  FieldUnpack out;
  if (parts.size() == 1) {
    out.glsl = parts[0];
  } else {
    const ScalarKind kind = formatIsInteger(f.format) ? ScalarKind::UInt : ScalarKind::Float;
    const auto type = vectorType(kind, n);
    out.glsl = fmt::format("{}({})", type ? glslName(*type) : "?", fmt::join(parts, ", "));
    if (regs.size() > 1) slots += static_cast<int64_t>(regs.size());  // one move per register gathered
  }
  out.slots = slots;
  return out;
}

void packField(const PackedField& f, const float* components, uint8_t* element) {
  std::array<uint8_t, 16> bytes{};
  encodeElement(f.format, components, bytes.data());
  // Every field starts on a byte (its alignment is 8 bits or more) and spans whole bytes.
  std::memcpy(element + 4 * f.word + f.bit / 8, bytes.data(), static_cast<size_t>(formatBytes(f.format)));
}

std::string packedFieldsJson(const RigAttribute& a) {
  static const char* const kConversion[] = {"float32", "float16", "unorm", "snorm", "uint"};
  nlohmann::json out = nlohmann::json::array();
  for (const PackedField& f : a.fields) {
    nlohmann::json bits = nlohmann::json::array(), at = nlohmann::json::array();
    for (int c = 0; c < formatComponents(f.format); ++c) {
      bits.push_back(formatComponentBits(f.format, c));
      at.push_back(fieldComponentBit(f, c));
    }
    out.push_back({{"format", formatName(f.format)},
                   {"vk_format", vulkanFormat(f.format).name},
                   {"conversion", kConversion[static_cast<int>(formatKind(f.format))]},
                   {"word", f.word},
                   {"bit", f.bit},
                   {"bits_per_component", std::move(bits)},
                   {"component_bit", std::move(at)}});
  }
  return out.dump();
}

}  // namespace sg

// glTF accessor decoding (docs/gltf.md): one accessor's elements as floats, bounds-checked
// against its buffer view, sparse values applied, normalized integers dequantized, every
// decoded byte charged to the import's budget. Private to the glTF reader (rig/gltf_*.cpp).
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "rig/gltf_tinygltf.h"

namespace sg::gltf {

std::string lower(std::string s);
[[noreturn]] void fail(const std::string& file, const std::string& msg);
const char* componentTypeName(int ct);
const char* typeName(int t);
// a + b and a * b, or nullopt when they do not fit in size_t (offsets and lengths come from the file).
std::optional<size_t> addSize(size_t a, size_t b);
std::optional<size_t> mulSize(size_t a, size_t b);
std::string mib(size_t bytes);
// The decoded-data budget of an import reading `inputBytes` (gltf_import.h), at most `maxBytes`.
size_t decodedBudget(size_t inputBytes, size_t maxBytes);
// One component as the GPU reads it (see gltf_accessor.cpp); an index of an index accessor.
float readComponent(const unsigned char* p, int ct, bool normalized);
uint32_t readIndex(const unsigned char* p, int ct);

struct AccessorData {
  int components = 0;
  size_t count = 0;
  int componentType = 0;
  int type = 0;
  bool normalized = false;
  bool sparse = false;
  std::vector<float> values;  // count * components
};

class Reader {
 public:
  Reader(const tinygltf::Model& m, std::string file, size_t budget)
      : m_(m), file_(std::move(file)), budget_(budget) {}

  // Counts `bytes` of decoded data against the budget before they are allocated: the counts
  // in a small file must not make the reader allocate gigabytes.
  void charge(size_t count, size_t bytesEach, const std::string& what);
  // Pointer to `bytes` bytes at `offset` of buffer view `bv`, bounds-checked without overflow.
  const unsigned char* at(int bv, size_t offset, size_t bytes, const std::string& what) const;
  AccessorData read(int index, const std::string& what);
  // Accessor data (d.components each) as a per-vertex stream of components [from, from+n).
  std::vector<std::array<float, 4>> stream(const AccessorData& d, int from, int n, const std::string& what);
  std::vector<std::array<float, 4>> zeros(size_t count, const std::string& what);

 private:
  const tinygltf::Model& m_;
  std::string file_;
  size_t budget_;
  size_t used_ = 0;
};

}  // namespace sg::gltf

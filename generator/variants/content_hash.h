// SHA-256 of byte strings, for the content-addressed variant cache (a key must change
// whenever any input byte does; a cryptographic hash makes accidental collisions moot).
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <string_view>

namespace sg {

class Sha256 {
 public:
  Sha256();
  Sha256& update(std::string_view bytes);
  // Length-prefixed field: "ab"+"c" and "a"+"bc" hash differently.
  Sha256& field(std::string_view bytes);
  std::string hex();  // finishes; 64 lowercase hex digits

 private:
  void block(const uint8_t* p);
  std::array<uint32_t, 8> h_;
  uint8_t buf_[64];
  size_t used_ = 0;
  uint64_t total_ = 0;
};

std::string sha256Hex(std::string_view bytes);

}  // namespace sg

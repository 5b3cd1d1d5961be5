// SHA-256 of byte strings: the keys of the content-addressed variant cache (a key must change
// whenever any input byte does, and an entry read from another machine is checked against its
// digest) and the fingerprint naming a device profile in calibrate's logs. Computed by OpenSSL's
// libcrypto (EVP), not by hand.
#pragma once
#include <memory>
#include <string>
#include <string_view>
#include <vector>

struct evp_md_ctx_st;

namespace sg {

class Sha256 {
 public:
  Sha256();
  ~Sha256();
  Sha256(Sha256&&) noexcept;
  Sha256& operator=(Sha256&&) noexcept;
  Sha256& update(std::string_view bytes);
  // Length-prefixed field: "ab"+"c" and "a"+"bc" hash differently.
  Sha256& field(std::string_view bytes);
  std::string hex();  // finishes; 64 lowercase hex digits

 private:
  struct Free {
    void operator()(evp_md_ctx_st* c) const;
  };
  std::unique_ptr<evp_md_ctx_st, Free> ctx_;
};

std::string sha256Hex(std::string_view bytes);
// Over the bytes of each file in order, each a field (paths left out: a pin moves between
// machines and checkouts). Throws std::runtime_error for a file it cannot read.
std::string sha256OfFiles(const std::vector<std::string>& paths);

}  // namespace sg

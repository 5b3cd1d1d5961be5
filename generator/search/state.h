// A search state: the set of facts computed so far, as a bitset.
#pragma once
#include <cstdint>
#include <functional>
#include <vector>

namespace sg {

class FactSet {
 public:
  FactSet() = default;
  explicit FactSet(size_t n) : words_((n + 63) / 64, 0) {}
  bool test(int i) const { return (words_[static_cast<size_t>(i) >> 6] >> (i & 63)) & 1u; }
  void set(int i) { words_[static_cast<size_t>(i) >> 6] |= uint64_t{1} << (i & 63); }
  bool containsAll(const std::vector<int>& facts) const {
    for (int f : facts)
      if (!test(f)) return false;
    return true;
  }
  bool operator==(const FactSet& o) const { return words_ == o.words_; }
  size_t hash() const {
    size_t h = 1469598103934665603ull;
    for (uint64_t w : words_) h = (h ^ w) * 1099511628211ull;
    return h;
  }

 private:
  std::vector<uint64_t> words_;
};

struct FactSetHash {
  size_t operator()(const FactSet& s) const { return s.hash(); }
};

}  // namespace sg

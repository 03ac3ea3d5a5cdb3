// A compact map from lattice keys to one bit each.
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace pic::detail {

/// 63-bit key (a lattice point's lattice_key) -> one bit, open addressing with linear probing:
/// the CSG's sign lookups (its hottest map) and the clean-up's sets of points seen. The bit
/// rides in bit 63 of the slot.
class KeyBits {
 public:
  /// The bit stored for `key`, or -1.
  int find(uint64_t key) const {
    if (slots_.empty()) return -1;
    for (size_t i = home(key);; i = (i + 1) & mask_) {
      const uint64_t v = slots_[i];
      if (v == kEmpty) return -1;
      if ((v & kKeyBits) == key) return int(v >> 63);
    }
  }
  /// Stores `bit` for `key` unless it has one; returns whether it was new.
  bool insert(uint64_t key, bool bit) {
    if (2 * (count_ + 1) > slots_.size()) grow();
    for (size_t i = home(key);; i = (i + 1) & mask_) {
      if (slots_[i] == kEmpty) {
        slots_[i] = key | uint64_t(bit) << 63;
        ++count_;
        return true;
      }
      if ((slots_[i] & kKeyBits) == key) return false;
    }
  }

 private:
  static constexpr uint64_t kEmpty = ~uint64_t{0};
  static constexpr uint64_t kKeyBits = ~uint64_t{0} >> 1;
  size_t home(uint64_t key) const { return size_t((key * 0x9E3779B97F4A7C15ull) >> shift_); }
  void grow() {
    std::vector<uint64_t> old = std::move(slots_);
    const size_t n = old.empty() ? 1024 : 2 * old.size();
    slots_.assign(n, kEmpty);
    mask_ = n - 1;
    shift_ = 64 - std::countr_zero(n);
    count_ = 0;
    for (uint64_t v : old)
      if (v != kEmpty) insert(v & kKeyBits, v >> 63);
  }
  std::vector<uint64_t> slots_;
  size_t mask_ = 0, count_ = 0;
  int shift_ = 64;
};

}  // namespace pic::detail

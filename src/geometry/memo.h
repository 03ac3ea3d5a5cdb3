// Direct-mapped memos of pure functions on grid points and grid segments, one table per
// thread, owned by the computation that fills them (a sampling call, a surface source): an
// answer never depends on what the memo held, only the time to get it does.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <tbb/cache_aligned_allocator.h>
#include <tbb/enumerable_thread_specific.h>

#include "geometry/lattice.h"

namespace pic::detail {

/// A slot index of `bits` bits for a grid point (and an extra word).
inline size_t memo_slot(const I3& p, uint64_t extra, int bits) {
  const uint64_t h = (uint64_t(p[0]) * 0x9E3779B97F4A7C15ull) ^ (uint64_t(p[1]) * 0xC2B2AE3D27D4EB4Full) ^
                     (uint64_t(p[2]) * 0x165667B19E3779F9ull) ^ extra;
  return (h ^ (h >> 29)) & ((size_t{1} << bits) - 1);
}
/// The same for a grid segment: from `a`, `len` along `axis`.
inline size_t edge_memo_slot(const I3& a, int axis, i64 len, int bits) {
  return memo_slot(a, (uint64_t(len) * 0xD6E8FEB86659FD93ull) ^ uint64_t(axis), bits);
}

/// 2^Bits entries per thread, made on a thread's first use (entries start empty: an Entry
/// says itself whether it holds an answer). Thread-safe without locks: each thread only ever
/// touches its own table.
template <class Entry, int Bits>
class ThreadMemo {
 public:
  static constexpr int kBits = Bits;
  Entry& slot(size_t i) { return tables_.local()[i]; }

 private:
  using Table = std::vector<Entry>;
  tbb::enumerable_thread_specific<Table, tbb::cache_aligned_allocator<Table>, tbb::ets_key_per_instance> tables_{
      [] { return Table(size_t{1} << Bits); }};
};

}  // namespace pic::detail

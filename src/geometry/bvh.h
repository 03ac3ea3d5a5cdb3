// A bounding-volume hierarchy over grid triangles, for "which triangles touch this cell".
// The partial contour of a CSG operand is a triangle soup; a leaf's region can be crossed by
// triangles of neighbouring fans (adaptive cells make long triangles), so the triangles of a
// cell are found by box query rather than by fan membership.
#pragma once

#include <cstdint>
#include <vector>

#include "geometry/lattice.h"

namespace pic::detail {

class TriangleBvh {
 public:
  void build(const std::vector<ITri>& tris);
  /// Appends to `out` the triangles whose box overlaps [lo, hi] and whose plane meets it.
  void query(const std::vector<ITri>& tris, const I3& lo, const I3& hi, std::vector<uint32_t>& out) const;

 private:
  struct BNode {
    I3 lo, hi;
    uint32_t first, count;  // leaf: range in order_; inner: first = left child, count = 0
    uint32_t right;
  };
  uint32_t build_range(const std::vector<ITri>& tris, uint32_t begin, uint32_t end);
  std::vector<BNode> nodes_;
  std::vector<uint32_t> order_;
};

}  // namespace pic::detail

// Blocks of fixed grids over a mesh's box, for collapsing edges in parallel: a vertex whose
// neighbours all lie in its block may collapse while other blocks do the same.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "geometry/tolerances.h"
#include "pic/types.h"

namespace pic::detail {

/// Blocks of fixed grids over the mesh's box, each vertex in the one holding it: collapses whose
/// two stars lie in one block touch nothing another block's collapses do. The first grid has
/// kBlocksPerAxis blocks a side; the second is shifted by half a block, so that its blocks hold
/// the bands along the first one's faces; the third and fourth have blocks twice and four
/// times as wide, shifted by an eighth and three sixteenths of theirs, so that no two grids
/// share a face and the long triangles of a coarse mesh fit in their blocks.
constexpr int kBlocksPerAxis = 8;
struct GridLayout {
  int per_axis;
  double offset;  // in blocks
  int side() const { return per_axis + (offset > 0); }
  size_t count() const { return size_t(side()) * side() * side(); }
};
constexpr GridLayout kGrids[] = {
    {kBlocksPerAxis, 0}, {kBlocksPerAxis, 0.5}, {kBlocksPerAxis / 2, 0.125}, {kBlocksPerAxis / 4, 0.1875}};

struct BlockGrid {
  Vec3 lo{kHuge, kHuge, kHuge}, hi{-kHuge, -kHuge, -kHuge};
  explicit BlockGrid(const std::vector<Vec3>& pos) {
    for (const Vec3& p : pos)
      for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(lo[k], p[k]);
        hi[k] = std::max(hi[k], p[k]);
      }
  }
  uint16_t block(const Vec3& p, const GridLayout& g) const {
    int b = 0;
    for (int k = 0; k < 3; ++k) {
      const double t = hi[k] > lo[k] ? (p[k] - lo[k]) / (hi[k] - lo[k]) : 0;
      b = b * g.side() + std::clamp(int(t * g.per_axis + g.offset), 0, g.side() - 1);
    }
    return uint16_t(b);
  }
};

}  // namespace pic::detail

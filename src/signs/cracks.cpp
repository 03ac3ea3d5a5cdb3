// The crack pass: uniform leaves beside a sign change given a vertex so the contour closes.
// See consistency.h (repair_cracks).
#include "signs/consistency.h"
#include "octree/dual_walk.h"

#include <array>
#include <unordered_map>

namespace pic::detail {

using Lat = std::array<int64_t, 3>;

/// Turns uniform leaves that border a sign change into gray leaves (vertex at the crossing
/// edge's midpoint), so the contour stays closed whatever the geometry decided.
size_t repair_cracks(Octree& t, const std::function<bool(uint32_t)>* active) {
  size_t fixed = 0;
  for (int pass = 0; pass < 4; ++pass) {
    const DualStats ds = crack_edges(t, active);
    if (ds.crack_leaves.empty()) break;
    std::unordered_map<uint32_t, std::pair<Lat, int>> mid_sum;  // leaf -> (sum of 2x midpoints, count)
    std::unordered_map<uint32_t, Cell> cells;
    for (size_t k = 0; k < ds.crack_leaves.size(); ++k) {
      auto& [sum, n] = mid_sum[ds.crack_leaves[k]];
      for (int a = 0; a < 3; ++a) sum[a] += ds.crack_points[k][a];
      ++n;
      cells[ds.crack_leaves[k]] = ds.crack_cells[k];
    }
    for (const auto& [node, ms] : mid_sum) {
      Node& n = t.nodes[node];
      if (n.kind == CellKind::Gray) continue;
      const Cell& cell = cells[node];
      const auto& [sum, cnt] = ms;
      constexpr double k = 1.0 / double(int64_t{1} << kMaxLevel);
      const Vec3 x{sum[0] * k / (2 * cnt), sum[1] * k / (2 * cnt), sum[2] * k / (2 * cnt)};
      n = add_gray(t.vertices, cell, n.kind == CellKind::Black ? 0xff : 0, x);
      ++fixed;
    }
  }
  return fixed;
}

}  // namespace pic::detail

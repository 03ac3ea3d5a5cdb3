// Triangles against axis-aligned boxes on the grid (an octree cell's box, or any other):
// conservative and exact overlap, the grid lines a triangle may cross, and the QEF of the
// triangles' parts inside a box. The cell sampler and the CSG's cell tests share them.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "geometry/lattice.h"
#include "geometry/qef.h"

namespace pic::detail {

/// Boxes with at least this many triangles share their per-triangle work between threads.
inline constexpr size_t kParallelTris = 4096;

/// Which axis-parallel grid lines a triangle's bounding box lets it cross: lines at
/// base + b step (b < count) on each axis, for segments from base to base + step along it.
struct LineMask {
  std::array<unsigned, 3> on{};  // bit b of on[d]: coordinate base[d] + b step within [lo, hi)
  std::array<bool, 3> spans{};   // segments along axis d overlap the box
  /// A segment along `axis` at grid steps ci (axis i) and cj (axis j), i < j the other two.
  bool may_cross(int axis, int i, int ci, int j, int cj) const {
    return spans[axis] && ((on[i] >> ci) & 1) && ((on[j] >> cj) & 1);
  }
};
/// The line mask of `t` for `count` grid lines per axis from `base`, `step` apart.
LineMask line_mask(const ITri& t, const I3& base, i64 step, int count);

/// QEF of the triangles meeting `box` (weights: clipped area / `face_area` + a floor, so
/// planes that touch the box only along its boundary still count — box corners on octree
/// planes need them), and, at the floor weight, those that touch the box only in a low face
/// but cross one of its edges (a slanted face or a crease through an octree line).
void box_qef(const std::vector<ITri>& tris, const std::vector<uint32_t>& idx, const IBox& box,
             double face_area, Qef& q);

/// Whether any triangle of `idx` meets `box` under the perturbation convention (a triangle
/// lying in one of the box's low faces belongs to the neighbour below). Exact.
bool meets_box(const std::vector<ITri>& tris, const std::vector<uint32_t>& idx, const IBox& box);

/// Triangles of `idx` overlapping the closed `box` (conservative).
void filter_box(const std::vector<ITri>& tris, const std::vector<uint32_t>& idx, const IBox& box,
                std::vector<uint32_t>& out);
/// Triangles of `idx` overlapping the closed boxes of `box`'s 8 halves (child c: bit k high
/// along axis k), conservative; the same lists as filter_box per half, in one pass.
void split_box(const std::vector<ITri>& tris, const std::vector<uint32_t>& idx, const IBox& box,
               std::array<std::vector<uint32_t>, 8>& out);

}  // namespace pic::detail

// Exact geometry on a fixed-point grid.
//
// Everything inside the library lives in root-cube units ([0,1]^3). Triangle vertices are
// snapped to a grid of 2^-32 (2.3e-10 of the root cube, far below any tolerance) and kept as
// int64, so the in/out predicates that decide corner signs are exact with __int128 products.
// Lattice points of the octree (level <= kMaxLevel = 20) are exact on that grid.
//
// Sign convention (the tie-break the whole system relies on): a point p is classified as
// p + (e, e^2, e^3) for an infinitesimal e — Simulation of Simplicity. A box face lying exactly
// on an octree plane therefore gets one consistent answer from every cell and every level.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "pic/octree.h"
#include "pic/types.h"

namespace pic::detail {

using i64 = int64_t;
using i128 = __int128;
using I3 = std::array<i64, 3>;

inline constexpr int kGridBits = 32;
inline constexpr double kGridScale = 4294967296.0;  // 2^32

/// Lattice coordinate (level-kMaxLevel units) to grid units.
inline i64 lattice_to_grid(int64_t l) { return l << (kGridBits - kMaxLevel); }
inline I3 lattice_to_grid(const std::array<int64_t, 3>& l) {
  return {lattice_to_grid(l[0]), lattice_to_grid(l[1]), lattice_to_grid(l[2])};
}
inline double grid_to_unit(i64 g) { return static_cast<double>(g) / kGridScale; }

/// A triangle on the grid with its exact (unnormalized) normal and plane offset.
struct ITri {
  std::array<I3, 3> v;
  std::array<i128, 3> n;  // (v1-v0) x (v2-v0), < 2^70 per component
  i128 d;                 // n . v0
  I3 lo, hi;              // bounding box
  std::array<double, 3> n_approx{};  // n and d rounded to double: filters for the exact
  double d_approx = 0;               // predicates (decide the clear cases without i128)
  Vec3 unit_normal{0, 0, 0};  // double precision, for QEFs
  double plane = 0;           // unit_normal . v0 (unit-cube coordinates)
  double area = 0;            // unit-cube units
  uint8_t use = 0xff;         // kUse* bits: which roles the triangle plays in sampling
};
/// Roles of a triangle in sampling. Every triangle counts in the signs' crossings; a triangle
/// of a robust (winding-number) input that does not bound the solid, a cap closing the input's
/// boundary, or a point cloud's splat plays only some of the other roles.
inline constexpr uint8_t kUseQef = 1;       ///< its plane enters the cells' QEFs
inline constexpr uint8_t kUseMeets = 2;     ///< a uniform cell it meets is subdivided
inline constexpr uint8_t kUseCrossing = 4;  ///< counted by the double-crossing test
inline constexpr uint8_t kUseAll = 0xff;
ITri make_itri(const I3& a, const I3& b, const I3& c);
inline bool is_degenerate(const ITri& t) { return t.n[0] == 0 && t.n[1] == 0 && t.n[2] == 0; }

/// Whether the axis-parallel segment from `a` to `a + len * e_axis` (len > 0) crosses `t`,
/// under the symbolic perturbation above. Exact.
bool crosses(const ITri& t, const I3& a, int axis, i64 len);

/// Side of p relative to the plane of t (sign of n.p - d) under the symbolic perturbation:
/// never 0 for a non-degenerate triangle. Exact.
int plane_side(const ITri& t, const I3& p);

/// Number of crossings of `tris[idx]` with the segment (exact, perturbed).
int count_crossings(const std::vector<ITri>& tris, const std::vector<uint32_t>& idx, const I3& a,
                    int axis, i64 len);

/// Conservative overlap of a triangle with the closed box [lo, hi] (bbox + plane test, exact).
bool overlaps_box(const ITri& t, const I3& lo, const I3& hi);
/// False only when one of the 9 axes (box axis x triangle edge) clearly separates t from the
/// closed box (floating point with a safety margin: "true" may still be apart). With
/// overlaps_box it makes the separating-axis test complete, which long slivers need: their
/// boxes and planes reach many cells their edges pass far from. Sampling asks ChildEdgeTest
/// (the same test for a box's 8 children at once); this one-box form is its reference.
bool edges_may_touch_box(const ITri& t, const I3& lo, const I3& hi);

/// Cell box in grid units.
struct IBox {
  I3 lo, hi;
};
/// Whether `t` crosses any of the 12 edges of the box (crosses() on each).
bool crosses_box_edge(const ITri& t, const IBox& box);

/// edges_may_touch_box for the 8 children of one box (split_box asks it for several): the
/// triangle's projections on the 9 axes are taken once about the box's centre and shifted to
/// each child's, with the margin widened by the shift.
class ChildEdgeTest {
 public:
  ChildEdgeTest(const ITri& t, const IBox& parent);
  /// Child c (bit k: high half along axis k).
  bool may_touch(int c) const;

 private:
  // Per axis x = 3 * edge + k: the projections' range about the parent's centre, the shift
  // to a child's centre as +-a_ +-b_, and the child's half width on the axis plus the margin.
  double pmin_[9], pmax_[9], a_[9], b_[9], reach_[9];
};
inline IBox cell_box(int level, const std::array<int64_t, 3>& lat) {
  const int64_t s = int64_t{1} << (kMaxLevel - level);
  return {lattice_to_grid(lat), lattice_to_grid({lat[0] + s, lat[1] + s, lat[2] + s})};
}

/// Area of the part of the triangle inside the box, under the perturbation convention:
/// a piece that lies entirely in one of the box's low faces belongs to the neighbour below,
/// so it counts as 0; a piece of zero area inside the box counts as a tiny positive weight.
/// Returns < 0 when the triangle does not meet the box: kTouchesLowFace when it touches the
/// closed box only in one of its low faces, else -1. Double precision (used for QEFs).
inline constexpr double kTouchesLowFace = -0.5;
double clipped_area(const ITri& t, const IBox& box);
/// A point of the triangle inside the closed box (the mean of the clipped polygon's corners),
/// under the same convention; nothing when they do not meet.
std::optional<Vec3> point_in_box(const ITri& t, const IBox& box);

/// Parameter in [0,1] of the crossings of `t` on the segment (double; for directed distances).
double crossing_param(const ITri& t, const I3& a, int axis, i64 len);

/// Whether triangles a and b intersect inside the closed box (double precision).
bool triangles_meet_in_box(const ITri& a, const ITri& b, const IBox& box);

/// Squared distance from a unit-space point to a grid triangle (double precision).
double point_triangle_distance2(const Vec3& p, const ITri& t);
double point_triangle_distance2(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);
Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

/// Unit-space position of a grid point.
inline Vec3 to_unit(const I3& g) { return {grid_to_unit(g[0]), grid_to_unit(g[1]), grid_to_unit(g[2])}; }
/// Snap a unit-space position to the grid.
I3 to_grid(const Vec3& u);

// Cube corner / edge tables. Corner c = (c&1, c>>1&1, c>>2&1).
inline constexpr std::array<std::array<int, 2>, 12> kEdgeCorners = {{
    {0, 1}, {2, 3}, {4, 5}, {6, 7},  // along x
    {0, 2}, {1, 3}, {4, 6}, {5, 7},  // along y
    {0, 4}, {1, 5}, {2, 6}, {3, 7},  // along z
}};
inline constexpr int edge_axis(int e) { return e / 4; }

/// Whether the signs of a cell's 3x3x3 child grid (index a + 3b + 9c) add nothing to what its
/// 8 corners say: no sign appears at an edge midpoint, face centre or the cell centre unless
/// the corners around it already change sign there, and inside and outside points are each
/// 6-connected. A leaf accepted with a non-simple grid would meet finer neighbours whose
/// signs show a second sheet on its faces (Ju et al. 2002, topology-safe simplification).
bool grid_is_simple(const std::array<bool, 27>& g);

/// One surface component by corner signs: inside corners connected along cube edges and
/// outside corners connected too (the 7 one-component Marching Cubes classes and their
/// complements). Uniform sign masks return false.
bool one_component(uint8_t signs);

}  // namespace pic::detail

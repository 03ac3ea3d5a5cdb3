// Dual contouring (SurfaceNets) on the adaptive octree: Ju et al. 2002 cellProc / faceProc /
// edgeProc. Every minimal edge with a sign change yields a polygon through the vertices of
// the 4 (or 3) leaves around it, oriented by which end is inside.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "octree/cell.h"

namespace pic::detail {

/// A dual polygon: gray-leaf node ids, counter-clockwise seen from outside.
struct DualPolygon {
  std::array<uint32_t, 4> leaf;
  std::array<Vec3, 4> pos;  // vertices in unit coordinates
  int count;  // 3 or 4
};

struct DualStats {
  // Sign-changing minimal edges next to a non-gray leaf: the leaf, its cell, and the edge's
  // midpoint (lattice coordinates doubled).
  std::vector<uint32_t> crack_leaves;
  std::vector<Cell> crack_cells;       // and their cells
  std::vector<std::array<int64_t, 3>> crack_points;  // midpoint lattice (x2) of each crack edge
};

/// Walks the dual of the whole tree, or — with `active` — only the parts that touch active
/// nodes (partial contour, paper 5.2.1: `active` = stamped by the current operation).
void dual_walk(const Octree& t, const std::function<bool(uint32_t)>* active,
               const std::function<void(const DualPolygon&)>& emit, DualStats* stats = nullptr);

/// A dual polygon of the whole contour: tree vertex indices (counter-clockwise from outside)
/// and the minimal edge it is dual to, in output coordinates.
struct MeshPolygon {
  std::array<uint32_t, 4> v{};
  int count = 0;
  Vec3 e0{0, 0, 0}, e1{0, 0, 0};
};

/// Fan points stay this fraction of the edge away from its ends (so no fan triangle degenerates).
inline constexpr double kFanEdgeMargin = 1.0 / 64;
/// The point strictly inside edge (e0, e1) that a polygon's fan is built around.
Vec3 fan_point(const std::array<Vec3, 4>& p, int count, const Vec3& e0, const Vec3& e1);

struct TriangulationStats {
  size_t fans = 0;                     // polygons fanned around a point on their edge
  size_t other_diagonal = 0;           // quads split along their other diagonal
  size_t moved_vertices = 0;           // vertices pulled toward their cell centre
  size_t initial_intersections = 0;    // exact self-intersecting pairs of the plain split
  size_t remaining_intersections = 0;  // after the last round
  int rounds = 0;
};
/// Triangles of the dual polygons (vertex ids into `x`); with `intersection_free`, polygons
/// near a crossing are re-triangulated until the exact test finds none (src/triangulate.cpp).
/// Fan points are appended to `x`.
/// A vertex's cell: a moved vertex stays inside it.
struct VertexCell {
  Vec3 center;
  double half;  // half the side
};
/// `cells`: each vertex's cell; `finest`: the side of a finest cell (moves are bounded by it).
std::vector<std::array<uint32_t, 3>> triangulate_polygons(std::vector<Vec3>& x, const std::vector<VertexCell>& cells,
                                                          const std::vector<MeshPolygon>& polys, double finest,
                                                          bool intersection_free, TriangulationStats* stats);

/// A point of the common face of two cells (a side a b of a polygon, c the third corner of its
/// triangle), kFanEdgeMargin of the face's side inside its border; false when the segment
/// xa xb already crosses the face inside it (nothing to split) or the cells share no face.
bool face_point(const VertexCell& ca, const VertexCell& cb, const Vec3& xa, const Vec3& xb, const Vec3& c, Vec3& f);
/// Every polygon as a fan around its edge point, sides split at face points where needed
/// (fan_contour.cpp). Edge and face points are appended to `x`.
std::vector<std::array<uint32_t, 3>> fan_triangulate(std::vector<Vec3>& x, const std::vector<VertexCell>& cells,
                                                     const std::vector<MeshPolygon>& polys, size_t* face_points);

/// Splits a quad along the diagonal that folds most (keeps sharp creases whose two vertices
/// lie on the crease); returns the 2 triangles as index triples into `quad`.
std::array<std::array<int, 3>, 2> split_quad(const std::array<Vec3, 4>& p);

}  // namespace pic::detail

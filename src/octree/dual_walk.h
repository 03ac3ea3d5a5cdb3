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
               const std::function<void(const DualPolygon&)>& emit);

/// The same walk, finding cracks instead of polygons, in the order it meets them.
DualStats crack_edges(const Octree& t, const std::function<bool(uint32_t)>* active);

/// A dual polygon of the whole contour: tree vertex indices (counter-clockwise from outside)
/// and the minimal edge it is dual to, in output coordinates.
struct MeshPolygon {
  std::array<uint32_t, 4> v{};
  int count = 0;
  Vec3 e0{0, 0, 0}, e1{0, 0, 0};
};

/// Every dual polygon of the whole tree, in the order a serial walk finds them (collected by 9
/// parallel tasks: the 8 root children and the faces and edges between them).
std::vector<MeshPolygon> dual_polygons(const Octree& tree);

}  // namespace pic::detail

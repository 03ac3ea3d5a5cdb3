// Dual contouring (SurfaceNets) on the adaptive octree: Ju et al. 2002 cellProc / faceProc /
// edgeProc. Every minimal edge with a sign change yields a polygon through the vertices of
// the 4 (or 3) leaves around it, oriented by which end is inside.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "octree_util.h"

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

/// Splits a quad along the diagonal that folds most (keeps sharp creases whose two vertices
/// lie on the crease); returns the 2 triangles as index triples into `quad`.
std::array<std::array<int, 3>, 2> split_quad(const std::array<Vec3, 4>& p);

}  // namespace pic::detail

// Refining a tree around one lattice point before its sign changes: the settling passes make a
// leaf representable by changing corner signs, and a sign changed at a coarse leaf's corner
// moves that leaf's whole surface (two cubes touching at a corner lost one of them). Splitting
// the coarser leaves that hold the point down to the finest level first keeps every change
// within a finest cell of the point.
#pragma once

#include <array>
#include <cstdint>
#include <functional>

#include "octree/cell.h"

namespace pic::detail {

/// Splits every leaf coarser than t.max_depth whose closed cell holds lattice point p until the
/// leaves around p are finest cells. A uniform leaf splits into uniform children; a gray leaf is
/// resampled from the contour around it (its dual polygons and its neighbours'), QEF threshold
/// `error`. `grown` is told of every leaf that became internal and of every node appended (at
/// indices past the tree's old size), so that per-node bookkeeping can follow. Returns how many leaves were split.
size_t refine_around(Octree& t, const std::array<int64_t, 3>& p, double error,
                     const std::function<void(uint32_t)>& grown);

}  // namespace pic::detail

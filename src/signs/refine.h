// Refining a tree around one lattice point before its sign changes. The settling passes make a
// leaf representable by changing corner signs, and a sign changed at a coarse leaf's corner
// moves that leaf's whole surface (two cubes touching at a corner lost one of them). Splitting
// the coarser leaves that hold the point down to the finest level first keeps every change
// within a finest cell of the point. How a leaf is split is the caller's: from the input a tree
// was sampled from, or from the tree's own contour.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "signs/consistency.h"

namespace pic::detail {

/// A leaf's cell sampled again into a subtree (root at slot 0) that reaches the finest level
/// wherever its cells hold lattice point p, with the leaf's corner signs.
using ResampleLeaf = std::function<Builder(const LeafRef& leaf, const std::array<int64_t, 3>& p)>;

/// Replaces every leaf coarser than t.max_depth whose closed cell holds p by its resampled
/// subtree, until the leaves around p are finest cells. `grown` is told of every leaf replaced
/// and every node appended (past the tree's old size). Returns how many leaves were replaced.
size_t refine_around(Octree& t, const std::array<int64_t, 3>& p, const ResampleLeaf& resample,
                     const std::function<void(uint32_t)>& grown);

/// refine_around for many points at once: every leaf coarser than t.max_depth whose closed cell
/// holds one of them is resampled once (with `parallel`, leaves side by side: `resample` must
/// then be safe to call from several threads). `resample` is handed the first of the points the
/// leaf holds; to split around all of them in one sampling it must know the others itself.
/// Returns how many leaves were replaced.
size_t refine_all_around(Octree& t, const std::vector<std::array<int64_t, 3>>& points, const ResampleLeaf& resample,
                         bool parallel);

/// Lattice points that finer leaves give a sign on an edge or face of a coarser gray leaf
/// whose corners there (the edge's two, the face's four) all have the other sign: the
/// surface crosses that side twice between the coarse leaf's corners, which the leaf cannot
/// hold. The settling would give such a point the coarse side's sign, moving the surface by
/// up to the coarse leaf's size; a sampler that can look again refines around it instead.
/// `near`: when not empty, only coarse leaves meeting one of these closed lattice boxes.
std::vector<std::array<int64_t, 3>> points_against_coarse_sides(
    const Octree& t, const std::vector<std::pair<std::array<int64_t, 3>, std::array<int64_t, 3>>>& near,
    bool parallel);

}  // namespace pic::detail

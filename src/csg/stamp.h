// Stamping (paper 5.2.1): the cells of both operands where their surfaces may meet, and the
// partial contours around them that the combine step reads.
#pragma once

#include "csg/operand.h"

namespace pic::detail {

/// The dual polygons of the walk over `active` nodes (dual_walk) as triangles, indexed for box
/// queries: a tree's contour around part of it.
void contour_of(const Octree& t, const std::function<bool(uint32_t)>& active, PartialContour& x);

/// An operand's partial contour: the dual polygons around its stamped cells and around the
/// edges of its stamped coarse leaves.
void partial_contour(const Octree& t, const Stamps& stamps, uint32_t stamp, PartialContour& x);

/// Stamps every node whose closed cell holds one of the lattice points; returns how many gray
/// leaves were not stamped yet (only those add polygons to the partial contour).
size_t stamp_holding(const Octree& t, Stamps& stamps, uint32_t stamp, const std::vector<Lat>& points);

/// Stamps the cells where the operands' surfaces may meet (pairs where neither is uniform;
/// under a gray leaf of A only B's cells that A's partial contour comes near) and builds both
/// operands' partial contours. Sets stats.cells_stamped and the contour times.
void stamp_overlap(const Octree& a, Stamps& sa, const Octree& b, Stamps& sb, uint32_t stamp, PartialContour& pa,
                   PartialContour& pb, CsgStats& stats);

}  // namespace pic::detail

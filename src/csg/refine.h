// A leaf of a Boolean's result sampled again from the result's own contour around it (the
// clean-up's way to split a coarse leaf before changing a sign at its corner: signs/refine.h).
#pragma once

#include <array>

#include "signs/consistency.h"

namespace pic::detail {

/// The leaf's cell resampled from the dual polygons of the leaves meeting it (crossing parity
/// for signs, their planes for QEFs), split down to the finest level around lattice point p;
/// QEF threshold `error`.
Builder resample_from_contour(const Octree& t, const LeafRef& leaf, const std::array<int64_t, 3>& p, double error);

}  // namespace pic::detail

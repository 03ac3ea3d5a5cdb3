// Internal invariant checks of a PIC object, compiled in with -DPIC_ENABLE_ASSERTS=ON (the
// sanitizer build CI runs) and called after each phase that builds or edits a tree.
#pragma once

#include <string>

#include "pic/octree.h"

namespace pic::detail {

/// What a finished PIC object guarantees; throws std::logic_error naming `phase` and the first
/// broken rule:
///  - nodes: children in range and not shared, gray leaves' vertex indices in range;
///  - every vertex inside its own cell (cell-local coordinates in [0, 1]);
///  - gray leaves have a sign change; leaves hold one surface component unless the depth cap
///    stopped them (flag kFlagCapped);
///  - one sign per lattice point: every leaf that has a point as a corner gives it one sign.
void check_octree(const Octree& t, const std::string& phase);

}  // namespace pic::detail

#ifdef PIC_ENABLE_ASSERTS
#define PIC_CHECK_OCTREE(tree, phase) ::pic::detail::check_octree(tree, phase)
#else
#define PIC_CHECK_OCTREE(tree, phase) ((void)0)
#endif

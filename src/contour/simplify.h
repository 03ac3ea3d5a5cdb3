// The simplification's rounds, with the choice a test needs: a round after crossings may take
// over the blocks its changes do not reach from the round before (the default) or redo them all.
// Both give the same mesh.
#pragma once

#include <cstddef>

#include "pic/types.h"

namespace pic::detail {

/// simplify(mesh, tolerance); `take_over` false: every round redoes every block.
size_t simplify_in_rounds(TriMesh& mesh, double tolerance, bool take_over);

}  // namespace pic::detail

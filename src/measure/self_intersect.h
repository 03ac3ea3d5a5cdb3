// The exact self-intersection search without its first step (src/measure/self_intersect.cpp).
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "pic/types.h"

namespace pic::detail {

/// self_intersecting_pairs for a mesh whose positions are all distinct: merging equal
/// positions would change nothing, so it is skipped.
std::vector<std::pair<uint32_t, uint32_t>> intersecting_pairs_of_distinct(const TriMesh& mesh);

}  // namespace pic::detail

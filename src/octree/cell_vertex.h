// The representative vertex of a gray cell, from its QEF (geometry/qef.h).
#pragma once

#include <cstdint>

#include "geometry/qef.h"
#include "octree/cell.h"

namespace pic::detail {

/// The vertex of a gray cell: QEF minimum seeded at the centre, then at the corner with the
/// smallest error when the first solution leaves the cell (paper Figure 2). With no planes at
/// all, the mass point of the sign-changing edges' midpoints.
Qef::Solution cell_vertex(const Qef& q, const Cell& cell, uint8_t signs);
bool inside_cell(const Vec3& x, const Cell& cell);

}  // namespace pic::detail

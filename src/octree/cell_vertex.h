// The representative vertex of a gray cell, from its QEF (geometry/qef.h).
#pragma once

#include <cstdint>

#include "geometry/qef.h"
#include "octree/cell.h"

namespace pic::detail {

/// The vertex of a gray cell: QEF minimum seeded at the centre, then at the corner with the
/// smallest error when the first solution leaves the cell (paper Figure 2). With no planes at
/// all, the mass point of the sign-changing edges' midpoints. With `tip_at_corner`, a cell whose
/// one corner differs from the other seven takes that corner as its vertex when the planes pass
/// through it and leave the vertex free: two parts touching at a lattice point, as a Boolean
/// meets them.
Qef::Solution cell_vertex(const Qef& q, const Cell& cell, uint8_t signs, bool tip_at_corner = false,
                          Qef::Pinv pinv = Qef::Pinv::Truncated);
/// cell_vertex, or, where its residual is `error` or more, the vertex with every direction the
/// planes fix solved (Qef::Pinv::Damped) when that one lies in the cell and the planes meet in
/// it (residual below kSharpFit * error): a shallow crease's vertex on its line, so the cell
/// need not split until the crease looks flat.
Qef::Solution cell_vertex_sharp(const Qef& q, const Cell& cell, uint8_t signs, bool tip_at_corner, double error);
/// The same second solve for a vertex found some other way (`sol`, seeded at `seed`).
Qef::Solution sharpen(const Qef& q, const Cell& cell, uint8_t signs, const Qef::Solution& sol, const Vec3& seed,
                      bool tip_at_corner, double error);
bool inside_cell(const Vec3& x, const Cell& cell);

}  // namespace pic::detail

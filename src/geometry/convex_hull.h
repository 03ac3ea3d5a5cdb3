// The convex hull of a point set in 3D (incremental, exact orientation tests): OpenSCAD's
// hull() and the Minkowski sums' convex pieces, and a round body's inradius.
#pragma once

#include <vector>

#include "pic/types.h"

namespace pic::detail {

/// Convex hull of points, outward triangles; empty mesh if the points span no volume.
TriMesh convex_hull(const std::vector<Vec3>& points);

}  // namespace pic::detail

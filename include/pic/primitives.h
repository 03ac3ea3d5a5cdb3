// Closed, outward-oriented, welded triangle meshes of common solids (for `pic prim`, tests
// and benchmarks).
#pragma once

#include "pic/types.h"

namespace pic {

/// Axis-aligned box [lo, hi].
TriMesh make_box(const Vec3& lo, const Vec3& hi);
/// UV sphere with `segments` around and segments/2 rings.
TriMesh make_sphere(const Vec3& center, double radius, int segments = 64);
/// Cylinder along `axis` (0, 1, 2) centred at `center`, total height `height`.
TriMesh make_cylinder(const Vec3& center, double radius, double height, int axis = 2, int segments = 64);
/// Cone along `axis`: base disk of `radius` at center - height/2, apex at center + height/2.
TriMesh make_cone(const Vec3& center, double radius, double height, int axis = 2, int segments = 64);
/// Torus around `axis`: ring radius `major`, tube radius `minor`.
TriMesh make_torus(const Vec3& center, double major, double minor, int axis = 2, int segments = 64,
                   int tube_segments = 32);
/// Applies p -> R p + t with a row-major 3x3 R.
TriMesh transformed(TriMesh mesh, const std::array<double, 9>& r, const Vec3& t);
/// Rotation matrix about a unit axis by `radians`.
std::array<double, 9> rotation(const Vec3& axis, double radians);

}  // namespace pic

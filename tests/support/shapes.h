// Test meshes: thin adapters over the library's primitives (pic/primitives.h).
#pragma once

#include "pic/pic.h"
#include "pic/primitives.h"

namespace pic {

/// Latitude/longitude sphere with `nu` segments around z (`nv` is nu / 2 in the library).
inline TriMesh make_uv_sphere(Vec3 c, double r, int nu, int /*nv*/) { return make_sphere(c, r, nu); }

/// Cylinder along z standing on `base` (centre of the bottom disk).
inline TriMesh make_cylinder_on(Vec3 base, double r, double height, int n) {
  return make_cylinder(Vec3{base[0], base[1], base[2] + height / 2}, r, height, 2, n);
}

/// Two meshes written as one (no vertex shared): overlapping, they cross each other.
inline TriMesh joined(TriMesh a, const TriMesh& b) {
  const auto base = uint32_t(a.positions.size());
  a.positions.insert(a.positions.end(), b.positions.begin(), b.positions.end());
  for (auto t : b.triangles) a.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  return a;
}

/// Torus around z.
inline TriMesh make_torus_z(Vec3 c, double big_r, double small_r, int nu, int nv) {
  return make_torus(c, big_r, small_r, 2, nu, nv);
}

}  // namespace pic

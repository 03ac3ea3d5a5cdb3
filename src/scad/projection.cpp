// projection() and minkowski(): operations that need a 3D operand's actual shape while the
// tree is lowered (lower.cpp).
#include <algorithm>
#include <cmath>

#include "scad/lower.h"
#include "scad/region.h"

namespace pic::detail::scad {

Region project(const TriMesh& m, bool cut) {
  if (!cut) {
    // The shadow of a closed surface is the union of its upward-facing triangles' shadows.
    Region tris;
    for (const auto& t : m.triangles) {
      const Vec3 &a = m.positions[t[0]], &b = m.positions[t[1]], &c = m.positions[t[2]];
      const double z = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
      if (z > 0) tris.push_back({{a[0], a[1]}, {b[0], b[1]}, {c[0], c[1]}});
    }
    return region_union({tris});
  }
  // The cut by z = 0: each triangle's segment across the plane (a vertex on it counts as
  // above, so every crossing is met by exactly two triangles), chained into rings.
  std::vector<Segment> segs;
  double extent = 0;
  const auto cross = [&](uint32_t i, uint32_t j) {
    if (i > j) std::swap(i, j);  // the same point for both triangles on the edge
    const Vec3 &p = m.positions[i], &q = m.positions[j];
    const double l = p[2] / (p[2] - q[2]);
    return P2{p[0] + l * (q[0] - p[0]), p[1] + l * (q[1] - p[1])};
  };
  for (const auto& t : m.triangles) {
    P2 ends[2];
    int n = 0;
    for (int k = 0; k < 3; ++k) {
      const uint32_t i = t[k], j = t[(k + 1) % 3];
      if ((m.positions[i][2] >= 0) != (m.positions[j][2] >= 0)) ends[n++] = cross(i, j);
    }
    if (n == 2) {
      segs.push_back({ends[0], ends[1]});
      for (const P2& e : ends) extent = std::max({extent, std::abs(e[0]), std::abs(e[1])});
    }
  }
  return region_even_odd(rings_from_segments(segs, std::max(extent, 1.0) * 1e-12));
}

namespace {

bool convex(const TriMesh& m) {
  const TriMesh h = convex_hull(m.positions);
  const double v = volume(m), hv = volume(h);
  return hv > 0 && std::abs(hv - v) <= 1e-9 * hv;
}

// The solid as a union of convex point sets (hull vertices), or false when a part is not
// convex.
bool convex_parts(const Solid& s, const EvalOptions& o, std::vector<std::vector<Vec3>>& out) {
  switch (s.kind) {
    case Solid::Kind::Empty: return true;
    case Solid::Kind::Union:
      for (const Solid& c : s.children)
        if (!convex_parts(c, o, out)) return false;
      return true;
    case Solid::Kind::Mesh:
      if (!convex(s.mesh)) return false;
      out.push_back(convex_hull(s.mesh.positions).positions);
      return true;
    default: {  // a hull, difference or intersection: its surface, if that is convex
      const TriMesh m = solid_surface(s, o);
      if (m.triangles.empty()) return true;
      if (!convex(m)) return false;
      out.push_back(convex_hull(m.positions).positions);
      return true;
    }
  }
}

}  // namespace

Solid minkowski(const std::vector<Solid>& operands, const EvalOptions& o) {
  std::vector<std::vector<Vec3>> acc;
  bool first = true;
  for (const Solid& s : operands) {
    if (s.kind == Solid::Kind::Empty) continue;
    std::vector<std::vector<Vec3>> parts;
    if (!convex_parts(s, o, parts))
      throw InvalidInput("minkowski: an operand that is not a union of convex parts is not supported");
    if (first) {
      acc = std::move(parts);
      first = false;
      continue;
    }
    // (A1 u A2) + (B1 u B2) = union of Ai + Bj; each convex sum is the hull of vertex sums.
    std::vector<std::vector<Vec3>> next;
    for (const auto& a : acc)
      for (const auto& b : parts) {
        std::vector<Vec3> sums;
        sums.reserve(a.size() * b.size());
        for (const Vec3& p : a)
          for (const Vec3& q : b) sums.push_back({p[0] + q[0], p[1] + q[1], p[2] + q[2]});
        next.push_back(convex_hull(sums).positions);
      }
    if (next.size() > 100000) throw InvalidInput("minkowski: too many convex parts");
    acc = std::move(next);
  }
  Solid out;
  out.kind = Solid::Kind::Union;
  for (const auto& pts : acc) {
    Solid leaf;
    leaf.kind = Solid::Kind::Mesh;
    leaf.mesh = convex_hull(pts);
    if (!leaf.mesh.triangles.empty()) out.children.push_back(std::move(leaf));
  }
  if (out.children.empty()) return {};
  if (out.children.size() == 1) return std::move(out.children[0]);
  return out;
}

}  // namespace pic::detail::scad

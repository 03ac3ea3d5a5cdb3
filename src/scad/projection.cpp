// projection() and minkowski(): operations that need a 3D operand's actual shape while the
// tree is lowered (lower.cpp).
#include <algorithm>
#include <cmath>
#include <map>
#include <unordered_map>

#include "scad/lower.h"
#include "scad/region.h"
#include "geometry/union_find.h"
#include "geometry/vec3.h"

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
  // above, so every crossing edge is met by exactly the two triangles sharing it). Segments
  // are chained through the mesh edges they end on, not through positions: copies of a
  // vertex (where sheets were split apart) cannot join the wrong pieces.
  std::map<std::pair<uint32_t, uint32_t>, std::vector<size_t>> at_edge;
  std::vector<std::array<std::pair<uint32_t, uint32_t>, 2>> seg_edges;
  for (const auto& t : m.triangles) {
    std::array<std::pair<uint32_t, uint32_t>, 2> ends;
    int n = 0;
    for (int k = 0; k < 3; ++k) {
      const uint32_t i = t[k], j = t[(k + 1) % 3];
      if ((m.positions[i][2] >= 0) != (m.positions[j][2] >= 0) && n < 2) ends[n++] = {std::min(i, j), std::max(i, j)};
    }
    if (n != 2) continue;
    for (const auto& e : ends) at_edge[e].push_back(seg_edges.size());
    seg_edges.push_back(ends);
  }
  const auto point = [&](const std::pair<uint32_t, uint32_t>& e) {
    const Vec3 &p = m.positions[e.first], &q = m.positions[e.second];
    const double l = p[2] / (p[2] - q[2]);
    return P2{p[0] + l * (q[0] - p[0]), p[1] + l * (q[1] - p[1])};
  };
  std::vector<bool> used(seg_edges.size(), false);
  std::vector<Ring> rings;
  for (size_t s0 = 0; s0 < seg_edges.size(); ++s0) {
    if (used[s0]) continue;
    used[s0] = true;
    Ring ring{point(seg_edges[s0][0])};
    auto edge = seg_edges[s0][1];
    while (edge != seg_edges[s0][0]) {
      ring.push_back(point(edge));
      size_t next = SIZE_MAX;
      for (size_t c : at_edge[edge])
        if (!used[c]) next = c;
      if (next == SIZE_MAX) break;  // an open surface: the chain closes where it stops
      used[next] = true;
      edge = seg_edges[next][0] == edge ? seg_edges[next][1] : seg_edges[next][0];
    }
    if (ring.size() >= 3) rings.push_back(std::move(ring));
  }
  return region_even_odd(rings);
}

namespace {

/// Whether a closed surface bounds a convex solid: connected, positive volume, and convex at
/// every edge (each neighbour's far vertex on or below a triangle's plane). A closed connected
/// surface that is locally convex everywhere is the boundary of a convex body. (Not a hull
/// and a volume comparison: the incremental hull does not finish on large, mostly coplanar
/// point sets such as extruded text.)
bool convex(const TriMesh& m) {
  if (m.triangles.empty() || !(volume(m) > 0)) return false;
  Vec3 lo = m.positions[m.triangles[0][0]], hi = lo;
  for (const auto& t : m.triangles)
    for (uint32_t v : t)
      for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], m.positions[v][k]), hi[k] = std::max(hi[k], m.positions[v][k]);
  const double eps = 1e-9 * std::hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
  std::unordered_map<uint64_t, uint32_t> by_edge;  // directed edge -> triangle
  by_edge.reserve(3 * m.triangles.size());
  for (uint32_t f = 0; f < m.triangles.size(); ++f)
    for (int e = 0; e < 3; ++e)
      if (!by_edge.emplace(uint64_t(m.triangles[f][e]) << 32 | m.triangles[f][(e + 1) % 3], f).second) return false;
  UnionFind parts(m.triangles.size());
  for (uint32_t f = 0; f < m.triangles.size(); ++f) {
    const auto& t = m.triangles[f];
    const Vec3 &a = m.positions[t[0]], &b = m.positions[t[1]], &c = m.positions[t[2]];
    const Vec3 n = cross3(sub3(b, a), sub3(c, a));
    const double len = std::sqrt(dot3(n, n));
    for (int e = 0; e < 3; ++e) {
      const auto it = by_edge.find(uint64_t(t[(e + 1) % 3]) << 32 | t[e]);
      if (it == by_edge.end()) return false;  // not closed
      parts.join(f, it->second);
      for (uint32_t v : m.triangles[it->second])
        if (len > 0 && dot3(n, sub3(m.positions[v], a)) > eps * len) return false;
    }
  }
  for (uint32_t f = 1; f < m.triangles.size(); ++f)
    if (parts.root(f) != parts.root(0)) return false;
  return true;
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
      throw InvalidInput("an operand that is not a union of convex parts is not supported");
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
    if (next.size() > 100000) throw InvalidInput("too many convex parts");
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

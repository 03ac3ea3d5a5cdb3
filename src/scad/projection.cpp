// projection(): the shadow or the section of a 3D operand's actual shape, taken while the
// tree is lowered (lower.cpp).
#include <algorithm>
#include <cmath>
#include <map>

#include "scad/lower.h"
#include "scad/region.h"
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
    // The union of thousands of shadows leaves pinholes between them a grid step wide, and
    // among those Clipper can label a real hole an outer ring (GEB's "B": a hole of 8.6 came
    // out filled). With the pinholes dropped (from_paths), the rings bound the shadow by their
    // nesting alone: even-odd fill reads them so whatever their orientation.
    return region_even_odd(region_union({tris}));
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

}  // namespace pic::detail::scad

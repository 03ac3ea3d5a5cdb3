#include <algorithm>
#include <map>
#include <unordered_map>

#include "octree/cell.h"
#include "geometry/union_find.h"

namespace pic {

MeshTopology analyze_topology(const TriMesh& mesh) {
  MeshTopology r;
  r.vertices = mesh.positions.size();
  r.triangles = mesh.triangles.size();
  // Directed half-edge counts per undirected edge.
  struct EdgeUse {
    uint32_t forward = 0, backward = 0;
  };
  std::unordered_map<uint64_t, EdgeUse> edges;
  edges.reserve(mesh.triangles.size() * 2);
  for (const auto& t : mesh.triangles) {
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) {
      ++r.degenerate_triangles;
      continue;
    }
    for (int e = 0; e < 3; ++e) {
      const uint64_t a = t[e], b = t[(e + 1) % 3];
      auto& u = edges[std::min(a, b) << 32 | std::max(a, b)];
      (a < b ? u.forward : u.backward)++;
    }
  }
  for (const auto& [k, u] : edges) {
    const uint32_t n = u.forward + u.backward;
    if (n == 1) ++r.boundary_edges;
    if (n > 2) ++r.nonmanifold_edges;
    if (n == 2 && u.forward != 1) ++r.inconsistent_edges;
  }
  // Vertex fans: the triangles around a manifold vertex form one cycle through its edges.
  std::vector<std::vector<uint32_t>> around(mesh.positions.size());
  for (uint32_t f = 0; f < mesh.triangles.size(); ++f) {
    const auto& t = mesh.triangles[f];
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;
    for (uint32_t v : t) around[v].push_back(f);
  }
  for (uint32_t v = 0; v < around.size(); ++v) {
    const auto& fan = around[v];
    if (fan.empty()) continue;
    // Union-find over the fan's triangles joined by shared edges at v.
    std::map<uint32_t, std::vector<size_t>> by_other;
    for (size_t i = 0; i < fan.size(); ++i)
      for (uint32_t w : mesh.triangles[fan[i]])
        if (w != v) by_other[w].push_back(i);
    detail::UnionFind fans(fan.size());
    for (const auto& [w, list] : by_other)
      for (size_t i = 1; i < list.size(); ++i) fans.join(list[i], list[0]);
    size_t roots = 0;
    for (size_t i = 0; i < fan.size(); ++i) roots += fans.root(i) == i;
    if (roots > 1) ++r.nonmanifold_vertices;
  }
  return r;
}

double volume(const TriMesh& mesh) {
  double v = 0;
  for (const auto& t : mesh.triangles) {
    const Vec3 &a = mesh.positions[t[0]], &b = mesh.positions[t[1]], &c = mesh.positions[t[2]];
    v += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
         a[2] * (b[0] * c[1] - b[1] * c[0]);
  }
  return v / 6;
}

}  // namespace pic

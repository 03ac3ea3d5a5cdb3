#include <algorithm>
#include <map>
#include <unordered_map>

#include "octree/cell.h"
#include "geometry/union_find.h"

namespace pic {

std::string to_string(CsgOp op) {
  switch (op) {
    case CsgOp::Union: return "union";
    case CsgOp::Intersect: return "intersect";
    case CsgOp::Subtract: return "subtract";
  }
  return "?";
}

std::optional<CsgOp> parse_csg_op(const std::string& s) {
  if (s == "union" || s == "add") return CsgOp::Union;
  if (s == "intersect" || s == "intersection") return CsgOp::Intersect;
  if (s == "subtract" || s == "difference" || s == "minus") return CsgOp::Subtract;
  return std::nullopt;
}

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

OctreeStats analyze(const Octree& tree) {
  OctreeStats s;
  s.memory_bytes = tree.nodes.size() * sizeof(Node) + tree.vertices.size() * sizeof(tree.vertices[0]);
  s.levels.resize(tree.max_depth + 1);
  s.bbox_min = {1e300, 1e300, 1e300};
  s.bbox_max = {-1e300, -1e300, -1e300};
  std::function<void(uint32_t, const detail::Cell&)> walk = [&](uint32_t node, const detail::Cell& cell) {
    const Node& n = tree.nodes[node];
    ++s.nodes;  // reachable nodes: an octree edited in place may hold replaced ones
    if (cell.level >= static_cast<int>(s.levels.size())) s.levels.resize(cell.level + 1);
    auto& l = s.levels[cell.level];
    switch (n.kind) {
      case CellKind::White: ++l.white; break;
      case CellKind::Black: ++l.black; break;
      case CellKind::Gray: {
        ++l.gray;
        ++s.pics;
        if (n.flags & kFlagCapped) ++s.capped;
        const Vec3 p = detail::unit_to_world(tree.cube, detail::vertex_unit(cell, tree.vertices[n.index]));
        for (int k = 0; k < 3; ++k) {
          s.bbox_min[k] = std::min(s.bbox_min[k], p[k]);
          s.bbox_max[k] = std::max(s.bbox_max[k], p[k]);
        }
        break;
      }
      case CellKind::Internal:
        ++l.internal;
        for (int c = 0; c < 8; ++c) walk(n.index + c, cell.child(c));
        break;
    }
  };
  walk(0, detail::Cell{});
  if (s.pics == 0) s.bbox_min = s.bbox_max = {0, 0, 0};
  return s;
}

}  // namespace pic

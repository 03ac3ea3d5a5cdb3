// Internal octree helpers: cell addressing on the global lattice and a tree builder.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "geometry/lattice.h"
#include "pic/octree.h"
#include "pic/types.h"

namespace pic::detail {

/// A cell: its level and the lattice coordinates (level-kMaxLevel units) of its min corner.
struct Cell {
  int level = 0;
  std::array<int64_t, 3> lat{0, 0, 0};

  int64_t span() const { return int64_t{1} << (kMaxLevel - level); }
  Cell child(int c) const {
    const int64_t h = span() / 2;
    return {level + 1, {lat[0] + (c & 1) * h, lat[1] + ((c >> 1) & 1) * h, lat[2] + ((c >> 2) & 1) * h}};
  }
  std::array<int64_t, 3> corner(int c) const {
    const int64_t s = span();
    return {lat[0] + (c & 1) * s, lat[1] + ((c >> 1) & 1) * s, lat[2] + ((c >> 2) & 1) * s};
  }
  IBox box() const { return cell_box(level, lat); }
  /// Which corner of this cell the lattice point p is, or -1.
  int corner_index(const std::array<int64_t, 3>& p) const {
    const int64_t s = span();
    int k = 0;
    for (int a = 0; a < 3; ++a) {
      if (p[a] == lat[a] + s) k |= 1 << a;
      else if (p[a] != lat[a]) return -1;
    }
    return k;
  }
  /// The child whose half-open cell holds lattice point p (p inside this cell).
  int child_toward(const std::array<int64_t, 3>& p) const {
    const int64_t h = span() / 2;
    int c = 0;
    for (int a = 0; a < 3; ++a)
      if (p[a] >= lat[a] + h) c |= 1 << a;
    return c;
  }
  /// Whether lattice point p lies in the closed cell.
  bool holds(const std::array<int64_t, 3>& p) const {
    const int64_t s = span();
    for (int a = 0; a < 3; ++a)
      if (p[a] < lat[a] || p[a] > lat[a] + s) return false;
    return true;
  }
  double size() const { return 1.0 / double(int64_t{1} << level); }
  Vec3 min_unit() const {
    constexpr double k = 1.0 / double(int64_t{1} << kMaxLevel);
    return {lat[0] * k, lat[1] * k, lat[2] * k};
  }
  Vec3 max_unit() const {
    const Vec3 lo = min_unit();
    const double s = size();
    return {lo[0] + s, lo[1] + s, lo[2] + s};
  }
};

/// Nodes and vertices being built; children of a node are 8 consecutive slots.
struct Builder {
  std::vector<Node> nodes;
  std::vector<std::array<float, 3>> vertices;

  uint32_t alloc_children() {
    const auto first = static_cast<uint32_t>(nodes.size());
    nodes.resize(nodes.size() + 8);
    return first;
  }
  void set_gray(uint32_t slot, const Cell& cell, uint8_t signs, const Vec3& x_unit, uint8_t flags);
  void set_uniform(uint32_t slot, bool inside) {
    nodes[slot] = Node{0, inside ? CellKind::Black : CellKind::White, 0, 0, 0};
  }
  /// Appends `sub` (root at sub.nodes[0]) with its root written into `slot`.
  void splice(uint32_t slot, const Builder& sub);

};

/// Appends the nodes and vertices of `sub` below its root, re-indexed, and returns its root
/// (for the caller to place).
Node append_subtree(std::vector<Node>& nodes, std::vector<std::array<float, 3>>& vertices, const Builder& sub);

/// Nodes reachable from the root (a tree edited in place keeps replaced subtrees in its arrays).
size_t reachable_nodes(const Octree& t);
/// Drops unreachable nodes and vertices (left behind by in-place replacement).
void compact(Octree& t);

/// World position of a cell-local vertex.
inline Vec3 vertex_unit(const Cell& cell, const std::array<float, 3>& local) {
  const Vec3 m = cell.min_unit();
  const double s = cell.size();
  return {m[0] + local[0] * s, m[1] + local[1] * s, m[2] + local[2] * s};
}

/// Cell-local float coordinates of a unit-space position, clamped into the cell (the .pic
/// quantization relies on the [0, 1] range).
inline std::array<float, 3> to_local(const Cell& cell, const Vec3& x) {
  const Vec3 m = cell.min_unit();
  const double inv = double(int64_t{1} << cell.level);
  std::array<float, 3> local;
  for (int k = 0; k < 3; ++k) local[k] = static_cast<float>(std::min(1.0, std::max(0.0, (x[k] - m[k]) * inv)));
  return local;
}

/// Appends a gray leaf's vertex to `vertices` and returns the leaf's node.
inline Node add_gray(std::vector<std::array<float, 3>>& vertices, const Cell& cell, uint8_t signs, const Vec3& x,
                     uint8_t flags = 0) {
  vertices.push_back(to_local(cell, x));
  return Node{static_cast<uint32_t>(vertices.size() - 1), CellKind::Gray, signs, flags, 0};
}

/// Unit-cube to input coordinates and back.
inline Vec3 unit_to_world(const Cube& c, const Vec3& u) {
  return {c.origin[0] + u[0] * c.size, c.origin[1] + u[1] * c.size, c.origin[2] + u[2] * c.size};
}
inline Vec3 world_to_unit(const Cube& c, const Vec3& p) {
  return {(p[0] - c.origin[0]) / c.size, (p[1] - c.origin[1]) / c.size, (p[2] - c.origin[2]) / c.size};
}

/// Visits every leaf with its cell, depth-first in child order.
template <class F>
void visit_leaves(const Octree& t, uint32_t node, const Cell& cell, F&& f) {
  const Node& n = t.nodes[node];
  if (n.kind == CellKind::Internal) {
    for (int c = 0; c < 8; ++c) visit_leaves(t, n.index + c, cell.child(c), f);
  } else {
    f(node, cell);
  }
}

}  // namespace pic::detail

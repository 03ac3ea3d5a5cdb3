// A lattice point's sign as the leaves around it hold it: see point_signs.h.
#include "octree/point_signs.h"

#include "octree/cell_vertex.h"

namespace pic::detail {

using Lat = std::array<int64_t, 3>;

/// The node covering cell `target`, or the leaf above it; `path` gets the nodes from the
/// root down to it.
LeafRef node_at(const Octree& t, const Cell& target, std::vector<uint32_t>* path) {
  uint32_t node = 0;
  Cell cell;
  while (cell.level < target.level && t.nodes[node].kind == CellKind::Internal) {
    if (path) path->push_back(node);
    const int c = cell.child_toward(target.lat);
    node = t.nodes[node].index + c;
    cell = cell.child(c);
  }
  if (path) path->push_back(node);
  return {node, cell};
}

/// The finest lattice cell touching p in octant o (bit k set: on p's high side along k);
/// false when it falls outside the root.
bool octant_cell(const Lat& p, int o, Lat& q) {
  constexpr int64_t kLimit = int64_t{1} << kMaxLevel;
  for (int k = 0; k < 3; ++k) {
    q[k] = p[k] - (((o >> k) & 1) ? 0 : 1);
    if (q[k] < 0 || q[k] >= kLimit) return false;
  }
  return true;
}

std::vector<Around> leaves_around(const Octree& t, const Lat& p, std::vector<uint32_t>* path) {
  std::vector<Around> out;
  for (int o = 0; o < 8; ++o) {
    Lat q;
    if (!octant_cell(p, o, q)) continue;
    const LeafRef l = leaf_at(t, q, path);
    const int c = l.cell.corner_index(p);
    if (c < 0) continue;
    bool seen = false;
    for (const auto& a : out) seen = seen || a.node == l.node;
    if (!seen) out.push_back({l.node, c, l.cell});
  }
  return out;
}

uint8_t signs_of(const Node& n) {
  if (n.kind == CellKind::Gray) return n.signs;
  return n.kind == CellKind::Black ? 0xff : 0;
}

uint8_t with_corner(uint8_t s, int c, bool inside) { return uint8_t(s & ~(1 << c)) | uint8_t(int(inside) << c); }

void flip_corner(Octree& t, uint32_t node, int c, const Cell& cell) {
  Node& n = t.nodes[node];
  if (n.kind == CellKind::Gray) {
    n.signs ^= uint8_t(1 << c);
    return;
  }
  const uint8_t s = uint8_t(signs_of(n) ^ (1 << c));
  n = add_gray(t.vertices, cell, s, cell_vertex(Qef{}, cell, s).position);
}

LeafRef leaf_at(const Octree& t, const Lat& q, std::vector<uint32_t>* path) {
  return node_at(t, Cell{kMaxLevel, q}, path);
}

std::optional<bool> point_sign(const Octree& t, const Lat& p) {
  for (int o = 0; o < 8; ++o) {
    Lat q;
    if (!octant_cell(p, o, q)) continue;
    const LeafRef l = leaf_at(t, q);
    if (const int c = l.cell.corner_index(p); c >= 0) return bool((signs_of(t.nodes[l.node]) >> c) & 1);
  }
  return std::nullopt;
}

/// Gives lattice point p the sign `inside` in every leaf that has it as a corner, and reports
/// the nodes on the way to them. Set, not toggled: around a crack (a uniform leaf beside a
/// sign change) the leaves disagree, and a toggle would keep them disagreeing — the gray
/// leaves' sign flips one way and the uniform leaf's the other, and the contour has a hole.
void set_point_sign(Octree& t, const Lat& p, bool inside, const std::function<void(uint32_t)>* touched) {
  std::vector<uint32_t> path;
  for (const auto& a : leaves_around(t, p, touched ? &path : nullptr))
    if (bool((signs_of(t.nodes[a.node]) >> a.corner) & 1) != inside) flip_corner(t, a.node, a.corner, a.cell);
  if (touched)
    for (uint32_t x : path) (*touched)(x);
}

}  // namespace pic::detail

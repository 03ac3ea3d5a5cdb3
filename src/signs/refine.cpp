// Refining around a lattice point: see refine.h.
#include "signs/refine.h"

#include <optional>

namespace pic::detail {

using Lat = std::array<int64_t, 3>;

namespace {

/// The sign a leaf outside `cell` gives lattice point q as one of its corners, if one does.
std::optional<bool> sign_outside(const Octree& t, const Cell& cell, const Lat& q) {
  for (int o = 0; o < 8; ++o) {
    Lat f;
    if (!octant_cell(q, o, f)) continue;
    bool in_cell = true;
    for (int k = 0; k < 3; ++k) in_cell = in_cell && f[k] >= cell.lat[k] && f[k] < cell.lat[k] + cell.span();
    if (in_cell) continue;
    const LeafRef l = leaf_at(t, f);
    if (const int c = l.cell.corner_index(q); c >= 0) return ((signs_of(t.nodes[l.node]) >> c) & 1) != 0;
  }
  return std::nullopt;
}

/// The new leaves of `cell`'s subtree take, at the points of the cell's boundary, the signs
/// the leaves outside show there: the signs there may have been settled since the tree was
/// made, and one point must have one sign whichever leaf asks.
void agree_on_boundary(Octree& t, uint32_t root, const Cell& cell) {
  std::vector<std::pair<LeafRef, int>> flips;
  visit_leaves(t, root, cell, [&](uint32_t node, const Cell& c) {
    for (int k = 0; k < 8; ++k) {
      const Lat q = c.corner(k);
      bool on_boundary = false;
      for (int a = 0; a < 3; ++a) on_boundary = on_boundary || q[a] == cell.lat[a] || q[a] == cell.lat[a] + cell.span();
      if (!on_boundary) continue;
      const std::optional<bool> s = sign_outside(t, cell, q);
      if (s && *s != (((signs_of(t.nodes[node]) >> k) & 1) != 0)) flips.push_back({{node, c}, k});
    }
  });
  for (const auto& [l, k] : flips) flip_corner(t, l.node, k, l.cell);
}

}  // namespace

size_t refine_around(Octree& t, const Lat& p, const ResampleLeaf& resample, const std::function<void(uint32_t)>& grown) {
  size_t replaced = 0;
  for (int o = 0; o < 8; ++o) {
    Lat q;
    if (!octant_cell(p, o, q)) continue;
    const LeafRef l = leaf_at(t, q);
    if (l.cell.level >= t.max_depth) continue;
    const auto first = static_cast<uint32_t>(t.nodes.size());
    const Builder sub = resample(l, p);
    t.nodes[l.node] = append_subtree(t.nodes, t.vertices, sub);
    agree_on_boundary(t, l.node, l.cell);
    ++replaced;
    grown(l.node);
    for (auto k = first; k < t.nodes.size(); ++k) grown(k);
  }
  return replaced;
}

}  // namespace pic::detail

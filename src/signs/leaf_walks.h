// Walks over leaves that the sign passes share.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "octree/point_signs.h"

namespace pic::detail {

/// Every leaf whose closed cell meets the closed lattice box [lo, hi], in depth-first order,
/// leaving out the subtrees for which `skip(node, cell)` holds.
template <class Skip>
void leaves_touching_if(const Octree& t, uint32_t node, const Cell& cell, const std::array<int64_t, 3>& lo,
                        const std::array<int64_t, 3>& hi, const Skip& skip, std::vector<LeafRef>& out) {
  if (skip(node, cell)) return;
  const int64_t s = cell.span();
  for (int k = 0; k < 3; ++k)
    if (cell.lat[k] > hi[k] || cell.lat[k] + s < lo[k]) return;
  const Node& n = t.nodes[node];
  if (n.kind != CellKind::Internal) {
    out.push_back({node, cell});
    return;
  }
  // Only the children whose halves meet the box along every axis, in child order.
  int first[3], last[3];
  for (int k = 0; k < 3; ++k) {
    const int64_t mid = cell.lat[k] + s / 2;
    first[k] = lo[k] <= mid ? 0 : 1;
    last[k] = hi[k] >= mid ? 1 : 0;
  }
  for (int z = first[2]; z <= last[2]; ++z)
    for (int y = first[1]; y <= last[1]; ++y)
      for (int x = first[0]; x <= last[0]; ++x) {
        const int c = x | y << 1 | z << 2;
        leaves_touching_if(t, n.index + c, cell.child(c), lo, hi, skip, out);
      }
}

/// Every leaf up to level `max_level` whose closed cell meets the closed lattice box [lo, hi],
/// in depth-first order.
inline void leaves_touching(const Octree& t, uint32_t node, const Cell& cell, const std::array<int64_t, 3>& lo,
                            const std::array<int64_t, 3>& hi, int max_level, std::vector<LeafRef>& out) {
  leaves_touching_if(t, node, cell, lo, hi, [&](uint32_t, const Cell& c) { return c.level > max_level; }, out);
}

/// Calls f(node) for every node whose closed cell meets the closed lattice box [lo, hi], below
/// `node` (cell `cell`), depth first.
template <class F>
void for_each_node_meeting(const Octree& t, uint32_t node, const Cell& cell, const std::array<int64_t, 3>& lo,
                           const std::array<int64_t, 3>& hi, F&& f) {
  const int64_t s = cell.span();
  for (int k = 0; k < 3; ++k)
    if (cell.lat[k] > hi[k] || cell.lat[k] + s < lo[k]) return;
  f(node);
  const Node& n = t.nodes[node];
  if (n.kind == CellKind::Internal)
    for (int c = 0; c < 8; ++c) for_each_node_meeting(t, n.index + c, cell.child(c), lo, hi, f);
}

/// Calls f(node, cell) for every gray leaf in the subtrees for which `active` holds (every
/// one when null), depth first.
template <class F>
void for_each_gray_leaf(const Octree& t, const std::function<bool(uint32_t)>* active, F&& f) {
  auto walk = [&](auto&& self, uint32_t node, const Cell& cell) -> void {
    if (active && !(*active)(node)) return;
    const Node& n = t.nodes[node];
    if (n.kind == CellKind::Internal) {
      for (int c = 0; c < 8; ++c) self(self, n.index + c, cell.child(c));
    } else if (n.kind == CellKind::Gray) {
      f(node, cell);
    }
  };
  walk(walk, 0, Cell{});
}

}  // namespace pic::detail

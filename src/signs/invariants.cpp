// Invariant checks: see invariants.h.
#include "signs/invariants.h"

#include <stdexcept>
#include <vector>

#include "octree/cell.h"
#include "signs/consistency.h"

namespace pic::detail {

namespace {

[[noreturn]] void broken(const std::string& phase, const std::string& what) {
  throw std::logic_error("invariant broken after " + phase + ": " + what);
}

std::string where(const Cell& cell) {
  return "level " + std::to_string(cell.level) + " cell at (" + std::to_string(cell.lat[0]) + ", " +
         std::to_string(cell.lat[1]) + ", " + std::to_string(cell.lat[2]) + ")";
}

void check_leaf(const Octree& t, const Node& n, const Cell& cell, const std::string& phase) {
  if (n.kind != CellKind::Gray) return;
  if (n.index >= t.vertices.size()) broken(phase, "vertex index out of range at " + where(cell));
  for (float x : t.vertices[n.index])
    if (!(x >= 0.0f && x <= 1.0f)) broken(phase, "vertex outside its cell at " + where(cell));
  if (n.signs == 0 || n.signs == 0xff) return;  // a crack repair: a vertex with no sign change
  if (!(n.flags & kFlagCapped) && multi_component(n.signs))
    broken(phase, "leaf with more than one surface component at " + where(cell));
}

/// Whether finest lattice cell q lies in `cell` (half-open).
bool contains(const Cell& cell, const std::array<int64_t, 3>& q) {
  const int64_t s = cell.span();
  for (int a = 0; a < 3; ++a)
    if (q[a] < cell.lat[a] || q[a] >= cell.lat[a] + s) return false;
  return true;
}

/// One sign per lattice point: each corner p of a leaf agrees with the first leaf, in octant
/// order around p, that has p as a corner (every leaf agreeing with that one is every leaf
/// agreeing). `path`: the nodes and cells from the root down to the leaf; neighbours are
/// found from the lowest ancestor that holds them, so most lookups are a step or two.
void check_corner_signs(const Octree& t, const std::vector<std::pair<uint32_t, Cell>>& path,
                        const std::string& phase) {
  const auto& [node, cell] = path.back();
  const uint8_t mine = signs_of(t.nodes[node]);
  for (int c = 0; c < 8; ++c) {
    const std::array<int64_t, 3> p = cell.corner(c);
    for (int o = 0; o < 8; ++o) {
      if (o == (~c & 7)) break;  // the leaf itself comes first: nothing to compare
      std::array<int64_t, 3> q;
      if (!octant_cell(p, o, q)) continue;
      size_t up = path.size() - 1;
      while (up > 0 && !contains(path[up].second, q)) --up;
      uint32_t n = path[up].first;
      Cell at = path[up].second;
      // The neighbour's subtree may not be walked yet: its children are checked on the way down.
      while (t.nodes[n].kind == CellKind::Internal) {
        if (at.level >= kMaxLevel || size_t(t.nodes[n].index) + 8 > t.nodes.size())
          broken(phase, "bad children at " + where(at));
        const int k = at.child_toward(q);
        n = t.nodes[n].index + k;
        at = at.child(k);
      }
      const int k = at.corner_index(p);
      if (k < 0) continue;
      if (bool((signs_of(t.nodes[n]) >> k) & 1) != bool((mine >> c) & 1))
        broken(phase, "corner " + std::to_string(c) + " of " + where(cell) + " disagrees with a neighbour's sign");
      break;
    }
  }
}

/// Checks the subtree of path.back() (nodes reached once, children in range, leaves).
void check_subtree(const Octree& t, std::vector<std::pair<uint32_t, Cell>>& path, std::vector<uint8_t>& seen,
                   const std::string& phase) {
  const auto [node, cell] = path.back();
  if (node >= t.nodes.size()) broken(phase, "child index out of range");
  if (seen[node]++) broken(phase, "node reached twice");
  const Node& n = t.nodes[node];
  if (n.kind == CellKind::Internal) {
    if (cell.level >= kMaxLevel || size_t(n.index) + 8 > t.nodes.size()) broken(phase, "bad children at " + where(cell));
    for (int c = 0; c < 8; ++c) {
      path.push_back({n.index + uint32_t(c), cell.child(c)});
      check_subtree(t, path, seen, phase);
      path.pop_back();
    }
    return;
  }
  check_leaf(t, n, cell, phase);
  check_corner_signs(t, path, phase);
}

}  // namespace

void check_octree(const Octree& t, const std::string& phase) {
  if (t.nodes.empty()) broken(phase, "no root node");
  if (t.max_depth < 0 || t.max_depth > kMaxLevel) broken(phase, "depth out of range");
  std::vector<uint8_t> seen(t.nodes.size(), 0);
  std::vector<std::pair<uint32_t, Cell>> path{{0u, Cell{}}};
  check_subtree(t, path, seen, phase);
}

}  // namespace pic::detail

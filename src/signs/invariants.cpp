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

/// One sign per lattice point: each corner of a gray leaf against the leaves around it.
void check_corner_signs(const Octree& t, const Node& n, const Cell& cell, const std::string& phase) {
  if (n.kind != CellKind::Gray) return;
  for (int c = 0; c < 8; ++c) {
    const std::optional<bool> s = point_sign(t, cell.corner(c));
    if (s && *s != bool((n.signs >> c) & 1)) broken(phase, "corner " + std::to_string(c) + " of " + where(cell) +
                                                               " disagrees with a neighbour's sign");
  }
}

}  // namespace

void check_octree(const Octree& t, const std::string& phase) {
  if (t.nodes.empty()) broken(phase, "no root node");
  if (t.max_depth < 0 || t.max_depth > kMaxLevel) broken(phase, "depth out of range");
  std::vector<uint8_t> seen(t.nodes.size(), 0);
  std::vector<std::pair<uint32_t, Cell>> stack{{0u, Cell{}}};
  std::vector<std::pair<uint32_t, Cell>> grays;
  while (!stack.empty()) {
    const auto [node, cell] = stack.back();
    stack.pop_back();
    if (node >= t.nodes.size()) broken(phase, "child index out of range");
    if (seen[node]++) broken(phase, "node reached twice");
    const Node& n = t.nodes[node];
    if (n.kind == CellKind::Internal) {
      if (cell.level >= kMaxLevel || size_t(n.index) + 8 > t.nodes.size()) broken(phase, "bad children at " + where(cell));
      for (int c = 0; c < 8; ++c) stack.push_back({n.index + uint32_t(c), cell.child(c)});
      continue;
    }
    check_leaf(t, n, cell, phase);
    if (n.kind == CellKind::Gray) grays.push_back({node, cell});
  }
  for (const auto& [node, cell] : grays) check_corner_signs(t, t.nodes[node], cell, phase);
}

}  // namespace pic::detail

// An operand's state over a cell of the recursion: see operand.h.
#include "csg/operand.h"

namespace pic::detail {

Side side_of(Operand& x, uint32_t node, const Cell& cell) {
  const Node& n = x.t.nodes[node];
  Side s;
  s.node = node;
  if (n.kind == CellKind::Internal) {
    s.kind = Side::Internal;
  } else if (n.kind == CellKind::Gray) {
    s.kind = Side::Gray;
    s.real = true;
    s.signs = n.signs;
    s.leaf_cell = cell;
    s.idx = x.triangles_in(node, cell);
  } else {
    s.inside = n.kind == CellKind::Black;
  }
  return s;
}

SignGrid sign_grid(Operand& x, const Side& s, const Cell& cell) {
  SignGrid g{};
  const int64_t h = cell.span() / 2;
  for (int i = 0; i < 27; ++i) {
    const int gx = i % 3, gy = (i / 3) % 3, gz = i / 9;
    if (gx != 1 && gy != 1 && gz != 1) g[i] = (s.signs >> (gx / 2 | (gy / 2) << 1 | (gz / 2) << 2)) & 1;
    else g[i] = x.sign_in({cell.lat[0] + gx * h, cell.lat[1] + gy * h, cell.lat[2] + gz * h}, s.node, s.leaf_cell);
  }
  return g;
}

/// The operand over child `c` of `cell`: a child node, or a virtual cell inside a gray leaf
/// (signs from the grid, the leaf's triangles that reach the child), or uniform when such a
/// virtual cell has neither a sign change nor a triangle.
Side child_side(Operand& x, const Side& s, const Cell& cell, int c, const SignGrid& grid) {
  const Cell cc = cell.child(c);
  if (s.kind == Side::Uniform) return s;
  if (s.kind == Side::Internal) return side_of(x, x.t.nodes[s.node].index + c, cc);
  Side v;
  v.kind = Side::Gray;
  v.node = s.node;
  v.real = false;
  v.leaf_cell = s.leaf_cell;
  for (int k = 0; k < 8; ++k) {
    const int gx = (c & 1) + (k & 1), gy = ((c >> 1) & 1) + ((k >> 1) & 1), gz = ((c >> 2) & 1) + ((k >> 2) & 1);
    v.signs |= uint8_t(grid[gx + 3 * gy + 9 * gz]) << k;
  }
  filter_box(x.tris, s.idx, cc.box(), v.idx);
  if ((v.signs == 0 || v.signs == 0xff) && !meets_box(x.tris, v.idx, cc.box())) {
    Side u;
    u.inside = v.signs != 0;
    return u;
  }
  return v;
}

}  // namespace pic::detail

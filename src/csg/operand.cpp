// An operand's state over a cell of the recursion: see operand.h.
#include "csg/operand.h"
#include "octree/point_signs.h"

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

namespace {

/// Whether every leaf corner of `t` on the closed square across `axis` at `plane` (from `lo` to
/// `hi` on the other two axes) has sign `inside`: a walk of the leaves touching the square.
bool face_corners_are(const Octree& t, uint32_t node, const Cell& cell, int axis, int64_t plane, const Lat& lo,
                      const Lat& hi, bool inside) {
  const int64_t s = cell.span();
  if (cell.lat[axis] > plane || cell.lat[axis] + s < plane) return true;
  for (int k = 0; k < 3; ++k)
    if (k != axis && (cell.lat[k] > hi[k] || cell.lat[k] + s < lo[k])) return true;
  const Node& n = t.nodes[node];
  if (n.kind == CellKind::Internal) {
    for (int c = 0; c < 8; ++c)
      if (!face_corners_are(t, n.index + c, cell.child(c), axis, plane, lo, hi, inside)) return false;
    return true;
  }
  for (int c = 0; c < 8; ++c) {
    const Lat p = cell.corner(c);
    bool on = p[axis] == plane;
    for (int k = 0; k < 3; ++k) on = on && (k == axis || (p[k] >= lo[k] && p[k] <= hi[k]));
    const bool sign = n.kind == CellKind::Gray ? bool((n.signs >> c) & 1) : n.kind == CellKind::Black;
    if (on && sign != inside) return false;
  }
  return true;
}

/// Whether x's sign is `inside` at every lattice point on the boundary of virtual cell `vc`
/// (inside gray leaf `leaf`) where a finer leaf beyond the leaf has a corner. Inside the
/// leaf, a cell that no triangle meets takes its corners' sign; on the leaf's faces, finer
/// neighbours' corners have their own, and the partial contour need not pass through the
/// virtual cell to separate them (the leaf's vertex may lie across the leaf, and its polygons
/// reach the face elsewhere). Only the neighbours of the leaf's size that are split are walked:
/// across the face, and across its edges where vc reaches them.
bool boundary_is(const Octree& t, const Cell& vc, const Cell& leaf, bool inside) {
  const int64_t s = vc.span(), ls = leaf.span();
  for (int axis = 0; axis < 3; ++axis)
    for (const bool high : {false, true}) {
      const int64_t plane = vc.lat[axis] + (high ? s : 0);
      if (plane != leaf.lat[axis] + (high ? ls : 0)) continue;  // a face inside the leaf
      Lat lo = vc.lat, hi{vc.lat[0] + s, vc.lat[1] + s, vc.lat[2] + s};
      lo[axis] = hi[axis] = plane;
      // Neighbours of the leaf's size: across the face, and across each of its edges vc touches.
      std::array<int, 2> shifts[2];
      int count[2] = {1, 1};
      for (int j = 0, side = 0; j < 3; ++j) {
        if (j == axis) continue;
        shifts[side] = {0, 0};
        if (lo[j] == leaf.lat[j]) shifts[side][count[side]++] = -1;
        if (hi[j] == leaf.lat[j] + ls) shifts[side][count[side]++] = 1;
        ++side;
      }
      const int i = axis == 0 ? 1 : 0, j = axis == 2 ? 1 : 2;
      for (int u = 0; u < count[0]; ++u)
        for (int v = 0; v < count[1]; ++v) {
          if (shifts[0][u] != 0 && shifts[1][v] != 0) continue;  // a corner: the leaf's own sign
          Lat across = leaf.lat;
          across[axis] += high ? ls : -ls;
          across[i] += shifts[0][u] * ls;
          across[j] += shifts[1][v] * ls;
          if (std::any_of(across.begin(), across.end(), [&](int64_t c) { return c < 0 || c >= Cell{}.span(); }))
            continue;  // outside the root cube
          const LeafRef n = node_at(t, Cell{leaf.level, across});
          if (t.nodes[n.node].kind != CellKind::Internal) continue;  // no corner finer than the leaf's
          if (!face_corners_are(t, n.node, n.cell, axis, plane, lo, hi, inside)) return false;
        }
    }
  return true;
}

}  // namespace

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
  if ((v.signs == 0 || v.signs == 0xff) && !meets_box(x.tris, v.idx, cc.box()) &&
      boundary_is(x.t, cc, s.leaf_cell, v.signs != 0)) {
    Side u;
    u.inside = v.signs != 0;
    return u;
  }
  return v;
}

}  // namespace pic::detail

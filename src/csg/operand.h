// One operand of a Boolean as the CSG sees it (paper section 5): its signs as a function of
// the lattice point (stored corner signs; inside a gray leaf, crossing parity through its
// partial contour), its partial contour, and its state over a cell of the recursion.
#pragma once

#include <algorithm>
#include <atomic>
#include <bit>
#include <optional>
#include <unordered_map>
#include <unordered_set>

#include <tbb/parallel_for.h>

#include "geometry/bvh.h"
#include "geometry/stopwatch.h"
#include "geometry/key_bits.h"
#include "geometry/tolerances.h"
#include "octree/dual_walk.h"
#include "csg/cleanup.h"
#include "octree/subdivide.h"
#include "signs/consistency.h"

namespace pic::detail {

using Lat = std::array<int64_t, 3>;


inline bool apply(CsgOp op, bool a, bool b) {
  switch (op) {
    case CsgOp::Union: return a || b;
    case CsgOp::Intersect: return a && b;
    case CsgOp::Subtract: return a && !b;
  }
  return false;
}
inline uint8_t apply_mask(CsgOp op, uint8_t a, uint8_t b) {
  switch (op) {
    case CsgOp::Union: return a | b;
    case CsgOp::Intersect: return a & b;
    case CsgOp::Subtract: return a & uint8_t(~b);
  }
  return 0;
}

/// An operand's partial contour (grid units), indexed for box queries. Read-only once built,
/// shared by all the tasks of an operation.
struct PartialContour {
  std::vector<ITri> tris;
  /// Per triangle: one of its polygon's leaves was accepted at the depth cap, so the triangle
  /// may lie up to a cell off the solid (its vertex fits no plane there).
  std::vector<uint8_t> rough;
  TriangleBvh bvh;
};

/// One operand as seen by one task of an operation: its tree, its partial contour, and the
/// task's caches (sign memo, triangles and anchor corner per leaf).
struct Operand {
  const Octree& t;
  const PartialContour& pc;
  const std::vector<ITri>& tris;
  const TriangleBvh& bvh;
  std::unordered_map<uint32_t, std::vector<uint32_t>> leaf_tris;  // gray leaf -> triangles in it
  KeyBits memo;                                                   // signs of non-corner points
  std::unordered_map<uint32_t, int> anchors;                      // gray leaf -> anchor corner

  const Stamps& stamps;  // per node of t: the operation's stamp where it stamped it
  uint32_t stamp = 0;

  /// A second pass over a few cells of a result (combine.h) must give each lattice point on
  /// such a cell's boundary that a leaf of the rest of the result has as a corner (`held`) the
  /// sign the first pass gave it: a parity walk depends on the partial contour, and the focus
  /// of the second pass stamps more cells and grows it. Those points are asked of `outer`, the
  /// operand as the first pass saw it; `inner` is the cell being recombined.
  Operand* outer = nullptr;
  const KeyBits* held = nullptr;
  Cell inner;

  Operand(const Octree& tree, const Stamps& tree_stamps, const PartialContour& contour, uint32_t op_stamp)
      : t(tree), pc(contour), tris(contour.tris), bvh(contour.bvh), stamps(tree_stamps), stamp(op_stamp) {}

  /// The corner of a gray leaf farthest from its contour triangles. A corner within the
  /// contour's error of the surface may sit on the wrong side of it; starting the parity walk
  /// from the farthest corner keeps fresh signs consistent with the contour everywhere except
  /// right next to such corners (cached per leaf).
  int anchor_corner(uint32_t leaf, const Cell& cell) {
    if (const auto it = anchors.find(leaf); it != anchors.end()) return it->second;
    const auto& idx = triangles_in(leaf, cell);
    int best = 0;
    double best_d = -1;
    for (int c = 0; c < 8; ++c) {
      const Vec3 p = to_unit(lattice_to_grid(cell.corner(c)));
      double d = kHuge;
      for (uint32_t k : idx) {
        d = std::min(d, point_triangle_distance2(p, tris[k]));
        if (d <= best_d) break;  // no farther than the best corner so far: cannot replace it
      }
      if (d > best_d) {
        best_d = d;
        best = c;
      }
    }
    anchors.emplace(leaf, best);
    return best;
  }

  /// Partial-contour triangles meeting a leaf's cell (cached per leaf).
  const std::vector<uint32_t>& triangles_in(uint32_t leaf, const Cell& cell) {
    auto [it, fresh] = leaf_tris.try_emplace(leaf);
    if (fresh) {
      const IBox b = cell.box();
      bvh.query(tris, b.lo, b.hi, it->second);
      std::sort(it->second.begin(), it->second.end());  // deterministic order
    }
    return it->second;
  }

  struct Hit {
    int state = 0;  // 0 none, 1 corner/uniform (sign known), 2 inside a gray leaf
    bool sign = false;
    uint32_t leaf = 0;
    Cell cell;
  };

  Hit find(uint32_t node, const Cell& cell, const Lat& p) const {
    const Node& n = t.nodes[node];
    const int k = cell.corner_index(p);
    if (k >= 0) {
      if (n.kind == CellKind::Internal) return find(n.index + k, cell.child(k), p);
      const bool s = n.kind == CellKind::Gray ? ((n.signs >> k) & 1) : n.kind == CellKind::Black;
      return {1, s, node, cell};
    }
    if (n.kind == CellKind::White || n.kind == CellKind::Black) return {1, n.kind == CellKind::Black, node, cell};
    if (n.kind == CellKind::Gray) return {2, false, node, cell};
    // On a face shared by several gray leaves, prefer one stamped by this operation: only
    // stamped leaves have their whole partial contour, which the parity walk needs. The
    // children holding p: along each axis the low one, the high one, or both when p lies on
    // the plane between them (visited in child order).
    const int64_t half = cell.span() / 2;
    int need = 0, open = 0;  // bits of the child index p fixes, and those it leaves open
    for (int a = 0; a < 3; ++a) {
      const int64_t mid = cell.lat[a] + half;
      if (p[a] > mid) need |= 1 << a;
      else if (p[a] == mid) open |= 1 << a;
    }
    Hit gray;
    for (int c = 0; c < 8; ++c) {
      if ((c & ~open) != need) continue;
      const Cell cc = cell.child(c);
      const Hit h = find(n.index + c, cc, p);
      if (h.state == 1) return h;
      if (h.state == 2 && (gray.state == 0 || (stamps[gray.leaf] != stamp && stamps[h.leaf] == stamp)))
        gray = h;
    }
    return gray;
  }

  /// sign_X(p): single-valued by construction (a pure function of the tree and p).
  bool sign(const Lat& p) {
    // Every lattice point is asked for by up to 8 cells: remember all answers, not only the
    // ones that needed a parity walk.
    if (held_outside(p)) return outer->sign(p);
    const uint64_t key = lattice_key(p);
    if (const int m = memo.find(key); m >= 0) return m;
    const Hit h = find(0, Cell{}, p);
    if (h.state != 2) {
      memo.insert(key, h.sign);
      return h.sign;
    }
    return classify(p, h.leaf, h.cell);
  }

  /// sign_X(p) for p known to lie in the closed cell of gray leaf `leaf`: a point strictly
  /// inside it needs no search from the root.
  bool sign_in(const Lat& p, uint32_t leaf, const Cell& cell) {
    if (!strictly_inside(cell, p)) return sign(p);
    if (held_outside(p)) return outer->sign_in(p, leaf, cell);
    if (const int m = memo.find(lattice_key(p)); m >= 0) return m;
    return classify(p, leaf, cell);
  }

  /// Parity walk for p in gray leaf `leaf` (callers have checked the memo).
  bool classify(const Lat& p, uint32_t leaf, const Cell& cell) {
    const uint64_t key = lattice_key(p);
    // Crossing parity along x, then y, then z from the leaf's most reliable corner. A cell's
    // grid asks one leaf many times in a row: its triangles and anchor are kept at hand.
    const Node& n = t.nodes[leaf];
    if (leaf != last_leaf_) {
      last_tris_ = &triangles_in(leaf, cell);
      last_anchor_ = anchor_corner(leaf, cell);
      last_leaf_ = leaf;
    }
    const auto& idx = *last_tris_;
    const int c = last_anchor_;
    bool s = (n.signs >> c) & 1;
    I3 a = lattice_to_grid(cell.corner(c));
    const I3 g = lattice_to_grid(p);
    for (int axis = 0; axis < 3; ++axis) {
      const i64 len = g[axis] - a[axis];
      if (len > 0) s ^= count_crossings(tris, idx, a, axis, len) & 1;
      if (len < 0) {
        I3 b = a;
        b[axis] = g[axis];
        s ^= count_crossings(tris, idx, b, axis, -len) & 1;
      }
      a[axis] = g[axis];
    }
    memo.insert(key, s);
    return s;
  }

 private:
  bool held_outside(const Lat& p) const {
    return outer && !strictly_inside(inner, p) && held->find(lattice_key(p)) >= 0;
  }
  static bool strictly_inside(const Cell& cell, const Lat& p) {
    const int64_t s = cell.span();
    for (int k = 0; k < 3; ++k)
      if (p[k] <= cell.lat[k] || p[k] >= cell.lat[k] + s) return false;
    return true;
  }

  uint32_t last_leaf_ = ~uint32_t{0};  // the leaf classify asked last, its triangles and anchor
  const std::vector<uint32_t>* last_tris_ = nullptr;
  int last_anchor_ = 0;
};

/// Sampler source over an operand's partial contour (forced subdivision, paper 5.2.3).
class FanSource : public SurfaceSource {
 public:
  explicit FanSource(Operand& x) : x_(x) { tris_ = &x.tris; }
  void child_grid_signs(const Cell& cell, const std::vector<uint32_t>&, std::array<bool, 27>& g,
                        Wind27*) const override {
    const int64_t h = cell.span() / 2;
    for (int i = 0; i < 27; ++i) {
      const int a = i % 3, b = (i / 3) % 3, c = i / 9;
      if (a != 1 && b != 1 && c != 1) continue;  // parent corner, known
      g[i] = x_.sign({cell.lat[0] + a * h, cell.lat[1] + b * h, cell.lat[2] + c * h});
    }
  }

 private:
  Operand& x_;
};

/// An operand's state over the current cell.
struct Side {
  enum Kind { Uniform, Internal, Gray } kind = Uniform;
  bool inside = false;  // Uniform
  uint32_t node = 0;    // Internal: the node; Gray: the leaf
  bool real = false;    // Gray: the cell is the leaf's own cell
  uint8_t signs = 0;    // Gray: signs at this cell's corners
  std::vector<uint32_t> idx;  // Gray: partial-contour triangles overlapping this cell
  Cell leaf_cell;             // Gray: the cell of the leaf `node`
};

/// The operand over `node` (cell `cell`): a uniform or internal node, or a gray leaf.
Side side_of(Operand& x, uint32_t node, const Cell& cell);
/// The operand's signs on the 27-point child grid of a gray side's cell (index x + 3y + 9z in
/// half cells): asked once per cell, not by each of its eight children (every sign that is
/// not a stored corner is a lookup in a large memo, and those lookups miss the cache).
using SignGrid = std::array<bool, 27>;
SignGrid sign_grid(Operand& x, const Side& s, const Cell& cell);
/// The operand over child `c` of `cell`: a child node, or a virtual cell inside a gray leaf
/// (its corner signs from `grid`, sign_grid of s over cell; read only when s is gray).
Side child_side(Operand& x, const Side& s, const Cell& cell, int c, const SignGrid& grid);
/// A virtual cell with no sign change that still holds surface: it must be refined until the
/// surface shows in the signs.
inline bool unresolved(const Side& s) { return !s.real && (s.signs == 0 || s.signs == 0xff); }

}  // namespace pic::detail

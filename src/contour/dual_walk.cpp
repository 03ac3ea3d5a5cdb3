#include "contour/dual_walk.h"
#include "geometry/predicates.h"
#include "geometry/vec3.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <type_traits>
#include <unordered_map>

namespace pic::detail {
namespace {

// What the walk carries for a node: the node and its cell (the whole contour needs the
// minimal edge's corners for the intersection-free triangulation).
struct CellRef {
  uint32_t node;
  Cell cell;
};
inline int level_of(const CellRef& r) { return r.cell.level; }
inline CellRef child_ref(const CellRef& r, uint32_t first, int c) { return {first + uint32_t(c), r.cell.child(c)}; }

/// The recursion of Ju et al. over node references. `V` supplies `active(node)` (is the node
/// part of the walked region), `kCracks` (report sign changes next to non-gray leaves instead
/// of skipping uniform leaves), `crack(...)` and `polygon(refs, count)`.
template <class Ref, class V>
class DualWalker {
 public:
  DualWalker(const Octree& t, V& v) : nodes_(t.nodes.data()), v_(v) {}

  bool leaf(const Ref& r) const { return nodes_[r.node].kind != CellKind::Internal; }
  // Every lattice point in a white or black leaf's closure has its colour, so no edge on a
  // face or edge it touches changes sign: the walk can skip it. Not when looking for cracks
  // (a violated invariant), which is exactly such an edge.
  bool skip(const Ref& r) const {
    if constexpr (V::kCracks) return false;
    const CellKind k = nodes_[r.node].kind;
    return k == CellKind::White || k == CellKind::Black;
  }
  bool on(const Ref& r) const { return v_.active(r.node); }
  Ref sub(const Ref& r, int c) const {
    const Node& n = nodes_[r.node];
    if (n.kind != CellKind::Internal) return r;
    return child_ref(r, n.index, c);
  }

  void cell_proc(const Ref& r) {
    if (leaf(r) || !on(r)) return;
    for (int c = 0; c < 8; ++c) cell_proc(sub(r, c));
    root_faces_and_edges(r);
  }

  /// The faces and edges inside an internal cell, between its children.
  void root_faces_and_edges(const Ref& r) {
    std::array<Ref, 8> ch;
    for (int c = 0; c < 8; ++c) ch[c] = sub(r, c);
    faces_and_edges_along<0>(ch);
    faces_and_edges_along<1>(ch);
    faces_and_edges_along<2>(ch);
  }

 private:
  // The axis is a template parameter: every child index below is then a constant.
  template <int D>
  void faces_and_edges_along(const std::array<Ref, 8>& ch) {
    for (int c = 0; c < 8; ++c)
      if (!((c >> D) & 1)) face_proc<D>(ch[c], ch[c | (1 << D)]);
    constexpr int p = D == 0 ? 1 : 0, q = D == 2 ? 1 : 2;
    for (int b = 0; b < 2; ++b) {
      std::array<Ref, 4> e;
      for (int k = 0; k < 4; ++k) e[k] = ch[((k & 1) << p) | ((k >> 1) << q) | (b << D)];
      edge_proc<D>(e);
    }
  }

  // The checks that end most calls are inlined into the caller; the recursion is not.
  template <int D>
  void face_proc(const Ref& lo, const Ref& hi) {
    if ((leaf(lo) && leaf(hi)) || skip(lo) || skip(hi)) return;
    if (!on(lo) && !on(hi)) return;
    face_body<D>(lo, hi);
  }
  template <int D>
  [[gnu::noinline]] void face_body(const Ref& lo, const Ref& hi) {
    constexpr int i = D == 0 ? 1 : 0, j = D == 2 ? 1 : 2;
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b) face_proc<D>(sub(lo, (1 << D) | (a << i) | (b << j)), sub(hi, (a << i) | (b << j)));
    face_edges<D, i, j>(lo, hi);
    face_edges<D, j, i>(lo, hi);
  }
  /// The two edges along axis E inside the face (normal D) between lo and hi; F is the other
  /// in-face axis.
  template <int D, int E, int F>
  void face_edges(const Ref& lo, const Ref& hi) {
    constexpr int p = E == 0 ? 1 : 0;  // first axis across the edge; the second is the other one
    for (int b = 0; b < 2; ++b) {
      std::array<Ref, 4> cells;
      for (int k = 0; k < 4; ++k) {
        const int bp = k & 1, bq = k >> 1;
        const int bd = p == D ? bp : bq, bf = p == F ? bp : bq;
        const Ref& parent = bd ? hi : lo;
        cells[k] = sub(parent, ((1 - bd) << D) | (bf << F) | (b << E));
      }
      edge_proc<E>(cells);
    }
  }

  template <int E>
  void edge_proc(const std::array<Ref, 4>& n) {
    if (!on(n[0]) && !on(n[1]) && !on(n[2]) && !on(n[3])) return;
    if (skip(n[0]) || skip(n[1]) || skip(n[2]) || skip(n[3])) return;
    if (leaf(n[0]) && leaf(n[1]) && leaf(n[2]) && leaf(n[3])) {
      process_edge(n, E);
      return;
    }
    edge_body<E>(n);
  }
  template <int E>
  [[gnu::noinline]] void edge_body(const std::array<Ref, 4>& n) {
    constexpr int p = E == 0 ? 1 : 0, q = E == 2 ? 1 : 2;
    for (int b = 0; b < 2; ++b) {
      std::array<Ref, 4> c;
      for (int k = 0; k < 4; ++k) c[k] = sub(n[k], ((1 - (k & 1)) << p) | ((1 - (k >> 1)) << q) | (b << E));
      edge_proc<E>(c);
    }
  }

  void process_edge(const std::array<Ref, 4>& n, int e) {
    int deepest = 0;
    for (int k = 1; k < 4; ++k)
      if (level_of(n[k]) > level_of(n[deepest])) deepest = k;
    const int p = e == 0 ? 1 : 0, q = e == 2 ? 1 : 2;
    const int c0 = ((1 - (deepest & 1)) << p) | ((1 - (deepest >> 1)) << q);
    const int c1 = c0 | (1 << e);
    const Node& dn = nodes_[n[deepest].node];
    bool s0, s1;
    if (dn.kind == CellKind::Gray) {
      s0 = (dn.signs >> c0) & 1;
      s1 = (dn.signs >> c1) & 1;
    } else {
      s0 = s1 = dn.kind == CellKind::Black;
    }
    if (s0 == s1) return;
    if constexpr (V::kCracks) {
      for (int k = 0; k < 4; ++k)
        if (nodes_[n[k].node].kind != CellKind::Gray) {
          v_.crack(n[k], n[deepest], c0, c1);
          return;
        }
    }
    // Cyclic order around the edge: (0,0) (1,0) (1,1) (0,1); counter-clockwise seen from +e
    // when (p, q, e) is right-handed, which fails only for e = y.
    static constexpr int kCycle[4] = {0, 1, 3, 2};
    const bool ccw_from_plus = e != 1;
    const bool outward_plus = s0;  // the low end is inside: the surface faces +e
    const bool reverse = ccw_from_plus != outward_plus;
    std::array<Ref, 4> poly;
    int count = 0;
    for (int m = 0; m < 4; ++m) {
      const Ref& r = n[kCycle[reverse ? 3 - m : m]];
      if (count > 0 && poly[count - 1].node == r.node) continue;
      poly[count++] = r;
    }
    if (count > 1 && poly[count - 1].node == poly[0].node) --count;
    if (count >= 3) v_.polygon(poly, count, n[deepest], c0, c1);
  }

 private:
  const Node* nodes_;
  V& v_;
};

/// dual_walk's visitor: the optional `active` filter, polygons with positions, cracks.
template <bool Cracks>
struct CallbackVisitor {
  static constexpr bool kCracks = Cracks;
  const Octree& t;
  const std::function<bool(uint32_t)>* filter;
  const std::function<void(const DualPolygon&)>& emit;
  DualStats* stats;

  bool active(uint32_t node) const { return !filter || (*filter)(node); }
  void crack(const CellRef& leaf, const CellRef& deepest, int c0, int c1) {
    stats->crack_leaves.push_back(leaf.node);
    stats->crack_cells.push_back(leaf.cell);
    const auto a = deepest.cell.corner(c0), b = deepest.cell.corner(c1);
    stats->crack_points.push_back({a[0] + b[0], a[1] + b[1], a[2] + b[2]});
  }
  void polygon(const std::array<CellRef, 4>& refs, int count, const CellRef&, int, int) {
    DualPolygon poly{};
    poly.count = count;
    for (int k = 0; k < count; ++k) {
      poly.leaf[k] = refs[k].node;
      poly.pos[k] = vertex_unit(refs[k].cell, t.vertices[t.nodes[refs[k].node].index]);
    }
    emit(poly);
  }
};


/// Whole-contour visitor: records each dual polygon (tree vertex indices) with its minimal
/// edge; triangulated afterwards (src/contour.cpp contour()).
struct MeshVisitor {
  static constexpr bool kCracks = false;
  const Node* nodes;
  const Cube& cube;
  std::vector<MeshPolygon>& polys;

  static bool active(uint32_t) { return true; }
  void polygon(const std::array<CellRef, 4>& r, int count, const CellRef& deepest, int c0, int c1) {
    MeshPolygon m;
    m.count = count;
    for (int k = 0; k < count; ++k) m.v[k] = nodes[r[k].node].index;
    const auto corner = [&](int c) {
      const auto l = deepest.cell.corner(c);
      constexpr double k = 1.0 / double(int64_t{1} << kMaxLevel);
      return unit_to_world(cube, Vec3{double(l[0]) * k, double(l[1]) * k, double(l[2]) * k});
    };
    m.e0 = corner(c0);
    m.e1 = corner(c1);
    polys.push_back(m);
  }
};

}  // namespace

void dual_walk(const Octree& t, const std::function<bool(uint32_t)>* active,
               const std::function<void(const DualPolygon&)>& emit, DualStats* stats) {
  // A leaf root, or an inactive one, has no dual polygons.
  if (t.nodes[0].kind != CellKind::Internal || (active && !(*active)(0))) return;
  // The 9 tasks of dual_polygons, each into its own lists, then emitted in that fixed order:
  // the same polygons and cracks, in the same order, as one walk.
  std::array<std::vector<DualPolygon>, 9> polys;
  std::array<DualStats, 9> parts;
  tbb::parallel_for(0, 9, [&](int task) {
    const std::function<void(const DualPolygon&)> keep = [&](const DualPolygon& p) { polys[task].push_back(p); };
    const auto walk = [&](auto& v) {
      DualWalker<CellRef, std::remove_reference_t<decltype(v)>> w(t, v);
      if (task < 8) w.cell_proc({t.nodes[0].index + uint32_t(task), Cell{}.child(task)});
      else w.root_faces_and_edges({0, Cell{}});
    };
    if (stats) {
      CallbackVisitor<true> v{t, active, keep, &parts[task]};
      walk(v);
    } else {
      CallbackVisitor<false> v{t, active, keep, nullptr};
      walk(v);
    }
  });
  for (int task = 0; task < 9; ++task) {
    for (const DualPolygon& p : polys[task]) emit(p);
    if (!stats) continue;
    const DualStats& d = parts[task];
    stats->crack_leaves.insert(stats->crack_leaves.end(), d.crack_leaves.begin(), d.crack_leaves.end());
    stats->crack_cells.insert(stats->crack_cells.end(), d.crack_cells.begin(), d.crack_cells.end());
    stats->crack_points.insert(stats->crack_points.end(), d.crack_points.begin(), d.crack_points.end());
  }
}

std::vector<MeshPolygon> dual_polygons(const Octree& tree) {
  const bool split = tree.nodes[0].kind == CellKind::Internal;
  // Polygons found by 9 tasks — the 8 root children and the faces and edges between them —
  // each into its own list; concatenated in that fixed order they are exactly what a serial
  // walk finds.
  std::array<std::vector<MeshPolygon>, 9> parts;
  tbb::parallel_for(0, split ? 9 : 1, [&](int task) {
    MeshVisitor v{tree.nodes.data(), tree.cube, parts[task]};
    DualWalker<CellRef, MeshVisitor> w(tree, v);
    if (!split) w.cell_proc({0, Cell{}});
    else if (task < 8) w.cell_proc({tree.nodes[0].index + uint32_t(task), Cell{}.child(task)});
    else w.root_faces_and_edges({0, Cell{}});
  });
  std::vector<MeshPolygon> polys;
  size_t total = 0;
  for (const auto& part : parts) total += part.size();
  polys.reserve(total);
  for (auto& part : parts) {
    polys.insert(polys.end(), part.begin(), part.end());
    std::vector<MeshPolygon>().swap(part);
  }
  return polys;
}

}  // namespace pic::detail

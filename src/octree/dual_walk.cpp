#include "octree/dual_walk.h"
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

/// dual_walk's visitor: the optional `active` filter; polygons with positions, or (Cracks)
/// cracks only.
template <bool Cracks>
struct CallbackVisitor {
  static constexpr bool kCracks = Cracks;
  const Octree& t;
  const std::function<bool(uint32_t)>* filter;
  std::vector<DualPolygon>* polys;
  DualStats* stats;

  bool active(uint32_t node) const { return !filter || (*filter)(node); }
  void crack(const CellRef& leaf, const CellRef& deepest, int c0, int c1) {
    stats->crack_leaves.push_back(leaf.node);
    stats->crack_cells.push_back(leaf.cell);
    const auto a = deepest.cell.corner(c0), b = deepest.cell.corner(c1);
    stats->crack_points.push_back({a[0] + b[0], a[1] + b[1], a[2] + b[2]});
  }
  void polygon(const std::array<CellRef, 4>& refs, int count, const CellRef&, int, int) {
    if constexpr (Cracks) return;
    DualPolygon poly{};
    poly.count = count;
    for (int k = 0; k < count; ++k) {
      poly.leaf[k] = refs[k].node;
      poly.pos[k] = vertex_unit(refs[k].cell, t.vertices[t.nodes[refs[k].node].index]);
    }
    polys->push_back(poly);
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

/// The dual walk in 9 parallel tasks (the 8 root children, then the faces and edges between
/// them), each with its own visitor from make(task): each task's findings, concatenated in
/// task order, are what one serial walk finds, in its order. A leaf root has no dual edges.
template <class MakeVisitor>
void in_nine_tasks(const Octree& t, MakeVisitor&& make) {
  if (t.nodes[0].kind != CellKind::Internal) return;
  tbb::parallel_for(0, 9, [&](int task) {
    auto v = make(task);
    DualWalker<CellRef, decltype(v)> w(t, v);
    if (task < 8) w.cell_proc({t.nodes[0].index + uint32_t(task), Cell{}.child(task)});
    else w.root_faces_and_edges({0, Cell{}});
  });
}

}  // namespace

void dual_walk(const Octree& t, const std::function<bool(uint32_t)>* active,
               const std::function<void(const DualPolygon&)>& emit) {
  if (active && !(*active)(0)) return;  // nothing active: no partial contour
  // Each task into its own list, then emitted in the tasks' order: the same polygons in the
  // same order as one walk.
  std::array<std::vector<DualPolygon>, 9> polys;
  in_nine_tasks(t, [&](int task) { return CallbackVisitor<false>{t, active, &polys[size_t(task)], nullptr}; });
  for (const auto& list : polys)
    for (const DualPolygon& p : list) emit(p);
}

DualStats crack_edges(const Octree& t, const std::function<bool(uint32_t)>* active) {
  DualStats all;
  if (active && !(*active)(0)) return all;  // nothing active: nothing to repair
  std::array<DualStats, 9> parts;
  in_nine_tasks(t, [&](int task) { return CallbackVisitor<true>{t, active, nullptr, &parts[size_t(task)]}; });
  for (const DualStats& d : parts) {
    all.crack_leaves.insert(all.crack_leaves.end(), d.crack_leaves.begin(), d.crack_leaves.end());
    all.crack_cells.insert(all.crack_cells.end(), d.crack_cells.begin(), d.crack_cells.end());
    all.crack_points.insert(all.crack_points.end(), d.crack_points.begin(), d.crack_points.end());
  }
  return all;
}

std::vector<MeshPolygon> dual_polygons(const Octree& tree) {
  std::array<std::vector<MeshPolygon>, 9> parts;
  in_nine_tasks(tree, [&](int task) { return MeshVisitor{tree.nodes.data(), tree.cube, parts[size_t(task)]}; });
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

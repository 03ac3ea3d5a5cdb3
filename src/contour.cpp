#include "contour.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace pic::detail {
namespace {

struct Ref {
  uint32_t node;
  Cell cell;
};

class DualWalker {
 public:
  DualWalker(const Octree& t, const std::function<bool(uint32_t)>* active,
             const std::function<void(const DualPolygon&)>& emit, DualStats* stats)
      : t_(t), active_(active), emit_(emit), stats_(stats) {}

  bool leaf(const Ref& r) const { return t_.nodes[r.node].kind != CellKind::Internal; }
  // Every lattice point in a white or black leaf's closure has its colour, so no edge on a
  // face or edge it touches changes sign: the walk can skip it. Not when looking for cracks
  // (a violated invariant), which is exactly such an edge.
  bool skip(const Ref& r) const {
    const CellKind k = t_.nodes[r.node].kind;
    return !stats_ && (k == CellKind::White || k == CellKind::Black);
  }
  bool on(const Ref& r) const { return !active_ || (*active_)(r.node); }
  Ref sub(const Ref& r, int c) const {
    if (leaf(r)) return r;
    return {t_.nodes[r.node].index + c, r.cell.child(c)};
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
    for (int d = 0; d < 3; ++d) {
      for (int c = 0; c < 8; ++c)
        if (!((c >> d) & 1)) face_proc(ch[c], ch[c | (1 << d)], d);
      const int p = d == 0 ? 1 : 0, q = d == 2 ? 1 : 2;
      for (int b = 0; b < 2; ++b) {
        std::array<Ref, 4> e;
        for (int k = 0; k < 4; ++k) e[k] = ch[((k & 1) << p) | ((k >> 1) << q) | (b << d)];
        edge_proc(e, d);
      }
    }
  }

  void face_proc(const Ref& lo, const Ref& hi, int d) {
    if ((leaf(lo) && leaf(hi)) || skip(lo) || skip(hi)) return;
    if (!on(lo) && !on(hi)) return;
    const int i = d == 0 ? 1 : 0, j = d == 2 ? 1 : 2;
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b)
        face_proc(sub(lo, (1 << d) | (a << i) | (b << j)), sub(hi, (a << i) | (b << j)), d);
    for (int e : {i, j}) {
      const int f = e == i ? j : i;  // the other in-face axis
      const int p = e == 0 ? 1 : 0;  // first axis across the edge; the second is the other one
      for (int b = 0; b < 2; ++b) {
        std::array<Ref, 4> cells;
        for (int k = 0; k < 4; ++k) {
          const int bp = k & 1, bq = k >> 1;
          const int bd = p == d ? bp : bq, bf = p == f ? bp : bq;
          const Ref& parent = bd ? hi : lo;
          cells[k] = sub(parent, ((1 - bd) << d) | (bf << f) | (b << e));
        }
        edge_proc(cells, e);
      }
    }
  }

  void edge_proc(const std::array<Ref, 4>& n, int e) {
    if (active_ && !on(n[0]) && !on(n[1]) && !on(n[2]) && !on(n[3])) return;
    if (skip(n[0]) || skip(n[1]) || skip(n[2]) || skip(n[3])) return;
    if (leaf(n[0]) && leaf(n[1]) && leaf(n[2]) && leaf(n[3])) {
      process_edge(n, e);
      return;
    }
    const int p = e == 0 ? 1 : 0, q = e == 2 ? 1 : 2;
    for (int b = 0; b < 2; ++b) {
      std::array<Ref, 4> c;
      for (int k = 0; k < 4; ++k)
        c[k] = sub(n[k], ((1 - (k & 1)) << p) | ((1 - (k >> 1)) << q) | (b << e));
      edge_proc(c, e);
    }
  }

  void process_edge(const std::array<Ref, 4>& n, int e) {
    int deepest = 0;
    for (int k = 1; k < 4; ++k)
      if (n[k].cell.level > n[deepest].cell.level) deepest = k;
    const int p = e == 0 ? 1 : 0, q = e == 2 ? 1 : 2;
    const int c0 = ((1 - (deepest & 1)) << p) | ((1 - (deepest >> 1)) << q);
    const int c1 = c0 | (1 << e);
    const Node& dn = t_.nodes[n[deepest].node];
    bool s0, s1;
    if (dn.kind == CellKind::Gray) {
      s0 = (dn.signs >> c0) & 1;
      s1 = (dn.signs >> c1) & 1;
    } else {
      s0 = s1 = dn.kind == CellKind::Black;
    }
    if (s0 == s1) return;
    for (int k = 0; k < 4; ++k) {
      if (t_.nodes[n[k].node].kind != CellKind::Gray) {
        if (stats_) {
          stats_->crack_leaves.push_back(n[k].node);
          stats_->crack_cells.push_back(n[k].cell);
          const auto a = n[deepest].cell.corner(c0), b = n[deepest].cell.corner(c1);
          stats_->crack_points.push_back({a[0] + b[0], a[1] + b[1], a[2] + b[2]});
        }
        return;
      }
    }
    // Cyclic order around the edge: (0,0) (1,0) (1,1) (0,1); counter-clockwise seen from +e
    // when (p, q, e) is right-handed, which fails only for e = y.
    static constexpr int kCycle[4] = {0, 1, 3, 2};
    const bool ccw_from_plus = e != 1;
    const bool outward_plus = s0;  // the low end is inside: the surface faces +e
    const bool reverse = ccw_from_plus != outward_plus;
    DualPolygon poly{};
    poly.count = 0;
    for (int m = 0; m < 4; ++m) {
      const Ref& r = n[kCycle[reverse ? 3 - m : m]];
      if (poly.count > 0 && poly.leaf[poly.count - 1] == r.node) continue;
      poly.leaf[poly.count] = r.node;
      poly.pos[poly.count] = vertex_unit(r.cell, t_.vertices[t_.nodes[r.node].index]);
      ++poly.count;
    }
    if (poly.count > 1 && poly.leaf[poly.count - 1] == poly.leaf[0]) --poly.count;
    if (poly.count >= 3) emit_(poly);
  }

 private:
  const Octree& t_;
  const std::function<bool(uint32_t)>* active_;
  const std::function<void(const DualPolygon&)>& emit_;
  DualStats* stats_;
};

Vec3 tri_normal(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 u{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  Vec3 n{u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
  const double l = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  if (l > 0) n = {n[0] / l, n[1] / l, n[2] / l};
  return n;
}

}  // namespace

void dual_walk(const Octree& t, const std::function<bool(uint32_t)>* active,
               const std::function<void(const DualPolygon&)>& emit, DualStats* stats) {
  DualWalker w(t, active, emit, stats);
  w.cell_proc({0, Cell{}});
}

std::array<std::array<int, 3>, 2> split_quad(const std::array<Vec3, 4>& p) {
  const Vec3 a0 = tri_normal(p[0], p[1], p[2]), a1 = tri_normal(p[0], p[2], p[3]);
  const Vec3 b0 = tri_normal(p[0], p[1], p[3]), b1 = tri_normal(p[1], p[2], p[3]);
  auto dot = [](const Vec3& x, const Vec3& y) { return x[0] * y[0] + x[1] * y[1] + x[2] * y[2]; };
  // The quad's own orientation: cross product of its diagonals (twice its vector area).
  const Vec3 d0{p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
  const Vec3 d1{p[3][0] - p[1][0], p[3][1] - p[1][1], p[3][2] - p[1][2]};
  const Vec3 n{d0[1] * d1[2] - d0[2] * d1[1], d0[2] * d1[0] - d0[0] * d1[2], d0[0] * d1[1] - d0[1] * d1[0]};
  // A split whose triangle faces against the quad folds it back on itself (a non-convex
  // quad split along its outer diagonal): never take it when the other split is clean.
  const bool a_ok = dot(a0, n) > 0 && dot(a1, n) > 0, b_ok = dot(b0, n) > 0 && dot(b1, n) > 0;
  bool use_a;
  if (a_ok != b_ok) {
    use_a = a_ok;
  } else if (!a_ok) {
    use_a = std::min(dot(a0, n), dot(a1, n)) >= std::min(dot(b0, n), dot(b1, n));
  } else {
    // Both clean: fold along the diagonal that bends most, which keeps a crease whose two
    // vertices lie on it.
    use_a = dot(a0, a1) <= dot(b0, b1);
  }
  if (use_a) return {{{0, 1, 2}, {0, 2, 3}}};
  return {{{0, 1, 3}, {1, 2, 3}}};
}

}  // namespace pic::detail

namespace pic {

TriMesh contour(const Octree& tree) {
  using namespace detail;
  // Triangles as triples of the tree's vertex indices, made by 9 tasks — the 8 root children
  // and the faces and edges between them — each into its own list; concatenated in that fixed
  // order they are exactly what a serial walk makes.
  using Tri = std::array<uint32_t, 3>;
  struct Part {
    std::vector<Tri> tris;
    std::vector<uint32_t> order;  // polygon vertices in walk order: output numbering
    std::vector<Vec3> pos;        // and their positions (unit cube)
  };
  auto triangulate = [&](const DualPolygon& poly, Part& part) {
    std::array<uint32_t, 4> v{};
    for (int k = 0; k < poly.count; ++k) {
      part.order.push_back(v[k] = tree.nodes[poly.leaf[k]].index);
      part.pos.push_back(poly.pos[k]);
    }
    std::vector<Tri>& out = part.tris;
    if (poly.count == 3) {
      out.push_back({v[0], v[1], v[2]});
      return;
    }
    for (const auto& tri : split_quad({poly.pos[0], poly.pos[1], poly.pos[2], poly.pos[3]}))
      out.push_back({v[tri[0]], v[tri[1]], v[tri[2]]});
  };
  std::array<Part, 9> parts;
  const bool split = tree.nodes[0].kind == CellKind::Internal;
  tbb::parallel_for(0, split ? 9 : 1, [&](int task) {
    std::function<void(const DualPolygon&)> keep = [&](const DualPolygon& p) { triangulate(p, parts[task]); };
    DualWalker w(tree, nullptr, keep, nullptr);
    if (!split) w.cell_proc({0, Cell{}});
    else if (task < 8) w.cell_proc({tree.nodes[0].index + uint32_t(task), Cell{}.child(task)});
    else w.root_faces_and_edges({0, Cell{}});
  });
  // Numbered by first appearance in the polygons, so the numbering does not depend on how
  // quads were split.
  TriMesh out;
  std::vector<uint32_t> remap(tree.vertices.size(), UINT32_MAX);
  size_t total = 0;
  for (const auto& part : parts) {
    total += part.tris.size();
    for (size_t i = 0; i < part.order.size(); ++i)
      if (remap[part.order[i]] == UINT32_MAX) {
        remap[part.order[i]] = static_cast<uint32_t>(out.positions.size());
        out.positions.push_back(unit_to_world(tree.cube, part.pos[i]));
      }
  }
  out.triangles.reserve(total);
  for (const auto& part : parts)
    for (const Tri& t : part.tris) out.triangles.push_back({remap[t[0]], remap[t[1]], remap[t[2]]});
  return out;
}

}  // namespace pic

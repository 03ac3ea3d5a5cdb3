// CSG on two PIC octrees (paper section 5), computed in place on A.
//
// Stages, each a function or class below:
//   tag / stamp_under_surface   stamp the overlap cells with this operation's timestamp
//   partial_contour             dual-contour only around stamped cells, triangles in a BVH
//   Operand, side_of/child_side an operand's signs, triangles and state over a cell
//   Combiner                    the paired recursion: trivial cases, GraycellCSG (built from
//                               edge_verdict, surfaces_meet, feature_is_local, ...), forced
//                               subdivision (resampling a leaf's partial contour), writing
//                               through a FragmentWriter
//   cleanup.h                   sign hints, islands, one component per leaf, specks, crack
//                               repair on the stamped part of the result
//
// Topology comes from signs alone: each operand's sign is a single-valued function of the
// lattice point (stored corner signs first; inside a gray leaf, crossing parity along a fixed
// path from the leaf's most reliable corner through its partial contour), and the result's
// sign is op(sign_A, sign_B). Vertex positions only decide accuracy.
#include <algorithm>
#include <bit>
#include <atomic>
#include <chrono>
#include <optional>
#include <unordered_map>
#include <unordered_set>

#include <tbb/parallel_for.h>

#include "geometry/bvh.h"
#include "contour/dual_walk.h"
#include "csg/cleanup.h"
#include "sample/sampler.h"
#include "signs/passes.h"

namespace pic {
namespace detail {
namespace {

using Lat = std::array<int64_t, 3>;
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

std::atomic<uint32_t> g_timestamp{0};

bool apply(CsgOp op, bool a, bool b) {
  switch (op) {
    case CsgOp::Union: return a || b;
    case CsgOp::Intersect: return a && b;
    case CsgOp::Subtract: return a && !b;
  }
  return false;
}
uint8_t apply_mask(CsgOp op, uint8_t a, uint8_t b) {
  switch (op) {
    case CsgOp::Union: return a | b;
    case CsgOp::Intersect: return a & b;
    case CsgOp::Subtract: return a & uint8_t(~b);
  }
  return 0;
}

/// Lattice point -> sign, open addressing with linear probing: the sign lookups are the CSG's
/// hottest map. A key uses 63 bits (3 x 21); the sign rides in bit 63.
class SignMemo {
 public:
  /// The stored sign of `key`, or -1.
  int find(uint64_t key) const {
    if (slots_.empty()) return -1;
    for (size_t i = home(key);; i = (i + 1) & mask_) {
      const uint64_t v = slots_[i];
      if (v == kEmpty) return -1;
      if ((v & kKeyBits) == key) return int(v >> 63);
    }
  }
  void insert(uint64_t key, bool sign) {
    if (2 * (count_ + 1) > slots_.size()) grow();
    for (size_t i = home(key);; i = (i + 1) & mask_) {
      if (slots_[i] == kEmpty) {
        slots_[i] = key | uint64_t(sign) << 63;
        ++count_;
        return;
      }
      if ((slots_[i] & kKeyBits) == key) return;
    }
  }

 private:
  static constexpr uint64_t kEmpty = ~uint64_t{0};
  static constexpr uint64_t kKeyBits = ~uint64_t{0} >> 1;
  size_t home(uint64_t key) const { return size_t((key * 0x9E3779B97F4A7C15ull) >> shift_); }
  void grow() {
    std::vector<uint64_t> old = std::move(slots_);
    const size_t n = old.empty() ? 1024 : 2 * old.size();
    slots_.assign(n, kEmpty);
    mask_ = n - 1;
    shift_ = 64 - std::countr_zero(n);
    count_ = 0;
    for (uint64_t v : old)
      if (v != kEmpty) insert(v & kKeyBits, v >> 63);
  }
  std::vector<uint64_t> slots_;
  size_t mask_ = 0, count_ = 0;
  int shift_ = 64;
};

/// An operand's partial contour (grid units), indexed for box queries. Read-only once built,
/// shared by all the tasks of an operation.
struct PartialContour {
  std::vector<ITri> tris;
  TriangleBvh bvh;
  /// What the parity walks cross: `tris` and the polygons around stamped coarse leaves
  /// (around_coarse_leaves), when there are any. Only signs use them: the QEFs and the edge
  /// crossings keep to `tris`, the operation's own cells. Empty when there are none.
  std::vector<ITri> parity_tris;
  TriangleBvh parity_bvh;
  /// Whether the parity walks cross more than `tris` (parity_tris holds tris and the rest).
  bool wider() const { return !parity_tris.empty(); }
};

/// One operand as seen by one task of an operation: its tree, its partial contour, and the
/// task's caches (sign memo, triangles and anchor corner per leaf).
struct Operand {
  const Octree& t;
  const PartialContour& pc;
  const std::vector<ITri>& tris;
  const TriangleBvh& bvh;
  const std::vector<ITri>& parity_tris;
  const TriangleBvh& parity_bvh;
  std::unordered_map<uint32_t, std::vector<uint32_t>> leaf_tris;  // gray leaf -> triangles in it
  std::unordered_map<uint32_t, std::vector<uint32_t>> leaf_parity_tris;  // the same, of parity_tris
  SignMemo memo;                                                  // signs of non-corner points
  std::unordered_map<uint32_t, int> anchors;                      // gray leaf -> anchor corner

  const Stamps& stamps;  // per node of t: the operation's stamp where it stamped it
  uint32_t stamp = 0;

  Operand(const Octree& tree, const Stamps& tree_stamps, const PartialContour& contour, uint32_t op_stamp)
      : t(tree), pc(contour), tris(contour.tris), bvh(contour.bvh),
        parity_tris(contour.wider() ? contour.parity_tris : contour.tris),
        parity_bvh(contour.wider() ? contour.parity_bvh : contour.bvh), stamps(tree_stamps), stamp(op_stamp) {}

  /// The corner of a gray leaf farthest from its contour triangles. A corner within the
  /// contour's error of the surface may sit on the wrong side of it; starting the parity walk
  /// from the farthest corner keeps fresh signs consistent with the contour everywhere except
  /// right next to such corners (cached per leaf).
  int anchor_corner(uint32_t leaf, const Cell& cell) {
    if (const auto it = anchors.find(leaf); it != anchors.end()) return it->second;
    const auto& idx = parity_triangles_in(leaf, cell);
    int best = 0;
    double best_d = -1;
    for (int c = 0; c < 8; ++c) {
      const Vec3 p = to_unit(lattice_to_grid(cell.corner(c)));
      double d = 1e300;
      for (uint32_t k : idx) d = std::min(d, point_triangle_distance2(p, parity_tris[k]));
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
    return cached_query(leaf_tris, tris, bvh, leaf, cell);
  }
  /// The same for the triangles the parity walks cross.
  const std::vector<uint32_t>& parity_triangles_in(uint32_t leaf, const Cell& cell) {
    if (&parity_tris == &tris) return triangles_in(leaf, cell);
    return cached_query(leaf_parity_tris, parity_tris, parity_bvh, leaf, cell);
  }
  /// The triangles of `in` (indexed by `index`) meeting a leaf's cell, cached in `cache`.
  static const std::vector<uint32_t>& cached_query(std::unordered_map<uint32_t, std::vector<uint32_t>>& cache,
                                                   const std::vector<ITri>& in, const TriangleBvh& index,
                                                   uint32_t leaf, const Cell& cell) {
    auto [it, fresh] = cache.try_emplace(leaf);
    if (fresh) {
      const IBox b = cell.box();
      index.query(in, b.lo, b.hi, it->second);
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

  static bool contains(const Cell& c, const Lat& p) {
    const int64_t s = c.span();
    for (int k = 0; k < 3; ++k)
      if (p[k] < c.lat[k] || p[k] > c.lat[k] + s) return false;
    return true;
  }
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
    // stamped leaves have their whole partial contour, which the parity walk needs.
    Hit gray;
    for (int c = 0; c < 8; ++c) {
      const Cell cc = cell.child(c);
      if (!contains(cc, p)) continue;
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
    const int64_t s = cell.span();
    for (int k = 0; k < 3; ++k)
      if (p[k] <= cell.lat[k] || p[k] >= cell.lat[k] + s) return sign(p);
    if (const int m = memo.find(lattice_key(p)); m >= 0) return m;
    return classify(p, leaf, cell);
  }

  /// Parity walk for p in gray leaf `leaf` (callers have checked the memo).
  bool classify(const Lat& p, uint32_t leaf, const Cell& cell) {
    const Hit h{2, false, leaf, cell};
    const uint64_t key = lattice_key(p);
    // Crossing parity along x, then y, then z from the leaf's most reliable corner.
    const Node& n = t.nodes[h.leaf];
    const auto& idx = parity_triangles_in(h.leaf, h.cell);
    const int c = anchor_corner(h.leaf, h.cell);
    bool s = (n.signs >> c) & 1;
    I3 a = lattice_to_grid(h.cell.corner(c));
    const I3 g = lattice_to_grid(p);
    for (int axis = 0; axis < 3; ++axis) {
      const i64 len = g[axis] - a[axis];
      if (len > 0) s ^= count_crossings(parity_tris, idx, a, axis, len) & 1;
      if (len < 0) {
        I3 b = a;
        b[axis] = g[axis];
        s ^= count_crossings(parity_tris, idx, b, axis, -len) & 1;
      }
      a[axis] = g[axis];
    }
    memo.insert(key, s);
    return s;
  }
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

/// Levels whose cells split into parallel tasks when both operands are subdivided there.
constexpr int kParallelLevels = 4;

/// Corners i and j of a cell joined by a cube edge.
bool adjacent_corners(int i, int j) { return std::popcount(unsigned(i ^ j)) == 1; }

/// The result's signs between a finest cell's corners, from the two operands (their signs at
/// the finer lattice points half-way).
struct HalfwaySigns {
  CsgOp op;
  Operand& xa;
  Operand& xb;
  const Cell& cell;
  bool between(int i, int j) const {
    const Lat p = cell.corner(i), q = cell.corner(j);
    const Lat m{(p[0] + q[0]) / 2, (p[1] + q[1]) / 2, (p[2] + q[2]) / 2};
    return apply(op, xa.sign(m), xb.sign(m));
  }
};

/// Whether all the corners of sign `inside` are one component once the result's sign half-way
/// between two of them (a face or body diagonal) may join them.
bool joined_halfway(const HalfwaySigns& h, uint8_t sr, bool inside) {
  std::array<int, 8> comp;  // union-find over the corners
  for (int i = 0; i < 8; ++i) comp[i] = i;
  auto root = [&](int i) {
    while (comp[i] != i) i = comp[i];
    return i;
  };
  auto has = [&](int i) { return bool((sr >> i) & 1) == inside; };
  for (int i = 0; i < 8; ++i)
    for (int j = i + 1; j < 8; ++j)
      if (has(i) && has(j) && adjacent_corners(i, j)) comp[root(j)] = root(i);
  for (int i = 0; i < 8; ++i)
    for (int j = i + 1; j < 8; ++j)
      if (has(i) && has(j) && root(i) != root(j) && h.between(i, j) == inside) comp[root(j)] = root(i);
  int first = -1;
  for (int i = 0; i < 8; ++i)
    if (has(i)) {
      if (first < 0) first = i;
      if (root(i) != root(first)) return false;
    }
  return true;
}

/// The corner of the other sign whose flip to `inside` leaves the cell one component, with the
/// most of its edges' midpoints on the `inside` side; -1 when no flip does.
int corner_to_join(const HalfwaySigns& h, uint8_t sr, bool inside) {
  int best = -1, best_score = -1;
  for (int k = 0; k < 8; ++k) {
    if (bool((sr >> k) & 1) == inside) continue;
    const uint8_t flipped = uint8_t(sr ^ (1 << k));
    if (flipped != 0 && flipped != 0xff && !one_component(flipped)) continue;
    int score = 0;
    for (int a = 0; a < 3; ++a) score += h.between(k, k ^ (1 << a)) == inside;
    if (score > best_score) {
      best_score = score;
      best = k;
    }
  }
  return best;
}

/// A finest leaf whose corner signs make more than one component (corners of one sign meeting
/// only diagonally): the clean-up must flip a corner, and its default (flip the minority sign)
/// erases a solid or a gap about a cell thick lying obliquely to the lattice, whose lattice
/// points meet only diagonally (harness seed 30: a box face and a torus meeting at a shallow
/// angle, a slab 1-2 cells thick cut to pieces; seed 82). The operands know better: the
/// result's sign half-way between two such corners says whether the solid (or the gap) joins
/// them. When it joins all the corners of one sign, the hint flips a corner of the other sign
/// to it. Nothing when it joins neither (a feature thinner than a cell).
std::optional<SignHint> sign_hint(CsgOp op, Operand& xa, Operand& xb, const Cell& cell, uint8_t sr) {
  const HalfwaySigns h{op, xa, xb, cell};
  for (const bool inside : {true, false}) {
    if (!joined_halfway(h, sr, inside)) continue;
    if (const int k = corner_to_join(h, sr, inside); k >= 0) return SignHint{cell.corner(k), inside};
  }
  return std::nullopt;
}

/// What one task of the combine step builds, kept apart from A (which every task reads) until
/// the tasks are done: new nodes and vertices, and writes into A's existing slots. Indices with
/// kLocal set point into the fragment's own arrays; the others into A's.
struct Fragment {
  static constexpr uint32_t kLocal = 1u << 31;
  std::vector<Node> nodes;
  std::vector<std::array<float, 3>> vertices;
  std::vector<std::pair<uint32_t, Node>> pending;  // A's slot -> node
  std::vector<SignHint> hints;                      // see sign_hint()

  static bool is_local(uint32_t index) { return (index & kLocal) != 0; }
  /// `n` with its fragment-local index moved to where the fragment's arrays land (bases
  /// possibly local themselves, when merging into a parent fragment).
  static Node relocate(Node n, uint32_t node_base, uint32_t vertex_base) {
    if (n.kind == CellKind::Internal && is_local(n.index)) n.index = node_base + (n.index & ~kLocal);
    if (n.kind == CellKind::Gray && is_local(n.index)) n.index = vertex_base + (n.index & ~kLocal);
    return n;
  }
  /// Appends `f` to this fragment; returns `root` (a node of f) relocated.
  Node absorb(const Fragment& f, Node root) {
    const uint32_t nb = kLocal | uint32_t(nodes.size()), vb = kLocal | uint32_t(vertices.size());
    for (const Node& n : f.nodes) nodes.push_back(relocate(n, nb, vb));
    vertices.insert(vertices.end(), f.vertices.begin(), f.vertices.end());
    for (const auto& [slot, n] : f.pending) pending.push_back({slot, relocate(n, nb, vb)});
    hints.insert(hints.end(), f.hints.begin(), f.hints.end());
    return relocate(root, nb, vb);
  }
};

/// What the recursion counts; each task counts its own, summed when the tasks merge.
struct CombineCounts {
  size_t cells_visited = 0, gray_pairs = 0, forced_subdivisions = 0;
  CombineCounts& operator+=(const CombineCounts& o) {
    cells_visited += o.cells_visited;
    gray_pairs += o.gray_pairs;
    forced_subdivisions += o.forced_subdivisions;
    return *this;
  }
};

/// Builds nodes and vertices into one task's Fragment (new slots are fragment-local).
class FragmentWriter {
 public:
  explicit FragmentWriter(Fragment& out) : out_(out) {}

  void hint(const SignHint& h) { out_.hints.push_back(h); }
  void set(uint32_t slot, const Node& n) {
    if (Fragment::is_local(slot)) out_.nodes[slot & ~Fragment::kLocal] = n;
    else out_.pending.push_back({slot, n});
  }
  uint32_t alloc8() {
    const auto first = static_cast<uint32_t>(out_.nodes.size());
    out_.nodes.resize(first + 8);
    return Fragment::kLocal | first;
  }
  Node gray(const Cell& cell, uint8_t signs, const Vec3& x, uint8_t flags) {
    Node n = add_gray(out_.vertices, cell, signs, x, flags);
    n.index |= Fragment::kLocal;
    return n;
  }
  static Node uniform(bool inside) { return Node{0, inside ? CellKind::Black : CellKind::White, 0, 0, 0}; }

  /// Copies a subtree of `src` into the output, complemented if `invert`.
  Node copy_subtree(const Octree& src, uint32_t node, bool invert) {
    const Node n = src.nodes[node];
    switch (n.kind) {
      case CellKind::White:
      case CellKind::Black: return uniform((n.kind == CellKind::Black) != invert);
      case CellKind::Gray:
        out_.vertices.push_back(src.vertices[n.index]);
        return Node{Fragment::kLocal | static_cast<uint32_t>(out_.vertices.size() - 1), CellKind::Gray,
                    invert ? uint8_t(~n.signs) : n.signs, n.flags, 0};
      case CellKind::Internal: {
        const uint32_t first = alloc8();
        for (int c = 0; c < 8; ++c) set(first + c, copy_subtree(src, n.index + c, invert));
        return Node{first, CellKind::Internal, 0, 0, 0};
      }
    }
    return n;
  }

  /// Appends a freshly sampled subtree; returns its root.
  Node append(const Builder& sub) {
    const size_t from = out_.nodes.size();
    Node root = append_subtree(out_.nodes, out_.vertices, sub);
    auto mark = [](Node& n) {
      if (n.kind == CellKind::Internal || n.kind == CellKind::Gray) n.index |= Fragment::kLocal;
    };
    for (size_t k = from; k < out_.nodes.size(); ++k) mark(out_.nodes[k]);
    mark(root);
    return root;
  }

  /// Appends another task's fragment; returns its root relocated.
  Node absorb(const Fragment& f, Node root) { return out_.absorb(f, root); }

 private:
  Fragment& out_;
};

// ---- operand states ---------------------------------------------------------------------

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

/// The operand over child `c` of `cell`: a child node, or a virtual cell inside a gray leaf
/// (signs from sign_X, the leaf's triangles that reach the child), or uniform when such a
/// virtual cell has neither a sign change nor a triangle.
Side child_side(Operand& x, const Side& s, const Cell& cell, int c) {
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
    bool sign;
    if (gx != 1 && gy != 1 && gz != 1) {
      sign = (s.signs >> ((gx / 2) | (gy / 2) << 1 | (gz / 2) << 2)) & 1;
    } else {
      sign = x.sign_in(cc.corner(k), s.node, s.leaf_cell);
    }
    v.signs |= uint8_t(sign) << k;
  }
  filter_tris(x.tris, s.idx, cc, v.idx);
  if ((v.signs == 0 || v.signs == 0xff) && !meets_cell(x.tris, v.idx, cc)) {
    Side u;
    u.inside = v.signs != 0;
    return u;
  }
  return v;
}

/// A virtual cell with no sign change that still holds surface: it must be refined until the
/// surface shows in the signs.
bool unresolved(const Side& s) { return !s.real && (s.signs == 0 || s.signs == 0xff); }

// ---- GraycellCSG pieces -----------------------------------------------------------------

struct EdgeCrossing {
  bool change;
  double t;
  int count;
};
EdgeCrossing edge_crossing(const Operand& x, const Side& s, const I3& a, int axis, i64 len, int c0, int c1) {
  EdgeCrossing r{(((s.signs >> c0) ^ (s.signs >> c1)) & 1) != 0, 0.5, 0};
  for (uint32_t k : s.idx) {
    if (crosses(x.tris[k], a, axis, len)) {
      if (r.count == 0) r.t = crossing_param(x.tris[k], a, axis, len);
      ++r.count;
    }
  }
  return r;
}

/// What the cell's edges say: whether either operand's surface is visible in the result
/// there, and whether the cell must split.
struct EdgeVerdict {
  bool must_split = false;
  bool vis_a = false, vis_b = false;
};

/// Directed distances on each edge and the 1D CSG of the two crossings (paper 5.2.3,
/// Table 1): two result crossings on one edge force a subdivision, as do two crossings of one
/// operand on an edge of a virtual cell.
EdgeVerdict edge_verdict(CsgOp op, const Operand& xa, const Side& a, const Operand& xb, const Side& b,
                         const Cell& cell) {
  EdgeVerdict v;
  const I3 lo = lattice_to_grid(cell.lat);
  const i64 len = lattice_to_grid(cell.span());
  for (int e = 0; e < 12; ++e) {
    const int c0 = kEdgeCorners[e][0], c1 = kEdgeCorners[e][1], axis = edge_axis(e);
    const I3 p{lo[0] + (c0 & 1) * len, lo[1] + ((c0 >> 1) & 1) * len, lo[2] + ((c0 >> 2) & 1) * len};
    const EdgeCrossing ea = edge_crossing(xa, a, p, axis, len, c0, c1);
    const EdgeCrossing eb = edge_crossing(xb, b, p, axis, len, c0, c1);
    if ((!a.real && ea.count >= 2) || (!b.real && eb.count >= 2)) {
      v.must_split = true;
      return v;
    }
    if (!ea.change && !eb.change) continue;
    const bool a0 = (a.signs >> c0) & 1, b0 = (b.signs >> c0) & 1;
    auto in_a = [&](double t) { return ea.change ? (t < ea.t ? a0 : !a0) : a0; };
    auto in_b = [&](double t) { return eb.change ? (t < eb.t ? b0 : !b0) : b0; };
    int n_r = 0;
    if (ea.change && eb.change && ea.t == eb.t) {
      n_r = apply(op, a0, b0) != apply(op, !a0, !b0);
      v.vis_a = v.vis_b = v.vis_a || n_r;
    } else {
      if (ea.change) {
        const bool vis = apply(op, a0, in_b(ea.t)) != apply(op, !a0, in_b(ea.t));
        n_r += vis;
        v.vis_a = v.vis_a || vis;
      }
      if (eb.change) {
        const bool vis = apply(op, in_a(eb.t), b0) != apply(op, in_a(eb.t), !b0);
        n_r += vis;
        v.vis_b = v.vis_b || vis;
      }
    }
    if (n_r >= 2) {
      v.must_split = true;
      return v;
    }
  }
  return v;
}

/// Whether the two operands' partial contours meet inside the cell.
bool surfaces_meet(const Operand& xa, const Side& a, const Operand& xb, const Side& b, const Cell& cell) {
  for (uint32_t i : a.idx)
    for (uint32_t j : b.idx)
      if (triangles_meet_in_box(xa.tris[i], xb.tris[j], cell.box())) return true;
  return false;
}

/// The new feature (where the two surfaces meet) must also fit one point or line over the
/// cell grown by half its size on every side: dual contouring joins this vertex to its
/// neighbours' by straight edges, so a curved intersection (a hole's rim) is refined until
/// those edges follow it. Not in the paper, whose per-cell test lets big cells sit on a
/// curved rim and chords cut across it.
bool feature_is_local(const Operand& xa, const Operand& xb, const Cell& cell, const Vec3& x, double error,
                      std::vector<uint32_t>& scratch) {
  IBox g = cell.box();
  const i64 h = lattice_to_grid(cell.span()) / 2;
  for (int k = 0; k < 3; ++k) {
    g.lo[k] = std::max<i64>(0, g.lo[k] - h);
    g.hi[k] = std::min<i64>(i64{1} << kGridBits, g.hi[k] + h);
  }
  const double face = 4 * cell.size() * cell.size();
  Qef q;
  scratch.clear();
  xa.bvh.query(xa.tris, g.lo, g.hi, scratch);
  box_qef(xa.tris, scratch, g, face, q);
  scratch.clear();
  xb.bvh.query(xb.tris, g.lo, g.hi, scratch);
  box_qef(xb.tris, scratch, g, face, q);
  return q.solve(x).error < error;
}

/// The result's signs on the cell's child grid are simple (see grid_is_simple): otherwise a
/// leaf here would meet finer neighbours showing a second sheet on its faces.
bool refinement_is_simple(CsgOp op, Operand& xa, const Side& a, Operand& xb, const Side& b, const Cell& cell,
                          uint8_t sr) {
  std::array<bool, 27> g{};
  for (int k = 0; k < 8; ++k) g[grid_index_of_corner(k)] = (sr >> k) & 1;
  const int64_t h = cell.span() / 2;
  for (int i = 0; i < 27; ++i) {
    const int x = i % 3, y = (i / 3) % 3, z = i / 9;
    if (x != 1 && y != 1 && z != 1) continue;
    const Lat p{cell.lat[0] + x * h, cell.lat[1] + y * h, cell.lat[2] + z * h};
    g[i] = apply(op, xa.sign_in(p, a.node, a.leaf_cell), xb.sign_in(p, b.node, b.leaf_cell));
  }
  return grid_is_simple(g);
}

/// The two operands' QEFs over the cell, and their sum.
struct CellQefs {
  Qef a, b, sum;
};
CellQefs cell_qefs(const Operand& xa, const Side& a, const Operand& xb, const Side& b, const Cell& cell) {
  CellQefs q;
  cell_qef(xa.tris, a.idx, cell, q.a);
  cell_qef(xb.tris, b.idx, cell, q.b);
  q.sum = q.a;
  q.sum += q.b;
  return q;
}

/// An operand's own vertex in the cell: the leaf's stored one, or the minimizer of its QEF in
/// a virtual cell.
Vec3 operand_vertex(const Operand& x, const Side& s, const Qef& q, const Cell& cell) {
  if (s.real) return vertex_unit(cell, x.t.vertices[x.t.nodes[s.node].index]);
  return cell_vertex(q, cell, s.signs).position;
}

/// The paired recursion over A's and B's cells (paper 5.2): trivial cases, GraycellCSG where
/// both are gray, forced subdivision (resampling a leaf's partial contour) where one is finer.
class Combiner {
 public:
  Combiner(Fragment& out, Operand& a, Operand& b, CsgOp op, double error, int max_depth, uint32_t stamp,
           int parallel_levels, bool parallel, CombineCounts& stats)
      : out_(out), a_(a), b_(b), op_(op), error_(error), max_depth_(max_depth), stamp_(stamp),
        parallel_levels_(parallel_levels), parallel_(parallel), stats_(stats) {}

  /// The result's root node (its index may be fragment-local).
  Node run() {
    Side sa = side_of(a_, 0, Cell{});
    Side sb = side_of(b_, 0, Cell{});
    return combine(Cell{}, sa, sb);
  }

 private:
  static Node uniform(bool inside) { return FragmentWriter::uniform(inside); }

  /// Resamples a (virtual) gray cell of operand x from its partial contour.
  Node resample(Operand& x, const Cell& cell, const Side& s, bool invert) {
    FanSource src(x);
    SampleParams p;
    p.max_depth = max_depth_;
    p.error = error_;
    p.invert = invert;
    Builder sub;
    sub.nodes.resize(1);
    size_t capped = 0;
    sample_cell(src, p, cell, s.signs, s.idx, sub, 0, capped);
    ++stats_.forced_subdivisions;
    return out_.append(sub);
  }

  /// An operand's cell as the result (complemented if `invert`): A's own nodes stay in place.
  Node copy_side(Operand& x, const Side& s, const Cell& cell, bool invert, bool is_a) {
    switch (s.kind) {
      case Side::Uniform: return uniform(s.inside != invert);
      case Side::Internal:
        if (is_a && !invert) return x.t.nodes[s.node];  // unchanged subtree of A, in place
        return out_.copy_subtree(x.t, s.node, invert);
      case Side::Gray:
        if (s.real) {
          if (is_a && !invert) return x.t.nodes[s.node];
          return out_.copy_subtree(x.t, s.node, invert);
        }
        return resample(x, cell, s, invert);
    }
    return uniform(false);
  }

  Node combine(const Cell& cell, const Side& a, const Side& b) {
    ++stats_.cells_visited;
    if (a.kind == Side::Uniform) {
      if (b.kind == Side::Uniform) return uniform(apply(op_, a.inside, b.inside));
      // white | X = X, black & X = X, black - X = not X; the rest are uniform.
      if (op_ == CsgOp::Union) return a.inside ? uniform(true) : copy_side(b_, b, cell, false, false);
      if (op_ == CsgOp::Intersect) return a.inside ? copy_side(b_, b, cell, false, false) : uniform(false);
      return a.inside ? copy_side(b_, b, cell, true, false) : uniform(false);
    }
    if (b.kind == Side::Uniform) {
      if (op_ == CsgOp::Union) return b.inside ? uniform(true) : copy_side(a_, a, cell, false, true);
      if (op_ == CsgOp::Intersect) return b.inside ? copy_side(a_, a, cell, false, true) : uniform(false);
      return b.inside ? uniform(false) : copy_side(a_, a, cell, false, true);
    }
    if (a.kind == Side::Internal || b.kind == Side::Internal) return subdivide(cell, a, b);
    return gray_cell(cell, a, b);
  }

  Node subdivide(const Cell& cell, const Side& a, const Side& b) {
    // Children of A's internal node are written in place; otherwise new slots.
    uint32_t first;
    if (a.kind == Side::Internal) {
      first = a_.t.nodes[a.node].index;
    } else {
      first = out_.alloc8();
      if (a.kind == Side::Gray && a.real) ++stats_.forced_subdivisions;
    }
    if (b.kind == Side::Gray && b.real) ++stats_.forced_subdivisions;
    std::array<Node, 8> kids;
    if (cell.level < parallel_levels_ && a.kind == Side::Internal && b.kind == Side::Internal) kids = split_in_tasks(cell, a, b);
    else
      for (int c = 0; c < 8; ++c) kids[c] = combine(cell.child(c), child_side(a_, a, cell, c), child_side(b_, b, cell, c));
    bool all_uniform = true;
    for (int c = 0; c < 8; ++c) {
      out_.set(first + c, kids[c]);
      all_uniform = all_uniform && (kids[c].kind == CellKind::White || kids[c].kind == CellKind::Black) &&
                    kids[c].kind == kids[0].kind;
    }
    if (all_uniform) return uniform(kids[0].kind == CellKind::Black);  // collapse
    return Node{first, CellKind::Internal, 0, 0, 0};
  }

  /// Near the root, each child is a task with its own fragment and caches, merged in child
  /// order: the same bytes whether the tasks run in parallel or not.
  std::array<Node, 8> split_in_tasks(const Cell& cell, const Side& a, const Side& b) {
    std::array<Node, 8> kids;
    std::array<Fragment, 8> frags;
    std::array<CombineCounts, 8> sub_stats;
    auto task = [&](int c) {
      Operand ca(a_.t, a_.stamps, a_.pc, stamp_), cb(b_.t, b_.stamps, b_.pc, stamp_);
      Combiner sub(frags[c], ca, cb, op_, error_, max_depth_, stamp_, parallel_levels_, parallel_, sub_stats[c]);
      kids[c] = sub.combine(cell.child(c), child_side(ca, a, cell, c), child_side(cb, b, cell, c));
    };
    if (parallel_) tbb::parallel_for(0, 8, task);
    else for (int c = 0; c < 8; ++c) task(c);
    for (int c = 0; c < 8; ++c) {
      kids[c] = out_.absorb(frags[c], kids[c]);
      stats_ += sub_stats[c];
    }
    return kids;
  }

  /// GraycellCSG: both operands gray over the cell. A leaf when the cell resolves (culled to
  /// one operand or uniform, or a new vertex where the surfaces meet); else split.
  Node gray_cell(const Cell& cell, const Side& a, const Side& b) {
    ++stats_.gray_pairs;
    const uint8_t sr = apply_mask(op_, a.signs, b.signs);
    // The same PIC in both operands (A op A, or untouched common history): nothing to compute.
    if (a.real && b.real && a.signs == b.signs &&
        a_.t.vertices[a_.t.nodes[a.node].index] == b_.t.vertices[b_.t.nodes[b.node].index]) {
      if (op_ == CsgOp::Subtract) return uniform(false);
      return copy_side(a_, a, cell, false, true);
    }
    const bool at_cap = cell.level >= max_depth_;
    if (!unresolved(a) && !unresolved(b)) {
      const EdgeVerdict ev = edge_verdict(op_, a_, a, b_, b, cell);
      if (!ev.must_split)
        if (const std::optional<Node> leaf = gray_leaf(cell, a, b, sr, ev, at_cap)) return *leaf;
    }
    if (at_cap) {
      if (sr == 0 || sr == 0xff) return uniform(sr != 0);
      const CellQefs q = cell_qefs(a_, a, b_, b, cell);
      if (!one_component(sr))
        if (const std::optional<SignHint> h = sign_hint(op_, a_, b_, cell, sr)) out_.hint(*h);
      return out_.gray(cell, sr, cell_vertex(q.sum, cell, sr).position, kFlagCapped);
    }
    return subdivide(cell, a, b);
  }

  /// The cell as one leaf, if it may be one: triangle-fan culling where the surfaces do not
  /// meet, Q_sum's vertex where they do (paper eq. 3); nothing when the cell must split.
  std::optional<Node> gray_leaf(const Cell& cell, const Side& a, const Side& b, uint8_t sr, const EdgeVerdict& ev,
                                bool at_cap) {
    const bool simple = at_cap || refinement_is_simple(op_, a_, a, b_, b, cell, sr);
    if (!simple) return std::nullopt;
    if (!surfaces_meet(a_, a, b_, b, cell)) {
      // The surfaces do not meet here, so the result is one operand's cell, or uniform, when
      // the signs agree.
      const uint8_t sb_seen = op_ == CsgOp::Subtract ? uint8_t(~b.signs) : b.signs;
      if (!ev.vis_a && !ev.vis_b && (sr == 0 || sr == 0xff)) return uniform(sr != 0);
      if (ev.vis_a && !ev.vis_b && sr == a.signs) return copy_side(a_, a, cell, false, true);
      if (ev.vis_b && !ev.vis_a && sr == sb_seen) return copy_side(b_, b, cell, op_ == CsgOp::Subtract, false);
      return std::nullopt;
    }
    // Q_sum = Q_A + Q_B minimized from the average of the two vertices.
    const CellQefs q = cell_qefs(a_, a, b_, b, cell);
    const Vec3 va = operand_vertex(a_, a, q.a, cell), vb = operand_vertex(b_, b, q.b, cell);
    const Vec3 seed{(va[0] + vb[0]) / 2, (va[1] + vb[1]) / 2, (va[2] + vb[2]) / 2};
    const Vec3 lo = cell.min_unit(), hi{lo[0] + cell.size(), lo[1] + cell.size(), lo[2] + cell.size()};
    Qef::Solution sol = q.sum.solve_in_box(seed, lo, hi);
    if (!inside_cell(sol.position, cell)) sol = cell_vertex(q.sum, cell, sr);
    if (sol.error < error_ && inside_cell(sol.position, cell) && one_component(sr) &&
        feature_is_local(a_, b_, cell, sol.position, error_, scratch_))
      return out_.gray(cell, sr, sol.position, 0);
    return std::nullopt;
  }

  FragmentWriter out_;
  Operand& a_;
  Operand& b_;
  CsgOp op_;
  double error_;
  int max_depth_;
  uint32_t stamp_;
  int parallel_levels_;
  bool parallel_;
  CombineCounts& stats_;
  std::vector<uint32_t> scratch_;
};

struct Deferred {
  uint32_t b_node;
  Cell cell;
};

/// Stamps the overlap: pairs of cells where neither operand is uniform (paper 5.2.1). Where a
/// gray leaf of A covers a subtree of B, B's subtree is not stamped yet: `deferred` keeps it
/// for stamp_under_surface(), which stamps only the parts A's surface comes near.
void tag(const Octree& a, Stamps& sa, uint32_t na, const Octree& b, Stamps& sb, uint32_t nb, const Cell& cell,
         uint32_t stamp, size_t& count, std::vector<Deferred>& deferred) {
  const Node& x = a.nodes[na];
  const Node& y = b.nodes[nb];
  const bool ux = x.kind == CellKind::White || x.kind == CellKind::Black;
  const bool uy = y.kind == CellKind::White || y.kind == CellKind::Black;
  if (ux || uy) return;
  if (sa[na] != stamp) {
    sa[na] = stamp;
    ++count;
  }
  if (sb[nb] != stamp) {
    sb[nb] = stamp;
    ++count;
  }
  if (x.kind != CellKind::Internal && y.kind != CellKind::Internal) return;
  if (x.kind == CellKind::Gray) {
    deferred.push_back({nb, cell});
    return;
  }
  for (int c = 0; c < 8; ++c)
    tag(a, sa, x.index + c, b, sb, y.kind == CellKind::Internal ? y.index + c : nb, cell.child(c), stamp, count,
        deferred);
}

/// Stamps the cells of B's subtree that A's partial contour comes near: elsewhere A is
/// uniform inside its gray leaf, so the result there is B's subtree or uniform, with no need
/// for B's partial contour. This makes the cost of a coarse clay against a fine tool follow
/// the clay's surface, not the tool's whole volume.
void stamp_under_surface(const PartialContour& a, const Octree& b, Stamps& sb, uint32_t nb, const Cell& cell,
                         uint32_t stamp, size_t& count, std::vector<uint32_t>& scratch) {
  const Node& y = b.nodes[nb];
  if (y.kind == CellKind::White || y.kind == CellKind::Black) return;
  const IBox box = cell.box();
  scratch.clear();
  a.bvh.query(a.tris, box.lo, box.hi, scratch);
  if (scratch.empty()) return;
  if (sb[nb] != stamp) {
    sb[nb] = stamp;
    ++count;
  }
  if (y.kind == CellKind::Internal)
    for (int c = 0; c < 8; ++c) stamp_under_surface(a, b, sb, y.index + c, cell.child(c), stamp, count, scratch);
}

/// Marks `node` and every node below it whose closed cell meets an edge of the lattice box
/// [lo, hi]: meets the box, and holds one of its bounds along two axes.
void mark_touching_edges(const Octree& t, uint32_t node, const Cell& cell, const Lat& lo, const Lat& hi,
                         std::unordered_set<uint32_t>& out) {
  const int64_t s = cell.span();
  int bounds = 0;
  for (int k = 0; k < 3; ++k) {
    if (cell.lat[k] > hi[k] || cell.lat[k] + s < lo[k]) return;
    auto holds = [&](int64_t x) { return cell.lat[k] <= x && x <= cell.lat[k] + s; };
    bounds += holds(lo[k]) || holds(hi[k]);
  }
  if (bounds < 2) return;
  out.insert(node);
  const Node& n = t.nodes[node];
  if (n.kind == CellKind::Internal)
    for (int c = 0; c < 8; ++c) mark_touching_edges(t, n.index + c, cell.child(c), lo, hi, out);
}

/// The nodes around the edges of the stamped gray leaves coarser than the finest level: signs
/// inside such a leaf come from crossing parity with the contour triangles in its cell, and a
/// dual polygon of finer neighbours (none of them stamped) can cut through a corner of that
/// cell. Without those triangles the parity is wrong over part of the cell (a box's coarse
/// leaf took a cone's tip for outside the box: a stray shell 4 cells from the exact result,
/// harness seed 81). Only cells at the leaf's edges matter: a polygon's vertices lie in their
/// cells, and cells that touch only the inside of one face all lie beyond that face's plane,
/// and so do their polygons.
std::unordered_set<uint32_t> around_coarse_leaves(const Octree& t, const Stamps& stamps, uint32_t stamp) {
  std::unordered_set<uint32_t> out;
  std::function<void(uint32_t, const Cell&)> walk = [&](uint32_t node, const Cell& cell) {
    if (stamps[node] != stamp) return;
    const Node& n = t.nodes[node];
    if (n.kind == CellKind::Internal) {
      for (int c = 0; c < 8; ++c) walk(n.index + c, cell.child(c));
    } else if (n.kind == CellKind::Gray && cell.level < t.max_depth) {
      mark_touching_edges(t, 0, Cell{}, cell.lat, cell.corner(7), out);
    }
  };
  walk(0, Cell{});
  return out;
}

/// The partial contour: dual polygons around stamped cells, indexed for box queries; for the
/// parity walks also those around the edges of stamped coarse leaves. One walk: a polygon
/// with a stamped leaf is the operation's own.
void partial_contour(const Octree& t, const Stamps& stamps, uint32_t stamp, PartialContour& x) {
  const std::unordered_set<uint32_t> around = around_coarse_leaves(t, stamps, stamp);
  const std::function<bool(uint32_t)> active = [&](uint32_t n) {
    return stamps[n] == stamp || around.count(n) != 0;
  };
  std::vector<ITri> extra;
  std::function<void(const DualPolygon&)> emit = [&](const DualPolygon& poly) {
    bool own = false;
    for (int k = 0; k < poly.count; ++k) own = own || stamps[poly.leaf[k]] == stamp;
    std::vector<ITri>& out = own ? x.tris : extra;
    std::array<I3, 4> g;
    for (int k = 0; k < poly.count; ++k) g[k] = to_grid(poly.pos[k]);
    auto add = [&](int i, int j, int k) {
      out.push_back(make_itri(g[i], g[j], g[k]));
    };
    if (poly.count == 3) {
      add(0, 1, 2);
      return;
    }
    for (const auto& tri : split_quad({poly.pos[0], poly.pos[1], poly.pos[2], poly.pos[3]})) add(tri[0], tri[1], tri[2]);
  };
  dual_walk(t, &active, emit);
  x.bvh.build(x.tris);
  if (extra.empty()) return;
  x.parity_tris = x.tris;
  x.parity_tris.insert(x.parity_tris.end(), extra.begin(), extra.end());
  x.parity_bvh.build(x.parity_tris);
}

/// Drops unreachable nodes and vertices (left behind by in-place replacement).
void compact(Octree& t) {
  Octree c;
  c.cube = t.cube;
  c.max_depth = t.max_depth;
  c.nodes.clear();
  c.nodes.reserve(t.nodes.size());
  c.nodes.push_back(Node{});
  std::function<void(uint32_t, uint32_t)> copy = [&](uint32_t from, uint32_t to) {
    Node n = t.nodes[from];
    if (n.kind == CellKind::Gray) {
      c.vertices.push_back(t.vertices[n.index]);
      n.index = static_cast<uint32_t>(c.vertices.size() - 1);
    } else if (n.kind == CellKind::Internal) {
      const auto first = static_cast<uint32_t>(c.nodes.size());
      c.nodes.resize(first + 8);
      for (int k = 0; k < 8; ++k) copy(n.index + k, first + k);
      n.index = first;
    }
    c.nodes[to] = n;
  };
  copy(0, 0);
  t.nodes = std::move(c.nodes);
  t.vertices = std::move(c.vertices);
}

/// One frame: B re-expressed in A's cube when they differ (its contour resampled). When B's
/// surface does not fit in A's cube, both are resampled into the cube around both cubes (A then
/// changes cube: its root grows). A op A works on a copy of B. Empty when B serves as it is.
std::optional<Octree> common_frame(Octree& a, const Octree& b_in, const CsgOptions& options, CsgStats& stats) {
  std::optional<Octree> resampled;
  if (!(a.cube == b_in.cube)) {
    SampleOptions so;
    so.cube = a.cube;
    so.depth = std::max(a.max_depth, b_in.max_depth);
    so.error = options.error;
    const TriMesh mb = unsplit_contour(b_in);
    try {
      resampled = sample(mb, so);
    } catch (const InvalidInput&) {
      Cube both;
      double hi = -1e300;
      for (int k = 0; k < 3; ++k) {
        both.origin[k] = std::min(a.cube.origin[k], b_in.cube.origin[k]);
        hi = std::max({hi, a.cube.origin[k] + a.cube.size - both.origin[k],
                       b_in.cube.origin[k] + b_in.cube.size - both.origin[k]});
      }
      both.size = hi;
      so.cube = both;
      const TriMesh ma = unsplit_contour(a);
      if (!ma.triangles.empty()) a = sample(ma, so);
      else a = Octree{both, so.depth, {Node{}}, {}};
      resampled = sample(mb, so);
    }
    stats.resampled_b = true;
  } else if (&a == &b_in) {
    resampled = b_in;
  }
  return resampled;
}

/// Stamps the cells where the operands' surfaces may meet (tag, then stamp_under_surface for
/// the subtrees of B it deferred) and builds both operands' partial contours.
void stamp_overlap(const Octree& a, Stamps& sa, const Octree& b, Stamps& sb, uint32_t stamp, PartialContour& pa,
                   PartialContour& pb, CsgStats& stats) {
  sa.assign(a.nodes.size(), 0);
  sb.assign(b.nodes.size(), 0);
  std::vector<Deferred> deferred;
  tag(a, sa, 0, b, sb, 0, Cell{}, stamp, stats.cells_stamped, deferred);

  auto tc = Clock::now();
  partial_contour(a, sa, stamp, pa);
  stats.contour_a_seconds = since(tc);
  tc = Clock::now();
  {
    std::vector<uint32_t> scratch;
    for (const Deferred& d : deferred) {
      const Node& y = b.nodes[d.b_node];
      for (int c = 0; c < 8; ++c)
        stamp_under_surface(pa, b, sb, y.index + c, d.cell.child(c), stamp, stats.cells_stamped, scratch);
    }
  }
  partial_contour(b, sb, stamp, pb);
  stats.contour_b_seconds = since(tc);
}

/// Combines the stamped cells into A. Every task reads A as it was; the new nodes land after
/// A's, and A's own slots are written only once all tasks are done.
std::vector<SignHint> combine_stamped(Octree& a, Stamps& sa, const Octree& b, const Stamps& sb, const PartialContour& pa,
                                      const PartialContour& pb, CsgOp op, const CsgOptions& options, int depth,
                                      uint32_t stamp, CsgStats& stats) {
  Fragment f;
  Operand oa(a, sa, pa, stamp), ob(b, sb, pb, stamp);
  CombineCounts counts;
  Combiner comb(f, oa, ob, op, options.error, depth, stamp, kParallelLevels, options.parallel, counts);
  const Node root = comb.run();
  stats.cells_visited = counts.cells_visited;
  stats.gray_pairs = counts.gray_pairs;
  stats.forced_subdivisions = counts.forced_subdivisions;
  const auto node_base = static_cast<uint32_t>(a.nodes.size()), vertex_base = static_cast<uint32_t>(a.vertices.size());
  for (const Node& n : f.nodes) a.nodes.push_back(Fragment::relocate(n, node_base, vertex_base));
  a.vertices.insert(a.vertices.end(), f.vertices.begin(), f.vertices.end());
  sa.resize(a.nodes.size(), stamp);
  // A slot written here is part of the result this operation made, even where the tag step
  // left it unstamped (A uniform there, B's subtree copied in): the clean-up must see it, or
  // B's own defects there pass into the result unchecked (an island a sampled tool carries —
  // a small sphere's pole piercing a lattice plane beside a coarse leaf — became a sculpting
  // stroke's pinched vertex). Cleaning these parts too costs sculpting about 2-3 ms a stroke.
  for (const auto& [slot, n] : f.pending) {
    a.nodes[slot] = Fragment::relocate(n, node_base, vertex_base);
    sa[slot] = stamp;
  }
  a.nodes[0] = Fragment::relocate(root, node_base, vertex_base);
  return std::move(f.hints);
}

}  // namespace

size_t reachable_nodes(const Octree& t) {
  size_t n = 0;
  std::function<void(uint32_t)> walk = [&](uint32_t i) {
    ++n;
    if (t.nodes[i].kind == CellKind::Internal)
      for (int c = 0; c < 8; ++c) walk(t.nodes[i].index + c);
  };
  walk(0);
  return n;
}

}  // namespace detail

std::string to_string(CsgOp op) {
  switch (op) {
    case CsgOp::Union: return "union";
    case CsgOp::Intersect: return "intersect";
    case CsgOp::Subtract: return "subtract";
  }
  return "?";
}

std::optional<CsgOp> parse_csg_op(const std::string& s) {
  if (s == "union" || s == "add") return CsgOp::Union;
  if (s == "intersect" || s == "intersection") return CsgOp::Intersect;
  if (s == "subtract" || s == "difference" || s == "minus") return CsgOp::Subtract;
  return std::nullopt;
}

void csg_inplace(Octree& a, const Octree& b_in, CsgOp op, const CsgOptions& options, CsgStats* stats_out) {
  using namespace detail;
  const auto t0 = Clock::now();
  CsgStats stats;
  const std::optional<Octree> resampled = common_frame(a, b_in, options, stats);
  const Octree& b = resampled ? *resampled : b_in;
  const int depth = std::max(a.max_depth, b.max_depth);

  const uint32_t stamp = ++g_timestamp;
  stats.stamp = stamp;
  // The cells this operation works on, per node of each operand: kept here, not in the
  // trees, so that csg(a, b) only reads b.
  Stamps sa, sb;
  PartialContour pa, pb;
  stamp_overlap(a, sa, b, sb, stamp, pa, pb, stats);

  const auto tc = Clock::now();
  const size_t before = a.nodes.size();
  const std::vector<SignHint> hints = combine_stamped(a, sa, b, sb, pa, pb, op, options, depth, stamp, stats);
  a.max_depth = depth;
  const auto tclean = Clock::now();
  {
    Operand ob(b, sb, pb, stamp);
    clean_up(a, sa, stamp, op, hints, [&](const Lat& p) { return ob.sign(p); }, stats);
  }
  stats.cleanup_seconds = since(tclean);
  stats.csg_seconds = since(tc);
  // Amortized garbage collection of replaced subtrees.
  if (a.nodes.size() > 2 * std::max<size_t>(before, 4096) || a.nodes.size() > before + 65536) {
    if (a.nodes.size() > 2 * reachable_nodes(a)) compact(a);
  }
  stats.seconds = since(t0);
  if (stats_out) *stats_out = stats;
}

Octree csg(const Octree& a, const Octree& b, CsgOp op, const CsgOptions& options, CsgStats* stats) {
  Octree r = a;
  csg_inplace(r, b, op, options, stats);
  if (r.nodes.size() > a.nodes.size() + 1024 || r.nodes.size() > 2 * detail::reachable_nodes(r)) detail::compact(r);
  return r;
}

}  // namespace pic

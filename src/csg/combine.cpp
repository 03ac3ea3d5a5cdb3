// The paired recursion over A's and B's cells (paper section 5.2), writing the result into
// fragments that land in A once every task is done. See combine.h.
#include "csg/combine.h"

#include <algorithm>

#include "csg/gray_cell.h"
#include "signs/leaf_walks.h"

namespace pic::detail {

namespace {


/// How many times a path down the recursion may split into parallel tasks: where both operands
/// are subdivided and at least two children hold surface of both (a sculpting stroke's few
/// busy cells lie several levels down, under levels where only one child is busy).
constexpr int kParallelSplits = 4;
/// Cells this close to the depth cap are not split: too little work per task.
constexpr int kMinTaskLevels = 3;

/// What one task of the combine step builds, kept apart from A (which every task reads) until
/// the tasks are done: new nodes and vertices, and writes into A's existing slots. Indices with
/// kLocal set point into the fragment's own arrays; the others into A's.
struct Fragment {
  static constexpr uint32_t kLocal = 1u << 31;
  std::vector<Node> nodes;
  std::vector<uint8_t> inside_copy;  // per node: inside a copied subtree, off its root's faces
  std::vector<std::array<float, 3>> vertices;
  std::vector<std::pair<uint32_t, Node>> pending;  // A's slot -> node
  std::vector<SignHint> hints;                      // see sign_hint()
  std::vector<Cell> contacts;  // finest cells whose result signs make two components

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
    inside_copy.insert(inside_copy.end(), f.inside_copy.begin(), f.inside_copy.end());
    vertices.insert(vertices.end(), f.vertices.begin(), f.vertices.end());
    for (const auto& [slot, n] : f.pending) pending.push_back({slot, relocate(n, nb, vb)});
    hints.insert(hints.end(), f.hints.begin(), f.hints.end());
    contacts.insert(contacts.end(), f.contacts.begin(), f.contacts.end());
    return relocate(root, nb, vb);
  }
};

/// The cells, at every level above the cap, whose closed box holds a given lattice point: the
/// recursion splits them down to the finest level, so that the leaves around the point are
/// finest cells (a sign the clean-up changes there then moves the surface by a finest cell,
/// not by a coarse leaf's size). A key may stand for two cells (then both split: harmless).
class FocusCells {
 public:
  FocusCells(const std::vector<Lat>& points, int max_depth) {
    for (const Lat& p : points) add(p, max_depth);
  }
  bool holds(const Cell& cell) const { return keys_.count(key(cell.level, cell.lat)) != 0; }

 private:
  static uint64_t key(int level, const Lat& lat) {
    const int shift = kMaxLevel - level;
    return uint64_t(level) << 59 ^ uint64_t(lat[0] >> shift) << 38 ^ uint64_t(lat[1] >> shift) << 19 ^
           uint64_t(lat[2] >> shift);
  }
  void add(const Lat& p, int max_depth) {
    constexpr int64_t kLimit = int64_t{1} << kMaxLevel;
    for (int level = 0; level < max_depth; ++level) {
      const int64_t span = int64_t{1} << (kMaxLevel - level);
      // Along each axis the cell holding p, and the one below when p lies on their plane.
      std::array<std::array<int64_t, 2>, 3> lo;
      std::array<int, 3> n{};
      for (int a = 0; a < 3; ++a) {
        const int64_t base = std::min(p[a], kLimit - 1) / span * span;
        lo[a][n[a]++] = base;
        if (p[a] == base && base > 0) lo[a][n[a]++] = base - span;
      }
      for (int i = 0; i < n[0]; ++i)
        for (int j = 0; j < n[1]; ++j)
          for (int k = 0; k < n[2]; ++k) keys_.insert(key(level, {lo[0][i], lo[1][j], lo[2][k]}));
    }
  }
  std::unordered_set<uint64_t> keys_;
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
  void contact(const Cell& c) { out_.contacts.push_back(c); }
  void set(uint32_t slot, const Node& n) {
    if (Fragment::is_local(slot)) out_.nodes[slot & ~Fragment::kLocal] = n;
    else out_.pending.push_back({slot, n});
  }
  uint32_t alloc8() {
    const auto first = static_cast<uint32_t>(out_.nodes.size());
    out_.nodes.resize(first + 8);
    out_.inside_copy.resize(first + 8, 0);
    return Fragment::kLocal | first;
  }
  Node gray(const Cell& cell, uint8_t signs, const Vec3& x, uint8_t flags) {
    Node n = add_gray(out_.vertices, cell, signs, x, flags);
    n.index |= Fragment::kLocal;
    return n;
  }
  static Node uniform(bool inside) { return Node{0, inside ? CellKind::Black : CellKind::White, 0, 0, 0}; }

  /// Copies a subtree of `src` into the output, complemented if `invert`. In a copy of more
  /// than kQuietCopy nodes, or any copy of a `settled` source, the nodes whose cells lie on none
  /// of the copy's root cell faces are marked inside_copy: every neighbour they have is the
  /// source's own, as it was there.
  Node copy_subtree(const Octree& src, uint32_t node, bool invert, bool settled) {
    const size_t from = out_.nodes.size();
    const Node root = copy_nodes(src, node, invert, 0x3f);
    if (!settled && out_.nodes.size() - from <= kQuietCopy)
      std::fill(out_.inside_copy.begin() + std::ptrdiff_t(from), out_.inside_copy.end(), uint8_t{0});
    return root;
  }

 private:
  /// A sampled operand can carry a sign island of its own (a small sphere's pole piercing a
  /// lattice plane beside a coarse leaf), which the clean-up removes from what it copies:
  /// sculpting tools are cleaned whole. Large copies (whole parts of a model placed apart, as
  /// in a union of disjoint parts) keep their interior as sampled, as their own contour has it:
  /// cleaning them cost about a second per 100,000 PICs.
  static constexpr size_t kQuietCopy = 1u << 15;

  /// copy_subtree's recursion. `faces`: which faces of the copy's root cell this cell lies on
  /// (bit 2a: the low side of axis a, 2a + 1: the high side).
  Node copy_nodes(const Octree& src, uint32_t node, bool invert, uint8_t faces) {
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
        for (int c = 0; c < 8; ++c) {
          uint8_t child_faces = 0;
          for (int a = 0; a < 3; ++a) child_faces |= uint8_t(faces & (1u << (2 * a + ((c >> a) & 1))));
          if (child_faces == 0) out_.inside_copy[(first & ~Fragment::kLocal) + c] = 1;
          set(first + c, copy_nodes(src, n.index + c, invert, child_faces));
        }
        return Node{first, CellKind::Internal, 0, 0, 0};
      }
    }
    return n;
  }

 public:
  /// Appends a freshly sampled subtree; returns its root.
  Node append(const Builder& sub) {
    const size_t from = out_.nodes.size();
    Node root = append_subtree(out_.nodes, out_.vertices, sub);
    out_.inside_copy.resize(out_.nodes.size(), 0);
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

/// The paired recursion over A's and B's cells (paper 5.2): trivial cases, GraycellCSG where
/// both are gray, forced subdivision (resampling a leaf's partial contour) where one is finer.
class Combiner {
 public:
  Combiner(Fragment& out, Operand& a, Operand& b, CsgOp op, const CsgOptions& options, int max_depth, uint32_t stamp,
           int parallel_splits, bool parallel, const FocusCells* focus, CombineCounts& stats)
      : out_(out), a_(a), b_(b), op_(op), options_(options), error_(options.error), max_depth_(max_depth),
        stamp_(stamp), parallel_splits_(parallel_splits), parallel_(parallel), focus_(focus), stats_(stats) {}

  /// The result's root node (its index may be fragment-local).
  Node run() {
    Side sa = side_of(a_, 0, Cell{});
    Side sb = side_of(b_, 0, Cell{});
    return combine(Cell{}, sa, sb);
  }

  /// The result over one cell: both operands followed down to it (virtual cells inside
  /// their gray leaves), then combined there.
  Node run_at(const Cell& target) {
    Side sa = side_of(a_, 0, Cell{});
    Side sb = side_of(b_, 0, Cell{});
    Cell cell;
    while (cell.level < target.level) {
      const int c = cell.child_toward(target.lat);
      const SignGrid ga = sa.kind == Side::Gray ? sign_grid(a_, sa, cell) : SignGrid{};
      const SignGrid gb = sb.kind == Side::Gray ? sign_grid(b_, sb, cell) : SignGrid{};
      sa = child_side(a_, sa, cell, c, ga);
      sb = child_side(b_, sb, cell, c, gb);
      cell = cell.child(c);
    }
    return combine(cell, sa, sb);
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
    p.tips_at_corners = true;
    p.partial_contour = true;
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
        return out_.copy_subtree(x.t, s.node, invert, !is_a && options_.b_settled);
      case Side::Gray:
        if (s.real) {
          if (is_a && !invert) return x.t.nodes[s.node];
          return out_.copy_subtree(x.t, s.node, invert, !is_a && options_.b_settled);
        }
        return resample(x, cell, s, invert);
    }
    return uniform(false);
  }

  Node combine(const Cell& cell, const Side& a, const Side& b) {
    ++stats_.cells_visited;
    if (focus_ && cell.level < max_depth_ && focus_->holds(cell)) return subdivide(cell, a, b, std::nullopt, true);
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

  /// Both operands' sign grids over a gray pair's cell, computed on first use.
  using PairGrids = std::optional<std::pair<SignGrid, SignGrid>>;
  const std::pair<SignGrid, SignGrid>& grids(PairGrids& pg, const Cell& cell, const Side& a, const Side& b) {
    if (!pg) pg.emplace(sign_grid(a_, a, cell), sign_grid(b_, b, cell));
    return *pg;
  }

  /// `pg`: the grids if gray_cell computed them already (both sides gray).
  /// `keep`: no collapse of uniform children (a focus cell must stay split).
  Node subdivide(const Cell& cell, const Side& a, const Side& b, PairGrids pg = std::nullopt, bool keep = false) {
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
    if (parallel_splits_ > 0 && cell.level + kMinTaskLevels < max_depth_ && a.kind == Side::Internal &&
        b.kind == Side::Internal && busy_children(a, b) >= 2)
      kids = split_in_tasks(cell, a, b);
    else {
      // Only a gray side's grid is read.
      const SignGrid ga = pg ? pg->first : a.kind == Side::Gray ? sign_grid(a_, a, cell) : SignGrid{};
      const SignGrid gb = pg ? pg->second : b.kind == Side::Gray ? sign_grid(b_, b, cell) : SignGrid{};
      for (int c = 0; c < 8; ++c)
        kids[c] = combine(cell.child(c), child_side(a_, a, cell, c, ga), child_side(b_, b, cell, c, gb));
    }
    bool all_uniform = true;
    for (int c = 0; c < 8; ++c) {
      out_.set(first + c, kids[c]);
      all_uniform = all_uniform && (kids[c].kind == CellKind::White || kids[c].kind == CellKind::Black) &&
                    kids[c].kind == kids[0].kind;
    }
    if (all_uniform && !keep) return uniform(kids[0].kind == CellKind::Black);  // collapse
    return Node{first, CellKind::Internal, 0, 0, 0};
  }

  /// Children of an internal pair where neither operand is uniform: where the work is.
  int busy_children(const Side& a, const Side& b) const {
    const auto uniform_node = [](const Node& n) { return n.kind == CellKind::White || n.kind == CellKind::Black; };
    int busy = 0;
    for (int c = 0; c < 8; ++c)
      busy += !uniform_node(a_.t.nodes[a_.t.nodes[a.node].index + c]) &&
              !uniform_node(b_.t.nodes[b_.t.nodes[b.node].index + c]);
    return busy;
  }

  /// Each child is a task with its own fragment and caches, merged in child order: the same
  /// bytes whether the tasks run in parallel or not.
  std::array<Node, 8> split_in_tasks(const Cell& cell, const Side& a, const Side& b) {
    std::array<Node, 8> kids;
    std::array<Fragment, 8> frags;
    std::array<CombineCounts, 8> sub_stats;
    auto task = [&](int c) {
      Operand ca(a_.t, a_.stamps, a_.pc, stamp_), cb(b_.t, b_.stamps, b_.pc, stamp_);
      // A second pass's outer views are shared: that pass runs without tasks in parallel.
      ca.outer = a_.outer, ca.held = a_.held, ca.inner = a_.inner;
      cb.outer = b_.outer, cb.held = b_.held, cb.inner = b_.inner;
      Combiner sub(frags[c], ca, cb, op_, options_, max_depth_, stamp_, parallel_splits_ - 1, parallel_, focus_,
                   sub_stats[c]);
      // Both sides internal here: no sign grid is read.
      kids[c] = sub.combine(cell.child(c), child_side(ca, a, cell, c, {}), child_side(cb, b, cell, c, {}));
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
    // The same PIC and the same surface in both operands (A op A, or untouched common
    // history): nothing to compute.
    if (a.real && b.real && a.signs == b.signs &&
        a_.t.vertices[a_.t.nodes[a.node].index] == b_.t.vertices[b_.t.nodes[b.node].index] &&
        same_surface(a_, a, b_, b)) {
      if (op_ == CsgOp::Subtract) return uniform(false);
      return copy_side(a_, a, cell, false, true);
    }
    const bool at_cap = cell.level >= max_depth_;
    PairGrids pg;
    if (!unresolved(a) && !unresolved(b)) {
      const EdgeVerdict ev = edge_verdict(op_, a_, a, b_, b, cell);
      if (!ev.must_split)
        if (const std::optional<Node> leaf = gray_leaf(cell, a, b, sr, ev, at_cap, pg)) return *leaf;
    }
    if (at_cap) {
      if (!unresolved(a) && !unresolved(b)) {
        // A feature thinner than the cell: the clean-up gives it lattice points; the leaves
        // around them must be finest cells (a contact).
        thin_.clear();
        thin_feature_hints(op_, a_, a, b_, b, cell, sr, error_, thin_);
        for (const SignHint& h : thin_)
          if (h.kind == SignHint::Kind::Thin) {
            out_.contact(cell);
            break;
          }
        for (const SignHint& h : thin_) out_.hint(h);
      }
      if (sr == 0 || sr == 0xff) return uniform(sr != 0);
      const CellQefs q = cell_qefs(a_, a, b_, b, cell);
      if (!one_component(sr)) {
        out_.contact(cell);
        if (const std::optional<SignHint> h = sign_hint(op_, a_, b_, cell, sr)) out_.hint(*h);
      }
      return out_.gray(cell, sr, cell_vertex(q.sum, cell, sr, true).position, kFlagCapped);
    }
    return subdivide(cell, a, b, pg);
  }

  /// The cell as one leaf, if it may be one: triangle-fan culling where the surfaces do not
  /// meet, Q_sum's vertex where they do (paper eq. 3); nothing when the cell must split.
  std::optional<Node> gray_leaf(const Cell& cell, const Side& a, const Side& b, uint8_t sr, const EdgeVerdict& ev,
                                bool at_cap, PairGrids& pg) {
    const bool simple = at_cap || [&] {
      const auto& [ga, gb] = grids(pg, cell, a, b);
      return refinement_is_simple(op_, ga, gb);
    }();
    if (!simple) return std::nullopt;
    // The result as uniform, or as one operand's cell, where the signs agree (and the caller
    // allows that case).
    const uint8_t sb_seen = op_ == CsgOp::Subtract ? uint8_t(~b.signs) : b.signs;
    const auto culled = [&](bool uniform_ok, bool a_ok, bool b_ok) -> std::optional<Node> {
      if (uniform_ok && (sr == 0 || sr == 0xff)) return uniform(sr != 0);
      if (a_ok && sr == a.signs) return copy_side(a_, a, cell, false, true);
      if (b_ok && sr == sb_seen) return copy_side(b_, b, cell, op_ == CsgOp::Subtract, false);
      return std::nullopt;
    };
    // The surfaces do not meet here: the result is what the visible operand says.
    if (!surfaces_meet(a_, a, b_, b, cell))
      return culled(!ev.vis_a && !ev.vis_b, ev.vis_a && !ev.vis_b, ev.vis_b && !ev.vis_a);
    // They coincide: one operand's face or none.
    if (surfaces_coincide(a_, a, b_, b, cell))
      if (std::optional<Node> n = culled(true, true, true)) return n;
    // Q_sum = Q_A + Q_B minimized from the average of the two vertices.
    const CellQefs q = cell_qefs(a_, a, b_, b, cell);
    const Vec3 va = operand_vertex(a_, a, q.a, cell), vb = operand_vertex(b_, b, q.b, cell);
    const Vec3 seed{(va[0] + vb[0]) / 2, (va[1] + vb[1]) / 2, (va[2] + vb[2]) / 2};
    const Vec3 lo = cell.min_unit(), hi{lo[0] + cell.size(), lo[1] + cell.size(), lo[2] + cell.size()};
    Qef::Solution sol = q.sum.solve_in_box(seed, lo, hi);
    if (!inside_cell(sol.position, cell)) sol = cell_vertex(q.sum, cell, sr, true);
    sol = sharpen(q.sum, cell, sr, sol, seed, true, error_);
    if (sol.error < error_ && inside_cell(sol.position, cell) && one_component(sr) &&
        feature_is_local(a_, b_, cell, sol.position, error_, scratch_))
      return out_.gray(cell, sr, sol.position, 0);
    return std::nullopt;
  }

  FragmentWriter out_;
  Operand& a_;
  Operand& b_;
  CsgOp op_;
  const CsgOptions& options_;
  double error_;
  int max_depth_;
  uint32_t stamp_;
  int parallel_splits_;
  bool parallel_;
  const FocusCells* focus_;  // cells to split down to the finest level whatever they hold
  CombineCounts& stats_;
  std::vector<uint32_t> scratch_;
  std::vector<SignHint> thin_;
};

}  // namespace

namespace {

/// How to take back a fragment landed in A: the sizes before, and the slots it overwrote.
struct Landing {
  size_t nodes = 0, vertices = 0, stamps = 0;
  std::vector<std::tuple<uint32_t, Node, uint32_t>> slots;  // slot, node before, stamp before

  void undo(Octree& a, Stamps& sa) const {
    for (auto it = slots.rbegin(); it != slots.rend(); ++it) {
      a.nodes[std::get<0>(*it)] = std::get<1>(*it);
      sa[std::get<0>(*it)] = std::get<2>(*it);
    }
    a.nodes.resize(nodes);
    a.vertices.resize(vertices);
    sa.resize(stamps);
  }
};

/// Writes the fragment into A: the new nodes land after A's, then A's own slots.
Landing land(Octree& a, Stamps& sa, const Fragment& f, const Node& root, uint32_t stamp) {
  Landing l{a.nodes.size(), a.vertices.size(), sa.size(), {}};
  const auto node_base = static_cast<uint32_t>(a.nodes.size()), vertex_base = static_cast<uint32_t>(a.vertices.size());
  for (const Node& n : f.nodes) a.nodes.push_back(Fragment::relocate(n, node_base, vertex_base));
  a.vertices.insert(a.vertices.end(), f.vertices.begin(), f.vertices.end());
  // The new nodes are this operation's, stamped for the clean-up; but inside a copied subtree,
  // off its root cell's faces, every neighbour is the source's own, as it was there: nothing
  // for the clean-up to find that the source did not have (a union of disjoint parts no longer
  // cleans each part whole).
  sa.resize(a.nodes.size(), stamp);
  for (size_t k = 0; k < f.inside_copy.size(); ++k)
    if (f.inside_copy[k]) sa[node_base + k] = 0;
  // A slot written here is part of the result this operation made, even where the tag step
  // left it unstamped (A uniform there, B's subtree copied in): the clean-up must see it, or
  // B's own defects there pass into the result unchecked (an island a sampled tool carries —
  // a small sphere's pole piercing a lattice plane beside a coarse leaf — became a sculpting
  // stroke's pinched vertex). Cleaning these parts too costs sculpting about 2-3 ms a stroke.
  for (const auto& [slot, n] : f.pending) {
    l.slots.emplace_back(slot, a.nodes[slot], sa[slot]);
    a.nodes[slot] = Fragment::relocate(n, node_base, vertex_base);
    sa[slot] = stamp;
  }
  l.slots.emplace_back(0, a.nodes[0], sa[0]);
  a.nodes[0] = Fragment::relocate(root, node_base, vertex_base);
  return l;
}

/// The corners of the contact cells, each once.
std::vector<Lat> contact_corners(const std::vector<Cell>& contacts) {
  std::vector<Lat> out;
  for (const Cell& c : contacts)
    for (int k = 0; k < 8; ++k) out.push_back(c.corner(k));
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

/// The gray leaves coarser than the finest level that hold one of the points, each once (a
/// uniform one flipped at a corner becomes gray with its vertex right next to that corner:
/// its surface stays at the point).
std::vector<LeafRef> coarse_gray_leaves_at(const Octree& a, const std::vector<Lat>& points, int depth) {
  std::vector<LeafRef> out;
  for (const Lat& p : points)
    for (int o = 0; o < 8; ++o) {
      Lat q;
      if (!octant_cell(p, o, q)) continue;
      const LeafRef l = leaf_at(a, q);
      if (l.cell.level >= depth || a.nodes[l.node].kind != CellKind::Gray) continue;
      bool seen = false;
      for (const LeafRef& x : out) seen = seen || x.node == l.node;
      if (!seen) out.push_back(l);
    }
  return out;
}

/// The lattice points on the boundaries of the `cells` (leaves of `t`) that other leaves of `t`
/// have as corners.
KeyBits corners_held_around(const Octree& t, const std::vector<LeafRef>& cells) {
  std::vector<uint32_t> recombined;
  for (const LeafRef& c : cells) recombined.push_back(c.node);
  std::sort(recombined.begin(), recombined.end());
  KeyBits held;
  std::vector<LeafRef> touching;
  for (const LeafRef& c : cells) {
    const int64_t s = c.cell.span();
    const Lat lo = c.cell.lat, hi{lo[0] + s, lo[1] + s, lo[2] + s};
    touching.clear();
    leaves_touching(t, 0, Cell{}, lo, hi, kMaxLevel, touching);
    for (const LeafRef& l : touching) {
      if (std::binary_search(recombined.begin(), recombined.end(), l.node)) continue;
      for (int k = 0; k < 8; ++k) {
        const Lat q = l.cell.corner(k);
        if (c.cell.holds(q)) held.insert(lattice_key(q), true);
      }
    }
  }
  return held;
}

}  // namespace

/// Combines the stamped cells into A. Every task reads A as it was; the new nodes land after
/// A's, and A's own slots are written only once all tasks are done. Where the result has
/// contacts (finest cells of two components, which the clean-up must settle by changing a
/// sign) next to coarser leaves, the combine runs again with the cells around them split down
/// to the finest level, from the operands' own surfaces.
std::vector<SignHint> combine_stamped(Octree& a, Stamps& sa, const Octree& b, const Stamps& sb, const PartialContour& pa,
                                      const PartialContour& pb, CsgOp op, const CsgOptions& options, int depth,
                                      uint32_t stamp, CsgStats& stats,
                                      const std::function<void(const std::vector<Lat>&)>& prepare_focus) {
  const auto run = [&](const FocusCells* focus, Fragment& f) {
    Operand oa(a, sa, pa, stamp), ob(b, sb, pb, stamp);
    CombineCounts counts;
    Combiner comb(f, oa, ob, op, options, depth, stamp, kParallelSplits, options.parallel, focus, counts);
    const Node root = comb.run();
    stats.cells_visited += counts.cells_visited;
    stats.gray_pairs += counts.gray_pairs;
    stats.forced_subdivisions += counts.forced_subdivisions;
    return root;
  };
  stats.cells_visited = stats.gray_pairs = stats.forced_subdivisions = 0;
  Fragment f;
  const Node root = run(nullptr, f);
  const Landing landed = land(a, sa, f, root, stamp);
  if (f.contacts.empty()) return std::move(f.hints);
  const std::vector<Lat> corners = contact_corners(f.contacts);
  const std::vector<LeafRef> coarse = coarse_gray_leaves_at(a, corners, depth);
  if (coarse.empty()) return std::move(f.hints);
  // Those leaves' cells combined again from A as it was, split down to the finest level
  // around the contacts; the rest of the result stays as it is, and with it the signs its
  // leaves hold on those cells' boundaries. The focus stamps more cells and grows the partial
  // contours, so there the operands are asked as the first pass saw them.
  const KeyBits held = corners_held_around(a, coarse);
  landed.undo(a, sa);
  const Stamps sa_first = sa, sb_first = sb;
  const PartialContour pa_first = pa, pb_first = pb;
  prepare_focus(corners);
  const FocusCells focus(corners, depth);
  Fragment again;
  std::vector<Node> roots;
  {
    Operand oa(a, sa, pa, stamp), ob(b, sb, pb, stamp);
    Operand oa_first(a, sa_first, pa_first, stamp), ob_first(b, sb_first, pb_first, stamp);
    oa.outer = &oa_first, ob.outer = &ob_first;
    oa.held = ob.held = &held;
    CombineCounts counts;
    Combiner comb(again, oa, ob, op, options, depth, stamp, 0, false, &focus, counts);
    for (const LeafRef& l : coarse) {
      oa.inner = ob.inner = l.cell;
      roots.push_back(comb.run_at(l.cell));
    }
    stats.cells_visited += counts.cells_visited;
    stats.gray_pairs += counts.gray_pairs;
    stats.forced_subdivisions += counts.forced_subdivisions;
  }
  land(a, sa, f, root, stamp);
  // The recombined cells' roots go where the coarse leaves were (the same slots: landing is
  // deterministic). Their nodes land after the result's.
  const auto node_base = static_cast<uint32_t>(a.nodes.size()), vertex_base = static_cast<uint32_t>(a.vertices.size());
  for (const Node& n : again.nodes) a.nodes.push_back(Fragment::relocate(n, node_base, vertex_base));
  a.vertices.insert(a.vertices.end(), again.vertices.begin(), again.vertices.end());
  sa.resize(a.nodes.size(), stamp);
  for (const auto& [slot, n] : again.pending) {
    a.nodes[slot] = Fragment::relocate(n, node_base, vertex_base);
    sa[slot] = stamp;
  }
  for (size_t i = 0; i < coarse.size(); ++i) {
    a.nodes[coarse[i].node] = Fragment::relocate(roots[i], node_base, vertex_base);
    sa[coarse[i].node] = stamp;
  }
  f.hints.insert(f.hints.end(), again.hints.begin(), again.hints.end());
  return std::move(f.hints);
}

}  // namespace pic::detail

// Stamping the overlap of two operands (paper 5.2.1) and building their partial contours.
// See stamp.h.
#include "csg/stamp.h"
#include "contour/triangulate.h"

namespace pic::detail {

namespace {

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
                         std::vector<uint8_t>& out) {
  const int64_t s = cell.span();
  int bounds = 0;
  for (int k = 0; k < 3; ++k) {
    if (cell.lat[k] > hi[k] || cell.lat[k] + s < lo[k]) return;
    auto holds = [&](int64_t x) { return cell.lat[k] <= x && x <= cell.lat[k] + s; };
    bounds += holds(lo[k]) || holds(hi[k]);
  }
  if (bounds < 2) return;
  out[node] = 1;
  const Node& n = t.nodes[node];
  if (n.kind == CellKind::Internal)
    for (int c = 0; c < 8; ++c) mark_touching_edges(t, n.index + c, cell.child(c), lo, hi, out);
}

/// The nodes around the edges of the stamped gray leaves coarser than the finest level: signs
/// inside such a leaf come from crossing parity with the contour triangles in its cell, and a
/// dual polygon of finer neighbours (none of them stamped) can cut through a corner of that
/// cell. Without those triangles the parity is wrong over part of the cell (a box's coarse
/// leaf took a cone's tip for outside the box: a stray shell 4 cells from the exact result).
/// Only cells at the leaf's edges matter: a polygon's vertices lie in their
/// cells, and cells that touch only the inside of one face all lie beyond that face's plane,
/// and so do their polygons. A flag per node (none when no such leaf is stamped): a hash set
/// of the nodes along the leaves' edges was slower.
std::vector<uint8_t> around_coarse_leaves(const Octree& t, const Stamps& stamps, uint32_t stamp) {
  std::vector<uint8_t> out;
  std::function<void(uint32_t, const Cell&)> walk = [&](uint32_t node, const Cell& cell) {
    if (stamps[node] != stamp) return;
    const Node& n = t.nodes[node];
    if (n.kind == CellKind::Internal) {
      for (int c = 0; c < 8; ++c) walk(n.index + c, cell.child(c));
    } else if (n.kind == CellKind::Gray && cell.level < t.max_depth) {
      if (out.empty()) out.assign(t.nodes.size(), 0);
      mark_touching_edges(t, 0, Cell{}, cell.lat, cell.corner(7), out);
    }
  };
  walk(0, Cell{});
  return out;
}

/// The partial contour: dual polygons around stamped cells and around the edges of stamped
/// coarse leaves, indexed for box queries. The second kind are the operand's surface as much
/// as the first: a parity walk needs them, and so does the QEF of a cell that a coarse leaf
/// is resampled into when such a polygon is all the surface it holds (a sphere's flat facet
/// in a coarse leaf beside an unstamped one: with only the stamped leaves' polygons, a
/// resampled cell had its sign change but no plane, and its vertex sat 9 cells off the facet).
}  // namespace

void partial_contour(const Octree& t, const Stamps& stamps, uint32_t stamp, PartialContour& x) {
  const std::vector<uint8_t> around = around_coarse_leaves(t, stamps, stamp);
  contour_of(t, [&](uint32_t n) { return stamps[n] == stamp || (!around.empty() && around[n] != 0); }, x);
}

size_t stamp_holding(const Octree& t, Stamps& stamps, uint32_t stamp, const std::vector<Lat>& points) {
  size_t fresh = 0;
  std::function<void(uint32_t, const Cell&, const Lat&)> walk = [&](uint32_t node, const Cell& cell, const Lat& p) {
    if (!cell.holds(p)) return;
    const Node& n = t.nodes[node];
    fresh += stamps[node] != stamp && n.kind == CellKind::Gray;
    stamps[node] = stamp;
    if (n.kind == CellKind::Internal)
      for (int c = 0; c < 8; ++c) walk(n.index + c, cell.child(c), p);
  };
  for (const Lat& p : points) walk(0, Cell{}, p);
  return fresh;
}

void contour_of(const Octree& t, const std::function<bool(uint32_t)>& active, PartialContour& x) {
  // The polygons first, then their triangles in parallel into a vector sized once: a
  // triangle is 272 bytes, and growing the vector one at a time copied them over and over.
  std::vector<std::array<Vec3, 4>> quads;
  std::vector<uint8_t> counts, rough;
  std::function<void(const DualPolygon&)> emit = [&](const DualPolygon& poly) {
    quads.push_back(poly.pos);
    counts.push_back(uint8_t(poly.count));
    bool capped = false;
    for (int k = 0; k < poly.count; ++k) capped = capped || (t.nodes[poly.leaf[k]].flags & kFlagCapped) != 0;
    rough.push_back(capped);
  };
  dual_walk(t, &active, emit);
  std::vector<uint32_t> first(quads.size() + 1, 0);
  for (size_t i = 0; i < quads.size(); ++i) first[i + 1] = first[i] + (counts[i] == 3 ? 1 : 2);
  const size_t base = x.tris.size();
  x.tris.resize(base + first.back());
  x.rough.resize(base + first.back());
  for (size_t i = 0; i < quads.size(); ++i)
    for (uint32_t k = first[i]; k < first[i + 1]; ++k) x.rough[base + k] = rough[i];
  tbb::parallel_for(size_t{0}, quads.size(), [&](size_t i) {
    const std::array<Vec3, 4>& q = quads[i];
    std::array<I3, 4> g;
    for (int k = 0; k < counts[i]; ++k) g[k] = to_grid(q[k]);
    ITri* out = x.tris.data() + base + first[i];
    if (counts[i] == 3) {
      *out = make_itri(g[0], g[1], g[2]);
      return;
    }
    for (const auto& tri : split_quad(q)) *out++ = make_itri(g[tri[0]], g[tri[1]], g[tri[2]]);
  });
  x.bvh.build(x.tris);
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

}  // namespace pic::detail

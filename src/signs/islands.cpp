// The island pass: finer points on a coarse gray leaf's faces and edges made to look like one
// cell's face. See consistency.h (remove_islands).
#include "signs/consistency.h"
#include "signs/leaf_walks.h"
#include "geometry/union_find.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <memory>
#include <vector>

namespace pic::detail {

using Lat = std::array<int64_t, 3>;

namespace {

/// Whether lattice point p, of sign sp, on the boundary of gray leaf `big` (not one of its
/// corners) disagrees with all of big's corners on the smallest face or edge through it.
bool is_island(const Node& big, const Cell& cell, const Lat& p, bool sp) {
  const int64_t sz = cell.span();
  bool all_differ = true;
  int seen = 0;
  for (int c = 0; c < 8; ++c) {
    bool on = true;
    for (int a = 0; a < 3; ++a) {
      const bool at_lo = p[a] == cell.lat[a], at_hi = p[a] == cell.lat[a] + sz;
      if (at_lo && ((c >> a) & 1)) on = false;
      if (at_hi && !((c >> a) & 1)) on = false;
    }
    if (!on) continue;
    ++seen;
    all_differ = all_differ && (((big.signs >> c) & 1) != 0) != sp;
  }
  return seen > 0 && seen < 8 && all_differ;
}

}  // namespace

namespace {

/// A leaf the island pass checks. Searches around it start from a near ancestor (found
/// through IslandSearch::parent) instead of the root.
struct PathLeaf {
  uint32_t node;
  Cell cell;
};

struct IslandSearch {
  const Octree& t;
  std::vector<PathLeaf> leaves;
  // Per node collect visited: its parent. Left uninitialised elsewhere (never read there), so
  // a pass over a small part of a big tree touches few of its pages.
  std::unique_ptr<uint32_t[]> parent;

  explicit IslandSearch(const Octree& tree) : t(tree), parent(new uint32_t[tree.nodes.size()]) {}

  /// The deepest ancestor of `l` whose cell holds the closed box [lo, hi] away from its
  /// boundary (`strict`) or anywhere inside it: every leaf meeting the box is below it.
  LeafRef start_for(const PathLeaf& l, const Lat& lo, const Lat& hi, bool strict) const {
    uint32_t node = l.node;
    for (int level = l.cell.level; level > 0; --level, node = parent[node]) {
      Cell c{level, l.cell.lat};
      const int64_t s = c.span();
      for (auto& x : c.lat) x -= x % s;
      bool inside = true;
      for (int k = 0; k < 3 && inside; ++k)
        inside = strict ? (c.lat[k] < lo[k] && hi[k] < c.lat[k] + s) : (c.lat[k] <= lo[k] && hi[k] <= c.lat[k] + s);
      if (inside) return {node, c};
    }
    return {0, Cell{}};
  }
  /// The node covering `target` (or the leaf above it), searched from `from`.
  LeafRef node_below(LeafRef from, const Cell& target) const {
    while (from.cell.level < target.level && t.nodes[from.node].kind == CellKind::Internal) {
      const int c = from.cell.child_toward(target.lat);
      from = {t.nodes[from.node].index + c, from.cell.child(c)};
    }
    return from;
  }

  void collect(uint32_t node, const Cell& cell, const std::function<bool(uint32_t)>* active) {
    if (active && !(*active)(node)) return;
    const Node& n = t.nodes[node];
    if (n.kind == CellKind::Internal) {
      for (int c = 0; c < 8; ++c) {
        parent[n.index + c] = node;
        collect(n.index + c, cell.child(c), active);
      }
    } else if (n.kind == CellKind::Gray && cell.level >= t.max_depth - 5) {
      // Islands are features near the finest cell size, next to leaves up to 5 levels up (the
      // teapot had one on a leaf 5 levels up; coarser faces cost more than they find).
      leaves.push_back({node, cell});
    }
  }
};

}  // namespace

namespace {

/// The face's plane, its in-face axes u and v, and its rectangle [lo, hi] (lo[d] = hi[d] =
/// plane); points on it are keyed by their in-face coordinates.
struct FaceFrame {
  int d, side, u, v;
  Lat lo, hi;
  uint8_t signs;  // the coarse leaf's corner signs

  FaceFrame(const LeafRef& big, int f, uint8_t leaf_signs)
      : d(f / 2), side(f % 2), u(d == 0 ? 1 : 0), v(d == 2 ? 1 : 2), lo(big.cell.lat), hi(big.cell.corner(7)),
        signs(leaf_signs) {
    lo[d] = hi[d] = big.cell.lat[d] + side * big.cell.span();
  }
  uint64_t key(const Lat& q) const { return uint64_t(q[u]) << 32 | uint64_t(q[v]); }
  Lat lat_of(uint64_t k) const {
    Lat q;
    q[d] = lo[d];
    q[u] = int64_t(k >> 32);
    q[v] = int64_t(k & 0xffffffffu);
    return q;
  }
  /// The coarse leaf's sign at the face's corner (cu, cv).
  bool corner_sign(int cu, int cv) const { return ((signs >> ((side << d) | (cu << u) | (cv << v))) & 1) != 0; }
};

/// Buffers face_flips reuses from face to face.
struct FaceScratch {
  std::vector<LeafRef> leaves;
  std::vector<std::pair<uint64_t, bool>> pts;  // sorted by key
  std::vector<std::pair<uint64_t, uint64_t>> links;
  std::vector<size_t> run;
  std::vector<char> flipped, anchored;
  std::vector<char> original;  // the points' signs as collected, before the passes
  UnionFind regions{0};
  std::vector<std::pair<Lat, bool>> flips;  // point, sign to give it

  size_t index_of(uint64_t k) const {
    return size_t(std::lower_bound(pts.begin(), pts.end(), std::pair{k, false}) - pts.begin());
  }
};

/// The points the finer leaves across the face show on it, with their signs, and links along
/// the edges of those leaves' faces (which join a region once the edge pass has set signs).
/// False when the node across the face is not subdivided (nothing finer to see).
bool collect_face_points(const Octree& t, const LeafRef& big, const FaceFrame& fr, FaceScratch& s) {
  const int d = fr.d, u = fr.u, v = fr.v;
  const int64_t span = big.cell.span();
  Cell across = big.cell;
  across.lat[d] += fr.side ? span : -span;
  if (across.lat[d] < 0 || across.lat[d] >= (int64_t{1} << kMaxLevel)) return false;
  const LeafRef n = node_at(t, across);
  if (n.cell.level < across.level || t.nodes[n.node].kind != CellKind::Internal) return false;
  s.leaves.clear();
  leaves_touching(t, n.node, n.cell, fr.lo, fr.hi, kMaxLevel, s.leaves);
  s.pts.clear();
  s.links.clear();
  for (const LeafRef& l : s.leaves) {
    if (l.cell.level <= big.cell.level) continue;
    // On the far side of the plane, with a face inside the rectangle.
    const int64_t ls = l.cell.span();
    const int touching = fr.side ? 0 : 1;  // which of its own sides lies on the plane
    if (l.cell.lat[d] + touching * ls != fr.lo[d]) continue;
    if (l.cell.lat[u] < fr.lo[u] || l.cell.lat[u] + ls > fr.hi[u] || l.cell.lat[v] < fr.lo[v] ||
        l.cell.lat[v] + ls > fr.hi[v])
      continue;
    const uint8_t sg = signs_of(t.nodes[l.node]);
    std::array<std::pair<uint64_t, bool>, 4> c4;
    for (int k = 0; k < 4; ++k) {
      const int c = (touching << d) | ((k & 1) << u) | ((k >> 1) << v);
      c4[k] = {fr.key(l.cell.corner(c)), ((sg >> c) & 1) != 0};
      s.pts.push_back(c4[k]);
    }
    for (const auto& [a, b] : {std::pair{0, 1}, std::pair{2, 3}, std::pair{0, 2}, std::pair{1, 3}})
      s.links.push_back({c4[a].first, c4[b].first});
  }
  std::sort(s.pts.begin(), s.pts.end());
  s.pts.erase(std::unique(s.pts.begin(), s.pts.end(), [](const auto& x, const auto& y) { return x.first == y.first; }),
              s.pts.end());
  return !s.pts.empty();
}

/// Along each edge of the face, the points in order between the coarse leaf's two corners
/// take the first corner's sign before one cut and the second's after it, at the cut needing
/// the fewest flips (marked in s.flipped).
void settle_face_edges(const FaceFrame& fr, FaceScratch& s) {
  auto& pts = s.pts;
  for (int e = 0; e < 4; ++e) {
    const int along = e < 2 ? fr.u : fr.v, across = along == fr.u ? fr.v : fr.u;
    const int64_t fixed = (e & 1) ? fr.hi[across] : fr.lo[across];
    std::vector<size_t>& run = s.run;
    run.clear();
    for (size_t i = 0; i < pts.size(); ++i) {
      const Lat q = fr.lat_of(pts[i].first);
      if (q[across] == fixed && q[along] > fr.lo[along] && q[along] < fr.hi[along]) run.push_back(i);
    }
    if (run.empty()) continue;
    std::sort(run.begin(), run.end(),
              [&](size_t x, size_t y) { return fr.lat_of(pts[x].first)[along] < fr.lat_of(pts[y].first)[along]; });
    const int fa = across == fr.u ? int(e & 1) : 0, fb = across == fr.v ? int(e & 1) : 0;
    const bool s0 = fr.corner_sign(fa, fb);
    const bool s1 = fr.corner_sign(along == fr.u ? 1 : fa, along == fr.v ? 1 : fb);
    size_t best_cut = 0, best = SIZE_MAX, before = 0, after = 0;
    for (size_t i : run) after += pts[i].second != s1;
    for (size_t cut = 0; cut <= run.size(); ++cut) {
      if (before + after < best) {
        best = before + after;
        best_cut = cut;
      }
      if (cut < run.size()) {
        before += pts[run[cut]].second != s0;
        after -= pts[run[cut]].second != s1;
      }
    }
    for (size_t r = 0; r < run.size(); ++r) {
      const bool want = r < best_cut ? s0 : s1;
      if (pts[run[r]].second != want) {
        pts[run[r]].second = want;
        s.flipped[run[r]] = 1;
      }
    }
  }
}

/// Regions of one sign on the face (union-find over same-sign links, edge flips applied)
/// that reach no face corner of their sign are flipped whole (marked in s.flipped).
void flip_stray_regions(const FaceFrame& fr, FaceScratch& s) {
  const auto& pts = s.pts;
  UnionFind& regions = s.regions;
  regions.reset(pts.size());
  for (const auto& [a, b] : s.links) {
    const size_t ia = s.index_of(a), ib = s.index_of(b);
    if (pts[ia].second == pts[ib].second) regions.join(ia, ib);
  }
  std::vector<char>& anchored = s.anchored;
  anchored.assign(pts.size(), 0);
  for (int c = 0; c < 4; ++c) {
    Lat q = fr.lo;
    if (c & 1) q[fr.u] = fr.hi[fr.u];
    if (c & 2) q[fr.v] = fr.hi[fr.v];
    const size_t i = s.index_of(fr.key(q));
    if (i < pts.size() && pts[i].first == fr.key(q) && pts[i].second == fr.corner_sign(c & 1, c >> 1))
      anchored[regions.root(i)] = 1;
  }
  for (size_t i = 0; i < pts.size(); ++i)
    if (!anchored[regions.root(i)]) s.flipped[i] ^= 1;
}

/// Face `f` (axis f / 2, high side if f % 2) of a coarse gray leaf, as the finer leaves
/// across it see it. Dual contouring gives the coarse leaf one vertex, so what those leaves
/// show on the face must look like a face of one cell:
/// - along each edge of the face the sign changes at most once (never when its ends agree),
///   else the edge gets several dual polygons through the same coarse vertices (a doubled
///   sheet, non-manifold edges);
/// - every connected region of one sign on the face reaches a corner of the face with that
///   sign, else the coarse vertex gets a second fan of polygons (a pinched, non-manifold
///   vertex).
/// Returns the lattice points to flip, with their new sign (as few as possible along edges;
/// whole stray regions on the face).
const std::vector<std::pair<Lat, bool>>& face_flips(const Octree& t, const LeafRef& big, int f, FaceScratch& s) {
  s.flips.clear();
  const FaceFrame fr(big, f, signs_of(t.nodes[big.node]));
  if (!collect_face_points(t, big, fr, s)) return s.flips;
  // The usual case: every point agrees with the face's four corners. The finer leaves tile the
  // face, so their points are one region holding the corners, and no edge changes sign.
  const bool s0 = fr.corner_sign(0, 0);
  const auto agrees = [&](const std::pair<uint64_t, bool>& p) { return p.second == s0; };
  if (fr.corner_sign(0, 1) == s0 && fr.corner_sign(1, 0) == s0 && fr.corner_sign(1, 1) == s0 &&
      std::all_of(s.pts.begin(), s.pts.end(), agrees))
    return s.flips;
  s.flipped.assign(s.pts.size(), 0);
  s.original.resize(s.pts.size());
  for (size_t i = 0; i < s.pts.size(); ++i) s.original[i] = s.pts[i].second;
  settle_face_edges(fr, s);
  flip_stray_regions(fr, s);
  for (size_t i = 0; i < s.pts.size(); ++i)
    if (s.flipped[i]) s.flips.push_back({fr.lat_of(s.pts[i].first), !s.original[i]});
  return s.flips;
}

/// A face of a coarse gray leaf to check with face_flips once the point islands are gone.
using CoarseFace = std::pair<LeafRef, int>;

/// Faces of `big` that meet the box [lo, hi].
void faces_meeting(const LeafRef& big, const Lat& lo, const Lat& hi, std::vector<CoarseFace>& faces) {
  const int64_t s = big.cell.span();
  for (int f = 0; f < 6; ++f) {
    const int d = f / 2;
    const int64_t plane = big.cell.lat[d] + (f % 2) * s;
    bool meets = lo[d] <= plane && plane <= hi[d];
    for (int k = 0; k < 3 && meets; ++k)
      if (k != d) meets = big.cell.lat[k] < hi[k] && lo[k] < big.cell.lat[k] + s;
    if (meets) faces.push_back({big, f});
  }
}

/// A fine active leaf's corners against the coarser gray leaves around them (an old coarse
/// leaf next to new fine ones): a corner that is an island on one of them is flipped. The
/// coarse leaves' faces are queued.
template <class Flip>
void fine_corners_on_coarse_leaves(const Octree& t, const IslandSearch& search, const PathLeaf& l, Flip&& flip,
                                   std::vector<LeafRef>& near, std::vector<CoarseFace>& faces) {
  const Cell& cell = l.cell;
  // The coarser leaves around its corners (a leaf as fine or finer touching a corner has it
  // as a corner too): one descent for the cell's closed box, from the nearest ancestor that
  // holds it.
  near.clear();
  const Lat lo = cell.lat, hi = cell.corner(7);
  const LeafRef from = search.start_for(l, lo, hi, true);
  leaves_touching(t, from.node, from.cell, lo, hi, cell.level - 1, near);
  for (const LeafRef& big : near)
    if (t.nodes[big.node].kind == CellKind::Gray) faces_meeting(big, lo, hi, faces);
  for (int k = 0; k < 8; ++k) {
    const Lat p = cell.corner(k);
    const bool sp = (signs_of(t.nodes[l.node]) >> k) & 1;
    for (const LeafRef& big : near) {
      if (t.nodes[big.node].kind != CellKind::Gray || big.cell.corner_index(p) >= 0) continue;
      bool touches = true;
      for (int a = 0; a < 3 && touches; ++a)
        touches = p[a] >= big.cell.lat[a] && p[a] <= big.cell.lat[a] + big.cell.span();
      if (!touches || !is_island(t.nodes[big.node], big.cell, p, sp)) continue;
      flip(p, !sp);
      break;
    }
  }
}

/// An active coarse leaf against the finer leaves across its faces (a new coarse leaf next to
/// old fine ones): their corners on the shared face that are islands on it are flipped. The
/// leaf's faces with finer leaves across are queued.
template <class Flip>
void finer_corners_on_coarse_leaf(const Octree& t, const IslandSearch& search, const PathLeaf& l, Flip&& flip,
                                  std::vector<CoarseFace>& faces) {
  constexpr int64_t kLimit = int64_t{1} << kMaxLevel;
  const uint32_t big = l.node;
  const Cell& cell = l.cell;
  const int64_t sz = cell.span();
  for (int d = 0; d < 3; ++d)
    for (int side = 0; side < 2; ++side) {
      Cell across = cell;
      across.lat[d] += side ? sz : -sz;
      if (across.lat[d] < 0 || across.lat[d] >= kLimit) continue;
      const Lat across_hi = across.corner(7);
      const LeafRef n = search.node_below(search.start_for(l, across.lat, across_hi, false), across);
      if (n.cell.level < cell.level || t.nodes[n.node].kind != CellKind::Internal) continue;
      if (t.nodes[big].kind == CellKind::Gray) faces.push_back({{big, cell}, 2 * d + side});
      const int64_t plane = side ? cell.lat[d] + sz : cell.lat[d];
      // Leaves of the finer side touching the shared face, and their corners on it.
      std::function<void(uint32_t, const Cell&)> visit = [&](uint32_t node, const Cell& c) {
        const Node& m = t.nodes[node];
        if (m.kind == CellKind::Internal) {
          for (int k = 0; k < 8; ++k) {
            const Cell ch = c.child(k);
            if (ch.lat[d] <= plane && ch.lat[d] + ch.span() >= plane) visit(m.index + k, ch);
          }
          return;
        }
        for (int k = 0; k < 8; ++k) {
          const Lat p = c.corner(k);
          if (p[d] != plane || cell.corner_index(p) >= 0) continue;
          const bool sp = (signs_of(m) >> k) & 1;
          if (is_island(t.nodes[big], cell, p, sp)) flip(p, !sp);
        }
      };
      visit(n.node, n.cell);
    }
}

}  // namespace

namespace {

/// Marks every node whose closed cell meets the closed lattice box [lo, hi].
void mark_meeting(const Octree& t, const Lat& lo, const Lat& hi, std::vector<uint8_t>& out) {
  for_each_node_meeting(t, 0, Cell{}, lo, hi, [&](uint32_t n) { out[n] = 1; });
}

/// Marks the nodes whose closed cell meets that of a leaf among `touched` (which holds every
/// node on the way down to each such leaf).
void mark_near_touched(const Octree& t, const std::vector<uint32_t>& touched, std::vector<uint8_t>& out) {
  std::vector<uint8_t> on(t.nodes.size(), 0);
  for (uint32_t n : touched) on[n] = 1;
  std::vector<LeafRef> leaves;
  auto walk = [&](auto&& self, uint32_t node, const Cell& cell) -> void {
    if (!on[node]) return;
    const Node& n = t.nodes[node];
    if (n.kind != CellKind::Internal) {
      leaves.push_back({node, cell});
      return;
    }
    for (int c = 0; c < 8; ++c) self(self, n.index + c, cell.child(c));
  };
  if (!touched.empty()) walk(walk, 0, Cell{});
  for (const LeafRef& l : leaves) mark_meeting(t, l.cell.lat, l.cell.corner(7), out);
}

}  // namespace

size_t remove_islands(Octree& t, const std::function<bool(uint32_t)>* active,
                      const std::function<void(uint32_t)>* touched, PinnedPoints* pinned, IslandRounds* rounds) {
  IslandSearch search(t);
  search.collect(0, Cell{}, active);
  // Where this round looks (empty: everywhere), and where its own flips have changed a stored
  // sign since it began (`moved`: the nodes whose closed cells meet a flipped point's leaves).
  std::vector<uint8_t> look;
  if (rounds && !rounds->seen.empty()) {
    look.assign(t.nodes.size(), 0);
    mark_near_touched(t, rounds->touched, look);
    for (const PathLeaf& l : search.leaves)
      if (l.node >= rounds->seen.size() || !rounds->seen[l.node]) look[l.node] = 1;
  }
  if (rounds) rounds->touched.clear();  // from here on: this round's flips, for the next one
  std::vector<uint8_t> moved(t.nodes.size(), 0);
  const auto looks_at = [&](uint32_t node) { return look.empty() || look[node] != 0 || moved[node] != 0; };
  size_t flipped = 0;
  auto flip = [&](const Lat& p, bool inside) {
    set_point_sign(t, p, inside, touched);
    if (pinned) pinned->insert(lattice_key(p));
    ++flipped;
    for (const Around& a : leaves_around(t, p)) mark_meeting(t, a.cell.lat, a.cell.corner(7), moved);
  };
  // Each pass first asks, in parallel and reading only, which of its leaves would flip a point
  // as the tree stands; then it runs in order over those and over the ones a flip since has
  // come near. A check whose inputs did not change finds what it found: nothing. So the flips
  // are those of one pass in order over every leaf, in the same order.
  std::vector<CoarseFace> faces;
  const auto pass = [&](auto&& eligible, auto&& check) {
    const size_t n = search.leaves.size();
    std::vector<uint8_t> hit(n, 0);
    tbb::enumerable_thread_specific<std::vector<CoarseFace>> queued;
    tbb::enumerable_thread_specific<std::vector<LeafRef>> nears;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 64), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i < r.end(); ++i) {
        const PathLeaf& l = search.leaves[i];
        if (!eligible(l) || !looks_at(l.node)) continue;
        bool would = false;
        check(l, [&](const Lat&, bool) { would = true; }, nears.local(), queued.local());
        hit[i] = would;
      }
    });
    for (const auto& q : queued) faces.insert(faces.end(), q.begin(), q.end());
    std::vector<LeafRef> near;
    for (size_t i = 0; i < n; ++i)
      if (eligible(search.leaves[i]) && (hit[i] || moved[search.leaves[i].node]))
        check(search.leaves[i], flip, near, faces);
  };
  // The finest leaves carry the islands.
  pass([&](const PathLeaf& l) { return l.cell.level >= t.max_depth - 1; },
       [&](const PathLeaf& l, auto&& f, std::vector<LeafRef>& near, std::vector<CoarseFace>& q) {
         fine_corners_on_coarse_leaves(t, search, l, f, near, q);
       });
  pass([&](const PathLeaf& l) { return l.cell.level < t.max_depth; },
       [&](const PathLeaf& l, auto&& f, std::vector<LeafRef>&, std::vector<CoarseFace>& q) {
         finer_corners_on_coarse_leaf(t, search, l, f, q);
       });
  // What the finer side shows on each coarse face (edges, stray regions), each face once. A
  // later round checks the faces queued now (some may be new) and those of earlier rounds
  // that something changed near, in the order a full round would.
  if (rounds) {
    if (!look.empty())
      for (const auto& f : faces) look[f.first.node] = 1;
    faces.insert(faces.end(), rounds->faces.begin(), rounds->faces.end());
  }
  std::sort(faces.begin(), faces.end(), [](const auto& x, const auto& y) {
    return x.first.node != y.first.node ? x.first.node < y.first.node : x.second < y.second;
  });
  faces.erase(std::unique(faces.begin(), faces.end(),
                          [](const auto& x, const auto& y) { return x.first.node == y.first.node && x.second == y.second; }),
              faces.end());
  const auto gray = [&](const CoarseFace& f) { return t.nodes[f.first.node].kind == CellKind::Gray; };
  std::vector<uint8_t> hit(faces.size(), 0);
  tbb::enumerable_thread_specific<FaceScratch> scratch;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, faces.size(), 64), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i < r.end(); ++i)
      if (gray(faces[i]) && looks_at(faces[i].first.node))
        hit[i] = !face_flips(t, faces[i].first, faces[i].second, scratch.local()).empty();
  });
  FaceScratch face_scratch;
  for (size_t i = 0; i < faces.size(); ++i) {
    if (!gray(faces[i]) || !(hit[i] || moved[faces[i].first.node])) continue;
    for (const auto& [p, inside] : face_flips(t, faces[i].first, faces[i].second, face_scratch)) flip(p, inside);
  }
  if (rounds) {
    rounds->seen.resize(t.nodes.size(), 0);
    for (const PathLeaf& l : search.leaves) rounds->seen[l.node] = 1;
    rounds->faces = std::move(faces);
  }
  return flipped;
}

}  // namespace pic::detail

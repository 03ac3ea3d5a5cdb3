// The coarse-boundary pass: a leaf with finer neighbours holds one vertex for every sign
// change the finer side shows on its faces and edges. That vertex is a manifold point of the
// contour only when the signs on the leaf's boundary -- its corners and every finer corner on
// its faces, joined by the minimal edges between them -- form one inside region and one
// outside region: then the sign changes around it make one closed curve, and the polygons
// around the vertex one disk. See consistency.h (erode_to_simple_boundaries).
#include "geometry/union_find.h"
#include "signs/consistency.h"
#include "signs/leaf_walks.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <unordered_map>
#include <vector>

namespace pic::detail {

namespace {

using Lat = std::array<int64_t, 3>;

/// The signs on a leaf's closed boundary, read at the corners of the leaves touching it.
struct Boundary {
  std::vector<Lat> points;
  std::vector<uint8_t> inside;
  std::vector<std::pair<uint32_t, uint32_t>> edges;  ///< minimal edges between the points
};

/// Per node: whether a gray leaf lies in its subtree.
std::vector<uint8_t> gray_below(const Octree& t) {
  std::vector<uint8_t> gray(t.nodes.size(), 0);
  auto walk = [&](auto&& self, uint32_t node) -> bool {
    const Node& n = t.nodes[node];
    bool any = n.kind == CellKind::Gray;
    if (n.kind == CellKind::Internal)
      for (int c = 0; c < 8; ++c) any = self(self, n.index + c) || any;
    gray[node] = any;
    return any;
  };
  walk(walk, 0);
  return gray;
}

/// Whether a gray leaf finer than `level` touches the closed lattice box [lo, hi].
bool finer_gray_touching(const Octree& t, const std::vector<uint8_t>& gray, uint32_t node, const Cell& cell,
                         const Lat& lo, const Lat& hi, int level) {
  if (!gray[node]) return false;
  const int64_t s = cell.span();
  for (int k = 0; k < 3; ++k)
    if (cell.lat[k] > hi[k] || cell.lat[k] + s < lo[k]) return false;
  const Node& n = t.nodes[node];
  if (n.kind != CellKind::Internal) return cell.level > level;
  for (int c = 0; c < 8; ++c)
    if (finer_gray_touching(t, gray, n.index + c, cell.child(c), lo, hi, level)) return true;
  return false;
}

Boundary boundary_of(const Octree& t, const LeafRef& l) {
  Boundary b;
  const Lat lo = l.cell.lat, hi = l.cell.corner(7);
  const auto on_boundary = [&](const Lat& p) {
    bool face = false;
    for (int k = 0; k < 3; ++k) {
      if (p[k] < lo[k] || p[k] > hi[k]) return false;
      face = face || p[k] == lo[k] || p[k] == hi[k];
    }
    return face;
  };
  thread_local std::vector<LeafRef> near;  // scratch, cleared here
  near.clear();
  leaves_touching(t, 0, Cell{}, lo, hi, kMaxLevel, near);
  // Leaves no finer than this one put only its own corners on its boundary; and around a
  // uniform leaf, finer uniform leaves tile its faces with its own sign (neighbours share
  // corners), so only a finer gray leaf can show it a sign change.
  const bool gray = t.nodes[l.node].kind == CellKind::Gray;
  if (std::none_of(near.begin(), near.end(), [&](const LeafRef& n) {
        return n.cell.level > l.cell.level && (gray || t.nodes[n.node].kind == CellKind::Gray);
      })) {
    b.points.resize(8);
    return b;
  }
  std::unordered_map<uint64_t, uint32_t> index;
  for (const LeafRef& n : near) {
    const uint8_t s = signs_of(t.nodes[n.node]);
    for (int c = 0; c < 8; ++c) {
      const Lat p = n.cell.corner(c);
      if (!on_boundary(p)) continue;
      if (index.emplace(lattice_key(p), uint32_t(b.points.size())).second) {
        b.points.push_back(p);
        b.inside.push_back((s >> c) & 1);
      }
    }
  }
  if (b.points.size() == 8) return b;  // no finer corner anywhere on it
  const auto find = [&](const Lat& p) {
    const auto it = index.find(lattice_key(p));
    return it == index.end() ? -1 : int64_t(it->second);
  };
  for (const LeafRef& n : near)
    for (int c = 0; c < 8; ++c)
      for (int axis = 0; axis < 3; ++axis) {
        if ((c >> axis) & 1) continue;
        const Lat p = n.cell.corner(c), q = n.cell.corner(c | (1 << axis));
        // On one face plane of the leaf (not only touching it at a point).
        bool in_face = false;
        for (int k = 0; k < 3; ++k)
          in_face = in_face || (k != axis && (p[k] == lo[k] || p[k] == hi[k]));
        if (!in_face) continue;
        const int64_t i = find(p), j = find(q);
        if (i < 0 || j < 0) continue;
        // A longer edge with a finer corner at its midpoint is covered by the finer edges.
        Lat mid = p;
        mid[axis] = (p[axis] + q[axis]) / 2;
        if ((q[axis] - p[axis]) % 2 == 0 && find(mid) >= 0) continue;
        b.edges.emplace_back(uint32_t(i), uint32_t(j));
      }
  return b;
}

/// An inside point whose removal works toward one region of each sign on the boundary, or -1
/// when there already is one of each.
int64_t point_to_erode(const Boundary& b, const Cell& cell) {
  const size_t n = b.points.size();
  UnionFind same(n);
  for (const auto& [i, j] : b.edges)
    if (b.inside[i] == b.inside[j]) same.join(i, j);
  std::vector<uint32_t> size(n, 0);
  for (size_t i = 0; i < n; ++i) ++size[same.root(i)];
  size_t regions[2] = {0, 0};
  for (size_t i = 0; i < n; ++i) regions[b.inside[i]] += same.root(i) == i;
  if (regions[0] <= 1 && regions[1] <= 1) return -1;
  // Prefer the points finer than the leaf (its own corners are what it was sampled with).
  const auto better = [&](int64_t best, size_t i) {
    if (best < 0) return true;
    const bool own = cell.corner_index(b.points[i]) >= 0, best_own = cell.corner_index(b.points[best]) >= 0;
    if (own != best_own) return best_own;
    return size[same.root(i)] < size[same.root(size_t(best))];
  };
  int64_t best = -1;
  if (regions[1] > 1) {
    // Two inside regions: the smallest goes.
    for (size_t i = 0; i < n; ++i)
      if (b.inside[i] && better(best, i)) best = int64_t(i);
    return best;
  }
  // One inside region around two outside ones: an inside point next to the smallest outside
  // region joins it to another.
  size_t smallest = n;
  for (size_t i = 0; i < n; ++i)
    if (!b.inside[i] && (smallest == n || size[same.root(i)] < size[same.root(smallest)])) smallest = i;
  const size_t hole = same.root(smallest);
  for (const auto& [i, j] : b.edges)
    for (const auto& [x, y] : {std::pair{i, j}, std::pair{j, i}})
      if (b.inside[x] && !b.inside[y] && same.root(y) == hole && better(best, x)) best = int64_t(x);
  return best;
}

}  // namespace

size_t erode_to_simple_boundaries(Octree& t, const std::function<bool(uint32_t)>* active,
                                  const std::function<void(uint32_t)>* touched) {
  std::vector<LeafRef> coarse;
  auto walk = [&](auto&& self, uint32_t node, const Cell& cell) -> void {
    if (active && !(*active)(node)) return;
    const Node& n = t.nodes[node];
    if (n.kind == CellKind::Internal) {
      for (int c = 0; c < 8; ++c) self(self, n.index + c, cell.child(c));
    } else if (cell.level < t.max_depth) {
      coarse.push_back({node, cell});
    }
  };
  walk(walk, 0, Cell{});
  // Around a uniform leaf, finer uniform leaves tile its faces with its own sign (neighbours
  // share corners): only a finer gray leaf can show it a sign change.
  const std::vector<uint8_t> gray = gray_below(t);
  std::erase_if(coarse, [&](const LeafRef& l) {
    return t.nodes[l.node].kind != CellKind::Gray &&
           !finer_gray_touching(t, gray, 0, Cell{}, l.cell.lat, l.cell.corner(7), l.cell.level);
  });
  // Which leaves need a flip, asked in parallel and reading only; then the flips in order,
  // each leaf looked at again until its boundary is simple (a flip for one leaf may mend or
  // break a neighbour's, which the next sweep of the caller's loop sees).
  std::vector<uint8_t> needs(coarse.size(), 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, coarse.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i < r.end(); ++i) {
      const Boundary b = boundary_of(t, coarse[i]);
      needs[i] = b.points.size() > 8 && point_to_erode(b, coarse[i].cell) >= 0;
    }
  });
  size_t flipped = 0;
  for (size_t i = 0; i < coarse.size(); ++i) {
    if (!needs[i]) continue;
    const LeafRef& l = coarse[i];
    for (;;) {
      const Boundary b = boundary_of(t, l);
      if (b.points.size() == 8) break;
      const int64_t p = point_to_erode(b, l.cell);
      if (p < 0) break;
      set_point_sign(t, b.points[size_t(p)], false, touched);
      ++flipped;
    }
  }
  return flipped;
}

}  // namespace pic::detail

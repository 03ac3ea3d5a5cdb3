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

/// Per node: which signs its subtree's leaves hold at their corners (bit 0: outside, bit 1:
/// inside).
std::vector<uint8_t> signs_below(const Octree& t) {
  std::vector<uint8_t> held(t.nodes.size(), 0);
  auto walk = [&](auto&& self, uint32_t node) -> uint8_t {
    const Node& n = t.nodes[node];
    uint8_t h = 0;
    if (n.kind == CellKind::Internal) {
      for (int c = 0; c < 8; ++c) h |= self(self, n.index + c);
    } else {
      const uint8_t s = signs_of(n);
      h = uint8_t((s != 0xff) | (s != 0) << 1);
    }
    held[node] = h;
    return h;
  };
  walk(walk, 0);
  return held;
}

/// Whether a leaf finer than `level` with a corner of sign `inside` touches the closed lattice
/// box [lo, hi]; stops at the first. `held` (signs_below; may be empty) prunes subtrees
/// without such a corner.
bool finer_sign_touching(const Octree& t, const std::vector<uint8_t>& held, bool inside, uint32_t node,
                         const Cell& cell, const Lat& lo, const Lat& hi, int level) {
  if (!held.empty() && !(held[node] & (inside ? 2 : 1))) return false;
  const int64_t s = cell.span();
  for (int k = 0; k < 3; ++k)
    if (cell.lat[k] > hi[k] || cell.lat[k] + s < lo[k]) return false;
  const Node& n = t.nodes[node];
  if (n.kind == CellKind::Internal) {
    for (int c = 0; c < 8; ++c)
      if (finer_sign_touching(t, held, inside, n.index + c, cell.child(c), lo, hi, level)) return true;
    return false;
  }
  const uint8_t signs = signs_of(n);
  return cell.level > level && (inside ? signs != 0 : signs != 0xff);
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
  if (std::none_of(near.begin(), near.end(), [&](const LeafRef& n) { return n.cell.level > l.cell.level; })) {
    b.points.resize(8);  // leaves no finer than this one put only its own corners there
    return b;
  }
  // Coarser and equal leaves put only this leaf's corners and edges there: it and the finer
  // leaves say everything.
  std::erase_if(near, [&](const LeafRef& n) { return n.cell.level <= l.cell.level && n.node != l.node; });
  thread_local std::vector<std::pair<uint64_t, uint8_t>> keyed;  // scratch, cleared here
  keyed.clear();
  for (const LeafRef& n : near) {
    const uint8_t s = signs_of(t.nodes[n.node]);
    for (int c = 0; c < 8; ++c) {
      const Lat p = n.cell.corner(c);
      if (on_boundary(p)) keyed.emplace_back(lattice_key(p), (s >> c) & 1);
    }
  }
  std::sort(keyed.begin(), keyed.end());
  keyed.erase(std::unique(keyed.begin(), keyed.end(), [](const auto& x, const auto& y) { return x.first == y.first; }),
              keyed.end());
  if (keyed.size() == 8) {  // no finer corner anywhere on it
    b.points.resize(8);
    return b;
  }
  b.points.reserve(keyed.size());
  for (const auto& [key, inside] : keyed) {
    const auto mask = (int64_t{1} << 21) - 1;
    b.points.push_back({int64_t(key) & mask, int64_t(key >> 21) & mask, int64_t(key >> 42) & mask});
    b.inside.push_back(inside);
  }
  const auto find = [&](const Lat& p) {
    const uint64_t key = lattice_key(p);
    const auto it = std::lower_bound(keyed.begin(), keyed.end(), std::pair<uint64_t, uint8_t>{key, 0});
    return it == keyed.end() || it->first != key ? -1 : int64_t(it - keyed.begin());
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
                                  const std::function<void(uint32_t)>* touched,
                                  const std::function<void(const Lat&)>* flipped) {
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
  // A uniform leaf's boundary is all its own sign unless a finer leaf with a corner of the
  // other sign touches it. Over a whole tree, per-subtree sign masks prune that search (a
  // partial run, a Boolean's clean-up, stays local without them).
  const std::vector<uint8_t> held = active ? std::vector<uint8_t>{} : signs_below(t);
  std::erase_if(coarse, [&](const LeafRef& l) {
    const CellKind kind = t.nodes[l.node].kind;
    return kind != CellKind::Gray && !finer_sign_touching(t, held, kind == CellKind::White, 0, Cell{}, l.cell.lat,
                                                          l.cell.corner(7), l.cell.level);
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
  size_t count = 0;
  for (size_t i = 0; i < coarse.size(); ++i) {
    if (!needs[i]) continue;
    const LeafRef& l = coarse[i];
    for (;;) {
      const Boundary b = boundary_of(t, l);
      if (b.points.size() == 8) break;
      const int64_t p = point_to_erode(b, l.cell);
      if (p < 0) break;
      set_point_sign(t, b.points[size_t(p)], false, touched);
      if (flipped) (*flipped)(b.points[size_t(p)]);
      ++count;
    }
  }
  return count;
}

}  // namespace pic::detail

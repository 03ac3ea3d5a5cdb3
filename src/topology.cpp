#include "topology.h"

#include "contour.h"
#include "sample.h"

#include <algorithm>
#include <array>
#include <unordered_map>
#include <vector>

namespace pic::detail {
namespace {

using Lat = std::array<int64_t, 3>;

struct LeafRef {
  uint32_t node;
  Cell cell;
};

/// The node covering cell `target`, or the leaf above it; `path` gets the nodes from the
/// root down to it.
LeafRef node_at(const Octree& t, const Cell& target, std::vector<uint32_t>* path = nullptr) {
  uint32_t node = 0;
  Cell cell;
  while (cell.level < target.level && t.nodes[node].kind == CellKind::Internal) {
    if (path) path->push_back(node);
    const int64_t h = cell.span() / 2;
    int c = 0;
    for (int k = 0; k < 3; ++k)
      if (target.lat[k] >= cell.lat[k] + h) c |= 1 << k;
    node = t.nodes[node].index + c;
    cell = cell.child(c);
  }
  if (path) path->push_back(node);
  return {node, cell};
}

/// The leaf containing the finest lattice cell whose min corner is `q`.
LeafRef leaf_at(const Octree& t, const Lat& q, std::vector<uint32_t>* path = nullptr) {
  return node_at(t, Cell{kMaxLevel, q}, path);
}

/// Every leaf up to level `max_level` whose closed cell meets the closed lattice box [lo, hi],
/// in depth-first order.
void leaves_touching(const Octree& t, uint32_t node, const Cell& cell, const Lat& lo, const Lat& hi,
                     int max_level, std::vector<LeafRef>& out) {
  if (cell.level > max_level) return;
  const int64_t s = cell.span();
  for (int k = 0; k < 3; ++k)
    if (cell.lat[k] > hi[k] || cell.lat[k] + s < lo[k]) return;
  const Node& n = t.nodes[node];
  if (n.kind != CellKind::Internal) {
    out.push_back({node, cell});
    return;
  }
  for (int c = 0; c < 8; ++c) leaves_touching(t, n.index + c, cell.child(c), lo, hi, max_level, out);
}

/// The finest lattice cell touching p in octant o (bit k set: on p's high side along k);
/// false when it falls outside the root.
bool octant_cell(const Lat& p, int o, Lat& q) {
  constexpr int64_t kLimit = int64_t{1} << kMaxLevel;
  for (int k = 0; k < 3; ++k) {
    q[k] = p[k] - (((o >> k) & 1) ? 0 : 1);
    if (q[k] < 0 || q[k] >= kLimit) return false;
  }
  return true;
}

/// Leaves having lattice point p as a corner, with the corner index in each; `path` gets
/// every node on the way down to them.
struct Around {
  uint32_t node;
  int corner;
  Cell cell;
};
std::vector<Around> leaves_around(const Octree& t, const Lat& p, std::vector<uint32_t>* path = nullptr) {
  std::vector<Around> out;
  for (int o = 0; o < 8; ++o) {
    Lat q;
    if (!octant_cell(p, o, q)) continue;
    const LeafRef l = leaf_at(t, q, path);
    const int c = l.cell.corner_index(p);
    if (c < 0) continue;
    bool seen = false;
    for (const auto& a : out) seen = seen || a.node == l.node;
    if (!seen) out.push_back({l.node, c, l.cell});
  }
  return out;
}

bool multi(uint8_t s) { return s != 0 && s != 0xff && !one_component(s); }

/// The leaf's corner signs as a mask (uniform leaves: all corners alike).
uint8_t signs_of(const Node& n) {
  if (n.kind == CellKind::Gray) return n.signs;
  return n.kind == CellKind::Black ? 0xff : 0;
}

/// Flips corner c of a leaf. A uniform leaf becomes gray with its vertex right next to that
/// corner (the only place its surface can be).
void flip_corner(Octree& t, uint32_t node, int c, const Cell& cell) {
  Node& n = t.nodes[node];
  if (n.kind == CellKind::Gray) {
    n.signs ^= uint8_t(1 << c);
    return;
  }
  const uint8_t s = uint8_t(signs_of(n) ^ (1 << c));
  n = add_gray(t.vertices, cell, s, cell_vertex(Qef{}, cell, s).position);
}

}  // namespace

namespace {

/// Flips lattice point p's sign in every leaf that has it as a corner (consistently), and
/// reports the nodes on the way to them.
void flip_point(Octree& t, const Lat& p, const std::function<void(uint32_t)>* touched) {
  std::vector<uint32_t> path;
  for (const auto& a : leaves_around(t, p, touched ? &path : nullptr)) flip_corner(t, a.node, a.corner, a.cell);
  if (touched)
    for (uint32_t x : path) (*touched)(x);
}

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

/// A leaf with the nodes from the root down to it (path[l] = its ancestor at level l), so
/// that searches around it can start from a near ancestor instead of the root.
struct PathLeaf {
  uint32_t node;
  Cell cell;
  size_t path;  // offset of the ancestors in IslandSearch::paths
};

struct IslandSearch {
  const Octree& t;
  std::vector<PathLeaf> leaves;
  std::vector<uint32_t> paths;

  /// The ancestor of `l` at `level`, with its cell.
  LeafRef ancestor(const PathLeaf& l, int level) const {
    Cell c{level, l.cell.lat};
    const int64_t span = c.span();
    for (auto& x : c.lat) x -= x % span;
    return {paths[l.path + size_t(level)], c};
  }
  /// The deepest ancestor of `l` whose cell holds the closed box [lo, hi] away from its
  /// boundary (`strict`) or anywhere inside it: every leaf meeting the box is below it.
  LeafRef start_for(const PathLeaf& l, const Lat& lo, const Lat& hi, bool strict) const {
    for (int level = l.cell.level; level > 0; --level) {
      const LeafRef a = ancestor(l, level);
      const int64_t s = a.cell.span();
      bool inside = true;
      for (int k = 0; k < 3 && inside; ++k)
        inside = strict ? (a.cell.lat[k] < lo[k] && hi[k] < a.cell.lat[k] + s)
                        : (a.cell.lat[k] <= lo[k] && hi[k] <= a.cell.lat[k] + s);
      if (inside) return a;
    }
    return {0, Cell{}};
  }
  /// The node covering `target` (or the leaf above it), searched from `from`.
  LeafRef node_below(LeafRef from, const Cell& target) const {
    while (from.cell.level < target.level && t.nodes[from.node].kind == CellKind::Internal) {
      const int64_t h = from.cell.span() / 2;
      int c = 0;
      for (int k = 0; k < 3; ++k)
        if (target.lat[k] >= from.cell.lat[k] + h) c |= 1 << k;
      from = {t.nodes[from.node].index + c, from.cell.child(c)};
    }
    return from;
  }

  void collect(uint32_t node, const Cell& cell, const std::function<bool(uint32_t)>* active,
               std::vector<uint32_t>& path) {
    if (active && !(*active)(node)) return;
    const Node& n = t.nodes[node];
    path.push_back(node);
    if (n.kind == CellKind::Internal) {
      for (int c = 0; c < 8; ++c) collect(n.index + c, cell.child(c), active, path);
    } else if (n.kind == CellKind::Gray && cell.level >= t.max_depth - 4) {
      // Islands are features near the finest cell size, next to leaves a few levels up.
      leaves.push_back({node, cell, paths.size()});
      paths.insert(paths.end(), path.begin(), path.end());
    }
    path.pop_back();
  }
};

}  // namespace

size_t remove_islands(Octree& t, const std::function<bool(uint32_t)>* active,
                      const std::function<void(uint32_t)>* touched) {
  IslandSearch search{t, {}, {}};
  {
    std::vector<uint32_t> path;
    search.collect(0, Cell{}, active, path);
  }
  size_t flipped = 0;
  auto flip = [&](const Lat& p) {
    flip_point(t, p, touched);
    ++flipped;
  };
  // A fine active leaf's corners against the coarser leaves around them (an old coarse
  // leaf next to new fine ones)...
  std::vector<LeafRef> near;
  for (const PathLeaf& l : search.leaves) {
    const uint32_t node = l.node;
    const Cell& cell = l.cell;
    if (cell.level < t.max_depth - 1) continue;  // the finest leaves carry the islands
    // The coarser leaves around its corners (a leaf as fine or finer touching a corner has it
    // as a corner too): one descent for the cell's closed box, from the nearest ancestor that
    // holds it.
    near.clear();
    const Lat lo = cell.lat, hi = cell.corner(7);
    const LeafRef from = search.start_for(l, lo, hi, true);
    leaves_touching(t, from.node, from.cell, lo, hi, cell.level - 1, near);
    for (int k = 0; k < 8; ++k) {
      const Lat p = cell.corner(k);
      const bool sp = (signs_of(t.nodes[node]) >> k) & 1;
      for (const LeafRef& big : near) {
        if (t.nodes[big.node].kind != CellKind::Gray || big.cell.corner_index(p) >= 0) continue;
        bool touches = true;
        for (int a = 0; a < 3 && touches; ++a)
          touches = p[a] >= big.cell.lat[a] && p[a] <= big.cell.lat[a] + big.cell.span();
        if (!touches || !is_island(t.nodes[big.node], big.cell, p, sp)) continue;
        flip(p);
        break;
      }
    }
  }
  // ... and an active coarse leaf against the finer leaves across its faces (a new coarse
  // leaf next to old fine ones).
  constexpr int64_t kLimit = int64_t{1} << kMaxLevel;
  for (const PathLeaf& l : search.leaves) {
    const uint32_t big = l.node;
    const Cell& cell = l.cell;
    if (cell.level >= t.max_depth) continue;
    const int64_t sz = cell.span();
    for (int d = 0; d < 3; ++d)
      for (int side = 0; side < 2; ++side) {
        Cell across = cell;
        across.lat[d] += side ? sz : -sz;
        if (across.lat[d] < 0 || across.lat[d] >= kLimit) continue;
        const Lat across_hi = across.corner(7);
        const LeafRef n = search.node_below(search.start_for(l, across.lat, across_hi, false), across);
        if (n.cell.level < cell.level || t.nodes[n.node].kind != CellKind::Internal) continue;
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
            if (is_island(t.nodes[big], cell, p, sp)) flip(p);
          }
        };
        visit(n.node, n.cell);
      }
  }
  return flipped;
}

TopologyFix enforce_one_component(Octree& t, const std::function<bool(uint32_t)>* active,
                                  const std::function<void(uint32_t)>* touched) {
  TopologyFix fix;
  for (int pass = 0; pass < 6; ++pass) {
    // Only subtrees with active nodes are visited: a sculpting stroke stays local.
    std::vector<LeafRef> bad;
    std::function<void(uint32_t, const Cell&)> walk = [&](uint32_t node, const Cell& cell) {
      if (active && !(*active)(node)) return;
      const Node& n = t.nodes[node];
      if (n.kind == CellKind::Internal) {
        for (int c = 0; c < 8; ++c) walk(n.index + c, cell.child(c));
      } else if (n.kind == CellKind::Gray && multi(n.signs)) {
        bad.push_back({node, cell});
      }
    };
    walk(0, Cell{});
    fix.remaining = bad.size();
    if (bad.empty()) break;
    for (const LeafRef& l : bad) {
      const uint8_t s = t.nodes[l.node].signs;
      if (!multi(s)) continue;  // fixed by an earlier flip
      // Try each corner; keep the flip that leaves the fewest multi-component leaves around it,
      // preferring to flip the minority sign (removing the thinner feature).
      int best = -1, best_cost = 1 << 30;
      const bool minority_inside = __builtin_popcount(s) <= 4;
      for (int k = 0; k < 8; ++k) {
        if (multi(uint8_t(s ^ (1 << k)))) continue;
        const auto around = leaves_around(t, l.cell.corner(k));
        int cost = 0;
        for (const auto& a : around) cost += 2 * multi(uint8_t(signs_of(t.nodes[a.node]) ^ (1 << a.corner)));
        cost += (((s >> k) & 1) != 0) != minority_inside;
        if (cost < best_cost) {
          best_cost = cost;
          best = k;
        }
      }
      if (best < 0) continue;
      flip_point(t, l.cell.corner(best), touched);
      ++fix.flipped;
    }
  }
  return fix;
}

/// Turns uniform leaves that border a sign change into gray leaves (vertex at the crossing
/// edge's midpoint), so the contour stays closed whatever the geometry decided.
size_t repair_cracks(Octree& t, const std::function<bool(uint32_t)>* active) {
  size_t fixed = 0;
  for (int pass = 0; pass < 4; ++pass) {
    DualStats ds;
    std::function<void(const DualPolygon&)> emit = [](const DualPolygon&) {};
    dual_walk(t, active, emit, &ds);
    if (ds.crack_leaves.empty()) break;
    std::unordered_map<uint32_t, std::pair<Lat, int>> mid_sum;  // leaf -> (sum of 2x midpoints, count)
    std::unordered_map<uint32_t, Cell> cells;
    for (size_t k = 0; k < ds.crack_leaves.size(); ++k) {
      auto& [sum, n] = mid_sum[ds.crack_leaves[k]];
      for (int a = 0; a < 3; ++a) sum[a] += ds.crack_points[k][a];
      ++n;
      cells[ds.crack_leaves[k]] = ds.crack_cells[k];
    }
    for (const auto& [node, ms] : mid_sum) {
      Node& n = t.nodes[node];
      if (n.kind == CellKind::Gray) continue;
      const Cell& cell = cells[node];
      const auto& [sum, cnt] = ms;
      constexpr double k = 1.0 / double(int64_t{1} << kMaxLevel);
      const Vec3 x{sum[0] * k / (2 * cnt), sum[1] * k / (2 * cnt), sum[2] * k / (2 * cnt)};
      n = add_gray(t.vertices, cell, n.kind == CellKind::Black ? 0xff : 0, x);
      ++fixed;
    }
  }
  return fixed;
}

}  // namespace pic::detail

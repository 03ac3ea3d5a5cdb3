// Refining around a lattice point: see refine.h.
#include "signs/refine.h"

#include "signs/leaf_walks.h"

#include <algorithm>
#include <optional>
#include <unordered_set>

#include <tbb/parallel_for.h>

namespace pic::detail {

using Lat = std::array<int64_t, 3>;

namespace {

/// The sign a leaf outside `cell` gives lattice point q as one of its corners, if one does.
std::optional<bool> sign_outside(const Octree& t, const Cell& cell, const Lat& q) {
  for (int o = 0; o < 8; ++o) {
    Lat f;
    if (!octant_cell(q, o, f)) continue;
    bool in_cell = true;
    for (int k = 0; k < 3; ++k) in_cell = in_cell && f[k] >= cell.lat[k] && f[k] < cell.lat[k] + cell.span();
    if (in_cell) continue;
    const LeafRef l = leaf_at(t, f);
    if (const int c = l.cell.corner_index(q); c >= 0) return ((signs_of(t.nodes[l.node]) >> c) & 1) != 0;
  }
  return std::nullopt;
}

/// The new leaves of `cell`'s subtree take, at the points of the cell's boundary, the signs
/// the leaves outside show there: the signs there may have been settled since the tree was
/// made, and one point must have one sign whichever leaf asks.
void agree_on_boundary(Octree& t, uint32_t root, const Cell& cell) {
  std::vector<std::pair<LeafRef, int>> flips;
  visit_leaves(t, root, cell, [&](uint32_t node, const Cell& c) {
    for (int k = 0; k < 8; ++k) {
      const Lat q = c.corner(k);
      bool on_boundary = false;
      for (int a = 0; a < 3; ++a) on_boundary = on_boundary || q[a] == cell.lat[a] || q[a] == cell.lat[a] + cell.span();
      if (!on_boundary) continue;
      const std::optional<bool> s = sign_outside(t, cell, q);
      if (s && *s != (((signs_of(t.nodes[node]) >> k) & 1) != 0)) flips.push_back({{node, c}, k});
    }
  });
  for (const auto& [l, k] : flips) flip_corner(t, l.node, k, l.cell);
}

/// The sign the leaves on the coarse side `cell` imply at boundary point p, when every corner
/// of the edge or face p lies inside shares one.
std::optional<bool> side_sign(const Cell& cell, uint8_t signs, const Lat& p) {
  const int64_t s = cell.span();
  // Per axis: p at the cell's low side (0), high side (1), or between (-1).
  int at[3];
  for (int k = 0; k < 3; ++k) at[k] = p[k] == cell.lat[k] ? 0 : p[k] == cell.lat[k] + s ? 1 : -1;
  std::optional<bool> sign;
  for (int c = 0; c < 8; ++c) {
    bool on = true;
    for (int k = 0; k < 3; ++k) on = on && (at[k] < 0 || ((c >> k) & 1) == at[k]);
    if (!on) continue;
    const bool in = ((signs >> c) & 1) != 0;
    if (sign && *sign != in) return std::nullopt;
    sign = in;
  }
  return sign;
}

}  // namespace

std::vector<Lat> points_against_coarse_sides(const Octree& t, const std::vector<std::pair<Lat, Lat>>& near,
                                            bool parallel) {
  // Per node: the level of its deepest leaf (the walk below skips subtrees no finer than the
  // coarse leaf, most of them).
  std::vector<uint8_t> deepest(t.nodes.size(), 0);
  std::vector<LeafRef> coarse;
  auto walk = [&](auto&& self, uint32_t node, const Cell& cell) -> int {
    const Node& n = t.nodes[node];
    int d = cell.level;
    if (n.kind == CellKind::Internal) {
      for (int c = 0; c < 8; ++c) d = std::max(d, self(self, n.index + c, cell.child(c)));
    } else if (n.kind == CellKind::Gray && cell.level < t.max_depth) {
      const Lat lo = cell.lat, hi = cell.corner(7);
      const bool meets = near.empty() || std::any_of(near.begin(), near.end(), [&](const auto& b) {
        for (int k = 0; k < 3; ++k)
          if (lo[k] > b.second[k] || hi[k] < b.first[k]) return false;
        return true;
      });
      if (meets) coarse.push_back({node, cell});
    }
    deepest[node] = uint8_t(d);
    return d;
  };
  walk(walk, 0, Cell{});
  std::vector<std::vector<Lat>> found(coarse.size());
  const auto look = [&](size_t i) {
    const LeafRef& l = coarse[i];
    const uint8_t signs = t.nodes[l.node].signs;
    // The leaves finer than this one touching it (subtrees no deeper than it are skipped).
    std::vector<LeafRef> finer;
    leaves_touching_if(t, 0, Cell{}, l.cell.lat, l.cell.corner(7),
                       [&](uint32_t n, const Cell&) { return deepest[n] <= l.cell.level; }, finer);
    for (const LeafRef& n : finer) {
      const uint8_t ns = signs_of(t.nodes[n.node]);
      for (int c = 0; c < 8; ++c) {
        const Lat p = n.cell.corner(c);
        if (!l.cell.holds(p) || l.cell.corner_index(p) >= 0) continue;
        const std::optional<bool> s = side_sign(l.cell, signs, p);
        if (s && *s != (((ns >> c) & 1) != 0)) found[i].push_back(p);
      }
    }
  };
  if (parallel) tbb::parallel_for(size_t{0}, coarse.size(), look);
  else for (size_t i = 0; i < coarse.size(); ++i) look(i);
  std::vector<Lat> out;
  for (const auto& f : found) out.insert(out.end(), f.begin(), f.end());
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

size_t refine_all_around(Octree& t, const std::vector<Lat>& points, const ResampleLeaf& resample, bool parallel) {
  std::vector<LeafRef> coarse;
  std::vector<Lat> first;  // per leaf: the first point that asked for it
  std::unordered_set<uint32_t> seen;
  for (const Lat& p : points)
    for (int o = 0; o < 8; ++o) {
      Lat q;
      if (!octant_cell(p, o, q)) continue;
      const LeafRef l = leaf_at(t, q);
      if (l.cell.level >= t.max_depth || !seen.insert(l.node).second) continue;
      coarse.push_back(l);
      first.push_back(p);
    }
  std::vector<Builder> subs(coarse.size());
  const auto one = [&](size_t i) { subs[i] = resample(coarse[i], first[i]); };
  if (parallel) tbb::parallel_for(size_t{0}, coarse.size(), one);
  else for (size_t i = 0; i < coarse.size(); ++i) one(i);
  for (size_t i = 0; i < coarse.size(); ++i) {
    t.nodes[coarse[i].node] = append_subtree(t.nodes, t.vertices, subs[i]);
    agree_on_boundary(t, coarse[i].node, coarse[i].cell);
  }
  return coarse.size();
}

size_t refine_around(Octree& t, const Lat& p, const ResampleLeaf& resample, const std::function<void(uint32_t)>& grown) {
  size_t replaced = 0;
  for (int o = 0; o < 8; ++o) {
    Lat q;
    if (!octant_cell(p, o, q)) continue;
    const LeafRef l = leaf_at(t, q);
    if (l.cell.level >= t.max_depth) continue;
    const auto first = static_cast<uint32_t>(t.nodes.size());
    const Builder sub = resample(l, p);
    t.nodes[l.node] = append_subtree(t.nodes, t.vertices, sub);
    agree_on_boundary(t, l.node, l.cell);
    ++replaced;
    grown(l.node);
    for (auto k = first; k < t.nodes.size(); ++k) grown(k);
  }
  return replaced;
}

}  // namespace pic::detail

// Splitting a closed mesh into sheets where it touches itself: an edge with four triangles
// (two sheets along a line) or a vertex with two fans (two sheets at a point) gets one copy
// of its vertices per sheet. Dual contouring with one vertex per cell leaves such spots where
// a feature is finer than a coarse neighbour; the split mesh is 2-manifold with coincident
// vertices there, which is what mesh tools downstream (slicers, mesh booleans) accept.
#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <unordered_map>
#include <vector>

#include <tbb/parallel_sort.h>

#include "pic/contour.h"
#include "pic/measure.h"
#include "pic/types.h"
#include "geometry/box_tree.h"
#include "geometry/predicates.h"
#include "geometry/union_find.h"
#include "geometry/vec3.h"
#include "measure/topology.h"

namespace pic {
namespace {

using detail::UnionFind;
constexpr auto sub = detail::sub3;
constexpr auto cross = detail::cross3;
constexpr auto dot = detail::dot3;

/// Half-edges (3 t + k: from corner k to corner k+1 of triangle t) around one edge, ordered
/// by angle about it, paired so that each pair bounds one wedge of the solid (`solids_apart`:
/// the solids on either side touch along the edge but stay apart) or one wedge of the outside
/// (the solid is pinched along the edge).
std::vector<std::pair<uint32_t, uint32_t>> pair_around_edge(const TriMesh& m, uint32_t u, uint32_t v,
                                                            const std::vector<uint32_t>& hs, bool solids_apart) {
  const Vec3 e0 = sub(m.positions[v], m.positions[u]);
  const double len = std::sqrt(dot(e0, e0));
  std::vector<std::pair<uint32_t, uint32_t>> pairs;
  if (len == 0) return pairs;
  const Vec3 e{e0[0] / len, e0[1] / len, e0[2] / len};
  // A unit vector perpendicular to e, and the third axis of a right-handed frame.
  const Vec3 helper = std::abs(e[0]) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  Vec3 b1 = cross(e, helper);
  const double l1 = std::sqrt(dot(b1, b1));
  b1 = {b1[0] / l1, b1[1] / l1, b1[2] / l1};
  const Vec3 b2 = cross(e, b1);
  struct Ray {
    uint32_t h;
    double angle;
    bool solid_ccw;  // the solid lies on the counter-clockwise side of this triangle
  };
  std::vector<Ray> rays;
  for (uint32_t h : hs) {
    const auto& t = m.triangles[h / 3];
    uint32_t w = t[0];
    for (uint32_t x : t)
      if (x != u && x != v) w = x;
    const Vec3 r = sub(m.positions[w], m.positions[u]);
    const double x = dot(r, b1), y = dot(r, b2);
    const Vec3 n = cross(sub(m.positions[t[1]], m.positions[t[0]]), sub(m.positions[t[2]], m.positions[t[0]]));
    const double nx = dot(n, b1), ny = dot(n, b2);
    // Counter-clockwise of the ray (x, y) is (-y, x); the outward normal points away from the solid.
    rays.push_back({h, std::atan2(y, x), (-y * nx + x * ny) < 0});
  }
  std::sort(rays.begin(), rays.end(), [](const Ray& a, const Ray& b) { return a.angle < b.angle || (a.angle == b.angle && a.h < b.h); });
  const size_t n = rays.size();
  size_t start = 0;
  while (start < n && rays[start].solid_ccw != solids_apart) ++start;
  if (start == n) return pairs;
  for (size_t k = 0; k + 1 < n; k += 2) pairs.push_back({rays[(start + k) % n].h, rays[(start + k + 1) % n].h});
  return pairs;
}

/// The triangles (ascending) with a vertex flagged in `off_fan`: all a split can change.
std::vector<uint32_t> triangles_at(const TriMesh& m, const std::vector<uint8_t>& off_fan) {
  std::vector<uint32_t> region;
  for (uint32_t t = 0; t < m.triangles.size(); ++t) {
    const auto& tri = m.triangles[t];
    if (off_fan[tri[0]] || off_fan[tri[1]] || off_fan[tri[2]]) region.push_back(t);
  }
  return region;
}

/// What split_sheets changed, to take it back: corners (3 t + k) and the vertex each had.
struct SplitUndo {
  std::vector<std::pair<uint32_t, uint32_t>> corners;
  size_t vertices = 0;  // the vertex count before
  void apply(TriMesh& m) const {
    for (const auto& [c, v] : corners) m.triangles[c / 3][c % 3] = v;
    m.positions.resize(vertices);
  }
};

/// Gives each fan of a flagged vertex (`off_fan`) but its first its own copy of the vertex.
/// Fans join corners across the edges at the vertex, paired around edges of more than two
/// triangles by pair_around_edge. Only `region` (triangles_at) is read: a vertex not flagged
/// has one fan, and a flagged vertex's edges and fans lie in the region.
size_t split_sheets(TriMesh& m, bool solids_apart, const std::vector<uint8_t>& off_fan,
                    const std::vector<uint32_t>& region, SplitUndo& undo) {
  const auto local = [&](uint32_t t) {
    return uint32_t(std::lower_bound(region.begin(), region.end(), t) - region.begin());
  };
  // Half-edges (3 t + k) at a flagged vertex, grouped by undirected edge.
  std::vector<std::pair<uint64_t, uint32_t>> edges;
  for (uint32_t t : region)
    for (uint32_t k = 0; k < 3; ++k) {
      const uint32_t a = m.triangles[t][k], b = m.triangles[t][(k + 1) % 3];
      if (off_fan[a] || off_fan[b]) edges.push_back({uint64_t(std::min(a, b)) << 32 | std::max(a, b), 3 * t + k});
    }
  std::sort(edges.begin(), edges.end());
  // Corners (3 i + k, i in the region) of one vertex join when their triangles are paired
  // across an edge there.
  UnionFind fans(region.size() * 3);
  auto corner_of = [&](uint32_t t, uint32_t vertex) {
    for (uint32_t k = 0; k < 3; ++k)
      if (m.triangles[t][k] == vertex) return 3 * local(t) + k;
    return 3 * local(t);
  };
  auto join = [&](uint32_t h1, uint32_t h2, uint32_t u, uint32_t v) {
    fans.join(corner_of(h1 / 3, u), corner_of(h2 / 3, u));
    fans.join(corner_of(h1 / 3, v), corner_of(h2 / 3, v));
  };
  std::vector<uint32_t> group;
  for (size_t i = 0; i < edges.size();) {
    size_t j = i;
    group.clear();
    while (j < edges.size() && edges[j].first == edges[i].first) group.push_back(edges[j++].second);
    const auto u = uint32_t(edges[i].first >> 32), v = uint32_t(edges[i].first & 0xffffffffu);
    if (group.size() == 2) {
      join(group[0], group[1], u, v);
    } else if (group.size() > 2) {
      for (const auto& [h1, h2] : pair_around_edge(m, u, v, group, solids_apart)) join(h1, h2, u, v);
    }
    i = j;
  }
  // One vertex per fan: the first fan (in corner order) keeps the index, the others get copies.
  std::unordered_map<uint32_t, uint32_t> first_root;   // vertex -> its first fan's root
  std::unordered_map<uint32_t, uint32_t> copy_of_fan;  // fan root -> its new vertex
  undo = {{}, m.positions.size()};
  size_t added = 0;
  for (uint32_t i = 0; i < region.size(); ++i)
    for (uint32_t k = 0; k < 3; ++k) {
      const uint32_t t = region[i], v = m.triangles[t][k];
      if (!off_fan[v]) continue;
      const auto r = static_cast<uint32_t>(fans.root(3 * i + k));
      if (first_root.try_emplace(v, r).first->second == r) continue;
      auto [it, fresh] = copy_of_fan.try_emplace(r, static_cast<uint32_t>(m.positions.size()));
      if (fresh) {
        const Vec3 p = m.positions[v];
        m.positions.push_back(p);
        ++added;
      }
      undo.corners.push_back({3 * t + k, v});
      m.triangles[t][k] = it->second;
    }
  return added;
}

/// Pairs of triangles on the same three vertices with opposite orientations (ascending): a
/// pocket of no volume, which puts four triangles on each of its edges. Only `region`
/// (triangles_at) is searched: a pocket's edges are not manifold.
std::vector<uint32_t> flat_pockets(const TriMesh& m, const std::vector<uint32_t>& region) {
  std::vector<std::pair<std::array<uint32_t, 3>, uint32_t>> keyed;  // rotation starting at the smallest index
  keyed.reserve(region.size());
  for (uint32_t t : region) {
    auto tri = m.triangles[t];
    while (tri[0] > tri[1] || tri[0] > tri[2]) tri = {tri[1], tri[2], tri[0]};
    keyed.push_back({tri, t});
  }
  auto same_set = [](const std::array<uint32_t, 3>& a, const std::array<uint32_t, 3>& b) {
    return a[0] == b[0] && ((a[1] == b[1] && a[2] == b[2]) || (a[1] == b[2] && a[2] == b[1]));
  };
  std::sort(keyed.begin(), keyed.end(), [](const auto& a, const auto& b) {
    const auto ka = std::array<uint32_t, 3>{a.first[0], std::min(a.first[1], a.first[2]), std::max(a.first[1], a.first[2])};
    const auto kb = std::array<uint32_t, 3>{b.first[0], std::min(b.first[1], b.first[2]), std::max(b.first[1], b.first[2])};
    return ka != kb ? ka < kb : a.second < b.second;
  });
  std::vector<char> drop(keyed.size(), 0);  // by position in keyed
  std::vector<uint32_t> dropped;
  for (size_t i = 0; i + 1 < keyed.size(); ++i) {
    const auto& a = keyed[i].first;
    const auto& b = keyed[i + 1].first;
    if (same_set(a, b) && a[1] == b[2] && !drop[i] && !drop[i + 1]) {
      drop[i] = drop[i + 1] = 1;
      dropped.insert(dropped.end(), {keyed[i].second, keyed[i + 1].second});
      ++i;
    }
  }
  std::sort(dropped.begin(), dropped.end());
  return dropped;
}

/// Removes the triangles `gone` (ascending), keeping the others in order.
void erase_triangles(TriMesh& m, const std::vector<uint32_t>& gone) {
  size_t k = 0, d = 0;
  for (size_t t = 0; t < m.triangles.size(); ++t) {
    if (d < gone.size() && gone[d] == t) {
      ++d;
      continue;
    }
    m.triangles[k++] = m.triangles[t];
  }
  m.triangles.resize(k);
}

/// Moves the copies of each split vertex apart, each into its own fan: toward the mean of its
/// ring by the least of 1/1024, 1/256, 1/64, 1/16 of the way for which no triangle around a
/// moved copy crosses another (the exact test, CGAL's rules). Coincident copies are one vertex
/// to a reader that merges equal positions (meshcheck, CGAL's soup loader): to it the sheets
/// would still touch at a pinched vertex or edge. Copies no step separates cleanly stay put.
void separate_copies(TriMesh& m) {
  const auto nv = static_cast<uint32_t>(m.positions.size());
  std::vector<uint32_t> order(nv);
  std::iota(order.begin(), order.end(), 0u);
  tbb::parallel_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    return m.positions[a] < m.positions[b] || (m.positions[a] == m.positions[b] && a < b);
  });
  std::vector<uint32_t> moving;  // vertices sharing their position with another
  for (size_t i = 0; i < order.size();) {
    size_t j = i + 1;
    while (j < order.size() && m.positions[order[j]] == m.positions[order[i]]) ++j;
    if (j - i > 1) moving.insert(moving.end(), order.begin() + ptrdiff_t(i), order.begin() + ptrdiff_t(j));
    i = j;
  }
  if (moving.empty()) return;
  std::vector<int32_t> slot(nv, -1);
  for (size_t k = 0; k < moving.size(); ++k) slot[moving[k]] = int32_t(k);
  // Each moving vertex's ring mean, and the triangles around the moving vertices.
  std::vector<Vec3> ring(moving.size(), Vec3{0, 0, 0});
  std::vector<double> count(moving.size(), 0);
  std::vector<uint32_t> touched;
  for (uint32_t t = 0; t < m.triangles.size(); ++t) {
    bool hit = false;
    for (int k = 0; k < 3; ++k) {
      const int32_t s = slot[m.triangles[t][k]];
      if (s < 0) continue;
      hit = true;
      for (int j = 1; j < 3; ++j) {
        const Vec3& q = m.positions[m.triangles[t][(k + j) % 3]];
        for (int a = 0; a < 3; ++a) ring[size_t(s)][a] += q[a];
        count[size_t(s)] += 1;
      }
    }
    if (hit) touched.push_back(t);
  }
  std::vector<Vec3> home(moving.size()), dir(moving.size());
  for (size_t k = 0; k < moving.size(); ++k) {
    home[k] = m.positions[moving[k]];
    for (int a = 0; a < 3; ++a) dir[k][a] = count[k] > 0 ? ring[k][a] / count[k] - home[k][a] : 0.0;
  }
  constexpr std::array<double, 4> kSteps{1.0 / 1024, 1.0 / 256, 1.0 / 64, 1.0 / 16};
  // Triangle boxes cover every step (a copy moves along a segment from its home).
  const auto box_of = [&](uint32_t t) {
    detail::Box b{m.positions[m.triangles[t][0]], m.positions[m.triangles[t][0]]};
    for (uint32_t v : m.triangles[t]) {
      Vec3 far = m.positions[v];
      if (slot[v] >= 0)
        for (int a = 0; a < 3; ++a) far[a] += kSteps.back() * dir[size_t(slot[v])][a];
      for (const Vec3& q : {m.positions[v], far})
        for (int a = 0; a < 3; ++a) {
          b.lo[a] = std::min(b.lo[a], q[a]);
          b.hi[a] = std::max(b.hi[a], q[a]);
        }
    }
    return b;
  };
  // Only triangles whose boxes meet those around the moving vertices can be crossed.
  std::vector<detail::Box> reach(touched.size());
  for (size_t i = 0; i < touched.size(); ++i) reach[i] = box_of(touched[i]);
  const detail::BoxTree reach_tree(reach);
  std::vector<uint32_t> near;  // ascending
  std::vector<detail::Box> boxes;
  for (uint32_t t = 0; t < m.triangles.size(); ++t) {
    const detail::Box b = box_of(t);
    bool hit = false;
    reach_tree.query(b, [&](uint32_t) { hit = true; });
    if (!hit) continue;
    near.push_back(t);
    boxes.push_back(b);
  }
  const detail::BoxTree tree(boxes);
  const auto box_at = [&](uint32_t t) -> const detail::Box& {
    return boxes[size_t(std::lower_bound(near.begin(), near.end(), t) - near.begin())];
  };
  // Vertices (by slot) still to place; a step is applied to all of them at once, then every
  // vertex with a triangle in a crossing goes on to the next step.
  std::vector<uint8_t> open(moving.size(), 1);
  for (double step : kSteps) {
    for (size_t k = 0; k < moving.size(); ++k)
      if (open[k])
        for (int a = 0; a < 3; ++a) m.positions[moving[k]][a] = home[k][a] + step * dir[k][a];
    std::vector<uint8_t> crossed(moving.size(), 0);
    for (uint32_t t : touched) {
      const auto& ta = m.triangles[t];
      if (detail::projection_axis(m.positions[ta[0]], m.positions[ta[1]], m.positions[ta[2]]) < 0) {
        for (uint32_t v : ta)
          if (slot[v] >= 0) crossed[size_t(slot[v])] = 1;
        continue;
      }
      tree.query(box_at(t), [&](uint32_t k) {
        const uint32_t u = near[k];
        if (u == t) return;
        const auto& tb = m.triangles[u];
        if (!detail::triangles_intersect(m.positions, ta, tb)) return;
        for (const auto* tri : {&ta, &tb})
          for (uint32_t v : *tri)
            if (slot[v] >= 0) crossed[size_t(slot[v])] = 1;
      });
    }
    bool any = false;
    for (size_t k = 0; k < moving.size(); ++k) {
      open[k] = crossed[k];
      any = any || crossed[k];
    }
    if (!any) return;
  }
  for (size_t k = 0; k < moving.size(); ++k)
    if (open[k]) m.positions[moving[k]] = home[k];
}

}  // namespace

size_t split_nonmanifold(TriMesh& m) {
  std::vector<uint8_t> off_fan;
  if (detail::analyze_topology(m, &off_fan).manifold()) return 0;
  // Everything below reads and writes only the triangles at the flagged vertices.
  std::vector<uint32_t> region = triangles_at(m, off_fan);
  std::vector<std::array<uint32_t, 3>> before;  // kept only when pockets go
  if (const std::vector<uint32_t> pockets = flat_pockets(m, region); !pockets.empty()) {
    before = m.triangles;
    erase_triangles(m, pockets);
    region = triangles_at(m, off_fan);
  }
  // The two pairings around a crowded edge are both manifold there; which one also gives
  // consistent fans at its end vertices depends on the neighbourhood, so try both.
  for (const bool solids_apart : {true, false}) {
    SplitUndo undo;
    const size_t added = split_sheets(m, solids_apart, off_fan, region, undo);
    if (analyze_topology(m).manifold()) {
      separate_copies(m);
      return added;
    }
    undo.apply(m);
  }
  if (!before.empty()) m.triangles = std::move(before);
  return 0;
}

}  // namespace pic

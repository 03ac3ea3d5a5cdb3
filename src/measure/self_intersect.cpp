// Exact self-intersection test of a triangle mesh, with CGAL's rules
// (Polygon_mesh_processing::self_intersections): two triangles sharing an edge intersect only
// when they are coplanar and fold onto the same side of it; two sharing a vertex only when the
// edge opposite that vertex in one meets the other; others when they meet at all (closed
// triangles). Positions are compared bit for bit: vertices at exactly the same position are
// one vertex (as /work/shared/tools meshcheck and a CGAL polygon-soup load see the file).
// Zero-area (collinear) triangles are skipped and counted apart, as meshcheck does.
//
// Predicates: src/predicates.h, exact on the doubles as given (no snapping): the answer holds
// for the coordinates written.
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <numeric>
#include <vector>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include "pic/measure.h"
#include "pic/types.h"
#include "geometry/box_tree.h"
#include "geometry/edge_faces.h"
#include "geometry/predicates.h"
#include "geometry/union_find.h"
#include "measure/self_intersect.h"

namespace pic {
namespace {

using detail::orient2d;
using detail::orient3d;
using detail::projection_axis;
using detail::segment_meets_triangle;
using detail::BoxTree;
using detail::Box;

/// The mesh with bit-identical positions merged (first occurrence kept, in position order).
TriMesh merged(const TriMesh& m) {
  std::vector<uint32_t> perm(m.positions.size());
  std::iota(perm.begin(), perm.end(), 0u);
  tbb::parallel_sort(perm.begin(), perm.end(), [&](uint32_t a, uint32_t b) {
    return m.positions[a] < m.positions[b] || (m.positions[a] == m.positions[b] && a < b);
  });
  std::vector<uint32_t> remap(m.positions.size());
  TriMesh out;
  for (size_t i = 0; i < perm.size(); ++i) {
    if (i == 0 || m.positions[perm[i]] != m.positions[perm[i - 1]]) out.positions.push_back(m.positions[perm[i]]);
    remap[perm[i]] = uint32_t(out.positions.size() - 1);
  }
  out.triangles.reserve(m.triangles.size());
  for (const auto& t : m.triangles) out.triangles.push_back({remap[t[0]], remap[t[1]], remap[t[2]]});
  return out;
}

std::vector<std::pair<uint32_t, uint32_t>> intersecting_pairs_merged(const TriMesh& m, size_t* collinear) {
  const size_t n = m.triangles.size();
  std::vector<Box> boxes(n);
  std::vector<char> skip(n, 0);
  tbb::parallel_for(size_t{0}, n, [&](size_t t) {
    const auto& tri = m.triangles[t];
    const Vec3 &a = m.positions[tri[0]], &b = m.positions[tri[1]], &c = m.positions[tri[2]];
    for (int k = 0; k < 3; ++k) {
      boxes[t].lo[k] = std::min({a[k], b[k], c[k]});
      boxes[t].hi[k] = std::max({a[k], b[k], c[k]});
    }
    skip[t] = tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] || projection_axis(a, b, c) < 0;
  });
  if (collinear) *collinear = size_t(std::count(skip.begin(), skip.end(), char(1)));
  const BoxTree tree(boxes);
  tbb::enumerable_thread_specific<std::vector<std::pair<uint32_t, uint32_t>>> found;
  tree.for_each_pair([&](uint32_t i, uint32_t j) {
    if (!skip[i] && !skip[j] && detail::triangles_intersect(m.positions, m.triangles[i], m.triangles[j]))
      found.local().push_back({i, j});
  });
  std::vector<std::pair<uint32_t, uint32_t>> all;
  for (auto& v : found) all.insert(all.end(), v.begin(), v.end());
  std::sort(all.begin(), all.end());
  return all;
}

}  // namespace

std::vector<std::pair<uint32_t, uint32_t>> self_intersecting_pairs(const TriMesh& mesh) {
  return intersecting_pairs_merged(merged(mesh), nullptr);
}

namespace detail {
std::vector<std::pair<uint32_t, uint32_t>> intersecting_pairs_of_distinct(const TriMesh& mesh) {
  return intersecting_pairs_merged(mesh, nullptr);
}
}  // namespace detail

size_t count_self_intersections(const TriMesh& mesh) { return self_intersecting_pairs(mesh).size(); }

MeshValidity check_validity(const TriMesh& mesh, bool self_intersections) {
  const TriMesh m = merged(mesh);
  MeshValidity r;
  const MeshTopology topo = analyze_topology(m);
  r.nonmanifold_vertices = topo.nonmanifold_vertices;
  r.nonmanifold_edges = topo.nonmanifold_edges;
  r.boundary_edges = topo.boundary_edges;
  r.degenerate_triangles = topo.degenerate_triangles;
  // Components: triangles joined across shared edges (as meshcheck counts them).
  const std::vector<std::pair<uint64_t, uint32_t>> edges = detail::edge_faces(m);
  detail::UnionFind uf(m.triangles.size());
  for (size_t i = 1; i < edges.size(); ++i)
    if (edges[i].first == edges[i - 1].first) uf.join(edges[i].second, edges[i - 1].second);
  std::vector<char> used(m.triangles.size(), 0);
  for (const auto& e : edges) used[e.second] = 1;
  for (size_t f = 0; f < m.triangles.size(); ++f)
    if (used[f] && uf.root(f) == f) ++r.components;
  if (self_intersections) {
    r.checked = true;
    r.self_intersections = intersecting_pairs_merged(m, &r.collinear_triangles).size();
  }
  return r;
}

}  // namespace pic

// The exact reference for PIC's CSG: CGAL's corefinement Boolean of the operands'
// own contours, and the comparison of PIC's result with it. Test-only (CGAL is a test
// dependency); shared by tests/csg_regression_test.cpp and the randomized harness
// bench/csg_fuzz.cpp.
#pragma once

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/Polygon_mesh_processing/corefinement.h>
#include <CGAL/Surface_mesh.h>

#include <cmath>
#include <limits>
#include <boost/variant/get.hpp>
#include <map>
#include <numeric>
#include <optional>
#include <random>
#include <vector>

#include "pic/pic.h"

namespace pic {

namespace exact_detail {
using Kernel = CGAL::Exact_predicates_exact_constructions_kernel;
using Mesh = CGAL::Surface_mesh<Kernel::Point_3>;

inline std::optional<Mesh> to_cgal(const TriMesh& m) {
  Mesh sm;
  std::vector<Mesh::Vertex_index> v;
  v.reserve(m.positions.size());
  for (const auto& p : m.positions) v.push_back(sm.add_vertex(Kernel::Point_3(p[0], p[1], p[2])));
  for (const auto& t : m.triangles)
    if (sm.add_face(v[t[0]], v[t[1]], v[t[2]]) == Mesh::null_face()) return std::nullopt;
  return sm;
}

inline TriMesh from_cgal(const Mesh& sm) {
  TriMesh m;
  std::vector<uint32_t> index(sm.number_of_vertices() + sm.number_of_removed_vertices(), 0);
  for (auto v : sm.vertices()) {
    index[v.idx()] = uint32_t(m.positions.size());
    const auto& p = sm.point(v);
    m.positions.push_back({CGAL::to_double(p.x()), CGAL::to_double(p.y()), CGAL::to_double(p.z())});
  }
  for (auto f : sm.faces()) {
    std::array<uint32_t, 3> t{};
    int k = 0;
    for (auto v : CGAL::vertices_around_face(sm.halfedge(f), sm)) {
      if (k < 3) t[k] = index[v.idx()];
      ++k;
    }
    if (k == 3) m.triangles.push_back(t);
  }
  return m;
}
}  // namespace exact_detail

/// A ∘ B computed exactly by CGAL (Polygon_mesh_processing corefinement, exact constructions,
/// rounded to doubles at the end). Empty when CGAL refuses: an operand that is not a valid
/// Surface_mesh or crosses itself (corefinement needs self-intersection-free inputs; with
/// `check` false the crossing test is skipped and CGAL corefines what it can).
inline std::optional<TriMesh> exact_boolean(const TriMesh& a, const TriMesh& b, CsgOp op, bool check = true) {
  using namespace exact_detail;
  namespace PMP = CGAL::Polygon_mesh_processing;
  if (check && (count_self_intersections(a) != 0 || count_self_intersections(b) != 0)) return std::nullopt;
  auto ma = to_cgal(a), mb = to_cgal(b);
  if (!ma || !mb) return std::nullopt;
  if (b.triangles.empty()) {
    if (op == CsgOp::Intersect) return TriMesh{};
    return a;
  }
  if (a.triangles.empty()) return op == CsgOp::Union ? std::optional<TriMesh>(b) : std::optional<TriMesh>(TriMesh{});
  Mesh out;
  bool ok = false;
  try {
    switch (op) {
      case CsgOp::Union: ok = PMP::corefine_and_compute_union(*ma, *mb, out); break;
      case CsgOp::Intersect: ok = PMP::corefine_and_compute_intersection(*ma, *mb, out); break;
      case CsgOp::Subtract: ok = PMP::corefine_and_compute_difference(*ma, *mb, out); break;
    }
  } catch (const std::exception&) {
    ok = false;
  }
  if (!ok) return std::nullopt;
  return from_cgal(out);
}

/// An edge-connected component of a mesh (equal positions merged).
struct MeshComponent {
  size_t triangles = 0;
  Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  double extent() const { return std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]}); }
};

/// The mesh's components, smallest first.
inline std::vector<MeshComponent> mesh_components(const TriMesh& m) {
  std::map<Vec3, uint32_t> id;
  std::vector<uint32_t> v(m.positions.size());
  for (size_t i = 0; i < m.positions.size(); ++i) v[i] = id.try_emplace(m.positions[i], uint32_t(id.size())).first->second;
  std::vector<uint32_t> parent(m.triangles.size());
  std::iota(parent.begin(), parent.end(), 0u);
  auto root = [&](uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  std::map<std::pair<uint32_t, uint32_t>, uint32_t> edges;
  for (uint32_t f = 0; f < m.triangles.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = v[m.triangles[f][k]], b = v[m.triangles[f][(k + 1) % 3]];
      const auto [it, fresh] = edges.try_emplace({std::min(a, b), std::max(a, b)}, f);
      if (!fresh) parent[root(f)] = root(it->second);
    }
  std::map<uint32_t, MeshComponent> comps;
  for (uint32_t f = 0; f < m.triangles.size(); ++f) {
    MeshComponent& c = comps[root(f)];
    ++c.triangles;
    for (uint32_t i : m.triangles[f])
      for (int k = 0; k < 3; ++k) {
        c.lo[k] = std::min(c.lo[k], m.positions[i][k]);
        c.hi[k] = std::max(c.hi[k], m.positions[i][k]);
      }
  }
  std::vector<MeshComponent> out;
  for (const auto& [r, c] : comps) out.push_back(c);
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.triangles < b.triangles; });
  return out;
}

/// Points on a mesh's surface (area-weighted, deterministic) with the triangle each lies on.
struct SurfaceSample {
  Vec3 p;
  uint32_t triangle;
};
inline std::vector<SurfaceSample> sample_with_triangles(const TriMesh& m, size_t n, uint64_t seed) {
  std::vector<double> cum(m.triangles.size());
  double total = 0;
  auto corner = [&](uint32_t f, int k) { return m.positions[m.triangles[f][k]]; };
  for (uint32_t f = 0; f < m.triangles.size(); ++f) {
    const Vec3 a = corner(f, 0), b = corner(f, 1), c = corner(f, 2);
    const Vec3 u{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double x = u[1] * v[2] - u[2] * v[1], y = u[2] * v[0] - u[0] * v[2], z = u[0] * v[1] - u[1] * v[0];
    total += std::sqrt(x * x + y * y + z * z) / 2;
    cum[f] = total;
  }
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0, 1);
  std::vector<SurfaceSample> out;
  if (total <= 0) return out;
  for (size_t i = 0; i < n; ++i) {
    const auto f = uint32_t(std::lower_bound(cum.begin(), cum.end(), unit(rng) * total) - cum.begin());
    if (f >= m.triangles.size()) continue;
    double r1 = unit(rng), r2 = unit(rng);
    if (r1 + r2 > 1) r1 = 1 - r1, r2 = 1 - r2;
    const Vec3 a = corner(f, 0), b = corner(f, 1), c = corner(f, 2);
    Vec3 p;
    for (int k = 0; k < 3; ++k) p[k] = a[k] + r1 * (b[k] - a[k]) + r2 * (c[k] - a[k]);
    out.push_back({p, f});
  }
  return out;
}

/// The solid's local size at each sample: along the surface normal, the distance to the mesh
/// inward (how thick the solid is there: a wedge near its edge, a thin sheet) and outward (how
/// wide the gap is: a thin slot); the smaller one. Infinite when neither ray hits.
inline std::vector<double> local_size(const TriMesh& m, const std::vector<SurfaceSample>& samples) {
  using K = CGAL::Simple_cartesian<double>;
  using Tri = K::Triangle_3;
  using Prim = CGAL::AABB_triangle_primitive<K, std::vector<Tri>::const_iterator>;
  using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, Prim>>;
  std::vector<Tri> tris;
  tris.reserve(m.triangles.size());
  auto pt = [&](uint32_t i) { return K::Point_3(m.positions[i][0], m.positions[i][1], m.positions[i][2]); };
  for (const auto& t : m.triangles) tris.emplace_back(pt(t[0]), pt(t[1]), pt(t[2]));
  Tree tree(tris.begin(), tris.end());
  tree.accelerate_distance_queries();
  std::vector<double> out;
  out.reserve(samples.size());
  for (const SurfaceSample& s : samples) {
    const Tri& own = tris[s.triangle];
    if (own.is_degenerate()) {
      out.push_back(std::numeric_limits<double>::infinity());
      continue;
    }
    const K::Vector_3 n = own.supporting_plane().orthogonal_vector();
    const K::Point_3 p(s.p[0], s.p[1], s.p[2]);
    double best = std::numeric_limits<double>::infinity();
    for (const K::Vector_3& d : {n, -n}) {
      const auto skip = [&](std::vector<Tri>::const_iterator it) { return &*it == &own; };
      const auto hit = tree.first_intersection(K::Ray_3(p, d), skip);
      if (!hit) continue;
      if (const K::Point_3* q = boost::get<K::Point_3>(&hit->first))
        best = std::min(best, std::sqrt(CGAL::squared_distance(p, *q)));
    }
    out.push_back(best);
  }
  return out;
}

/// PIC's result against the exact one. Distances in finest cells of the octree.
struct CsgComparison {
  size_t pic_components = 0, exact_components = 0;
  double hausdorff = 0;        ///< two-sided, cells
  double pic_to_exact = 0;     ///< max over PIC's surface (slits and specks show here), cells
  double exact_to_pic = 0;     ///< max over the exact surface (cut-off wedges show here), cells
  double volume_rel = 0;       ///< (vol PIC − vol exact) / vol exact
  Vec3 worst_pic{0, 0, 0};     ///< the point of PIC's surface farthest from the exact one
  Vec3 worst_exact{0, 0, 0};   ///< the point of the exact surface farthest from PIC's
  /// exact_to_pic over the points where the exact solid (or its gap) is at least a cell thick
  /// along the normal: what is left once the resolution limit (one vertex per finest cell, so
  /// nothing thinner than a cell) is set aside.
  double exact_to_pic_thick = 0;
  Vec3 worst_thick{0, 0, 0};
};

inline CsgComparison compare_to_exact(const TriMesh& pic_mesh, const TriMesh& exact, double cell,
                                      size_t samples = 20000) {
  CsgComparison c;
  c.pic_components = check_validity(pic_mesh, false).components;
  c.exact_components = check_validity(exact, false).components;
  const double ve = volume(exact), vp = volume(pic_mesh);
  c.volume_rel = ve != 0 ? (vp - ve) / std::abs(ve) : vp;
  if (pic_mesh.triangles.empty() || exact.triangles.empty()) {
    c.hausdorff = c.pic_to_exact = c.exact_to_pic = pic_mesh.triangles.empty() == exact.triangles.empty() ? 0 : 1e9;
    return c;
  }
  auto one_side = [&](const TriMesh& from, const TriMesh& to, Vec3& where) {
    const std::vector<Vec3> pts = sample_surface(from, samples, 777);
    const std::vector<double> d = distance_to_mesh(to, pts);
    double m = 0;
    for (size_t i = 0; i < d.size(); ++i)
      if (d[i] > m) {
        m = d[i];
        where = pts[i];
      }
    return m / cell;
  };
  c.pic_to_exact = one_side(pic_mesh, exact, c.worst_pic);
  c.exact_to_pic = one_side(exact, pic_mesh, c.worst_exact);
  c.hausdorff = std::max(c.pic_to_exact, c.exact_to_pic);
  const std::vector<SurfaceSample> es = sample_with_triangles(exact, samples, 778);
  std::vector<Vec3> pts;
  for (const auto& s : es) pts.push_back(s.p);
  const std::vector<double> d = distance_to_mesh(pic_mesh, pts), size = local_size(exact, es);
  for (size_t i = 0; i < d.size(); ++i)
    if (size[i] >= cell && d[i] / cell > c.exact_to_pic_thick) {
      c.exact_to_pic_thick = d[i] / cell;
      c.worst_thick = pts[i];
    }
  return c;
}

}  // namespace pic

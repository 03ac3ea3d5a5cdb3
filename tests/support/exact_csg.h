// The exact reference for PIC's CSG (issue 10): CGAL's corefinement Boolean of the operands'
// own contours, and the comparison of PIC's result with it. Test-only (CGAL is a test
// dependency); shared by tests/csg_regression_test.cpp and the randomized harness
// bench/csg_fuzz.cpp.
#pragma once

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/corefinement.h>
#include <CGAL/Surface_mesh.h>

#include <cmath>
#include <map>
#include <numeric>
#include <optional>
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

/// PIC's result against the exact one. Distances in finest cells of the octree.
struct CsgComparison {
  size_t pic_components = 0, exact_components = 0;
  double hausdorff = 0;        ///< two-sided, cells
  double pic_to_exact = 0;     ///< max over PIC's surface (slits and specks show here), cells
  double exact_to_pic = 0;     ///< max over the exact surface (cut-off wedges show here), cells
  double volume_rel = 0;       ///< (vol PIC − vol exact) / vol exact
  Vec3 worst_pic{0, 0, 0};     ///< the point of PIC's surface farthest from the exact one
  Vec3 worst_exact{0, 0, 0};   ///< the point of the exact surface farthest from PIC's
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
  return c;
}

}  // namespace pic

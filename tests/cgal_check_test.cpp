// Cross-check of pic::count_self_intersections against CGAL's own
// Polygon_mesh_processing::self_intersections (a test-only dependency, Debian libcgal-dev) on
// meshes that do cross themselves: fast contours of the bundled models and jittered spheres.
#include <gtest/gtest.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include <random>
#include <string>
#include <vector>

#include "pic/pic.h"
#include "pic/primitives.h"

namespace pic {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using SM = CGAL::Surface_mesh<K::Point_3>;

/// CGAL's count; -1 when the mesh is not a valid Surface_mesh (a non-manifold vertex).
long cgal_count(const TriMesh& m) {
  SM sm;
  std::vector<SM::Vertex_index> v;
  for (const auto& p : m.positions) v.push_back(sm.add_vertex(K::Point_3(p[0], p[1], p[2])));
  for (const auto& t : m.triangles)
    if (sm.add_face(v[t[0]], v[t[1]], v[t[2]]) == SM::null_face()) return -1;
  std::vector<std::pair<SM::Face_index, SM::Face_index>> pairs;
  CGAL::Polygon_mesh_processing::self_intersections(sm, std::back_inserter(pairs));
  return long(pairs.size());
}

TriMesh fast_contour(const char* model, int depth) {
  SampleOptions o;
  o.depth = depth;
  ContourOptions fast;
  fast.intersection_free = false;
  return contour(sample(read_mesh(std::string(PIC_DATA_DIR) + "/" + model + ".obj"), o), fast);
}

TEST(CgalCheck, FastContoursCountAsCgalDoes) {
  for (const char* model : {"fandisk", "spot", "cad_part"})
    for (int depth : {9, 11}) {
      const TriMesh m = fast_contour(model, depth);
      const long c = cgal_count(m);
      if (c < 0) continue;  // not a Surface_mesh (pinched vertex): nothing to compare
      EXPECT_EQ(long(count_self_intersections(m)), c) << model << " depth " << depth;
    }
}

TEST(CgalCheck, DefaultContoursAreCleanForCgalToo) {
  for (const char* model : {"fandisk", "spot", "cad_part"}) {
    SampleOptions o;
    o.depth = 10;
    const TriMesh m = contour(sample(read_mesh(std::string(PIC_DATA_DIR) + "/" + model + ".obj"), o));
    const long c = cgal_count(m);
    if (c >= 0) EXPECT_EQ(c, 0) << model;
    EXPECT_EQ(count_self_intersections(m), 0u) << model;
  }
}

TEST(CgalCheck, JitteredSpheres) {
  // Vertices moved at random by up to a fraction of the edge length: folds and crossings of
  // every kind (shared edge, shared vertex, disjoint), counted both ways.
  std::mt19937_64 rng(3);
  size_t nonzero = 0;
  for (int trial = 0; trial < 12; ++trial) {
    TriMesh m = make_sphere({0, 0, 0}, 1, 24);
    const double amp = 0.02 * (1 + trial);
    std::uniform_real_distribution<double> u(-amp, amp);
    for (auto& p : m.positions)
      for (double& x : p) x += u(rng);
    const long c = cgal_count(m);
    ASSERT_GE(c, 0);
    EXPECT_EQ(long(count_self_intersections(m)), c) << "trial " << trial;
    nonzero += c > 0;
  }
  EXPECT_GT(nonzero, 3u);  // the cases do cross
}

}  // namespace
}  // namespace pic

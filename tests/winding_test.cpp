// Winding numbers: the dipole tree's decisions against exact sums, and the boundary caps.
#include <gtest/gtest.h>

#include <numbers>
#include <random>

#include "mesh/clean.h"
#include "sample/sources.h"
#include "support/shapes.h"
#include "geometry/winding.h"

namespace pic {
namespace {

using detail::DipoleTree;
using detail::I3;
using detail::ITri;

std::vector<ITri> grid_tris(const TriMesh& m) {
  std::vector<ITri> out;
  for (const auto& t : m.triangles)
    out.push_back(detail::make_itri(detail::to_grid(m.positions[t[0]]), detail::to_grid(m.positions[t[1]]),
                                    detail::to_grid(m.positions[t[2]])));
  return out;
}

double exact_winding(const TriMesh& m, const Vec3& p) {
  double w = 0;
  for (const auto& t : m.triangles)
    w += detail::triangle_winding(p, m.positions[t[0]], m.positions[t[1]], m.positions[t[2]]);
  return w;
}

TEST(Winding, ClosedSphereIsOneInsideZeroOutside) {
  const TriMesh s = make_sphere({0.5, 0.5, 0.5}, 0.3, 32);
  EXPECT_NEAR(exact_winding(s, {0.5, 0.5, 0.5}), 1.0, 1e-9);
  EXPECT_NEAR(exact_winding(s, {0.55, 0.42, 0.61}), 1.0, 1e-9);
  EXPECT_NEAR(exact_winding(s, {0.95, 0.5, 0.5}), 0.0, 1e-9);
  EXPECT_NEAR(exact_winding(s, {0.1, 0.1, 0.9}), 0.0, 1e-9);
}

// The tree's inside() must take the same decision as the exact sum wherever that sum is not
// within rounding of 1/2, for an open mesh (a sphere with a cap cut off) at random points.
TEST(Winding, TreeDecisionsMatchExactSums) {
  TriMesh s = make_sphere({0.5, 0.5, 0.5}, 0.3, 48);
  std::erase_if(s.triangles, [&](const auto& t) { return s.positions[t[0]][2] > 0.72 && s.positions[t[1]][2] > 0.72; });
  DipoleTree tree;
  tree.build_triangles(grid_tris(s));
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.1, 0.9);
  int checked = 0, inside = 0;
  for (int i = 0; i < 4000; ++i) {
    const Vec3 p{u(rng), u(rng), u(rng)};
    const double w = tree.evaluate(p, nullptr, 0).w;
    EXPECT_NEAR(w, exact_winding(s, p), 1e-7);  // the tree's vertices are on the 2^-32 grid
    if (std::abs(std::abs(w) - 0.5) < 1e-7) continue;
    ++checked;
    inside += std::abs(w) >= 0.5;
    ASSERT_EQ(tree.inside(p), std::abs(w) >= 0.5) << "at " << p[0] << " " << p[1] << " " << p[2] << " w " << w;
  }
  EXPECT_GT(checked, 3900);
  EXPECT_GT(inside, 100);  // the test sees both answers
}

// The far field's truncation bound is rigorous: at random points, near and far, the tree's
// value (nearer nodes summarized at beta = 1.5, the first look inside() takes) is within its
// bound of the exact sum.
TEST(Winding, FarFieldErrorIsWithinItsBound) {
  TriMesh s = make_sphere({0.5, 0.5, 0.5}, 0.3, 48);
  std::erase_if(s.triangles, [&](const auto& t) { return s.positions[t[0]][0] > 0.7; });
  DipoleTree tree;
  tree.build_triangles(grid_tris(s));
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-0.5, 1.5);
  int approximated = 0;
  for (int i = 0; i < 3000; ++i) {
    const Vec3 p{u(rng), u(rng), u(rng)};
    const double exact = tree.evaluate(p, nullptr, 0).w;
    for (double beta : {1.5, 2.5}) {
      const auto v = tree.evaluate(p, nullptr, beta);
      approximated += v.bound > 0;
      ASSERT_LE(std::abs(v.w - exact), v.bound + 1e-9) << "beta " << beta << " at " << p[0] << " " << p[1] << " " << p[2];
    }
  }
  EXPECT_GT(approximated, 3000);  // the test exercises the far field
}

// Angles summed by complex products, turns counted, against the plain sum of atan2s:
// random terms (many wraps past +-pi), terms on the negative real axis with signed zeros.
TEST(Winding, AngleSumCountsTurnsExactly) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 200; ++trial) {
    detail::AngleSum sum;
    double plain = 0;
    const int n = 1 + trial * 5;
    for (int i = 0; i < n; ++i) {
      detail::AngleTerms t{u(rng), u(rng)};
      if (i % 7 == 3) t = {trial % 2 ? 0.0 : -0.0, -u(rng) * u(rng) - 1e-3};  // exactly +-pi
      if (i % 11 == 5) t.den *= 1e-30;                                       // tiny magnitudes
      sum.add(t);
      plain += std::atan2(t.det, t.den);
    }
    ASSERT_NEAR(sum.turns(), plain / (2 * std::numbers::pi), 1e-9) << "trial " << trial;
  }
}

// The caps close the boundary chain: every edge of mesh + caps has net count 0.
TEST(Winding, CapsCloseTheBoundaryChain) {
  TriMesh s = make_sphere({0.5, 0.5, 0.5}, 0.3, 32);
  // Two holes and a flipped triangle.
  std::erase_if(s.triangles, [&](const auto& t) { return s.positions[t[0]][2] > 0.75 || s.positions[t[0]][0] < 0.25; });
  std::swap(s.triangles[10][1], s.triangles[10][2]);
  const auto chain = detail::boundary_chain(s);
  ASSERT_FALSE(chain.empty());
  size_t loops = 0;
  TriMesh closed = s;
  for (const auto& t : detail::cap_loops(chain, &loops)) closed.triangles.push_back(t);
  EXPECT_GE(loops, 2u);
  EXPECT_TRUE(detail::boundary_chain(closed).empty());
}

// The sampler's decision at a lattice point (integer winding of mesh + caps by a ray, minus the
// caps' share) is the exact sum's wherever that is not within the caps' tolerance (0.05) of 1/2:
// an open sphere with two holes, one of them large, and a flipped triangle.
TEST(Winding, RayAndCapsDecideAsTheExactSum) {
  TriMesh s = make_sphere({0.5, 0.5, 0.5}, 0.3, 40);
  std::erase_if(s.triangles, [&](const auto& t) { return s.positions[t[0]][2] > 0.7 || s.positions[t[0]][0] < 0.25; });
  std::swap(s.triangles[10][1], s.triangles[10][2]);
  const detail::CleanMesh clean = detail::clean_mesh(s);
  std::vector<I3> grid;
  for (const Vec3& p : clean.mesh.positions) grid.push_back(detail::to_grid(p));
  size_t loops = 0;
  const detail::WindingInput in = detail::winding_input(clean.mesh, grid, 1.0 / 1024, &loops);
  EXPECT_EQ(loops, 2u);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.05, 0.95);
  int checked = 0, inside = 0;
  for (int i = 0; i < 4000; ++i) {
    const I3 g = detail::to_grid({u(rng), u(rng), u(rng)});
    const double w = exact_winding(clean.mesh, detail::to_unit(g));
    if (std::abs(std::abs(w) - 0.5) < 0.05) continue;
    ++checked;
    inside += std::abs(w) >= 0.5;
    const Vec3 q = detail::to_unit(g);
    ASSERT_EQ(in.source->inside(g), std::abs(w) >= 0.5) << "w " << w << " at " << q[0] << " " << q[1] << " " << q[2];
  }
  EXPECT_GT(checked, 3500);
  EXPECT_GT(inside, 100);
}

TEST(Winding, BoundaryFieldIsTheLevelSetNormalOfAFlatHole) {
  // A unit square loop in the plane z = 0.5, counter-clockwise seen from +z: on its axis the
  // field is along z.
  const std::vector<std::array<Vec3, 2>> loop = {{Vec3{0.4, 0.4, 0.5}, Vec3{0.6, 0.4, 0.5}},
                                                 {Vec3{0.6, 0.4, 0.5}, Vec3{0.6, 0.6, 0.5}},
                                                 {Vec3{0.6, 0.6, 0.5}, Vec3{0.4, 0.6, 0.5}},
                                                 {Vec3{0.4, 0.6, 0.5}, Vec3{0.4, 0.4, 0.5}}};
  const Vec3 f = detail::boundary_field(loop, {0.5, 0.5, 0.52});
  EXPECT_NEAR(std::abs(f[2]) / std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]), 1.0, 1e-9);
}

}  // namespace
}  // namespace pic

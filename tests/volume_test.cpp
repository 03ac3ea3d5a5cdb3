// Offsets, shells, rounds, thickened surfaces and implicit solids: volumes against the exact
// formulas, vertices on the exact offset surface, sharp edges where the exact answer is sharp.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <functional>
#include <memory>
#include <numbers>
#include <string>
#include <tuple>

#include <random>

#include "geometry/mesh_distance.h"
#include "geometry/tolerances.h"
#include "geometry/vec3.h"
#include "sample/round_body.h"
#include "sample/rounded_edges.h"
#include "pic/contour.h"
#include "pic/csg.h"
#include "pic/io.h"
#include "pic/measure.h"
#include "pic/primitives.h"
#include "pic/sample.h"
#include "pic/volume.h"
#include "support/mesh_checks.h"
#include "support/shapes.h"

namespace pic {
namespace {

using std::numbers::pi;
using test::IsClosedManifold;

/// Signed distance to the axis-aligned box [lo, hi].
double box_distance(const Vec3& p, const Vec3& lo, const Vec3& hi) {
  double out2 = 0, in = -1e300;
  for (int k = 0; k < 3; ++k) {
    const double d = std::max(lo[k] - p[k], p[k] - hi[k]);
    if (d > 0) out2 += d * d;
    in = std::max(in, d);
  }
  return out2 > 0 ? std::sqrt(out2) : in;
}

/// The volume of a box a x b x c grown by r (Minkowski sum with a ball).
double grown_box_volume(double a, double b, double c, double r) {
  return a * b * c + 2 * r * (a * b + b * c + c * a) + pi * r * r * (a + b + c) + 4.0 / 3 * pi * r * r * r;
}

double finest_cell(const Octree& t) { return t.cube.size / double(int64_t{1} << t.max_depth); }

SampleOptions at_depth(int depth) {
  SampleOptions o;
  o.depth = depth;
  return o;
}

void expect_valid(const TriMesh& m) {
  ASSERT_TRUE(IsClosedManifold(m));
  EXPECT_EQ(count_self_intersections(m), 0u);
}

TEST(Offset, UnitCubeGrownHasTheExactVolumeAndFlatFaces) {
  const Octree t = offset(make_box({0, 0, 0}, {1, 1, 1}), 0.1, at_depth(9));
  const TriMesh m = contour(t);
  expect_valid(m);
  const double exact = grown_box_volume(1, 1, 1, 0.1);
  EXPECT_NEAR(volume(m), exact, 5e-4 * exact);
  // Every vertex on the exact offset surface; those on the flat faces exactly.
  double worst = 0;
  size_t flat = 0;
  for (const Vec3& p : m.positions) {
    worst = std::max(worst, std::abs(box_distance(p, {0, 0, 0}, {1, 1, 1}) - 0.1));
    // Beside a face, two cells away from its rounded border: the face's plane, 0.1 out.
    const double c2 = 2 * finest_cell(t);
    int inside = 0;
    for (int k = 0; k < 3; ++k) inside += p[k] > c2 && p[k] < 1 - c2;
    if (inside == 2) {
      ++flat;
      for (int k = 0; k < 3; ++k)
        if (!(p[k] > c2 && p[k] < 1 - c2)) EXPECT_NEAR(std::abs(p[k] - 0.5), 0.6, 1e-6);
    }
  }
  EXPECT_GT(flat, 0u);
  EXPECT_LE(worst, 0.25 * finest_cell(t));
  std::printf("  [measure] grown cube: volume %.7f (exact %.7f), worst vertex %.3f cells, %zu PICs\n", volume(m),
              exact, worst / finest_cell(t), t.vertices.size());
}

TEST(Offset, UnitCubeShrunkIsTheSmallerCubeWithSharpEdges) {
  const Octree t = offset(make_box({0, 0, 0}, {1, 1, 1}), -0.1, at_depth(9));
  const TriMesh m = contour(t);
  expect_valid(m);
  EXPECT_NEAR(volume(m), 0.512, 1e-6);
  for (int c = 0; c < 8; ++c) {
    const Vec3 corner{c & 1 ? 0.9 : 0.1, c & 2 ? 0.9 : 0.1, c & 4 ? 0.9 : 0.1};
    EXPECT_LE(test::nearest_vertex_distance(m, corner), 1e-6) << "corner " << c;
  }
}

TEST(Offset, LPrismGrownKeepsItsConcaveEdgeSharp) {
  // An L: [0,2]x[0,1]x[0,1] and [0,1]x[0,2]x[0,1]; its concave edge runs along z at x = y = 1.
  SampleOptions o = at_depth(8);
  o.cube = Cube{{-0.5, -0.5, -0.5}, 3};
  const Octree lt = csg(sample(make_box({0, 0, 0}, {2, 1, 1}), o), sample(make_box({0, 0.5, 0}, {1, 2, 1}), o),
                        CsgOp::Union);
  const double r = 0.2;
  const Octree t = offset(lt, r, at_depth(9));
  const TriMesh m = contour(t);
  expect_valid(m);
  // The grown L's concave crease is the line x = y = 1 + r: a vertex on it, away from the ends.
  double best = 1e300;
  for (const Vec3& p : m.positions)
    if (p[2] > 0.2 && p[2] < 0.8) best = std::min(best, std::hypot(p[0] - (1 + r), p[1] - (1 + r)));
  EXPECT_LE(best, 1e-6);
}

TEST(Minkowski, CubePlusAFacetedSphereHasFlatFacesAtTheSupport) {
  const TriMesh ball = make_sphere({0.3, -0.2, 0.1}, 0.1, 64);  // centred off the origin
  ASSERT_TRUE(is_round_body(ball.positions));
  EXPECT_FALSE(is_round_body(make_box({0, 0, 0}, {1, 1, 1}).positions));
  EXPECT_FALSE(is_round_body(make_sphere({0, 0, 0}, 1, 6).positions));  // facets too deep
  const Octree t = minkowski_round(make_box({0, 0, 0}, {1, 1, 1}), ball.positions, at_depth(9));
  const TriMesh m = contour(t);
  expect_valid(m);
  // Faces move out by the ball's support along their normals (its extent from its centre),
  // and the whole sum by the centre. The sum is a polyhedron: a leaf holding the face and
  // the first facets of the round beside it (a shallow crease, 2.8 degrees) may take one
  // plane for both, its vertex a hair off the face; the others lie on it.
  double lo[3], hi[3];
  for (int k = 0; k < 3; ++k) lo[k] = 1e300, hi[k] = -1e300;
  for (const Vec3& p : ball.positions)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
  const Vec3 c{0.3, -0.2, 0.1};
  size_t flat = 0, exact_on_face = 0;
  double worst = 0;
  const double c2 = 2 * finest_cell(t);
  for (const Vec3& p : m.positions) {
    int inside = 0;
    for (int k = 0; k < 3; ++k) inside += p[k] - c[k] > c2 && p[k] - c[k] < 1 - c2;
    if (inside != 2) continue;
    ++flat;
    double off = 0;
    for (int k = 0; k < 3; ++k) {
      if (p[k] - c[k] <= c2) off = std::abs(p[k] - lo[k]);
      if (p[k] - c[k] >= 1 - c2) off = std::abs(p[k] - 1 - hi[k]);
    }
    worst = std::max(worst, off);
    exact_on_face += off <= 1e-6;
  }
  EXPECT_GT(flat, 100u);
  EXPECT_LE(worst, 0.05 * finest_cell(t));
  EXPECT_GE(exact_on_face, flat * 9 / 10);
  std::printf("face vertices: %zu, %zu on the face within 1e-6, worst %.3f cells off\n", flat, exact_on_face,
              worst / finest_cell(t));
  // Volume: the box grown by a ball of about the same radius (facets 0.1 % deep).
  const double exact = grown_box_volume(1, 1, 1, 0.1);
  EXPECT_NEAR(volume(m), exact, 3e-3 * exact);
}

TEST(Minkowski, IndexedSupportIsTheWholeScans) {
  // The support looked up among a direction cell's candidates must be the scan over every
  // vertex: the same value and the same vertex, the first among equals -- also along the
  // axes and the cube's diagonals, where a ring of a faceted sphere ties and cells meet.
  for (const int segments : {24, 32, 64}) {
    const detail::RoundBody plain = *detail::round_body_if_round(make_sphere({0.1, 0, -0.2}, 0.5, segments).positions);
    detail::RoundBody indexed = plain;
    indexed.index_directions();
    std::vector<Vec3> directions;
    for (int x = -2; x <= 2; ++x)
      for (int y = -2; y <= 2; ++y)
        for (int z = -2; z <= 2; ++z)
          if (x || y || z) directions.push_back({double(x), double(y), double(z)});
    std::mt19937 rng(segments);
    std::normal_distribution<double> n;
    for (int i = 0; i < 20000; ++i) directions.push_back({n(rng), n(rng), n(rng)});
    size_t differ = 0;
    for (Vec3 u : directions) {
      u = detail::scale3(u, 1 / detail::norm3(u));
      const auto [h, v] = plain.support_point(u);
      const auto [hi, vi] = indexed.support_point(u);
      differ += h != hi || v != vi;
    }
    EXPECT_EQ(differ, 0u) << segments << " segments";
  }
}

TEST(Minkowski, GradientIsTheNormalOfTheSumsSurface) {
  // f is a polytope's facet planes where one of them is highest, and d - h(u) off them (u
  // the direction from the nearest point, turning with p over a box's edges and corners, and
  // the support h with it). The gradient must be f's own (central differences), not the
  // distance's alone (u): the sampler's planes are tangent to f's zero set only then.
  const detail::RoundBody body = *detail::round_body_if_round(make_sphere({0, 0, 0}, 0.1, 24).positions);
  const TriMesh box = make_box({0, 0, 0}, {1, 1, 1});
  const detail::RoundSum sum(box, body);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> at(-0.12, 1.12);
  size_t turning = 0, agree = 0, distance_only = 0;
  for (int i = 0; i < 4000; ++i) {
    const Vec3 p{at(rng), at(rng), at(rng)};
    int outside = 0;
    for (int k = 0; k < 3; ++k) outside += p[k] < 0 || p[k] > 1;
    if (outside < 2) continue;  // over a face u is fixed
    Vec3 g, unused;
    const double f = sum(p, g);
    if (std::abs(f) > 0.05) continue;  // near the surface
    const double d = sum.distance()(p);
    Vec3 fd, u;
    bool smooth = true;
    for (int k = 0; k < 3; ++k) {
      constexpr double h = 1e-7;
      Vec3 a = p, b = p;
      a[k] -= h, b[k] += h;
      const double fa = sum(a, unused), fb = sum(b, unused);
      smooth = smooth && std::abs((fb - f) - (f - fa)) < 1e-10;  // no kink between
      fd[k] = (fb - fa) / (2 * h);
      Vec3 pa = p, pb = p;
      pa[k] -= h, pb[k] += h;
      u[k] = (sum.distance()(pb) - sum.distance()(pa)) / (2 * h);
    }
    if (!smooth || !(d > 0)) continue;
    ++turning;
    const double off = std::hypot(g[0] - fd[0], g[1] - fd[1], g[2] - fd[2]);
    agree += off < 1e-5;
    distance_only += std::hypot(u[0] - fd[0], u[1] - fd[1], u[2] - fd[2]) < 1e-5;
  }
  ASSERT_GT(turning, 200u);
  EXPECT_EQ(agree, turning);
  // And the distance's gradient alone is not it: the test tells the two apart.
  EXPECT_LT(distance_only, turning / 10);
}

TEST(Minkowski, NoCoarseLeafHidesTheSum) {
  // fandisk plus a 32-segment sphere: the sum is the offset by the sphere's radius within its
  // facet depth. Under the fandisk a leaf 278 finest cells wide has crossings whose planes
  // fit while the sum's surface runs 36 cells from its polygons: its octants must be asked
  // whether the surface lies nearer than the planes, as an offset's are.
  const TriMesh fandisk = read_mesh(std::string(PIC_DATA_DIR) + "/fandisk.obj");
  const double r = 0.03;
  const TriMesh ball = make_sphere({0, 0, 0}, r, 32);
  const Octree t = minkowski_round(fandisk, ball.positions, at_depth(12));
  const TriMesh m = contour(t);
  expect_valid(m);
  const double cell = finest_cell(t);
  const OffsetDistance to_offset = offset_distance(m, fandisk, r, 20000);
  std::printf("two-sided distance to the offset by r: %.2f / %.2f finest cells\n", to_offset.worst / cell,
              to_offset.back_worst / cell);
  EXPECT_LE(to_offset.hausdorff(), 4 * cell);
}

TEST(Minkowski, LPrismPlusASphereKeepsItsConcaveEdgeSharp) {
  SampleOptions o = at_depth(8);
  o.cube = Cube{{-0.5, -0.5, -0.5}, 3};
  const TriMesh l = contour(csg(sample(make_box({0, 0, 0}, {2, 1, 1}), o),
                                sample(make_box({0, 0.5, 0}, {1, 2, 1}), o), CsgOp::Union));
  const TriMesh ball = make_sphere({0, 0, 0}, 0.2, 64);
  const TriMesh m = contour(minkowski_round(l, ball.positions, at_depth(9)));
  expect_valid(m);
  // The crease at x = y = 1 + (the ball's extent along x and y).
  double ext = 0;
  for (const Vec3& p : ball.positions) ext = std::max(ext, p[0]);
  double best = 1e300;
  for (const Vec3& p : m.positions)
    if (p[2] > 0.2 && p[2] < 0.8) best = std::min(best, std::hypot(p[0] - (1 + ext), p[1] - (1 + ext)));
  EXPECT_LE(best, 1e-6);
}

TEST(Offset, SphereRadiusMovesByTheDistance) {
  const TriMesh ball = make_sphere({0.3, -0.2, 0.1}, 1.0, 96);
  for (const double d : {0.15, -0.15}) {
    const Octree t = offset(ball, d, at_depth(8));
    const TriMesh m = contour(t);
    expect_valid(m);
    // The faceted sphere's offset: each vertex at distance |d| from the input's surface.
    const std::vector<double> dist = distance_to_mesh(ball, m.positions);
    double worst = 0;
    for (double x : dist) worst = std::max(worst, std::abs(x - std::abs(d)));
    EXPECT_LE(worst, 0.1 * finest_cell(t)) << "distance " << d;
  }
}

TEST(Offset, ShellHasWallsOfTheThickness) {
  const double T = 0.1;
  const Octree inward = shell(make_box({0, 0, 0}, {1, 1, 1}), T, false, at_depth(8));
  const TriMesh m = contour(inward);
  expect_valid(m);
  EXPECT_NEAR(volume(m), 1 - std::pow(1 - 2 * T, 3), 1e-6);
  const Octree outward = shell(make_box({0, 0, 0}, {1, 1, 1}), T, true, at_depth(8));
  const TriMesh mo = contour(outward);
  expect_valid(mo);
  const double exact = grown_box_volume(1, 1, 1, T) - 1;
  EXPECT_NEAR(volume(mo), exact, 1e-3 * exact);
}

TEST(Offset, RoundingAConvexBoxIsItsOpening) {
  const double R = 0.1;
  const Octree t = round_edges(make_box({0, 0, 0}, {1, 1, 1}), R, true, at_depth(8));
  const TriMesh m = contour(t);
  expect_valid(m);
  const double exact = grown_box_volume(1 - 2 * R, 1 - 2 * R, 1 - 2 * R, R);
  EXPECT_NEAR(volume(m), exact, 2e-3 * exact);
}

TEST(Offset, ThickenedSquareSheetHasTheSlabVolume) {
  // One square of two triangles: no inside of its own.
  const TriMesh sheet{{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {{0, 1, 2}, {0, 2, 3}}};
  const double T = 0.1;
  const TriMesh m = contour(thicken(sheet, T, at_depth(8)));
  expect_valid(m);
  const double exact = 1 * T + 4 * pi * T * T / 8 + 4.0 / 3 * pi * std::pow(T / 2, 3);
  EXPECT_NEAR(volume(m), exact, 0.02 * exact);
}

TEST(Offset, ADegenerateTriangleDoesNotSpoilTheDistance) {
  // The square sheet plus a triangle with two coincident vertices (common in STL files): its
  // nearest point must not be NaN, or every later query on the thread would inherit it.
  TriMesh sheet{{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 0.5, 0}, {0.5, 0.5, 0}, {0.5, 0.6, 0}},
                {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}}};
  const double T = 0.1;
  const TriMesh m = contour(thicken(sheet, T, at_depth(7)));
  expect_valid(m);
  const double exact = 1 * T + 4 * pi * T * T / 8 + 4.0 / 3 * pi * std::pow(T / 2, 3);
  EXPECT_NEAR(volume(m), exact, 0.02 * exact);
}

TEST(Implicit, BoxWithASphericalCavityMatchesTheBoolean) {
  SampleOptions o = at_depth(7);
  o.cube = Cube{{-1, -1, -1}, 2};
  ImplicitSolid s;
  s.value = [](const Vec3& p) {
    const double box = box_distance(p, {-0.6, -0.6, -0.6}, {0.6, 0.6, 0.6});
    const double ball = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) - 0.4;
    return std::max(box, -ball);
  };
  SampleStats st;
  const Octree t = sample(s, o, &st);
  const TriMesh m = contour(t);
  expect_valid(m);
  const Octree boolean = csg(sample(make_box({-0.6, -0.6, -0.6}, {0.6, 0.6, 0.6}), o),
                             sample(make_sphere({0, 0, 0}, 0.4, 128), o), CsgOp::Subtract);
  EXPECT_LE(test::two_sided_distance(m, contour(boolean)), finest_cell(t));
  for (int c = 0; c < 8; ++c) {
    const Vec3 corner{c & 1 ? 0.6 : -0.6, c & 2 ? 0.6 : -0.6, c & 4 ? 0.6 : -0.6};
    EXPECT_LE(test::nearest_vertex_distance(m, corner), 1e-6) << "corner " << c;
  }
  EXPECT_EQ(st.classifier, "implicit");
  EXPECT_GT(st.evaluations, 0u);
}

TEST(Implicit, BadInputIsRefused) {
  ImplicitSolid s;
  SampleOptions o;
  EXPECT_THROW(sample(s, o), InvalidInput);  // no function
  s.value = [](const Vec3& p) { return p[0]; };
  EXPECT_THROW(sample(s, o), InvalidInput);  // no cube
  o.cube = Cube{{1, 1, 1}, 1};
  EXPECT_THROW(sample(s, o), InvalidInput);  // all outside: no solid
  EXPECT_THROW(offset(make_box({0, 0, 0}, {1, 1, 1}), std::nan(""), o), InvalidInput);
}

TEST(Offset, VolumeMeshVerticesLieOnTheExactOffset) {
  // spot grown by 2.6 % of its size: flat facets, cylinders along its edges, spheres at its
  // vertices. Where coarse cells meet fine ones the contour adds points on cell edges and
  // faces; placed on the span of the vertices around them they fall off the curved offset,
  // placed by the operation's own function they lie on it.
  const TriMesh spot = read_mesh(std::string(PIC_DATA_DIR) + "/spot.obj");
  const double d = 0.05;
  VolumeMesh vm;
  const Octree t = offset(spot, d, at_depth(8), nullptr, &vm);
  const double cell = finest_cell(t);
  expect_valid(vm.mesh);
  const OffsetDistance exact = offset_distance(vm.mesh, spot, d, 20000);
  const OffsetDistance plain = offset_distance(contour(t), spot, d, 0);
  EXPECT_LE(exact.worst_vertex, 0.5 * cell);
  EXPECT_LE(exact.worst, cell);
  // Leaves whose polygons would leave the curved offset split (NoCoarseLeafHidesOrInventsSurface),
  // so few such seams remain: the function's points are as good at worst, better on the whole.
  EXPECT_LE(exact.worst_vertex, plain.worst_vertex);
  EXPECT_LT(offset_distance(vm.mesh, spot, d, 0).mean, plain.mean);
  // The measure tells a wrong offset apart.
  EXPECT_GE(offset_distance(vm.mesh, spot, d + cell, 0).worst_vertex, 0.5 * cell);
  std::printf("worst vertex: %.3f cells with the function, %.3f without; mean %.4f / %.4f\n", exact.worst_vertex / cell,
              plain.worst_vertex / cell, offset_distance(vm.mesh, spot, d, 0).mean / cell, plain.mean / cell);
}

TEST(Offset, ACreaseThroughLatticePointsIsKept) {
  // A square prism turned 45 degrees about x, its end caps in lattice planes and its long
  // edges on lattice lines: each cap's creases with the slanted sides run diagonally through
  // lattice points. Where a side between two vertices on such a crease meets a cell face only
  // at the face's corner, the face point it needs must stay on the crease: put where the
  // surface around crosses the face, it lay on a slanted side, and the triangles from it cut
  // the crease by up to two finest cells.
  TriMesh prism;
  for (const double x : {-4.0, -2.0})
    for (const auto& [y, z] : std::array<std::array<double, 2>, 4>{{{4, 3}, {-2, 9}, {-8, 3}, {-2, -3}}})
      prism.positions.push_back({x, y, z});
  prism.triangles = {{0, 3, 2}, {0, 2, 1}, {4, 5, 6}, {4, 6, 7}};
  for (uint32_t i = 0; i < 4; ++i) {
    const uint32_t j = (i + 1) % 4;
    prism.triangles.push_back({i, j, 4 + j});
    prism.triangles.push_back({i, 4 + j, 4 + i});
  }
  ASSERT_NEAR(volume(prism), 144, 1e-9);
  SampleOptions o = at_depth(9);
  o.cube = Cube{{-14.25, -18, -13.25}, 32};
  VolumeMesh vm;
  const Octree t = offset(prism, 0, o, nullptr, &vm);
  const double cell = finest_cell(t);
  expect_valid(vm.mesh);
  const OffsetDistance d = offset_distance(vm.mesh, prism, 0, 20000);
  std::printf("  [measure] two-sided distance %.3f / %.3f finest cells\n", d.worst / cell, d.back_worst / cell);
  EXPECT_LE(d.hausdorff(), 0.25 * cell);
}

TEST(Offset, EveryVertexWithinAQuarterCellOfTheExactOffset) {
  // spot grown by 0.05 at depth 10. Beside a concave ridge of the distance (where the grown
  // surface folds) f crosses a coarse leaf's edge twice between its corners: the finer leaves
  // beside it sample the points between with f's sign; given the coarse side's sign by the
  // settling, a vertex lands 1.16 cells off. Such a leaf is sampled again around them, and a
  // face point Newton leaves stalled at its face's border is bisected onto f's zero.
  const TriMesh spot = read_mesh(std::string(PIC_DATA_DIR) + "/spot.obj");
  const double d = 0.05;
  VolumeMesh vm;
  const Octree t = offset(spot, d, at_depth(10), nullptr, &vm);
  const double cell = finest_cell(t);
  expect_valid(vm.mesh);
  const OffsetDistance exact = offset_distance(vm.mesh, spot, d, 0);
  std::printf("worst vertex: %.3f cells off the exact offset\n", exact.worst_vertex / cell);
  EXPECT_LE(exact.worst_vertex, 0.25 * cell);
}

TEST(Offset, VerticesOfCappedLeavesLieOnTheSurface) {
  // spot shrunk by two finest cells at depth 9: where its ears and nose meet the head the
  // leaves at the cap hold more than their planes fit, and their clamped QEF vertices sat up to
  // 0.36 cells inside the exact offset. Moved along f's gradient within their cells, they lie
  // on it.
  const TriMesh spot = read_mesh(std::string(PIC_DATA_DIR) + "/spot.obj");
  SampleOptions o = at_depth(9);
  o.cube = Cube{{-0.96632381249999999, -0.85789281250000005, -0.77627831250000001}, 1.932647625};
  const double cell = o.cube->size / 512, d = -2 * cell;
  VolumeMesh vm;
  const Octree t = offset(spot, d, o, nullptr, &vm);
  expect_valid(vm.mesh);
  const OffsetDistance exact = offset_distance(vm.mesh, spot, d, 0);
  std::printf("worst vertex: %.3f cells off the exact offset\n", exact.worst_vertex / cell);
  EXPECT_LE(exact.worst_vertex, 0.1 * cell);
  EXPECT_GT(analyze(t).capped, 0u);
}

TEST(Offset, SettledSignsAtTheCapKeepToTheSurface) {
  // spot shrunk by twenty finest cells at depth 9: its horns thin to tips a cell across, where
  // leaves at the cap hold two pieces and one corner's sign must give. Giving up a point half a
  // cell from the surface put a vertex 0.31 cells off (its cell has no point of the surface);
  // the point nearest the surface moves it least.
  const TriMesh spot = read_mesh(std::string(PIC_DATA_DIR) + "/spot.obj");
  SampleOptions o = at_depth(9);
  o.cube = Cube{{-0.96632381249999999, -0.85789281250000005, -0.77627831250000001}, 1.932647625};
  const double cell = o.cube->size / 512, d = -20 * cell;
  VolumeMesh vm;
  offset(spot, d, o, nullptr, &vm);
  expect_valid(vm.mesh);
  const OffsetDistance exact = offset_distance(vm.mesh, spot, d, 0);
  std::printf("worst vertex: %.3f cells off the exact offset\n", exact.worst_vertex / cell);
  EXPECT_LE(exact.worst_vertex, 0.2 * cell);
}

TEST(OffsetSurfacePoints, LieOnTheExactOffsetOfABoxInTheirShare) {
  // The unit cube grown by 0.1: six flat faces (area 6), twelve quarter cylinders (12 x 0.05 pi)
  // and eight eighth spheres (0.04 pi). Every point is at distance 0.1 from the box, and the
  // flat faces get their share of the points.
  const TriMesh cube = make_box({0, 0, 0}, {1, 1, 1});
  const std::vector<Vec3> grown = offset_surface_points(cube, 0.1, 20000);
  ASSERT_GE(grown.size(), 19000u);  // a convex solid: nearly every point is kept
  size_t flat = 0;
  for (const Vec3& p : grown) {
    EXPECT_NEAR(box_distance(p, {0, 0, 0}, {1, 1, 1}), 0.1, 1e-9);
    int outside = 0;
    for (int k = 0; k < 3; ++k) outside += p[k] < 0 || p[k] > 1;
    flat += outside == 1;
  }
  const double faces = 6, total = faces + 12 * 0.05 * pi + 0.04 * pi;
  EXPECT_NEAR(double(flat) / double(grown.size()), faces / total, 0.01);
  // Shrunk by 0.1: the cube of side 0.8, its faces all reached.
  const std::vector<Vec3> shrunk = offset_surface_points(cube, -0.1, 20000);
  ASSERT_GE(shrunk.size(), 5000u);
  Vec3 lo{1, 1, 1}, hi{0, 0, 0};
  for (const Vec3& p : shrunk) {
    EXPECT_NEAR(box_distance(p, {0.1, 0.1, 0.1}, {0.9, 0.9, 0.9}), 0, 1e-9);
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
  }
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(lo[k], 0.1, 1e-9);
    EXPECT_NEAR(hi[k], 0.9, 1e-9);
  }
}

TEST(Offset, TheOffsetDistanceSeesAMissingPart) {
  // Two unit cubes apart, and the offset of only one of them: every point of that offset lies
  // on the pair's exact offset (one way, nothing is wrong), but the other cube's offset surface
  // is far from it (the way back sees the missing part).
  const TriMesh a = make_box({0, 0, 0}, {1, 1, 1});
  TriMesh pair = a;
  const TriMesh b = make_box({3, 0, 0}, {4, 1, 1});
  for (const auto& t : b.triangles)
    pair.triangles.push_back({t[0] + uint32_t(a.positions.size()), t[1] + uint32_t(a.positions.size()),
                              t[2] + uint32_t(a.positions.size())});
  pair.positions.insert(pair.positions.end(), b.positions.begin(), b.positions.end());
  SampleOptions o = at_depth(7);
  o.cube = Cube{{-0.5, -0.5, -0.5}, 5};
  const Octree t = offset(a, 0.1, o);
  const double cell = finest_cell(t);
  const TriMesh grown = contour(t);
  const OffsetDistance own = offset_distance(grown, a, 0.1, 20000);
  EXPECT_LE(own.hausdorff(), cell);
  const OffsetDistance of_pair = offset_distance(grown, pair, 0.1, 20000);
  EXPECT_LE(of_pair.worst, cell);
  EXPECT_GE(of_pair.back_worst, 1.5);
  std::printf("  [measure] cube grown by 0.1 at depth 7: %.3f / %.3f cells both ways\n", own.worst / cell,
              own.back_worst / cell);
}

TEST(Offset, TheOffsetDistanceIsNotFooledByAFoldedSliver) {
  // A unit cube whose top is a fan around a vertex just past its edge x = 1 (as rounding to
  // floats folds a sliver over): the fan's triangle on that edge faces down, into the cube.
  // Points 0.1 above it lie on the exact offset by 0.1; the nearest face's normal alone would
  // put them inside, 0.2 from it.
  const double e = 1e-4, h = 0.1;
  TriMesh cube;
  cube.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}, {1 + e, 0.5, 1}};
  cube.triangles = {{0, 2, 1}, {0, 3, 2}, {0, 1, 5}, {0, 5, 4}, {1, 2, 6}, {1, 6, 5}, {2, 3, 7},
                    {2, 7, 6}, {3, 0, 4}, {3, 4, 7}, {4, 5, 8}, {5, 6, 8}, {6, 7, 8}, {7, 4, 8}};
  ASSERT_FALSE(self_intersecting_pairs(cube).empty());
  TriMesh above;
  const double x = 1 + e / 2;
  above.positions = {{x - e / 8, 0.5 - e / 8, 1 + h}, {x + e / 8, 0.5 - e / 8, 1 + h}, {x, 0.5 + e / 8, 1 + h}};
  above.triangles = {{0, 1, 2}};
  const OffsetDistance d = offset_distance(above, cube, h, 100);
  EXPECT_LT(d.worst, 1e-9);
  // The way back: every point of the exact offset lies outside the cube, at distance h.
  for (const Vec3& p : offset_surface_points(cube, h, 2000)) {
    const bool inside = p[0] > 0 && p[0] < 1 && p[1] > 0 && p[1] < 1 && p[2] > 0 && p[2] < 1;
    EXPECT_FALSE(inside) << p[0] << " " << p[1] << " " << p[2];
  }
}

// A leaf may stand only for the surface its corners, crossings and polygons account for: in
// each case below a coarse cell's data alone fit a wrong surface, which would still contour to
// a valid solid, the wrong part as wide as that cell at any depth.
TEST(Offset, NoCoarseLeafHidesOrInventsSurface) {
  const std::string dir = std::string(PIC_DATA_DIR);
  // fandisk grown by a hair: its flange passes through cells between their corners and edges
  // (missed, the grown solid would have 2 units^3 less volume than the input).
  const TriMesh fandisk = read_mesh(dir + "/fandisk.obj");
  const Octree grown = offset(fandisk, 0.001, at_depth(8));
  EXPECT_GT(volume(contour(grown)), volume(fandisk));
  // cad_part (a 0.05 wall between a hole and a face) at depth 9 in a cube of 0.66: shrunk by
  // 20 cells the wall goes, leaving a slot, and a level-2 cell's crossings fit the hole's
  // curved offset and the face's plane as one crease (a diamond 0.13 wide through the face);
  // grown by 20 cells, a level-3 cell's polygons would cut across the rounded rim of the hole;
  // grown by 100, the floor under the hole dips 2.5 cells (the rim's round) between four
  // level-3 leaves whose corners and octant centres all lie on the flat part, and only their
  // polygons' middles see it.
  const TriMesh part = read_mesh(dir + "/cad_part.obj");
  for (const auto& [cells, origin, size] :
       {std::tuple{-20.0, Vec3{-0.33, -0.33, -0.23}, 0.66}, std::tuple{20.0, Vec3{-0.361, -0.361, -0.261}, 0.722},
        std::tuple{100.0, Vec3{-0.55, -0.55, -0.45}, 1.1}}) {
    SampleOptions o = at_depth(9);
    o.cube = Cube{origin, size};
    const double cell = size / 512, d = cells * cell;
    const TriMesh m = contour(offset(part, d, o));
    const OffsetDistance e = offset_distance(m, part, d, 50000);
    EXPECT_LE(e.worst, cell) << cells << " cells";
    if (cells > 0) EXPECT_LE(e.back_worst, cell) << cells << " cells";
    std::printf("  [measure] cad_part offset by %g cells: %.3f / %.3f cells both ways\n", cells, e.worst / cell,
                e.back_worst / cell);
  }
}

// A coarse leaf's planes are its own edges' crossings, its polygons run to its neighbours'
// vertices: a faceted sphere of 6 segments shrunk by a third of a unit can have a leaf holding
// a corner of the top cap whose polygons run straight across the equator's crease to vertices
// below it, half a unit deep into the solid whatever the depth. Each polygon must keep to the
// surface between its vertices.
TEST(Offset, PolygonsOfACoarseLeafKeepToTheSurface) {
  const TriMesh ball = make_sphere({0, 0, 0}, 4, 6);
  for (const int depth : {8, 9}) {
    const Octree t = offset(ball, -0.3125, at_depth(depth));
    const TriMesh m = contour(t);
    expect_valid(m);
    const double cell = finest_cell(t);
    const OffsetDistance e = offset_distance(m, ball, -0.3125, 20000);
    EXPECT_LE(e.worst, cell) << "depth " << depth;
    EXPECT_LE(e.back_worst, cell) << "depth " << depth;
    std::printf("  [measure] 6-segment sphere shrunk at depth %d: %.3f / %.3f cells both ways\n", depth,
                e.worst / cell, e.back_worst / cell);
  }
}

// An offset rounds a shrunk solid's concave edges. A triangular prism with a square hole near
// its tip, shrunk by 20.37 cells: the hole's corner becomes a round of radius 0.64 that bulges
// 5 cells off the sharp corner its two walls' planes make, and a leaf 70 cells wide there can
// have every edge crossing on the walls beside the round, its polygons straight across it.
TEST(Offset, RoundsOfSharpEdgesAreNotCutOffByCoarseLeaves) {
  TriMesh prism;
  prism.positions = {{-6.5, -9.33013, 4}, {-6.5, -0.669872, 7}, {-6.5, -0.669872, 4}, {-6.5, -9.33013, 7},
                     {1, -5, 4},          {1, -5, 7},           {-1.5, -4.5, 7},      {-1.5, -5.5, 7},
                     {-0.5, -4.5, 7},     {-0.5, -5.5, 7},      {-1.5, -5.5, 4},      {-1.5, -4.5, 4},
                     {-0.5, -5.5, 4},     {-0.5, -4.5, 4}};
  prism.triangles = {{0, 1, 2},   {1, 0, 3},  {4, 1, 5},   {1, 4, 2},   {6, 1, 7},   {8, 1, 6},   {1, 8, 5},
                     {9, 5, 8},   {9, 3, 5},  {7, 3, 9},   {3, 7, 1},   {0, 5, 3},   {5, 0, 4},   {10, 0, 11},
                     {12, 0, 10}, {0, 12, 4}, {13, 4, 12}, {13, 2, 4},  {11, 2, 13}, {2, 11, 0},  {12, 8, 13},
                     {8, 12, 9},  {7, 11, 6}, {11, 7, 10}, {11, 8, 6},  {8, 11, 13}, {12, 7, 9},  {7, 12, 10}};
  SampleOptions o = at_depth(9);
  o.cube = Cube{{-10.75, -13.000001, -2.5}, 16};
  const double cell = 16.0 / 512, d = -20.37 * cell;
  const TriMesh m = contour(offset(prism, d, o));
  expect_valid(m);
  const OffsetDistance e = offset_distance(m, prism, d, 20000);
  EXPECT_LE(e.worst, cell);
  EXPECT_LE(e.back_worst, cell);
  std::printf("  [measure] prism with a hole shrunk by 20.37 cells: %.3f / %.3f cells both ways\n", e.worst / cell,
              e.back_worst / cell);
}

// A closed, consistently oriented mesh that crosses itself (two overlapping boxes written as
// one mesh, as a soup union or an export whose float vertices cross) has faces inside the
// solid, and a point beside one takes the sign of that face's pseudonormal: outside. Its
// offset is taken to its sampled surface instead, whose signs are the winding number's.
TEST(Offset, AMeshThatCrossesItselfIsOffsetAsTheSolidItBounds) {
  const TriMesh two = joined(make_box({0, 0, 0}, {1.2, 1, 1}), make_box({0.8, 0, 0}, {2, 1, 1}));
  ASSERT_GT(count_self_intersections(two), 0u);
  const TriMesh m = contour(offset(two, -0.1, at_depth(7)));
  expect_valid(m);
  // The union [0, 2] x [0, 1] x [0, 1] shrunk by 0.1.
  EXPECT_NEAR(volume(m), 1.8 * 0.8 * 0.8, 1e-6);
}

TEST(MeshDistance, FartherThanNeverMissesATriangle) {
  // Boxes of 1 to 32 finest cells (depth 10) about spot's surface and radii up to 40 cells:
  // whenever the test says every triangle is farther than r, no point of the box may be
  // within r (checked on a 6 x 6 x 6 grid of points in it). Boxes the centre's distance
  // alone clears must be cleared, and the test must clear more than those.
  const TriMesh spot = read_mesh(std::string(PIC_DATA_DIR) + "/spot.obj");
  const detail::MeshDistance md(spot);
  const double cell = 2.0 / 1024;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  int cleared = 0, by_centre = 0, beyond_centre = 0;
  for (int i = 0; i < 3000; ++i) {
    const Vec3& v = spot.positions[rng() % spot.positions.size()];
    const double size = cell * std::pow(2.0, std::floor(6 * u(rng))), r = 40 * cell * u(rng);
    Vec3 lo, hi;
    for (int k = 0; k < 3; ++k) lo[k] = v[k] + (u(rng) - 0.5) * 2 * (r + 2 * size), hi[k] = lo[k] + size;
    const bool away = md.farther_than(lo, hi, r);
    const Vec3 centre{(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2};
    const bool centre_clears = md.distance(centre) > r + size * std::sqrt(3.0) / 2;
    if (centre_clears) {
      ++by_centre;
      EXPECT_TRUE(away);
    }
    if (!away) continue;
    ++cleared;
    beyond_centre += !centre_clears;
    for (int a = 0; a < 6; ++a)
      for (int b = 0; b < 6; ++b)
        for (int c = 0; c < 6; ++c) {
          const Vec3 p{lo[0] + size * a / 5, lo[1] + size * b / 5, lo[2] + size * c / 5};
          ASSERT_GT(md.distance(p), r) << "box " << i << " point " << a << b << c;
        }
  }
  EXPECT_GT(by_centre, 100);
  EXPECT_GT(beyond_centre, 30);
  std::printf("cleared %d of 3000 boxes, %d the centre alone would not\n", cleared, beyond_centre);
}

TEST(MeshDistance, NearestIsTheLeastOverEveryTriangle) {
  // The search prunes by float boxes and by each triangle's plane and sides held in floats: a
  // bound whose rounding slack were too small would skip the answer for points on or near the
  // surface, most of all far from the origin. Spot as it is and moved 10^4 away, plus
  // degenerate triangles (a repeated vertex, three on a line); points on the surface, a hair
  // off it, at offset distances and far away, asked with the last answer as the hint and
  // with none: the distance must be a scan's over every triangle, the triangle one at that
  // distance whatever the hint, and `within` must agree. A lone triangle too (the tree is
  // one leaf), slivers apart (a sliver's computed plane can miss its own corners), and a point
  // 10^20 away (float squares of such gaps overflow).
  TriMesh spot = read_mesh(std::string(PIC_DATA_DIR) + "/spot.obj");
  const uint32_t n0 = uint32_t(spot.positions.size());
  spot.positions.push_back({0.1, 0.2, 0.3});
  spot.positions.push_back({0.4, 0.2, 0.3});
  spot.positions.push_back({0.7, 0.2, 0.3});
  spot.triangles.push_back({n0, n0, n0 + 1});
  spot.triangles.push_back({n0, n0 + 1, n0 + 2});
  TriMesh lone;
  lone.positions = {{0, 0, 0}, {1, 0.2, 0}, {0.3, 0.9, 0.1}};
  lone.triangles = {{0, 1, 2}};
  TriMesh slivers;
  for (const double h : {1e-15, 1e-13, 1e-11, 1e-9}) {
    const uint32_t v = uint32_t(slivers.positions.size());
    const double z = double(v);
    slivers.positions.push_back({0.1, 0.3, z});
    slivers.positions.push_back({1.7, 0.9, z + 0.2});
    slivers.positions.push_back({0.9 + h, 0.6 - h, z + 0.1 + h});
    slivers.triangles.push_back({v, v + 1, v + 2});
  }
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  for (const auto& [base, shift] :
       {std::pair{&spot, 0.0}, std::pair{&spot, 1e4}, std::pair{&lone, 0.0}, std::pair{&slivers, 0.0}}) {
    TriMesh mesh = *base;
    for (Vec3& x : mesh.positions) x = {x[0] + shift, x[1] - shift, x[2] + shift};
    const detail::MeshDistance md(mesh);
    const detail::MeshDistance boxes(mesh, detail::Pruning::Boxes);  // the same answers, fewer bounds
    uint32_t hint = 0;
    for (int i = 0; i < 4000; ++i) {
      const uint32_t ti = uint32_t(rng() % mesh.triangles.size());
      const auto& t = mesh.triangles[ti];
      const double w0 = (u(rng) + 1) / 2, w1 = (1 - w0) * (u(rng) + 1) / 2;
      Vec3 p;
      for (int k = 0; k < 3; ++k)
        p[k] = w0 * mesh.positions[t[0]][k] + w1 * mesh.positions[t[1]][k] + (1 - w0 - w1) * mesh.positions[t[2]][k];
      const double off = std::array{0.0, 1e-9, 1e-4, 0.05, 0.5, 3.0}[i % 6];
      for (int k = 0; k < 3; ++k) p[k] += off * u(rng);
      if (i == 3999) p = {1e20, -3e19, 2e19};
      double least = detail::kHuge;
      for (const auto& g : mesh.triangles)
        least = std::min(least, detail::nearest_on_triangle(p, mesh.positions[g[0]], mesh.positions[g[1]],
                                                            mesh.positions[g[2]]).distance);
      const detail::Nearest hinted = md.nearest(p, &hint), plain = md.nearest(p);
      ASSERT_EQ(hinted.distance, least) << "shift " << shift << " point " << i;
      // The triangle: one at that distance (ties of the rounded root may differ in their
      // squares, which the search compares), the same with and without the hint.
      const auto& g = mesh.triangles[hinted.triangle];
      ASSERT_EQ(detail::nearest_on_triangle(p, mesh.positions[g[0]], mesh.positions[g[1]], mesh.positions[g[2]]).distance,
                least);
      ASSERT_EQ(plain.triangle, hinted.triangle) << "shift " << shift << " point " << i;
      // distance() and within() have their own point-triangle formula: a margin for the two
      // roundings.
      const double margin = 1e-9 * least + 1e-14 * (1 + shift);
      ASSERT_NEAR(md.distance(p), least, margin);
      if (least > margin) ASSERT_FALSE(md.within(p, least - margin)) << "shift " << shift << " point " << i;
      ASSERT_TRUE(md.within(p, least + margin)) << "shift " << shift << " point " << i;
      ASSERT_EQ(boxes.nearest(p).distance, least) << "shift " << shift << " point " << i;
      // within() from the triangle the point was made on: what it finds lies within the radius.
      uint32_t slot = boxes.hint_of(ti);
      double found = -1;
      if (least > margin) ASSERT_FALSE(boxes.within(p, least - margin, &slot)) << "shift " << shift << " point " << i;
      slot = boxes.hint_of(ti);
      ASSERT_TRUE(boxes.within(p, least + margin, &slot, &found)) << "shift " << shift << " point " << i;
      ASSERT_GE(found, least - margin);
      ASSERT_LE(found, least + margin);
    }
  }
}

/// f = g(signed distance to `mesh`) with g's value and slope, as the sampler asks it, without
/// a proof of clear cells.
/// `rounds`: the offset distances whose rounds of sharp edges the function reports as bends,
/// as the offset `t` sampled with the default error does.
ImplicitSolid plain_distance(const detail::SignedDistance& sd, std::function<std::pair<double, double>(double)> g,
                             const TriMesh& surface, const Octree& t, std::vector<double> rounds,
                             std::vector<double> levels) {
  ImplicitSolid f;
  auto edges = std::make_shared<std::vector<detail::RoundedEdges>>();
  const double tolerance = detail::bend_tolerance(t.cube, t.max_depth, SampleOptions{}.error);
  for (double r : rounds) edges->emplace_back(surface, r, tolerance);
  f.features = [&surface, levels, tolerance](std::vector<Vec3>& points) {
    points = detail::offset_feature_points(surface, levels, tolerance);
  };
  f.bends = [edges](const Vec3& lo, const Vec3& hi, const Vec3& v, std::vector<std::array<Vec3, 2>>& out) {
    for (const detail::RoundedEdges& e : *edges) e.points(lo, hi, v, out);
  };
  f.value = [&sd, g](const Vec3& p) { return g(sd(p)).first; };
  f.value_gradient = [&sd, g](const Vec3& p, Vec3& grad) {
    const auto [v, slope] = g(sd.with_gradient(p, grad));
    for (double& x : grad) x *= slope;
    return v;
  };
  f.distance = true;  // the same distance, only without the proof that cells are clear
  return f;
}

/// Samples `plain` in t's cube at t's depth and expects the same contour as t's, bit for bit,
/// from far more cells; returns how many nodes t saved.
void expect_same_contour_from_more_cells(const Octree& t, const ImplicitSolid& plain, const char* what) {
  SampleOptions o = at_depth(t.max_depth);
  o.cube = t.cube;
  const Octree u = sample(plain, o);
  const TriMesh a = contour(t), b = contour(u);
  EXPECT_EQ(a.positions, b.positions) << what;
  EXPECT_EQ(a.triangles, b.triangles) << what;
  EXPECT_LT(double(t.nodes.size()), 0.8 * double(u.nodes.size())) << what;
  std::printf("%s: %zu nodes with the proof, %zu without\n", what, t.nodes.size(), u.nodes.size());
}

TEST(Offset, CellsBesideTheSurfaceStayCoarse) {
  // The distance proves uniform cells beside the operation's surface clear (a ball about a
  // mesh point holds the cell, or every triangle lies beyond the distance), where the bound
  // from f at the centre cannot: the same surface with far fewer cells. Sampled again without
  // that proof, the gray leaves and so the contour must be the same, bit for bit -- growing,
  // shrinking (the two proofs swap sides), a shell (two levels, one on the surface itself).
  const TriMesh spot = read_mesh(std::string(PIC_DATA_DIR) + "/spot.obj");
  const detail::SignedDistance sd(spot);
  const double d = 0.05, t = 0.03;
  const Octree grown = offset(spot, d, at_depth(9));
  expect_same_contour_from_more_cells(grown, plain_distance(sd, [&](double x) {
    return std::pair{x - d, 1.0};
  }, spot, grown, {d}, {d}), "grown");
  const Octree shrunk = offset(spot, -t, at_depth(9));
  expect_same_contour_from_more_cells(shrunk, plain_distance(sd, [&](double x) {
    return std::pair{x + t, 1.0};
  }, spot, shrunk, {-t}, {-t}), "shrunk");
  const Octree shelled = shell(spot, t, false, at_depth(9));
  expect_same_contour_from_more_cells(shelled, plain_distance(sd, [&](double x) {
    return x >= -x - t ? std::pair{x, 1.0} : std::pair{-x - t, -1.0};
  }, spot, shelled, {-t}, {0, -t}), "shell");
}

TEST(Offset, EveryLatticePointHasOneSignWhereTheDistanceBreaksItsBound) {
  // Suzanne's surface (taken through its PIC contour: sheets that touch are split a hair
  // apart) nearly touches itself, and the sign of a distance there can flip across a pinch;
  // shrunk by two finest cells at depth 9, the result must still be a consistent PIC object
  // (a loaded file is checked for one sign per lattice point) with a valid contour.
  const TriMesh suzanne = read_mesh(std::string(PIC_DATA_DIR) + "/suzanne.obj");
  const Octree t = offset(suzanne, -0.01201629638671875, at_depth(9));
  EXPECT_NO_THROW(deserialize(serialize(t)));
  expect_valid(contour(t));
}

TEST(Offset, ShrinkingToNothingSaysSo) {
  try {
    offset(make_box({0, 0, 0}, {1, 1, 1}), -0.6, at_depth(6));
    FAIL() << "expected EmptySolid";
  } catch (const EmptySolid& e) {
    EXPECT_NE(std::string(e.what()).find("leaves nothing"), std::string::npos) << e.what();
  }
  EXPECT_THROW(round_edges(make_box({0, 0, 0}, {1, 1, 1}), 0.6, true, at_depth(6)), EmptySolid);
}

TEST(Offset, DistanceBoundsDecideChecksAsTheValuesWould) {
  // The unit box's surface thickened to 0.3 on either side (a hollow box with rounded outer
  // edges and a sharp cubic cavity), f = d - 0.3 for the unsigned distance d to its triangles.
  // Told that f is a distance minus an offset, with the nearest triangle as the site, the
  // sampler decides most octant and polygon checks of its coarse leaves from bounds (the
  // parallelogram law below, the site's distance above) instead of asking f; each bound is a
  // proof, so the tree must be the same, bit for bit, from fewer values.
  const TriMesh box = make_box({0, 0, 0}, {1, 1, 1});
  const detail::MeshDistance md(box);
  const double d = 0.3;
  ImplicitSolid plain;
  plain.value = [&](const Vec3& p) { return md.nearest(p).distance - d; };
  plain.value_gradient = [&](const Vec3& p, Vec3& g) {
    const detail::Nearest n = md.nearest(p);
    const Vec3 away = detail::sub3(p, n.point);
    g = n.distance > 0 ? detail::scale3(away, 1 / n.distance) : Vec3{0, 0, 1};
    return n.distance - d;
  };
  plain.distance = true;
  ImplicitSolid bounded = plain;
  bounded.offset = d;
  bounded.value_site = [&](const Vec3& p, uint32_t& site) {
    site = 0;
    return md.nearest(p, &site).distance - d;
  };
  bounded.site_distance = [&](const Vec3& p, uint32_t site) { return md.distance_to_hint(p, site); };
  SampleOptions o = at_depth(9);
  o.cube = Cube{{-0.5, -0.5, -0.5}, 2};
  o.error = 1e-6;
  o.parallel = false;  // the per-thread memos' hits, and so the counts, vary with the threads
  SampleStats with, without;
  const Octree a = sample(bounded, o, &with), b = sample(plain, o, &without);
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  for (size_t i = 0; i < a.nodes.size(); ++i) {
    ASSERT_EQ(a.nodes[i].kind, b.nodes[i].kind) << "node " << i;
    ASSERT_EQ(a.nodes[i].signs, b.nodes[i].signs) << "node " << i;
    ASSERT_EQ(a.nodes[i].index, b.nodes[i].index) << "node " << i;
  }
  EXPECT_EQ(a.vertices, b.vertices);
  EXPECT_LT(double(with.evaluations), 0.85 * double(without.evaluations));
  std::printf("values: %zu with the bounds, %zu without\n", with.evaluations, without.evaluations);
  expect_valid(contour(a));
}

TEST(Offset, APartHiddenInACoarseLeafIsKept) {
  // A square prism 3 wide standing apart from a hexagonal prism, shrunk by 0.15 in a root cube
  // whose level-1 cell holds the whole square prism and a corner of the hexagonal one: the
  // leaf's corners, edges and octant centres all miss the square prism (every one outside
  // it, an octant centre 0.6 from it while its planes' extensions pass nearer), so it was
  // dropped, a whole part of the result gone. The surface point f's gradient leads to from
  // that octant centre lies on no polygon of the leaf: the leaf is sampled again.
  const double d = 0.148125;
  const TriMesh both = joined(make_cylinder({-4, -4, -6}, 3 / std::sqrt(2.0), 3 * std::sqrt(2.0), 2, 4),
                               make_cylinder({0, 4, 0}, 6, 4, 2, 6));
  SampleOptions o = at_depth(7);
  o.cube = Cube{{-14.56066, -14.462585, -17.5}, 32};
  const TriMesh m = contour(offset(both, -d, o));
  expect_valid(m);
  const double side = 3 - 2 * d, apothem = 6 * std::sqrt(3.0) / 2 - d;
  const double exact = side * side * (3 * std::sqrt(2.0) - 2 * d) + 2 * std::sqrt(3.0) * apothem * apothem * (4 - 2 * d);
  EXPECT_NEAR(volume(m), exact, 1e-3 * exact);
  EXPECT_EQ(check_validity(m, false).components, 2u);
}

TEST(Offset, AThinBarHiddenInACoarseLeafIsKept) {
  // An octagonal bar 3.7 across shrunk by 1.27 to a bar 1.2 across, inside a 16-unit leaf
  // that a triangular prism's corner makes gray. From the octant centre beside the bar's end
  // the first Newton step lands past the bar's rim, off the shrunk surface (the distance there
  // falls short of the way to it); further steps reach it, and the leaf is sampled again.
  const double d = 1.273125;
  const TriMesh bar = make_cylinder({8, -6, 2}, 2, 6, 0, 8);
  const TriMesh prism = make_cylinder({0, -3, 0.5}, 4, 9, 2, 3);
  SampleOptions o = at_depth(7);
  o.cube = Cube{{-15, -19, -15.25}, 32};
  const TriMesh m = contour(offset(joined(bar, prism), -d, o));
  expect_valid(m);
  const double parts = volume(contour(offset(bar, -d, o))) + volume(contour(offset(prism, -d, o)));
  EXPECT_NEAR(volume(m), parts, 2e-3 * parts);
  EXPECT_EQ(check_validity(m, false).components, 2u);
}

TEST(Offset, ADentSmallerThanACoarseLeafIsDrawn) {
  // A 4 x 5 x 6 box with a notch at one edge where a coarse sphere (8 facets round) bites 0.42
  // deep into it, shrunk by 0.105 in a root cube of 16: the shrunk notch is a dent in the
  // shrunk box's edge, smaller than the leaves around it. Every corner, edge crossing, octant
  // centre and polygon point the sampler asks lies on or beside the box's faces, whose planes
  // fit them all: the dent was dropped (the result a plain box, 0.25 off the exact offset at
  // every depth). The notch's creases, moved by the offset onto f's zero, are points of the
  // surface no polygon of that leaf passes: the leaf is split until one does.
  TriMesh notched;
  notched.positions = {{5, -6.5, 3},         {5, -1.5, -3},         {5, -1.5, 3},          {5, -6.5, -3},
                       {1, -1.5, 3},         {1, -6.5, 3},          {3.01322, -1.5, -3},   {2.93145, -1.53387, -3},
                       {2, -1.91969, -3},    {1, -6.5, -3},         {1.57403, -1.74324, -3}, {1, -1.50547, -3},
                       {1, -1.5, -2.99453},  {2, -1.5, -2.58031},   {2.84968, -1.5, -2.93226}, {1.47327, -1.5, -2.79849}};
  notched.triangles = {{0, 1, 2},   {1, 0, 3},   {4, 0, 2},   {0, 4, 5},   {3, 6, 1},   {3, 7, 6},   {3, 8, 7},
                       {9, 8, 3},   {8, 9, 10},  {10, 9, 11}, {9, 12, 11}, {12, 9, 4},  {4, 9, 5},   {2, 13, 4},
                       {2, 14, 13}, {1, 14, 2},  {14, 1, 6},  {15, 4, 13}, {4, 15, 12}, {9, 0, 5},   {0, 9, 3},
                       {11, 15, 10}, {15, 11, 12}, {10, 13, 8}, {13, 10, 15}, {8, 14, 7}, {14, 8, 13}, {6, 7, 14}};
  const double d = 0.1053125;
  SampleOptions o = at_depth(9);
  o.cube = Cube{{-5, -12, -8}, 16};
  VolumeMesh vm;
  const Octree t = offset(notched, -d, o, nullptr, &vm);
  expect_valid(vm.mesh);
  const double cell = finest_cell(t);
  const OffsetDistance exact = offset_distance(vm.mesh, notched, -d, 20000);
  std::printf("%.2f / %.2f cells from the exact offset\n", exact.worst / cell, exact.back_worst / cell);
  EXPECT_LE(exact.hausdorff(), cell);
}

}  // namespace
}  // namespace pic

// CSG on PIC octrees: exact box answers, Boolean algebra, curved cases against analytic
// signed distances, the paper's Figure 7 wedge, and cost proportional to the overlap.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <set>
#include <functional>
#include <numbers>
#include <vector>

#include "pic/pic.h"
#include "geometry/mesh_distance.h"
#include "pic/primitives.h"
#include "support/mesh_checks.h"

namespace pic {
namespace {
using namespace pic::test;

constexpr Cube kUnit{{0, 0, 0}, 1.0};

Octree sample_in_unit(const TriMesh& m, int depth, const Cube& cube = kUnit) {
  SampleOptions o;
  o.depth = depth;
  o.cube = cube;
  return sample(m, o);
}

// ---- exact solids: signed distance (negative inside) and their planes ---------------------

using Sdf = std::function<double(const Vec3&)>;

struct Plane {
  Vec3 n;
  double d;  // n.x = d
};

/// An oriented box: centre, rotation R (rows = local axes in world), half sizes.
struct Box {
  Vec3 c;
  std::array<double, 9> r;  // row-major, world = R^T local ... we store local axes as rows
  Vec3 h;

  Vec3 local(const Vec3& p) const {
    const Vec3 d{p[0] - c[0], p[1] - c[1], p[2] - c[2]};
    return {r[0] * d[0] + r[1] * d[1] + r[2] * d[2], r[3] * d[0] + r[4] * d[1] + r[5] * d[2],
            r[6] * d[0] + r[7] * d[1] + r[8] * d[2]};
  }
  double sdf(const Vec3& p) const {
    const Vec3 q = local(p);
    double out = 0, in = -1e300;
    for (int k = 0; k < 3; ++k) {
      const double e = std::abs(q[k]) - h[k];
      out += std::max(e, 0.0) * std::max(e, 0.0);
      in = std::max(in, e);
    }
    return in > 0 ? std::sqrt(out) : in;
  }
  std::vector<Plane> planes() const {
    std::vector<Plane> out;
    for (int k = 0; k < 3; ++k)
      for (double s : {-1.0, 1.0}) {
        const Vec3 n{s * r[3 * k], s * r[3 * k + 1], s * r[3 * k + 2]};
        out.push_back({n, n[0] * c[0] + n[1] * c[1] + n[2] * c[2] + h[k]});
      }
    return out;
  }
  TriMesh mesh() const {
    TriMesh m = make_box({-h[0], -h[1], -h[2]}, {h[0], h[1], h[2]});
    // local -> world: p = R^T q + c
    const std::array<double, 9> rt = {r[0], r[3], r[6], r[1], r[4], r[7], r[2], r[5], r[8]};
    return transformed(m, rt, c);
  }
};

Box axis_box(const Vec3& lo, const Vec3& hi) {
  return {{(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2},
          {1, 0, 0, 0, 1, 0, 0, 0, 1},
          {(hi[0] - lo[0]) / 2, (hi[1] - lo[1]) / 2, (hi[2] - lo[2]) / 2}};
}
Box rotated_box(const Vec3& c, const Vec3& h, const Vec3& axis, double radians) {
  const auto m = rotation(axis, radians);  // world = m * local  -> rows of m^T are local axes
  return {c, {m[0], m[3], m[6], m[1], m[4], m[7], m[2], m[5], m[8]}, h};
}

double sdf_op(CsgOp op, double a, double b) {
  switch (op) {
    case CsgOp::Union: return std::min(a, b);
    case CsgOp::Intersect: return std::max(a, b);
    case CsgOp::Subtract: return std::max(a, -b);
  }
  return 0;
}

/// Corners of the exact result: points on three independent planes of the operands that lie
/// on the result's surface and on each of the three solids' faces.
std::vector<Vec3> exact_corners(const Box& a, const Box& b, CsgOp op) {
  std::vector<std::pair<Plane, const Box*>> planes;
  for (const auto& p : a.planes()) planes.push_back({p, &a});
  for (const auto& p : b.planes()) planes.push_back({p, &b});
  std::vector<Vec3> out;
  for (size_t i = 0; i < planes.size(); ++i)
    for (size_t j = i + 1; j < planes.size(); ++j)
      for (size_t k = j + 1; k < planes.size(); ++k) {
        const Vec3 &n1 = planes[i].first.n, &n2 = planes[j].first.n, &n3 = planes[k].first.n;
        const Vec3 c23 = cross3(n2, n3), c31 = cross3(n3, n1), c12 = cross3(n1, n2);
        const double det = dot3(n1, c23);
        if (std::abs(det) < 1e-6) continue;
        Vec3 p;
        for (int q = 0; q < 3; ++q)
          p[q] = (planes[i].first.d * c23[q] + planes[j].first.d * c31[q] + planes[k].first.d * c12[q]) / det;
        const double r = sdf_op(op, a.sdf(p), b.sdf(p));
        bool on_faces = std::abs(r) < 1e-9;
        for (size_t m : {i, j, k}) on_faces = on_faces && std::abs(planes[m].second->sdf(p)) < 1e-9;
        if (on_faces) out.push_back(p);
      }
  return out;
}

/// Checks a box CSG result: closed and manifold; every representative vertex on the exact
/// surface within 1e-6 of the root cube, except leaves accepted at the depth cap (a feature
/// thinner than the finest cell), which must stay within one finest cell; every sharp corner
/// of the exact answer reproduced by a vertex within 1e-6.
void expect_exact_box_result(const Box& a, const Box& b, CsgOp op, int depth, double expected_volume = -1,
                             const Cube& cube = kUnit, bool all_corners = true, size_t min_corners = 8) {
  const Octree ta = sample_in_unit(a.mesh(), depth, cube), tb = sample_in_unit(b.mesh(), depth, cube);
  const Octree r = csg(ta, tb, op);
  const TriMesh m = unsplit_contour(r);
  ASSERT_FALSE(m.triangles.empty());
  EXPECT_TRUE(IsClosedManifold(m));
  double worst = 0, worst_capped = 0;
  const double finest = cube.size / double(1 << depth);
  for_each_leaf(r, [&](const LeafView& v) {
    if (v.kind != CellKind::Gray) return;
    const double d = std::abs(sdf_op(op, a.sdf(v.vertex), b.sdf(v.vertex)));
    if (r.nodes[v.node].flags & kFlagCapped) worst_capped = std::max(worst_capped, d);
    else worst = std::max(worst, d);
  });
  EXPECT_LT(worst, 1e-6) << "an output vertex is off the exact CSG surface";
  EXPECT_LT(worst_capped, finest) << "a vertex at the depth cap is more than a cell off";
  const auto corners = exact_corners(a, b, op);
  EXPECT_GE(corners.size(), min_corners);
  // A corner whose cell is at the depth cap may sit just across a lattice plane from the
  // leaf that has to represent it; that leaf's vertex is kept in its cell (rule 2), so the
  // corner is then reproduced within one finest cell, by a capped leaf.
  std::vector<Vec3> capped;
  for_each_leaf(r, [&](const LeafView& v) {
    if (v.kind == CellKind::Gray && (r.nodes[v.node].flags & kFlagCapped)) capped.push_back(v.vertex);
  });
  size_t exact = 0;
  if (all_corners)
    for (const Vec3& c : corners) {
      const double d = nearest_vertex_distance(m, c);
      double dc = 1e300;
      for (const Vec3& v : capped) dc = std::min(dc, dist3(v, c));
      exact += d < 1e-6;
      EXPECT_TRUE(d < 1e-6 || dc < finest)
          << "sharp corner (" << c[0] << ", " << c[1] << ", " << c[2] << ") is not reproduced: " << d;
    }
  if (all_corners) EXPECT_GE(double(exact), 0.75 * double(corners.size()));
  // Vertices are stored as floats in their cells: ~1e-8 of the root cube, so volumes to 1e-6.
  if (expected_volume > 0) EXPECT_NEAR(volume(m), expected_volume, 1e-6 * expected_volume);
}

TEST(Csg, BoxMinusRotatedBox) {
  const Box a = axis_box({0.25, 0.25, 0.25}, {0.75, 0.75, 0.75});
  // A prism turned 30 degrees about z notches A's vertical edge, through its full height.
  const Box b = rotated_box({0.72, 0.7, 0.5}, {0.1, 0.12, 0.35}, {0, 0, 1}, 30.0 * M_PI / 180);
  expect_exact_box_result(a, b, CsgOp::Subtract, 8);
}

TEST(Csg, UnionOfBoxesSharingCoplanarFaces) {
  // Same height: top and bottom faces coplanar, and a shared face at x = 0.5.
  const Box a = axis_box({0.25, 0.25, 0.25}, {0.5, 0.75, 0.5});
  const Box b = axis_box({0.5, 0.375, 0.25}, {0.75, 0.625, 0.5});
  expect_exact_box_result(a, b, CsgOp::Union, 8, 0.25 * 0.5 * 0.25 + 0.25 * 0.25 * 0.25);
}

TEST(Csg, LShapeFromTwoBoxes) {
  const Box a = axis_box({0.2, 0.2, 0.3}, {0.7, 0.35, 0.6});
  const Box b = axis_box({0.2, 0.2, 0.3}, {0.35, 0.8, 0.6});
  const double v = 0.5 * 0.15 * 0.3 + 0.15 * 0.6 * 0.3 - 0.15 * 0.15 * 0.3;
  expect_exact_box_result(a, b, CsgOp::Union, 8, v);
}

// A box minus boxes that share three or four of its faces (OpenSCAD's box-frame idiom): where
// the operands' faces, edges or corners coincide the result is one operand's surface or
// nothing, so the Boolean must not refine there (it used to refine the faces down to the finest
// level, 60 s and millions of cells, and later the shared edges: 100,000 cell pairs and leaves
// at the depth cap). The frame comes out exact, with no leaf at the cap.
TEST(Csg, BoxMinusBoxesSharingFacesIsAFrame) {
  const double h = 0.5, w = 0.03;
  const Box a = axis_box({0.2, 0.2, 0.2}, {0.2 + h, 0.2 + h, 0.2 + h});
  Octree r = sample_in_unit(a.mesh(), 12);
  size_t gray_pairs = 0;
  for (int k = 0; k < 3; ++k) {
    Vec3 hi{0.2 + h - w, 0.2 + h - w, 0.2 + h - w};
    hi[k] = 0.2 + h;
    CsgStats st;
    r = csg(r, sample_in_unit(axis_box({0.2, 0.2, 0.2}, hi).mesh(), 12), CsgOp::Subtract, {}, &st);
    gray_pairs += st.gray_pairs;
  }
  const TriMesh m = unsplit_contour(r);
  EXPECT_TRUE(IsClosedManifold(m));
  const double frame = h * h * h - 3 * h * (h - w) * (h - w) + 2 * (h - w) * (h - w) * (h - w);
  EXPECT_NEAR(volume(m), frame, 1e-4 * frame);
  // The work follows the frame's 12 edges, not its faces (a face at depth 12 alone is ~4
  // million finest cells).
  std::printf("  [measure] frame: %zu PICs, %zu gray cell pairs evaluated\n", size_t(analyze(r).pics), gray_pairs);
  EXPECT_LT(gray_pairs, 40000u);
  EXPECT_EQ(analyze(r).capped, 0u);
}

TEST(Csg, BoxMinusBoxLeavesThinWall) {
  // A cup: walls and floor 0.01 thick, thinner than three cells at depth 8.
  const Box a = axis_box({0.25, 0.25, 0.25}, {0.75, 0.75, 0.75});
  const Box b = axis_box({0.26, 0.26, 0.26}, {0.74, 0.74, 0.9});
  expect_exact_box_result(a, b, CsgOp::Subtract, 8, 0.125 - 0.48 * 0.48 * 0.49);
}

/// Area of the convex polygon `p` (counter-clockwise) on the side y < y0 (below) or y > y0.
double area_beyond(std::vector<std::array<double, 2>> p, double y0, bool below) {
  std::vector<std::array<double, 2>> kept;
  const auto in = [&](const std::array<double, 2>& q) { return below ? q[0] < y0 : q[0] > y0; };
  for (size_t i = 0; i < p.size(); ++i) {
    const auto& a = p[i];
    const auto& b = p[(i + 1) % p.size()];
    if (in(a)) kept.push_back(a);
    if (in(a) != in(b)) {
      const double t = (y0 - a[0]) / (b[0] - a[0]);
      kept.push_back({y0, a[1] + t * (b[1] - a[1])});
    }
  }
  double twice = 0;
  for (size_t i = 0; i < kept.size(); ++i) {
    const auto& a = kept[i];
    const auto& b = kept[(i + 1) % kept.size()];
    twice += a[0] * b[1] - b[0] * a[1];
  }
  return std::abs(twice) / 2;
}

// A cube turned 17 degrees about its edge on the x axis, minus a box with a corner at the
// same point, whose faces x = 0 and z = 0 hold that edge: each operand is one PIC per octant,
// and in the octant holding the common corner both have the same corner signs and a vertex on
// that corner. The two leaves still stand for different surfaces (their polygons run to
// different neighbours), so the Boolean must compute the cell, not take it for A - A.
TEST(Csg, LeavesWithTheSameDataButDifferentSurfacesAreCombined) {
  const double s = 1.95, turn = 17 * std::numbers::pi / 180;
  const Vec3 box{3.88, 1.42, 3.28};
  const TriMesh a = transformed(make_box({0, 0, 0}, {s, s, s}), rotation({1, 0, 0}, turn), {0, 0, 0});
  const TriMesh b = make_box({0, 0, 0}, box);
  const Cube cube{{-0.2425, -1.535, -0.5425}, 4.365};
  const Octree r = csg(sample_in_unit(a, 10, cube), sample_in_unit(b, 10, cube), CsgOp::Subtract);
  const TriMesh m = unsplit_contour(r);
  ASSERT_TRUE(IsClosedManifold(m));
  // The box spans the cube along x and above it, so the result is the turned square (in y, z)
  // outside the strip 0 < y < box y, times the side.
  const double c = std::cos(turn), sn = std::sin(turn);
  const std::vector<std::array<double, 2>> square{{0, 0}, {s * c, s * sn}, {s * (c - sn), s * (sn + c)}, {-s * sn, s * c}};
  const double exact = s * (area_beyond(square, 0, true) + area_beyond(square, box[1], false));
  EXPECT_NEAR(volume(m), exact, 2e-3 * exact);
}

TEST(Csg, IntersectionOfRotatedBoxes) {
  // An axis box and a diamond prism (45 degrees about z): an octagonal prism.
  const Box a = axis_box({0.3, 0.3, 0.3}, {0.7, 0.7, 0.6});
  const Box b = rotated_box({0.5, 0.5, 0.5}, {0.24, 0.24, 0.2}, {0, 0, 1}, M_PI / 4);
  expect_exact_box_result(a, b, CsgOp::Intersect, 8);
}

// The paper's Figure 7: A - B leaves a sharp wedge; at zero QEF residual two crossings can
// still fall on one cell edge and must be separated by subdivision.
TEST(Csg, Figure7WedgeKeepsItsSharpEdge) {
  // B's face passes through the line x = 0.75, z = 0.45 at 10 degrees from A's side face, so
  // A - B keeps a 10-degree wedge hanging on that side: crossings of both faces crowd onto
  // the same cell edges near its tip. Sampled in a cube of side 2 so B's far side fits.
  const double alpha = 10.0 * M_PI / 180;
  const Box a = axis_box({0.25, 0.25, 0.25}, {0.75, 0.75, 0.75});
  const Vec3 u{std::cos(alpha), 0, -std::sin(alpha)};
  const double h = 0.45;
  const Box b = rotated_box({0.75 - h * u[0], 0.5, 0.45 - h * u[2]}, {h, 0.4, 0.45}, {0, 1, 0}, alpha);
  // Near its tip the wedge is thinner than any cell, so the corners there cannot all be
  // exact; the faces and the sharp edge above the tip must be.
  const Cube cube{{-0.5, -0.5, -0.5}, 2.0};
  expect_exact_box_result(a, b, CsgOp::Subtract, 10, -1, cube, /*all_corners=*/false, /*min_corners=*/6);
  const Octree r = csg(sample_in_unit(a.mesh(), 10, cube), sample_in_unit(b.mesh(), 10, cube), CsgOp::Subtract);
  const TriMesh m = unsplit_contour(r);
  // The wedge's volume: a triangular prism of depth 0.5 and legs 0.2 and 0.2 tan(10 deg).
  EXPECT_NEAR(volume(m), 0.5 * 0.2 * 0.2 * std::tan(alpha) * 0.5, 2e-4);
  // The wedge's two edges at its thick end (A's bottom edge and where B's face meets A's
  // bottom) lie on the mesh.
  const double x_cut = 0.75 - 0.2 * std::tan(alpha);
  for (double y : {0.3, 0.5, 0.7}) {
    EXPECT_LT(point_mesh_distance(m, {0.75, y, 0.25}), 1e-6);
    EXPECT_LT(point_mesh_distance(m, {x_cut, y, 0.25}), 1e-6);
  }
}

TEST(Csg, AWallThinnerThanTheFinestCellIsKept) {
  // A box minus a box 0.16 of a finest cell smaller on every side, both turned obliquely to the
  // lattice: the walls left pass between lattice points almost everywhere, and a capped cell
  // sees them only as two crossings of one edge, by A's face and by B's. Dropped, the walls
  // fell into 34 pieces with 3.5 % of their volume, 38 cells from the missing walls; kept (both
  // ends of such an edge take the wall's sign), they are one piece, up to a cell thicker, within
  // two cells of the exact walls both ways.
  const double wall = 0.16 / 128;
  const double turn_z = 0.35, turn_x = 0.2;
  const auto turned = [&](TriMesh m) {
    for (Vec3& p : m.positions) {
      const double x = p[0] - 0.5, y = p[1] - 0.5, z = p[2] - 0.5;
      const double x1 = std::cos(turn_z) * x - std::sin(turn_z) * y, y1 = std::sin(turn_z) * x + std::cos(turn_z) * y;
      p = {0.5 + x1, 0.5 + std::cos(turn_x) * y1 - std::sin(turn_x) * z, 0.5 + std::sin(turn_x) * y1 + std::cos(turn_x) * z};
    }
    return m;
  };
  const TriMesh outer = turned(make_box({0.2, 0.2, 0.2}, {0.8, 0.8, 0.8}));
  const TriMesh inner = turned(make_box({0.2 + wall, 0.2 + wall, 0.2 + wall}, {0.8 - wall, 0.8 - wall, 0.8 - wall}));
  const Octree r = csg(sample_in_unit(outer, 7), sample_in_unit(inner, 7), CsgOp::Subtract);
  const TriMesh m = unsplit_contour(r);
  ASSERT_TRUE(IsClosedManifold(m));
  EXPECT_LE(test::component_count(m), 2u);
  TriMesh exact = outer;
  const auto offset = static_cast<uint32_t>(exact.positions.size());
  exact.positions.insert(exact.positions.end(), inner.positions.begin(), inner.positions.end());
  for (auto t : inner.triangles) exact.triangles.push_back({t[0] + offset, t[2] + offset, t[1] + offset});
  const double d = two_sided_distance(m, exact);
  std::printf("  [measure] thin walls: %zu components, volume %.2f x the exact walls', %.2f cells both ways\n",
              test::component_count(m), volume(m) / volume(exact), d * 128);
  EXPECT_GE(volume(m), volume(exact));
  EXPECT_LE(d, 2.0 / 128);
}

// ---- algebra --------------------------------------------------------------------------------

struct AlgebraTest : ::testing::Test {
  static void SetUpTestSuite() {
    a = new Octree(sample_in_unit(make_sphere({0.45, 0.5, 0.5}, 0.25, 96), 8));
    b = new Octree(sample_in_unit(make_cylinder({0.6, 0.5, 0.5}, 0.15, 0.6, 0, 96), 8));
  }
  static void TearDownTestSuite() {
    delete a;
    delete b;
  }
  static Octree* a;
  static Octree* b;
};
Octree* AlgebraTest::a = nullptr;
Octree* AlgebraTest::b = nullptr;

TEST_F(AlgebraTest, AMinusAIsEmpty) {
  const Octree r = csg(*a, *a, CsgOp::Subtract);
  EXPECT_TRUE(unsplit_contour(r).triangles.empty());
  EXPECT_EQ(analyze(r).pics, 0u);
}

TEST_F(AlgebraTest, UnionAndIntersectionWithItselfGiveA) {
  const TriMesh ma = unsplit_contour(*a);
  for (CsgOp op : {CsgOp::Union, CsgOp::Intersect}) {
    const TriMesh m = unsplit_contour(csg(*a, *a, op));
    EXPECT_TRUE(IsClosedManifold(m));
    EXPECT_LT(two_sided_distance(m, ma), 1e-6) << to_string(op);
    EXPECT_NEAR(volume(m), volume(ma), 1e-9) << to_string(op);
  }
}

TEST_F(AlgebraTest, IntersectionWithDisjointIsEmpty) {
  const Octree far = sample_in_unit(make_box({0.85, 0.85, 0.85}, {0.95, 0.95, 0.95}), 8);
  const Octree r = csg(*a, far, CsgOp::Intersect);
  EXPECT_TRUE(unsplit_contour(r).triangles.empty());
  const TriMesh u = unsplit_contour(csg(*a, far, CsgOp::Union));
  EXPECT_TRUE(IsClosedManifold(u));
  EXPECT_EQ(component_count(u), 2u);
}

TEST_F(AlgebraTest, UnionMinusBEqualsAMinusB) {
  const TriMesh lhs = contour(csg(csg(*a, *b, CsgOp::Union), *b, CsgOp::Subtract));
  const TriMesh rhs = unsplit_contour(csg(*a, *b, CsgOp::Subtract));
  EXPECT_TRUE(IsClosedManifold(lhs));
  EXPECT_TRUE(IsClosedManifold(rhs));
  EXPECT_LT(two_sided_distance(lhs, rhs), 2e-3);
  EXPECT_NEAR(volume(lhs), volume(rhs), 1e-3 * volume(rhs));
}

TEST_F(AlgebraTest, ResultsChainSaveAndLoad) {
  Octree r = csg(*a, *b, CsgOp::Subtract);
  const auto bytes = serialize(r);
  const Octree back = deserialize(bytes);
  EXPECT_EQ(serialize(back), bytes);
  const Octree s = sample_in_unit(make_sphere({0.3, 0.5, 0.5}, 0.1, 64), 8);
  const TriMesh m = unsplit_contour(csg(back, s, CsgOp::Union));
  EXPECT_TRUE(IsClosedManifold(m));
}

TEST_F(AlgebraTest, InPlaceEditsSaveAndLoad) {
  // csg_inplace leaves replaced subtrees in the arrays until it compacts: the file must hold
  // only the live tree.
  Octree r = *a;
  for (double x : {0.3, 0.4, 0.5, 0.6})
    csg_inplace(r, sample_in_unit(make_sphere({x, 0.5, 0.72}, 0.05, 48), 8), CsgOp::Subtract);
  const Octree back = deserialize(serialize(r));
  EXPECT_EQ(analyze(back).pics, analyze(r).pics);
  const TriMesh m = unsplit_contour(back);
  EXPECT_TRUE(IsClosedManifold(m));
  // The file holds each vertex to 2^-16 of its cell: the contour's region tests may then choose
  // another triangulation somewhere, within a few thousandths of a finest cell.
  EXPECT_LT(two_sided_distance(m, unsplit_contour(r)), 1e-5);
}

TEST(Csg, OperandsInDifferentCubesShareOneFrame) {
  SampleOptions o;
  o.depth = 8;
  const Octree a = sample(make_box({0.2, 0.2, 0.2}, {0.8, 0.8, 0.8}), o);              // cube from its bbox
  const Octree b = sample(make_sphere({0.8, 0.8, 0.8}, 0.25, 96), o);                   // another cube
  ASSERT_FALSE(a.cube == b.cube);
  CsgStats st;
  const Octree r = csg(a, b, CsgOp::Subtract, {}, &st);
  EXPECT_TRUE(st.resampled_b);
  // B sticks out of A's cube: both are resampled into a cube around both.
  for (int k = 0; k < 3; ++k) {
    EXPECT_LE(r.cube.origin[k], std::min(a.cube.origin[k], b.cube.origin[k]));
    EXPECT_GE(r.cube.origin[k] + r.cube.size, b.cube.origin[k] + b.cube.size);
  }
  const TriMesh m = unsplit_contour(r);
  EXPECT_TRUE(IsClosedManifold(m));
  // The box minus an eighth of the ball: 0.216 - (1/8)(4/3)pi 0.25^3.
  // A sphere that fits in A's cube is resampled into it, and A keeps its frame.
  const Octree inner = sample(make_sphere({0.5, 0.5, 0.5}, 0.2, 96), o);
  const Octree r2 = csg(a, inner, CsgOp::Subtract, {}, &st);
  EXPECT_TRUE(st.resampled_b);
  EXPECT_TRUE(r2.cube == a.cube);
  EXPECT_TRUE(IsClosedManifold(unsplit_contour(r2)));
  EXPECT_NEAR(volume(m), 0.216 - M_PI * 0.015625 / 6, 2e-3 * 0.216);
}

// ---- curved cases against analytic signed distances ------------------------------------------

double sd_cylinder(const Vec3& p, const Vec3& c, double r, double h, int axis) {
  const int a = (axis + 1) % 3, b = (axis + 2) % 3;
  const double d1 = std::hypot(p[a] - c[a], p[b] - c[b]) - r, d2 = std::abs(p[axis] - c[axis]) - h / 2;
  return std::max(d1, d2) > 0 ? std::hypot(std::max(d1, 0.0), std::max(d2, 0.0)) : std::max(d1, d2);
}

// Paper Table 3's CAD tool: cube, union a cylinder, minus two cylinders.
TEST(Csg, CadToolMatchesTheExactSolid) {
  const int depth = 10, seg = 256;
  const Box cube = axis_box({0.25, 0.25, 0.25}, {0.75, 0.75, 0.75});
  const Vec3 c{0.5, 0.5, 0.5};
  Octree t = sample_in_unit(cube.mesh(), depth);
  std::vector<CsgStats> stats(3);
  t = csg(t, sample_in_unit(make_cylinder(c, 0.15, 0.8, 2, seg), depth), CsgOp::Union, {}, &stats[0]);
  t = csg(t, sample_in_unit(make_cylinder(c, 0.1, 0.8, 0, seg), depth), CsgOp::Subtract, {}, &stats[1]);
  t = csg(t, sample_in_unit(make_cylinder(c, 0.07, 0.8, 1, seg), depth), CsgOp::Subtract, {}, &stats[2]);
  const TriMesh m = unsplit_contour(t);
  ASSERT_TRUE(IsClosedManifold(m));
  EXPECT_EQ(euler_characteristic(m), -4);  // genus 3
  auto sdf = [&](const Vec3& p) {
    return std::max({std::min(cube.sdf(p), sd_cylinder(p, c, 0.15, 0.8, 2)), -sd_cylinder(p, c, 0.1, 0.8, 0),
                     -sd_cylinder(p, c, 0.07, 0.8, 1)});
  };
  // Tessellation of the 256-gon cylinders is 1.1e-5 of the root cube at most.
  double worst = 0;
  for (const Vec3& p : surface_points(m, 20000)) worst = std::max(worst, std::abs(sdf(p)));
  for (const Vec3& p : m.positions) worst = std::max(worst, std::abs(sdf(p)));
  std::printf("  [measure] CAD tool: %.3g of the root cube from the exact solid\n", worst);
  EXPECT_LT(worst, 2e-4);
  // Each operation stamps its own cells (in arrays of its own: no state carried between calls).
  for (const auto& s : stats) EXPECT_GT(s.cells_stamped, 0u);
}

// Determinism: the parallel combine builds exactly the serial tree, over a chain of in-place
// operations (the result is the next operation's A, so any difference would compound).
TEST(Csg, ParallelEqualsSerial) {
  const int depth = 9;
  const Vec3 c{0.5, 0.5, 0.5};
  auto chain = [&](bool parallel) {
    CsgOptions o;
    o.parallel = parallel;
    Octree t = sample_in_unit(axis_box({0.25, 0.25, 0.25}, {0.75, 0.75, 0.75}).mesh(), depth);
    csg_inplace(t, sample_in_unit(make_cylinder(c, 0.15, 0.8, 2, 64), depth), CsgOp::Union, o);
    csg_inplace(t, sample_in_unit(make_cylinder(c, 0.1, 0.8, 0, 64), depth), CsgOp::Subtract, o);
    csg_inplace(t, sample_in_unit(make_sphere({0.75, 0.75, 0.6}, 0.1, 32), depth), CsgOp::Subtract, o);
    csg_inplace(t, sample_in_unit(make_sphere({0.3, 0.5, 0.5}, 0.2, 32), depth), CsgOp::Intersect, o);
    return t;
  };
  const Octree serial = chain(false), parallel = chain(true);
  EXPECT_TRUE(serialize(serial) == serialize(parallel));
  EXPECT_EQ(serial.nodes.size(), parallel.nodes.size());
  EXPECT_TRUE(serial.vertices == parallel.vertices);
  EXPECT_TRUE(IsClosedManifold(unsplit_contour(parallel)));
}

// ---- cost follows the overlap -----------------------------------------------------------------

size_t cells_for_stroke(const Octree& object, const Vec3& at, double radius, int depth) {
  const Octree tool = sample_in_unit(make_sphere(at, radius, 64), depth);
  CsgStats st;
  Octree r = csg(object, tool, CsgOp::Subtract, {}, &st);
  EXPECT_TRUE(IsClosedManifold(unsplit_contour(r)));
  return st.cells_visited;
}

// Sculpting: many small in-place subtractions where coarse old leaves meet the new fine ones.
// Each result must stay closed and 2-manifold (a coarse leaf whose face or edge the finer side
// sees with extra sign regions would get a doubled sheet or a pinched vertex).
TEST(Csg, SculptingStaysClosedAndManifold) {
  const int depth = 12;
  Octree clay = sample_in_unit(axis_box({0.1, 0.25, 0.42}, {0.9, 0.75, 0.58}).mesh(), depth);
  csg_inplace(clay, sample_in_unit(make_sphere({0.3, 0.5, 0.6}, 0.12, 48), depth), CsgOp::Subtract);
  std::mt19937_64 rng(1);
  int bad = 0;
  // Stroke centres from the plain split's vertices (the default contour adds and moves a few).
  ContourOptions plain;
  plain.intersection_free = false;
  for (int stroke = 0; stroke < 40; ++stroke) {
    const TriMesh surface = contour(clay, plain);
    const Vec3 c = surface.positions[std::uniform_int_distribution<size_t>(0, surface.positions.size() - 1)(rng)];
    csg_inplace(clay, sample_in_unit(make_sphere(c, 0.02, 24), depth), CsgOp::Subtract);
    const TriMesh m = unsplit_contour(clay);
    const auto topo = analyze_topology(m);
    EXPECT_TRUE(topo.closed()) << "stroke " << stroke;
    if (!topo.manifold()) ++bad;
  }
  EXPECT_EQ(bad, 0) << "strokes leaving non-manifold results";
}

// A union of parts placed apart is the parts themselves: each is copied into the result whole
// (large copies are cleaned only where they meet the rest), so the result's contour has exactly
// the vertices of the two parts' own contours.
TEST(Csg, UnionOfDisjointPartsIsThePartsThemselves) {
  const int depth = 10;
  const Octree a = sample_in_unit(make_sphere({0.27, 0.5, 0.5}, 0.2, 96), depth);
  SampleOptions fine;  // a finely faceted torus sampled to a tight error: many cells
  fine.depth = depth;
  fine.cube = kUnit;
  fine.error = 1e-10;
  const Octree b = sample(make_torus({0.73, 0.5, 0.5}, 0.14, 0.06, 2, 192), fine);
  ASSERT_GT(b.nodes.size(), size_t{1} << 15) << b.nodes.size() << " nodes: large enough to be copied as a part";
  Octree u = a;
  csg_inplace(u, b, CsgOp::Union);
  const TriMesh m = unsplit_contour(u);
  EXPECT_TRUE(IsClosedManifold(m));
  std::multiset<Vec3> parts, whole(m.positions.begin(), m.positions.end());
  for (const Octree* t : {&a, &b})
    for (const Vec3& p : unsplit_contour(*t).positions) parts.insert(p);
  EXPECT_TRUE(parts == whole);
  EXPECT_NEAR(volume(m), volume(unsplit_contour(a)) + volume(unsplit_contour(b)), 1e-9);
}

// A Boolean's result has been through the clean-up wherever its parts landed, so copying it
// into another solid with `b_settled` (checked only along the copy's faces) gives the same
// solid as cleaning the copy whole again: the CSG tree relies on it for its inner nodes.
TEST(Csg, ASettledOperandNeedsNoSecondCleanUp) {
  const int depth = 9;
  const Octree b = csg(sample_in_unit(make_sphere({0.62, 0.5, 0.5}, 0.1, 48), depth),
                       sample_in_unit(make_torus({0.72, 0.5, 0.5}, 0.09, 0.04, 2, 48), depth), CsgOp::Union);
  // One solid apart from B (a union copies B whole), one holding part of B (each operation
  // copies B's cells where A is uniform).
  const Octree apart = sample_in_unit(make_sphere({0.25, 0.5, 0.5}, 0.12, 48), depth);
  const Octree over = sample_in_unit(make_box({0.35, 0.2, 0.2}, {0.7, 0.8, 0.8}), depth);
  CsgOptions settled;
  settled.b_settled = true;
  for (CsgOp op : {CsgOp::Union, CsgOp::Subtract, CsgOp::Intersect}) {
    const Octree y = csg(over, b, op, settled);
    EXPECT_EQ(serialize(csg(over, b, op)), serialize(y)) << to_string(op);
    EXPECT_TRUE(IsClosedManifold(unsplit_contour(y))) << to_string(op);
  }
  const Octree u = csg(apart, b, CsgOp::Union, settled);
  EXPECT_EQ(serialize(csg(apart, b, CsgOp::Union)), serialize(u));
  EXPECT_NEAR(volume(unsplit_contour(u)), volume(unsplit_contour(apart)) + volume(unsplit_contour(b)), 1e-9);
}

TEST(Csg, CostFollowsTheOverlapNotTheObject) {
  const int depth = 9;
  const Octree big = sample_in_unit(make_sphere({0.5, 0.5, 0.5}, 0.4, 256), depth);
  const Octree small = sample_in_unit(make_sphere({0.5, 0.5, 0.5}, 0.25, 256), depth);
  // Strokes on the surface of each object, averaged over a few directions.
  auto strokes = [&](const Octree& object, double object_radius, double tool_radius) {
    size_t total = 0;
    for (const Vec3& d : {Vec3{0, 0, 1}, Vec3{0.6, 0, 0.8}, Vec3{0, -0.6, -0.8}, Vec3{0.8, 0.6, 0}})
      total += cells_for_stroke(object, {0.5 + object_radius * d[0], 0.5 + object_radius * d[1], 0.5 + object_radius * d[2]},
                                tool_radius, depth);
    return double(total) / 4;
  };
  const double on_big = strokes(big, 0.4, 0.03), on_small = strokes(small, 0.25, 0.03);
  const double larger_tool = strokes(big, 0.4, 0.09);
  // Independent of the object's size...
  EXPECT_LT(on_big, 2.0 * on_small);
  EXPECT_LT(on_small, 2.0 * on_big);
  // ... a small fraction of the object's cells ...
  EXPECT_LT(on_big, 0.1 * double(big.nodes.size()));
  // ... and growing with the tool (9x its area for 3x its radius).
  EXPECT_GT(larger_tool, 2.0 * on_big);
}

}  // namespace
}  // namespace pic

namespace pic {
namespace {
using namespace pic::test;

// Generalized winding number of a closed mesh at p (1 inside, 0 outside): the reference
// inside test for meshes without an analytic form.
double winding_number(const TriMesh& m, const Vec3& p) {
  double w = 0;
  for (const auto& t : m.triangles) {
    Vec3 a = sub3(m.positions[t[0]], p), b = sub3(m.positions[t[1]], p), c = sub3(m.positions[t[2]], p);
    const double la = norm3(a), lb = norm3(b), lc = norm3(c);
    const double det = dot3(a, cross3(b, c));
    const double den = la * lb * lc + dot3(a, b) * lc + dot3(b, c) * la + dot3(c, a) * lb;
    w += 2 * std::atan2(det, den);
  }
  return w / (4 * M_PI);
}

/// One-sided distance from the result to the exact Boolean of A's contour and B's analytic
/// surface: each point must be on A's contour where B leaves it visible, on B's surface where
/// A makes it the boundary, or on both. Returns the worst distance, in the meshes' units.
double distance_to_boolean(const TriMesh& result, const TriMesh& a, const std::function<double(const Vec3&)>& sd_b,
                           CsgOp op, double tol) {
  // 1500 of the result's vertices and 1500 area-weighted samples.
  std::vector<Vec3> pts;
  const size_t step = std::max<size_t>(1, result.positions.size() / 1500);
  for (size_t i = 0; i < result.positions.size(); i += step) pts.push_back(result.positions[i]);
  const auto extra = sample_surface(result, 1500, 7);
  pts.insert(pts.end(), extra.begin() + static_cast<std::ptrdiff_t>(result.positions.size()), extra.end());
  const auto da = distance_to_mesh(a, pts);
  double worst = 0;
  for (size_t i = 0; i < pts.size(); ++i) {
    const Vec3& p = pts[i];
    const double sb = sd_b(p);
    // On A's surface where B leaves it visible...
    const bool a_visible = op == CsgOp::Intersect ? sb <= tol : sb >= -tol;
    double d = a_visible ? da[i] : 1e300;
    d = std::min(d, std::max(da[i], std::abs(sb)));  // ... or on the intersection curve ...
    if (d > tol) {
      // ... or on B's surface where A makes it the boundary (winding number only here).
      const bool in_a = winding_number(a, p) > 0.5;
      if (op == CsgOp::Union ? !in_a : in_a) d = std::min(d, std::abs(sb));
    }
    worst = std::max(worst, d);
  }
  return worst;
}

TEST(Csg, FandiskMinusSphereFollowsTheExactBoolean) {
  SampleOptions o;
  o.depth = 10;
  o.cube = Cube{{-0.5, 12.0, -3.0}, 6.0};
  const TriMesh fandisk = read_mesh(std::string(PIC_DATA_DIR) + "/fandisk.obj");
  const Octree a = sample(fandisk, o);
  const Vec3 c{2.4, 15.2, -1.3};
  const double r = 1.0;
  const Octree b = sample(make_sphere(c, r, 256), o);
  const Octree res = csg(a, b, CsgOp::Subtract);
  const TriMesh m = unsplit_contour(res);
  ASSERT_TRUE(IsClosedManifold(m));
  // Reference: fandisk's own contour minus the analytic sphere (the tessellation of the 256-gon
  // sphere is 7.5e-5 of its radius), in units of the root cube.
  const TriMesh ca = unsplit_contour(a);
  auto sd_sphere = [&](const Vec3& p) { return dist3(p, c) - r; };
  const double d = distance_to_boolean(m, ca, sd_sphere, CsgOp::Subtract, 1e-4 * o.cube->size) / o.cube->size;
  std::printf("  [measure] fandisk - sphere: %.3g of the root cube from the exact boolean\n", d);
  // Over all vertices the worst is 2.3e-4 (spot | torus: 3.4e-4): near the intersection
  // curve, where a triangle can cut the concave crease; 0.4 of a finest cell bounds both.
  EXPECT_LT(d, 4e-4);
  EXPECT_LT(volume(m), volume(ca));
}

TEST(Csg, SpotUnionTorusFollowsTheExactBoolean) {
  SampleOptions o;
  o.depth = 10;
  o.cube = Cube{{-1.2, -1.2, -1.2}, 2.6};
  const Octree a = sample(read_mesh(std::string(PIC_DATA_DIR) + "/spot.obj"), o);
  const Vec3 c{0.0, 0.2, 0.4};
  const double big = 0.45, small = 0.08;
  const Octree b = sample(make_torus(c, big, small, 2, 256, 64), o);
  const TriMesh m = unsplit_contour(csg(a, b, CsgOp::Union));
  ASSERT_TRUE(IsClosedManifold(m));
  auto sd_torus = [&](const Vec3& p) {
    const double q = std::hypot(p[0] - c[0], p[1] - c[1]) - big;
    return std::hypot(q, p[2] - c[2]) - small;
  };
  const TriMesh ca = unsplit_contour(a);
  const double d = distance_to_boolean(m, ca, sd_torus, CsgOp::Union, 1e-4 * o.cube->size) / o.cube->size;
  std::printf("  [measure] spot | torus: %.3g of the root cube from the exact boolean\n", d);
  EXPECT_LT(d, 4e-4);
  EXPECT_GT(volume(m), volume(ca));
}

}  // namespace
}  // namespace pic

namespace pic {
namespace {

/// A wavy star (9 lobes, radius r) extruded to height h with a twist and a taper, as OpenSCAD's
/// linear_extrude(height, twist, slices, scale) writes it (each slice's quads split in two).
TriMesh twisted_star(double r, double h, double twist_deg, int slices, double scale) {
  constexpr int kRing = 36;
  TriMesh m;
  for (int j = 0; j <= slices; ++j) {
    const double t = double(j) / slices, turn = -twist_deg * t * std::numbers::pi / 180, s = 1 + (scale - 1) * t;
    for (int i = 0; i < kRing; ++i) {
      const double a = 2 * std::numbers::pi * i / kRing, rr = r * s * (1 + 0.12 * std::cos(9 * a));
      m.positions.push_back({rr * std::cos(a + turn), rr * std::sin(a + turn), h * t});
    }
  }
  const auto at = [&](int j, int i) { return uint32_t(j * kRing + (i % kRing)); };
  for (int j = 0; j < slices; ++j)
    for (int i = 0; i < kRing; ++i) {
      m.triangles.push_back({at(j, i), at(j, i + 1), at(j + 1, i + 1)});
      m.triangles.push_back({at(j, i), at(j + 1, i + 1), at(j + 1, i)});
    }
  const auto bottom = uint32_t(m.positions.size());
  m.positions.push_back({0, 0, 0});
  const auto top = uint32_t(m.positions.size());
  m.positions.push_back({0, 0, h});
  for (int i = 0; i < kRing; ++i) {
    m.triangles.push_back({bottom, at(0, i + 1), at(0, i)});
    m.triangles.push_back({top, at(slices, i), at(slices, i + 1)});
  }
  return m;
}

TEST(Csg, ResampledCoarseLeafKeepsItsVertexOnTheSurface) {
  // A twisted vase's outer wall minus its inner one, sampled in a cube much larger than the
  // vase (as a floor's cutting box in the same OpenSCAD file makes it): the outer wall's coarse
  // leaves are split where the inner wall is finer, and each part resampled from the wall's
  // partial contour. A part whose sign change no triangle of that contour explains must not
  // take the plane of a triangle beside it: that puts its vertex 12 finest cells inside the wall.
  const TriMesh outer = twisted_star(20, 60, 120, 60, 1.3), inner = twisted_star(18, 66, 132, 66, 1.33);
  ASSERT_TRUE(IsClosedManifold(outer));
  const Cube cube{{-112.5, -112.5, -82}, 225};
  const Octree r = csg(sample_in_unit(outer, 12, cube), sample_in_unit(inner, 12, cube), CsgOp::Subtract);
  const TriMesh m = contour(r);
  ASSERT_TRUE(IsClosedManifold(m));
  const detail::MeshDistance to_outer(outer), to_inner(inner);
  double worst = 0;
  for (const Vec3& p : m.positions) worst = std::max(worst, std::min(to_outer.distance(p), to_inner.distance(p)));
  const double cell = cube.size / 4096;
  std::printf("  [measure] worst vertex %.2f finest cells from both walls\n", worst / cell);
  EXPECT_LT(worst, 1.5 * cell);
}

// csg(a, b) keeps its bookkeeping (the timestamps of paper 5.2.1) to itself: both operands
// are left exactly as they were, so they can be shared between threads without a lock.
TEST(Csg, LeavesItsOperandsUntouched) {
  const Octree a = sample_in_unit(make_box({0.2, 0.2, 0.2}, {0.7, 0.7, 0.7}), 7);
  const Octree b = sample_in_unit(make_sphere({0.6, 0.6, 0.6}, 0.25, 48), 7);
  const std::vector<uint8_t> bytes_a = serialize(a), bytes_b = serialize(b);
  const size_t nodes_a = a.nodes.size(), nodes_b = b.nodes.size();
  for (CsgOp op : {CsgOp::Union, CsgOp::Intersect, CsgOp::Subtract}) {
    const Octree r = csg(a, b, op);
    EXPECT_GT(r.vertices.size(), 0u);
  }
  EXPECT_EQ(a.nodes.size(), nodes_a);
  EXPECT_EQ(b.nodes.size(), nodes_b);
  EXPECT_TRUE(serialize(a) == bytes_a);
  EXPECT_TRUE(serialize(b) == bytes_b);
}

TEST(CsgTree, UnionOfThreeIsTheFirstWithTheOthers) {
  const int depth = 8;
  const Octree a = sample_in_unit(make_sphere({0.4, 0.5, 0.5}, 0.2, 48), depth);
  const Octree b = sample_in_unit(make_box({0.45, 0.3, 0.3}, {0.8, 0.7, 0.6}), depth);
  const Octree c = sample_in_unit(make_cylinder({0.55, 0.5, 0.5}, 0.1, 0.8, 0, 48), depth);
  // The balanced order puts floor(n/2) children first, as pic eval does: a | (b | c).
  const Octree nested = csg(a, csg(b, c, CsgOp::Union), CsgOp::Union);
  const Octree tree = evaluate(csg_union({csg_leaf(a), csg_leaf(b), csg_leaf(c)}));
  EXPECT_EQ(serialize(tree), serialize(nested));
  // Two children are the chain's one step; an empty child is skipped by a union and empties
  // an intersection.
  EXPECT_EQ(serialize(evaluate(csg_union({csg_leaf(a), csg_leaf(b)}))), serialize(csg(a, b, CsgOp::Union)));
  EXPECT_EQ(serialize(evaluate(csg_union({csg_leaf(a), csg_empty(), csg_leaf(b)}))),
            serialize(csg(a, b, CsgOp::Union)));
  EXPECT_TRUE(evaluate(csg_intersection({csg_leaf(a), csg_empty()})).vertices.empty());
  EXPECT_EQ(serialize(evaluate(csg_difference(csg_leaf(a), {csg_empty()}))), serialize(a));
  // A difference takes the union of the rest; an intersection of two is their Boolean.
  const Octree diff = evaluate(csg_difference(csg_leaf(b), {csg_leaf(a), csg_leaf(c)}));
  EXPECT_EQ(serialize(diff), serialize(csg(b, csg(a, c, CsgOp::Union), CsgOp::Subtract)));
  const Octree both = evaluate(csg_intersection({csg_leaf(a), csg_leaf(b)}));
  EXPECT_EQ(serialize(both), serialize(csg(a, b, CsgOp::Intersect)));
}

TEST(CsgTree, ManyPartsInABalancedOrderAndMeshLeaves) {
  // Nine overlapping balls in a row: the balanced union against the left-to-right one (the
  // same solid; the order of the Booleans may place a few vertices differently).
  const int depth = 8;
  std::vector<Octree> balls;
  std::vector<CsgTree> leaves;
  for (int i = 0; i < 9; ++i) {
    balls.push_back(sample_in_unit(make_sphere({0.2 + 0.075 * i, 0.5, 0.5}, 0.06, 32), depth));
    leaves.push_back(csg_leaf(balls.back()));
  }
  Octree chained = balls[0];
  for (int i = 1; i < 9; ++i) csg_inplace(chained, balls[i], CsgOp::Union);
  const TriMesh m = unsplit_contour(evaluate(csg_union(std::move(leaves))));
  EXPECT_TRUE(IsClosedManifold(m));
  EXPECT_NEAR(volume(m), volume(unsplit_contour(chained)), 1e-6);
  EXPECT_EQ(test::component_count(m), 1u);
  // Mesh leaves are sampled into one cube around them all.
  const TriMesh box = make_box({0, 0, 0}, {2, 2, 2}), hole = make_box({0.5, 0.5, -1}, {1.5, 1.5, 3});
  CsgChainOptions o;
  o.sampling.depth = 7;
  const TriMesh d = unsplit_contour(evaluate(csg_difference(csg_leaf(box), {csg_leaf(hole)}), o));
  EXPECT_NEAR(volume(d), 8 - 2, 1e-6);
  EXPECT_TRUE(unsplit_contour(evaluate(csg_union({}))).triangles.empty());
}

}  // namespace
}  // namespace pic

// Sampling (pic::sample) followed by contouring (pic::contour): topology, distance to the
// input, volume, sharp features, option validation and determinism.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <string>

#include "pic/pic.h"
#include "pic/primitives.h"
#include "support/mesh_checks.h"
#include "support/shapes.h"

namespace pic {
namespace {

using test::IsClosedManifold;

struct Sampled {
  Octree tree;
  TriMesh out;
  SampleStats stats;
  double hausdorff = 0;  // two-sided distance, root-cube units
  double volume_in = 0, volume_out = 0;
  double rel_volume_error() const { return std::abs(volume_out - volume_in) / std::abs(volume_in); }
};

Sampled sample_and_contour(const TriMesh& in, int depth, std::optional<Cube> cube = std::nullopt,
                           bool distance = true) {
  Sampled s;
  SampleOptions o;
  o.depth = depth;
  o.cube = cube;
  s.tree = sample(in, o, &s.stats);
  s.out = unsplit_contour(s.tree);
  s.volume_in = volume(in);
  s.volume_out = volume(s.out);
  if (distance) s.hausdorff = test::two_sided_distance(s.out, in) / s.tree.cube.size;
  std::printf("  [measure] depth %d: %zu PICs, %zu capped, %zu out vertices, %zu out triangles, "
              "hausdorff %.3g (cube units), volume rel error %.3g, sample %.3f s\n",
              depth, s.stats.pics, s.stats.capped, s.out.positions.size(), s.out.triangles.size(),
              s.hausdorff, s.rel_volume_error(), s.stats.seconds);
  return s;
}

// Box corners reproduced, every output vertex on the box surface (tolerances in cube units).
void expect_box_features(const Sampled& s, const TriMesh& box_in, double tol = 1e-6) {
  const double unit = s.tree.cube.size;
  double worst_corner = 0;
  for (const Vec3& corner : box_in.positions)
    worst_corner = std::max(worst_corner, test::nearest_vertex_distance(s.out, corner) / unit);
  EXPECT_LE(worst_corner, tol) << "a box corner has no output vertex near it";
  double worst_vertex = 0;
  for (double d : distance_to_mesh(box_in, s.out.positions)) worst_vertex = std::max(worst_vertex, d / unit);
  EXPECT_LE(worst_vertex, tol) << "an output vertex is off the box surface";
  std::printf("  [measure] worst corner %.3g, worst vertex off surface %.3g\n", worst_corner, worst_vertex);
}

// ---------------------------------------------------------------------------------------
// Boxes

TEST(Sample, GridAlignedBoxOffGridPlanesIsExact) {
  const Vec3 lo{0.3, 0.27, 0.33}, hi{0.71, 0.66, 0.69};
  const TriMesh box = make_box(lo, hi);
  const Sampled s = sample_and_contour(box, 8, Cube{{0, 0, 0}, 1});
  ASSERT_TRUE(IsClosedManifold(s.out));
  EXPECT_LE(s.hausdorff, 1e-6);
  // Vertices are floats in cell-local coordinates (~1e-7 of a cell): not exact off the lattice.
  EXPECT_NEAR(s.volume_out, s.volume_in, 1e-6 * s.volume_in);
  expect_box_features(s, box);
}

TEST(Sample, UnitCubeOnOctreePlanesIsExact) {
  // Root cube [-0.5, 1.5]^3: the faces of [0,1]^3 lie on level-2 planes and its corners
  // are lattice points (the everyday CAD case).
  const TriMesh box = make_box({0, 0, 0}, {1, 1, 1});
  const Sampled s = sample_and_contour(box, 8, Cube{{-0.5, -0.5, -0.5}, 2});
  ASSERT_TRUE(IsClosedManifold(s.out));
  EXPECT_LE(s.hausdorff, 1e-6);
  EXPECT_NEAR(s.volume_out, 1.0, 1e-12);
  expect_box_features(s, box);
}

TEST(Sample, QuarterBoxOnOctreePlanesIsExact) {
  const TriMesh box = make_box({0.25, 0.25, 0.25}, {0.75, 0.75, 0.75});
  const Sampled s = sample_and_contour(box, 8, Cube{{0, 0, 0}, 1});
  ASSERT_TRUE(IsClosedManifold(s.out));
  EXPECT_LE(s.hausdorff, 1e-6);
  EXPECT_NEAR(s.volume_out, 0.125, 1e-12);
  expect_box_features(s, box);
}

TEST(Sample, BoxWithSomeFacesOnOctreePlanes) {
  // Mixed: x faces on level-3 planes, y/z faces off the lattice.
  const TriMesh box = make_box({0.125, 0.3, 0.21}, {0.875, 0.61, 0.77});
  const Sampled s = sample_and_contour(box, 8, Cube{{0, 0, 0}, 1});
  ASSERT_TRUE(IsClosedManifold(s.out));
  EXPECT_LE(s.hausdorff, 1e-6);
  EXPECT_NEAR(s.volume_out, s.volume_in, 1e-6 * s.volume_in);
  expect_box_features(s, box);
}

TEST(Sample, BoxWithAutomaticCube) {
  const TriMesh box = make_box({-3, 2, 10}, {5, 4, 11});
  const Sampled s = sample_and_contour(box, 8);
  ASSERT_TRUE(IsClosedManifold(s.out));
  EXPECT_LE(s.hausdorff, 1e-6);
  EXPECT_NEAR(s.volume_out, 16.0, 1e-6 * 16);
  expect_box_features(s, box);
}

struct RotatedCase {
  Vec3 axis;
  double degrees;
};

class SampleRotatedBox : public ::testing::TestWithParam<RotatedCase> {};

TEST_P(SampleRotatedBox, CornersEdgesAndVolumeReproduced) {
  const auto [axis, degrees] = GetParam();
  const TriMesh base = make_box({-0.2, -0.15, -0.1}, {0.2, 0.15, 0.1});
  const TriMesh box = transformed(base, rotation(axis, degrees * std::numbers::pi / 180), {0.5, 0.5, 0.5});
  const int depth = 9;
  const Sampled s = sample_and_contour(box, depth, Cube{{0, 0, 0}, 1});
  ASSERT_TRUE(IsClosedManifold(s.out));
  EXPECT_NEAR(s.volume_out, s.volume_in, 1e-4 * s.volume_in);
  // Every corner of the rotated box has an output vertex on it.
  double worst_corner = 0;
  for (const Vec3& c : box.positions) worst_corner = std::max(worst_corner, test::nearest_vertex_distance(s.out, c));
  EXPECT_LE(worst_corner, 1e-6);
  // Vertices of leaves accepted by the QEF test are on the box surface. Leaves accepted only
  // at the depth cap may hold a vertex clamped into their cell: a box edge that passes just
  // outside a cell both of whose faces enter it puts the QEF minimum outside the cell at
  // every level (dual contouring's one-vertex-per-cell limit). Bound those by the cap cell.
  const double cap_cell = 1.0 / (1 << depth);
  double worst_ok = 0, worst_capped = 0;
  size_t capped = 0;
  for_each_leaf(s.tree, [&](const LeafView& l) {
    if (l.kind != CellKind::Gray) return;
    const double d = distance_to_mesh(box, {l.vertex})[0];
    if (s.tree.nodes[l.node].flags & kFlagCapped) {
      ++capped;
      worst_capped = std::max(worst_capped, d);
    } else {
      worst_ok = std::max(worst_ok, d);
    }
  });
  std::printf("  [measure] worst corner %.3g, worst vertex off surface %.3g (%zu capped leaves: %.3g)\n",
              worst_corner, worst_ok, capped, worst_capped);
  EXPECT_LE(worst_ok, 1e-6);
  EXPECT_LE(worst_capped, 0.5 * cap_cell);
  EXPECT_LE(s.hausdorff, 0.5 * cap_cell);
}

INSTANTIATE_TEST_SUITE_P(Sample, SampleRotatedBox,
                         ::testing::Values(RotatedCase{{0, 0, 1}, 30}, RotatedCase{{1, 0, 0}, 45},
                                           RotatedCase{{1, 1, 0}, 20}, RotatedCase{{1, 2, 3}, 37},
                                           RotatedCase{{-0.3, 0.8, 0.5}, 71}));

// ---------------------------------------------------------------------------------------
// Curved shapes

TEST(Sample, CylinderIsClosedAndClose) {
  const TriMesh cyl = make_cylinder({0.5, 0.5, 0.5}, 0.3, 0.6, 2, 64);
  const Sampled s = sample_and_contour(cyl, 9, Cube{{0.03, 0.02, 0.01}, 1});
  ASSERT_TRUE(IsClosedManifold(s.out));
  EXPECT_LE(s.hausdorff, 2e-3);
  EXPECT_NEAR(s.volume_out, s.volume_in, 5e-3 * s.volume_in);
  EXPECT_EQ(test::euler_characteristic(s.out), 2);
}

TEST(Sample, SphereIsClosedAndClose) {
  const TriMesh sph = make_sphere({0.1, -0.2, 0.3}, 0.7, 64);
  const Sampled s = sample_and_contour(sph, 9);
  ASSERT_TRUE(IsClosedManifold(s.out));
  EXPECT_LE(s.hausdorff, 2e-3);
  EXPECT_NEAR(s.volume_out, s.volume_in, 5e-3 * s.volume_in);
  EXPECT_EQ(test::euler_characteristic(s.out), 2);
  EXPECT_EQ(test::component_count(s.out), 1u);
}

TEST(Sample, TorusHasGenusOne) {
  const TriMesh tor = make_torus({0.5, 0.5, 0.5}, 0.3, 0.1, 0, 64, 32);
  const Sampled s = sample_and_contour(tor, 9, Cube{{0, 0, 0}, 1});
  ASSERT_TRUE(IsClosedManifold(s.out));
  EXPECT_EQ(test::euler_characteristic(s.out), 0) << "V - E + F of a torus is 0";
  EXPECT_EQ(test::component_count(s.out), 1u);
  EXPECT_LE(s.hausdorff, 2e-3);
  EXPECT_NEAR(s.volume_out, s.volume_in, 1e-2 * s.volume_in);
}

TEST(Sample, ConeApexIsReproduced) {
  const TriMesh cone = make_cone({0.5, 0.5, 0.5}, 0.3, 0.6, 1, 48);
  const Sampled s = sample_and_contour(cone, 9, Cube{{0, 0, 0}, 1});
  ASSERT_TRUE(IsClosedManifold(s.out));
  EXPECT_LE(s.hausdorff, 2e-3);
  EXPECT_NEAR(s.volume_out, s.volume_in, 5e-3 * s.volume_in);
  EXPECT_LE(test::nearest_vertex_distance(s.out, {0.5, 0.8, 0.5}), 2e-3);
}

TEST(Sample, TwoDisjointObjectsGiveTwoComponents) {
  TriMesh a = make_sphere({0.3, 0.5, 0.5}, 0.15, 48);
  const TriMesh b = make_box({0.6, 0.35, 0.4}, {0.85, 0.65, 0.62});
  const auto offset = static_cast<uint32_t>(a.positions.size());
  a.positions.insert(a.positions.end(), b.positions.begin(), b.positions.end());
  for (auto t : b.triangles) a.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  const Sampled s = sample_and_contour(a, 9, Cube{{0, 0, 0}, 1});
  ASSERT_TRUE(IsClosedManifold(s.out));
  EXPECT_EQ(test::component_count(s.out), 2u);
  EXPECT_EQ(test::euler_characteristic(s.out), 4);
  EXPECT_LE(s.hausdorff, 2e-3);
  EXPECT_NEAR(s.volume_out, s.volume_in, 5e-3 * s.volume_in);
}

TEST(Sample, ThinPlateCrossingOneCellEdgeTwiceIsKept) {
  // Thickness 0.01 of the cube: at levels <= 6 (cell >= 1/64) an edge along z crosses both
  // faces of the plate with equal corner signs, so only the double-crossing rule sees it.
  const TriMesh plate = make_box({0.21, 0.23, 0.503}, {0.79, 0.77, 0.513});
  const Sampled s = sample_and_contour(plate, 8, Cube{{0, 0, 0}, 1});
  ASSERT_TRUE(IsClosedManifold(s.out));
  EXPECT_EQ(test::component_count(s.out), 1u);
  EXPECT_NEAR(s.volume_out, s.volume_in, 0.03 * s.volume_in);
  EXPECT_LE(s.hausdorff, 1e-5);
}

TEST(Sample, AWallThinnerThanTheFinestCellIsKept) {
  // A hollow box whose walls are 0.16 of a finest cell thick, turned obliquely to the lattice:
  // the walls pass between lattice points almost everywhere. Dropped at the depth cap they fell
  // into 2,513 pieces, 9 cells from the missing walls, with 9 % of their volume; kept (both ends
  // of each edge crossing a wall take its sign), the walls are one piece, up to a cell thicker,
  // within two cells both ways. (Where two walls meet, a few slits stay: 1 component, not 2.)
  const double wall = 0.16 / 128;
  TriMesh m = make_box({0.2, 0.2, 0.2}, {0.8, 0.8, 0.8});
  const TriMesh inner = make_box({0.2 + wall, 0.2 + wall, 0.2 + wall}, {0.8 - wall, 0.8 - wall, 0.8 - wall});
  const auto offset = static_cast<uint32_t>(m.positions.size());
  m.positions.insert(m.positions.end(), inner.positions.begin(), inner.positions.end());
  for (auto t : inner.triangles) m.triangles.push_back({t[0] + offset, t[2] + offset, t[1] + offset});
  const double a = 0.35, b = 0.2;  // radians about z, then x
  for (Vec3& p : m.positions) {
    const double x = p[0] - 0.5, y = p[1] - 0.5, z = p[2] - 0.5;
    const double x1 = std::cos(a) * x - std::sin(a) * y, y1 = std::sin(a) * x + std::cos(a) * y;
    p = {0.5 + x1, 0.5 + std::cos(b) * y1 - std::sin(b) * z, 0.5 + std::sin(b) * y1 + std::cos(b) * z};
  }
  const Sampled s = sample_and_contour(m, 7, Cube{{0, 0, 0}, 1});
  ASSERT_TRUE(IsClosedManifold(s.out));
  EXPECT_LE(test::component_count(s.out), 2u);
  EXPECT_GE(s.volume_out, s.volume_in);
  EXPECT_LE(s.hausdorff, 2.0 / 128);
}

TEST(Sample, ThinPlateOnOctreePlaneIsKept) {
  // The plate's lower face lies exactly on the level-1 plane z = 0.5.
  const TriMesh plate = make_box({0.2, 0.2, 0.5}, {0.8, 0.8, 0.51});
  const Sampled s = sample_and_contour(plate, 8, Cube{{0, 0, 0}, 1});
  ASSERT_TRUE(IsClosedManifold(s.out));
  EXPECT_NEAR(s.volume_out, s.volume_in, 0.03 * s.volume_in);
  EXPECT_LE(s.hausdorff, 1e-5);
}

TEST(Sample, PrismEdgeOnAnOctreeLineIsKept) {
  // A hexagonal prism (OpenSCAD's cylinder with $fn = 6) whose leftmost vertical edge lies on
  // the octree line x = y = 1/2, the solid to its right: the cells left of the line meet the
  // prism only along their edge, so no area of it lies in them, yet every lattice point on
  // the line is inside (the perturbation puts it at x = 1/2 + e). Those cells must split, or
  // the contour has a hole along the edge.
  TriMesh prism;
  const double cx = 0.62, r = 0.12, z0 = 0.3, z1 = 0.38;
  for (int k = 0; k < 6; ++k) {
    const double a = std::numbers::pi * (1 + k / 3.0);
    prism.positions.push_back({cx + r * std::cos(a), 0.5 + r * std::sin(a), z0});
    prism.positions.push_back({cx + r * std::cos(a), 0.5 + r * std::sin(a), z1});
  }
  prism.positions[0] = {0.5, 0.5, z0};  // exactly on the line, not 1 ulp off
  prism.positions[1] = {0.5, 0.5, z1};
  for (uint32_t k = 0; k < 6; ++k) {
    const uint32_t a = 2 * k, b = 2 * ((k + 1) % 6);
    prism.triangles.push_back({a, b, b + 1});
    prism.triangles.push_back({a, b + 1, a + 1});
  }
  for (uint32_t k = 1; k + 1 < 6; ++k) {
    prism.triangles.push_back({0, 2 * (k + 1), 2 * k});
    prism.triangles.push_back({1, 2 * k + 1, 2 * (k + 1) + 1});
  }
  ASSERT_GT(volume(prism), 0);
  for (int depth : {6, 9}) {
    const Sampled s = sample_and_contour(prism, depth, Cube{{0, 0, 0}, 1});
    ASSERT_TRUE(IsClosedManifold(s.out)) << "depth " << depth;
    EXPECT_NEAR(s.volume_out, s.volume_in, 1e-6 * s.volume_in);
    EXPECT_LE(s.hausdorff, 1e-6);
  }
}

TEST(Sample, SlantedFaceThroughAnOctreeLineKeepsItsEdge) {
  // A square prism along y turned 45 degrees (OpenSCAD's cylinder with $fn = 4): one of its
  // slanted faces contains the octree line x = z = 1/2. A cell beside that line meets the face
  // only along its edge, so the face has no area in it, but the face crosses the cell's edge
  // there (a sign change): its plane must be in the cell's QEF, or the cell's vertex sits on
  // the end cap alone and the contour cuts a notch out of the prism's end.
  const double cx = 0.47, cz = 0.53, r = 0.06, y0 = 0.55, y1 = 0.70;
  TriMesh prism;
  const double ring[4][2] = {{cx + r, cz}, {cx, cz + r}, {cx - r, cz}, {cx, cz - r}};
  for (const auto& p : ring) {
    prism.positions.push_back({p[0], y0, p[1]});
    prism.positions.push_back({p[0], y1, p[1]});
  }
  for (uint32_t k = 0; k < 4; ++k) {
    const uint32_t a = 2 * k, b = 2 * ((k + 1) % 4);
    prism.triangles.push_back({a, a + 1, b + 1});
    prism.triangles.push_back({a, b + 1, b});
  }
  prism.triangles.push_back({0, 2, 4});
  prism.triangles.push_back({0, 4, 6});
  prism.triangles.push_back({1, 5, 3});
  prism.triangles.push_back({1, 7, 5});
  if (volume(prism) < 0)
    for (auto& t : prism.triangles) std::swap(t[1], t[2]);
  for (int depth : {8, 10}) {
    const Sampled s = sample_and_contour(prism, depth, Cube{{0, 0, 0}, 1});
    ASSERT_TRUE(IsClosedManifold(s.out)) << "depth " << depth;
    EXPECT_NEAR(s.volume_out, s.volume_in, 1e-5 * s.volume_in) << "depth " << depth;
    EXPECT_LE(s.hausdorff, 1e-6) << "depth " << depth;
  }
}

TEST(Sample, NestedShellsGiveAHollowSolid) {
  // Outer sphere plus an inward-facing inner sphere: crossing parity makes a hollow ball.
  TriMesh m = make_sphere({0.5, 0.5, 0.5}, 0.4, 48);
  TriMesh inner = make_sphere({0.52, 0.49, 0.5}, 0.2, 32);
  const auto offset = static_cast<uint32_t>(m.positions.size());
  m.positions.insert(m.positions.end(), inner.positions.begin(), inner.positions.end());
  for (auto t : inner.triangles) m.triangles.push_back({t[0] + offset, t[2] + offset, t[1] + offset});
  const Sampled s = sample_and_contour(m, 9, Cube{{0, 0, 0}, 1});
  ASSERT_TRUE(IsClosedManifold(s.out));
  EXPECT_EQ(test::component_count(s.out), 2u);
  EXPECT_GT(s.volume_in, 0);
  EXPECT_NEAR(s.volume_out, s.volume_in, 5e-3 * s.volume_in);
  EXPECT_LE(s.hausdorff, 2e-3);
}

TEST(Sample, InsideOutMeshGivesTheSameSolid) {
  // Signs come from crossing parity, so a consistently inverted mesh samples to the same
  // solid, contoured with outward orientation.
  TriMesh m = make_cylinder({0.5, 0.5, 0.5}, 0.3, 0.5, 1, 32);
  const double v = volume(m);
  for (auto& t : m.triangles) std::swap(t[1], t[2]);
  ASSERT_LT(volume(m), 0);
  SampleOptions o;
  o.depth = 8;
  o.cube = Cube{{0, 0, 0}, 1};
  const TriMesh out = unsplit_contour(sample(m, o));
  ASSERT_TRUE(IsClosedManifold(out));
  EXPECT_NEAR(volume(out), v, 5e-3 * v);
}

TEST(Sample, FandiskIsClosedAndClose) {
  const TriMesh in = read_mesh(std::string(PIC_DATA_DIR) + "/fandisk.obj");
  const Sampled s = sample_and_contour(in, 12);
  ASSERT_TRUE(IsClosedManifold(s.out));
  EXPECT_EQ(test::euler_characteristic(s.out), test::euler_characteristic(in));
  EXPECT_LE(s.hausdorff, 2e-3);
  EXPECT_NEAR(s.volume_out, s.volume_in, 2e-3 * std::abs(s.volume_in));
}

// ---------------------------------------------------------------------------------------
// Validation

TEST(Sample, RejectsBadOptions) {
  const TriMesh box = make_box({0, 0, 0}, {1, 1, 1});
  auto with = [&](auto set) {
    SampleOptions o;
    o.depth = 4;
    set(o);
    return o;
  };
  EXPECT_THROW(sample(box, with([](SampleOptions& o) { o.depth = 0; })), InvalidInput);
  EXPECT_THROW(sample(box, with([](SampleOptions& o) { o.depth = 21; })), InvalidInput);
  EXPECT_THROW(sample(box, with([](SampleOptions& o) { o.depth = -3; })), InvalidInput);
  EXPECT_THROW(sample(box, with([](SampleOptions& o) { o.error = -1e-8; })), InvalidInput);
  EXPECT_THROW(sample(box, with([](SampleOptions& o) { o.error = std::nan(""); })), InvalidInput);
  EXPECT_THROW(sample(box, with([](SampleOptions& o) { o.error = INFINITY; })), InvalidInput);
  EXPECT_THROW(sample(box, with([](SampleOptions& o) { o.cube = Cube{{std::nan(""), 0, 0}, 4}; })), InvalidInput);
  EXPECT_THROW(sample(box, with([](SampleOptions& o) { o.cube = Cube{{-1, -1, -1}, std::nan("")}; })), InvalidInput);
  EXPECT_THROW(sample(box, with([](SampleOptions& o) { o.cube = Cube{{-1, -1, -1}, 0}; })), InvalidInput);
  EXPECT_THROW(sample(box, with([](SampleOptions& o) { o.cube = Cube{{-1, -1, -1}, -4}; })), InvalidInput);
  // The mesh must lie strictly inside the cube: touching its boundary is rejected.
  EXPECT_THROW(sample(box, with([](SampleOptions& o) { o.cube = Cube{{0, 0, 0}, 2}; })), InvalidInput);
  EXPECT_THROW(sample(box, with([](SampleOptions& o) { o.cube = Cube{{0.5, 0.5, 0.5}, 2}; })), InvalidInput);
  // Extremes that are valid.
  EXPECT_NO_THROW(sample(box, with([](SampleOptions& o) { o.depth = 1; })));
  EXPECT_NO_THROW(sample(box, with([](SampleOptions& o) { o.error = 0; })));
}

TEST(Sample, RejectsEmptyAndNonFiniteMeshes) {
  EXPECT_THROW(sample(TriMesh{}), InvalidInput);
  TriMesh box = make_box({0, 0, 0}, {1, 1, 1});
  TriMesh nan_box = box;
  nan_box.positions[3][1] = std::nan("");
  EXPECT_THROW(sample(nan_box), InvalidInput);
  TriMesh inf_box = box;
  inf_box.positions[5][2] = std::numeric_limits<double>::infinity();
  EXPECT_THROW(sample(inf_box), InvalidInput);
  TriMesh bad_index = box;
  bad_index.triangles[0][1] = 99;
  EXPECT_THROW(sample(bad_index), InvalidInput);
}

// Crossing parity (asked for explicitly; `auto` takes open meshes by their winding number).
TEST(Sample, OpenMeshIsRejectedWithBoundaryEdgeCount) {
  SampleOptions parity;
  parity.inside = InsideMode::Parity;
  TriMesh box = make_box({0, 0, 0}, {1, 1, 1});
  box.triangles.pop_back();
  try {
    sample(box, parity);
    FAIL() << "an open mesh was accepted";
  } catch (const InvalidInput& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("3 boundary edges"), std::string::npos) << msg;
    EXPECT_NE(msg.find("not closed"), std::string::npos) << msg;
  }
  // Two triangles removed from different faces: 6 boundary edges.
  TriMesh box2 = make_box({0, 0, 0}, {1, 1, 1});
  box2.triangles.erase(box2.triangles.begin());
  box2.triangles.pop_back();
  try {
    sample(box2, parity);
    FAIL() << "an open mesh was accepted";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("6 boundary edges"), std::string::npos) << e.what();
  }
}

TEST(Sample, StatsAreFilled) {
  const TriMesh box = make_box({0.3, 0.3, 0.3}, {0.7, 0.7, 0.7});
  SampleOptions o;
  o.depth = 6;
  o.cube = Cube{{0, 0, 0}, 1};
  SampleStats st;
  const Octree t = sample(box, o, &st);
  EXPECT_EQ(st.triangles_in, 12u);
  EXPECT_EQ(st.pics, t.vertices.size());
  EXPECT_EQ(st.pics, analyze(t).pics);
  EXPECT_GT(st.pics, 0u);
  EXPECT_GE(st.seconds, 0.0);
  EXPECT_EQ(t.max_depth, 6);
  EXPECT_EQ(t.cube, (Cube{{0, 0, 0}, 1}));
}

TEST(Sample, AutomaticCubeContainsMeshWithMargin) {
  const TriMesh box = make_box({1, 2, 3}, {3, 3, 4});
  const Cube c = bounding_cube(box);
  EXPECT_NEAR(c.size, 2 * (1 + 2.0 / 16), 1e-12);
  EXPECT_NEAR(c.origin[0] + c.size / 2, 2, 1e-12);
  EXPECT_NEAR(c.origin[1] + c.size / 2, 2.5, 1e-12);
  EXPECT_NEAR(c.origin[2] + c.size / 2, 3.5, 1e-12);
  SampleOptions o;
  o.depth = 5;
  EXPECT_EQ(sample(box, o).cube, c);
}

// ---------------------------------------------------------------------------------------
// Determinism: the parallel sampler builds exactly the serial tree.

void expect_parallel_equals_serial(const TriMesh& mesh, int depth) {
  SampleOptions o;
  o.depth = depth;
  o.parallel = false;
  const auto serial = serialize(sample(mesh, o));
  o.parallel = true;
  const auto parallel = serialize(sample(mesh, o));
  const auto again = serialize(sample(mesh, o));
  EXPECT_EQ(serial.size(), parallel.size());
  EXPECT_TRUE(serial == parallel) << "parallel and serial sampling differ";
  EXPECT_TRUE(parallel == again) << "two parallel runs differ";
}

TEST(Sample, ParallelIsByteIdenticalToSerialSphere) {
  expect_parallel_equals_serial(make_sphere({0, 0, 0}, 1, 48), 9);
}

TEST(Sample, ParallelIsByteIdenticalToSerialFandisk) {
  expect_parallel_equals_serial(read_mesh(std::string(PIC_DATA_DIR) + "/fandisk.obj"), 12);
}

// The winding path memoizes decisions and hole crossings per thread and collects the cells it
// skipped from every thread: none of it may depend on which thread asked first. The teapot has
// holes, overlapping parts and interior walls.
TEST(Sample, ParallelIsByteIdenticalToSerialWindingTeapot) {
  expect_parallel_equals_serial(read_mesh(std::string(PIC_DATA_DIR) + "/teapot.obj"), 10);
}

}  // namespace
}  // namespace pic

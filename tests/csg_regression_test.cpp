// CSG results against the exact Boolean of the operands' own contours: the worst
// cases the randomized harness (bench/csg_fuzz.cpp) found, kept by seed, and the Thingi10K
// difference pair's slit and specks. The reference is CGAL's corefinement (test-only
// dependency, tests/support/exact_csg.h).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>

#include "pic/pic.h"
#include "support/csg_cases.h"
#include "support/exact_csg.h"
#include "support/thingi_pair.h"

namespace pic {
namespace {

TriMesh written(const Octree& t) {
  TriMesh m = unsplit_contour(t);
  split_nonmanifold(m);
  return m;
}

struct Kept {
  uint64_t seed;
  double pic_to_exact, exact_to_pic;  // bounds, finest cells
  const char* what;
  double exact_to_pic_thick = 2.0;  // bound where the exact solid is at least a cell thick
};

// Cases the harness found, each with the situation it holds; bounds in finest cells.
constexpr Kept kKept[] = {
    {8, 1.5, 3.0, "torus union torus subtract box subtract cone: 4 components, 2 exact (specks)"},
    // A slab 1-2 cells thick lying obliquely to the lattice, whose inside points meet only
    // diagonally: the one-component pass must join it (sign hints), not erase it.
    {30, 1.5, 2.0, "box intersect torus: 4 components, 1 exact (specks along a thin tube)", 1.0},
    {87, 1.5, 2.5, "cone subtract box: 2 components, 1 exact (a speck between nearly touching surfaces)"},
    // Specks of 2-3 lattice points that the exact solid keeps joined to the body by sub-cell
    // bridges: absorbing them costs exact->PIC where they stood (the second: a wedge's tip
    // there, 3.0 cells where the exact solid is a cell thick). In the third, the bridge is an
    // oblique slab a cell thick, which stays joined.
    {84, 1.5, 2.0, "sphere subtract box: 2 components, 1 exact (a 2-point speck)"},
    {67, 1.5, 5.0, "cylinder subtract sphere union cone: 3 components, 1 exact (two 2-point specks)", 3.1},
    {82, 1.5, 1.5, "cone union fandisk intersect sphere subtract sphere: 2 components, 1 exact (3-point speck)", 1.0},
    // A box's coarse leaf whose partial contour must hold a finer neighbour's polygon cutting
    // through the cell, or points inside the box read as outside (a stray shell).
    {81, 1.0, 2.0, "cone subtract box: 2 components, 1 exact (a stray shell at the cone's tip)"},
    // The thin end of a wedge beside a coarser leaf: a flip that leaves that leaf without a
    // sign change lets the island pass clear its faces of the wedge's finer points, cutting the
    // wedge short where the exact solid is a cell thick, or splitting a body (the first).
    {43, 1.5, 7.0, "box union cad_part union box subtract sphere: 3 components, 2 exact", 1.0},
    {263, 1.5, 2.5, "cad_part subtract sphere: a wedge cut 1.5 cells short", 1.0},
    {265, 1.0, 2.5, "cone intersect cylinder subtract cylinder: a wedge's tip cut 1.9 cells short", 1.0},
    // A chain whose cones' subtrees are copied where the tori were uniform (those copies are
    // cleaned too), and two pieces that hang on the body by a bridge about a cell thin stay
    // joined, as in the exact result; exact->PIC's worst point lies where the exact solid is
    // thinner than a cell (0.3 cells where it is a cell thick).
    {105, 1.5, 4.7, "torus subtract torus subtract cone subtract cone: 4 components, 2 exact", 1.0},
    // A flat void a quarter cell thick where spot's top nearly touches the cylinder's base:
    // a speck, though one of its points lies on an edge of a coarser leaf copied whole from
    // spot (SpeckSearch::coarse_rim).
    {300, 1.5, 3.0, "spot union cylinder subtract teapot: 2 components, 1 exact (a void beside a coarse leaf)", 1.0},
    // A sign hint (a finest cell's corner the operands say joins a slab) at the corner of a
    // 4-cell leaf copied whole: the finer points along that leaf's edges must not read as
    // islands and follow it (the surface moved 1.41 cells in the first, 1.21 cells on the
    // intersection curve in the second).
    {56, 1.0, 1.5, "sphere subtract cylinder: a coarse leaf's edge filled by a hint (PIC->exact 1.41)", 1.0},
    {117, 1.0, 3.0, "torus subtract fandisk: a tooth on the intersection curve (PIC->exact 1.21)", 1.0},
};

class HarnessCase : public ::testing::TestWithParam<Kept> {};

TEST_P(HarnessCase, MatchesTheExactBoolean) {
  static const std::vector<TriMesh> models = load_case_models(PIC_DATA_DIR);
  const Kept kept = GetParam();
  const CsgCase k = make_case(kept.seed, 0, models);
  SampleOptions so;
  so.depth = k.depth;
  so.cube = Cube{{0, 0, 0}, 1};
  std::vector<Octree> trees;
  for (const TriMesh& m : k.inputs) trees.push_back(sample(m, so));
  Octree acc = trees[0];
  std::optional<TriMesh> exact = written(trees[0]);
  for (size_t i = 1; i < trees.size(); ++i) {
    acc = csg(acc, trees[i], k.ops[i - 1]);
    exact = exact_boolean(*exact, written(trees[i]), k.ops[i - 1]);
    ASSERT_TRUE(exact) << "CGAL refused case " << kept.seed;
  }
  const TriMesh result = written(acc);
  // A valid solid: closed, 2-manifold, no self-intersections (exact test).
  const MeshValidity v = check_validity(result);
  EXPECT_TRUE(v.valid()) << k.text << ": " << v.self_intersections << " self-intersections, " << v.nonmanifold_vertices
                         << " non-manifold vertices, " << v.nonmanifold_edges << " non-manifold edges, "
                         << v.boundary_edges << " boundary edges";
  const CsgComparison c = compare_to_exact(result, *exact, 1.0 / double(1 << k.depth));
  EXPECT_EQ(c.pic_components, c.exact_components) << k.text << " (" << kept.what << ")";
  EXPECT_LE(c.pic_to_exact, kept.pic_to_exact) << k.text;
  EXPECT_LE(c.exact_to_pic, kept.exact_to_pic) << k.text;
  EXPECT_LE(c.exact_to_pic_thick, kept.exact_to_pic_thick) << k.text;
}

INSTANTIATE_TEST_SUITE_P(Kept, HarnessCase, ::testing::ValuesIn(kKept),
                         [](const auto& info) { return "seed" + std::to_string(info.param.seed); });

// The Thingi10K difference pair (1706459 − 1514499, sampled in one cube at depth
// 12). Its meshes are not in this repository: the test runs where PIC_THINGI_DIR (or the
// workplace's shared data folder) holds them. Without an exact reference (CGAL takes ~15 s
// here): every point of the result's surface must lie near one operand's surface — the slit
// (a crack repair of B taken for an island, 8 cells from both) did not — and the result has
// as many components as the exact difference (4; the specks made 6).
TEST(CsgRegression, ThingiPairHasNoSlitAndNoSpecks) {
  const auto pair = test::load_thingi_pair();
  if (!pair) GTEST_SKIP() << "no Thingi10K pair (set PIC_THINGI_DIR)";
  const auto& [a, b, cube] = *pair;
  SampleOptions so;
  so.depth = 12;
  so.cube = cube;
  const Octree ta = sample(a, so), tb = sample(b, so);
  const TriMesh r = written(csg(ta, tb, CsgOp::Subtract));
  const double cell = so.cube->size / double(1 << so.depth);
  const std::vector<Vec3> pts = sample_surface(r, 100000, 5);
  const std::vector<double> da = distance_to_mesh(unsplit_contour(ta), pts), db = distance_to_mesh(unsplit_contour(tb), pts);
  double worst = 0;
  for (size_t i = 0; i < pts.size(); ++i) worst = std::max(worst, std::min(da[i], db[i]) / cell);
  // The slit was 8.3 cells deep. Below 3 cells before the intersection-free contour's last
  // resort (a coarse cell's vertex may move 1/8 of its cell, up to ~1.5 finest cells here).
  EXPECT_LT(worst, 4.5) << "a point of A − B's surface is " << worst << " cells from both operands";
  EXPECT_TRUE(check_validity(r).valid());
  EXPECT_EQ(check_validity(r, false).components, 4u);
  std::printf("  [measure] Thingi A - B: %.2f cells from the operands at most, %zu components\n", worst,
              check_validity(r, false).components);
}

}  // namespace
}  // namespace pic

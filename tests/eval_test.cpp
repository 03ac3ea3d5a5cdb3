// `pic eval`: OpenSCAD CSG trees (tests/data/scad/*.csg, each with a known volume) evaluated on
// octrees; the CLI's errors; `pic csg` with mesh operands; a .scad through `openscad`.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>

#include "pic/pic.h"
#include "pic/primitives.h"
#include "pic/scad.h"
#include "scad/scad_detail.h"
#include "signs/invariants.h"
#include "support/mesh_checks.h"
#include "support/temp_dir.h"

namespace pic {
namespace {

namespace fs = std::filesystem;
const fs::path kData = PIC_SCAD_DATA_DIR;

struct Result {
  TriMesh mesh;
  double volume = 0;
  double cell = 0;  // finest cell
};

Result eval_file(const std::string& name, int depth = 8, EvalStats* stats = nullptr) {
  EvalOptions o;
  o.depth = depth;
  const Octree t = eval_csg_file(kData / name, o, stats);
  Result r;
  r.mesh = unsplit_contour(t);
  split_nonmanifold(r.mesh);
  r.volume = volume(r.mesh);
  r.cell = t.cube.size / double(1 << depth);
  return r;
}

void expect_volume(const Result& r, double expected, double rel) {
  EXPECT_NEAR(r.volume, expected, rel * expected) << "relative error " << (r.volume - expected) / expected;
  EXPECT_TRUE(test::IsClosedManifold(r.mesh));
}

TEST(Eval, CubeMinusCube) { expect_volume(eval_file("cube_minus_cube.csg"), 840, 1e-3); }

TEST(Eval, Fn6CylinderIsHexagonalPrism) {
  const Result r = eval_file("hex_prism.csg");
  expect_volume(r, 3 * std::sqrt(3.0), 1e-3);
  // Vertices of the hexagon are at angles 60 i (OpenSCAD's circle placement): the point
  // (1, 0, 1) is on the surface, (cos 30, 0, 1)... is inside; the apothem is sqrt(3)/2.
  EXPECT_LT(test::point_mesh_distance(r.mesh, {1, 0, 1}), r.cell);
  EXPECT_LT(test::point_mesh_distance(r.mesh, {0, std::sqrt(3.0) / 2, 1}), r.cell);
}

TEST(Eval, LinearExtrudeTwistAndScale) { expect_volume(eval_file("twist_scale.csg"), 280.0 / 3, 2e-3); }

// A band along 300 degrees of a circle far from the axis, twisted by 1500 degrees in 80 slices
// (example020's spring): the twisted wall quads are far from flat. By Cavalieri the solid's
// volume is area x height; OpenSCAD's walls (each quad split along its shorter diagonal) keep
// it to 2e-4 here, where one diagonal for the whole extrusion gives +7 % or -11 %.
TEST(Eval, TwistedBandKeepsItsVolume) {
  detail::scad::Ring band;
  const int arc = 16;
  for (int side = 0; side < 2; ++side)
    for (int i = 0; i <= arc; ++i) {
      const double a = (side ? arc - i : i) * (300.0 / arc) * std::numbers::pi / 180;
      const double r = side ? 90 : 110;
      band.push_back({r * std::cos(a), r * std::sin(a)});
    }
  double area = 0;
  for (size_t i = 0; i < band.size(); ++i) {
    const auto& p = band[i];
    const auto& q = band[(i + 1) % band.size()];
    area += (p[0] * q[1] - q[0] * p[1]) / 2;
  }
  detail::scad::LinearExtrude e;
  e.height = 100;
  e.twist = 1500;
  e.slices = 80;
  const TriMesh m = detail::scad::extrude_linear(band, e);
  EXPECT_TRUE(test::IsClosedManifold(m));
  EXPECT_NEAR(volume(m), area * e.height, 5e-3 * area * e.height);
  e.twist = -1500;  // the mirror image
  EXPECT_NEAR(volume(detail::scad::extrude_linear(band, e)), area * e.height, 5e-3 * area * e.height);
}

// A rectangle with a corner on the axis, twisted: the quads of its two sides along lines through
// the axis have diagonals of equal length, and OpenSCAD 2021 splits those by the twist's
// direction. Volumes of OpenSCAD's own output (`openscad -o x.stl`, CGAL): 23.26630439 and,
// twisted the other way, 23.26628369; a square centred on the axis scaled unevenly without a
// twist (every quad a tie) 13.93333333, each within the STL's rounding. Ties taken by rounding
// gave 23.16 and 22.90.
TEST(Eval, TwistedQuadsSplitAsOpenScadSplitsThem) {
  const detail::scad::Ring rectangle{{0, 0}, {3.28, 0}, {3.28, 1.83}, {0, 1.83}};
  detail::scad::LinearExtrude e;
  e.height = 3.8;
  e.slices = 10;
  e.twist = 30;
  const TriMesh left = detail::scad::extrude_linear(rectangle, e);
  EXPECT_TRUE(test::IsClosedManifold(left));
  EXPECT_NEAR(volume(left), 23.26630439, 1e-4);
  e.twist = -30;
  EXPECT_NEAR(volume(detail::scad::extrude_linear(rectangle, e)), 23.26628369, 1e-4);
  const detail::scad::Ring square{{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  e.twist = 0;
  e.slices = 2;
  e.scale = {1.5, 0.5};
  EXPECT_NEAR(volume(detail::scad::extrude_linear(square, e)), 13.93333333, 1e-4);
}

// Slices when none are given: OpenSCAD 2021's counts (its output's triangles, `openscad -o
// x.stl`, less the two caps' over 8 per slice of a square's 4 sides) for a square [0.51, 1.44]
// (first four rows, height 2.08) and a unit square (height 0.1): a twist without scale walks
// its helix, an even scale a section of an Archimedes spiral that ends at the unscaled radius
// (3 slices at scale 1.5 and at 10, 4 at 3, where the true path grows with the scale), an
// uneven one the more of the helix and its longest vertex path.
TEST(Eval, LinearExtrudeSlicesAsOpenScadCountsThem) {
  struct Case {
    const char* twist_scale_height;
    double square;
    int slices;
  };
  const Case cases[] = {{"twist = 200, scale = 1, height = 2.08", 0, 3},
                        {"twist = 200, scale = 2, height = 2.08", 0, 3},
                        {"twist = 200, scale = [1.5, 0.7], height = 2.08", 0, 3},
                        {"twist = 200, scale = 1.5, height = 20", 0, 11},
                        {"twist = 360, scale = 3, height = 0.1", 1, 4},
                        {"twist = 360, scale = 10, height = 0.1", 1, 3},
                        {"twist = 360, scale = 1.2, height = 0.1", 1, 5},
                        {"twist = 720, scale = 0.5, height = 0.1", 1, 7},
                        {"twist = 1000, scale = 0.2, height = 0.1", 1, 9}};
  for (const Case& c : cases) {
    const std::string square = c.square > 0 ? "square(size = [1, 1]);" : "square(size = [0.51, 1.44]);";
    EvalOptions o;
    o.depth = 9;  // the 0.1 slabs a few cells thick in their cubes
    EvalStats stats;
    eval_csg(std::string("linear_extrude(") + c.twist_scale_height + ") { " + square + " }", o, &stats);
    EXPECT_EQ(stats.triangles, size_t(8 * c.slices + 4)) << c.twist_scale_height;
  }
}

// A polygon crossing itself (a bow tie) is two lobes touching at a point; each ring's nesting
// was asked at its first vertex, which is that point, on the other ring: one lobe became the
// other's hole and the extrusion was half of OpenSCAD's 4.5.
TEST(Eval, RingsTouchingAtAPointAreNotNested) {
  EvalOptions o;
  o.depth = 8;
  const TriMesh m = unsplit_contour(
      eval_csg("linear_extrude(height = 1) { polygon(points = [[0, 0], [3, 3], [3, 0], [0, 3]], paths = undef); }", o));
  EXPECT_NEAR(volume(m), 4.5, 4.5 * 1e-3);
}

// A leaf thinner than a finest cell (here a 1e-7 thick box; in GEB.scad a sliver ring of a 2D
// difference, extruded) is empty at that depth, not an error that stops the whole model.
TEST(Eval, FlatLeafIsEmpty) { expect_volume(eval_file("flat_leaf.csg"), 1000, 1e-3); }

// A sphere's flat facets sample into coarse leaves, which a Boolean nearby subdivides and
// resamples from the sphere's partial contour. Two ways that went wrong, both at depth 10 and
// in these models' own cubes (found by bench/scad_fuzz.py), both measured against
// OpenSCAD's render of the same model:
// - facet_minus_inner_sphere: a resampled cell at a coarse leaf's corner held only polygons of
//   unstamped neighbours, which the partial contour kept for parity walks alone: its sign
//   changed but its QEF had no plane, and its vertex sat at a corner, 24 cells off the facet;
// - crease_on_lattice_diagonal: the sphere's crease lies in the lattice plane x = y, so the
//   facet beyond it crosses the resampled cells' edges without area in them; without those
//   edge-crossing planes the vertices sat on one facet and the crease came out toothed (5.6).
TEST(Eval, CoarseFacetsKeepTheirShapeWhereABooleanResamplesThem) {
  for (const std::string name : {"facet_minus_inner_sphere", "crease_on_lattice_diagonal"}) {
    const Result r = eval_file(name + ".csg", 10);
    EXPECT_TRUE(test::IsClosedManifold(r.mesh)) << name;
    const SurfaceDistance d = surface_distance(r.mesh, read_mesh(kData / (name + ".stl")), 20000);
    EXPECT_LT(d.hausdorff / r.cell, 3.0) << name;  // 2.3 and 1.6: a tangency and a thin wedge
  }
}

// Three boxes and a prism stacked face to face, turned: where two operands' faces coincide
// their contours stand a few hundredths of a cell apart (further beside leaves accepted at the
// cap, whose vertices fit no plane). No such gap is a feature: the union is one solid without
// a void.
TEST(Eval, StackedPartsLeaveNoVoidBetweenThem) {
  for (const int depth : {7, 8, 9}) {
    EvalStats st;
    const Result r = eval_file("stacked_turned_boxes.csg", depth, &st);
    EXPECT_EQ(test::component_count(r.mesh), 1u) << "depth " << depth;
    EXPECT_EQ(st.thin_points, 0u) << "depth " << depth;
    // 10 x 10 x 10 + 10 x 3 x 10 + the 7-gon prism (r 2, h 3).
    const double prism = 3 * 0.5 * 7 * 4 * std::sin(2 * std::numbers::pi / 7);
    expect_volume(r, 1300 + prism, 2e-3);
  }
}

// A hollow cube, its walls 0.02 of 10 thick (0.14 of a finest cell at depth 7), turned: the
// difference leaves walls thinner than a cell, kept about a cell thick (without that, 100
// fragments): closed, at most two sheets (the outside's and the cavity's), at least the exact
// walls' volume.
TEST(Eval, ThinWallsOfADifferenceAreKept) {
  EvalStats st;
  const Result r = eval_file("hollow_box_thin_walls.csg", 7, &st);
  EXPECT_GT(st.thin_points, 0u);
  EXPECT_TRUE(test::IsClosedManifold(r.mesh));
  EXPECT_LE(test::component_count(r.mesh), 2u);
  EXPECT_GE(r.volume, 1000 - std::pow(9.96, 3));
}

TEST(Eval, RotateExtrudeFn4) { expect_volume(eval_file("rotate_square.csg"), 6, 1e-3); }

TEST(Eval, PolyhedronClockwiseFaces) { expect_volume(eval_file("polyhedron.csg"), 2000.0 / 3, 1e-3); }

TEST(Eval, Extruded2DDifferenceAndPolygonHole) { expect_volume(eval_file("extruded_difference.csg"), 420, 1e-3); }

// Two plates with rounded edges, each a union of two crossed boxes and four cylinders whose
// caps are flush with the boxes' faces. The flush faces meet as crossings a few float steps
// apart; taken for one crossing the wrong way, the union refined them to the depth cap (52,540
// PICs at depth 9 instead of about 5,000, four times more at each further level).
TEST(Eval, FlushFacesDoNotRefine) {
  EvalOptions o;
  o.depth = 9;
  const Octree t = eval_csg_file(kData / "flush_plates.csg", o);
  EXPECT_LT(analyze(t).pics, 10000u);
  Result r;
  r.mesh = unsplit_contour(t);
  r.volume = volume(r.mesh);
  expect_volume(r, 46357.5454, 1e-4);  // OpenSCAD 2021's render
}

// Leaves whose boxes are apart are sampled together as one soup: the nine pins cost one
// sampling and one Boolean, not nine of each; the two blocks that meet still need their union.
TEST(Eval, LeavesApartAreSampledTogether) {
  EvalOptions o;
  o.depth = 8;
  EvalStats st;
  const Octree t = eval_csg_file(kData / "apart_leaves.csg", o, &st);
  EXPECT_EQ(st.leaves, 13u);
  // plate - soup of pins; (blocks A u B) and C apart, A u B meets the plate: 3 Booleans at most.
  EXPECT_LE(st.booleans, 4u);
  Result r;
  r.mesh = unsplit_contour(t);
  r.volume = volume(r.mesh);
  expect_volume(r, 1560, 1e-3);
  // One part (the blocks stand on the plate) with the nine holes through it: genus 9.
  EXPECT_EQ(test::component_count(r.mesh), 1u);
  EXPECT_EQ(test::euler_characteristic(r.mesh), 2 - 2 * 9);
}

// Three parallel bars turned 30 degrees about z and 20 about x: their axis boxes overlap, but
// a plane along their own faces separates each pair, so they are one soup (no Boolean).
// A fourth bar crossing the middle one leaves the three one group: one Boolean.
TEST(Eval, TurnedBarsApartAreSampledTogether) {
  const double a = std::numbers::pi / 6, b = std::numbers::pi / 9;
  // R = Rx(b) Rz(a), then each bar moved 4 along its own turned y axis.
  const double r[3][3] = {{std::cos(a), -std::sin(a), 0},
                          {std::cos(b) * std::sin(a), std::cos(b) * std::cos(a), -std::sin(b)},
                          {std::sin(b) * std::sin(a), std::sin(b) * std::cos(a), std::cos(b)}};
  const auto bar = [&](double y) {
    std::ostringstream s;
    s.precision(17);
    s << "multmatrix([";
    for (int i = 0; i < 3; ++i)
      s << "[" << r[i][0] << ", " << r[i][1] << ", " << r[i][2] << ", " << r[i][1] * y << "], ";
    s << "[0, 0, 0, 1]]) { cube(size = [20, 2, 2], center = true); }\n";
    return s.str();
  };
  const std::string three = bar(-4) + bar(0) + bar(4);
  EvalOptions o;
  o.depth = 8;
  EvalStats st;
  Result res;
  res.mesh = unsplit_contour(eval_csg("union() {\n" + three + "}\n", o, &st, "bars"));
  res.volume = volume(res.mesh);
  EXPECT_EQ(st.booleans, 0u);
  expect_volume(res, 3 * 80, 2e-3);
  EXPECT_EQ(test::component_count(res.mesh), 3u);

  const std::string crossed = three + "cube(size = [2, 2, 30], center = true);\n";
  res.mesh = unsplit_contour(eval_csg("union() {\n" + crossed + "}\n", o, &st, "bars"));
  EXPECT_EQ(st.booleans, 1u);
  EXPECT_EQ(test::component_count(res.mesh), 3u);  // the middle bar and the fourth are one
  EXPECT_TRUE(test::IsClosedManifold(res.mesh));
}

TEST(Eval, HullOfTwoSpheres) {
  // The $fn = 16 sphere polytope: 8 rings of 16 points at polar angles 180 (i + 0.5) / 8; its
  // volume is the stack of frusta between rings (the caps are flat). The hull with its copy
  // 3 higher adds 3 times the area of its projection (the widest ring's 16-gon).
  const int n = 16, rings = 8;
  auto ngon = [&](double r) { return n / 2.0 * r * r * std::sin(2 * std::numbers::pi / n); };
  double v = 0, widest = 0;
  for (int i = 0; i + 1 < rings; ++i) {
    const double p1 = std::numbers::pi * (i + 0.5) / rings, p2 = std::numbers::pi * (i + 1.5) / rings;
    const double a1 = ngon(std::sin(p1)), a2 = ngon(std::sin(p2));
    v += (std::cos(p1) - std::cos(p2)) / 3 * (a1 + a2 + std::sqrt(a1 * a2));
    widest = std::max({widest, a1, a2});
  }
  expect_volume(eval_file("hull_spheres.csg", 9), v + 3 * widest, 2e-3);
}

TEST(Eval, FragmentRule) {
  using detail::scad::fragments_from_r;
  EXPECT_EQ(fragments_from_r(10, 0, 2, 12), 30);  // 360 / $fa
  EXPECT_EQ(fragments_from_r(1, 0, 2, 12), 5);    // at least 5
  EXPECT_EQ(fragments_from_r(3, 0, 2, 12), 10);   // 2 pi r / $fs, rounded up
  EXPECT_EQ(fragments_from_r(3, 6, 2, 12), 6);    // $fn wins
  EXPECT_EQ(fragments_from_r(3, 2, 2, 12), 3);    // but at least 3
}

TEST(Eval, UnsupportedNodeNamesNodeAndLine) {
  try {
    eval_file("unsupported.csg");
    FAIL() << "expected InvalidInput";
  } catch (const InvalidInput& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("roof"), std::string::npos) << m;
    EXPECT_NE(m.find("line 3"), std::string::npos) << m;
  }
}

// pic eval runs the library's CSG tree: an n-ary union of parts that all meet is the same
// balanced union, byte for byte, as evaluate() of the same meshes in the same cube.
TEST(Eval, UnionIsTheLibrarysTreeByteForByte) {
  const test::TempDir dir;
  std::string text = "union() {\n";
  std::vector<CsgTree> leaves;
  for (int i = 0; i < 5; ++i) {
    const double a = 2 * std::numbers::pi * i / 5;
    const TriMesh ball = make_sphere({0.3 * std::cos(a), 0.3 * std::sin(a), 0.1 * i}, 0.5, 24);
    const std::string name = "ball" + std::to_string(i) + ".obj";
    write_mesh(ball, dir / name);
    leaves.push_back(csg_leaf(read_mesh(dir / name)));
    text += " import(file = \"" + name + "\");\n";
  }
  text += "}\n";
  EvalOptions o;
  o.depth = 7;
  o.base_dir = dir.path();
  EvalStats st;
  const Octree via_eval = eval_csg(text, o, &st);
  EXPECT_EQ(st.booleans, 4u);
  CsgChainOptions co;
  co.sampling.depth = o.depth;
  co.sampling.cube = st.cube;
  co.compact = false;
  const Octree via_tree = evaluate(csg_union(std::move(leaves)), co);
  EXPECT_EQ(serialize(via_eval), serialize(via_tree));
  EXPECT_TRUE(IsClosedManifold(unsplit_contour(via_tree)));
}

// minkowski() of a non-convex part and a faceted sphere: one distance sampling (not a hull
// per convex piece), its volume within 0.5 % of OpenSCAD's exact polyhedral sum.
TEST(Eval, MinkowskiWithASphereIsOneSampling) {
  const std::string text =
      "minkowski() {\n difference() {\n  cube(size = [20, 14, 8]);\n"
      "  multmatrix([[1, 0, 0, 6], [0, 1, 0, -1], [0, 0, 1, 4], [0, 0, 0, 1]]) cube(size = [20, 16, 10]);\n"
      "  multmatrix([[1, 0, 0, 3], [0, 1, 0, 7], [0, 0, 1, -1], [0, 0, 0, 1]]) cylinder(h = 10, r1 = 2, r2 = 2, $fn = 24);\n"
      " }\n sphere(r = 1.5, $fn = 24);\n}\n";
  EvalOptions o;
  o.depth = 8;
  EvalStats st;
  const TriMesh m = unsplit_contour(eval_csg(text, o, &st));
  EXPECT_EQ(st.leaves, 1u);
  EXPECT_EQ(st.booleans, 0u);
  EXPECT_TRUE(IsClosedManifold(m));
  const double openscad = 3216.31;  // `openscad -o x.stl` of the same model, its volume by meshcheck
  EXPECT_NEAR(volume(m), openscad, 5e-3 * openscad);
}

// OpenSCAD warns about an import() of a file that does not exist and renders the rest; so
// does pic eval (a file that exists but is broken is still an error).
TEST(Eval, MissingImportIsLeftOutWithAWarning) {
  EvalOptions o;
  o.depth = 7;
  std::vector<std::string> warnings;
  o.warning = [&](const std::string& w) { warnings.push_back(w); };
  const Octree t = eval_csg(
      "union() {\n cube(size = [2, 3, 4]);\n import(file = \"no_such_part.stl\");\n"
      " linear_extrude(height = 1) { import(file = \"no_such_drawing.dxf\"); }\n}",
      o);
  EXPECT_NEAR(volume(contour(t)), 24, 24 * 1e-6);
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_NE(warnings[0].find("line 3"), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[0].find("no_such_part.stl"), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[1].find("no_such_drawing.dxf"), std::string::npos) << warnings[1];
}

// A profile on both sides of the axis: OpenSCAD reports an error for the rotate_extrude,
// leaves it out and renders the rest (the cube's volume, 24); so does pic eval, with a warning.
TEST(Eval, RotateExtrudeAcrossTheAxisIsLeftOutWithAWarning) {
  EvalOptions o;
  o.depth = 7;
  std::vector<std::string> warnings;
  o.warning = [&](const std::string& w) { warnings.push_back(w); };
  const Octree t = eval_csg(
      "union() {\n cube(size = [2, 3, 4]);\n rotate_extrude() { multmatrix([[1, 0, 0, -0.5], [0, 1, 0, 0], "
      "[0, 0, 1, 0], [0, 0, 0, 1]]) { square(size = [1, 1]); } }\n}",
      o);
  EXPECT_NEAR(volume(contour(t)), 24, 24 * 1e-6);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("line 3"), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[0].find("same x coordinate sign"), std::string::npos) << warnings[0];
}

TEST(Eval, SyntaxErrorNamesLine) {
  EXPECT_THROW(eval_csg("cube(size = [1, 1, 1]);\ncube(size = [1, 1 1]);\n"), InvalidInput);
  try {
    eval_csg("cube(size = 1);\n\nsphere(r = );\n");
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("line 3"), std::string::npos) << e.what();
  }
}

TEST(Eval, SmoothSphereIsCloserToTheTrueSphere) {
  EvalOptions o;
  o.depth = 7;
  o.smooth = true;
  const Octree t = eval_csg("sphere($fn = 0, $fa = 12, $fs = 2, r = 1);", o);
  const double v = volume(unsplit_contour(t)), exact = 4.0 / 3 * std::numbers::pi;
  EXPECT_NEAR(v, exact, 0.01 * exact);  // the $fa/$fs sphere (5 fragments) is far smaller
  o.smooth = false;
  const double coarse = volume(contour(eval_csg("sphere($fn = 0, $fa = 12, $fs = 2, r = 1);", o)));
  EXPECT_LT(coarse, 0.8 * exact);
}

// ---- the CLI ----

std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}
int run(const std::string& args, const fs::path& dir, std::string* err = nullptr) {
  const fs::path e = dir / ".stderr";
  const int status = std::system((quote(PIC_CLI) + " " + args + " > /dev/null 2> " + quote(e.string())).c_str());
  if (err) {
    std::ifstream in(e);
    std::stringstream ss;
    ss << in.rdbuf();
    *err = ss.str();
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(EvalCli, WritesMeshAndPic) {
  test::TempDir dir("pic_eval");
  ASSERT_EQ(run("eval " + quote((kData / "cube_minus_cube.csg").string()) + " -o " + quote((dir / "a.stl").string()) +
                    " --depth 7",
                dir.path()),
            0);
  const TriMesh m = read_mesh(dir / "a.stl");
  EXPECT_NEAR(volume(m), 840, 1);
  ASSERT_EQ(run("eval " + quote((kData / "hex_prism.csg").string()) + " -o " + quote((dir / "a.pic").string()) +
                    " --depth 7",
                dir.path()),
            0);
  EXPECT_NEAR(volume(unsplit_contour(load(dir / "a.pic"))), 3 * std::sqrt(3.0), 0.01);
}

// STL holds 32-bit floats. Rounded to the nearest floats, the contour of two plates with flush
// rounded edges folds 140 triangle pairs through each other (its vertices come within a float's
// step of other triangles); round_to_float32 picks another float near the double where that
// keeps them apart, and the STL the CLI writes is the rounded mesh it checked.
TEST(Float32, RoundingKeepsTheContourFromCrossingItself) {
  EvalOptions o;
  o.depth = 8;
  const TriMesh m = contour(eval_csg_file(kData / "flush_plates.csg", o));
  ASSERT_EQ(count_self_intersections(m), 0u);
  TriMesh nearest = m;
  for (Vec3& p : nearest.positions)
    for (double& c : p) {
      volatile float f = static_cast<float>(c);  // (g++ 12 -O3 drops a plain round trip in such a loop)
      c = f;
    }
  EXPECT_GT(count_self_intersections(nearest), 0u);  // the case this is about
  const TriMesh r = round_to_float32(m);
  EXPECT_TRUE(check_validity(r).valid());
  ASSERT_EQ(r.positions.size(), m.positions.size());
  size_t moved = 0;
  for (size_t i = 0; i < r.positions.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      const double x = m.positions[i][k], y = r.positions[i][k];
      volatile float fy = static_cast<float>(y);
      EXPECT_EQ(y, double(fy));
      // at most three float steps from x (one of the two around it, unless that left a crossing)
      EXPECT_LE(std::abs(y - x), 3 * std::abs(double(std::nextafter(float(x), 2 * float(x) + 1)) - double(float(x))));
      moved += y != nearest.positions[i][k];
    }
  EXPECT_GT(moved, 0u);
  EXPECT_EQ(round_to_float32(r).positions, r.positions);  // floats already: left as they are
  // The library's writer rounds the same way (not a cast): what a reader gets back is valid.
  test::TempDir dir("pic_float32");
  write_mesh(m, dir / "m.stl");
  EXPECT_EQ(count_self_intersections(read_mesh(dir / "m.stl")), 0u);
}

TEST(Float32, EvalToStlWritesWhatItChecked) {
  test::TempDir dir("pic_eval");
  ASSERT_EQ(run("eval " + quote((kData / "flush_plates.csg").string()) + " -o " + quote((dir / "a.stl").string()) +
                    " --depth 8 --json > " + quote((dir / "a.json").string()),
                dir.path()),
            0);
  const TriMesh m = read_mesh(dir / "a.stl");
  EXPECT_TRUE(test::IsClosedManifold(m));
  EXPECT_EQ(count_self_intersections(m), 0u);
  // The exact volume; the written mesh is simplified within half a finest cell (0.11 here) of
  // the raw contour over about 9,700 of area, which moves it by about a thousandth.
  EXPECT_NEAR(volume(m), 46357.5454, 46357.5454 * 2e-3);
}

// A Boolean combines a few coarse cells a second time around contacts, after stamping more
// cells, which grows the operands' partial contours. Here a parity walk in a level-4 leaf of
// the text can turn at a point on such a cell's face that finer leaves beside the cell hold as
// a corner: that point must keep one sign, or the contour has a boundary edge and
// non-manifold edges at depth 9.
TEST(Eval, ASecondPassKeepsTheSignsTheFirstGave) {
  const std::string csg = R"(resize(newsize = [3.08,0,3.03], auto = [1,1,1], convexity = 0) {
  union() {
    multmatrix([[0.5, 0.612372, 0.612372, 0], [0, 0.707107, -0.707107, 0], [-0.866025, 0.353553, 0.353553, 0], [0, 0, 0, 1]]) {
      linear_extrude(height = 1, center = false, convexity = 1, scale = [1, 1], $fn = 0, $fa = 12, $fs = 2) {
        text(text = "g8", size = 3.84, spacing = 1, font = "", direction = "ltr", language = "en", script = "Latn", halign = "right", valign = "baseline", $fn = 0, $fa = 12, $fs = 2);
      }
    }
    multmatrix([[1, 0.3, 0, 0], [0, 1, -0.21, 0], [0, 0, 1, 0], [0, 0, 0, 1]]) {
      rotate_extrude(angle = 360, convexity = 2, $fn = 0, $fa = 5, $fs = 2) {
        multmatrix([[1, 0, 0, 2.74], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]) {
          polygon(points = [[0, 0], [3.7, 3.7], [2.97, 0], [0, 3.64]], paths = undef, convexity = 1);
        }
      }
    }
  }
})";
  EvalOptions o;
  o.depth = 9;
  const Octree t = eval_csg(csg, o);
  EXPECT_NO_THROW(detail::check_octree(t, "eval"));
  const MeshTopology topo = analyze_topology(contour(t));
  EXPECT_TRUE(topo.closed() && topo.manifold());
}

TEST(EvalCli, UnsupportedNodeExits2WithOneLine) {
  test::TempDir dir("pic_eval");
  std::string err;
  EXPECT_EQ(run("eval " + quote((kData / "unsupported.csg").string()) + " -o " + quote((dir / "a.stl").string()),
                dir.path(), &err),
            2);
  EXPECT_NE(err.find("pic: error:"), std::string::npos) << err;
  EXPECT_NE(err.find("'roof'"), std::string::npos) << err;
  EXPECT_NE(err.find("line 3"), std::string::npos) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  EXPECT_FALSE(fs::exists(dir / "a.stl"));
}

TEST(EvalCli, CsgWithMeshOperands) {
  test::TempDir dir("pic_eval");
  write_mesh(make_box({0, 0, 0}, {2, 2, 2}), dir / "part.stl");
  write_mesh(make_box({0.5, 0.5, -1}, {1.5, 1.5, 3}), dir / "hole.stl");
  ASSERT_EQ(run("csg " + quote((dir / "part.stl").string()) + " subtract " + quote((dir / "hole.stl").string()) +
                    " -o " + quote((dir / "out.stl").string()) + " --depth 7",
                dir.path()),
            0);
  const TriMesh m = read_mesh(dir / "out.stl");
  EXPECT_NEAR(volume(m), 8 - 2, 0.01);
  EXPECT_TRUE(test::IsClosedManifold(m));
}

TEST(EvalCli, ScadThroughOpenscad) {
  if (std::system("command -v openscad > /dev/null 2>&1") != 0) GTEST_SKIP() << "openscad is not installed";
  test::TempDir dir("pic_eval");
  {
    std::ofstream f(dir / "part.scad");
    f << "difference() { cube(10); translate([5, 5, -1]) cylinder(r = 2, h = 12, $fn = 4); }\n";
  }
  EvalOptions o;
  o.depth = 7;
  const TriMesh m = unsplit_contour(eval_scad(dir / "part.scad", o));
  // A $fn = 4 cylinder of radius 2 is a square of diagonal 4: area 8.
  EXPECT_NEAR(volume(m), 1000 - 8 * 10, 0.5);
  EXPECT_FALSE(fs::exists(dir / "part.csg"));  // the export goes to a temporary directory
}

TEST(EvalCli, ScadEvaluatesTheRenderTreeNotThePreview) {
  if (std::system("command -v openscad > /dev/null 2>&1") != 0) GTEST_SKIP() << "openscad is not installed";
  test::TempDir dir("pic_eval");
  {
    std::ofstream f(dir / "part.scad");
    // OpenSCAD renders one cube; its preview shows a second one.
    f << "cube(1);\nif ($preview) translate([5, 0, 0]) cube(1);\nif (!$preview) translate([0, 5, 0]) cube(2);\n";
  }
  EvalOptions o;
  o.depth = 7;
  const TriMesh m = unsplit_contour(eval_scad(dir / "part.scad", o));
  EXPECT_NEAR(volume(m), 1 + 8, 1e-6);
  for (const Vec3& p : m.positions) EXPECT_LT(p[0], 2.5);  // nothing where the preview cube is
}

/// `body` moved by (x, y, z), as OpenSCAD's .csg export writes it.
std::string moved(double x, double y, double z, const std::string& body) {
  std::ostringstream s;
  s << "multmatrix([[1, 0, 0, " << x << "], [0, 1, 0, " << y << "], [0, 0, 1, " << z << "], [0, 0, 0, 1]]) { " << body
    << " }";
  return s.str();
}

// A part cut in half by a box twenty times its size: the root cube is around the half that
// remains, not around the box, so the cut keeps the part's resolution (around the box the
// finest cell would be ten times larger and the half sphere 0.12 % short of its volume).
TEST(Eval, APartCutByAHugeBoxKeepsItsResolution) {
  EvalOptions o;
  o.depth = 8;
  const std::string sphere = "sphere($fn = 48, $fa = 12, $fs = 2, r = 10);";
  EvalStats whole_stats, half_stats;
  const double whole = volume(unsplit_contour(eval_csg(sphere, o, &whole_stats)));
  const std::string box = moved(-100, -100, -200, "cube(size = [200, 200, 200], center = false);");
  const TriMesh half = unsplit_contour(eval_csg("difference() { " + sphere + " " + box + " }", o, &half_stats));
  EXPECT_TRUE(test::IsClosedManifold(half));
  EXPECT_LT(half_stats.cube.size, 1.2 * whole_stats.cube.size);
  // The faceted sphere's rings are symmetric about z = 0.
  EXPECT_NEAR(volume(half), whole / 2, 2e-4 * whole / 2);
  for (const Vec3& p : half.positions) EXPECT_GE(p[2], -1e-6 * half_stats.cube.size);
}

// A subtree whose shape `resize` needs is evaluated in the cube around its own result too: the
// half of a unit sphere cut by a 200-unit box, scaled up tenfold, is the half of the sphere
// scaled tenfold, not a blob sampled at the box's resolution.
TEST(Eval, AResizedPartCutByAHugeBoxKeepsItsResolution) {
  EvalOptions o;
  o.depth = 8;
  const std::string box = moved(-100, -100, -200, "cube(size = [200, 200, 200], center = false);");
  const std::string small = "sphere($fn = 48, $fa = 12, $fs = 2, r = 1);";
  const std::string big = "multmatrix([[10, 0, 0, 0], [0, 10, 0, 0], [0, 0, 10, 0], [0, 0, 0, 1]]) { " + small + " }";
  // OpenSCAD's sphere of 48 fragments has its rings at polar angles (i + 1/2)·180°/24: it
  // reaches cos(3.75°) of its radius along every axis, and resize fits that reach.
  const double reach = std::cos(3.75 * std::numbers::pi / 180);
  const double expected =
      volume(unsplit_contour(eval_csg("difference() { " + big + " " + box + " }", o))) / std::pow(reach, 3);
  const TriMesh resized = unsplit_contour(eval_csg(
      "resize(newsize = [20, 20, 10], auto = [0, 0, 0]) { difference() { " + small + " " + box + " } }", o));
  EXPECT_TRUE(test::IsClosedManifold(resized));
  EXPECT_NEAR(volume(resized), expected, 2e-3 * expected);
  for (const Vec3& p : resized.positions) EXPECT_GE(p[2], -1e-3);
}

// The cube may follow the result only where the leaves reaching out of it can be cut to it:
// a cutter that is not convex (an extruded L) keeps the cube around every leaf, and so does a
// hull, whose parts outside shape what is inside.
TEST(Eval, LeavesThatCannotBeCutKeepTheCubeAroundThemAll) {
  EvalOptions o;
  o.depth = 6;
  const std::string part = "cube(size = [10, 10, 10], center = false);";
  const std::string l_cutter = moved(
      -100, -100, 5,
      "linear_extrude(height = 200, center = false, convexity = 1, scale = [1, 1], $fn = 0, $fa = 12, $fs = 2) { "
      "polygon(points = [[0, 0], [200, 0], [200, 50], [50, 50], [50, 200], [0, 200]], paths = undef, convexity = 1); }");
  const std::string hull_cutter = "hull() { " + moved(-100, -100, 5, "cube(size = [1, 1, 1], center = false);") + " " +
                                  moved(100, 100, 150, "cube(size = [1, 1, 1], center = false);") + " }";
  for (const std::string& cutter : {l_cutter, hull_cutter}) {
    EvalStats st;
    eval_csg("difference() { " + part + " " + cutter + " }", o, &st);
    EXPECT_GT(st.cube.size, 150) << cutter;
  }
}

}  // namespace
}  // namespace pic

// OpenSCAD's 2D side: regions through Clipper (Booleans, polygon paths, offset), text through
// FreeType/HarfBuzz, 2D models written as outlines, and the `%`/`*` modifiers. Expected areas
// are analytic, or OpenSCAD 2021.01's own exports of the same model (DXF, area by the shoelace
// formula), stored here so the tests do not need `openscad`.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>
#include <string>

#include "pic/pic.h"
#include "pic/scad.h"
#include "pic/render.h"
#include "scad/dxf.h"
#include "scad/lower.h"
#include "scad/region.h"
#include "scad/text.h"
#include "signs/invariants.h"
#include "support/mesh_checks.h"
#include "support/temp_dir.h"

namespace pic {
namespace {

using detail::scad::Region;
using detail::scad::Ring;

// A .csg model evaluated as a 2D outline.
Outline outline_of(const std::string& csg) {
  test::TempDir dir("outline");
  const auto path = dir / "model.csg";
  std::ofstream(path) << csg;
  const std::optional<Outline> o = eval_outline(path);
  if (!o) throw std::runtime_error("not a 2D model");
  return *o;
}

double relative(double a, double b) { return std::abs(a - b) / std::abs(b); }

Ring square(double x0, double y0, double s) { return {{x0, y0}, {x0 + s, y0}, {x0 + s, y0 + s}, {x0, y0 + s}}; }

TEST(Region, BooleansOfSquares) {
  const Region a{square(0, 0, 10)}, b{square(5, 5, 10)};
  EXPECT_NEAR(detail::scad::region_area(detail::scad::region_union({a, b})), 175, 1e-6);
  EXPECT_NEAR(detail::scad::region_area(detail::scad::region_intersection({a, b})), 25, 1e-6);
  EXPECT_NEAR(detail::scad::region_area(detail::scad::region_difference({a, b})), 75, 1e-6);
  // A hole: the difference of a square and one inside it is two rings, the hole clockwise.
  const Region framed = detail::scad::region_difference({a, {square(2, 2, 6)}});
  ASSERT_EQ(framed.size(), 2u);
  EXPECT_NEAR(detail::scad::region_area(framed), 64, 1e-6);
}

TEST(Region, OffsetByDeltaAndChamfer) {
  using detail::scad::OffsetJoin;
  const Region a{square(0, 0, 10)};
  // Mitred corners stay square: (10 + 2)^2.
  EXPECT_NEAR(detail::scad::region_area(detail::scad::region_offset(a, 1, OffsetJoin::kMiter, 0)), 144, 1e-6);
  EXPECT_NEAR(detail::scad::region_area(detail::scad::region_offset(a, -1, OffsetJoin::kMiter, 0)), 64, 1e-6);
  // Rounded corners: 10^2 + 4 * 10 * 2 + (a polygon just inside) pi 2^2.
  const double round = detail::scad::region_area(detail::scad::region_offset(a, 2, OffsetJoin::kRound, 1e-3));
  EXPECT_LT(round, 180 + 4 * std::numbers::pi);
  EXPECT_GT(round, 180 + 4 * std::numbers::pi - 0.05);
}

// Each against OpenSCAD 2021.01's export of the same node.
TEST(ScadOutline, OffsetMatchesOpenScad) {
  const auto area_of = [](const std::string& node) { return area(outline_of(node)); };
  EXPECT_LT(relative(area_of("offset(r = 2, $fn = 40) { square(size = [10, 10]); }"), 192.514714), 1e-4);
  EXPECT_LT(relative(area_of("offset(delta = 1, $fn = 0, $fa = 12, $fs = 2) { circle(r = 5, $fn = 0, $fa = 12, $fs = 2); }"),
                     110.933201),
            1e-4);
  EXPECT_LT(relative(area_of("offset(delta = 1, chamfer = true) { square(size = [5, 5]); }"), 48.313718), 1e-4);
  EXPECT_NEAR(area_of("offset(r = -1, $fn = 24) { square(size = [10, 10]); }"), 64, 1e-6);
  // Six pieces per turn ask for 1.5 steps on a square's corner: one, as OpenSCAD's cosine of
  // 30 degrees gives (its output: 8 vertices, each corner cut straight), where the cosine of
  // the rounded radian angle gave two (12 vertices, 3 % more area on a small square).
  const Outline six = outline_of("offset(r = 1, $fn = 6) { square(size = [4, 4], center = true); }");
  ASSERT_EQ(six.rings.size(), 1u);
  EXPECT_EQ(six.rings[0].size(), 8u);
  EXPECT_NEAR(area(six), 16 + 4 * 4 + 4 * 0.5, 1e-6);
}

TEST(ScadOutline, PolygonPathsAreEvenOdd) {
  const Outline o = outline_of(
      "polygon(points = [[0, 0], [10, 0], [10, 10], [0, 10], [2, 2], [8, 2], [8, 8], [2, 8]], "
      "paths = [[0, 1, 2, 3], [4, 5, 6, 7]]);");
  EXPECT_EQ(o.rings.size(), 2u);
  EXPECT_NEAR(area(o), 64, 1e-6);
}

TEST(ScadOutline, TwoDimensionalHullOfADifference) {
  // The hull of a frame is the full square (the old hand-written 2D code refused this).
  const Outline o = outline_of(
      "hull() { difference() { square(size = [10, 10]); "
      "multmatrix([[1, 0, 0, 2], [0, 1, 0, 2], [0, 0, 1, 0], [0, 0, 0, 1]]) { square(size = [6, 6]); } } }");
  EXPECT_EQ(o.rings.size(), 1u);
  EXPECT_NEAR(area(o), 100, 1e-6);
}

// Liberation Sans, OpenSCAD's default font (fonts-liberation2).
TEST(ScadText, MatchesOpenScadsOutlines) {
  const std::string csg = "text(text = \"PIC 0.1\", size = 10, spacing = 1, font = \"\", direction = \"ltr\", "
                          "language = \"en\", script = \"Latn\", halign = \"left\", valign = \"baseline\", "
                          "$fn = 0, $fa = 12, $fs = 2);";
  const Outline o = outline_of(csg);
  EXPECT_LT(relative(area(o), 114.327960), 0.005);
  // Its extent along x, as OpenSCAD lays the glyphs out: P's left side to 1's right side.
  double lo = 1e300, hi = -1e300;
  for (const auto& r : o.rings)
    for (const auto& p : r) lo = std::min(lo, p[0]), hi = std::max(hi, p[0]);
  EXPECT_NEAR(lo, 1.1393, 1e-3);
  EXPECT_NEAR(hi, 44.7357, 1e-3);
}

// Small text, or text with few fragments, still cuts each curve of a glyph in two: OpenSCAD
// 2021's own exports of text("og", ...) as DXF (90 lines for size 2.1 and for $fn = 3; the
// areas agree to 3e-4 everywhere, as for larger text).
TEST(ScadText, SmallTextKeepsTwoPiecesPerCurve) {
  EXPECT_LT(relative(area(outline_of("text(text = \"og\", size = 2.1);")), 2.251156), 1e-3);
  EXPECT_LT(relative(area(outline_of("text(text = \"og\", size = 2.1, $fn = 7);")), 2.251156), 1e-3);
  EXPECT_LT(relative(area(outline_of("text(text = \"og\", size = 10, $fn = 3);")), 51.047460), 1e-3);
  EXPECT_LT(relative(area(outline_of("text(text = \"og\", size = 5);")), 13.048432), 1e-3);
}

TEST(ScadText, LettersHaveTheirHolesAndParts) {
  detail::scad::TextParams p;
  p.size = 10;
  p.segments = 4;
  p.text = "A";
  const Region a = detail::scad::text_region(p);
  ASSERT_EQ(a.size(), 2u);  // the outline and one hole
  EXPECT_NE(detail::scad::signed_area(a[0]) > 0, detail::scad::signed_area(a[1]) > 0);
  EXPECT_LT(relative(detail::scad::region_area(a), 27.525522), 0.005);
  p.text = "i";
  const Region i = detail::scad::text_region(p);
  ASSERT_EQ(i.size(), 2u);  // the stem and the dot, both filled
  EXPECT_GT(detail::scad::signed_area(i[0]), 0);
  EXPECT_GT(detail::scad::signed_area(i[1]), 0);
  EXPECT_LT(relative(detail::scad::region_area(i), 10.380513), 0.005);
}

// Centred as OpenSCAD centres it: across the line by the outlines' extent measured at the
// advances' scale, so not exactly symmetric (OpenSCAD 2021.01: x -13.9307 .. 14.1720,
// y -4.80434 .. 5.02844).
TEST(ScadText, CentredTextIsPlacedAsOpenScadPlacesIt) {
  detail::scad::TextParams p;
  p.text = "HOH";
  p.segments = 4;
  p.halign = "center";
  p.valign = "center";
  const Region r = detail::scad::text_region(p);
  double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
  for (const Ring& ring : r)
    for (const auto& q : ring)
      for (int a = 0; a < 2; ++a) lo[a] = std::min(lo[a], q[a]), hi[a] = std::max(hi[a], q[a]);
  EXPECT_NEAR(lo[0], -13.9307, 2e-3);
  EXPECT_NEAR(hi[0], 14.1720, 2e-3);
  EXPECT_NEAR(lo[1], -4.80434, 2e-3);
  EXPECT_NEAR(hi[1], 5.02844, 2e-3);
}

// Vertical text placed as OpenSCAD 2021 places it (its DXF exports of "lH" at size 10): each
// glyph centred on the pen line, the pen going down by the font's line height, "top" lifting
// the column above the origin, halign by the widest glyph.
TEST(ScadText, VerticalTextIsPlacedAsOpenScadPlacesIt) {
  struct Case {
    const char* args;
    double x0, x1, y0, y1;
  };
  const Case cases[] = {
      {"direction = \"ttb\"", -3.7582, 3.9995, -23.7558, -1.2151},
      {"direction = \"btt\", spacing = 1.5, valign = \"top\"", -3.7582, 3.9995, 7.8148, 36.7147},
      {"direction = \"ttb\", halign = \"right\", valign = \"center\"", -11.3394, -3.5817, -11.0269, 11.5138},
      {"direction = \"btt\", halign = \"center\", valign = \"bottom\", spacing = 0.8", -7.5488, 0.2089, -21.4616,
       -1.4721},
  };
  for (const Case& c : cases) {
    const Outline o = outline_of(std::string("text(text = \"lH\", size = 10, ") + c.args + ");");
    double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
    for (const auto& r : o.rings)
      for (const auto& q : r)
        for (int a = 0; a < 2; ++a) lo[a] = std::min(lo[a], q[a]), hi[a] = std::max(hi[a], q[a]);
    SCOPED_TRACE(c.args);
    EXPECT_NEAR(lo[0], c.x0, 0.01);
    EXPECT_NEAR(hi[0], c.x1, 0.01);
    EXPECT_NEAR(lo[1], c.y0, 0.01);
    EXPECT_NEAR(hi[1], c.y1, 0.01);
  }
}

// Extruded text (holes, separate parts) is a closed solid of its outline's area times height.
TEST(ScadText, ExtrudedTextIsAValidSolid) {
  EvalOptions o;
  o.depth = 10;
  const Octree t = eval_csg("linear_extrude(height = 2) { text(text = \"Agi\", size = 10); }", o);
  const TriMesh m = contour(t);
  const MeshTopology topo = analyze_topology(m);
  EXPECT_TRUE(topo.closed() && topo.manifold());
  const double a = area(outline_of("text(text = \"Agi\", size = 10);"));
  EXPECT_LT(relative(volume(m), 2 * a), 0.01);
}

// A DXF drawing: a 10 x 10 square of LINEs on layer "a" (one side drawn backwards), a CIRCLE
// hole on layer "a", and on layer "b" a block of one closed LWPOLYLINE inserted twice, once
// rotated a quarter turn.
constexpr const char* kDrawing = R"(0
SECTION
2
BLOCKS
0
BLOCK
2
tri
10
0.0
20
0.0
0
LWPOLYLINE
8
b
90
3
70
1
10
0.0
20
0.0
10
4.0
20
0.0
10
0.0
20
2.0
0
ENDBLK
0
ENDSEC
0
SECTION
2
ENTITIES
0
LINE
8
a
10
0
20
0
11
10
21
0
0
LINE
8
a
10
10
20
0
11
10
21
10
0
LINE
8
a
10
0
20
10
11
10
21
10
0
LINE
8
a
10
0
20
10
11
0
21
0
0
CIRCLE
8
a
10
5
20
5
40
2
0
INSERT
8
0
2
tri
10
20
20
0
0
INSERT
8
0
2
tri
10
40
20
0
50
90
0
ENDSEC
0
EOF
)";

TEST(ScadImport, DxfLayersCirclesAndBlocks) {
  test::TempDir dir("dxf");
  const std::string file = (dir / "d.dxf").string();
  std::ofstream(file) << kDrawing;
  const auto import = [&](const std::string& layer) {
    return outline_of("import(file = \"" + file + "\", layer = \"" + layer + "\", $fn = 64);");
  };
  // The square minus the circle's 64-gon (area (64 / 2) r^2 sin(2 pi / 64)).
  EXPECT_NEAR(area(import("a")), 100 - 32 * 4 * std::sin(2 * std::numbers::pi / 64), 1e-6);
  // Two copies of the block's triangle (area 4); the quarter-turned copy, inserted at x = 40,
  // reaches back to x = 38.
  const Outline b = import("b");
  EXPECT_NEAR(area(b), 8, 1e-6);
  double lo = 1e300;
  for (const auto& r : b.rings)
    if (r[0][0] > 30)  // the rotated copy
      for (const auto& p : r) lo = std::min(lo, p[0]);
  EXPECT_NEAR(lo, 38, 1e-9);
}

TEST(ScadProjection, ShadowAndCutOfABox) {
  // A box tilted about z only: its shadow and its section are the same 10 x 10 square.
  const std::string box =
      "multmatrix([[0.8, -0.6, 0, 0], [0.6, 0.8, 0, 0], [0, 0, 1, -5], [0, 0, 0, 1]]) { cube(size = [10, 10, 10]); }";
  EXPECT_NEAR(area(outline_of("projection(cut = false) { " + box + " }")), 100, 1e-6);
  EXPECT_NEAR(area(outline_of("projection(cut = true) { " + box + " }")), 100, 1e-6);
  // A cut that misses the solid is empty.
  EXPECT_THROW(outline_of("projection(cut = true) { cube(size = [1, 1, 1]); }"), InvalidInput);
  // The shadow of a difference (evaluated on octrees, then projected): a 10 x 10 square with a
  // 4 x 4 hole through it.
  const Outline o = outline_of(
      "projection() { difference() { cube(size = [10, 10, 2]); "
      "multmatrix([[1, 0, 0, 3], [0, 1, 0, 3], [0, 0, 1, -1], [0, 0, 0, 1]]) { cube(size = [4, 4, 4]); } } }");
  EXPECT_NEAR(area(o), 84, 0.5);
}

TEST(ScadMinkowski, SumsOfConvexPartsAndTheirUnions) {
  EvalOptions o;
  o.depth = 8;
  // A box grown by a centred 2-cube: a 12-cube.
  const double box = volume(contour(eval_csg(
      "minkowski() { cube(size = [10, 10, 10]); cube(size = [2, 2, 2], center = true); }", o)));
  EXPECT_NEAR(box, 1728, 1728 * 1e-6);
  // An L of two bars (not convex, a union of convex parts) grown the same way, moved as a whole.
  const double ell = volume(contour(eval_csg(
      "multmatrix([[1, 0, 0, 5], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]) { minkowski() { union() { "
      "cube(size = [10, 2, 2]); cube(size = [2, 10, 2]); } cube(size = [2, 2, 2], center = true); } }",
      o)));
  EXPECT_NEAR(ell, 12 * 4 * 4 + 4 * 12 * 4 - 4 * 4 * 4, 320 * 1e-6);
  // A hull() is one convex part whatever it holds, not its contour's flat pieces (9 hulls
  // here, and thousands, past the limit, for a hull with a faceted ball in it).
  // Two unit cubes offset diagonally hull to a hexagonal prism; plus a unit cube, the hexagon
  // (0,0) (2,0) (3,1) (3,3) (1,3) (0,2), area 8, twice as high: 16.
  EvalStats stats;
  const double prism = volume(contour(eval_csg(
      "minkowski() { hull() { cube(size = [1, 1, 1]); multmatrix([[1, 0, 0, 1], [0, 1, 0, 1], [0, 0, 1, 0], "
      "[0, 0, 0, 1]]) { cube(size = [1, 1, 1]); } } cube(size = [1, 1, 1]); }",
      o, &stats)));
  EXPECT_NEAR(prism, 16, 16 * 1e-6);
  EXPECT_EQ(stats.leaves, 1u);
}

TEST(ScadMinkowski, AnEmptyOperandIsLeftOut) {
  // OpenSCAD leaves an empty child out of minkowski(): an intersection of two cubes apart plus
  // a ball is the ball (OpenSCAD 2021 renders it so), not nothing. Through each path: a
  // faceted sphere with what would be a non-convex operand, and a cube.
  EvalOptions o;
  o.depth = 8;
  const std::string empty = "intersection() { cube(size = [1, 1, 1]); "
                            "multmatrix([[1, 0, 0, 5], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]) { cube(size = [1, 1, 1]); } }";
  const TriMesh ball = contour(eval_csg("minkowski() { " + empty + " sphere(r = 2, $fn = 24); }", o));
  const TriMesh alone = contour(eval_csg("sphere(r = 2, $fn = 24);", o));
  EXPECT_TRUE(test::IsClosedManifold(ball));
  EXPECT_NEAR(volume(ball), volume(alone), 1e-4 * volume(alone));  // sampled in another root cube
  const TriMesh box = contour(eval_csg("minkowski() { " + empty + " cube(size = [2, 3, 4]); }", o));
  EXPECT_NEAR(volume(box), 24, 24 * 1e-6);
}

// A non-convex operand plus a convex one: the operand cut into convex pieces (a difference of
// convex parts, a prism), or moved, with the hull of each flat piece of its surface.
TEST(ScadMinkowski, NonConvexOperandPlusConvexOne) {
  EvalOptions o;
  o.depth = 8;
  // A 4-cube with a 2 x 2 notch along one vertical edge (the cube beyond each side face of the
  // notch: two convex pieces), grown by a centred 2-cube: the L's outline grows by 1 on every
  // side and the notch shrinks to 2 x 2, so 6 x 6 - 2 x 2 in plan, 6 high.
  const TriMesh notch = contour(eval_csg(
      "minkowski() { difference() { cube(size = [4, 4, 4]); cube(size = [2, 2, 9]); } "
      "cube(size = [2, 2, 2], center = true); }",
      o));
  EXPECT_TRUE(test::IsClosedManifold(notch));
  EXPECT_NEAR(volume(notch), (36 - 4) * 6, 192 * 1e-5);
  // A tube (its top and bottom are squares with square holes) grown by the same cube: the
  // hole shrinks from 4 x 4 to 2 x 2 and stays open.
  const TriMesh tube = contour(eval_csg(
      "minkowski() { difference() { cube(size = [10, 10, 10], center = true); "
      "cube(size = [4, 4, 20], center = true); } cube(size = [2, 2, 2], center = true); }",
      o));
  EXPECT_TRUE(test::IsClosedManifold(tube));
  EXPECT_NEAR(volume(tube), 12 * 12 * 12 - 2 * 2 * 12, 1680 * 1e-5);
  // A plate with 6 x 6 square holes decomposes into too many pieces: its contour's flat faces
  // are grouped instead (the top and bottom cut into trapezoids). Grown by the 2-cube, the
  // 4 x 4 holes shrink to 2 x 2: 42 x 42 x 4 less 36 holes of 2 x 2 x 4.
  std::string holes;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j)
      holes += "multmatrix([[1, 0, 0, " + std::to_string(3 + 6 * i) + "], [0, 1, 0, " + std::to_string(3 + 6 * j) +
               "], [0, 0, 1, -1], [0, 0, 0, 1]]) { cube(size = [4, 4, 4]); } ";
  const TriMesh plate = contour(eval_csg(
      "minkowski() { difference() { cube(size = [40, 40, 2]); " + holes + "} cube(size = [2, 2, 2], center = true); }",
      o));
  EXPECT_TRUE(test::IsClosedManifold(plate));
  EXPECT_NEAR(volume(plate), 42 * 42 * 4 - 36 * 16, 6480 * 1e-4);
  // A ball with a corner cut away is the union of the ball beyond each face of the cube: three
  // convex pieces, so the sum is three hulls (volume of OpenSCAD 2021's CGAL render).
  const TriMesh ball = contour(eval_csg(
      "minkowski() { difference() { sphere(r = 10); multmatrix([[1, 0, 0, 5], [0, 1, 0, 5], [0, 0, 1, 5], "
      "[0, 0, 0, 1]]) { cube(size = [10, 10, 10], center = true); } } sphere(r = 1, $fn = 8); }",
      o));
  EXPECT_TRUE(test::IsClosedManifold(ball));
  EXPECT_NEAR(volume(ball) / 4965.831324, 1, 0.005);
  // A ball minus a ball has no few convex pieces and no flat faces to group: it would need
  // tens of thousands of hulls, so it is refused at once with the count.
  try {
    eval_csg("minkowski() { difference() { sphere(r = 10, $fn = 48); sphere(r = 5, $fn = 48); } "
             "sphere(r = 1, $fn = 8); }",
             o);
    FAIL() << "a curved operand was summed";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("planar pieces"), std::string::npos) << e.what();
  }
  // Two notched cubes: each decomposes into convex pieces, so their sum is exact: the L
  // [0,4]x[2,4] u [2,4]x[0,2] plus itself (area 52, as in 2D) times a height of 8.
  const std::string notched = "difference() { cube(size = [4, 4, 4]); cube(size = [2, 2, 9]); }";
  EXPECT_NEAR(volume(contour(eval_csg("minkowski() { " + notched + " " + notched + " }", o))), 52 * 8, 416 * 1e-5);
  // Extruded L polygons are prisms over convex pieces: the same L area 52, 2 + 2 high.
  const std::string ell =
      "linear_extrude(height = 2) { polygon(points = [[0, 0], [4, 0], [4, 4], [2, 4], [2, 2], [0, 2]]); }";
  EXPECT_NEAR(volume(contour(eval_csg("minkowski() { " + ell + " " + ell + " }", o))), 52 * 4, 208 * 1e-5);
  // The same L as one polyhedron with a hexagon cap: a leaf that is not convex, and its caps
  // reach the sum as fans whose triangles partly face back. Plus a unit cube: (L + square)
  // (area 21) times 3; a cap taken as the union of its fan's triangles would fill the notch (66).
  const std::string ell_polyhedron =
      "polyhedron(points = [[0, 0, 0], [4, 0, 0], [4, 4, 0], [2, 4, 0], [2, 2, 0], [0, 2, 0], [0, 0, 2], [4, 0, 2], "
      "[4, 4, 2], [2, 4, 2], [2, 2, 2], [0, 2, 2]], faces = [[5, 4, 3, 2, 1, 0], [6, 7, 8, 9, 10, 11], [0, 1, 7, 6], "
      "[1, 2, 8, 7], [2, 3, 9, 8], [3, 4, 10, 9], [4, 5, 11, 10], [5, 0, 6, 11]]);";
  EXPECT_NEAR(volume(contour(eval_csg("minkowski() { " + ell_polyhedron + " cube(size = [1, 1, 1]); }", o))), 63,
              63 * 1e-5);
  // The polyhedron is a prism whose caps arrive as fans: its pieces are the cap's convex
  // pieces (two boxes here, four hulls), not the general sum of two non-convex solids below.
  EXPECT_NEAR(volume(contour(eval_csg("minkowski() { " + ell_polyhedron + " " + ell_polyhedron + " }", o))), 52 * 4,
              208 * 1e-5);
  // A non-convex leaf that is no prism (the L's top slanted, z = 2 + x / 2) is cut into convex
  // pieces by the plane of a face at its reflex edge: two pieces, four hulls, the same sum as
  // the union of the two pieces written out.
  const auto slanted = [](const std::vector<std::array<double, 2>>& ring) {
    const size_t n = ring.size();
    std::string points, faces = "[";
    for (int top = 0; top < 2; ++top)
      for (const auto& [x, y] : ring)
        points += (points.empty() ? "[" : ", [") + std::to_string(x) + ", " + std::to_string(y) + ", " +
                  std::to_string(top ? 2 + x / 2 : 0) + "]";
    for (size_t k = n; k-- > 0;) faces += std::to_string(k) + (k ? ", " : "], [");
    for (size_t k = 0; k < n; ++k) faces += std::to_string(n + k) + (k + 1 < n ? ", " : "]");
    for (size_t k = 0; k < n; ++k) {
      const size_t j = (k + 1) % n;
      faces += ", [" + std::to_string(k) + ", " + std::to_string(j) + ", " + std::to_string(n + j) + ", " +
               std::to_string(n + k) + "]";
    }
    return "polyhedron(points = [" + points + "], faces = [" + faces + "]);";
  };
  const std::string slanted_ell = slanted({{0, 0}, {4, 0}, {4, 4}, {2, 4}, {2, 2}, {0, 2}});
  const std::string slanted_pieces =
      "union() { " + slanted({{0, 0}, {4, 0}, {4, 2}, {0, 2}}) + " " + slanted({{2, 2}, {4, 2}, {4, 4}, {2, 4}}) + " }";
  EvalStats cut_stats;
  const TriMesh cut = contour(eval_csg("minkowski() { " + slanted_ell + " " + slanted_ell + " }", o, &cut_stats));
  EXPECT_TRUE(test::IsClosedManifold(cut));
  EXPECT_EQ(cut_stats.leaves, 4u);  // the hulls of two pieces plus two, not one per pair of faces
  const double by_pieces = volume(contour(eval_csg("minkowski() { " + slanted_pieces + " " + slanted_pieces + " }", o)));
  EXPECT_NEAR(volume(cut), by_pieces, by_pieces * 1e-4);
  // A 2-cube and a 2 x 3 x 3 box apart as one polyhedron: no reflex edge and no prism, so no
  // convex pieces -- the general sum: each moved by a point of each of the other's shells, and
  // every pair of planar pieces summed (a hull each). The sums are boxes that only touch:
  // 64 + 100 + 144.
  const auto box = [](int first, double x0, double x1, double h, std::string& points, std::string& faces) {
    for (int k = 0; k < 8; ++k)
      points += (points.empty() ? "[" : ", [") + std::to_string(k & 1 ? x1 : x0) + ", " + std::to_string(k & 2 ? h : 0) +
                ", " + std::to_string(k & 4 ? h : 0) + "]";
    for (const auto& q : {std::array{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}})
      faces += std::string(faces.empty() ? "[" : ", [") + std::to_string(first + q[0]) + ", " + std::to_string(first + q[1]) +
               ", " + std::to_string(first + q[2]) + ", " + std::to_string(first + q[3]) + "]";
  };
  std::string points, faces;
  box(0, 0, 2, 2, points, faces);
  box(8, 4, 6, 3, points, faces);
  const std::string two_boxes = "polyhedron(points = [" + points + "], faces = [" + faces + "]);";
  EvalStats general_stats;
  const TriMesh general = contour(eval_csg("minkowski() { " + two_boxes + " " + two_boxes + " }", o, &general_stats));
  EXPECT_TRUE(test::IsClosedManifold(general));
  EXPECT_GT(general_stats.leaves, 50u);  // not the four hulls of the cut L above
  EXPECT_NEAR(volume(general), 64 + 100 + 144, 308 * 1e-5);
  // A slanted U (top z = 2 + x / 2) and a unit cube far off, as one polyhedron: a cell of the
  // U's reflex planes holds both shells, so no convex pieces -- each planar piece of it plus a
  // unit cube. Its caps arrive as fans with triangles facing back and one on a line: each cap
  // is one face through that line (the back-facing triangles alone would fill the notch), and
  // no piece of no width crosses the notch (summed with the cube it would be a solid there).
  // Exact: the U plus the cube, 33 * 2 + 33 + 2 * (11 + 17), and the 2-cube.
  std::string u_points, u_faces;
  size_t u_count = 0;  // points so far
  const auto shell = [&](const std::vector<std::array<double, 2>>& ring, double (*top_at)(double)) {
    const size_t n = ring.size(), first = u_count;
    u_count += 2 * n;
    for (int top = 0; top < 2; ++top)
      for (const auto& [x, y] : ring)
        u_points += (u_points.empty() ? "[" : ", [") + std::to_string(x) + ", " + std::to_string(y) + ", " +
                    std::to_string(top ? top_at(x) : 0) + "]";
    const auto index = [&](size_t k) { return std::to_string(first + k); };
    std::string bottom = "[", cap = "[";
    for (size_t k = 0; k < n; ++k) bottom += index(n - 1 - k) + (k + 1 < n ? ", " : "]");
    for (size_t k = 0; k < n; ++k) cap += index(n + k) + (k + 1 < n ? ", " : "]");
    u_faces += (u_faces.empty() ? "" : ", ") + bottom + ", " + cap;
    for (size_t k = 0; k < n; ++k)
      u_faces += ", [" + index(k) + ", " + index((k + 1) % n) + ", " + index(n + (k + 1) % n) + ", " + index(n + k) + "]";
  };
  const std::vector<std::array<double, 2>> u_ring{{0, 0}, {6, 0}, {6, 4}, {4, 4}, {4, 2}, {2, 2}, {2, 4}, {0, 4}};
  shell(u_ring, [](double x) { return 2 + x / 2; });
  shell({{20, 0}, {21, 0}, {21, 1}, {20, 1}}, [](double) { return 1.0; });
  EvalStats u_stats;
  const TriMesh u_sum = contour(eval_csg("minkowski() { polyhedron(points = [" + u_points + "], faces = [" + u_faces +
                                             "]); cube(size = [1, 1, 1]); }",
                                         o, &u_stats));
  EXPECT_TRUE(test::IsClosedManifold(u_sum));
  EXPECT_GT(u_stats.leaves, 10u);  // the planar pieces, not convex ones
  EXPECT_NEAR(volume(u_sum), 155 + 8, 163 * 2e-3);
  // The U with a flat top is a prism: the convex pieces of its cap, which Clipper's union of the
  // fan leaves as two rings touching along a diagonal -- no strip of no width between them may
  // become a piece. (U + square) 33 times 3 high.
  u_points.clear(), u_faces.clear(), u_count = 0;
  shell(u_ring, [](double) { return 2.0; });
  const TriMesh u_prism = contour(eval_csg("minkowski() { polyhedron(points = [" + u_points + "], faces = [" +
                                               u_faces + "]); cube(size = [1, 1, 1]); }",
                                           o));
  EXPECT_NEAR(volume(u_prism), 99, 99 * 1e-5);
  // Two twisted extrusions: 66 planar pieces each (every side triangle its own), 4,356 hulls
  // -- refused at once with the count.
  const std::string twisted = "linear_extrude(height = 2, twist = 90, slices = 8) { square(size = [2, 2]); }";
  try {
    eval_csg("minkowski() { " + twisted + " " + twisted + " }", o);
    FAIL() << "4,356 hulls were summed";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("convex hulls"), std::string::npos) << e.what();
  }
}

// A ball minus a corner cube plus an octahedral ball: three hulls that share faces, united
// at depth 12. The Booleans resample coarse leaves from the operands' partial contours, where a
// corner's parity-walk sign may have no crossing inside to explain it; such a cell must not
// split (its child grid would give its faces' points signs its neighbours do not share, and the
// contour would have boundary edges).
TEST(ScadMinkowski, HullsSharingFacesUniteIntoOneValidSolid) {
  EvalOptions o;
  o.depth = 12;
  const Octree t = eval_csg(
      "minkowski() { difference() { sphere($fn = 0, $fa = 12, $fs = 2, r = 10); "
      "multmatrix([[1, 0, 0, 5], [0, 1, 0, 5], [0, 0, 1, 5], [0, 0, 0, 1]]) { cube(size = [10, 10, 10], center = true); } } "
      "sphere($fn = 8, $fa = 12, $fs = 2, r = 1); }",
      o);
  EXPECT_NO_THROW(detail::check_octree(t, "minkowski"));
  const TriMesh m = contour(t);
  const MeshTopology topo = analyze_topology(m);
  EXPECT_TRUE(topo.closed()) << topo.boundary_edges << " boundary edges";
  EXPECT_TRUE(topo.manifold());
}

// Rounded text, the idiom that used to be refused: an extruded glyph with a hole plus a ball.
// Closed, one part, and the volume of OpenSCAD 2021's CGAL render of the same model
// (`openscad -o ref.stl`, Liberation Sans).
constexpr double kRoundedPVolume = 140.1232047;
TEST(ScadMinkowski, RoundedText) {
  EvalOptions o;
  o.depth = 8;
  const TriMesh m = contour(eval_csg("minkowski() { linear_extrude(height = 2) { text(text = \"P\", size = 10); } "
                                     "sphere(r = 0.5, $fn = 8); }",
                                     o));
  EXPECT_TRUE(test::IsClosedManifold(m));
  EXPECT_EQ(test::component_count(m), 1u);
  EXPECT_NEAR(volume(m) / kRoundedPVolume, 1, 0.005);
}

// hull() of extruded text: thousands of points on two planes. The hull tested "sees" with a
// tolerance; points almost on several faces' planes saw sets of faces that were not disks, and
// the face list grew until memory ran out. Exact orientation tests keep it a convex polytope.
TEST(ScadHull, ExtrudedTextIsHulled) {
  EvalOptions o;
  o.depth = 8;
  const TriMesh m = contour(eval_csg("hull() { linear_extrude(height = 2) { text(text = \"PIC 0.1 hello\", size = 10); } }", o));
  EXPECT_TRUE(analyze_topology(m).manifold());
  EXPECT_NEAR(volume(m), 1490.4007, 1490.4007 * 5e-3);  // OpenSCAD 2021's render
}

// surface(): heights from a text matrix, and from a PNG's luminance (OpenSCAD 2021.01's export
// of the same 3 x 2 image has these heights: white 100, green 71.52, red 21.26, ...).
TEST(ScadSurface, HeightMapsFromTextAndImages) {
  test::TempDir dir("surface");
  std::ofstream(dir / "h.dat") << "# two rows\n1 2 3\n4 5 6\n";
  // Cells of mean height 3 and 4 over a bottom at min - 1 = 0.
  const TriMesh dat = detail::scad::surface_mesh(dir / "h.dat", false, false);
  EXPECT_TRUE(analyze_topology(dat).manifold());
  EXPECT_NEAR(volume(dat), 7, 1e-12);
  Image img;
  img.width = 3;
  img.height = 2;
  img.rgb = {255, 255, 255, 0, 0, 0, 255, 0, 0, 0, 255, 0, 0, 0, 255, 128, 128, 128};
  write_png(img, dir / "h.png");
  const TriMesh png = detail::scad::surface_mesh(dir / "h.png", false, false);
  EXPECT_TRUE(analyze_topology(png).manifold());
  const auto height_at = [&](double x, double y) {
    for (const Vec3& p : png.positions)
      if (p[0] == x && p[1] == y && p[2] > -1) return p[2];
    return -1e300;
  };
  EXPECT_NEAR(height_at(0, 1), 100, 1e-9);    // the image's top row is at y = 1
  EXPECT_NEAR(height_at(2, 1), 21.26, 1e-9);  // red
  EXPECT_NEAR(height_at(0, 0), 71.52, 1e-9);  // green
  EXPECT_NEAR(height_at(2, 0), 100.0 * 128 / 255, 1e-9);
  EXPECT_THROW(detail::scad::surface_mesh(dir / "missing.dat", false, false), IoError);
}

TEST(ScadResize, ToTheGivenSizeOrProportionally) {
  // A 2 x 3 x 5 box made 10 x 10 x 4 where it stands, then moved.
  EvalOptions o;
  o.depth = 8;
  const TriMesh box = contour(eval_csg(
      "multmatrix([[1, 0, 0, 30], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]) { "
      "resize(newsize = [10, 10, 4], auto = [0, 0, 0]) { cube(size = [2, 3, 5]); } }",
      o));
  EXPECT_NEAR(volume(box), 400, 400 * 1e-6);
  // A circle of radius 3 (a 30-gon) to width 10, its height following: area scales by (10/6)^2.
  const double circle = area(outline_of("circle(r = 3, $fn = 30);"));
  EXPECT_NEAR(area(outline_of("resize(newsize = [10, 0], auto = true) { circle(r = 3, $fn = 30); }")),
              circle * 100 / 36, 1e-6);
  // An axis left at 0 takes the factor of the axis given the largest new size, not the
  // largest factor: a 1 x 1 x 4 box to x 2, z 3 has y scaled by 3 / 4 (OpenSCAD: volume 4.5).
  const TriMesh auto_sized =
      contour(eval_csg("resize(newsize = [2, 0, 3], auto = true) { cube(size = [1, 1, 4]); }", o));
  EXPECT_NEAR(volume(auto_sized), 4.5, 4.5 * 1e-6);
}

// Malformed drawings are one clear error; a drawing with nothing closed in the layer is empty.
TEST(ScadImport, MalformedDxfIsAnError) {
  test::TempDir dir("baddxf");
  const auto import = [&](const std::string& bytes) {
    std::ofstream(dir / "x.dxf", std::ios::binary) << bytes;
    return detail::scad::read_dxf(dir / "x.dxf", {});
  };
  EXPECT_THROW(import("0\nSECTION\n2\nENTITIES\n0\nLINE\n10\nabc\n"), InvalidInput);
  EXPECT_THROW(import(std::string("\x00\xff\x13garbage\n\x01\n", 14)), InvalidInput);
  EXPECT_TRUE(import("0\nSECTION\n2\nENTITIES\n0\nLINE\n10\n0\n20\n0\n11\n1\n21\n0\n").empty());
  EXPECT_THROW(detail::scad::read_dxf(dir / "missing.dxf", {}), IoError);
}

// SVG: px at 72 dpi (OpenSCAD 2021's default), y flipped about the document's height, each
// shape filled by the even-odd rule; mm documents through their viewBox.
TEST(ScadImport, SvgShapesUnitsAndTransforms) {
  test::TempDir dir("svg");
  const std::string px = (dir / "px.svg").string(), mm = (dir / "mm.svg").string();
  std::ofstream(px) << "<?xml version=\"1.0\"?>\n<!-- test -->\n"
                       "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"100\" height=\"50\" viewBox=\"0 0 100 50\">"
                       "<defs><rect width=\"999\" height=\"999\"/></defs>"
                       "<rect x=\"10\" y=\"5\" width=\"20\" height=\"10\"/>"
                       "<path d=\"M 50 10 L 70 10 L 60 30 z\"/></svg>";
  const double u = 25.4 / 72;
  const Outline a = outline_of("import(file = \"" + px + "\");");
  EXPECT_NEAR(area(a), (200 + 200) * u * u, 1e-6);  // to Clipper's grid
  double lo = 1e300, hi = -1e300;
  for (const auto& r : a.rings)
    for (const auto& p : r) lo = std::min(lo, p[1]), hi = std::max(hi, p[1]);
  EXPECT_NEAR(lo, (50 - 30) * u, 1e-6);  // the triangle's tip, y = 30 from the top
  EXPECT_NEAR(hi, (50 - 5) * u, 1e-6);   // the rectangle's top edge
  // A 40 x 20 mm document of 160 x 80 user units: a path with an inner square (a hole by the
  // even-odd rule, though drawn the same way round), in a translated group.
  std::ofstream(mm) << "<svg width=\"40mm\" height=\"20mm\" viewBox=\"0 0 160 80\"><g transform=\"translate(10 5)\">"
                       "<path d=\"M0,0 h40 v40 h-40 z M10,10 h10 v10 h-10 z\"/></g></svg>";
  EXPECT_NEAR(area(outline_of("import(file = \"" + mm + "\");")), (1600 - 100) / 16.0, 1e-6);
  std::ofstream(dir / "bad.svg") << "<svg><path d=\"M 0 0 L 1 q\"/></svg>";
  EXPECT_THROW(outline_of("import(file = \"" + (dir / "bad.svg").string() + "\");"), InvalidInput);
}

// SVG paths with cubic and quadratic Beziers (smooth and relative forms too), elliptical arcs
// (turned, large, scaled up to reach), circles and ellipses, against OpenSCAD 2021.01's area of
// the same import (its SVG export, by the shoelace formula). Its import cuts a Bezier into 20
// pieces and a circle into 40 and an arc by the angle it turns, whatever $fn, $fa and $fs say:
// three settings, one answer.
TEST(ScadImport, SvgCurvesAndArcsAsOpenScadFlattensThem) {
  const std::pair<const char*, double> drawings[] = {
      {"svg_curves_beziers.svg", 4087.39067723},
      {"svg_curves_relative.svg", 5352.617729325},
      {"svg_curves_arcs.svg", 2180.680598478499},
  };
  for (const auto& [name, openscad_area] : drawings)
    for (const char* settings : {"$fn = 0, $fa = 12, $fs = 2", "$fn = 12, $fa = 12, $fs = 2", "$fn = 0, $fa = 2, $fs = 0.2"}) {
      const std::string file = std::string(PIC_SCAD_DATA_DIR) + "/" + name;
      const Outline o = outline_of("import(file = \"" + file + "\", " + settings + ");");
      EXPECT_LT(relative(area(o), openscad_area), 1e-5) << name << " with " << settings;
    }
}

// The 2D rounded rectangle: a 10 x 4 rectangle plus a 16-gon of radius 1 (vertices at 0, 22.5,
// ... degrees: 2 wide and 2 high) is the rectangle, a 1-wide strip along each side and the
// 16-gon's area at the corners; moved once by the translation.
TEST(ScadMinkowski, TwoDimensionalRoundedRectangle) {
  const double gon = 8 * std::sin(2 * std::numbers::pi / 16);  // (16 / 2) r^2 sin(2 pi / 16)
  const Outline o = outline_of(
      "multmatrix([[1, 0, 0, 50], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]) { minkowski() { "
      "square(size = [10, 4]); circle(r = 1, $fn = 16); } }");
  EXPECT_NEAR(area(o), 40 + 2 * 10 + 2 * 4 + gon, 1e-6);
  double lo = 1e300;
  for (const auto& r : o.rings)
    for (const auto& p : r) lo = std::min(lo, p[0]);
  EXPECT_NEAR(lo, 49, 1e-6);
  // An L made of two bars (a union of convex parts, not convex) grown by a 1-square centred
  // on the origin: bars of 7 x 3 and 3 x 7 overlapping in a 3 x 3 square.
  EXPECT_NEAR(area(outline_of("minkowski() { union() { square(size = [5, 1]); square(size = [1, 5]); } "
                              "square(size = [2, 2], center = true); }")),
              21 + 21 - 9, 1e-6);
  // Non-convex operands are cut into convex pieces. A 4-square with a 2 x 2 notch (an L) grown
  // by a centred 2-square: 6 x 6 less a 2 x 2 notch.
  const std::string ell = "difference() { square(size = [4, 4]); square(size = [2, 2]); }";
  EXPECT_NEAR(area(outline_of("minkowski() { " + ell + " square(size = [2, 2], center = true); }")), 36 - 4, 1e-6);
  // A frame (a ring with a hole) grown the same way: 12 x 12 with a 2 x 2 hole left.
  EXPECT_NEAR(area(outline_of("minkowski() { difference() { square(size = [10, 10], center = true); "
                              "square(size = [4, 4], center = true); } square(size = [2, 2], center = true); }")),
              144 - 4, 1e-6);
  // Two L's: [0,4]x[2,4] u [2,4]x[0,2] summed with itself is [0,8]x[4,8] u [2,8]x[2,6] u
  // [4,8]x[0,4], 32 + 12 + 8.
  EXPECT_NEAR(area(outline_of("minkowski() { " + ell + " " + ell + " }")), 52, 1e-6);
}

// A notched pentagon plus a square turned 45 degrees: the sum's outline has 11 vertices (as
// OpenSCAD's own output has), none where the sums of the convex pieces (cut at the notch's
// heights) meet along a straight side -- a twisted extrusion splits each side quad, and such a
// vertex took 4 % off its volume.
TEST(ScadMinkowski, TwoDimensionalSumHasOnlyItsOwnVertices) {
  const Outline o = outline_of(
      "minkowski() { polygon(points = [[0, 0], [2.54, 0], [2.06, 2.31], [1, 1], [0, 2.2]]); "
      "circle(r = 0.24, $fn = 4); }");
  ASSERT_EQ(o.rings.size(), 1u);
  EXPECT_EQ(o.rings[0].size(), 11u);
  // The exact sum's area: its vertices are the pentagon's moved by the square's, but at the
  // notch, where the side (1.82, 2.31)-(0.76, 1) meets (1.24, 1)-(0.24, 2.2) at t = 2.006 /
  // 2.582 along the first (OpenSCAD's 6.30564 carries its fixed-point grid).
  const double t = 2.006 / 2.582;
  const Ring exact{{-0.24, 0}, {0, -0.24}, {2.54, -0.24}, {2.78, 0}, {2.30, 2.31}, {2.06, 2.55}, {1.82, 2.31},
                   {1.82 - 1.06 * t, 2.31 - 1.31 * t}, {0.24, 2.2}, {0, 2.44}, {-0.24, 2.2}};
  double expected = 0;
  for (size_t i = 0; i < exact.size(); ++i) {
    const auto& a = exact[i];
    const auto& b = exact[(i + 1) % exact.size()];
    expected += (a[0] * b[1] - b[0] * a[1]) / 2;
  }
  EXPECT_NEAR(area(o), expected, 1e-7);
}

TEST(ScadModel, BackgroundAndDisabledObjectsAreLeftOut) {
  EvalOptions o;
  o.depth = 7;
  const Octree t = eval_csg("cube(size = [1, 1, 1]); %cube(size = [5, 5, 5]); *sphere(r = 9);", o);
  EXPECT_NEAR(volume(contour(t)), 1, 1e-3);
}

TEST(ScadModel, TwoDimensionalModelsAreOutlinesNotSolids) {
  EXPECT_THROW(eval_csg("square(size = [2, 2]);"), InvalidInput);
  test::TempDir dir;
  std::ofstream(dir / "cube.csg") << "cube(size = [1, 1, 1]);";
  EXPECT_FALSE(eval_outline(dir / "cube.csg").has_value());
  // SVG and DXF outputs, written and re-read as text.
  const Outline o = outline_of("square(size = [2, 3]);");
  write_outline(o, dir / "out.svg");
  write_outline(o, dir / "out.dxf");
  std::ifstream svg(dir / "out.svg"), dxf(dir / "out.dxf");
  const std::string s((std::istreambuf_iterator<char>(svg)), {}), d((std::istreambuf_iterator<char>(dxf)), {});
  EXPECT_NE(s.find("<path"), std::string::npos);
  EXPECT_NE(d.find("LWPOLYLINE"), std::string::npos);
  EXPECT_THROW(write_outline(o, dir / "out.stl"), InvalidInput);
}

// The shadow of OpenSCAD's GEB (three extruded letters intersected), from above: the "B" with
// its two holes. The union of the contour's ~21,000 upward triangles leaves hundreds of
// pinholes a grid step wide, among which Clipper can label a hole (the lower one, area 8.56)
// an outer ring; read by its orientation, that hole is filled.
TEST(ScadProjection, ShadowKeepsEveryHole) {
  const std::optional<Outline> o = eval_outline(std::string(PIC_SCAD_DATA_DIR) + "/geb_projection.csg");
  ASSERT_TRUE(o.has_value());
  EXPECT_EQ(o->rings.size(), 3u);
  EXPECT_LT(relative(area(*o), 58.169378), 1e-3);  // OpenSCAD 2021's DXF of the same projection
}

}  // namespace
}  // namespace pic

// Internals of the OpenSCAD evaluator: the parsed .csg tree, OpenSCAD's tessellation rules,
// extrusions and convex hulls. One stage per file: parse.cpp, tessellate.cpp, hull.cpp, eval.cpp.
#pragma once

#include <array>
#include <map>
#include <string>
#include <vector>

#include "geometry/convex_hull.h"
#include "pic/types.h"

namespace pic::detail::scad {

/// OpenSCAD's GRID_FINE (2^-20): radii below it get the fewest fragments or slices.
inline constexpr double kGridFine = 0.00000095367431640625;

/// A literal of the .csg format: number, boolean, string, vector or undef.
struct Value {
  enum class Kind { Undef, Number, Bool, String, Vector };
  Kind kind = Kind::Undef;
  double number = 0;
  bool boolean = false;
  std::string text;
  std::vector<Value> items;
};

/// `name(key = value, ...) { children }`; positional arguments get keys "0", "1", ...
struct Node {
  std::string name;
  std::map<std::string, Value> args;
  std::vector<Node> children;
  int line = 0;
};

/// Parses .csg text into its top-level statements. \throws InvalidInput "line N: ...".
std::vector<Node> parse(const std::string& text);

using P2 = std::array<double, 2>;
using Ring = std::vector<P2>;

/// OpenSCAD's Calc::get_fragments_from_r: $fn if set (at least 3), else from $fa and $fs.
int fragments_from_r(double r, double fn, double fs, double fa);
/// The cosine of an angle in degrees as OpenSCAD takes it: exact at multiples of 30 and 45
/// degrees (cos 30 is sqrt(3) / 2 rounded, one unit in the last place below the cosine of
/// the rounded radian angle), which decides knife-edge counts such as the arc steps of an
/// offset with $fn = 6.
double cos_degrees(double deg);
/// Regular polygon with `n` vertices at angles 360 i / n (OpenSCAD's circle placement).
Ring circle_ring(double r, int n);
/// OpenSCAD's sphere: (n + 1) / 2 rings at polar angles 180 (i + 0.5) / rings, n points each.
TriMesh sphere_mesh(double r, int n);
/// OpenSCAD's cylinder/cone along z from z1 to z2; a zero radius closes with an apex.
TriMesh cylinder_mesh(double r1, double r2, double z1, double z2, int n);

/// Signed area (positive counter-clockwise).
double signed_area(const Ring& ring);
/// Triangulates a simple counter-clockwise polygon (ear clipping); indices into `ring`.
std::vector<std::array<uint32_t, 3>> triangulate(const Ring& ring);

struct LinearExtrude {
  double height = 1, twist = 0;
  int slices = 1;
  P2 scale{1, 1};
  bool center = false;
};
/// Extrudes one simple ring (any orientation) as OpenSCAD does: slice j rotated by
/// -twist j / slices degrees, then scaled by 1 + (scale - 1) j / slices; each twisted wall
/// quad split along its shorter diagonal, as OpenSCAD does. Empty mesh for a degenerate ring.
TriMesh extrude_linear(Ring ring, const LinearExtrude& e);
/// Revolves one simple ring of the x >= 0 half plane about z through `angle` degrees in
/// `fragments` steps, with OpenSCAD's vertex placement (a full turn starts on the -x axis).
TriMesh extrude_rotate(Ring ring, double angle, int fragments);

/// Convex hull of 2D points, counter-clockwise, no collinear vertices.
Ring convex_hull_2d(std::vector<P2> points);

}  // namespace pic::detail::scad

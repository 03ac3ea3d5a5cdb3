// Lowering an OpenSCAD CSG tree: the parsed .csg tree becomes a tree of Booleans over closed
// meshes in world coordinates (transforms pushed into the leaves; 2D subtrees under an
// extrusion become extruded leaves combined with the same Booleans, since extrusion commutes
// with them). evaluate.cpp then samples the leaves and runs the Booleans on octrees.
#pragma once

#include <algorithm>
#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "pic/scad.h"
#include "scad/scad_detail.h"
#include "geometry/tolerances.h"

namespace pic::detail::scad {

/// The lowered tree: Booleans over closed meshes (3D) ...
struct Solid {
  /// RoundSum: the Minkowski sum of its one child with a round convex body (`body`: its
  /// vertices), sampled as a distance (pic::minkowski_round).
  enum class Kind { Empty, Mesh, Union, Intersect, Difference, Hull, RoundSum };
  Kind kind = Kind::Empty;
  TriMesh mesh;
  std::vector<Solid> children;
  std::vector<Vec3> body;
};

/// Lowers `root`. `finest_cell` > 0 tessellates spheres, cylinders and circles against it
/// (EvalOptions::smooth); 0 follows $fn/$fa/$fs. `nodes` (optional) gets the number of nodes.
/// \throws InvalidInput for an unsupported node or bad arguments (naming the node's line).
Solid lower(const Node& root, const EvalOptions& options, double finest_cell, size_t* nodes);

/// The bounding box of points: {lo, hi}.
inline std::array<Vec3, 2> box_of(const std::vector<Vec3>& pts) {
  std::array<Vec3, 2> b{Vec3{kHuge, kHuge, kHuge}, Vec3{-kHuge, -kHuge, -kHuge}};
  for (const Vec3& p : pts)
    for (int k = 0; k < 3; ++k) b[0][k] = std::min(b[0][k], p[k]), b[1][k] = std::max(b[1][k], p[k]);
  return b;
}
/// Whether two boxes {lo, hi} have no point in common.
inline bool boxes_apart(const std::array<Vec3, 2>& a, const std::array<Vec3, 2>& b) {
  for (int k = 0; k < 3; ++k)
    if (a[1][k] < b[0][k] || b[1][k] < a[0][k]) return true;
  return false;
}

/// Grows [lo, hi] by the leaves' vertices; counts the leaves and their triangles.
void solid_bounds(const Solid& s, Vec3& lo, Vec3& hi, size_t& leaves, size_t& triangles);
/// The root cube to evaluate `model` in: around where its result can lie when that cube is at
/// most half the one around all its leaves, the leaves reaching out of it cut to it; else
/// around all the leaves (a hull, a sum or a leaf that is not convex reaching out) (root_cube.cpp).
Cube root_cube(Solid& model);
/// The surface of a lowered 3D subtree: a leaf's own mesh, else its Booleans evaluated on
/// octrees (options.depth, in the subtree's own cube) and contoured (evaluate.cpp).
TriMesh solid_surface(const Solid& s, const EvalOptions& options);
/// projection(): the shadow of a closed surface on z = 0 (union of its triangles' shadows), or,
/// with `cut`, its section by that plane (projection.cpp).
std::vector<Ring> project(const TriMesh& surface, bool cut);
/// minkowski(): each operand as convex parts where it decomposes (hulls, differences and
/// intersections of convex parts, prisms, polyhedra cut at their reflex edges) and the union of
/// the hulls of the parts' vertex sums; a non-convex part that does not decompose is summed by
/// its moved copies and the hulls of its planar pieces (minkowski.cpp, docs/openscad.md).
/// \throws InvalidInput past the count of hulls it takes on.
/// A non-convex operand plus a round one (a faceted sphere) is a RoundSum instead, unless
/// `exact_only`.
Solid minkowski(const std::vector<Solid>& operands, const EvalOptions& options, bool exact_only = false);

/// Whether a closed surface bounds a convex solid: connected, positive volume, convex at
/// every edge (hull.cpp).
bool is_convex(const TriMesh& m);
/// hull() input: the vertices of the leaves, when the subtree is only unions (and hulls) of
/// them; false otherwise (hull.cpp).
bool hull_points(const Solid& s, std::vector<Vec3>& out);
/// A plane n.x = d, n unit and outward.
struct Plane {
  Vec3 n;
  double d;
};
/// The distinct planes of a convex hull's faces.
std::vector<Plane> face_planes(const TriMesh& hull);
/// The part of a convex polytope (its hull) on the side n.x >= d (`outside`) or n.x <= d: its
/// vertices there and its edges' crossings. Empty when it does not reach past the plane by
/// more than eps.
std::vector<Vec3> clip_convex(const TriMesh& hull, const Plane& p, bool outside, double eps);

/// surface(): the solid under a height map, a .dat text matrix or a PNG (surface.cpp).
/// \throws IoError when unreadable, InvalidInput when malformed.
TriMesh surface_mesh(const std::filesystem::path& path, bool center, bool invert);

/// 2 when the tree's objects are 2D (a 2D model), 3 when 3D, 0 when it has none.
int dimension(const Node& n);
/// Lowers a 2D model to its region. \throws as lower().
std::vector<Ring> lower_2d(const Node& root, const EvalOptions& options, size_t* nodes);

}  // namespace pic::detail::scad

namespace pic {
/// eval_outline() on .csg text: nullopt when the model is not 2D (evaluate.cpp).
std::optional<Outline> eval_csg_outline(const std::string& text, const EvalOptions& options, EvalStats* stats,
                                        const std::string& source);
}  // namespace pic

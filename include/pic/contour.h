// PIC — dual contouring of a PIC object into a closed triangle mesh.
#pragma once

#include <cstddef>
#include <functional>

#include "pic/octree.h"

namespace pic {

/// The simplification the CLI's Boolean and OpenSCAD outputs use, in finest cells: the raw
/// contour's vertices lie up to a few tenths of a cell off the creases they stand for, and
/// merged vertices go onto the planes' point, so half a cell writes fewer triangles than a
/// quarter (a median 1.5× fewer over OpenSCAD's examples) about as near the exact surface
/// (docs/algorithms.md).
inline constexpr double kCompactSimplify = 0.5;

/// Options for contouring.
struct ContourOptions {
  /// Triangulate the dual polygons so that no two triangles cross, by construction: each
  /// polygon keeps dual contouring's two-triangle split where that split provably stays in a
  /// region no other polygon's triangles enter, else it becomes a fan around a point of its
  /// minimal edge (sides split at a point of their cells' common face where needed), after
  /// Ju & Udeshi 2006. No vertex moves, no search. false: always the plain split (slivers may
  /// fold through each other).
  bool intersection_free = true;
  /// Give each sheet its own copies of the vertices where the contour touches itself
  /// (split_nonmanifold), so the mesh is 2-manifold. false: the dual contouring mesh as is.
  bool split_sheets = true;
  /// Every polygon a fan (for comparison: about 2.4 times the triangles). Overrides
  /// intersection_free.
  bool fan_all = false;
  /// Merge the contour's vertices where the surface is flat or runs straight along a crease,
  /// staying within this many finest cells of the raw contour (simplify());
  /// 0: the raw contour, a vertex per gray leaf. kCompactSimplify is what `pic eval` and
  /// `pic csg` write.
  double simplify = 0;
  /// The sampled solid's function, when known (input coordinates, < 0 inside: the function a
  /// volume operation or pic::sample of an ImplicitSolid sampled): the points the contour adds
  /// on cell edges go where it changes sign there, on the surface, instead of where the edge
  /// meets the surface the vertices around it span.
  std::function<double(const Vec3&)> surface;
};
struct ContourStats {
  size_t fans = 0;            ///< polygons triangulated as a fan around a point on their edge
  size_t other_diagonal = 0;  ///< quads split along the other diagonal to stay in their region
  size_t face_points = 0;     ///< polygon sides split at a point of their cells' common face
  size_t face_fans = 0;       ///< polygons with face points, fanned from a point of their own ring
  size_t split_vertices = 0;  ///< vertex copies added by split_sheets
  size_t simplified_away = 0; ///< triangles removed by simplify
  // Kept for readers of `pic mesh --json`: the construction moves no vertex and leaves no
  // crossing to resolve, so these stay 0.
  size_t moved_vertices = 0;
  size_t initial_intersections = 0;
  size_t remaining_intersections = 0;
  int rounds = 0;
};
/// Extracts the closed surface by dual contouring, in the input's coordinates: what `pic mesh`
/// writes (intersection-free, sheets split apart where they touch).
TriMesh contour(const Octree& tree, const ContourOptions& options = {}, ContourStats* stats = nullptr);
/// The contour before its sheets are split apart (dual contouring may leave edges and vertices
/// where the surface touches itself): for resampling a surface, and for looking at it.
inline TriMesh unsplit_contour(const Octree& tree) {
  ContourOptions o;
  o.split_sheets = false;
  return contour(tree, o);
}

/// Makes a closed mesh 2-manifold where it touches itself: an edge with four or more
/// triangles (sheets meeting along a line) or a vertex whose triangles form several fans
/// (sheets meeting at a point) gets one copy of its vertices per sheet; the copies coincide.
/// Around such an edge, triangles are paired so that each pair bounds one wedge of the solid
/// (solids that touch stay apart), or else one wedge of the outside, whichever makes the whole
/// mesh manifold. Dual contouring leaves these spots where a feature is finer than a coarse
/// neighbouring cell (see docs/algorithms.md). Zero-volume pockets (two opposite triangles on
/// the same vertices) are dropped. Returns how many vertices were added; a mesh that is
/// already manifold, or that neither pairing repairs, is left unchanged (and 0 returned).
/// The copies are then moved apart, each a hair (1/1024 to 1/16 of the way to its ring's mean)
/// into its own sheet, where the exact test finds no crossing: a reader that merges equal
/// positions would otherwise see the pinch again.
size_t split_nonmanifold(TriMesh& mesh);

/// Collapses edges of a closed 2-manifold mesh, both ends moving to the point nearest their
/// planes, while every original vertex stays within `tolerance` of the result and the new
/// vertex and triangles' centroids within `tolerance` of the original: flat regions become a
/// few large triangles, straight creases keep their line, curved parts stay within tolerance. Each collapse keeps the mesh closed and
/// 2-manifold (the link condition) and its triangles' orientation and shape; a result with a
/// crossing is not taken. Returns the triangles removed.
size_t simplify(TriMesh& mesh, double tolerance);

}  // namespace pic

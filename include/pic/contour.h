// PIC — dual contouring of a PIC object into a closed triangle mesh.
#pragma once

#include <cstddef>

#include "pic/octree.h"

namespace pic {

/// Options for contouring.
struct ContourOptions {
  /// Triangulate the dual polygons so that no two triangles cross: polygons with a triangle in
  /// an exactly intersecting pair take the other diagonal or a fan of 3-4 triangles around a
  /// new vertex inside their minimal edge (after Ju & Udeshi 2006), whichever the exact test
  /// finds clean. false: always the plain split (today's `--fast`: a few percent fewer
  /// triangles and faster, but slivers may fold through each other).
  bool intersection_free = true;
  /// Give each sheet its own copies of the vertices where the contour touches itself
  /// (split_nonmanifold), so the mesh is 2-manifold. false: the dual contouring mesh as is.
  bool split_sheets = true;
  /// Experimental: every polygon a fan around a point of its minimal edge, sides split at a
  /// point of their cells' common face where needed (intersection-free by construction, no
  /// search; about twice the triangles). Overrides intersection_free.
  bool fan_all = false;
};
struct ContourStats {
  size_t fans = 0;            ///< polygons triangulated as a fan around a point on their edge
  size_t other_diagonal = 0;  ///< quads split along the diagonal that folds less
  size_t moved_vertices = 0;  ///< vertices pulled toward their cell centre to undo a crossing
  size_t initial_intersections = 0;    ///< exact self-intersecting pairs of the plain split
  size_t remaining_intersections = 0;  ///< after re-triangulation (0 unless it could not resolve)
  int rounds = 0;                      ///< re-triangulation rounds
  size_t split_vertices = 0;           ///< vertex copies added by split_sheets
};
/// Extracts the closed surface by dual contouring, in the input's coordinates: what `pic mesh`
/// writes (intersection-free, sheets split apart where they touch).
TriMesh contour(const Octree& tree, const ContourOptions& options = {}, ContourStats* stats = nullptr);
/// The contour before its sheets are split apart (dual contouring may leave edges and vertices
/// where the surface touches itself): for resampling a surface, and for looking at it.
inline TriMesh unsplit_contour(const Octree& tree) { return contour(tree, {true, false}); }

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

}  // namespace pic

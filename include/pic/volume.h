// PIC — operations only a volume does well: offsets, shells, rounds and thickened surfaces,
// each sampled from a signed distance (pic::ImplicitSolid) with the paper's rules, so faces and
// the creases the exact result keeps stay sharp and the output is a PIC object like any other.
#pragma once

#include "pic/contour.h"
#include "pic/octree.h"
#include "pic/sample.h"

namespace pic {

/// A volume operation's mesh, when asked for (the last argument of each operation): its
/// contour with the points the contour adds on cell edges placed where the operation's own
/// function changes sign there (ContourOptions::surface), so every vertex lies on the exact
/// surface within the sampling's error -- which contour(tree) alone cannot know.
struct VolumeMesh {
  ContourOptions options;  ///< in: how to contour (`surface` is set by the operation)
  TriMesh mesh;            ///< out
  ContourStats stats;      ///< out
  double seconds = 0;      ///< out: the contouring's share of the operation's time
};

/// The solid grown by `distance` (> 0) or shrunk by -distance (< 0): the points whose signed
/// distance to the solid's surface is below `distance`. A mesh that is not a clean, closed,
/// consistently oriented surface is sampled first (any input sample() takes) and its contour
/// used; a PIC object through its contour. `options.cube` defaults to the solid's bounding
/// cube grown to hold the offset.
/// `stats`: the implicit sampling's (for a round, its second offset's).
/// \throws InvalidInput for non-finite values; EmptySolid when shrinking leaves nothing.
Octree offset(const TriMesh& solid, double distance, const SampleOptions& options = {},
              SampleStats* stats = nullptr, VolumeMesh* mesh = nullptr);
Octree offset(const Octree& solid, double distance, const SampleOptions& options = {},
              SampleStats* stats = nullptr, VolumeMesh* mesh = nullptr);

/// The Minkowski sum of a solid with a round convex body given by its vertices (a faceted
/// sphere: every vertex within 2 % of one radius from their centroid c): the
/// points whose distance to the solid, seen along the direction u from the nearest point, is
/// below the body's support h(u) = max over vertices v of (v - c).u -- then moved by c. Exact
/// on the solid's faces (each moves out by the body's support along its normal, as in the
/// exact sum) and on its concave creases; where it rounds convex edges and corners, within
/// the body's facet depth (r - its inradius) of the exact sum.
/// Throws InvalidInput for fewer than 4 points, or a body that is not round.
Octree minkowski_round(const TriMesh& solid, const std::vector<Vec3>& round_body, const SampleOptions& options = {},
                       SampleStats* stats = nullptr, VolumeMesh* mesh = nullptr);
/// Whether minkowski_round takes these points: every one within 2 % of one radius from their
/// centroid, and none of the body's facets deeper than 2 % of it.
bool is_round_body(const std::vector<Vec3>& points);

/// The solid hollowed to walls `thickness` thick (the solid minus its inward offset), or with
/// `outward` a skin of that thickness around it (its outward offset minus the solid).
Octree shell(const TriMesh& solid, double thickness, bool outward = false, const SampleOptions& options = {},
             SampleStats* stats = nullptr, VolumeMesh* mesh = nullptr);

/// Rounded edges: with `convex` the convex edges get radius `radius` (an opening: shrink, then
/// grow back), else the concave ones are filled to it (a closing: grow, then shrink back).
Octree round_edges(const TriMesh& solid, double radius, bool convex = true, const SampleOptions& options = {},
                   SampleStats* stats = nullptr, VolumeMesh* mesh = nullptr);

/// The solid within thickness / 2 of a surface, open or closed (a sheet, a drawing's
/// triangles, a scan with holes): the answer for inputs with no inside of their own.
Octree thicken(const TriMesh& surface, double thickness, const SampleOptions& options = {},
               SampleStats* stats = nullptr, VolumeMesh* mesh = nullptr);

}  // namespace pic

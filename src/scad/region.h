// 2D regions as OpenSCAD 2021 computes them: polygon sets through Clipper 6.4, the library
// OpenSCAD links, in fixed point (region.cpp).
#pragma once

#include <vector>

#include "scad/scad_detail.h"

namespace pic::detail::scad {

/// A 2D region: rings that do not cross, outer boundaries counter-clockwise and holes
/// clockwise (Clipper's output); filled where the winding number is non-zero.
using Region = std::vector<Ring>;

/// The rings filled by the even-odd rule (a `polygon` with `paths`: inner paths are holes).
Region region_even_odd(const std::vector<Ring>& rings);
/// Union, intersection of all, or the first minus the rest.
Region region_union(const std::vector<Region>& parts);
Region region_intersection(const std::vector<Region>& parts);
Region region_difference(const std::vector<Region>& parts);

/// OpenSCAD's offset(): by r with round joins (arcs within `arc_tolerance`), or by delta with
/// mitred joins, or square-cut ones with `chamfer`. Negative amounts shrink.
enum class OffsetJoin { kRound, kMiter, kChamfer };
Region region_offset(const Region& region, double amount, OffsetJoin join, double arc_tolerance);

/// Rings from line segments chained where their ends meet (within `tol`); a chain that does
/// not close is closed by its last point joining its first, as OpenSCAD imports such paths.
using Segment = std::array<P2, 2>;
std::vector<Ring> rings_from_segments(const std::vector<Segment>& segs, double tol);

/// Area (holes subtracted).
double region_area(const Region& region);
/// The largest |x| or |y| of the region's points: the scale its tolerances are taken in.
double region_extent(const Region& region);

/// Whether a counter-clockwise ring turns left (or goes straight) at every vertex.
bool convex_ring(const Ring& ring);
/// The rings without vertices within `tol` of the line through their neighbours.
Region without_straight_vertices(Region region, double tol);
/// The region cut into convex pieces (counter-clockwise rings) that cover it exactly:
/// trapezoids between consecutive heights of its vertices, stacked while convex.
std::vector<Ring> convex_pieces(const Region& region);

}  // namespace pic::detail::scad

// Every tolerance, guard and stand-in limit of the library, named by the geometric quantity it
// bounds. Equal values with different meanings have different names; changing one must not
// change the others.
#pragma once

namespace pic::detail {

// ---- Limits and guards ---------------------------------------------------------------------

/// A stand-in for infinity: larger than any coordinate, distance or squared distance we meet
/// (the start of a min/max search, an empty box's corners), yet finite, so 0 * it stays 0.
inline constexpr double kHuge = 1e300;
/// A divisor at or below this is taken as zero (a point on a segment's line, a ray parallel to
/// a slab, a point set of one point): far below any length, far above where 1/x overflows.
inline constexpr double kTinyDivisor = 1e-300;

// ---- geometry/ -----------------------------------------------------------------------------

/// Rounding of a winding number's exact sums and running bound is far below this, so a
/// margin past bound + this decides the side for certain.
inline constexpr double kWindingRounding = 1e-9;
/// A triangle's solid-angle determinant below this, relative to the product of its vertices'
/// distances, is rounding noise: the point is in the triangle's plane.
inline constexpr double kInPlaneDet = 1e-10;
/// A running complex product of angles below this in size is rescaled before it underflows.
inline constexpr double kAngleRenormalize = 1e-100;
/// Distances to a triangle's plane below this (root-cube units) are snapped onto the plane: a
/// vertex on it computes to rounding noise, far below the 2^-32 grid step.
inline constexpr double kPlaneSnap = 1e-13;
/// Relative rounding of the double products in the lattice's box-edge tests; the margin adds
/// one grid step on top.
inline constexpr double kProductRounding = 1e-12;
/// Relative eigenvalue cutoff of the QEF's pseudo-inverse. Singular values of A^(1/2) below 0.1
/// of the largest are dropped, as in Ju et al. 2002 (dual contouring).
inline constexpr double kRelativeCutoff = 1e-2;
/// The damping of the QEF's sharp solve (relative to the largest eigenvalue; Qef::Pinv::Damped).
/// Two planes a few degrees apart (a faceted sphere's crease, 12° in OpenSCAD's default) have
/// a weakest eigenvalue near or below kRelativeCutoff, so the truncated solve takes their
/// crease for a plane and puts the vertex off it; the sharp one solves every direction well
/// above this.
inline constexpr double kSharpDamping = 1e-6;
/// The sharp solve's vertex is taken where the planes meet in it: its residual below this
/// fraction of δ² (a quarter of δ as a distance). A compromise between features fits on average
/// within δ² and can cut a corner by more than a finest cell (a hull's corner where facets
/// meet at a few degrees, other facets beside it in the cell); such cells split.
inline constexpr double kSharpFit = 1.0 / 16;

// ---- octree/ -------------------------------------------------------------------------------

/// How far (in cell sizes) a vertex may lie outside its cell and still count as inside: the
/// rounding of a QEF solve.
inline constexpr double kInsideCellSlack = 1e-9;
/// How much more than the QEF's minimum a tip corner's error may be, in cell sizes squared.
inline constexpr double kTipTolerance = 1e-12;

/// A feature thinner than a capped cell is kept when the faces an edge crosses it through turn
/// by more than about 162 degrees (their normals' cosine below minus this): a wall, or a wedge
/// under 18 degrees, which dropped would be cut back by three cells or more.
inline constexpr double kThinFeatureTurn = 0.95;

// ---- contour/ ------------------------------------------------------------------------------

/// Two cells whose gap along an axis is below this (relative to their half sizes) touch along
/// that axis: the rounding of their centres.
inline constexpr double kTouchingCellsGap = 1e-9;
/// A ring's heights must lie this far (relative to the edge's length) strictly inside the
/// edge's span, so rounding cannot put a triangle on the edge's end.
inline constexpr double kRingHeightMargin = 1e-9;
/// Simplification keeps a triangle it turns only when its normal stays within about 25
/// degrees of where it was (the cosine): a fan that folds over its neighbours never passes.
inline constexpr double kKeptNormalCosine = 0.9;
/// Simplification makes no triangle worse than this (4 sqrt(3) area over the sum of squared
/// sides: 1 equilateral, 0 flat) unless the ones it replaces were: about as thin as an exact
/// kernel's facets of a twisted extrusion (Manifold's of OpenSCAD's linear_extrude example:
/// 0.033 and more, median 0.064). Thinner needles shade badly and, rounded to floats, cross
/// their neighbours more easily (the float writers check for that).
inline constexpr double kMinTriangleQuality = 0.03;

// ---- sample/ -------------------------------------------------------------------------------

/// The sampler's default QEF residual threshold delta^2 (as SampleOptions::error).
inline constexpr double kDefaultQefError = 1e-8;
/// A level-set value below this on an edge is its root: the search stops there.
inline constexpr double kLevelRootValue = 1e-9;
// Winding-number decisions stop refining once the far field's truncation bound is below these
// (docs/algorithms.md): a cap's level set may move to where w is within the tolerance of 1/2.
// A point cloud's w is itself an estimate (Barill et al. 2018): its decisions take the
// far-field sum as it is.
inline constexpr double kCapTolerance = 0.05;
inline constexpr double kPointTolerance = 1e300;
/// How far (unit cube) to either side of a triangle its winding numbers are compared to tell
/// an interior triangle: far above the grid step, far below any feature.
inline constexpr double kInteriorProbe = 1e-6;

// ---- csg/ ----------------------------------------------------------------------------------

/// Crossings of the two operands this close (unit cube) bound no sliver of the result where
/// the result does not change across the pair: coplanar faces of the two operands (a cutter
/// flush with a face) come through their stored float vertices up to a few float steps of the
/// unit cube apart, and would otherwise count as two crossings and refine the whole shared
/// face's rim to the depth cap. A sliver this thin is far below a finest cell.
inline constexpr double kCoincident = 0x1p-22;
/// Two operands' surfaces within this fraction of a cell are one surface.
inline constexpr double kCoincidentRelative = 1e-6;

// ---- csg/ and scad/ ------------------------------------------------------------------------

/// Unit vectors whose |cosine| is within this of 1 are parallel (one plane's two sides, one
/// direction counted once): rounding of normals from float vertices.
inline constexpr double kParallelCosine = 1e-9;

// ---- scad/ ---------------------------------------------------------------------------------

/// Adjacent faces whose normals' cosine is within this of 1 are one flat face of a prism.
inline constexpr double kFlatNeighbourCosine = 1e-8;
/// A point this close to a face's plane, as a fraction of the solid's extent, is on it (convex
/// tests and the clipping of convex pieces).
inline constexpr double kOnPlane = 1e-9;
/// A root of a function along a cell edge is found to this fraction of the edge, in at most
/// kEdgeRootSteps values.
inline constexpr double kEdgeRoot = 1e-6;
inline constexpr int kEdgeRootSteps = 40;
/// False position keeps its next value this fraction of the bracket off the bracket's ends.
inline constexpr double kBracketInset = 1e-3;
/// Central differences of a function step this fraction of the cell's side ...
inline constexpr double kGradientStep = 1e-3;
/// ... and, within a face, this fraction of the face's side, where a point moved onto a
/// function's zero stops when |f| is below the same fraction of the side.
inline constexpr double kFaceStep = 1e-4;
/// A face point Newton left farther off the level than this fraction of its face (stalled
/// at the face's border) is found by bisection towards a corner of the other sign.
inline constexpr double kFaceStall = 1e-2;
/// The search of a nearest triangle bounded by a hint's distance allows it this relative slack.
inline constexpr double kHintSlack = 1e-12;
/// A bound on |f| carried from a leaf's corners to a point inside it is lowered by this fraction
/// of the cell: f's values are rounded.
inline constexpr double kCornerBoundSlack = 1e-9;
/// A value bounded inside (or outside) a tolerance decides a test without asking f only with
/// this fraction of the tolerance to spare: the value f would give is rounded.
inline constexpr double kBoundMargin = 1e-9;
/// A point nearer a mesh than this fraction of the mesh's size is on it: the direction to its
/// nearest point is rounding noise there, so the nearest face's normal stands for the gradient.
inline constexpr double kOnSurface = 1e-10;
/// Two planes of a hull are one when their normals' cosine is within this of 1 ...
inline constexpr double kSamePlaneCosine = 1e-12;
/// ... and their offsets agree to this, relative to the offset (plus one).
inline constexpr double kSamePlaneOffset = 1e-12;
/// A prism's volume must match its cap's area times its height to this fraction.
inline constexpr double kPrismVolume = 1e-6;
/// Convex pieces of a polyhedron (hulls in the cells of its reflex edges' planes) are taken
/// when their volumes add up to the solid's within this fraction: a hull over two parts of a
/// cell fills the gap between them and adds that gap. Pieces of a non-convex face come
/// through Clipper's integer grid (about 1e-8 of the extent), which this must allow; a gap
/// thinner than that lies far below the finest cell of any depth.
inline constexpr double kPieceVolume = 1e-7;
/// Float contour vertices on a flat face sit within ~1e-7 of a cell of its plane: this
/// fraction of the extent.
inline constexpr double kFlatFaceTolerance = 1e-6;
/// A 2D ring is convex when its hull's area exceeds its own by at most this fraction.
inline constexpr double kConvexArea = 1e-9;
/// A 2D point nearer than this times the region's extent to a line or a ring lies on it
/// (Clipper's grid is about 1e-9 of the extent): a vertex left on a Minkowski sum's straight
/// side, a vertex where two rings touch.
inline constexpr double kStraightVertex = 1e-8;
/// The smallest arc tolerance of a 2D offset, so a zero request cannot ask for endless arcs.
inline constexpr double kMinArcTolerance = 1e-9;
/// OpenSCAD's miter limit for delta is effectively unbounded (sharp corners stay sharp).
inline constexpr double kUnboundedMiter = 1e6;
/// Cross products below this, relative to the ring's extent squared, are collinear points.
inline constexpr double kCollinearCross = 1e-12;
/// DXF segment ends this close (relative to the drawing's extent) meet.
inline constexpr double kDxfJoin = 1e-9;

// ---- render/ -------------------------------------------------------------------------------

/// An up vector whose cross product with the unit view direction is shorter than this is
/// parallel to it: no camera frame.
inline constexpr double kParallelUp = 1e-12;
/// The perspective near plane, as a fraction of the scene's radius.
inline constexpr double kNearPlane = 1e-4;
/// The smallest projected extent (in units of the view, or of the radius) a flat or
/// single-point object is zoomed to, so the zoom stays finite.
inline constexpr double kMinViewExtent = 1e-3;
/// Screen triangles with twice the area (in pixels squared) below this are dropped as edge-on.
inline constexpr double kDegenerateScreenArea = 1e-12;
/// Barycentric coordinates down to minus this still cover the pixel: closes cracks between
/// triangles sharing an edge.
inline constexpr double kRasterEdgeSlack = 1e-9;

}  // namespace pic::detail

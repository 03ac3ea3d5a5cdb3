// PIC — adaptive sampling of a mesh or a point cloud into a PIC object (paper section 4).
#pragma once

#include <cstddef>
#include <cstdint>
#include <array>
#include <functional>
#include <optional>
#include <string>

#include "pic/octree.h"

namespace pic {

/// How sample() tells inside from outside.
enum class InsideMode {
  Auto,     ///< Parity for a clean closed mesh (see MeshDefects::clean), Winding otherwise
  Parity,   ///< exact crossing parity: closed meshes only (an open one is refused)
  Winding,  ///< generalized winding number |w| >= 1/2: any triangle soup (docs/algorithms.md)
};
std::string to_string(InsideMode mode);
/// Parses "auto", "parity", "winding".
std::optional<InsideMode> parse_inside_mode(const std::string& s);

/// Defects of a triangle mesh, counted after exact welding of equal positions.
struct MeshDefects {
  size_t boundary_edges = 0;      ///< edges with one triangle
  size_t nonmanifold_edges = 0;   ///< edges with more than two triangles
  size_t inconsistent_edges = 0;  ///< edges whose two triangles traverse them the same way
  size_t duplicated_faces = 0;    ///< extra copies of a triangle, in either orientation
  size_t degenerate_faces = 0;    ///< triangles with a repeated vertex
  size_t shells = 0;              ///< edge-connected components
  bool overlapping_shells = false;  ///< the bounding boxes of two shells overlap
  /// The domain of exact crossing parity: closed, every edge on exactly two triangles, no
  /// duplicates, shells apart. (Orientation does not matter to parity.)
  bool clean() const {
    return boundary_edges == 0 && nonmanifold_edges == 0 && duplicated_faces == 0 && !overlapping_shells;
  }
};
MeshDefects find_defects(const TriMesh& mesh);

/// Options for sampling a triangle mesh or a point cloud (paper section 4).
struct SampleOptions {
  int depth = 12;          ///< maximum octree level, 1..kMaxLevel
  double error = 1e-8;     ///< QEF residual threshold delta^2, in root-cube units squared
  std::optional<Cube> cube;  ///< root cube; default: bounding cube plus a margin
  double margin = 1.0 / 16;  ///< automatic cube: margin on each side, relative to the extent
  bool parallel = true;      ///< build subtrees with TBB (output identical to serial)
  InsideMode inside = InsideMode::Auto;  ///< meshes only; point clouds use their winding number
};

/// Statistics of a sampling run.
struct SampleStats {
  int max_depth = 0;    ///< the option's maximum level
  double error = 0;     ///< the option's QEF threshold
  size_t triangles_in = 0;
  size_t points_in = 0;  ///< point clouds: input points
  size_t pics = 0;
  size_t capped = 0;  ///< leaves accepted at the depth cap although a refinement rule failed
  double seconds = 0;
  std::string classifier;   ///< "parity", "winding", "points" or "implicit"
  MeshDefects defects;      ///< of the input mesh (meshes only)
  size_t interior_triangles = 0;  ///< winding: triangles with the solid on both sides (dropped)
  size_t boundary_loops = 0;      ///< winding: closed curves of the input's boundary, capped
  int depth = 0;  ///< deepest level allowed: the option's, or for a point cloud its spacing's
  size_t evaluations = 0;  ///< implicit solids: how many times f (or its gradient) was asked
};

/// Adaptively samples a triangle mesh into a PIC object. A clean closed mesh is classified by
/// exact crossing parity; any other (holes, non-manifold edges, flipped or duplicated triangles,
/// overlapping shells, unwelded soups) by its generalized winding number, after welding,
/// removing duplicates and orienting each edge-connected part by its majority (InsideMode).
/// \throws InvalidInput for an empty mesh, non-finite coordinates, bad options, a mesh that
///         does not fit strictly inside the given cube, an open mesh with InsideMode::Parity,
///         or a mesh that encloses no solid (its winding number never reaches 1/2).
Octree sample(const TriMesh& mesh, const SampleOptions& options = {}, SampleStats* stats = nullptr);
/// Samples an oriented point cloud: signs from the points' winding number (each point a small
/// disc of the area its neighbours leave it), vertices from their tangent planes. The depth
/// stops where a cell is half the points' spacing (SampleStats::depth says where).
/// \throws InvalidInput for an empty cloud, missing or zero normals, non-finite values.
Octree sample(const PointCloud& cloud, const SampleOptions& options = {}, SampleStats* stats = nullptr);

/// A solid given by a function of space: f(p) < 0 inside, f(p) >= 0 outside (world
/// coordinates), with |f(p) - f(q)| <= lipschitz |p - q| (1 for a signed distance).
struct ImplicitSolid {
  std::function<double(const Vec3&)> value;
  /// f's gradient (pointing out of the solid); empty: central differences of `value`.
  std::function<Vec3(const Vec3&)> gradient;
  /// f and its gradient from one evaluation (optional; a distance's nearest point gives both):
  /// edge crossings are then found by Newton steps, about two evaluations per edge (not used
  /// when `values` is given: a batched f's crossings are found by false position, in step).
  std::function<double(const Vec3&, Vec3&)> value_gradient;
  /// f at many points at once (optional, and then `value` is not needed): the sampler asks
  /// each level's questions in batches -- a vectorised function (numpy) is called a few dozen
  /// times per level instead of once per point.
  std::function<void(const std::vector<Vec3>& points, std::vector<double>& values)> values;
  /// The gradients at many points at once (optional).
  std::function<void(const std::vector<Vec3>& points, std::vector<Vec3>& gradients)> gradients;
  double lipschitz = 1;
  /// Whether |f| is about the distance to the surface {f = 0} (a signed distance grown, shrunk
  /// or shelled; a sum with a round body, along the direction it is measured in): a leaf's
  /// octants are then also asked whether the surface lies nearer than the leaf's planes, |f|
  /// taken at slope 1 -- which a function whose |f| falls short of the distance (most
  /// functions) would claim everywhere.
  bool distance = false;
  /// When f = s - offset for a signed distance s to a surface (|s| the distance to it: an
  /// offset of a mesh), that offset (optional). The distance to any set at a mean of points is
  /// bounded from below by theirs (the parallelogram law: for weights w_k summing to 1 and
  /// c = sum w_k x_k, d(c)^2 >= sum w_k d(x_k)^2 - sum w_k |x_k - c|^2), a bound far tighter
  /// than the Lipschitz one where the surface is far from the cell, which decides many of the
  /// sampler's checks without asking f.
  std::optional<double> offset;
  /// With `offset` (both optional): f at p (the same value as `value`) and an opaque site there
  /// (the surface's feature nearest p), and from a site an upper bound on |s| anywhere (the
  /// distance to that feature),
  /// far cheaper than f. With the lower bound above they decide most of the checks of the
  /// polygons between points asked.
  std::function<double(const Vec3&, uint32_t& site)> value_site;
  std::function<double(const Vec3&, uint32_t site)> site_distance;
  /// Whether f keeps one sign over the whole box [lo, hi] (world units), proven (optional;
  /// false when unsure). Asked, in place of f at the centre, of each cell whose corners agree
  /// and that no corner's value proves clear: it must prove at least what |f(centre)| beyond
  /// the half-diagonal times `lipschitz` does. Near the surface a distance proves more (it
  /// knows where its surface lies), so the cells beside a coarse leaf stay coarse.
  std::function<bool(const Vec3& lo, const Vec3& hi)> clear;
  /// Where the surface may bend inside the box [lo, hi] (world units) by more than the sampling
  /// tolerance across it (optional): for each such bend, its point nearest a cell's vertex and
  /// the normal there. An offset rounds a sharp edge, and the crossings of a coarse cell's
  /// edges can all miss the round (they land on the flat parts beside it, whose planes then
  /// meet in a sharp corner). A cell above the cap whose vertex lies farther than the tolerance
  /// from the tangent plane at such a point that f puts on the surface is split. Called from
  /// several threads at once.
  std::function<void(const Vec3& lo, const Vec3& hi, const Vec3& vertex, std::vector<std::array<Vec3, 2>>& bends)>
      bends;
  /// Points at or beside the surface's own features (optional, world units): for an offset of
  /// a mesh, each vertex, edge middle and face centre of the mesh moved along its normal by the
  /// offset. Each is moved onto f's zero by Newton steps, and a leaf above the cap it lands in
  /// must have a polygon within the sampling tolerance of it, else that leaf is split: a dent
  /// or a bump smaller than a coarse leaf, between all the points the sampler asks, is drawn.
  std::function<void(std::vector<Vec3>& points)> features;
};
/// Samples an implicit solid in `options.cube` (required) with the paper's rules: corner signs
/// from f (0 counts as outside), edge crossings by root finding, Hermite normals from the
/// gradient, refinement where the QEF residual exceeds the error; a cell that f's bound keeps
/// away from the surface (|f| beyond its reach from the cell's centre or a corner) is never
/// subdivided.
/// Throws InvalidInput without a cube or a function; EmptySolid when the solid is empty in the
/// cube (or fills it).
Octree sample(const ImplicitSolid& solid, const SampleOptions& options, SampleStats* stats = nullptr);

/// The automatic root cube for a mesh: bounding cube enlarged by `margin` of the extent.
Cube bounding_cube(const TriMesh& mesh, double margin = 1.0 / 16);

}  // namespace pic

// PIC — Points with Implicit Connectivity.
//
// A PIC object is an adaptive octree over a root cube. Leaves are white (outside), black
// (inside) or gray; a gray leaf holds one representative vertex and the in/out signs of its
// eight corners. The surface is recovered by dual contouring (SurfaceNets) of the octree.
// Reference: Zhang, Qu, Kaufman, "CSG Operations on Point Models with Implicit Connectivity".
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <iosfwd>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace pic {

using Vec3 = std::array<double, 3>;

/// @name Errors thrown at the library boundary.
///@{
/// Bad user input: a malformed mesh, an open mesh, NaN coordinates, bad options.
class InvalidInput : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};
/// A file could not be read or written, or a .pic file is corrupted / foreign.
class IoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};
///@}

/// Indexed triangle mesh, counter-clockwise triangles seen from outside.
struct TriMesh {
  std::vector<Vec3> positions;
  std::vector<std::array<uint32_t, 3>> triangles;
};

/// An oriented point cloud (a scan): one normal per point, pointing out of the solid.
struct PointCloud {
  std::vector<Vec3> positions;
  std::vector<Vec3> normals;  ///< same length as positions (need not be unit length)
};

/// The root cube: minimum corner and side length, in the input's own coordinates.
struct Cube {
  Vec3 origin{0, 0, 0};
  double size = 1.0;
  friend bool operator==(const Cube&, const Cube&) = default;
};

/// Deepest level any octree may reach (lattice of 2^kMaxLevel points per axis).
inline constexpr int kMaxLevel = 20;

enum class CellKind : uint8_t { White = 0, Black = 1, Gray = 2, Internal = 3 };

/// One octree node: 8 bytes. Children of an internal node are stored contiguously.
struct Node {
  uint32_t index = 0;  ///< Internal: first child. Gray: index into Octree::vertices.
  CellKind kind = CellKind::White;
  uint8_t signs = 0;   ///< Gray: bit c set = corner c inside; corner c = (c&1, c>>1&1, c>>2&1).
  uint8_t flags = 0;   ///< bit 0: leaf accepted only because the depth cap was reached.
  uint8_t reserved = 0;
};
inline constexpr uint8_t kFlagCapped = 1;

/// A PIC object. Plain data: nodes[0] is the root; vertices are stored in cell-local
/// coordinates in [0,1]^3 (so float keeps ~1e-7 of the *cell* size at every level).
struct Octree {
  Cube cube;
  int max_depth = 12;
  std::vector<Node> nodes{Node{}};
  std::vector<std::array<float, 3>> vertices;
  /// CSG timestamps per node (paper 5.2.1). Not part of the value: never saved.
  mutable std::vector<uint32_t> stamps;
};

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
  size_t triangles_in = 0;
  size_t pics = 0;
  size_t capped = 0;  ///< leaves accepted at the depth cap although a refinement rule failed
  double seconds = 0;
  std::string classifier;   ///< "parity", "winding" or "points"
  MeshDefects defects;      ///< of the input mesh (meshes only)
  size_t interior_triangles = 0;  ///< winding: triangles with the solid on both sides (dropped)
  size_t boundary_loops = 0;      ///< winding: closed curves of the input's boundary, capped
  int depth = 0;  ///< deepest level allowed: the option's, or for a point cloud its spacing's
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

/// The automatic root cube for a mesh: bounding cube enlarged by `margin` of the extent.
Cube bounding_cube(const TriMesh& mesh, double margin = 1.0 / 16);

/// Extracts the closed surface by dual contouring, in the input's coordinates.
TriMesh contour(const Octree& tree);

/// Options for contouring.
struct ContourOptions {
  /// Triangulate the dual polygons so that no two triangles cross: polygons with a triangle in
  /// an exactly intersecting pair take the other diagonal or a fan of 3-4 triangles around a
  /// new vertex inside their minimal edge (after Ju & Udeshi 2006), whichever the exact test
  /// finds clean. false: always the plain split (today's `--fast`: a few percent fewer
  /// triangles and faster, but slivers may fold through each other).
  bool intersection_free = true;
};
struct ContourStats {
  size_t fans = 0;            ///< polygons triangulated as a fan around a point on their edge
  size_t other_diagonal = 0;  ///< quads split along the diagonal that folds less
  size_t moved_vertices = 0;  ///< vertices pulled toward their cell centre to undo a crossing
  size_t initial_intersections = 0;    ///< exact self-intersecting pairs of the plain split
  size_t remaining_intersections = 0;  ///< after re-triangulation (0 unless it could not resolve)
  int rounds = 0;                      ///< re-triangulation rounds
};
TriMesh contour(const Octree& tree, const ContourOptions& options, ContourStats* stats = nullptr);

enum class CsgOp { Union, Intersect, Subtract };
std::string to_string(CsgOp op);
/// Parses "union", "intersect"/"intersection", "subtract"/"difference".
std::optional<CsgOp> parse_csg_op(const std::string& s);

struct CsgOptions {
  double error = 1e-8;  ///< QEF residual threshold for new vertices
  bool parallel = true; ///< combine subtrees near the root with TBB (output identical to serial)
};

struct CsgStats {
  double seconds = 0;
  double contour_a_seconds = 0;  ///< partial contour of A
  double contour_b_seconds = 0;  ///< partial contour of B
  double csg_seconds = 0;        ///< the octree recursion itself, clean-up included
  double cleanup_seconds = 0;    ///< of which: islands, one component per leaf, cracks
  size_t cells_visited = 0;      ///< cell pairs visited by the recursion
  size_t cells_stamped = 0;      ///< operand cells stamped as overlap
  size_t gray_pairs = 0;         ///< gray/gray evaluations (GraycellCSG)
  size_t forced_subdivisions = 0;
  size_t repaired = 0;           ///< uniform leaves turned gray to keep the surface closed
  uint32_t stamp = 0;            ///< this operation's timestamp
  bool resampled_b = false;      ///< B was re-expressed in A's cube
};

/// Boolean of two PIC objects computed on the octrees (paper section 5). Operands should
/// share a root cube; if they do not, B is resampled from its contour into A's cube, or,
/// when B does not fit there, both are resampled into the cube around both cubes. Depths may
/// differ (the result takes the larger). The result is closed; see docs/algorithms.md.
/// \throws InvalidInput when an operand cannot be resampled.
Octree csg(const Octree& a, const Octree& b, CsgOp op, const CsgOptions& options = {},
           CsgStats* stats = nullptr);

/// The same Boolean written into `a` (A := A op B). Only the overlap region is rebuilt;
/// untouched subtrees stay where they are, so a sculpting stroke costs what it touches.
void csg_inplace(Octree& a, const Octree& b, CsgOp op, const CsgOptions& options = {},
                 CsgStats* stats = nullptr);

/// @name The .pic file (docs/pic-format.md).
///@{
/// Writes atomically (temp file + rename). \throws IoError.
void save(const Octree& tree, const std::filesystem::path& path);
/// \throws IoError for a missing, truncated, corrupted or foreign file.
Octree load(const std::filesystem::path& path);
std::vector<uint8_t> serialize(const Octree& tree);
Octree deserialize(const std::vector<uint8_t>& bytes);
///@}

/// What a geometry file holds: a triangle mesh, or (PLY with vertices and no faces, or .xyz
/// text "x y z nx ny nz" per line) an oriented point cloud. Exactly one of the two is filled.
struct Geometry {
  TriMesh mesh;
  PointCloud points;
  bool is_point_cloud() const { return mesh.triangles.empty() && !points.positions.empty(); }
};
/// Reads a mesh file or a point cloud file. A point cloud without normals is InvalidInput
/// ("normals are needed"). \throws IoError, InvalidInput as read_mesh.
Geometry read_geometry(const std::filesystem::path& path);

/// @name Mesh files: OBJ, STL, PLY, OFF, glTF/GLB (assimp), duplicate vertices welded.
///@{
/// \throws IoError (missing/unreadable/unknown format) or InvalidInput (empty, non-finite).
TriMesh read_mesh(const std::filesystem::path& path);
/// Format from the extension; atomic write. \throws IoError.
void write_mesh(const TriMesh& mesh, const std::filesystem::path& path);
///@}

/// Writes a text file atomically (temp file + rename). \throws IoError.
void write_text(const std::filesystem::path& path, const std::string& text);

/// Topology of a triangle mesh (exact vertex indices; no position merging).
struct MeshTopology {
  size_t vertices = 0, triangles = 0;
  size_t boundary_edges = 0;       ///< edges with one triangle
  size_t nonmanifold_edges = 0;    ///< edges with more than two triangles
  size_t inconsistent_edges = 0;   ///< edges whose two triangles disagree on orientation
  size_t nonmanifold_vertices = 0; ///< vertices whose triangle fan is not a single disk
  size_t degenerate_triangles = 0; ///< repeated vertex index
  bool closed() const { return boundary_edges == 0; }
  bool manifold() const {
    return closed() && nonmanifold_edges == 0 && nonmanifold_vertices == 0 && inconsistent_edges == 0;
  }
};
MeshTopology analyze_topology(const TriMesh& mesh);

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
/// @name Validity of a mesh as a solid's boundary (src/self_intersect.cpp).
/// Vertices at bit-identical positions count as one vertex (as a mesh file reader sees them).
///@{
/// Pairs of triangles that intersect other than in a shared vertex or edge, with CGAL's rules
/// (Polygon_mesh_processing::self_intersections): triangles sharing an edge count only when
/// coplanar and folded onto the same side; sharing a vertex, only when the edge opposite it in
/// one meets the other. Exact predicates on the doubles as given. Zero-area triangles are
/// skipped. Each pair (i < j) once, sorted.
std::vector<std::pair<uint32_t, uint32_t>> self_intersecting_pairs(const TriMesh& mesh);
size_t count_self_intersections(const TriMesh& mesh);
struct MeshValidity {
  bool checked = false;             ///< self_intersections was computed
  size_t self_intersections = 0;    ///< as count_self_intersections
  size_t collinear_triangles = 0;   ///< zero-area triangles (skipped by the test)
  size_t nonmanifold_vertices = 0;  ///< after merging equal positions
  size_t nonmanifold_edges = 0;
  size_t boundary_edges = 0;
  size_t degenerate_triangles = 0;  ///< a repeated vertex after merging
  size_t components = 0;            ///< triangles connected across shared edges
  bool valid() const {
    return checked && self_intersections == 0 && nonmanifold_vertices == 0 && nonmanifold_edges == 0 &&
           boundary_edges == 0 && degenerate_triangles == 0 && collinear_triangles == 0;
  }
};
/// Topology after merging equal positions, and (unless `self_intersections` is false) the
/// exact self-intersection count.
MeshValidity check_validity(const TriMesh& mesh, bool self_intersections = true);
///@}
/// Signed volume (positive for outward orientation).
double volume(const TriMesh& mesh);

/// A leaf as seen by visitors: its cell in the input's coordinates.
struct LeafView {
  uint32_t node = 0;
  int level = 0;
  Vec3 cell_min{0, 0, 0};  ///< input coordinates
  double cell_size = 0;    ///< input units
  CellKind kind = CellKind::White;
  uint8_t signs = 0;
  Vec3 vertex{0, 0, 0};    ///< gray leaves: representative vertex, input coordinates
};
/// Calls `visit` for every leaf, depth-first in child order.
void for_each_leaf(const Octree& tree, const std::function<void(const LeafView&)>& visit);

/// @name Distances between surfaces (exact point-to-triangle, sampled).
///@{
/// Every vertex plus `samples` area-weighted points (deterministic for a given seed).
std::vector<Vec3> sample_surface(const TriMesh& mesh, size_t samples, uint64_t seed = 12345);
/// Unsigned distance from each point to the mesh.
std::vector<double> distance_to_mesh(const TriMesh& mesh, const std::vector<Vec3>& points);
struct SurfaceDistance {
  double hausdorff = 0;            ///< max of the two one-sided distances
  double a_to_b = 0, b_to_a = 0;   ///< one-sided maxima
  double mean_a_to_b = 0, mean_b_to_a = 0;
};
/// Two-sided (Hausdorff) distance sampled at all vertices plus `samples` points per side.
SurfaceDistance surface_distance(const TriMesh& a, const TriMesh& b, size_t samples = 100000);
///@}

/// Cell counts of an octree (`pic info`).
struct OctreeStats {
  struct Level {
    size_t white = 0, black = 0, gray = 0, internal = 0;
  };
  std::vector<Level> levels;  ///< index = level
  size_t pics = 0, nodes = 0, capped = 0;
  size_t memory_bytes = 0;    ///< nodes + vertices in memory
  Vec3 bbox_min{0, 0, 0}, bbox_max{0, 0, 0};  ///< of the gray leaves' vertices
};
OctreeStats analyze(const Octree& tree);

}  // namespace pic

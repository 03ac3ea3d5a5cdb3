// PIC — what a mesh is: topology, validity as a solid, volume, distances between surfaces.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "pic/types.h"

namespace pic {

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
/// analyze_topology of the mesh with equal positions merged: what a reader of a file without
/// shared vertices (STL) sees. Two sheets touching at a point that the mesh keeps apart by
/// index only, with their copies of the vertex at one position, are one non-manifold vertex.
MeshTopology analyze_welded_topology(const TriMesh& mesh);

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
/// The mesh with its positions rounded to 32-bit floats, as STL and GLB files hold them
/// (src/measure/float32.cpp). Each coordinate goes to the nearest float, except at the vertices
/// of triangles that rounding made cross, flattened or made share a position: there each
/// coordinate may take the float on its other side (or, where that is not enough, one up to
/// three steps out), whichever leaves the fewest crossings around the vertex. Exact tests on
/// the rounded values; what no choice removes is left (count_self_intersections tells).
TriMesh round_to_float32(const TriMesh& mesh);
/// Whether every coordinate is a 32-bit float already (round_to_float32 returns such a mesh
/// as it is).
bool holds_floats(const TriMesh& mesh);
///@}
/// Signed volume (positive for outward orientation).
double volume(const TriMesh& mesh);

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
  Vec3 worst_a{}, worst_b{};       ///< where the one-sided maxima are: a point of A, of B
};
/// Two-sided (Hausdorff) distance sampled at all vertices plus `samples` points per side.
SurfaceDistance surface_distance(const TriMesh& a, const TriMesh& b, size_t samples = 100000);
struct OffsetDistance {
  double worst = 0, mean = 0;  ///< over every vertex and sample
  double worst_vertex = 0;     ///< over the vertices alone
  Vec3 where{};                ///< the worst point
  /// The other way: from points of the exact offset surface to `surface`.
  double back_worst = 0, back_mean = 0;
  Vec3 back_where{};
  size_t back_points = 0;  ///< points of the exact offset surface measured
  double hausdorff() const { return std::max(worst, back_worst); }
};
/// How far `surface` lies from `reference`'s surface offset by `offset` (> 0 outward), both
/// ways: |signed distance to reference - offset| at every vertex plus `samples` area-weighted
/// points; and the distance to `surface` from about `samples` points of the exact offset surface
/// (offset_surface_points). \throws InvalidInput when `reference` is not closed, 2-manifold and
/// consistently oriented (its sign comes from pseudonormals).
OffsetDistance offset_distance(const TriMesh& surface, const TriMesh& reference, double offset,
                               size_t samples = 100000);
/// Points of the exact offset surface of a closed, outward-oriented mesh: each is a point q of
/// the mesh moved by |offset| along a direction of q's normal cone (a face's normal, an arc
/// between an edge's two face normals, a blend of a vertex's face normals), drawn in proportion
/// to the area each sweeps, and kept only where no other part of the mesh lies nearer.
std::vector<Vec3> offset_surface_points(const TriMesh& reference, double offset, size_t samples, uint64_t seed = 777);
///@}

}  // namespace pic

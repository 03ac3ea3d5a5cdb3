// Turning the dual polygons into triangles that cannot cross (contour/triangulate.cpp).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "octree/dual_walk.h"

namespace pic::detail {

/// A vertex's cell, in output coordinates.
struct VertexCell {
  Vec3 center;
  double half;  // half the side
};

/// How the polygons become triangles.
enum class Triangulation : uint8_t {
  kPlain,      // dual contouring's split (may cross where slivers fold)
  kConstruct,  // the plain split where it provably stays in its polygon's region, else a fan
               // from one of its points or around a point of its edge
  kFanAll,     // every polygon a fan around a point of its edge
};

struct TriangulationStats {
  size_t fans = 0;            // polygons fanned around a point on their edge
  size_t other_diagonal = 0;  // quads split along the diagonal split_quad did not prefer
  size_t face_points = 0;     // polygon sides split at a point of their cells' common face
  size_t face_fans = 0;       // polygons with face points, fanned from a point of their own ring
};

/// The solid's function in output coordinates (< 0 inside), or empty.
using SurfaceFunction = std::function<double(const Vec3&)>;

/// Triangles of the dual polygons (vertex ids into `x`; edge and face points are appended to
/// `x`). `cells`: each vertex's cell; with kConstruct and kFanAll every vertex must lie
/// strictly inside its cell. Edge and face points stay `inset` inside their edge or face; an
/// edge point lies where `level` changes sign on its edge when given, else where the edge
/// meets the plain split of the polygons around it.
std::vector<std::array<uint32_t, 3>> triangulate(std::vector<Vec3>& x, const std::vector<VertexCell>& cells,
                                                 const std::vector<MeshPolygon>& polys, Triangulation how,
                                                 double inset, const SurfaceFunction& level,
                                                 TriangulationStats* stats);

/// Splits a quad along the diagonal that folds most (keeps sharp creases whose two vertices
/// lie on the crease); returns the 2 triangles as index triples into `quad`.
std::array<std::array<int, 3>, 2> split_quad(const std::array<Vec3, 4>& p);

}  // namespace pic::detail

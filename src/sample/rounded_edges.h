// The rounds an offset makes of a mesh's sharp edges, for the implicit sampler's bends
// (ImplicitSolid::bends): where a coarse cell's crossings could all miss one.
#pragma once

#include <array>
#include <memory>
#include <vector>

#include "geometry/box_tree.h"
#include "pic/types.h"

namespace pic::detail {

/// The sharp edges of a closed, 2-manifold surface that an offset by `distance` rounds: convex
/// ones when it grows, concave ones when it shrinks. The offset there is a cylinder of radius
/// |distance| over the angle θ between the faces' normals, which bulges |distance| (1 - cos θ/2)
/// off the chord across it; only edges whose bulge exceeds `tolerance` are kept. A cell's
/// crossings can miss such a round altogether where the cell is wider than the chord that
/// stays within the tolerance, sqrt(8 |distance| tolerance).
class RoundedEdges {
 public:
  RoundedEdges(const TriMesh& surface, double distance, double tolerance);

  /// The points of the rounds nearest `vertex` inside the box [lo, hi], with their normals,
  /// where the box is wider than that chord: on each edge within reach, the point at the offset
  /// distance from the edge's point nearest the vertex.
  void points(const Vec3& lo, const Vec3& hi, const Vec3& vertex, std::vector<std::array<Vec3, 2>>& out) const;

  size_t size() const { return segments_.size(); }

 private:
  double radius_, widest_;
  std::vector<std::array<Vec3, 2>> segments_;
  std::unique_ptr<BoxTree> tree_;
};

/// The distance the implicit sampler holds a leaf's surface to (its polygons, its bends), in
/// world units: the planes' own fit 2δ (δ² = `error`, in root-cube units), at most half a
/// finest cell.
double bend_tolerance(const Cube& cube, int depth, double error);

}  // namespace pic::detail

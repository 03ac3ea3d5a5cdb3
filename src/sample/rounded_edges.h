// The rounds an offset makes of a mesh's sharp edges, for the implicit sampler's bends
// (ImplicitSolid::bends): where a coarse cell's crossings could all miss one; and the points
// where its creases put features of the offset (ImplicitSolid::features).
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

/// Where the offsets of a closed surface by each of `distances` have features of their own, for
/// the implicit sampler's feature points (ImplicitSolid::features): at each crease (an edge
/// whose faces meet at more than 10 degrees, or at less where the offset's round of it would
/// bulge beyond `tolerance`), its middle, its ends and its faces' centres, each moved along its
/// normal by the distance (a face's unit normal; an edge's faces' summed; a vertex's faces'
/// weighted by their angles there, its pseudonormal). A vertex's point lies on its offset's
/// round or corner, a face's on its plane. Flat and gently curved parts have none: the
/// sampler's own questions see their offsets.
std::vector<Vec3> offset_feature_points(const TriMesh& surface, const std::vector<double>& distances,
                                        double tolerance);

/// The distance the implicit sampler holds a leaf's surface to (its polygons, its bends), in
/// world units: the planes' own fit 2δ (δ² = `error`, in root-cube units), at most half a
/// finest cell.
double bend_tolerance(const Cube& cube, int depth, double error);

}  // namespace pic::detail

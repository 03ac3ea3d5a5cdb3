// A round convex body (a faceted sphere) and the solid swept by it over another: the function
// whose zero set the Minkowski sum's surface is taken to be (pic::minkowski_round).
#pragma once

#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "geometry/mesh_distance.h"
#include "pic/types.h"

namespace pic::detail {

/// A round convex body about its centroid: support h(u) = max (v - c).u.
struct RoundBody {
  Vec3 centre{0, 0, 0};
  std::vector<Vec3> rel;  ///< vertices minus the centre
  double outer = 0;       ///< largest |v - c|
  double inner = 0;       ///< smallest support over all directions (the inradius about c)
  double support(const Vec3& u) const { return support_point(u).first; }
  /// The support along u and a vertex where it is reached (the first in `rel` among equals).
  std::pair<double, Vec3> support_point(const Vec3& u) const;
  /// Bins the directions so that support_point looks at a few candidate vertices, not all.
  void index_directions();

 private:
  /// Directions binned by a cube around the unit sphere, `side` x `side` cells per face; per
  /// cell, the vertices that can reach the support for some unit direction in it, in order.
  int side_ = 0;
  std::vector<uint32_t> first_, candidates_;
  int cell_of(const Vec3& u) const;
};

/// The body about its centroid when it is round (every vertex and facet within 2 % of one
/// radius from it), else nothing.
std::optional<RoundBody> round_body_if_round(const std::vector<Vec3>& points);

/// The sum of a closed surface (already moved by the body's centre) and a round body, as a
/// function: outside the solid, f = d - h(u), d the distance to the surface and u the unit
/// direction from its nearest point (zero where the body, moved to that point, reaches p
/// along u); inside, d - inner, negative throughout. Keeps references to both.
class RoundSum {
 public:
  RoundSum(const TriMesh& surface, const RoundBody& body) : surface_(surface), body_(body), distance_(surface) {}
  /// f at p and its gradient. `hint`: see MeshDistance::nearest; `distance` and `nearest`,
  /// when given, get the signed distance d and the surface point nearest p.
  double operator()(const Vec3& p, Vec3& gradient, uint32_t* hint = nullptr, double* distance = nullptr,
                    Vec3* nearest = nullptr) const;
  const SignedDistance& distance() const { return distance_; }
  const RoundBody& body() const { return body_; }

 private:
  const TriMesh& surface_;
  const RoundBody& body_;
  SignedDistance distance_;
};

}  // namespace pic::detail

// A round convex body (a faceted sphere) and the solid swept by it over another: the function
// whose zero set the Minkowski sum's surface is taken to be (pic::minkowski_round).
#pragma once

#include <atomic>
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
  /// The hull's facets: unit outward normals and their supports (about c).
  std::vector<Vec3> facet_normal;
  std::vector<double> facet_support;
  /// The hull's edges between facets that are not coplanar, as arcs of the sphere of
  /// directions: the normals on either side and a point of the edge (about c), where the
  /// support is reached for every direction between them.
  struct Arc {
    Vec3 n1, n2, at;
  };
  std::vector<Arc> arcs;
  /// outer tan(near_angle / 4): above a triangle's inside, farther than this and the body's
  /// outer radius from its sides, the sum is the triangle's face moved out.
  double face_depth = 0;
  double support(const Vec3& u) const { return support_point(u).first; }
  /// The support along u and a vertex where it is reached (the first in `rel` among equals).
  std::pair<double, Vec3> support_point(const Vec3& u) const;
  /// Bins the directions so that support_point looks at a few candidate vertices, not all,
  /// and a sum's facet search only the facets near a direction.
  void index_directions();
  bool indexed() const { return side_ > 0; }
  /// The facets (indices into facet_normal) whose normals may lie within near_angle of u
  /// (indexed bodies only; none for a u of no length).
  struct Near {
    const uint32_t *facets, *facets_end;
  };
  Near near(const Vec3& u) const;
  /// The angle about a direction that `near` covers: the sum's facet search needs
  /// acos(1 - 2 (outer - inner) / inner) (RoundSum::triangle_sum).
  double near_angle() const;

 private:
  /// Directions binned by a cube around the unit sphere, `side` x `side` cells per face; per
  /// cell, the vertices that can reach the support for some unit direction in it, in order,
  /// and the facets within near_angle of some direction in it.
  int side_ = 0;
  std::vector<uint32_t> first_, candidates_;
  std::vector<uint32_t> facet_first_, facet_list_;
  int cell_of(const Vec3& u) const;
};

/// The body about its centroid when it is round (every vertex and facet within 2 % of one
/// radius from it), else nothing.
std::optional<RoundBody> round_body_if_round(const std::vector<Vec3>& points);

/// The sum S of a closed solid A (its surface already moved by the body's centre) and a
/// convex body B about the origin, as a function whose zero set is S's surface exactly: S is
/// A together with T + B for every triangle T of A's surface (a point b of B moved to a
/// point of A leaves A, if at all, through some T). Each T + B is a convex polytope, and
/// F_T(p) = max over its facet normals n of n.p - h_T(n) - h_B(n) is its signed distance
/// inside and a lower bound on it outside (exact above a facet). Outside A,
/// f = min over T of F_T; inside A, f = d - inner (d the signed distance to A's surface).
/// |f| never exceeds the distance to S's surface, and f is exact next to it.
/// Keeps references to both.
class RoundSum {
 public:
  RoundSum(const TriMesh& surface, const RoundBody& body);
  ~RoundSum();
  RoundSum(const RoundSum&) = delete;
  RoundSum& operator=(const RoundSum&) = delete;
  /// f at p and its gradient (the winning facet's normal). `hint`: see MeshDistance::nearest;
  /// `distance` and `nearest`, when given, get the signed distance d and the surface point
  /// nearest p; `winner` the triangle whose F_T f is (outside the solid; else unchanged).
  double operator()(const Vec3& p, Vec3& gradient, uint32_t* hint = nullptr, double* distance = nullptr,
                    Vec3* nearest = nullptr, uint32_t* winner = nullptr) const;
  /// Whether the box [lo, hi] lies proven inside or outside the sum (a box beside the surface
  /// that no ball about its centre clears: inside one T + B with all its corners, or beyond
  /// a supporting plane of every T + B that may reach it). False when unsure. `d`, `f` and
  /// `winner`: what operator() gave at the box's centre.
  bool box_clear(const Vec3& lo, const Vec3& hi, double d, double f, uint32_t winner) const;
  const SignedDistance& distance() const { return distance_; }
  const RoundBody& body() const { return body_; }

 private:
  /// f at p outside the solid (`d`: its distance), its gradient and the triangle whose F_T it is.
  double outside(const Vec3& p, double d, const std::vector<Nearest>& around, Vec3& gradient, uint32_t& winner) const;
  /// Triangle t's support along n.
  double support_of(uint32_t t, const Vec3& n) const;
  /// The distance from p to triangle t and its point nearest p.
  Nearest nearest_point(uint32_t t, const Vec3& p) const;
  /// F_T(p) for triangle t (`at`: its point nearest p) and its gradient. `plane`, when
  /// given, gets the normal n of the plane whose value F_T is (T + B lies below it by that
  /// much at p: n.x <= h_T(n) + h_B(n)), `plane_support` h_B(n).
  double triangle_sum(uint32_t t, const Vec3& p, const Nearest& at, Vec3& gradient, Vec3* plane = nullptr,
                      double* plane_support = nullptr) const;
  /// The highest plane value so far: its gradient, its plane's normal n and B's support h_B(n).
  struct Best {
    double value = 0;
    Vec3 gradient{0, 0, 0}, plane{0, 0, 0};
    double support = 0;
  };
  /// Raises `best` to the highest of T + B's facet planes within acos(cut) of u at p.
  void facet_planes(uint32_t t, const Vec3& p, const Vec3& u, double cut, Best& best) const;
  /// The gradient of d_T - h_B(u) (u the direction from T's point nearest p, `feature` the
  /// part of T holding it, `top` the vertex of B reaching the support along u).
  Vec3 along_gradient(uint32_t t, Feature feature, const Vec3& u, double dt, const Vec3& top) const;
  /// Whether T's face value d_T - h_B(u) may stand for F_T (`near` inside T, so u is T's
  /// normal, and far from its sides; `outside`: p outside the sum, where sides a coplanar
  /// triangle continues count as inside).
  bool above_face_inside(uint32_t t, const Vec3& near, double dt, double cut, bool outside) const;
  static constexpr uint32_t kNoTriangle = ~uint32_t{0};
  /// Per triangle side (3 t + k, from corner k): the coplanar triangle across it, or kNoTriangle.
  static std::vector<uint32_t> flat_neighbours(const TriMesh& surface);

  const TriMesh& surface_;
  /// The normals of the facets an edge of the surface sweeps along B's edges: where B's arcs
  /// cross the circle of directions perpendicular to it (`axis`), in order round it (`angle`:
  /// a pseudo-angle from a1 towards a2), with B's support there.
  struct Zone {
    Vec3 axis{0, 0, 0}, a1{0, 0, 0}, a2{0, 0, 0};
    std::vector<double> angle, support;
    std::vector<Vec3> normal;
  };
  /// The zone of triangle t's side k, made when first asked (safe from several threads).
  const Zone& zone(uint32_t t, int k) const;

  const RoundBody& body_;
  SignedDistance distance_;
  std::vector<uint32_t> across_;
  std::vector<uint32_t> zone_of_;  // per side (3 t + k): its zone's number
  struct Face {
    Vec3 normal{0, 0, 0};  // unit; zero for a triangle without area
    double up = 0, down = 0;  // B's support along normal and along -normal
  };
  std::vector<Face> face_;  // per triangle
  mutable std::vector<std::atomic<const Zone*>> zones_;
};

}  // namespace pic::detail

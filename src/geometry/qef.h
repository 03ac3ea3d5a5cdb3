// Quadric error function Q(x) = x'Ax - 2b'x + c over weighted planes (paper eq. 1),
// stored in compact symmetric form so two QEFs add (Q_sum = Q_A + Q_B, paper eq. 3).
#pragma once

#include <array>

#include "pic/types.h"

namespace pic::detail {

struct Qef {
  std::array<double, 6> a{};  // xx xy xz yy yz zz
  std::array<double, 3> b{};
  double c = 0;
  double weight = 0;  // sum of plane weights; the residual is reported per unit weight

  /// Adds the plane n.x = d (n unit length) with weight w.
  void add_plane(const Vec3& n, double d, double w);
  Qef& operator+=(const Qef& o);
  bool empty() const { return weight <= 0; }
  /// Mean squared distance of x to the planes.
  double error(const Vec3& x) const;

  struct Solution {
    Vec3 position;
    double error;  // mean squared distance (root-cube units squared)
    int rank;
  };
  /// How A+ treats small eigenvalues λ: Truncated drops those below kRelativeCutoff of the
  /// largest; Damped takes λ/(λ² + μ²) with μ = kSharpDamping times the largest, continuous in
  /// the planes and exact to (μ/λ)² where λ is well above μ (a shallow crease's line).
  enum class Pinv { Truncated, Damped };
  /// x = seed + A+ (b - A seed), A+ by eigendecomposition (Lindstrom 2000); truncated, flat and
  /// creased patches keep the vertex close to the seed along their free directions.
  Solution solve(const Vec3& seed, Pinv pinv = Pinv::Truncated) const;
  /// As solve(), but when the minimum leaves the box [lo, hi] and the QEF has free
  /// directions (a crease line or a plane), slides along them to a point inside the box:
  /// the middle of the line's chord through the box, or the centroid of the plane's section.
  Solution solve_in_box(const Vec3& seed, const Vec3& lo, const Vec3& hi, Pinv pinv = Pinv::Truncated) const;
};

}  // namespace pic::detail

// Generalized winding numbers (Jacobson, Kavan, Sorkine-Hornung 2013) made fast by a
// hierarchy of dipoles (Barill, Dickson, Schmidt, Levin, Jacobson 2018), for triangle sets and
// for oriented point clouds.
//
// A DipoleTree holds "elements" that each carry a vector area (area times unit normal) at a
// position: triangles (exact contribution: their solid angle / 4 pi) or points (a small disc).
// Far from a node (distance > beta * radius) the node's elements are replaced by one dipole at
// their area-weighted centre; evaluate() returns the sum with a bound on what that
// approximation can have cost, so a caller can ask again exactly when a decision is close.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "geometry/lattice.h"
#include "geometry/tolerances.h"

namespace pic::detail {

/// Solid angle of triangle (a, b, c) seen from p, divided by 4 pi: +1/2 just behind a
/// counter-clockwise triangle (the side its normal points away from), -1/2 just in front.
/// `side` (+1 behind / -1 in front / 0 unknown) decides the sign when p lies (numerically) in
/// the triangle's plane, so the jump agrees with the exact crossing predicates.
double triangle_winding(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, int side = 0);
/// The two terms of Van Oosterom and Strackee's formula for triangle (a, b, c) seen from p:
/// tan(Omega / 2) = det / den, so the triangle's winding number is atan2(det, den) / (2 pi).
/// `side()` (+1 behind / -1 in front / 0 unknown) is asked only when p lies (numerically) in
/// the triangle's plane; det is then a signed zero, so the jump agrees with the exact predicates.
struct AngleTerms {
  double det = 0, den = 0;
};
template <class Side>
AngleTerms triangle_angle_terms(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, Side&& side) {
  const Vec3 A{a[0] - p[0], a[1] - p[1], a[2] - p[2]}, B{b[0] - p[0], b[1] - p[1], b[2] - p[2]},
      C{c[0] - p[0], c[1] - p[1], c[2] - p[2]};
  const double la = std::sqrt(A[0] * A[0] + A[1] * A[1] + A[2] * A[2]);
  const double lb = std::sqrt(B[0] * B[0] + B[1] * B[1] + B[2] * B[2]);
  const double lc = std::sqrt(C[0] * C[0] + C[1] * C[1] + C[2] * C[2]);
  AngleTerms t;
  t.det = A[0] * (B[1] * C[2] - B[2] * C[1]) - A[1] * (B[0] * C[2] - B[2] * C[0]) + A[2] * (B[0] * C[1] - B[1] * C[0]);
  t.den = la * lb * lc + (A[0] * B[0] + A[1] * B[1] + A[2] * B[2]) * lc +
          (B[0] * C[0] + B[1] * C[1] + B[2] * C[2]) * la + (C[0] * A[0] + C[1] * A[1] + C[2] * A[2]) * lb;
  // In the plane (relative to the terms' size) the sign of det is noise: use the side given.
  if (std::abs(t.det) <= kInPlaneDet * la * lb * lc) {
    const int s = side();
    if (s != 0) t.det = s > 0 ? 0.0 : -0.0;
  }
  return t;
}
template <class Side>
double triangle_winding(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, Side&& side) {
  const AngleTerms t = triangle_angle_terms(p, a, b, c, side);
  return std::atan2(t.det, t.den) * (0.5 / 3.14159265358979323846);
}

/// A sum of angles atan2(det_i, den_i) with one atan2 at the end: the complex numbers
/// den_i + i det_i are multiplied (the arguments add), and the half-turns the product's argument
/// wraps past +-pi are counted, so the sum is exact to rounding, not only modulo 2 pi. Each
/// wrap is read off the computed product itself, so rounding near +-pi cannot lose a turn.
class AngleSum {
 public:
  void add(const AngleTerms& t) {
    if (t.det == 0 && t.den == 0) return;  // p at a vertex: atan2(0, 0) = 0 contributes nothing
    // Each factor is scaled to |den| + |det| = 1 off the dependency chain; the product then
    // shrinks by at most 2^-1/2 per factor and is rescaled only when it gets small.
    const double s = 1 / (std::abs(t.den) + std::abs(t.det)), den = t.den * s, det = t.det * s;
    const bool lower_a = std::signbit(im_), lower_b = std::signbit(det);
    const double re = re_ * den - im_ * det, im = re_ * det + im_ * den;
    if (!lower_a && !lower_b && std::signbit(im)) ++turns_;  // the arguments' sum passed +pi
    if (lower_a && lower_b && !std::signbit(im)) --turns_;   // ... or -pi
    re_ = re;
    im_ = im;
    if (std::abs(re_) + std::abs(im_) < kAngleRenormalize) {
      const double r = 1 / (std::abs(re_) + std::abs(im_));
      re_ *= r;
      im_ *= r;
    }
  }
  /// The sum divided by 2 pi: the triangles' winding number.
  double turns() const { return std::atan2(im_, re_) * (0.5 / 3.14159265358979323846) + turns_; }

 private:
  double re_ = 1, im_ = 0;
  int turns_ = 0;
};

class DipoleTree {
 public:
  /// Grid triangles; winding = sum of solid angles / 4 pi.
  void build_triangles(std::vector<ITri> tris);
  /// Oriented points: position, normal (any length), area each.
  void build_points(const std::vector<Vec3>& pos, const std::vector<Vec3>& normal, const std::vector<double>& area);

  bool empty() const { return nodes_.empty(); }
  struct Value {
    double w = 0;      ///< winding number
    double bound = 0;  ///< |w - exact| <= bound (far-field truncation)
  };
  /// Winding number at p with far nodes approximated (beta > 0) or everything exact (beta = 0).
  /// `gp`, when given, is p on the grid: a point in a triangle's plane then takes the side the
  /// exact crossing predicates give it.
  Value evaluate(const Vec3& p, const I3* gp = nullptr, double beta = 2.5) const;
  /// Whether |w| >= 1/2 for the winding number `offset - w_tree(p)` (offset: an exact integer
  /// part computed by the caller). Far nodes are opened while the decision is within their
  /// truncation bound, until the bound is below `tolerance` (0: the decision is exact).
  bool inside(const Vec3& p, const I3* gp = nullptr, double offset = 0, double tolerance = 0) const;
  /// The same decision when the dipoles of a few far nodes alone settle it (nothing otherwise):
  /// cheaper than a memo lookup, so callers that memoize ask this first.
  std::optional<bool> inside_far(const Vec3& p, double offset = 0) const;

 private:
  struct Element {
    Vec3 centre{}, area{};  // position and vector area
    double abs_area = 0, radius = 0;
    uint32_t tri = UINT32_MAX;  // index into tris_, or UINT32_MAX for a point
  };
  struct DNode {
    Vec3 centre{}, area{};
    double abs_area = 0, radius = 0;
    double moment2 = 0;  // sum of |area| * (distance of the element's farthest point from centre)^2
    std::array<double, 9> spread{};  // sum of (element centre - centre) (x) area: first-order term
    uint32_t first = 0, count = 0;  // leaf: elements [first, first + count)
    uint32_t right = 0;             // inner: left child is this + 1
  };
  uint32_t build_range(uint32_t begin, uint32_t end);
  uint32_t build_range(uint32_t begin, uint32_t end, const std::function<uint32_t()>& left,
                       const std::function<uint32_t()>& right);
  uint32_t build_classes(const std::vector<uint32_t>& starts, size_t first, uint32_t end);
  static double truncation_bound(const DNode& n, double d);
  static double far_field(const DNode& n, const Vec3& p);
  /// Whether a decision (inside(), inside_far()) takes node `n`, at distance d, as its dipole.
  static bool summarized(const DNode& n, double d);
  /// Adds leaf `n`'s exact sum: triangles' angles to `angles`, points' discs to `w`.
  void add_exact(const DNode& n, const Vec3& p, const I3* gp, AngleSum& angles, double& w) const;
  void build();

  std::vector<Element> elems_;
  std::vector<std::array<Vec3, 3>> tris_;
  std::vector<ITri> itris_;
  std::vector<DNode> nodes_;
};

/// Gradient direction of the winding number of a surface whose boundary is the closed curve
/// made of `edges` (a -> b), at p: the Biot-Savart field of a unit current in the curve. It
/// does not depend on the surface, so it is the normal of the w = 1/2 level set across a hole.
Vec3 boundary_field(const std::vector<std::array<Vec3, 2>>& edges, const Vec3& p);

}  // namespace pic::detail

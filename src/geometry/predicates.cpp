// Exact orientation predicates on doubles and the closed segment/triangle test built on them.
//
// Shewchuk's static error bounds filter the plain double determinant (Shewchuk 1997,
// "Adaptive precision floating-point arithmetic and fast robust geometric predicates",
// o3derrboundA / ccwerrboundA); when the filter cannot decide, the determinant is evaluated
// exactly with expansion arithmetic (two-sum, fma two-product, grow- and scale-expansion from
// the same paper). Exact for any finite doubles short of underflow.
#include "geometry/predicates.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace pic::detail {
namespace {

// ---------------------------------------------------------------- exact arithmetic
/// Nonoverlapping components, increasing magnitude, zeros dropped. Fixed capacity on the stack:
/// the largest expansion orient3d builds has 192 components (3 x 2 x 2 x 16).
struct Expansion {
  std::array<double, 192> v;  // only v[0..n) is ever read or copied
  int n = 0;
  Expansion() = default;
  Expansion(const Expansion& o) : n(o.n) { std::copy_n(o.v.begin(), n, v.begin()); }
  Expansion& operator=(const Expansion& o) {
    n = o.n;
    std::copy_n(o.v.begin(), n, v.begin());
    return *this;
  }
  void push(double x) {
    if (x != 0) v[size_t(n++)] = x;
  }
};

inline void two_sum(double a, double b, double& x, double& y) {
  x = a + b;
  const double bv = x - a, av = x - bv;
  y = (a - av) + (b - bv);
}
inline void two_prod(double a, double b, double& x, double& y) {
  x = a * b;
  y = std::fma(a, b, -x);
}
/// v[0..n) += b, in place (Shewchuk's Grow-Expansion: component i of the result needs only
/// v[0..i]); the caller's storage holds one more component.
void grow(double* v, int& n, double b) {
  double q = b;
  int k = 0;
  for (int i = 0; i < n; ++i) {
    double h;
    two_sum(q, v[i], q, h);
    if (h != 0) v[k++] = h;
  }
  if (q != 0) v[k++] = q;
  n = k;
}
void grow(Expansion& e, double b) { grow(e.v.data(), e.n, b); }
Expansion add(Expansion e, const Expansion& f) {
  for (int i = 0; i < f.n; ++i) grow(e, f.v[size_t(i)]);
  return e;
}
Expansion scale(const Expansion& e, double b) {
  Expansion h;
  if (e.n == 0 || b == 0) return h;
  double q, lo;
  two_prod(e.v[0], b, q, lo);
  h.push(lo);
  for (int i = 1; i < e.n; ++i) {
    double t_hi, t_lo, s;
    two_prod(e.v[size_t(i)], b, t_hi, t_lo);
    two_sum(q, t_lo, q, s);
    h.push(s);
    two_sum(t_hi, q, q, s);
    h.push(s);
  }
  h.push(q);
  return h;
}
Expansion mul(const Expansion& e, const Expansion& f) {
  Expansion r;
  for (int i = 0; i < f.n; ++i) r = add(r, scale(e, f.v[size_t(i)]));
  return r;
}
Expansion neg(Expansion e) {
  for (int i = 0; i < e.n; ++i) e.v[size_t(i)] = -e.v[size_t(i)];
  return e;
}
Expansion diff(double a, double b) {
  double x, y;
  two_sum(a, -b, x, y);
  Expansion e;
  e.push(y);
  e.push(x);
  return e;
}
int sign_of(const Expansion& e) { return e.n == 0 ? 0 : (e.v[size_t(e.n - 1)] > 0 ? 1 : -1); }

/// The sign of b·(c × d) when every coordinate difference is exact (as where the points are
/// close, or share an exponent): each product two-term, each minor four, the sum at most 24
/// terms, all on the stack.
int orient3d_exact_differences(const Vec3& b, const Vec3& c, const Vec3& d) {
  std::array<double, 24> sum;
  int n = 0;
  for (int k = 0; k < 3; ++k) {
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    std::array<double, 4> minor;
    int m = 0;
    double hi, lo;
    two_prod(c[i], d[j], hi, lo);
    grow(minor.data(), m, lo);
    grow(minor.data(), m, hi);
    two_prod(-c[j], d[i], hi, lo);
    grow(minor.data(), m, lo);
    grow(minor.data(), m, hi);
    for (int t = 0; t < m; ++t) {
      two_prod(minor[size_t(t)], b[k], hi, lo);
      grow(sum.data(), n, lo);
      grow(sum.data(), n, hi);
    }
  }
  return n == 0 ? 0 : (sum[size_t(n - 1)] > 0 ? 1 : -1);
}

}  // namespace

// ---------------------------------------------------------------- predicates
/// Sign of det[b-a, c-a, d-a] (CGAL::orientation(a, b, c, d)).
int orient3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const double bx = b[0] - a[0], by = b[1] - a[1], bz = b[2] - a[2];
  const double cx = c[0] - a[0], cy = c[1] - a[1], cz = c[2] - a[2];
  const double dx = d[0] - a[0], dy = d[1] - a[1], dz = d[2] - a[2];
  const double m1 = cy * dz - cz * dy, m2 = cz * dx - cx * dz, m3 = cx * dy - cy * dx;
  const double det = bx * m1 + by * m2 + bz * m3;
  const double perm = std::abs(bx) * (std::abs(cy * dz) + std::abs(cz * dy)) +
                      std::abs(by) * (std::abs(cz * dx) + std::abs(cx * dz)) +
                      std::abs(bz) * (std::abs(cx * dy) + std::abs(cy * dx));
  // Shewchuk's o3derrboundA = (7 + 56 eps) eps, eps = 2^-53.
  constexpr double kBound = 7.7715611723761027e-16;
  if (det > kBound * perm) return 1;
  if (-det > kBound * perm) return -1;
  if (perm == 0) return 0;
  // Four points on one axis-aligned plane (a CAD face: one coordinate shared exactly) are
  // coplanar without the exact sum.
  for (int k = 0; k < 3; ++k)
    if (a[k] == b[k] && a[k] == c[k] && a[k] == d[k]) return 0;
  bool exact = true;
  Vec3 eb, ec, ed;
  for (int k = 0; k < 3; ++k) {
    double tail;
    two_sum(b[k], -a[k], eb[k], tail);
    exact = exact && tail == 0;
    two_sum(c[k], -a[k], ec[k], tail);
    exact = exact && tail == 0;
    two_sum(d[k], -a[k], ed[k], tail);
    exact = exact && tail == 0;
  }
  if (exact) return orient3d_exact_differences(eb, ec, ed);
  const Expansion ebx = diff(b[0], a[0]), eby = diff(b[1], a[1]), ebz = diff(b[2], a[2]);
  const Expansion ecx = diff(c[0], a[0]), ecy = diff(c[1], a[1]), ecz = diff(c[2], a[2]);
  const Expansion edx = diff(d[0], a[0]), edy = diff(d[1], a[1]), edz = diff(d[2], a[2]);
  const Expansion e1 = add(mul(ecy, edz), neg(mul(ecz, edy)));
  const Expansion e2 = add(mul(ecz, edx), neg(mul(ecx, edz)));
  const Expansion e3 = add(mul(ecx, edy), neg(mul(ecy, edx)));
  return sign_of(add(add(mul(ebx, e1), mul(eby, e2)), mul(ebz, e3)));
}

/// Sign of the 2D orientation of (a, b, c) projected along axis `drop`.
int orient2d(const Vec3& a, const Vec3& b, const Vec3& c, int drop) {
  const int i = drop == 0 ? 1 : 0, j = drop == 2 ? 1 : 2;
  const double l = (a[i] - c[i]) * (b[j] - c[j]), r = (a[j] - c[j]) * (b[i] - c[i]);
  const double det = l - r;
  // Shewchuk's ccwerrboundA = (3 + 16 eps) eps.
  constexpr double kBound = 3.3306690738754716e-16;
  const double bound = kBound * (std::abs(l) + std::abs(r));
  if (det > bound) return 1;
  if (-det > bound) return -1;
  if (l == 0 && r == 0) return 0;
  const Expansion d = add(mul(diff(a[i], c[i]), diff(b[j], c[j])), neg(mul(diff(a[j], c[j]), diff(b[i], c[i]))));
  return sign_of(d);
}

/// An axis along which triangle abc projects to a non-degenerate triangle, or -1 when the
/// triangle is collinear (its exact normal is zero; orient2d along axis k is its k-th component).
int projection_axis(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 u{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const std::array<double, 3> n{std::abs(u[1] * v[2] - u[2] * v[1]), std::abs(u[2] * v[0] - u[0] * v[2]),
                                std::abs(u[0] * v[1] - u[1] * v[0])};
  std::array<int, 3> order{0, 1, 2};
  std::sort(order.begin(), order.end(), [&](int x, int y) { return n[x] > n[y]; });
  for (int k : order)
    if (orient2d(a, b, c, k) != 0) return k;
  return -1;
}

namespace {

/// Closed 2D point-on-segment for a point known to be collinear with the segment.
bool within(const Vec3& p, const Vec3& a, const Vec3& b, int drop) {
  for (int k = 0; k < 3; ++k) {
    if (k == drop) continue;
    if (p[k] < std::min(a[k], b[k]) || p[k] > std::max(a[k], b[k])) return false;
  }
  return true;
}

/// Closed segments pq and ab in the projection along `drop` (all four points coplanar).
bool segments_meet_2d(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b, int drop) {
  const int o1 = orient2d(p, q, a, drop), o2 = orient2d(p, q, b, drop);
  const int o3 = orient2d(a, b, p, drop), o4 = orient2d(a, b, q, drop);
  if (o1 * o2 < 0 && o3 * o4 < 0) return true;
  if (o1 == 0 && within(a, p, q, drop)) return true;
  if (o2 == 0 && within(b, p, q, drop)) return true;
  if (o3 == 0 && within(p, a, b, drop)) return true;
  if (o4 == 0 && within(q, a, b, drop)) return true;
  return false;
}

/// Closed point-in-triangle in the projection along `drop`.
bool point_in_triangle_2d(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, int drop) {
  const int s1 = orient2d(a, b, p, drop), s2 = orient2d(b, c, p, drop), s3 = orient2d(c, a, p, drop);
  const bool has_neg = s1 < 0 || s2 < 0 || s3 < 0, has_pos = s1 > 0 || s2 > 0 || s3 > 0;
  return !(has_neg && has_pos);
}

/// Whether direction d - s lies in the closed cone at s spanned by p1 - s and p2 - s (counter-
/// clockwise in the projection, less than a half turn).
bool in_cone(const Vec3& s, const Vec3& p1, const Vec3& p2, const Vec3& d, int drop) {
  return orient2d(s, p1, d, drop) >= 0 && orient2d(s, p2, d, drop) <= 0;
}

/// Two coplanar, non-degenerate triangles with `shared` (0 or 1) common vertices, by CGAL's
/// rule, in the projection along `drop`. A few 2D orientations where the general test would
/// run its segment tests in 3D first: flat regions of a mesh make many such pairs.
bool coplanar_triangles_meet(const std::vector<Vec3>& x, const std::array<uint32_t, 3>& ta,
                             const std::array<uint32_t, 3>& tb, int shared, int ia, int ib, int drop) {
  if (shared == 1) {
    // Sharing vertex s, they meet elsewhere iff their cones at s overlap (the shorter of the
    // two along a common ray ends on an opposite edge, inside the other triangle). Turning
    // counter-clockwise, their overlap (if any) starts on the first ray of one of them, which
    // then lies in the other.
    const Vec3& s = x[ta[size_t(ia)]];
    const Vec3 *p1 = &x[ta[size_t(ia + 1) % 3]], *p2 = &x[ta[size_t(ia + 2) % 3]];
    const Vec3 *q1 = &x[tb[size_t(ib + 1) % 3]], *q2 = &x[tb[size_t(ib + 2) % 3]];
    if (orient2d(s, *p1, *p2, drop) < 0) std::swap(p1, p2);
    if (orient2d(s, *q1, *q2, drop) < 0) std::swap(q1, q2);
    return in_cone(s, *p1, *p2, *q1, drop) || in_cone(s, *q1, *q2, *p1, drop);
  }
  // Disjoint closed convex polygons have a separating line through an edge of one of them,
  // with the other strictly outside.
  const auto outside_an_edge = [&](const std::array<uint32_t, 3>& t, const std::array<uint32_t, 3>& o) {
    const int turn = orient2d(x[t[0]], x[t[1]], x[t[2]], drop);
    for (int k = 0; k < 3; ++k) {
      const Vec3 &u = x[t[size_t(k)]], &v = x[t[size_t(k + 1) % 3]];
      if (orient2d(u, v, x[o[0]], drop) * turn < 0 && orient2d(u, v, x[o[1]], drop) * turn < 0 &&
          orient2d(u, v, x[o[2]], drop) * turn < 0)
        return true;
    }
    return false;
  };
  return !outside_an_edge(ta, tb) && !outside_an_edge(tb, ta);
}

}  // namespace

/// Whether the closed segment pq meets the closed, non-degenerate triangle abc (exact).
bool segment_meets_triangle(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c) {
  const int op = orient3d(a, b, c, p), oq = orient3d(a, b, c, q);
  if (op != 0 && op == oq) return false;
  if (op == 0 && oq == 0) {
    const int drop = projection_axis(a, b, c);
    if (drop < 0) return false;
    if (point_in_triangle_2d(p, a, b, c, drop) || point_in_triangle_2d(q, a, b, c, drop)) return true;
    return segments_meet_2d(p, q, a, b, drop) || segments_meet_2d(p, q, b, c, drop) ||
           segments_meet_2d(p, q, c, a, drop);
  }
  // pq reaches the plane: the line through it passes through the triangle iff it lies on one
  // side (or on) all three edges.
  const int s1 = orient3d(p, q, a, b), s2 = orient3d(p, q, b, c), s3 = orient3d(p, q, c, a);
  const bool has_neg = s1 < 0 || s2 < 0 || s3 < 0, has_pos = s1 > 0 || s2 > 0 || s3 > 0;
  return !(has_neg && has_pos);
}

/// CGAL's rule for a pair of non-degenerate triangles of one mesh.
bool triangles_intersect(const std::vector<Vec3>& x, const std::array<uint32_t, 3>& ta,
                         const std::array<uint32_t, 3>& tb) {
  // A triangle with a repeated vertex has no interior: nothing to cross (and the shared-vertex
  // bookkeeping below assumes three distinct indices per triangle).
  for (const auto* t : {&ta, &tb})
    if ((*t)[0] == (*t)[1] || (*t)[1] == (*t)[2] || (*t)[0] == (*t)[2]) return false;
  int ia[3] = {}, ib[3] = {}, shared = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (ta[i] == tb[j]) {
        ia[shared] = i;
        ib[shared] = j;
        ++shared;
      }
  if (shared == 3) return true;  // the same triangle twice
  const Vec3 &a0 = x[ta[0]], &a1 = x[ta[1]], &a2 = x[ta[2]];
  const Vec3 &b0 = x[tb[0]], &b1 = x[tb[1]], &b2 = x[tb[2]];
  if (shared == 2) {
    // Folded onto the same side of the shared edge uv, in one plane.
    const Vec3 &u = x[ta[ia[0]]], &v = x[ta[ia[1]]];
    const Vec3 &p = x[ta[3 - ia[0] - ia[1]]], &q = x[tb[3 - ib[0] - ib[1]]];
    if (orient3d(u, v, p, q) != 0) return false;
    const int drop = projection_axis(u, v, p);
    return drop >= 0 && orient2d(u, v, p, drop) * orient2d(u, v, q, drop) > 0;
  }
  // Separating planes (exact): a triangle whose vertices other than the shared ones lie
  // strictly on one side of the other's plane touches that plane at most in the shared vertex,
  // so neither triangle's remaining edges can meet the other. Settles most pairs of a mesh in a
  // few orientation tests.
  // `coplanar`: set when every vertex of t lies in the plane (then t and the other triangle
  // are coplanar).
  auto one_side = [&](const std::array<uint32_t, 3>& t, const Vec3& p0, const Vec3& p1, const Vec3& p2,
                      const std::array<uint32_t, 3>& other, bool* coplanar) {
    int side = 0;
    bool flat = true, one = true;
    for (int k = 0; k < 3; ++k) {
      if (other[0] == t[k] || other[1] == t[k] || other[2] == t[k]) continue;
      const int o = orient3d(p0, p1, p2, x[t[k]]);
      flat = flat && o == 0;
      if (o == 0 || (side != 0 && o != side)) one = false;
      if (!one && !flat) break;
      side = o;
    }
    if (coplanar) *coplanar = flat;
    return one;
  };
  bool coplanar = false;
  if (one_side(tb, a0, a1, a2, ta, &coplanar)) return false;
  if (coplanar) {
    const int drop = projection_axis(a0, a1, a2);
    return drop >= 0 && coplanar_triangles_meet(x, ta, tb, shared, ia[0], ib[0], drop);
  }
  if (one_side(ta, b0, b1, b2, tb, nullptr)) return false;
  if (shared == 1) {
    const int i = ia[0], j = ib[0];
    return segment_meets_triangle(x[tb[(j + 1) % 3]], x[tb[(j + 2) % 3]], a0, a1, a2) ||
           segment_meets_triangle(x[ta[(i + 1) % 3]], x[ta[(i + 2) % 3]], b0, b1, b2);
  }
  // Two closed triangles meet iff an edge of one meets the other: an extreme point of their
  // (convex) intersection lies on the boundary of one of them.
  return segment_meets_triangle(a0, a1, b0, b1, b2) || segment_meets_triangle(a1, a2, b0, b1, b2) ||
         segment_meets_triangle(a2, a0, b0, b1, b2) || segment_meets_triangle(b0, b1, a0, a1, a2) ||
         segment_meets_triangle(b1, b2, a0, a1, a2) || segment_meets_triangle(b2, b0, a0, a1, a2);
}

}  // namespace pic::detail

#include "geometry/lattice.h"
#include "geometry/tolerances.h"
#include "geometry/vec3.h"

#include <algorithm>
#include <cmath>

namespace pic::detail {
namespace {

int sgn(i128 v) { return (v > 0) - (v < 0); }

// Sign of f(p + delta) for the plane function f(p) = n.p - d, delta = (e, e^2, e^3).
int perturbed_plane_sign(const ITri& t, const I3& p) {
  // Floating-point filter: n and d carry a relative error of 2^-53, p is exact, and each
  // operation adds at most 2^-53 of its magnitude; 2^-48 of the terms' sum bounds it all.
  const double t0 = t.n_approx[0] * double(p[0]), t1 = t.n_approx[1] * double(p[1]),
               t2 = t.n_approx[2] * double(p[2]);
  const double fa = t0 + t1 + t2 - t.d_approx;
  const double bound = (std::abs(t0) + std::abs(t1) + std::abs(t2) + std::abs(t.d_approx)) * 0x1p-48;
  if (fa > bound) return 1;
  if (fa < -bound) return -1;
  const i128 f = t.n[0] * p[0] + t.n[1] * p[1] + t.n[2] * p[2] - t.d;
  if (f != 0) return sgn(f);
  if (t.n[0] != 0) return sgn(t.n[0]);
  if (t.n[1] != 0) return sgn(t.n[1]);
  return sgn(t.n[2]);
}

// Orientation of (u, w, q + delta) in the (i, j) projection, perturbed (never 0 unless u == w).
int perturbed_orient(const I3& u, const I3& w, const I3& q, int i, int j) {
  const i64 a = w[i] - u[i], b = q[j] - u[j], c = w[j] - u[j], d = q[i] - u[i];
  // Floating-point filter (differences are exact in double below 2^53).
  const double p1 = double(a) * double(b), p2 = double(c) * double(d), oa = p1 - p2;
  const double bound = (std::abs(p1) + std::abs(p2)) * 0x1p-50;
  if (oa > bound) return 1;
  if (oa < -bound) return -1;
  const i128 o = i128(a) * b - i128(c) * d;
  if (o != 0) return sgn(o);
  if (u[j] != w[j]) return u[j] > w[j] ? 1 : -1;  // coefficient of delta_i
  return w[i] > u[i] ? 1 : (w[i] < u[i] ? -1 : 0);  // coefficient of delta_j
}

struct Poly {
  std::array<Vec3, 12> p;
  int n = 0;
};

// Clip `in` against the half-space sign*(x[axis] - value) <= 0 into `out`, snapping new
// points onto the plane.
void clip(const Poly& in, Poly& out, int axis, double value, bool keep_below) {
  out.n = 0;
  for (int k = 0; k < in.n; ++k) {
    const Vec3& a = in.p[k];
    const Vec3& b = in.p[k + 1 == in.n ? 0 : k + 1];
    const double da = keep_below ? a[axis] - value : value - a[axis];
    const double db = keep_below ? b[axis] - value : value - b[axis];
    if (da <= 0) out.p[out.n++] = a;
    if ((da < 0 && db > 0) || (da > 0 && db < 0)) {
      const double s = da / (da - db);
      Vec3 x{a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1]), a[2] + s * (b[2] - a[2])};
      x[axis] = value;
      out.p[out.n++] = x;
    }
  }
}


std::array<uint8_t, 256> make_component_table() {
  std::array<uint8_t, 256> table{};
  for (int m = 0; m < 256; ++m) {
    if (m == 0 || m == 255) continue;
    auto connected = [&](bool inside) {
      int seen = 0, stack = 0;
      int first = -1;
      for (int c = 0; c < 8; ++c)
        if (((m >> c) & 1) == inside) first = first < 0 ? c : first;
      seen = 1 << first;
      stack = 1 << first;
      while (stack) {
        const int c = __builtin_ctz(stack);
        stack &= stack - 1;
        for (int a = 0; a < 3; ++a) {
          const int nb = c ^ (1 << a);
          if (((m >> nb) & 1) == inside && !((seen >> nb) & 1)) {
            seen |= 1 << nb;
            stack |= 1 << nb;
          }
        }
      }
      for (int c = 0; c < 8; ++c)
        if (((m >> c) & 1) == inside && !((seen >> c) & 1)) return false;
      return true;
    };
    table[m] = connected(true) && connected(false);
  }
  return table;
}

}  // namespace

ITri make_itri(const I3& a, const I3& b, const I3& c) {
  ITri t;
  t.v = {a, b, c};
  const i128 e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const i128 e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  t.n = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
  t.d = t.n[0] * a[0] + t.n[1] * a[1] + t.n[2] * a[2];
  for (int k = 0; k < 3; ++k) {
    t.lo[k] = std::min({a[k], b[k], c[k]});
    t.hi[k] = std::max({a[k], b[k], c[k]});
  }
  const double nx = double(t.n[0]), ny = double(t.n[1]), nz = double(t.n[2]);
  t.n_approx = {nx, ny, nz};
  t.d_approx = double(t.d);
  const double len = std::sqrt(nx * nx + ny * ny + nz * nz);
  if (len > 0) {
    t.unit_normal = {nx / len, ny / len, nz / len};
    const Vec3 v0 = to_unit(a);
    t.plane = t.unit_normal[0] * v0[0] + t.unit_normal[1] * v0[1] + t.unit_normal[2] * v0[2];
    t.area = 0.5 * len / (kGridScale * kGridScale);
  }
  return t;
}

int plane_side(const ITri& t, const I3& p) { return perturbed_plane_sign(t, p); }

bool crosses(const ITri& t, const I3& a, int axis, i64 len) {
  const int i = axis == 0 ? 1 : 0;
  const int j = axis == 2 ? 1 : 2;
  // Bounding-box rejection; the perturbation moves q by +delta, so q == hi is outside.
  if (a[i] < t.lo[i] || a[i] >= t.hi[i] || a[j] < t.lo[j] || a[j] >= t.hi[j]) return false;
  if (a[axis] + len < t.lo[axis] || a[axis] > t.hi[axis]) return false;
  if (t.n[axis] == 0) return false;  // parallel to the segment: never crossed after perturbation
  // The triangle's orientation in the (i, j) projection is n's component along the axis
  // ((i, j, axis) is cyclic except for axis = y).
  const int orient = axis == 1 ? -sgn(t.n[1]) : sgn(t.n[axis]);
  for (int e = 0; e < 3; ++e) {
    if (perturbed_orient(t.v[e], t.v[(e + 1) % 3], a, i, j) != orient) return false;
  }
  I3 b = a;
  b[axis] += len;
  return perturbed_plane_sign(t, a) != perturbed_plane_sign(t, b);
}

bool crosses_box_edge(const ITri& t, const IBox& box) {
  for (int k = 0; k < 3; ++k)
    if (t.hi[k] < box.lo[k] || t.lo[k] > box.hi[k]) return false;
  for (int axis = 0; axis < 3; ++axis) {
    const int i = (axis + 1) % 3, j = (axis + 2) % 3;
    for (int e = 0; e < 4; ++e) {
      I3 a = box.lo;
      a[i] = (e & 1) ? box.hi[i] : box.lo[i];
      a[j] = (e & 2) ? box.hi[j] : box.lo[j];
      if (crosses(t, a, axis, box.hi[axis] - box.lo[axis])) return true;
    }
  }
  return false;
}

int count_crossings(const std::vector<ITri>& tris, const std::vector<uint32_t>& idx, const I3& a,
                    int axis, i64 len) {
  int n = 0;
  for (uint32_t k : idx) n += (tris[k].use & kUseCrossing) && crosses(tris[k], a, axis, len);
  return n;
}

bool overlaps_box(const ITri& t, const I3& lo, const I3& hi) {
  for (int k = 0; k < 3; ++k)
    if (t.hi[k] < lo[k] || t.lo[k] > hi[k]) return false;
  // Floating-point filter first (see perturbed_plane_sign): decide when the plane is clearly
  // off the box or clearly through it.
  double amin = -t.d_approx, amax = -t.d_approx, mag = std::abs(t.d_approx);
  for (int k = 0; k < 3; ++k) {
    const double x = t.n_approx[k] * double(lo[k]), y = t.n_approx[k] * double(hi[k]);
    amin += std::min(x, y);
    amax += std::max(x, y);
    mag += std::max(std::abs(x), std::abs(y));
  }
  const double bound = mag * 0x1p-48;
  if (amin > bound || amax < -bound) return false;
  if (amin < -bound && amax > bound) return true;
  i128 fmin = -t.d, fmax = -t.d;
  for (int k = 0; k < 3; ++k) {
    const i128 x = t.n[k] * lo[k], y = t.n[k] * hi[k];
    fmin += std::min(x, y);
    fmax += std::max(x, y);
  }
  return fmin <= 0 && fmax >= 0;
}

bool edges_may_touch_box(const ITri& t, const I3& lo, const I3& hi) {
  // Coordinates relative to the box centre (exact in double: below 2^33).
  double v[3][3], half[3];
  for (int k = 0; k < 3; ++k) {
    const double c = (double(lo[k]) + double(hi[k])) / 2;
    half[k] = (double(hi[k]) - double(lo[k])) / 2;
    for (int i = 0; i < 3; ++i) v[i][k] = double(t.v[i][k]) - c;
  }
  for (int e = 0; e < 3; ++e) {
    const double* a = v[e];
    const double* b = v[(e + 1) % 3];
    const double f[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    for (int k = 0; k < 3; ++k) {
      // Axis = unit vector k x f: components (i, j) = (-f[j], f[i]) for (i, j) the other two.
      const int i = (k + 1) % 3, j = (k + 2) % 3;
      double pmin = kHuge, pmax = -kHuge, mag = 0;
      for (const auto& w : v) {
        const double p = -f[j] * w[i] + f[i] * w[j];
        pmin = std::min(pmin, p);
        pmax = std::max(pmax, p);
        mag = std::max(mag, std::abs(f[j] * w[i]) + std::abs(f[i] * w[j]));
      }
      const double r = half[i] * std::abs(f[j]) + half[j] * std::abs(f[i]);
      const double slack = kProductRounding * (mag + r) + 1;
      if (pmin > r + slack || pmax < -r - slack) return false;
    }
  }
  return true;
}

ChildEdgeTest::ChildEdgeTest(const ITri& t, const IBox& parent) {
  double v[3][3];
  for (int k = 0; k < 3; ++k) {
    const double c = (double(parent.lo[k]) + double(parent.hi[k])) / 2;
    for (int i = 0; i < 3; ++i) v[i][k] = double(t.v[i][k]) - c;
  }
  const double q = (double(parent.hi[0]) - double(parent.lo[0])) / 4;  // a child's half size
  for (int e = 0; e < 3; ++e) {
    const double* a = v[e];
    const double* b = v[(e + 1) % 3];
    const double f[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    for (int k = 0; k < 3; ++k) {
      const int i = (k + 1) % 3, j = (k + 2) % 3, x = 3 * e + k;
      double mag = 0;
      pmin_[x] = kHuge, pmax_[x] = -kHuge;
      for (const auto& w : v) {
        const double p = -f[j] * w[i] + f[i] * w[j];
        pmin_[x] = std::min(pmin_[x], p);
        pmax_[x] = std::max(pmax_[x], p);
        mag = std::max(mag, std::abs(f[j] * w[i]) + std::abs(f[i] * w[j]));
      }
      // q is a power of two: the shift's terms are exact.
      a_[x] = f[j] * q;
      b_[x] = f[i] * q;
      const double r = q * (std::abs(f[j]) + std::abs(f[i]));
      // About the child's centre the vertices' terms grow by at most r: edges_may_touch_box's margin.
      reach_[x] = r + (kProductRounding * (mag + 2 * r) + 1);
    }
  }
}

bool ChildEdgeTest::may_touch(int c) const {
  for (int x = 0; x < 9; ++x) {
    const int k = x % 3, i = (k + 1) % 3, j = (k + 2) % 3;
    // The axis (-f_j, f_i) at the child's centre offset (+-q, +-q).
    const double shift = ((c >> i) & 1 ? -a_[x] : a_[x]) + ((c >> j) & 1 ? b_[x] : -b_[x]);
    if (pmin_[x] - shift > reach_[x] || pmax_[x] - shift < -reach_[x]) return false;
  }
  return true;
}

namespace {

/// The part of `t` inside the closed box, under clipped_area's perturbation convention, in
/// one of `bufs`; null when there is none. `whole`: no clipping was needed (bufs[0] is `t`).
/// `low_face`: the null is a piece lying in one of the box's low faces.
const Poly* clip_to_box(const ITri& t, const IBox& box, Poly (&bufs)[2], bool& whole, bool* low_face = nullptr) {
  for (int k = 0; k < 3; ++k)
    if (t.hi[k] < box.lo[k] || t.lo[k] > box.hi[k]) return nullptr;
  int cur = 0;
  bufs[0].n = 3;
  for (int k = 0; k < 3; ++k) bufs[0].p[k] = to_unit(t.v[k]);
  // Wholly inside the box, away from its low faces: no clipping needed.
  whole = t.lo[0] > box.lo[0] && t.lo[1] > box.lo[1] && t.lo[2] > box.lo[2] && t.hi[0] <= box.hi[0] &&
          t.hi[1] <= box.hi[1] && t.hi[2] <= box.hi[2];
  if (whole) return &bufs[0];
  // Only the planes the triangle's box crosses can cut it (exact: same integer bounds).
  for (int k = 0; k < 3; ++k) {
    if (t.hi[k] > box.hi[k]) {
      clip(bufs[cur], bufs[1 - cur], k, grid_to_unit(box.hi[k]), true);
      cur = 1 - cur;
      if (bufs[cur].n == 0) return nullptr;
    }
    if (t.lo[k] < box.lo[k]) {
      clip(bufs[cur], bufs[1 - cur], k, grid_to_unit(box.lo[k]), false);
      cur = 1 - cur;
      if (bufs[cur].n == 0) return nullptr;
    }
  }
  const Poly& poly = bufs[cur];
  const Vec3 lo = to_unit(box.lo);
  for (int k = 0; k < 3; ++k) {
    bool all_low = true;
    for (int q = 0; q < poly.n && all_low; ++q) all_low = poly.p[q][k] == lo[k];
    if (all_low) {  // lies in a low face: the perturbation hands it to the neighbour
      if (low_face) *low_face = true;
      return nullptr;
    }
  }
  return &poly;
}

}  // namespace

double clipped_area(const ITri& t, const IBox& box) {
  Poly bufs[2];
  bool whole = false, low_face = false;
  const Poly* poly = clip_to_box(t, box, bufs, whole, &low_face);
  if (!poly) return low_face ? kTouchesLowFace : -1;
  if (whole) return t.area;
  Vec3 acc{0, 0, 0};
  for (int q = 1; q + 1 < poly->n; ++q) {
    const Vec3 c = cross3(sub3(poly->p[q], poly->p[0]), sub3(poly->p[q + 1], poly->p[0]));
    acc = {acc[0] + c[0], acc[1] + c[1], acc[2] + c[2]};
  }
  return 0.5 * std::sqrt(dot3(acc, acc));
}

std::optional<Vec3> point_in_box(const ITri& t, const IBox& box) {
  Poly bufs[2];
  bool whole = false;
  const Poly* poly = clip_to_box(t, box, bufs, whole);
  if (!poly) return std::nullopt;
  Vec3 mean{0, 0, 0};
  for (int q = 0; q < poly->n; ++q)
    for (int k = 0; k < 3; ++k) mean[k] += poly->p[q][k] / poly->n;
  return mean;
}

double crossing_param(const ITri& t, const I3& a, int axis, i64 len) {
  const i128 f = t.n[0] * a[0] + t.n[1] * a[1] + t.n[2] * a[2] - t.d;
  const double den = static_cast<double>(t.n[axis]) * static_cast<double>(len);
  if (den == 0) return 0.5;
  return std::clamp(-static_cast<double>(f) / den, 0.0, 1.0);
}

bool triangles_meet_in_box(const ITri& a, const ITri& b, const IBox& box) {
  for (int k = 0; k < 3; ++k) {
    if (a.hi[k] < b.lo[k] || b.hi[k] < a.lo[k]) return false;
  }
  const std::array<Vec3, 3> pa = {to_unit(a.v[0]), to_unit(a.v[1]), to_unit(a.v[2])};
  const std::array<Vec3, 3> pb = {to_unit(b.v[0]), to_unit(b.v[1]), to_unit(b.v[2])};
  const Vec3 na = cross3(sub3(pa[1], pa[0]), sub3(pa[2], pa[0]));
  const Vec3 nb = cross3(sub3(pb[1], pb[0]), sub3(pb[2], pb[0]));
  const double la = std::sqrt(dot3(na, na)), lb = std::sqrt(dot3(nb, nb));
  if (la == 0 || lb == 0) return false;
  const Vec3 lo = to_unit(box.lo), hi = to_unit(box.hi);
  // Signed distances of each triangle's vertices to the other's plane.
  std::array<double, 3> da, db;
  for (int k = 0; k < 3; ++k) {
    db[k] = dot3(nb, sub3(pa[k], pb[0])) / lb;  // a's vertices vs plane b
    da[k] = dot3(na, sub3(pb[k], pa[0])) / la;  // b's vertices vs plane a
  }
  for (auto* d : {&da, &db})
    for (double& x : *d)
      if (std::abs(x) < kPlaneSnap) x = 0;  // snap near-zero distances to the plane
  auto same_side = [](const std::array<double, 3>& d) {
    return (d[0] > 0 && d[1] > 0 && d[2] > 0) || (d[0] < 0 && d[1] < 0 && d[2] < 0);
  };
  if (same_side(da) || same_side(db)) return false;
  const bool coplanar = da[0] == 0 && da[1] == 0 && da[2] == 0;
  if (coplanar) {
    // Coplanar overlapping sheets (e.g. coincident box faces): count as meeting when the
    // bounding boxes overlap inside the cell; the QEF then sees one plane twice.
    for (int k = 0; k < 3; ++k) {
      const double l = std::max({lo[k], std::min({pa[0][k], pa[1][k], pa[2][k]}),
                                 std::min({pb[0][k], pb[1][k], pb[2][k]})});
      const double h = std::min({hi[k], std::max({pa[0][k], pa[1][k], pa[2][k]}),
                                 std::max({pb[0][k], pb[1][k], pb[2][k]})});
      if (l > h) return false;
    }
    return true;
  }
  // Segment where a triangle crosses the other's plane.
  auto plane_segment = [](const std::array<Vec3, 3>& p, const std::array<double, 3>& d, Vec3& s0,
                          Vec3& s1) {
    int n = 0;
    Vec3 pts[3];
    for (int k = 0; k < 3 && n < 2; ++k) {
      const int m = (k + 1) % 3;
      if (d[k] == 0) {
        pts[n++] = p[k];
      } else if ((d[k] < 0 && d[m] > 0) || (d[k] > 0 && d[m] < 0)) {
        const double s = d[k] / (d[k] - d[m]);
        pts[n++] = {p[k][0] + s * (p[m][0] - p[k][0]), p[k][1] + s * (p[m][1] - p[k][1]),
                    p[k][2] + s * (p[m][2] - p[k][2])};
      }
    }
    if (n == 0) return false;
    s0 = pts[0];
    s1 = n > 1 ? pts[1] : pts[0];
    return true;
  };
  Vec3 a0, a1, b0, b1;
  if (!plane_segment(pa, db, a0, a1) || !plane_segment(pb, da, b0, b1)) return false;
  const Vec3 dir = cross3(na, nb);
  const double ta0 = dot3(dir, a0), ta1 = dot3(dir, a1), tb0 = dot3(dir, b0), tb1 = dot3(dir, b1);
  const double amin = std::min(ta0, ta1), amax = std::max(ta0, ta1);
  const double bmin = std::min(tb0, tb1), bmax = std::max(tb0, tb1);
  const double smin = std::max(amin, bmin), smax = std::min(amax, bmax);
  if (smin > smax) return false;
  // The common segment, as points on a's segment.
  auto at = [&](double tv) {
    const double span = ta1 - ta0;
    const double s = span == 0 ? 0 : (tv - ta0) / span;
    return Vec3{a0[0] + s * (a1[0] - a0[0]), a0[1] + s * (a1[1] - a0[1]), a0[2] + s * (a1[2] - a0[2])};
  };
  Vec3 p = at(smin), q = at(smax);
  // Slab clip of segment p-q against the closed box.
  double t0 = 0, t1 = 1;
  for (int k = 0; k < 3; ++k) {
    const double d = q[k] - p[k];
    if (d == 0) {
      if (p[k] < lo[k] || p[k] > hi[k]) return false;
      continue;
    }
    double u0 = (lo[k] - p[k]) / d, u1 = (hi[k] - p[k]) / d;
    if (u0 > u1) std::swap(u0, u1);
    t0 = std::max(t0, u0);
    t1 = std::min(t1, u1);
    if (t0 > t1) return false;
  }
  return true;
}

double point_triangle_distance2(const Vec3& p, const ITri& t) {
  return point_triangle_distance2(p, to_unit(t.v[0]), to_unit(t.v[1]), to_unit(t.v[2]));
}

Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  // Ericson, Real-Time Collision Detection 5.1.5: closest point by Voronoi regions.
  const Vec3 ab = sub3(b, a), ac = sub3(c, a), ap = sub3(p, a);
  auto d2 = [](const Vec3& q) { return q; };
  const double d1 = dot3(ab, ap), d2v = dot3(ac, ap);
  if (d1 <= 0 && d2v <= 0) return d2(a);
  const Vec3 bp = sub3(p, b);
  const double d3 = dot3(ab, bp), d4 = dot3(ac, bp);
  if (d3 >= 0 && d4 <= d3) return d2(b);
  const double vc = d1 * d4 - d3 * d2v;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 / (d1 - d3);
    return d2({a[0] + v * ab[0], a[1] + v * ab[1], a[2] + v * ab[2]});
  }
  const Vec3 cp = sub3(p, c);
  const double d5 = dot3(ab, cp), d6 = dot3(ac, cp);
  if (d6 >= 0 && d5 <= d6) return d2(c);
  const double vb = d5 * d2v - d1 * d6;
  if (vb <= 0 && d2v >= 0 && d6 <= 0) {
    const double w = d2v / (d2v - d6);
    return d2({a[0] + w * ac[0], a[1] + w * ac[1], a[2] + w * ac[2]});
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return d2({b[0] + w * (c[0] - b[0]), b[1] + w * (c[1] - b[1]), b[2] + w * (c[2] - b[2])});
  }
  const double denom = 1 / (va + vb + vc);
  const double v = vb * denom, w = vc * denom;
  return d2({a[0] + ab[0] * v + ac[0] * w, a[1] + ab[1] * v + ac[1] * w, a[2] + ab[2] * v + ac[2] * w});
}

double point_triangle_distance2(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 v = sub3(p, closest_point_on_triangle(p, a, b, c));
  return dot3(v, v);
}

I3 to_grid(const Vec3& u) {
  return {std::llround(u[0] * kGridScale), std::llround(u[1] * kGridScale),
          std::llround(u[2] * kGridScale)};
}

bool grid_is_simple(const std::array<bool, 27>& g) {
  auto at = [&](int a, int b, int c) { return g[a + 3 * b + 9 * c]; };
  // Edges: a midpoint between two equal corners must agree with them.
  for (int axis = 0; axis < 3; ++axis)
    for (int u = 0; u < 3; u += 2)
      for (int v = 0; v < 3; v += 2) {
        int p0[3], p1[3], m[3];
        const int i = (axis + 1) % 3, j = (axis + 2) % 3;
        p0[axis] = 0, p1[axis] = 2, m[axis] = 1;
        p0[i] = p1[i] = m[i] = u;
        p0[j] = p1[j] = m[j] = v;
        const bool s0 = at(p0[0], p0[1], p0[2]), s1 = at(p1[0], p1[1], p1[2]);
        if (s0 == s1 && at(m[0], m[1], m[2]) != s0) return false;
      }
  // Faces: with four equal corners the centre agrees.
  for (int axis = 0; axis < 3; ++axis)
    for (int w = 0; w < 3; w += 2) {
      const int i = (axis + 1) % 3, j = (axis + 2) % 3;
      int q[3];
      q[axis] = w;
      bool first = true, same = true, s0 = false;
      for (int u = 0; u < 3; u += 2)
        for (int v = 0; v < 3; v += 2) {
          q[i] = u, q[j] = v;
          const bool sv = at(q[0], q[1], q[2]);
          if (first) s0 = sv, first = false;
          same = same && sv == s0;
        }
      q[i] = q[j] = 1;
      if (same && at(q[0], q[1], q[2]) != s0) return false;
    }
  // Each sign class 6-connected over the grid.
  for (bool inside : {false, true}) {
    int seen = 0, stack = 0, total = 0, start = -1;
    for (int k = 0; k < 27; ++k)
      if (g[k] == inside) {
        ++total;
        if (start < 0) start = k;
      }
    if (total == 0) continue;
    seen = stack = 1 << start;
    int count = 0;
    while (stack) {
      const int k = __builtin_ctz(stack);
      stack &= stack - 1;
      ++count;
      const int a = k % 3, b = (k / 3) % 3, c = k / 9;
      const int nb[6][3] = {{a - 1, b, c}, {a + 1, b, c}, {a, b - 1, c}, {a, b + 1, c}, {a, b, c - 1}, {a, b, c + 1}};
      for (const auto& n : nb) {
        if (n[0] < 0 || n[0] > 2 || n[1] < 0 || n[1] > 2 || n[2] < 0 || n[2] > 2) continue;
        const int kk = n[0] + 3 * n[1] + 9 * n[2];
        if (g[kk] == inside && !((seen >> kk) & 1)) {
          seen |= 1 << kk;
          stack |= 1 << kk;
        }
      }
    }
    if (count != total) return false;
  }
  return true;
}

bool one_component(uint8_t signs) {
  static const std::array<uint8_t, 256> table = make_component_table();
  return table[signs] != 0;
}

}  // namespace pic::detail

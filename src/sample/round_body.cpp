// A round body and the sum swept by it: see round_body.h.
#include "sample/round_body.h"

#include <algorithm>
#include <cmath>

#include "geometry/convex_hull.h"
#include "geometry/tolerances.h"
#include "geometry/vec3.h"

namespace pic::detail {

std::pair<double, Vec3> RoundBody::support_point(const Vec3& u) const {
  double h = -kHuge;
  Vec3 top{0, 0, 0};
  for (const Vec3& v : rel)
    if (const double x = dot3(v, u); x > h) h = x, top = v;
  return {h, top};
}

namespace {

RoundBody round_body(const std::vector<Vec3>& points) {
  RoundBody b;
  for (const Vec3& p : points) b.centre = add3(b.centre, p);
  b.centre = scale3(b.centre, 1.0 / double(points.size()));
  for (const Vec3& p : points) {
    b.rel.push_back(sub3(p, b.centre));
    b.outer = std::max(b.outer, norm3(b.rel.back()));
  }
  // The inradius about the centre is the support's minimum over directions, reached at a
  // facet's normal: the nearest of the hull's facet planes.
  const TriMesh hull = convex_hull(points);
  b.inner = hull.triangles.empty() ? 0 : kHuge;
  for (const auto& t : hull.triangles) {
    const Vec3& a = hull.positions[t[0]];
    const Vec3 n = cross3(sub3(hull.positions[t[1]], a), sub3(hull.positions[t[2]], a));
    const double len = norm3(n);
    if (len > 0) b.inner = std::min(b.inner, dot3(n, sub3(a, b.centre)) / len);
  }
  b.inner = std::max(b.inner, 0.0);
  return b;
}

/// The gradient of d - h(u) at distance d > 0, where the support is reached at the vertex
/// `top` (h is linear in u near it). u is fixed over a face's region and turns about an
/// edge's line over the edge's region and about the point over a vertex's: there
/// grad u = (I - uu^T - ee^T) / d (e along the edge; no e term at a vertex), so
/// grad (d - h) = u - grad u . top.
Vec3 support_gradient(const TriMesh& surface, const Nearest& at, const Vec3& u, double d, const Vec3& top) {
  if (at.feature == Feature::Face) return u;
  // top without its parts along u (and along the edge): how far the support moves as u turns.
  Vec3 turn = sub3(top, scale3(u, dot3(u, top)));
  if (at.feature == Feature::E01 || at.feature == Feature::E12 || at.feature == Feature::E20) {
    const int k = at.feature == Feature::E01 ? 0 : at.feature == Feature::E12 ? 1 : 2;
    const auto& t = surface.triangles[at.triangle];
    const Vec3 e = sub3(surface.positions[t[(k + 1) % 3]], surface.positions[t[k]]);
    const double len2 = dot3(e, e);
    if (len2 > 0) turn = sub3(turn, scale3(e, dot3(e, turn) / len2));
  }
  return sub3(u, scale3(turn, 1 / d));
}

}  // namespace

std::optional<RoundBody> round_body_if_round(const std::vector<Vec3>& points) {
  if (points.size() < 4) return std::nullopt;
  for (const Vec3& p : points)
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) return std::nullopt;
  RoundBody b = round_body(points);
  if (!(b.outer > 0 && b.inner >= 0.98 * b.outer)) return std::nullopt;
  return b;
}

double RoundSum::operator()(const Vec3& p, Vec3& gradient, uint32_t* hint, double* distance, Vec3* nearest) const {
  Nearest at;
  const double d = distance_.with_gradient(p, gradient, hint, nearest, &at);
  if (distance) *distance = d;
  if (!(d > 0)) return d - body_.inner;
  const auto [h, top] = body_.support_point(gradient);
  gradient = support_gradient(surface_, at, gradient, d, top);
  return d - h;
}

}  // namespace pic::detail

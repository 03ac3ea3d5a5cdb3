// A round body and the sum swept by it: see round_body.h.
#include "sample/round_body.h"

#include <algorithm>
#include <cmath>

#include "geometry/convex_hull.h"
#include "geometry/tolerances.h"
#include "geometry/vec3.h"

namespace pic::detail {

namespace {

/// The direction through the point of the cube face `face` (axis face / 2, sign by face % 2)
/// at coordinates (x, y) in [-1, 1] along the face's other two axes.
Vec3 face_direction(int face, double x, double y) {
  const int a = face / 2;
  Vec3 d{0, 0, 0};
  d[a] = face % 2 ? -1 : 1;
  d[(a + 1) % 3] = x;
  d[(a + 2) % 3] = y;
  return scale3(d, 1 / norm3(d));
}

}  // namespace

int RoundBody::cell_of(const Vec3& u) const {
  int a = 0;
  for (int k = 1; k < 3; ++k)
    if (std::abs(u[k]) > std::abs(u[a])) a = k;
  const double m = std::abs(u[a]);
  if (!(m > 0) || !std::isfinite(m)) return -1;
  auto bin = [&](double t) { return std::clamp(int((t / m + 1) / 2 * side_), 0, side_ - 1); };
  const int face = 2 * a + (u[a] < 0);
  return (face * side_ + bin(u[(a + 1) % 3])) * side_ + bin(u[(a + 2) % 3]);
}

std::pair<double, Vec3> RoundBody::support_point(const Vec3& u) const {
  double h = -kHuge;
  Vec3 top{0, 0, 0};
  const int cell = side_ > 0 ? cell_of(u) : -1;
  if (cell < 0) {
    for (const Vec3& v : rel)
      if (const double x = dot3(v, u); x > h) h = x, top = v;
    return {h, top};
  }
  // The cell's candidates hold every vertex that can reach the support there, in the order
  // of `rel`: the first maximum is the one the whole scan finds.
  for (uint32_t i = first_[cell]; i < first_[cell + 1]; ++i)
    if (const double x = dot3(rel[candidates_[i]], u); x > h) h = x, top = rel[candidates_[i]];
  return {h, top};
}

void RoundBody::index_directions() {
  // Cells about 1/side of a face wide: the candidates thin out with the cell's angle, the
  // build costs cells times vertices (bounded here).
  side_ = int(std::clamp(std::sqrt(2e7 / (6.0 * double(std::max<size_t>(rel.size(), 1)))), 1.0, 32.0));
  const int cells = 6 * side_ * side_;
  first_.assign(size_t(cells) + 1, 0);
  candidates_.clear();
  for (int cell = 0; cell < cells; ++cell) {
    const int face = cell / (side_ * side_), i = (cell / side_) % side_, j = cell % side_;
    const auto at = [&](double t) { return 2 * t / side_ - 1; };
    const Vec3 mid = face_direction(face, at(i + 0.5), at(j + 0.5));
    // Every unit direction of the cell lies within `chord` of mid: the cell is convex on
    // the sphere, so its farthest points are its corners.
    double chord = 0;
    for (int c = 0; c < 4; ++c)
      chord = std::max(chord, norm3(sub3(face_direction(face, at(i + (c & 1)), at(j + (c >> 1))), mid)));
    // Over the cell a vertex's v.u moves by at most |v| chord, as does the support: one
    // more than 2 outer chord below the support at mid never reaches it (a margin above
    // rounding, and for a u a hair off unit length).
    chord = chord * (1 + 1e-6) + 1e-9;
    double h = -kHuge;
    for (const Vec3& v : rel) h = std::max(h, dot3(v, mid));
    const double floor = h - 2 * outer * chord - 1e-9 * outer;
    for (uint32_t k = 0; k < rel.size(); ++k)
      if (dot3(rel[k], mid) >= floor) candidates_.push_back(k);
    first_[size_t(cell) + 1] = uint32_t(candidates_.size());
  }
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

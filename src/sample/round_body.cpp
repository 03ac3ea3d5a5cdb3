// A round body and the sum swept by it: see round_body.h.
#include "sample/round_body.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <numeric>

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

/// Triangle t's normal scaled by twice its area (zero for a triangle without area).
Vec3 area_normal(const TriMesh& mesh, size_t t) {
  const auto& tri = mesh.triangles[t];
  const Vec3& a = mesh.positions[tri[0]];
  return cross3(sub3(mesh.positions[tri[1]], a), sub3(mesh.positions[tri[2]], a));
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
  facet_first_.assign(size_t(cells) + 1, 0);
  facet_list_.clear();
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
    // Facets within near_angle of a direction of the cell: within that plus the cell's
    // angular radius of mid (a hair more for rounding).
    const double radius = 2 * std::asin(std::min(chord / 2, 1.0)) + 1e-9;
    const double facet_cos = std::cos(std::min(near_angle() + radius, std::numbers::pi));
    for (uint32_t f = 0; f < facet_normal.size(); ++f)
      if (dot3(facet_normal[f], mid) >= facet_cos) facet_list_.push_back(f);
    facet_first_[size_t(cell) + 1] = uint32_t(facet_list_.size());
  }
}

double RoundBody::near_angle() const {
  if (!(inner > 0)) return std::numbers::pi;
  return std::acos(std::clamp(1 - 2 * (outer - inner) / inner, -1.0, 1.0));
}

RoundBody::Near RoundBody::near(const Vec3& u) const {
  const int cell = cell_of(u);
  if (cell < 0) return {nullptr, nullptr};
  return {facet_list_.data() + facet_first_[cell], facet_list_.data() + facet_first_[cell + 1]};
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
  std::vector<Vec3> normal(hull.triangles.size(), Vec3{0, 0, 0});
  for (size_t i = 0; i < hull.triangles.size(); ++i) {
    const Vec3 n = area_normal(hull, i);
    const double len = norm3(n);
    if (!(len > 0)) continue;
    normal[i] = scale3(n, 1 / len);
    const double support = dot3(normal[i], sub3(hull.positions[hull.triangles[i][0]], b.centre));
    b.inner = std::min(b.inner, support);
    // Pieces of one facet (a quad split in two) give it once.
    const bool seen = std::any_of(b.facet_normal.begin(), b.facet_normal.end(),
                                  [&](const Vec3& m) { return dot3(m, normal[i]) >= 1 - kSamePlaneCosine; });
    if (!seen) b.facet_normal.push_back(normal[i]), b.facet_support.push_back(support);
  }
  b.inner = std::max(b.inner, 0.0);
  // Each edge once, from the two triangles that share it (a closed hull).
  std::map<std::pair<uint32_t, uint32_t>, size_t> first;
  for (size_t i = 0; i < hull.triangles.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      const uint32_t u = hull.triangles[i][k], v = hull.triangles[i][(k + 1) % 3];
      const auto key = std::minmax(u, v);
      const auto [it, fresh] = first.emplace(key, i);
      if (fresh) continue;
      const Vec3 &n1 = normal[it->second], &n2 = normal[i];
      // Coplanar pieces of one facet (a quad split in two) bound no arc.
      if (norm3(n1) > 0 && norm3(n2) > 0 && dot3(n1, n2) < 1 - kSamePlaneCosine)
        b.arcs.push_back({n1, n2, sub3(hull.positions[u], b.centre)});
    }
  b.face_depth = b.outer * std::tan(b.near_angle() / 4);
  return b;
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

double RoundSum::operator()(const Vec3& p, Vec3& gradient, uint32_t* hint, double* distance, Vec3* nearest,
                            uint32_t* winner) const {
  // F_T is at least d_T - outer, the nearest triangle's at most d - inner: only triangles
  // within d + outer - inner of p can give the least. Next to the sum's surface one search
  // gathers them, bounded by a nearby point's nearest triangle (the hint), and gives d too.
  thread_local std::vector<Nearest> around;
  around.clear();
  const MeshDistance& mesh = distance_.mesh_distance();
  const double spread = body_.outer - body_.inner;
  const double bound = hint ? mesh.distance_to_hint(p, *hint) : kHuge;
  Nearest n;
  size_t least = 0;
  if (bound <= 2 * body_.outer) least = mesh.nearest_within(p, (bound + spread) * (1 + 1e-9) + kTinyDivisor, around);
  if (!around.empty()) {
    n = around[least];
    *hint = mesh.hint_of(n.triangle);
  } else {
    n = mesh.nearest(p, hint);
  }
  const double d = distance_.signed_at(p, n, gradient);
  if (distance) *distance = d;
  if (nearest) *nearest = n.point;
  if (!(d > 0)) return d - body_.inner;
  const double reach = (d + spread) * (1 + 1e-9) + kTinyDivisor;
  if (around.empty()) mesh.nearest_within(p, reach, around);
  // The hint's bound gathers a wider shell: on a mesh of small triangles several times as many.
  std::erase_if(around, [&](const Nearest& t) { return t.distance > reach; });
  uint32_t won = 0;
  const double f = outside(p, d, around, gradient, won);
  if (winner) *winner = won;
  return f;
}

double RoundSum::outside(const Vec3& p, double d, const std::vector<Nearest>& around, Vec3& gradient,
                         uint32_t& winner) const {
  // `around`: every triangle within d + outer - inner of p (F_T is at least d_T - outer, the
  // nearest triangle's at most d - inner: no other can come lower) with its point nearest p.
  // Nearest first: F_T is at least its value along u_T, d_T - h_B(u_T), so a triangle whose
  // value there is no lower than the best so far needs no search of its facets.
  thread_local std::vector<uint32_t> order;
  order.resize(around.size());
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](uint32_t x, uint32_t y) {
    return around[x].distance < around[y].distance ||
           (around[x].distance == around[y].distance && around[x].triangle < around[y].triangle);
  });
  // Skipping a triangle whose bound is no lower keeps f at most the distance to S's surface
  // outside (that T + B is no nearer than `best`) and inside (it holds p no deeper).
  double best = d - body_.inner;  // the nearest triangle's bound, should none be found
  bool found = false;
  Vec3 best_plane{0, 0, 0};  // the plane of the best value so far ...
  double best_support = 0;   // ... and B's support along it
  for (uint32_t i : order) {
    const Nearest& at = around[i];
    if (found && at.distance >= 0.5 * body_.inner) {
      // Any direction n gives n.p - h_T(n) - h_B(n), at most the distance to T + B outside
      // it and at most F_T inside: along the best plane so far (a triangle beside the best
      // one, on its plane or sharing its edge, usually gives the same), and along u_T.
      if (dot3(best_plane, p) - support_of(at.triangle, best_plane) - best_support >= best) continue;
      if (at.distance - body_.support(scale3(sub3(p, at.point), 1 / at.distance)) >= best) continue;
    }
    Vec3 g, plane;
    double support = 0;
    const double v = triangle_sum(at.triangle, p, at, g, &plane, &support);
    if (!found || v < best) {
      best = v, gradient = g, winner = at.triangle;
      best_plane = plane, best_support = support;
    }
    found = true;
  }
  return best;
}

double RoundSum::support_of(uint32_t t, const Vec3& n) const {
  const auto& tri = surface_.triangles[t];
  return std::max({dot3(n, surface_.positions[tri[0]]), dot3(n, surface_.positions[tri[1]]),
                   dot3(n, surface_.positions[tri[2]])});
}

Nearest RoundSum::nearest_point(uint32_t t, const Vec3& p) const {
  const auto& tri = surface_.triangles[t];
  return nearest_on_triangle(p, surface_.positions[tri[0]], surface_.positions[tri[1]], surface_.positions[tri[2]]);
}

bool RoundSum::box_clear(const Vec3& lo, const Vec3& hi, double d, double f, uint32_t winner) const {
  const Vec3 c = scale3(add3(lo, hi), 0.5), half_side = scale3(sub3(hi, lo), 0.5);
  const double half = norm3(half_side);
  // How far the box reaches along n from its centre.
  const auto width = [&](const Vec3& n) {
    return std::abs(n[0]) * half_side[0] + std::abs(n[1]) * half_side[1] + std::abs(n[2]) * half_side[2];
  };
  if (!(d > half)) return false;  // the box may meet the solid itself
  thread_local std::vector<Nearest> near_c;
  const MeshDistance& mesh = distance_.mesh_distance();
  if (f < 0) {
    // Inside T + B, a convex polytope, with all eight corners: the box is in the sum.
    for (int k = 0; k < 8; ++k) {
      const Vec3 x{k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1], k & 4 ? hi[2] : lo[2]};
      Vec3 gx;
      if (!(triangle_sum(winner, x, nearest_point(winner, x), gx) < 0)) return false;
    }
    return true;
  }
  // Outside: every T + B that may reach the box (T within outer of it) lies beyond the plane
  // its facet search at the centre found (a supporting plane of T + B), the box on the other
  // side of it.
  mesh.nearest_within(c, (body_.outer + half) * (1 + 1e-9) + kTinyDivisor, near_c);
  for (const Nearest& at : near_c) {
    Vec3 g, n;
    const double v = triangle_sum(at.triangle, c, at, g, &n);
    if (!(at.distance >= 0.5 * body_.inner) || !(v - width(n) > 0)) return false;
  }
  return true;
}

namespace {

/// A number that grows with the angle of (x, y) from the x axis, once round from -pi to pi
/// (the position on the square |x| + |y| = 1 about the origin): an order without atan2.
double pseudo_angle(double x, double y) {
  const double sum = std::abs(x) + std::abs(y);
  if (!(sum > 0)) return 0;
  const double t = y / sum;  // -1 .. 1 on each half
  return x >= 0 ? t : (y >= 0 ? 2 - t : -2 - t);
}

/// How far x lies inside the side from p to q of triangle pqr, along the triangle's plane
/// (x on that plane; negative outside).
double inside_side(const Vec3& p, const Vec3& q, const Vec3& r, const Vec3& x) {
  const Vec3 e = sub3(q, p), w = sub3(r, p);
  const double len2 = dot3(e, e);
  if (!(len2 > 0)) return -kHuge;
  const Vec3 m = sub3(w, scale3(e, dot3(w, e) / len2));  // towards r, across the side
  const double len = norm3(m);
  return len > 0 ? dot3(sub3(x, p), m) / len : -kHuge;
}

}  // namespace

RoundSum::RoundSum(const TriMesh& surface, const RoundBody& body)
    : surface_(surface), body_(body), distance_(surface), across_(flat_neighbours(surface)) {
  // One zone per side, shared by the two triangles on it.
  zone_of_.assign(3 * surface.triangles.size(), 0);
  std::map<std::pair<uint32_t, uint32_t>, uint32_t> numbered;
  for (uint32_t t = 0; t < surface.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const auto key = std::minmax(surface.triangles[t][k], surface.triangles[t][(k + 1) % 3]);
      zone_of_[3 * t + k] = numbered.emplace(key, uint32_t(numbered.size())).first->second;
    }
  zones_ = std::vector<std::atomic<const Zone*>>(numbered.size());
  // Each triangle's unit normal and B's supports along it, either way.
  face_.resize(surface.triangles.size());
  for (size_t t = 0; t < surface.triangles.size(); ++t) {
    const Vec3 n = area_normal(surface, t);
    const double len = norm3(n);
    if (!(len > 0)) continue;
    face_[t].normal = scale3(n, 1 / len);
    face_[t].up = body.support(face_[t].normal);
    face_[t].down = body.support(scale3(face_[t].normal, -1));
  }
}

RoundSum::~RoundSum() {
  for (auto& z : zones_) delete z.load();
}

const RoundSum::Zone& RoundSum::zone(uint32_t t, int k) const {
  std::atomic<const Zone*>& slot = zones_[zone_of_[3 * t + k]];
  if (const Zone* z = slot.load(std::memory_order_acquire)) return *z;
  const auto& tri = surface_.triangles[t];
  const Vec3 e = sub3(surface_.positions[tri[(k + 1) % 3]], surface_.positions[tri[k]]);
  auto* z = new Zone;
  const double len = norm3(e);
  if (len > 0) {
    z->axis = scale3(e, 1 / len);
    // Any unit direction across the edge, and the one across both.
    const int least = std::abs(z->axis[0]) <= std::abs(z->axis[1]) && std::abs(z->axis[0]) <= std::abs(z->axis[2]) ? 0
                      : std::abs(z->axis[1]) <= std::abs(z->axis[2]) ? 1 : 2;
    Vec3 pick{0, 0, 0};
    pick[least] = 1;
    z->a1 = cross3(z->axis, pick);
    z->a1 = scale3(z->a1, 1 / norm3(z->a1));
    z->a2 = cross3(z->axis, z->a1);
    std::vector<std::pair<double, size_t>> order;
    for (const RoundBody::Arc& arc : body_.arcs) {
      const double s1 = dot3(arc.n1, z->axis), s2 = dot3(arc.n2, z->axis);
      if (!((s1 < 0 && s2 > 0) || (s1 > 0 && s2 < 0))) continue;
      const Vec3 m = add3(scale3(arc.n1, std::abs(s2)), scale3(arc.n2, std::abs(s1)));
      const double m_len = norm3(m);
      if (!(m_len > 0)) continue;
      const Vec3 n = scale3(m, 1 / m_len);
      order.push_back({pseudo_angle(dot3(n, z->a1), dot3(n, z->a2)), z->normal.size()});
      z->normal.push_back(n);
      z->support.push_back(dot3(n, arc.at));
    }
    std::sort(order.begin(), order.end());
    Zone sorted = *z;
    for (size_t i = 0; i < order.size(); ++i) {
      sorted.angle.push_back(order[i].first);
      sorted.normal[i] = z->normal[order[i].second];
      sorted.support[i] = z->support[order[i].second];
    }
    *z = std::move(sorted);
  }
  const Zone* expected = nullptr;
  if (slot.compare_exchange_strong(expected, z, std::memory_order_acq_rel)) return *z;
  delete z;  // another thread's is in
  return *expected;
}

std::vector<uint32_t> RoundSum::flat_neighbours(const TriMesh& surface) {
  std::vector<uint32_t> across(3 * surface.triangles.size(), kNoTriangle);
  std::map<std::pair<uint32_t, uint32_t>, uint32_t> side;  // directed side -> 3 t + k
  std::vector<Vec3> normal(surface.triangles.size());
  for (uint32_t t = 0; t < surface.triangles.size(); ++t) {
    normal[t] = area_normal(surface, t);
    for (int k = 0; k < 3; ++k) side.emplace(std::pair{surface.triangles[t][k], surface.triangles[t][(k + 1) % 3]}, 3 * t + k);
  }
  for (uint32_t t = 0; t < surface.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const auto it = side.find({surface.triangles[t][(k + 1) % 3], surface.triangles[t][k]});
      if (it == side.end()) continue;
      const Vec3 &n = normal[t], &m = normal[it->second / 3];
      const double nn = norm3(n), mm = norm3(m);
      // Coplanar: the two share the side's line, so parallel normals make one plane.
      if (nn > 0 && mm > 0 && dot3(n, m) >= (1 - kSamePlaneCosine) * nn * mm) across[3 * t + k] = it->second / 3;
    }
  return across;
}

Vec3 RoundSum::along_gradient(uint32_t t, Feature feature, const Vec3& u, double dt, const Vec3& top) const {
  // grad d_T = u; u is fixed over T's face, turns about a side's line beside a side and about
  // the point beside a corner: there grad u = (I - uu^T - ee^T) / d_T (no e term at a corner),
  // so grad (d_T - h_B(u)) = u - grad u . top.
  if (feature == Feature::Face) return u;
  Vec3 turn = sub3(top, scale3(u, dot3(u, top)));
  if (feature == Feature::E01 || feature == Feature::E12 || feature == Feature::E20) {
    const int k = feature == Feature::E01 ? 0 : feature == Feature::E12 ? 1 : 2;
    const auto& tri = surface_.triangles[t];
    const Vec3 e = sub3(surface_.positions[tri[(k + 1) % 3]], surface_.positions[tri[k]]);
    const double len2 = dot3(e, e);
    if (len2 > 0) turn = sub3(turn, scale3(e, dot3(e, turn) / len2));
  }
  return sub3(u, scale3(turn, 1 / dt));
}

bool RoundSum::above_face_inside(uint32_t t, const Vec3& near, double dt, double cut, bool outside) const {
  // A normal n at angle t from u (t up to acos(cut)) gives at most
  // d_T cos t - rho sin t - h_B(u) + 2 outer sin(t/2), rho the distance from `near` to T's
  // sides (T's support along n is that much beyond `near`; B's support moves with n by at
  // most outer |n - u|). With rho at least outer and d_T at least outer tan(t/4) that is
  // never above d_T - h_B(u), T + B's face over T.
  // t is at most the body's near_angle (d_T at least half the inradius).
  // Outside the sum, a side that a coplanar triangle continues bounds nothing: where the disk
  // of radius outer about `near` lies in T and the triangles across such sides (each of their
  // other sides outer away), the sum of that plane piece is its face moved out there, and
  // its distance, d_T - h_B(u), is no more than any of those triangles' F_T.
  const double outer = body_.outer;
  if (!(cut > 0) || dt < body_.face_depth) return false;
  const auto& tri = surface_.triangles[t];
  for (int k = 0; k < 3; ++k) {
    const Vec3 &p = surface_.positions[tri[k]], &q = surface_.positions[tri[(k + 1) % 3]],
               &r = surface_.positions[tri[(k + 2) % 3]];
    if (inside_side(p, q, r, near) >= outer) continue;
    const uint32_t next = across_[3 * t + k];
    if (!outside || next == kNoTriangle) return false;
    const auto& other = surface_.triangles[next];
    for (int j = 0; j < 3; ++j) {
      const Vec3 &p2 = surface_.positions[other[j]], &q2 = surface_.positions[other[(j + 1) % 3]],
                 &r2 = surface_.positions[other[(j + 2) % 3]];
      // The shared side itself is the one whose far vertex is not T's.
      const bool shared = (other[j] == tri[(k + 1) % 3] && other[(j + 1) % 3] == tri[k]);
      if (!shared && inside_side(p2, q2, r2, near) < outer) return false;
    }
  }
  return true;
}

double RoundSum::triangle_sum(uint32_t t, const Vec3& p, const Nearest& at, Vec3& gradient, Vec3* plane,
                              double* plane_support) const {
  const Vec3 x = sub3(p, at.point);
  const double dt = norm3(x);
  Best best;
  if (dt < 0.5 * body_.inner) {
    // Deep in T + B: a ball of radius inner - d_T about p lies in it, and F_T is at most
    // d_T - inner. That value, not F_T, serves: it keeps |f| below the distance to S's surface.
    best.value = dt - body_.inner;
    best.gradient = best.plane = dt > 0 ? scale3(x, 1 / dt) : gradient;
    best.support = body_.support(best.plane);
  } else {
    // Along u itself (T's support there is reached at its nearest point): d_T - h_B(u), with
    // u turning as p moves over T's sides and corners.
    const Vec3 u = scale3(x, 1 / dt);
    const auto [support_u, top] = body_.support_point(u);
    best = {dt - support_u, along_gradient(t, at.feature, u, dt, top), u, support_u};
    // Any facet normal n does at most n.(p - near) - inner = d_T cos(n, u) - inner: those
    // with cos(n, u) at or below `cut` cannot beat it.
    const double cut = (best.value + body_.inner) / dt;
    if (at.feature != Feature::Face || !above_face_inside(t, at.point, dt, cut, best.value >= 0))
      facet_planes(t, p, u, cut, best);
  }
  gradient = best.gradient;
  if (plane) *plane = best.plane;
  if (plane_support) *plane_support = best.support;
  return best.value;
}

void RoundSum::facet_planes(uint32_t t, const Vec3& p, const Vec3& u, double cut, Best& best) const {
  const auto& tri = surface_.triangles[t];
  const Vec3 &a = surface_.positions[tri[0]], &b = surface_.positions[tri[1]], &c = surface_.positions[tri[2]];
  const auto consider = [&](const Vec3& n, double support_b) {
    const double v = dot3(n, p) - std::max({dot3(n, a), dot3(n, b), dot3(n, c)}) - support_b;
    if (v > best.value) best = {v, n, n, support_b};
  };
  if (body_.indexed()) {
    const RoundBody::Near near_u = body_.near(u);
    for (const uint32_t* j = near_u.facets; j != near_u.facets_end; ++j)
      if (dot3(body_.facet_normal[*j], u) > cut) consider(body_.facet_normal[*j], body_.facet_support[*j]);
  } else {
    for (size_t j = 0; j < body_.facet_normal.size(); ++j)
      if (dot3(body_.facet_normal[j], u) > cut) consider(body_.facet_normal[j], body_.facet_support[j]);
  }
  if (const Face& face = face_[t]; norm3(face.normal) > 0) {
    if (dot3(face.normal, u) > cut) consider(face.normal, face.up);
    if (-dot3(face.normal, u) > cut) consider(scale3(face.normal, -1), face.down);
  }
  // Facets of T + B that an edge of T sweeps along an edge of B: their normals are
  // perpendicular to the edge, where B's arcs cross the circle of such directions (the zone,
  // one per side of the surface), in order around it. n.u falls away from u's own direction
  // across the edge both ways round: from there, the entries with n.u above the cut.
  for (int k = 0; k < 3; ++k) {
    const Zone& z = zone(t, k);
    const size_t count = z.normal.size();
    const Vec3 across = sub3(u, scale3(z.axis, dot3(u, z.axis)));
    if (!(norm3(across) > cut) || count == 0) continue;
    const double angle_u = pseudo_angle(dot3(across, z.a1), dot3(across, z.a2));
    const size_t mid = size_t(std::lower_bound(z.angle.begin(), z.angle.end(), angle_u) - z.angle.begin());
    for (size_t step = 0; step < count; ++step) {  // upwards from mid
      const size_t i = (mid + step) % count;
      if (!(dot3(z.normal[i], u) > cut)) break;
      consider(z.normal[i], z.support[i]);
    }
    for (size_t step = 1; step < count; ++step) {  // downwards from below mid
      const size_t i = (mid + count - step) % count;
      if (!(dot3(z.normal[i], u) > cut)) break;
      consider(z.normal[i], z.support[i]);
    }
  }
}

}  // namespace pic::detail

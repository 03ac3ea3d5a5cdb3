#include "geometry/winding.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <functional>
#include <numbers>
#include <optional>

#include "geometry/tolerances.h"
#include "geometry/vec3.h"

namespace pic::detail {
namespace {

constexpr double kInv4Pi = 1.0 / (4 * std::numbers::pi);
constexpr double kNearBeta = 1.5;  // inside(): nearer nodes are never summarized


// Winding number of a dipole of vector area `area` at `x`, seen from p; `radius` clamps the
// distance so a point sample behaves like a disc of that radius next to it.
double dipole(const Vec3& p, const Vec3& x, const Vec3& area, double radius = 0) {
  const Vec3 d = sub3(x, p);
  const double r = std::max(norm3(d), radius);
  if (r == 0) return 0;
  return dot3(d, area) * kInv4Pi / (r * r * r);
}

}  // namespace

double DipoleTree::far_field(const DNode& n, const Vec3& p) {
  // w = sum_i K(x_i) . a_i with K(x) = (x - p) / (4 pi |x - p|^3), expanded at the centre c to
  // first order: K(c) . A + sum_ab dK_b/dx_a (c) S_ab, with S = sum_i (x_i - c) (x) a_i and
  // dK_b/dx_a = (delta_ab / r^3 - 3 r_a r_b / r^5) / (4 pi).
  const Vec3 r = sub3(n.centre, p);
  const double r2 = dot3(r, r), inv = 1 / std::sqrt(r2), inv3 = inv * inv * inv;
  double w = dot3(r, n.area) * inv3;
  const double trace = n.spread[0] + n.spread[4] + n.spread[8];
  double rsr = 0;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) rsr += r[a] * n.spread[3 * a + b] * r[b];
  w += trace * inv3 - 3 * rsr * inv3 / r2;
  return w * kInv4Pi;
}

double DipoleTree::truncation_bound(const DNode& n, double d) {
  // far_field is the first-order Taylor expansion, at the centre c, of the exact sum
  // sum_i int_Ti K(y) . n_i dA with K(y) = (y - p) / (4 pi |y - p|^3) = -grad(1/|y - p|) / (4 pi).
  // Its remainder is at most 1/2 sup |grad^2 K| int |y - c|^2 |dA|, and the third derivatives
  // of 1/r are at most 3! / r^4 (Legendre polynomials are bounded by 1), taken at the nearest
  // point of any element, at least d - radius away: |error| <= 3 M2 / (4 pi (d - radius)^4),
  // with M2 = sum_i |a_i| reach_i^2 (reach: an element's farthest point from c).
  const double r = d - n.radius;
  return 3 * n.moment2 * kInv4Pi / (r * r * r * r);
}

double triangle_winding(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, int side) {
  return triangle_winding(p, a, b, c, [side] { return side; });
}

void DipoleTree::build_triangles(std::vector<ITri> tris) {
  itris_ = std::move(tris);
  tris_.clear();
  for (const ITri& t : itris_) tris_.push_back({to_unit(t.v[0]), to_unit(t.v[1]), to_unit(t.v[2])});
  elems_.clear();
  elems_.reserve(tris_.size());
  for (uint32_t i = 0; i < tris_.size(); ++i) {
    const auto& t = tris_[i];
    Element e;
    e.centre = scale3(add3(add3(t[0], t[1]), t[2]), 1.0 / 3);
    e.area = scale3(cross3(sub3(t[1], t[0]), sub3(t[2], t[0])), 0.5);
    e.abs_area = norm3(e.area);
    for (const Vec3& v : t) e.radius = std::max(e.radius, norm3(sub3(v, e.centre)));
    e.tri = i;
    elems_.push_back(e);
  }
  build();
}

void DipoleTree::build_points(const std::vector<Vec3>& pos, const std::vector<Vec3>& normal,
                              const std::vector<double>& area) {
  tris_.clear();
  itris_.clear();
  elems_.clear();
  elems_.reserve(pos.size());
  for (size_t i = 0; i < pos.size(); ++i) {
    const double len = norm3(normal[i]);
    if (!(len > 0)) continue;
    Element e;
    e.centre = pos[i];
    e.area = scale3(normal[i], area[i] / len);
    e.abs_area = area[i];
    e.radius = std::sqrt(area[i] / std::numbers::pi);
    elems_.push_back(e);
  }
  build();
}

void DipoleTree::build() {
  nodes_.clear();
  if (elems_.empty()) return;
  // Elements of very different sizes (a cap's small fans by the rim, its big ones across the
  // hole) make loose nodes: group them by size class first, then split each class in space.
  auto size_class = [](const Element& e) { return e.radius > 0 ? std::ilogb(e.radius) : INT32_MIN; };
  std::stable_sort(elems_.begin(), elems_.end(),
                   [&](const Element& a, const Element& b) { return size_class(a) < size_class(b); });
  std::vector<uint32_t> starts;
  for (uint32_t i = 0; i < elems_.size(); ++i)
    if (i == 0 || size_class(elems_[i]) != size_class(elems_[i - 1])) starts.push_back(i);
  build_classes(starts, 0, static_cast<uint32_t>(elems_.size()));
}

uint32_t DipoleTree::build_classes(const std::vector<uint32_t>& starts, size_t first, uint32_t end) {
  if (first + 1 == starts.size()) return build_range(starts[first], end);
  // A node over classes first.. : left child the first class, right child the rest.
  return build_range(starts[first], end, [&] { return build_range(starts[first], starts[first + 1]); },
                     [&] { return build_classes(starts, first + 1, end); });
}

uint32_t DipoleTree::build_range(uint32_t begin, uint32_t end) {
  return build_range(begin, end, nullptr, nullptr);
}

uint32_t DipoleTree::build_range(uint32_t begin, uint32_t end, const std::function<uint32_t()>& left,
                                 const std::function<uint32_t()>& right) {
  const auto id = static_cast<uint32_t>(nodes_.size());
  nodes_.push_back({});
  DNode n;
  // Centre weighted by |area| (plain average when all areas vanish).
  double wsum = 0;
  Vec3 c{0, 0, 0}, plain{0, 0, 0};
  Vec3 lo{kHuge, kHuge, kHuge}, hi{-kHuge, -kHuge, -kHuge};
  for (uint32_t i = begin; i < end; ++i) {
    const Element& e = elems_[i];
    c = add3(c, scale3(e.centre, e.abs_area));
    plain = add3(plain, e.centre);
    wsum += e.abs_area;
    n.area = add3(n.area, e.area);
    n.abs_area += e.abs_area;
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], e.centre[k]);
      hi[k] = std::max(hi[k], e.centre[k]);
    }
  }
  n.centre = wsum > 0 ? scale3(c, 1 / wsum) : scale3(plain, 1.0 / (end - begin));
  for (uint32_t i = begin; i < end; ++i) {
    const double reach = norm3(sub3(elems_[i].centre, n.centre)) + elems_[i].radius;
    n.radius = std::max(n.radius, reach);
    n.moment2 += elems_[i].abs_area * reach * reach;
    const Vec3 off = sub3(elems_[i].centre, n.centre);
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) n.spread[3 * a + b] += off[a] * elems_[i].area[b];
  }
  if (left) {
    left();
    n.right = right();
    nodes_[id] = n;
    return id;
  }
  constexpr uint32_t kLeafSize = 4;
  if (end - begin <= kLeafSize) {
    n.first = begin;
    n.count = end - begin;
    nodes_[id] = n;
    return id;
  }
  int axis = 0;
  for (int k = 1; k < 3; ++k)
    if (hi[k] - lo[k] > hi[axis] - lo[axis]) axis = k;
  const uint32_t mid = (begin + end) / 2;
  std::nth_element(elems_.begin() + begin, elems_.begin() + mid, elems_.begin() + end,
                   [&](const Element& a, const Element& b) { return a.centre[axis] < b.centre[axis]; });
  build_range(begin, mid);
  n.right = build_range(mid, end);
  nodes_[id] = n;
  return id;
}

DipoleTree::Value DipoleTree::evaluate(const Vec3& p, const I3* gp, double beta) const {
  // (inside() refines this adaptively; evaluate() is for values, e.g. gradients.)
  Value v;
  if (nodes_.empty()) return v;
  AngleSum angles;
  uint32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const uint32_t id = stack[--top];
    const DNode& n = nodes_[id];
    const double d = norm3(sub3(n.centre, p));
    if (beta > 0 && d > beta * n.radius && n.abs_area > 0) {
      v.w += far_field(n, p);
      v.bound += truncation_bound(n, d);
      continue;
    }
    if (n.count > 0) {
      add_exact(n, p, gp, angles, v.w);
    } else {
      stack[top++] = n.right;
      stack[top++] = id + 1;
    }
  }
  v.w += angles.turns();
  return v;
}

void DipoleTree::add_exact(const DNode& n, const Vec3& p, const I3* gp, AngleSum& angles, double& w) const {
  for (uint32_t i = n.first; i < n.first + n.count; ++i) {
    const Element& e = elems_[i];
    if (e.tri == UINT32_MAX) {
      w += dipole(p, e.centre, e.area, e.radius);
      continue;
    }
    const auto& t = tris_[e.tri];
    // The side of the plane by the exact, perturbed predicate (the one crossings use):
    // det(a - p, b - p, c - p) = -(n . p - d).
    angles.add(triangle_angle_terms(p, t[0], t[1], t[2], [&] { return gp ? -plane_side(itris_[e.tri], *gp) : 0; }));
  }
}

bool DipoleTree::summarized(const DNode& n, double d) { return d > kNearBeta * n.radius && n.abs_area > 0; }

std::optional<bool> DipoleTree::inside_far(const Vec3& p, double offset) const {
  if (nodes_.empty()) return std::abs(offset) >= 0.5;
  // inside()'s first look, given up as soon as it would need an exact sum or many nodes.
  constexpr int kMaxFar = 32;
  uint32_t stack[128];
  int n = 0, far = 0;
  double w = 0, bound = 0;
  stack[n++] = 0;
  while (n > 0) {
    const uint32_t k = stack[--n];
    const DNode& nd = nodes_[k];
    const double d = norm3(sub3(nd.centre, p));
    if (summarized(nd, d)) {
      if (++far > kMaxFar) return std::nullopt;
      w += far_field(nd, p);
      bound += truncation_bound(nd, d);
    } else if (nd.count > 0) {
      return std::nullopt;
    } else {
      stack[n++] = nd.right;
      stack[n++] = k + 1;
    }
  }
  if (std::abs(std::abs(offset - w) - 0.5) > bound + kWindingRounding) return std::abs(offset - w) >= 0.5;
  return std::nullopt;
}

bool DipoleTree::inside(const Vec3& p, const I3* gp, double offset, double tolerance) const {
  if (nodes_.empty()) return std::abs(offset) >= 0.5;
  if (tolerance >= 1) return std::abs(offset - evaluate(p, gp).w) >= 0.5;  // no decision can move
  // Nodes beyond kNearBeta radii are summarized by their dipoles, leaves included, each with a
  // rigorous truncation bound. While the decision |offset - w| >= 1/2 is within the bounds'
  // sum, the node with the largest bound is opened (its children replace it; a leaf is summed
  // exactly), until the decision is clear — then it is the exact answer — or the bound is
  // below `tolerance`. Deterministic: it depends on p only.
  struct Far {
    uint32_t node;
    double w, bound;
    bool operator<(const Far& o) const { return bound < o.bound; }
  };
  thread_local std::vector<Far> heap;
  heap.clear();
  AngleSum angles;
  double w_far = 0, w_points = 0, bound = 0;
  bool angles_changed = false, is_heap = false;  // the first look needs no order
  auto open = [&](uint32_t id) {
    uint32_t stack[128];
    int n = 0;
    stack[n++] = id;
    while (n > 0) {
      const uint32_t k = stack[--n];
      const DNode& nd = nodes_[k];
      const double d = norm3(sub3(nd.centre, p));
      if (summarized(nd, d)) {
        const Far f{k, far_field(nd, p), truncation_bound(nd, d)};
        heap.push_back(f);
        if (is_heap) std::push_heap(heap.begin(), heap.end());
        w_far += f.w;
        bound += f.bound;
      } else if (nd.count > 0) {
        add_exact(nd, p, gp, angles, w_points);
        angles_changed = true;
      } else {
        stack[n++] = nd.right;
        stack[n++] = k + 1;
      }
    }
  };
  open(0);
  double turns = 0;
  for (;;) {
    if (angles_changed) turns = angles.turns(), angles_changed = false;
    const double w = w_far + w_points + turns;
    const double margin = std::abs(std::abs(offset - w) - 0.5);
    // Rounding of the exact sums, and of the running bound, is far below 1e-9.
    if (heap.empty() || margin > bound + kWindingRounding || bound < tolerance) return std::abs(offset - w) >= 0.5;
    if (!is_heap) std::make_heap(heap.begin(), heap.end()), is_heap = true;
    // Open the largest bounds until their sum has halved before looking again (each look
    // costs an atan2).
    const double target = bound / 2;
    do {
      std::pop_heap(heap.begin(), heap.end());
      const Far f = heap.back();
      heap.pop_back();
      w_far -= f.w;
      bound -= f.bound;
      const DNode& nd = nodes_[f.node];
      if (nd.count > 0) {
        add_exact(nd, p, gp, angles, w_points);
        angles_changed = true;
      } else {
        open(f.node + 1);
        open(nd.right);
      }
    } while (!heap.empty() && bound > target);
  }
}

Vec3 boundary_field(const std::vector<std::array<Vec3, 2>>& edges, const Vec3& p) {
  Vec3 f{0, 0, 0};
  for (const auto& [a, b] : edges) {
    const Vec3 ra = sub3(a, p), rb = sub3(b, p);
    const double la = norm3(ra), lb = norm3(rb);
    const double den = la * lb * (la * lb + dot3(ra, rb));
    if (!(den > kTinyDivisor)) continue;  // p on the segment's line
    f = add3(f, scale3(cross3(ra, rb), (la + lb) / den));
  }
  return f;
}

}  // namespace pic::detail

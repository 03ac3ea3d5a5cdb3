// Distances from points to a triangle mesh: see mesh_distance.h.
#include "geometry/mesh_distance.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <unordered_map>

#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include "geometry/lattice.h"
#include "geometry/tolerances.h"
#include "geometry/vec3.h"

namespace pic::detail {

namespace {

/// nearest_on_triangle with the squared distance in `distance`.
Nearest nearest_on_triangle2(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  // Voronoi regions of the vertices, then the edges, then the face (Ericson, Real-Time
  // Collision Detection, 5.1.5).
  const Vec3 ab = sub3(b, a), ac = sub3(c, a), ap = sub3(p, a);
  const double d1 = dot3(ab, ap), d2 = dot3(ac, ap);
  auto at = [&](const Vec3& x, Feature f) {
    const Vec3 d = sub3(p, x);
    return Nearest{x, dot3(d, d), 0, f};
  };
  if (d1 <= 0 && d2 <= 0) return at(a, Feature::V0);
  const Vec3 bp = sub3(p, b);
  const double d3 = dot3(ab, bp), d4 = dot3(ac, bp);
  if (d3 >= 0 && d4 <= d3) return at(b, Feature::V1);
  const double vc = d1 * d4 - d3 * d2;
  // Each edge's parameter only where its denominator is positive: a triangle with two
  // coincident vertices would give 0/0 there.
  if (vc <= 0 && d1 >= 0 && d3 <= 0 && d1 - d3 > 0) return at(add3(a, scale3(ab, d1 / (d1 - d3))), Feature::E01);
  const Vec3 cp = sub3(p, c);
  const double d5 = dot3(ab, cp), d6 = dot3(ac, cp);
  if (d6 >= 0 && d5 <= d6) return at(c, Feature::V2);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0 && d2 - d6 > 0) return at(add3(a, scale3(ac, d2 / (d2 - d6))), Feature::E20);
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0 && (d4 - d3) + (d5 - d6) > 0)
    return at(add3(b, scale3(sub3(c, b), (d4 - d3) / ((d4 - d3) + (d5 - d6)))), Feature::E12);
  const double denom = va + vb + vc;
  if (!(std::abs(denom) > kTinyDivisor)) {
    // A degenerate triangle: the nearest of its corners.
    const Nearest na = at(a, Feature::V0), nb = at(b, Feature::V1), nc = at(c, Feature::V2);
    return na.distance <= nb.distance ? (na.distance <= nc.distance ? na : nc) : (nb.distance <= nc.distance ? nb : nc);
  }
  const double v = vb / denom, w = vc / denom;
  return at(add3(a, add3(scale3(ab, v), scale3(ac, w))), Feature::Face);
}

float round_down(double x) {
  const float f = static_cast<float>(x);
  return double(f) > x ? std::nextafter(f, -std::numeric_limits<float>::infinity()) : f;
}

float round_up(double x) {
  const float f = static_cast<float>(x);
  return double(f) < x ? std::nextafter(f, std::numeric_limits<float>::infinity()) : f;
}

}  // namespace

Nearest nearest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  Nearest n = nearest_on_triangle2(p, a, b, c);
  n.distance = std::sqrt(n.distance);
  return n;
}

namespace {

/// Ranges of more triangles than this build their halves as parallel tasks.
constexpr uint32_t kParallelBuild = 1 << 15;

}  // namespace

MeshDistance::MeshDistance(const TriMesh& mesh) : triangles_(mesh.triangles.size()) {
  const size_t n = mesh.triangles.size();
  std::vector<uint32_t> order(n);
  std::iota(order.begin(), order.end(), uint32_t{0});
  std::vector<Vec3> lo(n), hi(n), centre(n);
  tbb::parallel_for(size_t{0}, n, [&](size_t i) {
    const auto& t = mesh.triangles[i];
    for (int k = 0; k < 3; ++k) {
      lo[i][k] = std::min({mesh.positions[t[0]][k], mesh.positions[t[1]][k], mesh.positions[t[2]][k]});
      hi[i][k] = std::max({mesh.positions[t[0]][k], mesh.positions[t[1]][k], mesh.positions[t[2]][k]});
      centre[i][k] = (lo[i][k] + hi[i][k]) / 2;
    }
  });
  if (n == 0) return;
  nodes_.reserve(2 * (n / kLeafSize) + 3);
  nodes_.resize(1);
  build(nodes_, 0, bounds(0, uint32_t(n), order, lo, hi), 0, static_cast<uint32_t>(n), order, lo, hi, centre);
  tris_.resize(n);
  tbb::parallel_for(size_t{0}, n, [&](size_t i) {
    const auto& t = mesh.triangles[order[i]];
    LeafTriangle& l = tris_[i];
    l.a = mesh.positions[t[0]], l.b = mesh.positions[t[1]], l.c = mesh.positions[t[2]];
    for (int k = 0; k < 3; ++k) l.lo[k] = round_down(lo[order[i]][k]), l.hi[k] = round_up(hi[order[i]][k]);
    l.id = order[i];
  });
}

template <class Box>
double MeshDistance::box_distance2(const Box& box, const Vec3& p) {
  double s = 0;
  for (int k = 0; k < 3; ++k) {
    const double d = std::max({double(box.lo[k]) - p[k], 0.0, p[k] - double(box.hi[k])});
    s += d * d;
  }
  return s;
}

/// Visits the triangles that may be nearer than best2 (squared), nearer boxes first; `visit`
/// lowers best2 as it finds nearer triangles.
template <class Visit>
void MeshDistance::search(const Vec3& p, double& best2, Visit&& visit) const {
  if (nodes_.empty()) return;
  uint32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const BNode& nd = nodes_[stack[--top]];
    if (box_distance2(nd, p) >= best2) continue;
    if (nd.count > 0) {
      for (uint32_t i = nd.first; i < nd.first + nd.count; ++i) visit(tris_[i]);
      continue;
    }
    const BNode &l = nodes_[nd.first], &r = nodes_[nd.first + 1];
    const double dl = box_distance2(l, p), dr = box_distance2(r, p);
    // Push the farther first so the nearer is explored first.
    if (dl < dr) {
      if (dr < best2) stack[top++] = nd.first + 1;
      if (dl < best2) stack[top++] = nd.first;
    } else {
      if (dl < best2) stack[top++] = nd.first;
      if (dr < best2) stack[top++] = nd.first + 1;
    }
  }
}

double MeshDistance::distance(const Vec3& p) const {
  double best2 = std::numeric_limits<double>::infinity();
  search(p, best2, [&](const LeafTriangle& t) {
    if (box_distance2(t, p) < best2) best2 = std::min(best2, point_triangle_distance2(p, t.a, t.b, t.c));
  });
  return std::sqrt(best2);
}

bool MeshDistance::within(const Vec3& p, double r, uint32_t* hint, double* found) const {
  const double r2 = r * r;
  double d2 = 0;
  auto reaches = [&](const LeafTriangle& t) {
    return box_distance2(t, p) <= r2 && (d2 = point_triangle_distance2(p, t.a, t.b, t.c)) <= r2;
  };
  auto take = [&](const LeafTriangle& t) {
    if (hint) *hint = static_cast<uint32_t>(&t - tris_.data());
    if (found) *found = std::sqrt(d2);
    return true;
  };
  // The hint's triangles first: stored in leaf order, the slots around it lie close by.
  constexpr uint32_t kAround = 8;
  if (hint && *hint < triangles_) {
    const uint32_t lo = *hint > kAround ? *hint - kAround : 0, hi = std::min<uint32_t>(uint32_t(triangles_), *hint + kAround + 1);
    for (uint32_t i = lo; i < hi; ++i)
      if (reaches(tris_[i])) return take(tris_[i]);
  }
  // Just above r^2, so that a box at exactly r is still opened; once a triangle is found the
  // bound drops below every distance and the search ends.
  double bound2 = std::nextafter(r2, std::numeric_limits<double>::infinity());
  search(p, bound2, [&](const LeafTriangle& t) {
    if (bound2 >= 0 && reaches(t)) {
      bound2 = -1;
      take(t);
    }
  });
  return bound2 < 0;
}

namespace {

/// Squared distance between two boxes (0 when they meet).
template <class A, class B>
double box_box_distance2(const A& a, const B& b) {
  double s = 0;
  for (int k = 0; k < 3; ++k) {
    const double d = std::max({double(a.lo[k]) - double(b.hi[k]), 0.0, double(b.lo[k]) - double(a.hi[k])});
    s += d * d;
  }
  return s;
}

struct Box {
  Vec3 lo, hi;
};

/// How many times farther_than halves a box against a triangle it cannot prove away whole.
constexpr int kOctantDepth = 3;

/// Whether triangle abc (n: its unit normal, or any unit vector, or zero) lies farther than r
/// from every point of the box: all eight corners beyond r on one side of its extent along n,
/// or its distance from the box's centre beyond r plus the half-diagonal (each point of the
/// box is that close to the centre); else the same for each octant, `depth` more times (the
/// centre's slack halves each time).
bool triangle_farther(const Box& box, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& n, double r,
                      int depth) {
  double lo = kHuge, hi = -kHuge;
  for (int k = 0; k < 8; ++k) {
    const Vec3 x{k & 1 ? box.hi[0] : box.lo[0], k & 2 ? box.hi[1] : box.lo[1], k & 4 ? box.hi[2] : box.lo[2]};
    const double h = dot3(n, sub3(x, a));
    lo = std::min(lo, h), hi = std::max(hi, h);
  }
  // The triangle's own extent along n (0 for an exact normal; a nearly flat triangle's
  // rounded normal may tilt out of its plane): the box must clear it by r on one side.
  const double hb = dot3(n, sub3(b, a)), hc = dot3(n, sub3(c, a));
  if (lo > std::max({0.0, hb, hc}) + r || hi < std::min({0.0, hb, hc}) - r) return true;
  const Vec3 centre = scale3(add3(box.lo, box.hi), 0.5);
  const double half = norm3(sub3(box.hi, box.lo)) / 2;
  const double d2 = point_triangle_distance2(centre, a, b, c);
  if (d2 > (r + half) * (r + half)) return true;
  if (depth == 0 || d2 <= r * r) return false;  // the centre itself within r: not away
  for (int k = 0; k < 8; ++k) {
    Box o;
    for (int i = 0; i < 3; ++i) {
      const bool upper = (k >> i) & 1;
      o.lo[i] = upper ? centre[i] : box.lo[i];
      o.hi[i] = upper ? box.hi[i] : centre[i];
    }
    if (!triangle_farther(o, a, b, c, n, r, depth - 1)) return false;
  }
  return true;
}

}  // namespace

bool MeshDistance::farther_than(const Vec3& lo, const Vec3& hi, double r) const {
  const Box box{lo, hi};
  const double r2 = r * r;
  auto away = [&](const LeafTriangle& t) {
    if (box_box_distance2(t, box) > r2) return true;
    const Vec3 n = cross3(sub3(t.b, t.a), sub3(t.c, t.a));
    const double len = norm3(n);
    return triangle_farther(box, t.a, t.b, t.c, len > 0 ? scale3(n, 1 / len) : Vec3{0, 0, 0}, r, kOctantDepth);
  };
  if (nodes_.empty()) return true;
  uint32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const BNode& nd = nodes_[stack[--top]];
    if (box_box_distance2(nd, box) > r2) continue;
    if (nd.count == 0) {
      stack[top++] = nd.first;
      stack[top++] = nd.first + 1;
      continue;
    }
    for (uint32_t i = nd.first; i < nd.first + nd.count; ++i)
      if (!away(tris_[i])) return false;
  }
  return true;
}

Nearest MeshDistance::nearest(const Vec3& p, uint32_t* hint) const {
  double best2 = std::numeric_limits<double>::infinity();
  Nearest best;
  if (hint && *hint < triangles_) {
    const LeafTriangle& t = tris_[*hint];
    best = nearest_on_triangle2(p, t.a, t.b, t.c);
    best.triangle = t.id;
    // A hair more: the search must still find the hint's own triangle when it is the answer.
    if (std::isfinite(best.distance)) best2 = best.distance * (1 + kHintSlack) + kTinyDivisor;
  }
  // The same answer whatever the hint, so a point asked twice gets one value (its feature, and
  // so its sign): the boxes visit in an order the hint does not change, the hint's bound is a
  // hair above its distance and so prunes no triangle at the least distance, and among those
  // visited a tie goes to the lowest index.
  uint32_t slot = hint ? *hint : 0;
  search(p, best2, [&](const LeafTriangle& t) {
    if (box_distance2(t, p) >= best2) return;
    const Nearest n = nearest_on_triangle2(p, t.a, t.b, t.c);
    if (n.distance < best2 || (n.distance == best2 && t.id < best.triangle)) {
      best2 = n.distance;
      best = n;
      best.triangle = t.id;
      slot = static_cast<uint32_t>(&t - tris_.data());
    }
  });
  if (hint) *hint = slot;
  best.distance = std::sqrt(best.distance);
  return best;
}

namespace {

/// Surface area of a box (half of it: only ratios are compared).
double half_area(const Vec3& lo, const Vec3& hi) {
  const double x = std::max(0.0, hi[0] - lo[0]), y = std::max(0.0, hi[1] - lo[1]), z = std::max(0.0, hi[2] - lo[2]);
  return x * y + y * z + z * x;
}

constexpr int kBins = 16;

}  // namespace

MeshDistance::Split MeshDistance::split(uint32_t first, uint32_t last, std::vector<uint32_t>& order,
                                        const std::vector<Vec3>& lo, const std::vector<Vec3>& hi,
                                        const std::vector<Vec3>& centre) {
  // The surface area heuristic over kBins slabs of the centres' box along its longest axis (all
  // three axes cost three times the build for 3 % faster queries): a query opens a child about
  // in proportion to its area, and then looks at its triangles.
  Vec3 clo{kHuge, kHuge, kHuge}, chi{-kHuge, -kHuge, -kHuge};
  for (uint32_t i = first; i < last; ++i)
    for (int k = 0; k < 3; ++k) clo[k] = std::min(clo[k], centre[order[i]][k]), chi[k] = std::max(chi[k], centre[order[i]][k]);
  int axis = 0;
  for (int k = 1; k < 3; ++k)
    if (chi[k] - clo[k] > chi[axis] - clo[axis]) axis = k;
  Split best;
  if (!(chi[axis] > clo[axis])) {  // every centre in one point: halves by position in the order
    best.mid = first + (last - first) / 2;
    best.left = bounds(first, best.mid, order, lo, hi);
    best.right = bounds(best.mid, last, order, lo, hi);
    return best;
  }
  const double scale = kBins / (chi[axis] - clo[axis]);
  const auto bin_of = [&](uint32_t t) { return std::min(kBins - 1, int((centre[t][axis] - clo[axis]) * scale)); };
  const Bounds empty{{kHuge, kHuge, kHuge}, {-kHuge, -kHuge, -kHuge}};
  std::array<Bounds, kBins> bins;
  bins.fill(empty);
  std::array<uint32_t, kBins> count{};
  for (uint32_t i = first; i < last; ++i) {
    const int b = bin_of(order[i]);
    ++count[b];
    bins[b].grow(lo[order[i]], hi[order[i]]);
  }
  // The split after bin b costs the left's area times its count plus the right's.
  std::array<Bounds, kBins> left;
  std::array<uint32_t, kBins> left_count{};
  Bounds acc = empty;
  for (int b = 0, n = 0; b < kBins - 1; ++b) {
    n += count[b];
    acc.grow(bins[b].lo, bins[b].hi);
    left[b] = acc, left_count[b] = n;
  }
  double best_cost = kHuge;
  int best_bin = 0;
  acc = empty;
  for (int b = kBins - 1, n = 0; b > 0; --b) {
    n += count[b];
    acc.grow(bins[b].lo, bins[b].hi);
    if (!n || !left_count[b - 1]) continue;
    const double cost = half_area(left[b - 1].lo, left[b - 1].hi) * left_count[b - 1] + half_area(acc.lo, acc.hi) * n;
    if (cost < best_cost) best_cost = cost, best_bin = b - 1, best.left = left[b - 1], best.right = acc;
  }
  const auto at_left = [&](uint32_t t) { return bin_of(t) <= best_bin; };
  best.mid = uint32_t(std::partition(order.begin() + first, order.begin() + last, at_left) - order.begin());
  return best;
}

MeshDistance::Bounds MeshDistance::bounds(uint32_t first, uint32_t last, const std::vector<uint32_t>& order,
                                       const std::vector<Vec3>& lo, const std::vector<Vec3>& hi) {
  Bounds b{{kHuge, kHuge, kHuge}, {-kHuge, -kHuge, -kHuge}};
  for (uint32_t i = first; i < last; ++i) b.grow(lo[order[i]], hi[order[i]]);
  return b;
}

void MeshDistance::build(std::vector<BNode>& out, uint32_t self, const Bounds& box, uint32_t first, uint32_t last,
                         std::vector<uint32_t>& order, const std::vector<Vec3>& lo, const std::vector<Vec3>& hi,
                         const std::vector<Vec3>& centre) {
  BNode nd;
  for (int k = 0; k < 3; ++k) nd.lo[k] = round_down(box.lo[k]), nd.hi[k] = round_up(box.hi[k]);
  if (last - first <= kLeafSize) {
    nd.first = first;
    nd.count = last - first;
    out[self] = nd;
    return;
  }
  const Split s = split(first, last, order, lo, hi, centre);
  if (last - first <= kParallelBuild) {
    // The children side by side, each one's descendants after them.
    nd.first = uint32_t(out.size());
    out[self] = nd;
    out.resize(out.size() + 2);
    build(out, nd.first, s.left, first, s.mid, order, lo, hi, centre);
    build(out, nd.first + 1, s.right, s.mid, last, order, lo, hi, centre);
    return;
  }
  // Large halves in parallel, each into its own nodes (its root first), then appended: the
  // same layout whatever the thread count.
  std::vector<BNode> left(1), right(1);
  tbb::parallel_invoke([&] { build(left, 0, s.left, first, s.mid, order, lo, hi, centre); },
                       [&] { build(right, 0, s.right, s.mid, last, order, lo, hi, centre); });
  const uint32_t pair = uint32_t(out.size()), left_base = pair + 2, right_base = left_base + uint32_t(left.size()) - 1;
  nd.first = pair;
  out[self] = nd;
  out.resize(out.size() + 2);
  const auto append = [&](std::vector<BNode>& part, uint32_t root, uint32_t base) {
    // Index i of the part (0 its root) goes to `root` for 0 and base + i - 1 after.
    for (BNode& n : part)
      if (n.count == 0) n.first = base + n.first - 1;
    out[root] = part[0];
    out.insert(out.end(), part.begin() + 1, part.end());
  };
  append(left, pair, left_base);
  append(right, pair + 1, right_base);
}

namespace {

Vec3 unit_or_zero(const Vec3& v) {
  const double l = norm3(v);
  return l > 0 ? scale3(v, 1 / l) : Vec3{0, 0, 0};
}

}  // namespace

SignedDistance::SignedDistance(const TriMesh& mesh)
    : mesh_(mesh), distance_(mesh), face_normal_(mesh.triangles.size()), vertex_normal_(mesh.positions.size()),
      edge_normal_(mesh.triangles.size()) {
  const auto& P = mesh.positions;
  Vec3 lo{kHuge, kHuge, kHuge}, hi{-kHuge, -kHuge, -kHuge};
  for (const Vec3& p : P)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
  if (!P.empty()) on_surface_ = kOnSurface * norm3(sub3(hi, lo));
  std::unordered_map<uint64_t, Vec3> edge_sum;  // undirected edge -> sum of its faces' normals
  auto key = [](uint32_t a, uint32_t b) { return (uint64_t(std::min(a, b)) << 32) | std::max(a, b); };
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    const auto& t = mesh.triangles[f];
    const Vec3 n = unit_or_zero(cross3(sub3(P[t[1]], P[t[0]]), sub3(P[t[2]], P[t[0]])));
    face_normal_[f] = n;
    for (int k = 0; k < 3; ++k) {
      // The vertex's pseudonormal weights each face by its angle there.
      const Vec3 e1 = unit_or_zero(sub3(P[t[(k + 1) % 3]], P[t[k]])), e2 = unit_or_zero(sub3(P[t[(k + 2) % 3]], P[t[k]]));
      const double angle = std::acos(std::clamp(dot3(e1, e2), -1.0, 1.0));
      vertex_normal_[t[k]] = add3(vertex_normal_[t[k]], scale3(n, angle));
      Vec3& e = edge_sum[key(t[k], t[(k + 1) % 3])];
      e = add3(e, n);
    }
  }
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    const auto& t = mesh.triangles[f];
    for (int k = 0; k < 3; ++k) edge_normal_[f][k] = edge_sum[key(t[k], t[(k + 1) % 3])];
  }
}

double SignedDistance::operator()(const Vec3& p, uint32_t* hint) const {
  Vec3 g;
  return with_gradient(p, g, hint);
}

double SignedDistance::with_gradient(const Vec3& p, Vec3& gradient, uint32_t* hint, Vec3* nearest,
                                     Nearest* feature) const {
  const Nearest n = distance_.nearest(p, hint);
  if (nearest) *nearest = n.point;
  if (feature) *feature = n;
  const auto& t = mesh_.triangles[n.triangle];
  Vec3 pseudo{0, 0, 0};
  switch (n.feature) {
    case Feature::V0: pseudo = vertex_normal_[t[0]]; break;
    case Feature::V1: pseudo = vertex_normal_[t[1]]; break;
    case Feature::V2: pseudo = vertex_normal_[t[2]]; break;
    case Feature::E01: pseudo = edge_normal_[n.triangle][0]; break;
    case Feature::E12: pseudo = edge_normal_[n.triangle][1]; break;
    case Feature::E20: pseudo = edge_normal_[n.triangle][2]; break;
    case Feature::Face: pseudo = face_normal_[n.triangle]; break;
  }
  const Vec3 away = sub3(p, n.point);
  const bool outside = dot3(away, pseudo) >= 0;
  // On the surface (a root finder lands there) the gradient is the nearest face's normal: the
  // direction to the nearest point is noise, and on an edge or a vertex the pseudonormal's
  // plane would cut the crease where each face's plane holds the point.
  gradient = n.distance > on_surface_ ? scale3(away, (outside ? 1 : -1) / n.distance) : face_normal_[n.triangle];
  return outside ? n.distance : -n.distance;
}

}  // namespace pic::detail

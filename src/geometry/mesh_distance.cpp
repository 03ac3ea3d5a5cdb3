// Distances from points to a triangle mesh: see mesh_distance.h.
#include "geometry/mesh_distance.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <unordered_map>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

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

/// Surface area of a box (half of it: only ratios are compared).
double half_area(const Vec3& lo, const Vec3& hi) {
  const double x = std::max(0.0, hi[0] - lo[0]), y = std::max(0.0, hi[1] - lo[1]), z = std::max(0.0, hi[2] - lo[2]);
  return x * y + y * z + z * x;
}

/// A box [lo, hi] rounded outward to floats: what the vector tests measure against.
struct FloatBox {
  float lo[3], hi[3];
  FloatBox(const Vec3& l, const Vec3& h) {
    for (int k = 0; k < 3; ++k) lo[k] = round_down(l[k]), hi[k] = round_up(h[k]);
  }
};

/// The float bounds below are taken only where every coordinate, the query's and the mesh's,
/// is at most kFar in size: no square of a gap then overflows. Beyond, a query bounds nothing
/// (every box is opened: slow, exact). Each sum of squares loses its relative rounding and
/// then kTinySquare, more than a square below the floats' normal range can round up by.
constexpr double kFar = 1e18;
constexpr float kTinySquare = 1e-44f;

#if defined(__SSE2__)
/// The gap g as the bounds square it: NaN and negative gaps 0.
__m128 clamped_gap(__m128 g) { return _mm_max_ps(g, _mm_setzero_ps()); }
/// A sum of squared gaps as a lower bound.
__m128 lower_sum(__m128 s, float shrink) {
  return _mm_sub_ps(_mm_mul_ps(s, _mm_set1_ps(shrink)), _mm_set1_ps(kTinySquare));
}
#else
float clamped_gap(float g) { return g > 0 ? g : 0.0f; }
float lower_sum(float s, float shrink) { return s * shrink - kTinySquare; }
#endif

/// Squared distances from the box q to four boxes side by side (axis k's bounds at lo + k *
/// stride, hi + k * stride) into out, each at most the exact distance between the boxes: q's
/// bounds are rounded outward, and the float rounding of the differences, squares and sums (a
/// few units in 2^-24, relative) is taken off by the shrink.
void box_distance2_x4(const float* lo, const float* hi, size_t stride, const FloatBox& q, float* out) {
  constexpr float kShrink = 1.0f - 1.0f / (1 << 20);
#if defined(__SSE2__)
  __m128 s = _mm_setzero_ps();
  for (size_t k = 0; k < 3; ++k) {
    const __m128 below = _mm_sub_ps(_mm_load_ps(lo + k * stride), _mm_set1_ps(q.hi[k]));
    const __m128 above = _mm_sub_ps(_mm_set1_ps(q.lo[k]), _mm_load_ps(hi + k * stride));
    const __m128 d = clamped_gap(_mm_max_ps(below, above));
    s = _mm_add_ps(s, _mm_mul_ps(d, d));
  }
  _mm_store_ps(out, lower_sum(s, kShrink));
#else
  for (int i = 0; i < 4; ++i) {
    float s = 0;
    for (size_t k = 0; k < 3; ++k) {
      const float below = lo[k * stride + i] - q.hi[k], above = q.lo[k] - hi[k * stride + i];
      const float d = clamped_gap(below > above ? below : above);
      s += d * d;
    }
    out[i] = lower_sum(s, kShrink);
  }
#endif
}

/// How far a plane or side stored in floats may be from the exact one, at p, relative to p's
/// and the mesh's largest coordinate: their products and sums round to a few units in 2^-24
/// of those; 2^-18 is a wide margin over that.
constexpr double kPlaneRounding = 1.0 / (1 << 18);

/// Raises out[0..3] to lower bounds on the squared distances from p (in floats: x) to four
/// triangles side by side (`plane`, `side`: LeafPlanes' arrays at the first one's slot, rows
/// of 8): a triangle lies in its plane and, within it, inside each side's line, so its distance
/// is at least that of the half-plane beyond its farthest side, sqrt(h^2 + o^2) for p at height
/// h over the plane and o outside that side. `slack` covers the floats' rounding.
void plane_distance2_x4(const float* plane, const float* side, const float (&x)[3], float slack, float* out) {
  constexpr float kShrink = 1.0f - 1.0f / (1 << 20);
#if defined(__SSE2__)
  const __m128 px = _mm_set1_ps(x[0]), py = _mm_set1_ps(x[1]), pz = _mm_set1_ps(x[2]);
  const auto along = [&](const float* row) {  // n . x - offset for a row block (n: 3 rows, offset: 1)
    __m128 v = _mm_mul_ps(_mm_load_ps(row), px);
    v = _mm_add_ps(v, _mm_mul_ps(_mm_load_ps(row + 8), py));
    v = _mm_add_ps(v, _mm_mul_ps(_mm_load_ps(row + 16), pz));
    return _mm_sub_ps(v, _mm_load_ps(row + 24));
  };
  const __m128 h = along(plane);
  const __m128 height = _mm_max_ps(h, _mm_sub_ps(_mm_setzero_ps(), h));
  const __m128 out_of = _mm_max_ps(_mm_max_ps(along(side), along(side + 32)), along(side + 64));
  const __m128 s = _mm_set1_ps(slack);
  const __m128 a = clamped_gap(_mm_sub_ps(height, s)), b = clamped_gap(_mm_sub_ps(out_of, s));
  const __m128 d2 = lower_sum(_mm_add_ps(_mm_mul_ps(a, a), _mm_mul_ps(b, b)), kShrink);
  _mm_store_ps(out, _mm_max_ps(_mm_load_ps(out), d2));
#else
  for (int i = 0; i < 4; ++i) {
    const auto along = [&](const float* row) { return row[i] * x[0] + row[8 + i] * x[1] + row[16 + i] * x[2] - row[24 + i]; };
    const float h = along(plane), height = h > -h ? h : -h;
    float out_of = along(side);
    for (const float o : {along(side + 32), along(side + 64)}) out_of = out_of > o ? out_of : o;
    const float a = clamped_gap(height - slack), b = clamped_gap(out_of - slack);
    const float d2 = lower_sum(a * a + b * b, kShrink);
    out[i] = out[i] > d2 ? out[i] : d2;
  }
#endif
}

/// A traversal's stack: each node opened leaves at most three of its children behind, so a
/// tree `depth` Node4 levels deep needs 3 * depth + 4 entries -- on the caller's stack for the
/// usual trees, on the heap for a deep one.
template <class T>
class TraversalStack {
 public:
  explicit TraversalStack(uint32_t depth) {
    const size_t need = 3 * size_t(depth) + 4;
    if (need > kLocal) heap_.resize(need);
    data_ = heap_.empty() ? local_ : heap_.data();
  }
  T& operator[](int i) { return data_[i]; }

 private:
  static constexpr size_t kLocal = 256;
  T local_[kLocal];
  std::vector<T> heap_;
  T* data_;
};

/// The largest coordinate of x in size.
double largest_coordinate(const Vec3& x) { return std::max({std::abs(x[0]), std::abs(x[1]), std::abs(x[2])}); }

/// The axis boxes of a leaf's eight triangles measured from the box q, into out.
template <class Leaf>
void leaf_boxes_distance2(const Leaf& l, const FloatBox& q, float* out) {
  box_distance2_x4(&l.lo[0][0], &l.hi[0][0], 8, q, out);
  box_distance2_x4(&l.lo[0][4], &l.hi[0][4], 8, q, out + 4);
}

/// A query point as the vector tests take it: rounded outward to a box of floats, rounded to
/// floats, and the slack of the leaves' planes there (see kPlaneRounding).
struct FloatPoint {
  FloatBox box;
  float x[3];
  float slack;
  bool far;  // beyond kFar, or the mesh is: bounds nothing
  FloatPoint(const Vec3& p, float rounding, bool mesh_far)
      : box(p, p),
        x{float(p[0]), float(p[1]), float(p[2])},
        slack(rounding + float(largest_coordinate(p) * kPlaneRounding)),
        far(mesh_far || !(largest_coordinate(p) <= kFar)) {}
};

/// Lower bounds on the squared distances from q to a leaf's eight triangles, into out
/// (`planes`: theirs, or none).
template <class Boxes, class Planes>
void leaf_distance2(const Boxes& l, const Planes* planes, const FloatPoint& q, float* out) {
  if (q.far) {
    std::fill_n(out, 8, 0.0f);
    return;
  }
  leaf_boxes_distance2(l, q.box, out);
  if (!planes) return;
  plane_distance2_x4(&planes->plane[0][0], &planes->side[0][0][0], q.x, q.slack, out);
  plane_distance2_x4(&planes->plane[0][4], &planes->side[0][0][4], q.x, q.slack, out + 4);
}

/// Lower bounds on the squared distances from q to a node's four children: their axis boxes',
/// or with `oriented` the larger of those and their oriented boxes' (measured in floats along
/// the stored axes, each gap less q's slack; the stored axes are orthonormal to float
/// rounding, which kShrink covers).
template <class Node>
void children_distance2(const Node& n, const FloatPoint& q, bool oriented, float* out) {
  if (q.far) {
    std::fill_n(out, 4, 0.0f);
    return;
  }
  box_distance2_x4(&n.lo[0][0], &n.hi[0][0], 4, q.box, out);
  if (!oriented) return;
  constexpr float kShrink = 1.0f - 1.0f / (1 << 18);
#if defined(__SSE2__)
  const __m128 px = _mm_set1_ps(q.x[0]), py = _mm_set1_ps(q.x[1]), pz = _mm_set1_ps(q.x[2]);
  const __m128 slack = _mm_set1_ps(q.slack);
  __m128 s = _mm_setzero_ps();
  for (int k = 0; k < 3; ++k) {
    __m128 x = _mm_mul_ps(_mm_load_ps(n.axis[k][0]), px);
    x = _mm_add_ps(x, _mm_mul_ps(_mm_load_ps(n.axis[k][1]), py));
    x = _mm_add_ps(x, _mm_mul_ps(_mm_load_ps(n.axis[k][2]), pz));
    const __m128 gap = _mm_max_ps(_mm_sub_ps(_mm_load_ps(n.along[k][0]), x), _mm_sub_ps(x, _mm_load_ps(n.along[k][1])));
    const __m128 d = clamped_gap(_mm_sub_ps(gap, slack));
    s = _mm_add_ps(s, _mm_mul_ps(d, d));
  }
  _mm_store_ps(out, _mm_max_ps(_mm_load_ps(out), lower_sum(s, kShrink)));
#else
  for (int i = 0; i < 4; ++i) {
    float s = 0;
    for (int k = 0; k < 3; ++k) {
      const float x = n.axis[k][0][i] * q.x[0] + n.axis[k][1][i] * q.x[1] + n.axis[k][2][i] * q.x[2];
      const float below = n.along[k][0][i] - x, above = x - n.along[k][1][i];
      const float d = clamped_gap((below > above ? below : above) - q.slack);
      s += d * d;
    }
    const float d2 = lower_sum(s, kShrink);
    out[i] = out[i] > d2 ? out[i] : d2;
  }
#endif
}

}  // namespace

MeshDistance::MeshDistance(const TriMesh& mesh, Pruning pruning) : pruning_(pruning) {
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
  std::vector<BNode> binary;
  binary.reserve(2 * (n / kLeafSize) + 3);
  binary.resize(1);
  build(binary, 0, bounds(0, uint32_t(n), order, lo, hi), 0, static_cast<uint32_t>(n), order, lo, hi, centre);
  nodes_.reserve(binary.size() / 3 + 1);
  leaves_.reserve(binary.size() / 2 + 1);
  double extent = 0;
  for (const Vec3& x : mesh.positions) extent = std::max(extent, largest_coordinate(x));
  rounding_ = float(extent * kPlaneRounding);
  far_ = !(extent <= kFar);
  std::vector<std::array<uint32_t, 4>> oriented;  // Node4 children whose oriented boxes are due
  const auto runs = pruning_ == Pruning::Full ? runs_of(binary) : std::vector<std::pair<uint32_t, uint32_t>>{};
  root_ = collapse(binary, runs, 0, 0, oriented);
  fill_leaves(mesh, order, lo, hi);
  // The build's own arrays freed before the oriented boxes: a large mesh's peak memory.
  for (auto* v : {&lo, &hi, &centre}) std::vector<Vec3>().swap(*v);
  std::vector<BNode>().swap(binary);
  if (pruning_ == Pruning::Full) fill_oriented_boxes(oriented);
}

std::vector<std::pair<uint32_t, uint32_t>> MeshDistance::runs_of(const std::vector<BNode>& binary) {
  // A subtree's triangles are contiguous in the order.
  std::vector<std::pair<uint32_t, uint32_t>> range(binary.size());
  const auto runs = [&](auto&& self, uint32_t b) -> std::pair<uint32_t, uint32_t> {
    const BNode& nd = binary[b];
    if (nd.count > 0) return range[b] = {nd.first, nd.first + nd.count};
    return range[b] = {self(self, nd.first).first, self(self, nd.first + 1).second};
  };
  runs(runs, 0);
  return range;
}

void MeshDistance::fill_leaves(const TriMesh& mesh, const std::vector<uint32_t>& order, const std::vector<Vec3>& lo,
                               const std::vector<Vec3>& hi) {
  tris_.resize(order.size());
  slot_of_.resize(order.size());
  for (uint32_t at = 0; at < order.size(); ++at) slot_of_[order[at]] = at;
  if (pruning_ == Pruning::Full) {
    // Every slot starts bounding nothing: zero planes, sides' offsets +inf (see set_planes).
    planes_.resize(leaves_.size());
    tbb::parallel_for(size_t{0}, planes_.size(), [&](size_t leaf) {
      for (int e = 0; e < 3; ++e) std::fill_n(planes_[leaf].side[e][3], 8, std::numeric_limits<float>::infinity());
    });
  }
  tbb::parallel_for(size_t{0}, leaves_.size(), [&](size_t leaf) {
    LeafBoxes& l = leaves_[leaf];
    for (uint32_t i = 0; i < l.count; ++i) {
      const uint32_t at = l.first + i;
      const FloatBox box(lo[order[at]], hi[order[at]]);
      for (int k = 0; k < 3; ++k) l.lo[k][i] = box.lo[k], l.hi[k][i] = box.hi[k];
      const auto& t = mesh.triangles[order[at]];
      LeafTriangle& tri = tris_[at];
      tri = {mesh.positions[t[0]], mesh.positions[t[1]], mesh.positions[t[2]], order[at], uint32_t(leaf)};
      if (!planes_.empty()) set_planes(planes_[leaf], i, tri.a, tri.b, tri.c, rounding_ / 2);
    }
  });
}

void MeshDistance::fill_oriented_boxes(const std::vector<std::array<uint32_t, 4>>& due) {
  std::vector<Vec3> normals(tris_.size());
  tbb::parallel_for(size_t{0}, tris_.size(), [&](size_t i) {
    const LeafTriangle& t = tris_[i];
    normals[i] = cross3(sub3(t.b, t.a), sub3(t.c, t.a));
  });
  tbb::parallel_for(size_t{0}, due.size(), [&](size_t j) {
    const auto [node, slot, first, last] = due[j];
    set_oriented_box(nodes_[node], slot, &tris_[first], &normals[first], last - first);
  });
}

uint32_t MeshDistance::collapse(const std::vector<BNode>& binary,
                                const std::vector<std::pair<uint32_t, uint32_t>>& range, uint32_t b, uint32_t depth,
                                std::vector<std::array<uint32_t, 4>>& oriented) {
  depth_ = std::max(depth_, depth);
  constexpr float kInf = std::numeric_limits<float>::infinity();
  const BNode& nd = binary[b];
  if (nd.count > 0) {
    const uint32_t leaf = uint32_t(leaves_.size());
    LeafBoxes& l = leaves_.emplace_back();
    for (int k = 0; k < 3; ++k) std::fill_n(l.lo[k], 8, kInf), std::fill_n(l.hi[k], 8, -kInf);
    l.first = nd.first, l.count = nd.count;
    return leaf | kLeafBit;
  }
  // Up to four descendants: the widest inner one opened until there are four (a query opens a
  // box about in proportion to its area), in the binary tree's order.
  uint32_t kids[4] = {nd.first, nd.first + 1};
  int count = 2;
  while (count < 4) {
    int widest = -1;
    double area = -1;
    for (int i = 0; i < count; ++i) {
      const BNode& k = binary[kids[i]];
      if (k.count == 0 && half_area(k.lo, k.hi) > area) area = half_area(k.lo, k.hi), widest = i;
    }
    if (widest < 0) break;
    const uint32_t first = binary[kids[widest]].first;
    for (int i = count; i > widest + 1; --i) kids[i] = kids[i - 1];
    kids[widest] = first, kids[widest + 1] = first + 1;
    ++count;
  }
  const uint32_t self = uint32_t(nodes_.size());
  nodes_.emplace_back();
  Node4 out;
  for (int k = 0; k < 3; ++k) {
    std::fill_n(out.lo[k], 4, kInf), std::fill_n(out.hi[k], 4, -kInf);
    for (int j = 0; j < 3; ++j) std::fill_n(out.axis[k][j], 4, k == j ? 1.0f : 0.0f);
    // Unused slots' oriented boxes are empty; with Pruning::Boxes none is built, and each
    // bounds nothing (were it ever measured).
    const bool none = pruning_ == Pruning::Boxes;
    std::fill_n(out.along[k][0], 4, none ? -kInf : kInf), std::fill_n(out.along[k][1], 4, none ? kInf : -kInf);
  }
  for (int i = 0; i < 4; ++i) out.child[i] = kNoChild;
  for (int i = 0; i < count; ++i) {
    const FloatBox box(binary[kids[i]].lo, binary[kids[i]].hi);
    for (int k = 0; k < 3; ++k) out.lo[k][i] = box.lo[k], out.hi[k][i] = box.hi[k];
    if (!range.empty()) oriented.push_back({self, uint32_t(i), range[kids[i]].first, range[kids[i]].second});
    out.child[i] = collapse(binary, range, kids[i], depth + 1, oriented);
  }
  nodes_[self] = out;
  return self;
}

void MeshDistance::set_oriented_box(Node4& n, uint32_t i, const LeafTriangle* tris, const Vec3* normals,
                                    uint32_t count) {
  const auto centroid = [&](uint32_t t) { return scale3(add3(add3(tris[t].a, tris[t].b), tris[t].c), 1.0 / 3); };
  // The normal: the triangles' normals weighted by area; across it, the principal direction
  // of their centroids' spread in its plane.
  Vec3 normal{0, 0, 0}, mean{0, 0, 0};
  for (uint32_t t = 0; t < count; ++t) normal = add3(normal, normals[t]), mean = add3(mean, centroid(t));
  const double len = norm3(normal);
  normal = len > kTinyDivisor ? scale3(normal, 1 / len) : Vec3{0, 0, 1};
  mean = scale3(mean, 1.0 / double(count));
  const int least = std::abs(normal[0]) <= std::abs(normal[1]) && std::abs(normal[0]) <= std::abs(normal[2]) ? 0
                    : std::abs(normal[1]) <= std::abs(normal[2])                                           ? 1
                                                                                                           : 2;
  Vec3 e{0, 0, 0};
  e[least] = 1;
  const Vec3 t1 = scale3(cross3(normal, e), 1 / norm3(cross3(normal, e))), t2 = cross3(normal, t1);
  double c11 = 0, c12 = 0, c22 = 0;
  for (uint32_t t = 0; t < count; ++t) {
    const Vec3 d = sub3(centroid(t), mean);
    const double x = dot3(d, t1), y = dot3(d, t2);
    c11 += x * x, c12 += x * y, c22 += y * y;
  }
  const double angle = 0.5 * std::atan2(2 * c12, c11 - c22);
  const Vec3 u = add3(scale3(t1, std::cos(angle)), scale3(t2, std::sin(angle))), v = cross3(normal, u);
  // The axes as stored (floats); the extents along them, in doubles from those, rounded out.
  const Vec3* axes[3] = {&normal, &u, &v};
  Vec3 stored[3];
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j) stored[k][j] = double(n.axis[k][j][i] = float((*axes[k])[j]));
  double lo[3] = {kHuge, kHuge, kHuge}, hi[3] = {-kHuge, -kHuge, -kHuge};
  for (uint32_t t = 0; t < count; ++t)
    for (const Vec3* c : {&tris[t].a, &tris[t].b, &tris[t].c})
      for (int k = 0; k < 3; ++k) {
        const double x = dot3(stored[k], *c);
        lo[k] = std::min(lo[k], x), hi[k] = std::max(hi[k], x);
      }
  for (int k = 0; k < 3; ++k) n.along[k][0][i] = round_down(lo[k]), n.along[k][1][i] = round_up(hi[k]);
}

void MeshDistance::set_planes(LeafPlanes& l, uint32_t i, const Vec3& a, const Vec3& b, const Vec3& c,
                              double tolerance) {
  // Slot i starts bounding nothing (zero plane, every side's offset +inf: p is -inf outside
  // each side); a plane or side is kept only where the corners, measured against it as
  // stored, lie on it (or inside it) within `tolerance`. A sliver's cross product is mostly
  // rounding: its plane can miss its own corners by far more than the slack a query allows.
  const Vec3 corner[3] = {a, b, c};
  const Vec3 n = cross3(sub3(b, a), sub3(c, a));
  const double twice_area = norm3(n);
  if (!(twice_area > kTinyDivisor)) return;
  const Vec3 u = scale3(n, 1 / twice_area);
  const auto stored = [&](const Vec3& v, double offset, Vec3& out) {
    for (int k = 0; k < 3; ++k) out[k] = double(float(v[k]));
    return double(float(offset));
  };
  Vec3 un;
  const double uc = stored(u, dot3(u, a), un);
  for (const Vec3& x : corner)
    if (!(std::abs(dot3(un, x) - uc) <= tolerance)) return;
  for (int k = 0; k < 3; ++k) l.plane[k][i] = float(un[k]);
  l.plane[3][i] = float(uc);
  for (int e = 0; e < 3; ++e) {
    // In the plane, perpendicular to the side, away from the third corner.
    const Vec3 m = cross3(sub3(corner[(e + 1) % 3], corner[e]), u);
    const double len = norm3(m);
    if (!(len > kTinyDivisor)) continue;
    Vec3 mn;
    const double mc = stored(scale3(m, 1 / len), dot3(m, corner[e]) / len, mn);
    const double o0 = dot3(mn, corner[e]) - mc, o1 = dot3(mn, corner[(e + 1) % 3]) - mc,
                 o2 = dot3(mn, corner[(e + 2) % 3]) - mc;
    if (!(std::abs(o0) <= tolerance && std::abs(o1) <= tolerance && o2 <= tolerance)) continue;
    for (int k = 0; k < 3; ++k) l.side[e][k][i] = float(mn[k]);
    l.side[e][3][i] = float(mc);
  }
}

/// Visits the triangles whose bounds may be nearer than best2 (squared), the nearest child of
/// each node opened next, with the triangle's squared lower bound; `visit` lowers best2 as it
/// finds nearer triangles. Which boxes are opened depends on best2, their order does not.
template <class Visit>
void MeshDistance::search(const Vec3& p, double& best2, Visit&& visit) const {
  if (tris_.empty()) return;
  const FloatPoint q(p, rounding_, far_);
  struct Entry {
    uint32_t ref;
    double d2;
  };
  TraversalStack<Entry> stack(depth_);
  int top = 0;
  stack[top++] = {root_, 0};
  while (top > 0) {
    const Entry e = stack[--top];
    if (e.d2 >= best2) continue;
    if (e.ref & kLeafBit) {
      const uint32_t leaf = e.ref & ~kLeafBit;
      alignas(16) float d[8];
      leaf_distance2(leaves_[leaf], planes_of(leaf), q, d);
      const LeafBoxes& l = leaves_[leaf];
      for (uint32_t i = 0; i < l.count; ++i)
        if (double(d[i]) < best2) visit(tris_[l.first + i], double(d[i]));
      continue;
    }
    const Node4& nd = nodes_[e.ref];
    alignas(16) float d[4];
    children_distance2(nd, q, pruning_ == Pruning::Full, d);
    // The children within best2, the nearest last so that it is opened next.
    const int first = top;
    for (int i = 0; i < 4 && nd.child[i] != kNoChild; ++i) {
      if (!(double(d[i]) < best2)) continue;
      stack[top] = {nd.child[i], double(d[i])};
      if (top > first && stack[top].d2 > stack[top - 1].d2) std::swap(stack[top], stack[top - 1]);
      ++top;
    }
  }
}

double MeshDistance::distance(const Vec3& p) const {
  double best2 = std::numeric_limits<double>::infinity();
  search(p, best2, [&](const LeafTriangle& t, double lower2) {
    if (lower2 < best2) best2 = std::min(best2, point_triangle_distance2(p, t.a, t.b, t.c));
  });
  return std::sqrt(best2);
}

bool MeshDistance::within(const Vec3& p, double r, uint32_t* hint, double* found) const {
  const double r2 = r * r;
  double d2 = 0;
  auto reaches = [&](const LeafTriangle& t, double lower2) {
    return lower2 <= r2 && (d2 = point_triangle_distance2(p, t.a, t.b, t.c)) <= r2;
  };
  auto take = [&](const LeafTriangle& t) {
    if (hint) *hint = static_cast<uint32_t>(&t - tris_.data());
    if (found) *found = std::sqrt(d2);
    return true;
  };
  // The hint's leaf and the leaves on either side first: stored in leaf order, they lie close
  // by. The nearest of their triangles, not the first: a caller keeping `found` as a bound on
  // the point's distance (the simplifier) keeps it low.
  if (hint && *hint < tris_.size()) {
    const FloatPoint q(p, rounding_, far_);
    const uint32_t leaf = tris_[*hint].leaf, last = uint32_t(leaves_.size()) - 1;
    double best2 = r2;
    const LeafTriangle* best = nullptr;
    for (uint32_t l = leaf > 0 ? leaf - 1 : 0; l <= std::min(leaf + 1, last); ++l) {
      alignas(16) float d[8];
      leaf_distance2(leaves_[l], planes_of(l), q, d);
      const uint32_t first = leaves_[l].first;
      for (uint32_t i = 0; i < leaves_[l].count; ++i)
        if (double(d[i]) <= best2 && reaches(tris_[first + i], d[i]) && d2 <= best2)
          best2 = d2, best = &tris_[first + i];
    }
    if (best) {
      d2 = best2;
      return take(*best);
    }
  }
  // Just above r^2, so that a box at exactly r is still opened; once a triangle is found the
  // bound drops below every distance and the search ends.
  double bound2 = std::nextafter(r2, std::numeric_limits<double>::infinity());
  search(p, bound2, [&](const LeafTriangle& t, double lower2) {
    if (bound2 >= 0 && reaches(t, lower2)) {
      bound2 = -1;
      take(t);
    }
  });
  return bound2 < 0;
}

namespace {

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
  const FloatBox q(lo, hi);
  const double r2 = r * r;
  auto away = [&](const LeafTriangle& t) {
    const Vec3 n = cross3(sub3(t.b, t.a), sub3(t.c, t.a));
    const double len = norm3(n);
    return triangle_farther(box, t.a, t.b, t.c, len > 0 ? scale3(n, 1 / len) : Vec3{0, 0, 0}, r, kOctantDepth);
  };
  if (tris_.empty()) return true;
  // Beyond kFar the float boxes prune nothing (see kFar): every triangle is asked.
  const bool far = far_ || !(std::max(largest_coordinate(lo), largest_coordinate(hi)) <= kFar);
  TraversalStack<uint32_t> stack(depth_);
  int top = 0;
  stack[top++] = root_;
  while (top > 0) {
    const uint32_t ref = stack[--top];
    if (ref & kLeafBit) {
      const uint32_t leaf = ref & ~kLeafBit;
      alignas(16) float d[8] = {};
      if (!far) leaf_boxes_distance2(leaves_[leaf], q, d);
      for (uint32_t i = 0; i < leaves_[leaf].count; ++i)
        if (double(d[i]) <= r2 && !away(tris_[leaves_[leaf].first + i])) return false;
      continue;
    }
    const Node4& nd = nodes_[ref];
    alignas(16) float d[4] = {};
    if (!far) box_distance2_x4(&nd.lo[0][0], &nd.hi[0][0], 4, q, d);
    for (int i = 0; i < 4 && nd.child[i] != kNoChild; ++i)
      if (double(d[i]) <= r2) stack[top++] = nd.child[i];
  }
  return true;
}

double MeshDistance::distance_to_hint(const Vec3& p, uint32_t hint) const {
  const LeafTriangle& t = tris_[hint];
  return std::sqrt(point_triangle_distance2(p, t.a, t.b, t.c));
}

size_t MeshDistance::nearest_within(const Vec3& p, double r, std::vector<Nearest>& out) const {
  out.clear();
  // The bounds are rounded outward, so the search's cut-off is a hair above r: each triangle
  // it offers is measured exactly.
  const double r2 = r * r;
  double cut2 = r2 * (1 + 1e-6) + kTinyDivisor;
  size_t best = 0;
  search(p, cut2, [&](const LeafTriangle& t, double) {
    Nearest n = nearest_on_triangle2(p, t.a, t.b, t.c);  // distance squared, ranked so
    if (!(n.distance <= r2)) return;
    n.triangle = t.id;
    out.push_back(n);
    const Nearest& b = out[best];
    if (n.distance < b.distance || (n.distance == b.distance && n.triangle < b.triangle)) best = out.size() - 1;
  });
  for (Nearest& n : out) n.distance = std::sqrt(n.distance);
  return out.empty() ? 0 : best;
}

Nearest MeshDistance::nearest(const Vec3& p, uint32_t* hint) const {
  double best2 = std::numeric_limits<double>::infinity();
  Nearest best;
  if (hint && *hint < tris_.size()) {
    const LeafTriangle& t = tris_[*hint];
    best = nearest_on_triangle2(p, t.a, t.b, t.c);
    best.triangle = t.id;
    // A hair more: the search must still find the hint's own triangle when it is the answer.
    if (std::isfinite(best.distance)) best2 = best.distance * (1 + kHintSlack) + kTinyDivisor;
  }
  // The same answer whatever the hint, so a point asked twice gets one value (its feature, and
  // so its sign): the boxes visit in an order the hint does not change, and the hint's bound is
  // a hair above its distance, so no triangle at the least distance is pruned before the first
  // of them in that order is found; that one is the answer (a later one at the same distance
  // takes it only with a lower index, and once the distance is 0 none is looked at).
  uint32_t slot = hint ? *hint : 0;
  search(p, best2, [&](const LeafTriangle& t, double lower2) {
    if (lower2 >= best2) return;
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
  nd.lo = box.lo, nd.hi = box.hi;
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
  return signed_at(p, n, gradient);
}

double SignedDistance::signed_at(const Vec3& p, const Nearest& n, Vec3& gradient) const {
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

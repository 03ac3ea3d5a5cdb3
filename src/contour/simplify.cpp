// Output sized to the geometry: a dual contour has a vertex per gray cell, so a flat face or a
// straight crease costs one vertex per finest cell along it. Edge collapses merge those
// vertices: both ends move to the point nearest their planes (on a crease, onto its line),
// allowed where every distinct plane of the original triangles merged into either end passes
// within the tolerance of that point. Each collapse is checked locally (the link condition
// keeps the mesh closed and 2-manifold; the turned triangles keep their orientation and do not
// become needles), and the whole result is checked for crossings before it replaces the
// contour.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <optional>
#include <utility>
#include <vector>


#include "geometry/qef.h"
#include "geometry/tolerances.h"
#include "geometry/vec3.h"
#include "pic/contour.h"
#include "pic/measure.h"

namespace pic {

namespace {

using detail::cross3;
using detail::dot3;
using detail::norm3;
using detail::kKeptNormalCosine;
using detail::kMinTriangleQuality;

/// A symmetric 4x4 quadric: the sum of squared distances to a set of planes.
struct Quadric {
  std::array<double, 10> q{};  // xx xy xz xw yy yz yw zz zw ww
  void add_plane(const Vec3& n, double d) {
    const double a = n[0], b = n[1], c = n[2];
    const double v[10] = {a * a, a * b, a * c, a * d, b * b, b * c, b * d, c * c, c * d, d * d};
    for (int i = 0; i < 10; ++i) q[i] += v[i];
    ++count;
  }
  void add(const Quadric& o) {
    for (int i = 0; i < 10; ++i) q[i] += o.q[i];
    count += o.count;
  }
  /// The mean squared distance: no plane is nearer than that on the whole.
  double mean_at(const Vec3& p) const { return count ? at(p) / count : 0; }
  double count = 0;
  /// The point nearest the planes from `seed`: seed + A+ (b - A seed), with A+ the
  /// pseudo-inverse truncated below a fraction of A's largest eigenvalue, so the point moves
  /// only across the planes and stays at the seed along the directions they leave free.
  Vec3 minimum_near(const Vec3& seed) const {
    detail::Qef e;
    e.a = {q[0], q[1], q[2], q[4], q[5], q[7]};
    e.b = {-q[3], -q[6], -q[8]};
    e.c = q[9];
    e.weight = 1;
    return e.solve(seed).position;
  }
  double at(const Vec3& p) const {
    const double x = p[0], y = p[1], z = p[2];
    return q[0] * x * x + 2 * q[1] * x * y + 2 * q[2] * x * z + 2 * q[3] * x + q[4] * y * y + 2 * q[5] * y * z +
           2 * q[6] * y + q[7] * z * z + 2 * q[8] * z + q[9];
  }
};

Vec3 normal_of(const Vec3& a, const Vec3& b, const Vec3& c) {
  return cross3({b[0] - a[0], b[1] - a[1], b[2] - a[2]}, {c[0] - a[0], c[1] - a[1], c[2] - a[2]});
}

double dist2(const Vec3& a, const Vec3& b) {
  const double x = a[0] - b[0], y = a[1] - b[1], z = a[2] - b[2];
  return x * x + y * y + z * z;
}

/// 1 for an equilateral triangle, 0 for a flat one: 4 sqrt(3) area / (sum of squared sides).
double quality(const Vec3& a, const Vec3& b, const Vec3& c) {
  const double s = dist2(a, b) + dist2(b, c) + dist2(c, a);
  return s > 0 ? 2 * std::sqrt(3.0) * norm3(normal_of(a, b, c)) / s : 0;
}


/// A plane n.x + d = 0, n of unit length.
struct Plane {
  Vec3 n;
  double d;
};
/// The most planes one vertex may answer for: a merge beyond is refused (curved parts keep
/// their vertices long before, flat parts and creases need one to three).
constexpr size_t kMaxPlanes = 48;

/// Adds p to a set of planes unless one already there is the same plane: normals within about
/// 1e-5 radians, offsets within `same` (a hundredth of the tolerance).
void add_plane(std::vector<Plane>& set, const Plane& p, double same) {
  for (const Plane& q : set)
    if (dot3(p.n, q.n) > 1 - 1e-10 && std::abs(p.d - q.d) <= same) return;
  set.push_back(p);
}
/// The largest distance from x to the planes.
double farthest(const std::vector<Plane>& set, const Vec3& x) {
  double far = 0;
  for (const Plane& p : set) far = std::max(far, std::abs(dot3(p.n, x) + p.d));
  return far;
}

class Simplifier {
 public:
  /// `frozen`: per vertex of `mesh`, whether it must stay where it is (empty: none).
  Simplifier(const TriMesh& mesh, double tolerance, const std::vector<uint8_t>& frozen)
      : pos_(mesh.positions), tris_(mesh.triangles), tol_(tolerance), same_(tolerance / 100), quadric_(pos_.size()),
        planes_(pos_.size()), faces_(pos_.size()), alive_(tris_.size(), 1), merged_into_(pos_.size()),
        frozen_(frozen) {
    std::iota(merged_into_.begin(), merged_into_.end(), 0u);
    frozen_.resize(pos_.size(), 0);
    for (uint32_t f = 0; f < tris_.size(); ++f) {
      const auto& t = tris_[f];
      const Vec3 n = normal_of(pos_[t[0]], pos_[t[1]], pos_[t[2]]);
      const double len = norm3(n);
      for (int k = 0; k < 3; ++k) faces_[t[k]].push_back(f);
      if (!(len > 0)) continue;
      const Vec3 u{n[0] / len, n[1] / len, n[2] / len};
      const double d = -dot3(u, pos_[t[0]]);
      for (int k = 0; k < 3; ++k) {
        quadric_[t[k]].add_plane(u, d);
        add_plane(planes_[t[k]], {u, d}, same_);
      }
    }
  }

  /// Passes over the vertices, each moving onto the neighbour that keeps the planes closest,
  /// until one collapses fewer than a thousandth of them; after the first, only vertices whose
  /// star changed are tried again.
  void run() {
    std::vector<uint8_t> dirty(pos_.size(), 1), next(pos_.size(), 0);
    for (int pass = 0; pass < 32; ++pass) {
      size_t done = 0;
      for (uint32_t u = 0; u < pos_.size(); ++u)
        if (dirty[u] && !faces_[u].empty() && collapse_cheapest(u)) {
          for (uint32_t w : ring_u_) next[w] = 1;
          ++done;
        }
      if (done * 1000 < pos_.size()) break;
      dirty.swap(next);
      std::fill(next.begin(), next.end(), 0);
    }
  }

  /// The input vertex that u was merged into, at last (u itself when it was kept).
  uint32_t survivor(uint32_t u) {
    uint32_t root = u;
    while (merged_into_[root] != root) root = merged_into_[root];
    while (merged_into_[u] != root) u = std::exchange(merged_into_[u], root);  // shorten the chain
    return root;
  }

  /// The simplified mesh; `kept[i]`: the vertex of the input that output vertex i is.
  TriMesh result(std::vector<uint32_t>& kept) const {
    TriMesh out;
    kept.clear();
    std::vector<uint32_t> remap(pos_.size(), UINT32_MAX);
    for (uint32_t f = 0; f < tris_.size(); ++f) {
      if (!alive_[f]) continue;
      std::array<uint32_t, 3> t;
      for (int k = 0; k < 3; ++k) {
        uint32_t& r = remap[tris_[f][k]];
        if (r == UINT32_MAX) {
          r = uint32_t(out.positions.size());
          out.positions.push_back(pos_[tris_[f][k]]);
          kept.push_back(tris_[f][k]);
        }
        t[k] = r;
      }
      out.triangles.push_back(t);
    }
    return out;
  }

 private:
  std::vector<Vec3> pos_;
  std::vector<std::array<uint32_t, 3>> tris_;
  double tol_, same_;
  std::vector<Quadric> quadric_;       // per vertex: its planes summed (where to merge)
  std::vector<std::vector<Plane>> planes_;  // per vertex: the distinct original planes merged into it
  std::vector<std::vector<uint32_t>> faces_;  // per vertex: its live triangles
  std::vector<uint8_t> alive_;
  std::vector<uint32_t> ring_u_, ring_v_;  // scratch
  std::vector<Plane> merged_;
  std::vector<uint32_t> merged_into_;  // per input vertex: the vertex it was merged into, or itself
  std::vector<uint8_t> frozen_;
  struct Candidate {
    double error;
    uint32_t v;
    Vec3 x;
  };
  std::vector<Candidate> candidates_;


  void ring(uint32_t v, std::vector<uint32_t>& out) const {
    out.clear();
    for (uint32_t f : faces_[v])
      for (uint32_t w : tris_[f])
        if (w != v) out.push_back(w);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
  }

  /// Where u and v merge: the point nearest their planes (least squares, truncated along the
  /// directions they leave free, from the edge's middle), or else the better end; nothing when
  /// every choice is farther than the tolerance from one of the original planes merged into u
  /// or v. `error`: the largest distance to them there.
  std::optional<Vec3> merged_position(uint32_t u, uint32_t v, double& error) {
    Quadric q = quadric_[u];
    q.add(quadric_[v]);
    const Vec3 &a = pos_[u], &b = pos_[v];
    const Vec3 mid{(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2};
    const Vec3 x = q.minimum_near(mid);
    // The largest distance is at least the mean: where the mean is over, no need to look.
    const double tol2 = tol_ * tol_;
    if (q.mean_at(x) > tol2 && q.mean_at(a) > tol2 && q.mean_at(b) > tol2) return std::nullopt;
    merged_.assign(planes_[u].begin(), planes_[u].end());
    for (const Plane& p : planes_[v]) add_plane(merged_, p, same_);
    if (merged_.size() > kMaxPlanes) return std::nullopt;
    // Keep to the edge's neighbourhood: a far optimum of nearly parallel planes is no merge.
    if (dist2(x, mid) <= dist2(a, b) && (error = farthest(merged_, x)) <= tol_) return x;
    const double ea = farthest(merged_, a), eb = farthest(merged_, b);
    error = std::min(ea, eb);
    if (error > tol_) return std::nullopt;
    return ea < eb ? a : b;
  }

  /// Merges u with the neighbour that keeps the planes closest, among those that may take it.
  bool collapse_cheapest(uint32_t u) {
    if (frozen_[u]) return false;
    ring(u, ring_u_);
    candidates_.clear();
    double error = 0;
    for (uint32_t v : ring_u_)
      if (!frozen_[v])
        if (const auto x = merged_position(u, v, error)) candidates_.push_back({error, v, *x});
    std::sort(candidates_.begin(), candidates_.end(),
              [](const Candidate& a, const Candidate& b) { return a.error < b.error || (a.error == b.error && a.v < b.v); });
    for (const Candidate& c : candidates_)
      if (can_collapse(u, c.v, c.x)) {
        collapse(u, c.v, c.x);
        return true;
      }
    return false;
  }

  /// The link condition (the vertices next to both u and v are exactly the two across the
  /// edge uv), and every triangle of u or v that survives keeps its orientation and its shape
  /// when both move to x.
  bool can_collapse(uint32_t u, uint32_t v, const Vec3& x) {
    int shared = 0;
    std::array<uint32_t, 2> across{};
    for (uint32_t f : faces_[u]) {
      const auto& t = tris_[f];
      if (t[0] != v && t[1] != v && t[2] != v) continue;
      if (shared == 2) return false;
      for (uint32_t w : t)
        if (w != u && w != v) across[shared] = w;
      ++shared;
    }
    if (shared != 2 || across[0] == across[1]) return false;
    ring(v, ring_v_);
    size_t common = 0;
    for (uint32_t w : ring_u_)
      if (std::binary_search(ring_v_.begin(), ring_v_.end(), w)) ++common;
    if (common != 2) return false;
    // A closed mesh of 4 vertices (a tetrahedron) would fold flat.
    if (ring_u_.size() <= 3 && ring_v_.size() <= 3) return false;
    return keeps_shape(u, v, x) && keeps_shape(v, u, x);
  }

  /// Whether the triangles of `a` without `b` keep orientation and shape with `a` at x.
  bool keeps_shape(uint32_t a, uint32_t b, const Vec3& x) const {
    double worst_before = 1;
    for (uint32_t f : faces_[a]) {
      const auto& t = tris_[f];
      worst_before = std::min(worst_before, quality(pos_[t[0]], pos_[t[1]], pos_[t[2]]));
    }
    const double min_quality = std::min(kMinTriangleQuality, worst_before);
    for (uint32_t f : faces_[a]) {
      const auto& t = tris_[f];
      if (t[0] == b || t[1] == b || t[2] == b) continue;
      std::array<Vec3, 3> p;
      for (int k = 0; k < 3; ++k) p[k] = t[k] == a ? x : pos_[t[k]];
      const Vec3 before = normal_of(pos_[t[0]], pos_[t[1]], pos_[t[2]]);
      const Vec3 after = normal_of(p[0], p[1], p[2]);
      const double lb = norm3(before), la = norm3(after);
      // Turned by less than about 25 degrees: the new fan covers the old star, folding nothing.
      if (!(la > 0) || !(lb > 0) || dot3(before, after) < kKeptNormalCosine * lb * la) return false;
      if (quality(p[0], p[1], p[2]) < min_quality) return false;
    }
    return true;
  }

  void collapse(uint32_t u, uint32_t v, const Vec3& x) {
    pos_[v] = x;
    merged_into_[u] = v;
    for (uint32_t f : faces_[u]) {
      auto& t = tris_[f];
      if (t[0] == v || t[1] == v || t[2] == v) {
        alive_[f] = 0;
        for (uint32_t w : t)
          if (w != u) std::erase(faces_[w], f);
        continue;
      }
      for (uint32_t& w : t)
        if (w == u) w = v;
      faces_[v].push_back(f);
    }
    faces_[u].clear();
    quadric_[v].add(quadric_[u]);
    for (const Plane& p : planes_[u]) add_plane(planes_[v], p, same_);
    planes_[u].clear();
  }
};

}  // namespace

size_t simplify(TriMesh& mesh, double tolerance) {
  if (!(tolerance > 0) || mesh.triangles.empty()) return 0;
  // The local checks keep the mesh closed and 2-manifold; a crossing between parts that are
  // not neighbours (two sheets a fraction of a cell apart) is found on the result. Then the
  // input vertices merged into the crossing triangles stay as they are, and the rest is
  // simplified again (a few rounds; the raw contour when crossings remain).
  std::vector<uint8_t> frozen(mesh.positions.size(), 0);
  for (int round = 0; round < 4; ++round) {
    Simplifier s(mesh, tolerance, frozen);
    s.run();
    std::vector<uint32_t> kept;
    TriMesh out = s.result(kept);
    if (out.triangles.size() == mesh.triangles.size()) return 0;
    const auto crossings = self_intersecting_pairs(out);
    if (crossings.empty()) {
      const size_t removed = mesh.triangles.size() - out.triangles.size();
      mesh = std::move(out);
      return removed;
    }
    std::vector<uint8_t> at_crossing(mesh.positions.size(), 0);
    for (const auto& [a, b] : crossings)
      for (uint32_t t : {a, b})
        for (uint32_t v : out.triangles[t]) at_crossing[kept[v]] = 1;
    for (uint32_t u = 0; u < mesh.positions.size(); ++u)
      if (at_crossing[s.survivor(u)]) frozen[u] = 1;
  }
  return 0;
}

}  // namespace pic

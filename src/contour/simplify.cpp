// Output sized to the geometry: a dual contour has a vertex per gray cell, so a flat face or a
// straight crease costs one vertex per finest cell along it. Half-edge collapses merge those
// vertices where every plane of the original surface around both ends passes within the
// tolerance of the kept end; each collapse is checked locally (the link condition keeps the
// mesh closed and 2-manifold, the turned triangles must keep their orientation), and the whole
// result is checked for crossings before it replaces the contour.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

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
  }
  void add(const Quadric& o) {
    for (int i = 0; i < 10; ++i) q[i] += o.q[i];
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


class Simplifier {
 public:
  Simplifier(const TriMesh& mesh, double tolerance)
      : pos_(mesh.positions), tris_(mesh.triangles), tol2_(tolerance * tolerance), quadric_(pos_.size()),
        faces_(pos_.size()), alive_(tris_.size(), 1) {
    for (uint32_t f = 0; f < tris_.size(); ++f) {
      const auto& t = tris_[f];
      const Vec3 n = normal_of(pos_[t[0]], pos_[t[1]], pos_[t[2]]);
      const double len = norm3(n);
      for (int k = 0; k < 3; ++k) faces_[t[k]].push_back(f);
      if (!(len > 0)) continue;
      const Vec3 u{n[0] / len, n[1] / len, n[2] / len};
      const double d = -dot3(u, pos_[t[0]]);
      for (int k = 0; k < 3; ++k) quadric_[t[k]].add_plane(u, d);
    }
  }

  /// Passes over the edges, shortest first (small triangles merge before long ones form),
  /// until one collapses fewer than a thousandth of the vertices.
  void run() {
    std::vector<std::pair<double, std::pair<uint32_t, uint32_t>>> edges;
    for (int pass = 0; pass < 32; ++pass) {
      edges.clear();
      for (uint32_t f = 0; f < tris_.size(); ++f) {
        if (!alive_[f]) continue;
        for (int k = 0; k < 3; ++k) {
          const uint32_t a = tris_[f][k], b = tris_[f][(k + 1) % 3];
          edges.push_back({dist2(pos_[a], pos_[b]), {a, b}});  // each edge once per side: both directions
        }
      }
      std::sort(edges.begin(), edges.end());
      size_t done = 0;
      for (const auto& [len, e] : edges) {
        const auto [u, v] = e;
        if (faces_[u].empty() || faces_[v].empty()) continue;
        Quadric q = quadric_[u];
        q.add(quadric_[v]);
        if (!(q.at(pos_[v]) <= tol2_)) continue;
        ring(u, ring_u_);
        if (!std::binary_search(ring_u_.begin(), ring_u_.end(), v) || !can_collapse(u, v)) continue;
        collapse(u, v);
        ++done;
      }
      if (done * 1000 < pos_.size()) break;
    }
  }

  TriMesh result() const {
    TriMesh out;
    std::vector<uint32_t> remap(pos_.size(), UINT32_MAX);
    for (uint32_t f = 0; f < tris_.size(); ++f) {
      if (!alive_[f]) continue;
      std::array<uint32_t, 3> t;
      for (int k = 0; k < 3; ++k) {
        uint32_t& r = remap[tris_[f][k]];
        if (r == UINT32_MAX) {
          r = uint32_t(out.positions.size());
          out.positions.push_back(pos_[tris_[f][k]]);
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
  double tol2_;
  std::vector<Quadric> quadric_;
  std::vector<std::vector<uint32_t>> faces_;  // per vertex: its live triangles
  std::vector<uint8_t> alive_;
  std::vector<uint32_t> ring_u_, ring_v_;  // scratch


  void ring(uint32_t v, std::vector<uint32_t>& out) const {
    out.clear();
    for (uint32_t f : faces_[v])
      for (uint32_t w : tris_[f])
        if (w != v) out.push_back(w);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
  }

  /// The link condition (the vertices next to both u and v are exactly the two across the
  /// edge uv), and every triangle of u that survives keeps its orientation when u moves to v.
  bool can_collapse(uint32_t u, uint32_t v) {
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
    double worst_before = 1;
    for (uint32_t f : faces_[u]) {
      const auto& t = tris_[f];
      worst_before = std::min(worst_before, quality(pos_[t[0]], pos_[t[1]], pos_[t[2]]));
    }
    const double min_quality = std::min(kMinTriangleQuality, worst_before);
    for (uint32_t f : faces_[u]) {
      const auto& t = tris_[f];
      if (t[0] == v || t[1] == v || t[2] == v) continue;
      std::array<Vec3, 3> p;
      for (int k = 0; k < 3; ++k) p[k] = pos_[t[k] == u ? v : t[k]];
      const Vec3 before = normal_of(pos_[t[0]], pos_[t[1]], pos_[t[2]]);
      const Vec3 after = normal_of(p[0], p[1], p[2]);
      const double lb = norm3(before), la = norm3(after);
      // Turned by less than about 25 degrees, and not a sliver: the new fan covers the old star.
      if (!(la > 0) || !(lb > 0) || dot3(before, after) < kKeptNormalCosine * lb * la) return false;
      if (quality(p[0], p[1], p[2]) < min_quality) return false;
    }
    return true;
  }

  void collapse(uint32_t u, uint32_t v) {
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
  }
};

}  // namespace

size_t simplify(TriMesh& mesh, double tolerance) {
  if (!(tolerance > 0) || mesh.triangles.empty()) return 0;
  Simplifier s(mesh, tolerance);
  s.run();
  TriMesh out = s.result();
  // The local checks keep the mesh closed and 2-manifold; a crossing between parts that are
  // not neighbours is checked once, on the result: the contour stays where one would appear.
  if (out.triangles.size() == mesh.triangles.size() || !self_intersecting_pairs(out).empty()) return 0;
  const size_t removed = mesh.triangles.size() - out.triangles.size();
  mesh = std::move(out);
  return removed;
}

}  // namespace pic

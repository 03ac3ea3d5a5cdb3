// Test helpers: exact point-to-mesh distance (BVH accelerated), a sampled two-sided
// (Hausdorff) distance between meshes, and topology assertions.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <string>
#include <vector>

#include "pic/pic.h"

namespace pic::test {

inline Vec3 sub3(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline Vec3 add3(const Vec3& a, const Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
inline Vec3 mul3(const Vec3& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
inline double dot3(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline Vec3 cross3(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double norm3(const Vec3& a) { return std::sqrt(dot3(a, a)); }
inline double dist3(const Vec3& a, const Vec3& b) { return norm3(sub3(a, b)); }

/// Closest point on triangle abc to p (Ericson, Real-Time Collision Detection 5.1.5).
inline Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = sub3(b, a), ac = sub3(c, a), ap = sub3(p, a);
  const double d1 = dot3(ab, ap), d2 = dot3(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = sub3(p, b);
  const double d3 = dot3(ab, bp), d4 = dot3(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 / (d1 - d3);
    return add3(a, mul3(ab, v));
  }
  const Vec3 cp = sub3(p, c);
  const double d5 = dot3(ab, cp), d6 = dot3(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double w = d2 / (d2 - d6);
    return add3(a, mul3(ac, w));
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return add3(b, mul3(sub3(c, b), w));
  }
  const double denom = 1.0 / (va + vb + vc);
  if (!std::isfinite(denom)) {  // degenerate triangle: closest of its three edges
    Vec3 best = a;
    double bd = dist3(p, a);
    const Vec3 pts[3] = {a, b, c};
    for (int e = 0; e < 3; ++e) {
      const Vec3 &u = pts[e], &w = pts[(e + 1) % 3];
      const Vec3 d = sub3(w, u);
      const double l2 = dot3(d, d);
      const double t = l2 > 0 ? std::clamp(dot3(sub3(p, u), d) / l2, 0.0, 1.0) : 0.0;
      const Vec3 q = add3(u, mul3(d, t));
      if (dist3(p, q) < bd) {
        bd = dist3(p, q);
        best = q;
      }
    }
    return best;
  }
  const double v = vb * denom, w = vc * denom;
  return add3(a, add3(mul3(ab, v), mul3(ac, w)));
}

inline double point_triangle_distance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  return dist3(p, closest_point_on_triangle(p, a, b, c));
}

/// Exact unsigned distance from points to a triangle mesh, accelerated by a median-split BVH.
class MeshDistance {
 public:
  explicit MeshDistance(const TriMesh& mesh) : mesh_(mesh) {
    const size_t n = mesh.triangles.size();
    order_.resize(n);
    std::iota(order_.begin(), order_.end(), uint32_t{0});
    lo_.resize(n);
    hi_.resize(n);
    centre_.resize(n);
    for (size_t i = 0; i < n; ++i) {
      const auto& t = mesh.triangles[i];
      for (int k = 0; k < 3; ++k) {
        lo_[i][k] = std::min({mesh.positions[t[0]][k], mesh.positions[t[1]][k], mesh.positions[t[2]][k]});
        hi_[i][k] = std::max({mesh.positions[t[0]][k], mesh.positions[t[1]][k], mesh.positions[t[2]][k]});
        centre_[i][k] = (lo_[i][k] + hi_[i][k]) / 2;
      }
    }
    if (n > 0) {
      nodes_.emplace_back();
      build(0, 0, static_cast<uint32_t>(n));
    }
  }

  double distance(const Vec3& p) const {
    double best = std::numeric_limits<double>::infinity();
    if (nodes_.empty()) return best;
    uint32_t stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const BNode& nd = nodes_[stack[--top]];
      if (box_distance(nd, p) >= best) continue;
      if (nd.count > 0) {
        for (uint32_t i = nd.first; i < nd.first + nd.count; ++i) {
          const auto& t = mesh_.triangles[order_[i]];
          best = std::min(best, point_triangle_distance(p, mesh_.positions[t[0]], mesh_.positions[t[1]],
                                                        mesh_.positions[t[2]]));
        }
        continue;
      }
      const BNode &l = nodes_[nd.left], &r = nodes_[nd.left + 1];
      const double dl = box_distance(l, p), dr = box_distance(r, p);
      // Push the farther first so the nearer is explored first.
      if (dl < dr) {
        if (dr < best) stack[top++] = nd.left + 1;
        if (dl < best) stack[top++] = nd.left;
      } else {
        if (dl < best) stack[top++] = nd.left;
        if (dr < best) stack[top++] = nd.left + 1;
      }
    }
    return best;
  }

 private:
  struct BNode {
    Vec3 lo, hi;
    uint32_t left = 0;   // internal: children at left, left + 1
    uint32_t first = 0;  // leaf: range in order_
    uint32_t count = 0;  // 0 = internal
  };

  static double box_distance(const BNode& nd, const Vec3& p) {
    double s = 0;
    for (int k = 0; k < 3; ++k) {
      const double d = std::max({nd.lo[k] - p[k], 0.0, p[k] - nd.hi[k]});
      s += d * d;
    }
    return std::sqrt(s);
  }

  // Builds the subtree of order_[first, last) into nodes_[id]; children are consecutive.
  void build(uint32_t id, uint32_t first, uint32_t last) {
    BNode nd;
    nd.lo = {1e300, 1e300, 1e300};
    nd.hi = {-1e300, -1e300, -1e300};
    for (uint32_t i = first; i < last; ++i)
      for (int k = 0; k < 3; ++k) {
        nd.lo[k] = std::min(nd.lo[k], lo_[order_[i]][k]);
        nd.hi[k] = std::max(nd.hi[k], hi_[order_[i]][k]);
      }
    if (last - first <= 4) {
      nd.first = first;
      nd.count = last - first;
      nodes_[id] = nd;
      return;
    }
    int axis = 0;
    for (int k = 1; k < 3; ++k)
      if (nd.hi[k] - nd.lo[k] > nd.hi[axis] - nd.lo[axis]) axis = k;
    const uint32_t mid = first + (last - first) / 2;
    std::nth_element(order_.begin() + first, order_.begin() + mid, order_.begin() + last,
                     [&](uint32_t a, uint32_t b) { return centre_[a][axis] < centre_[b][axis]; });
    nd.left = static_cast<uint32_t>(nodes_.size());
    nodes_.emplace_back();
    nodes_.emplace_back();
    nodes_[id] = nd;
    build(nd.left, first, mid);
    build(nd.left + 1, mid, last);
  }

  const TriMesh& mesh_;
  std::vector<uint32_t> order_;
  std::vector<Vec3> lo_, hi_, centre_;
  std::vector<BNode> nodes_;
};

inline double point_mesh_distance(const TriMesh& mesh, const Vec3& p) { return MeshDistance(mesh).distance(p); }

/// Deterministic 64-bit generator (SplitMix64) with a portable double in [0, 1).
class Rng {
 public:
  explicit Rng(uint64_t seed) : s_(seed) {}
  uint64_t next() {
    uint64_t z = (s_ += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  double uniform() { return double(next() >> 11) * (1.0 / 9007199254740992.0); }

 private:
  uint64_t s_;
};

/// All vertices plus `samples` area-weighted random points on the surface (deterministic).
inline std::vector<Vec3> surface_points(const TriMesh& m, size_t samples, uint64_t seed = 12345) {
  std::vector<Vec3> pts = m.positions;
  std::vector<double> cum(m.triangles.size());
  double total = 0;
  for (size_t i = 0; i < m.triangles.size(); ++i) {
    const auto& t = m.triangles[i];
    total += norm3(cross3(sub3(m.positions[t[1]], m.positions[t[0]]), sub3(m.positions[t[2]], m.positions[t[0]]))) / 2;
    cum[i] = total;
  }
  if (!(total > 0)) return pts;
  Rng rng(seed);
  for (size_t s = 0; s < samples; ++s) {
    const double x = rng.uniform() * total;
    size_t i = std::upper_bound(cum.begin(), cum.end(), x) - cum.begin();
    i = std::min(i, cum.size() - 1);
    const auto& t = m.triangles[i];
    double u = rng.uniform(), v = rng.uniform();
    if (u + v > 1) {
      u = 1 - u;
      v = 1 - v;
    }
    const Vec3 &a = m.positions[t[0]], &b = m.positions[t[1]], &c = m.positions[t[2]];
    pts.push_back(add3(a, add3(mul3(sub3(b, a), u), mul3(sub3(c, a), v))));
  }
  return pts;
}

/// max over points of `from` (vertices + area samples) of the distance to `to`.
inline double one_sided_distance(const TriMesh& from, const TriMesh& to, size_t samples = 20000) {
  const MeshDistance d(to);
  double worst = 0;
  for (const Vec3& p : surface_points(from, samples)) worst = std::max(worst, d.distance(p));
  return worst;
}

/// Hausdorff distance approximated from all vertices of each mesh plus area-weighted samples.
inline double two_sided_distance(const TriMesh& a, const TriMesh& b, size_t samples = 20000) {
  return std::max(one_sided_distance(a, b, samples), one_sided_distance(b, a, samples));
}

inline double nearest_vertex_distance(const TriMesh& mesh, const Vec3& p) {
  double best = std::numeric_limits<double>::infinity();
  for (const Vec3& q : mesh.positions) best = std::min(best, dist3(p, q));
  return best;
}

/// Closed (no boundary / non-manifold edges), manifold vertices, consistent orientation,
/// no degenerate (repeated index) triangles, and at least one triangle.
inline ::testing::AssertionResult IsClosedManifold(const TriMesh& mesh) {
  const MeshTopology t = analyze_topology(mesh);
  if (mesh.triangles.empty()) return ::testing::AssertionFailure() << "mesh has no triangles";
  if (t.manifold() && t.degenerate_triangles == 0) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << "mesh not closed manifold: " << t.vertices << " vertices, " << t.triangles << " triangles, "
         << t.boundary_edges << " boundary edges, " << t.nonmanifold_edges << " non-manifold edges, "
         << t.inconsistent_edges << " inconsistent edges, " << t.nonmanifold_vertices
         << " non-manifold vertices, " << t.degenerate_triangles << " degenerate triangles";
}

/// Number of undirected edges of a (closed) mesh.
inline size_t edge_count(const TriMesh& mesh) {
  std::vector<uint64_t> e;
  e.reserve(mesh.triangles.size() * 3);
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      const uint64_t a = t[k], b = t[(k + 1) % 3];
      e.push_back(std::min(a, b) << 32 | std::max(a, b));
    }
  std::sort(e.begin(), e.end());
  return static_cast<size_t>(std::unique(e.begin(), e.end()) - e.begin());
}

/// V - E + F.
inline long euler_characteristic(const TriMesh& mesh) {
  return long(mesh.positions.size()) - long(edge_count(mesh)) + long(mesh.triangles.size());
}

/// Connected components by shared vertices.
inline size_t component_count(const TriMesh& mesh) {
  std::vector<uint32_t> parent(mesh.positions.size());
  std::iota(parent.begin(), parent.end(), 0u);
  auto find = [&](uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  std::vector<bool> used(mesh.positions.size(), false);
  for (const auto& t : mesh.triangles) {
    for (uint32_t v : t) used[v] = true;
    parent[find(t[1])] = find(t[0]);
    parent[find(t[2])] = find(t[0]);
  }
  size_t n = 0;
  for (uint32_t v = 0; v < parent.size(); ++v) n += used[v] && find(v) == v;
  return n;
}

/// Distance from p to the surface of the axis-aligned box [lo, hi].
inline double box_surface_distance(const Vec3& p, const Vec3& lo, const Vec3& hi) {
  bool inside = true;
  double out2 = 0, in = 1e300;
  for (int k = 0; k < 3; ++k) {
    if (p[k] < lo[k] || p[k] > hi[k]) inside = false;
    const double d = std::max({lo[k] - p[k], 0.0, p[k] - hi[k]});
    out2 += d * d;
    in = std::min({in, p[k] - lo[k], hi[k] - p[k]});
  }
  return inside ? in : std::sqrt(out2);
}

}  // namespace pic::test

namespace pic {
// The helpers are also visible unqualified inside namespace pic (tests live there).
using namespace pic::test;
}  // namespace pic

// Convex hulls for OpenSCAD's hull(): the 3D hull is geometry/convex_hull.h; here Andrew's
// monotone chain in 2D, and the convex polytope tests and clips that minkowski() cuts its
// operands with.
#include <algorithm>
#include <cmath>
#include <unordered_map>
#include <unordered_set>

#include "pic/measure.h"
#include "geometry/predicates.h"
#include "geometry/tolerances.h"
#include "geometry/union_find.h"
#include "geometry/vec3.h"
#include "scad/lower.h"
#include "scad/scad_detail.h"

namespace pic::detail::scad {

Ring convex_hull_2d(std::vector<P2> p) {
  std::sort(p.begin(), p.end());
  p.erase(std::unique(p.begin(), p.end()), p.end());
  if (p.size() < 3) return {};
  auto cr = [](const P2& o, const P2& a, const P2& b) {
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
  };
  Ring h(2 * p.size());
  size_t k = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && cr(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  for (size_t i = p.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && cr(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  h.resize(k - 1);
  return h;
}

/// Whether a closed surface bounds a convex solid: connected, positive volume, and convex at
/// every edge (each neighbour's far vertex on or below a triangle's plane). A closed connected
/// surface that is locally convex everywhere is the boundary of a convex body. (Not a hull
/// and a volume comparison: the incremental hull does not finish on large, mostly coplanar
/// point sets such as extruded text.)
bool is_convex(const TriMesh& m) {
  if (m.triangles.empty() || !(volume(m) > 0)) return false;
  Vec3 lo = m.positions[m.triangles[0][0]], hi = lo;
  for (const auto& t : m.triangles)
    for (uint32_t v : t)
      for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], m.positions[v][k]), hi[k] = std::max(hi[k], m.positions[v][k]);
  const double eps = kOnPlane * std::hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
  std::unordered_map<uint64_t, uint32_t> by_edge;  // directed edge -> triangle
  by_edge.reserve(3 * m.triangles.size());
  for (uint32_t f = 0; f < m.triangles.size(); ++f)
    for (int e = 0; e < 3; ++e)
      if (!by_edge.emplace(uint64_t(m.triangles[f][e]) << 32 | m.triangles[f][(e + 1) % 3], f).second) return false;
  UnionFind parts(m.triangles.size());
  for (uint32_t f = 0; f < m.triangles.size(); ++f) {
    const auto& t = m.triangles[f];
    const Vec3 &a = m.positions[t[0]], &b = m.positions[t[1]], &c = m.positions[t[2]];
    const Vec3 n = cross3(sub3(b, a), sub3(c, a));
    const double len = std::sqrt(dot3(n, n));
    for (int e = 0; e < 3; ++e) {
      const auto it = by_edge.find(uint64_t(t[(e + 1) % 3]) << 32 | t[e]);
      if (it == by_edge.end()) return false;  // not closed
      parts.join(f, it->second);
      for (uint32_t v : m.triangles[it->second])
        if (len > 0 && dot3(n, sub3(m.positions[v], a)) > eps * len) return false;
    }
  }
  for (uint32_t f = 1; f < m.triangles.size(); ++f)
    if (parts.root(f) != parts.root(0)) return false;
  return true;
}


bool hull_points(const Solid& s, std::vector<Vec3>& out) {
  switch (s.kind) {
    case Solid::Kind::Empty: return true;
    case Solid::Kind::Mesh: out.insert(out.end(), s.mesh.positions.begin(), s.mesh.positions.end()); return true;
    case Solid::Kind::Union:
    case Solid::Kind::Hull:
      for (const Solid& c : s.children)
        if (!hull_points(c, out)) return false;
      return true;
    default: return false;
  }
}

std::vector<Plane> face_planes(const TriMesh& hull) {
  std::vector<Plane> out;
  for (const auto& t : hull.triangles) {
    const Vec3 &a = hull.positions[t[0]], &b = hull.positions[t[1]], &c = hull.positions[t[2]];
    const Vec3 n = cross3(sub3(b, a), sub3(c, a));
    const double len = norm3(n);
    if (!(len > 0)) continue;
    const Plane p{scale3(n, 1 / len), dot3(n, a) / len};
    // The two triangles of a quad give one plane: one clipped piece, not two.
    const bool seen = std::any_of(out.begin(), out.end(), [&](const Plane& q) {
      return dot3(p.n, q.n) > 1 - kSamePlaneCosine && std::abs(p.d - q.d) <= kSamePlaneOffset * (1 + std::abs(p.d));
    });
    if (!seen) out.push_back(p);
  }
  return out;
}

// The part of a convex polytope on the side n.x >= d (`outside` of the plane) or n.x <= d:
// its vertices there and its edges' crossings. Empty when it does not reach past the plane
// by more than eps.
std::vector<Vec3> clip_convex(const TriMesh& hull, const Plane& p, bool outside, double eps) {
  const double sign = outside ? 1 : -1;
  std::vector<double> side(hull.positions.size());
  bool reaches = false;
  for (size_t i = 0; i < side.size(); ++i) {
    side[i] = sign * (dot3(p.n, hull.positions[i]) - p.d);
    reaches = reaches || side[i] > eps;
  }
  if (!reaches) return {};
  std::vector<Vec3> out;
  for (size_t i = 0; i < side.size(); ++i)
    if (side[i] >= 0) out.push_back(hull.positions[i]);
  for (const auto& t : hull.triangles)
    for (int e = 0; e < 3; ++e) {
      const uint32_t a = t[e], b = t[(e + 1) % 3];
      if (a < b && ((side[a] > 0 && side[b] < 0) || (side[a] < 0 && side[b] > 0))) {
        const double l = side[a] / (side[a] - side[b]);
        out.push_back(add3(hull.positions[a], scale3(sub3(hull.positions[b], hull.positions[a]), l)));
      }
    }
  return out;
}

}  // namespace pic::detail::scad

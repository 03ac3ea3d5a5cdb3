// Convex hulls for OpenSCAD's hull(): an incremental 3D hull (each point removes the faces it
// sees and cones the horizon to itself) and Andrew's monotone chain in 2D; and the convex
// polytope tests and clips that minkowski() cuts its operands with.
//
// "Sees" is decided by the exact orientation predicate: a point sees a face only when it lies
// strictly above the face's plane. With a tolerance instead, a point almost on the planes of
// several faces (extruded text: thousands of coplanar points) could see a set of faces that is
// not a disk; its "horizon" was then not a cycle and the face list grew without bound. Exact,
// the visible faces of a convex polytope from a point outside it always form a disk, and
// points on the hull's surface (coplanar, duplicates) are simply not vertices.
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
namespace {

Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// The index of the point of `pts` that maximises `score`.
template <class F>
size_t farthest(const std::vector<Vec3>& pts, const F& score) {
  size_t best = 0;
  double top = -1;
  for (size_t i = 0; i < pts.size(); ++i)
    if (const double s = score(pts[i]); s > top) top = s, best = i;
  return best;
}

}  // namespace

TriMesh convex_hull(const std::vector<Vec3>& pts) {
  TriMesh out;
  if (pts.size() < 4) return out;
  // A first tetrahedron of far-apart points (a leftmost one, the farthest from it, the farthest
  // from their line, the farthest from their plane); none when all points are coplanar.
  const size_t i0 = farthest(pts, [](const Vec3& p) { return -p[0]; });
  const size_t i1 = farthest(pts, [&](const Vec3& p) { return dot(sub(p, pts[i0]), sub(p, pts[i0])); });
  const Vec3 e = sub(pts[i1], pts[i0]);
  const size_t i2 = farthest(pts, [&](const Vec3& p) {
    const Vec3 c = cross(e, sub(p, pts[i0]));
    return dot(c, c);
  });
  const Vec3 n = cross(e, sub(pts[i2], pts[i0]));
  size_t i3 = farthest(pts, [&](const Vec3& p) { return std::abs(dot(n, sub(p, pts[i0]))); });
  int side = orient3d(pts[i0], pts[i1], pts[i2], pts[i3]);
  for (size_t i = 0; i < pts.size() && side == 0; ++i) side = orient3d(pts[i0], pts[i1], pts[i2], pts[i3 = i]);
  if (side == 0) return out;  // flat (or fewer than 3 distinct non-collinear points)

  std::vector<std::array<uint32_t, 3>> faces;  // outward by the right-hand rule
  std::vector<bool> alive;
  const auto add = [&](uint32_t a, uint32_t b, uint32_t c) {
    faces.push_back({a, b, c});
    alive.push_back(true);
  };
  const uint32_t t0 = uint32_t(i0), t1 = uint32_t(i1), t2 = uint32_t(i2), t3 = uint32_t(i3);
  if (side > 0) {  // t3 on the side (t0, t1, t2) faces: that face points inward
    add(t0, t2, t1), add(t0, t1, t3), add(t1, t2, t3), add(t2, t0, t3);
  } else {
    add(t0, t1, t2), add(t0, t3, t1), add(t1, t3, t2), add(t2, t3, t0);
  }
  std::unordered_set<uint64_t> edges;
  std::vector<size_t> visible;
  size_t live = 4;
  for (size_t pi = 0; pi < pts.size(); ++pi) {
    const Vec3& p = pts[pi];
    visible.clear();
    for (size_t f = 0; f < faces.size(); ++f)
      if (alive[f] && orient3d(pts[faces[f][0]], pts[faces[f][1]], pts[faces[f][2]], p) > 0) visible.push_back(f);
    if (visible.empty()) continue;
    edges.clear();
    for (size_t f : visible)
      for (int k = 0; k < 3; ++k) edges.insert(uint64_t(faces[f][k]) << 32 | faces[f][(k + 1) % 3]);
    for (size_t f : visible) {
      alive[f] = false;
      --live;
      for (int k = 0; k < 3; ++k) {
        const uint32_t a = faces[f][k], b = faces[f][(k + 1) % 3];
        if (!edges.count(uint64_t(b) << 32 | a)) {  // a horizon edge
          add(a, b, static_cast<uint32_t>(pi));
          ++live;
        }
      }
    }
    if (faces.size() > 4 * live + 64) {  // drop dead faces so the scan stays short
      size_t kept = 0;
      for (size_t f = 0; f < faces.size(); ++f)
        if (alive[f]) faces[kept++] = faces[f];
      faces.resize(kept);
      alive.assign(kept, true);
    }
  }
  std::vector<uint32_t> remap(pts.size(), UINT32_MAX);
  for (size_t f = 0; f < faces.size(); ++f) {
    if (!alive[f]) continue;
    std::array<uint32_t, 3> tri;
    for (int k = 0; k < 3; ++k) {
      uint32_t& r = remap[faces[f][k]];
      if (r == UINT32_MAX) {
        r = static_cast<uint32_t>(out.positions.size());
        out.positions.push_back(pts[faces[f][k]]);
      }
      tri[k] = r;
    }
    out.triangles.push_back(tri);
  }
  return out;
}

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

// Convex hulls for OpenSCAD's hull(): an incremental 3D hull (each point removes the faces it
// sees and cones the horizon to itself) and Andrew's monotone chain in 2D.
#include <algorithm>
#include <cmath>
#include <unordered_set>

#include "scad/scad_detail.h"

namespace pic::detail::scad {
namespace {

Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double norm(const Vec3& a) { return std::sqrt(dot(a, a)); }

struct Face {
  uint32_t v[3];
  Vec3 n;      // unit outward normal
  double d;    // plane: dot(n, p) = d
  bool alive;
};

}  // namespace

TriMesh convex_hull(const std::vector<Vec3>& pts) {
  TriMesh out;
  if (pts.size() < 4) return out;
  Vec3 lo = pts[0], hi = pts[0];
  for (const Vec3& p : pts)
    for (int d = 0; d < 3; ++d) lo[d] = std::min(lo[d], p[d]), hi[d] = std::max(hi[d], p[d]);
  // Points closer than this to a face plane count as on it (relative to the extent: the
  // coordinates carry ~1e-16 relative error, products of differences ~1e-12 of the extent).
  const double eps = 1e-10 * std::max(norm(sub(hi, lo)), 1e-300);
  // Initial tetrahedron from extreme points.
  size_t i0 = 0;
  for (size_t i = 1; i < pts.size(); ++i)
    if (pts[i][0] < pts[i0][0]) i0 = i;
  size_t i1 = i0;
  double best = 0;
  for (size_t i = 0; i < pts.size(); ++i)
    if (const double dd = norm(sub(pts[i], pts[i0])); dd > best) best = dd, i1 = i;
  if (best <= eps) return out;
  size_t i2 = i0;
  best = 0;
  const Vec3 e = sub(pts[i1], pts[i0]);
  for (size_t i = 0; i < pts.size(); ++i)
    if (const double dd = norm(cross(e, sub(pts[i], pts[i0]))) / norm(e); dd > best) best = dd, i2 = i;
  if (best <= eps) return out;
  Vec3 pn = cross(e, sub(pts[i2], pts[i0]));
  pn = {pn[0] / norm(pn), pn[1] / norm(pn), pn[2] / norm(pn)};
  size_t i3 = i0;
  best = 0;
  for (size_t i = 0; i < pts.size(); ++i)
    if (const double dd = std::abs(dot(pn, sub(pts[i], pts[i0]))); dd > best) best = dd, i3 = i;
  if (best <= eps) return out;

  std::vector<Face> faces;
  auto add = [&](uint32_t a, uint32_t b, uint32_t c) {
    Vec3 n = cross(sub(pts[b], pts[a]), sub(pts[c], pts[a]));
    const double l = norm(n);
    if (l > 0) n = {n[0] / l, n[1] / l, n[2] / l};
    faces.push_back({{a, b, c}, n, dot(n, pts[a]), true});
  };
  const uint32_t t[4] = {uint32_t(i0), uint32_t(i1), uint32_t(i2), uint32_t(i3)};
  if (dot(pn, sub(pts[i3], pts[i0])) > 0) {  // i3 above plane (i0, i1, i2): that face points down
    add(t[0], t[2], t[1]);
    add(t[0], t[1], t[3]);
    add(t[1], t[2], t[3]);
    add(t[2], t[0], t[3]);
  } else {
    add(t[0], t[1], t[2]);
    add(t[0], t[3], t[1]);
    add(t[1], t[3], t[2]);
    add(t[2], t[3], t[0]);
  }
  std::unordered_set<uint64_t> edges;
  std::vector<size_t> visible;
  size_t alive = 4;
  for (size_t pi = 0; pi < pts.size(); ++pi) {
    if (pi == i0 || pi == i1 || pi == i2 || pi == i3) continue;
    const Vec3& p = pts[pi];
    visible.clear();
    for (size_t f = 0; f < faces.size(); ++f)
      if (faces[f].alive && dot(faces[f].n, p) - faces[f].d > eps) visible.push_back(f);
    if (visible.empty()) continue;
    edges.clear();
    for (size_t f : visible)
      for (int k = 0; k < 3; ++k)
        edges.insert(uint64_t(faces[f].v[k]) << 32 | faces[f].v[(k + 1) % 3]);
    for (size_t f : visible) {
      faces[f].alive = false;
      --alive;
      for (int k = 0; k < 3; ++k) {
        const uint32_t a = faces[f].v[k], b = faces[f].v[(k + 1) % 3];
        if (!edges.count(uint64_t(b) << 32 | a)) {  // horizon edge
          add(a, b, static_cast<uint32_t>(pi));
          ++alive;
        }
      }
    }
    if (faces.size() > 4 * alive + 64) {  // drop dead faces so the scan stays short
      std::erase_if(faces, [](const Face& f) { return !f.alive; });
    }
  }
  std::vector<uint32_t> remap(pts.size(), UINT32_MAX);
  for (const Face& f : faces) {
    if (!f.alive) continue;
    std::array<uint32_t, 3> tri;
    for (int k = 0; k < 3; ++k) {
      uint32_t& r = remap[f.v[k]];
      if (r == UINT32_MAX) {
        r = static_cast<uint32_t>(out.positions.size());
        out.positions.push_back(pts[f.v[k]]);
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

}  // namespace pic::detail::scad

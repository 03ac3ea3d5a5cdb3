// The convex hull of a point set: incremental (each point removes the faces it sees and cones
// the horizon to itself). "Sees" is decided by the exact orientation predicate: a point sees a
// face only when it lies strictly above the face's plane. With a tolerance instead, a point
// almost on the planes of several faces (extruded text: thousands of coplanar points) could
// see a set of faces that is not a disk; its "horizon" was then not a cycle and the face list
// grew without bound. Exact, the visible faces of a convex polytope from a point outside it
// always form a disk, and points on the hull's surface (coplanar, duplicates) are simply not
// vertices.
#include "geometry/convex_hull.h"

#include <cmath>
#include <unordered_set>

#include "geometry/live_mesh.h"
#include "geometry/predicates.h"
#include "geometry/vec3.h"

namespace pic::detail {
namespace {

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
  if (pts.size() < 4) return {};
  // A first tetrahedron of far-apart points (a leftmost one, the farthest from it, the farthest
  // from their line, the farthest from their plane); none when all points are coplanar.
  const size_t i0 = farthest(pts, [](const Vec3& p) { return -p[0]; });
  const size_t i1 = farthest(pts, [&](const Vec3& p) { return dot3(sub3(p, pts[i0]), sub3(p, pts[i0])); });
  const Vec3 e = sub3(pts[i1], pts[i0]);
  const size_t i2 = farthest(pts, [&](const Vec3& p) {
    const Vec3 c = cross3(e, sub3(p, pts[i0]));
    return dot3(c, c);
  });
  const Vec3 n = cross3(e, sub3(pts[i2], pts[i0]));
  size_t i3 = farthest(pts, [&](const Vec3& p) { return std::abs(dot3(n, sub3(p, pts[i0]))); });
  int side = orient3d(pts[i0], pts[i1], pts[i2], pts[i3]);
  for (size_t i = 0; i < pts.size() && side == 0; ++i) side = orient3d(pts[i0], pts[i1], pts[i2], pts[i3 = i]);
  if (side == 0) return {};  // flat (or fewer than 3 distinct non-collinear points)

  std::vector<std::array<uint32_t, 3>> faces;  // outward by the right-hand rule
  std::vector<uint8_t> alive;
  const auto add = [&](uint32_t a, uint32_t b, uint32_t c) {
    faces.push_back({a, b, c});
    alive.push_back(1);
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
      alive[f] = 0;
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
      alive.assign(kept, 1);
    }
  }
  return live_mesh(pts, faces, alive);
}

}  // namespace pic::detail

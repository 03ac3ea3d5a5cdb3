// Triangulating every dual polygon as a fan around a point of its minimal edge, with sides
// split at a point of their cells' common face where the segment between the two cells'
// vertices does not cross that face inside it (Ju and Udeshi 2006, "Intersection-free
// contouring on an octree grid"). Every triangle then lies in one cell (the edge point and a
// face point are on the cell's boundary, its vertex inside it), or in the two cells of a side
// that crosses their common face: inside a cell the triangles are cones from its vertex over
// segments of its boundary that meet only at their ends, so triangles of different polygons
// meet only in shared vertices and edges. No exact search, no vertex moves.
#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "contour/dual_walk.h"
#include "geometry/vec3.h"

namespace pic::detail {

// A point f of the common face of a's and b's cells for side a b (c: the third corner of the
// side's triangle), kFanEdgeMargin of the face's side inside its border; false when the
// segment already crosses the face inside it (nothing to split) or the cells share no face.
bool face_point(const VertexCell& ca, const VertexCell& cb, const Vec3& xa, const Vec3& xb, const Vec3& c, Vec3& f) {
  // The axis across the face: where the cells touch (centres half + half apart).
  int axis = 0;
  double best = -1e300;
  for (int d = 0; d < 3; ++d) {
    const double gap = std::abs(cb.center[d] - ca.center[d]) - (ca.half + cb.half);
    if (gap > best) {
      best = gap;
      axis = d;
    }
  }
  if (std::abs(best) > 1e-9 * (ca.half + cb.half)) return false;
  const double plane = ca.center[axis] + (cb.center[axis] > ca.center[axis] ? ca.half : -ca.half);
  const double den = xb[axis] - xa[axis];
  const double t = den != 0 ? std::clamp((plane - xa[axis]) / den, 0.0, 1.0) : 0.5;
  bool inside = true;
  Vec3 lo, hi;
  for (int d = 0; d < 3; ++d) {
    f[d] = xa[d] + t * (xb[d] - xa[d]);
    if (d == axis) continue;
    lo[d] = std::max(ca.center[d] - ca.half, cb.center[d] - cb.half);
    hi[d] = std::min(ca.center[d] + ca.half, cb.center[d] + cb.half);
    if (!(hi[d] > lo[d])) return false;  // the cells touch along an edge only
    inside = inside && f[d] > lo[d] && f[d] < hi[d];
  }
  if (inside) return false;
  f[axis] = plane;
  // Off the face: slide along the line where the plane of the side's triangle (a, b, c)
  // meets the face's plane (which the side's crossing is on), toward the face, so the
  // point stays on the surface as far as the face allows; then into the face.
  const Vec3 n = cross3(sub3(xb, xa), sub3(c, xa));
  const int u = (axis + 1) % 3, w = (axis + 2) % 3;
  const double nn = n[u] * n[u] + n[w] * n[w];
  if (nn > 0) {
    Vec3 mid = f;
    for (int d : {u, w}) mid[d] = std::clamp(f[d], lo[d], hi[d]);
    // Nearest point to the clamped one on the line n_u (x_u - f_u) + n_w (x_w - f_w) = 0.
    const double s = (n[u] * (mid[u] - f[u]) + n[w] * (mid[w] - f[w])) / nn;
    f[u] = mid[u] - s * n[u];
    f[w] = mid[w] - s * n[w];
  }
  for (int d : {u, w}) {
    const double margin = kFanEdgeMargin * (hi[d] - lo[d]);
    f[d] = std::clamp(f[d], lo[d] + margin, hi[d] - margin);
  }
  return true;
}

std::vector<std::array<uint32_t, 3>> fan_triangulate(std::vector<Vec3>& x, const std::vector<VertexCell>& cells,
                                                     const std::vector<MeshPolygon>& polys, size_t* face_points) {
  constexpr uint32_t kNone = ~uint32_t{0};
  std::vector<std::array<uint32_t, 3>> out;
  out.reserve(polys.size() * 4);
  std::unordered_map<uint64_t, uint32_t> face_of_side;  // side (low id << 32 | high id) -> face point or kNone
  size_t faces = 0;
  for (const MeshPolygon& p : polys) {
    std::array<Vec3, 4> q;
    for (int k = 0; k < p.count; ++k) q[k] = x[p.v[k]];
    const Vec3 e = fan_point(q, p.count, p.e0, p.e1);
    const auto ie = static_cast<uint32_t>(x.size());
    x.push_back(e);
    for (int k = 0; k < p.count; ++k) {
      const uint32_t a = p.v[k], b = p.v[(k + 1) % p.count];
      const uint64_t key = uint64_t(std::min(a, b)) << 32 | std::max(a, b);
      auto [it, fresh] = face_of_side.try_emplace(key, kNone);
      if (fresh) {
        Vec3 f;
        if (face_point(cells[a], cells[b], x[a], x[b], e, f)) {
          it->second = static_cast<uint32_t>(x.size());
          x.push_back(f);
          ++faces;
        }
      }
      if (it->second == kNone) {
        out.push_back({ie, a, b});
      } else {
        out.push_back({ie, a, it->second});
        out.push_back({ie, it->second, b});
      }
    }
  }
  if (face_points) *face_points = faces;
  return out;
}

}  // namespace pic::detail

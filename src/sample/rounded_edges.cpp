// The rounds and features an offset makes of a mesh's sharp edges (rounded_edges.h).
#include "sample/rounded_edges.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "geometry/edge_faces.h"
#include "geometry/vec3.h"

namespace pic::detail {

namespace {

Vec3 unit_normal(const TriMesh& m, const std::array<uint32_t, 3>& t) {
  const Vec3 n = cross3(sub3(m.positions[t[1]], m.positions[t[0]]), sub3(m.positions[t[2]], m.positions[t[0]]));
  const double len = norm3(n);
  return len > 0 ? scale3(n, 1 / len) : n;
}

Vec3 nearest_on_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = sub3(b, a);
  const double len2 = dot3(ab, ab);
  const double t = len2 > 0 ? std::clamp(dot3(sub3(p, a), ab) / len2, 0.0, 1.0) : 0.0;
  return add3(a, scale3(ab, t));
}

}  // namespace

RoundedEdges::RoundedEdges(const TriMesh& surface, double distance, double tolerance)
    : radius_(std::abs(distance)), widest_(std::sqrt(8 * std::abs(distance) * tolerance)) {
  // A round bulges at most its radius off its chord.
  if (!(radius_ > tolerance)) return;
  // Faces meeting at more than this angle bulge beyond the tolerance.
  const double min_cos = std::cos(2 * std::acos(std::clamp(1 - tolerance / radius_, -1.0, 1.0)));
  const std::vector<std::pair<uint64_t, uint32_t>> edges = edge_faces(surface);
  std::vector<Box> boxes;
  for (size_t i = 0; i + 1 < edges.size(); ++i) {
    const bool two_faces = edges[i].first == edges[i + 1].first &&
                           (i + 2 == edges.size() || edges[i + 2].first != edges[i].first) &&
                           (i == 0 || edges[i - 1].first != edges[i].first);
    if (!two_faces) continue;
    const auto& t1 = surface.triangles[edges[i].second];
    const auto& t2 = surface.triangles[edges[i + 1].second];
    const Vec3 n1 = unit_normal(surface, t1), n2 = unit_normal(surface, t2);
    if (dot3(n1, n1) == 0 || dot3(n2, n2) == 0) continue;  // a face without area has no side
    if (dot3(n1, n2) > min_cos) continue;                   // too flat to bulge
    const auto a = uint32_t(edges[i].first >> 32), b = uint32_t(edges[i].first & 0xffffffffu);
    // The second face's far corner below the first face's plane: a convex edge.
    uint32_t far = t2[0];
    for (uint32_t v : t2)
      if (v != a && v != b) far = v;
    const bool convex = dot3(n1, sub3(surface.positions[far], surface.positions[a])) < 0;
    if (convex != (distance > 0)) continue;  // the offset keeps it a crease
    const Vec3 &p = surface.positions[a], &q = surface.positions[b];
    segments_.push_back({p, q});
    Box box{p, p};
    for (int k = 0; k < 3; ++k) box.lo[k] = std::min(p[k], q[k]), box.hi[k] = std::max(p[k], q[k]);
    boxes.push_back(box);
  }
  tree_ = std::make_unique<BoxTree>(boxes);
}

void RoundedEdges::points(const Vec3& lo, const Vec3& hi, const Vec3& vertex,
                          std::vector<std::array<Vec3, 2>>& out) const {
  if (segments_.empty() || hi[0] - lo[0] <= widest_) return;
  const Vec3 c = scale3(add3(lo, hi), 0.5);
  const double reach = radius_ + norm3(sub3(hi, lo)) / 2;
  Box q{c, c};
  for (int k = 0; k < 3; ++k) q.lo[k] -= reach, q.hi[k] += reach;
  tree_->query(q, [&](uint32_t j) {
    const Vec3 p = nearest_on_segment(vertex, segments_[j][0], segments_[j][1]);
    const Vec3 d = sub3(vertex, p);
    const double len = norm3(d);
    if (!(len > 0)) return;
    const Vec3 n = scale3(d, 1 / len);
    const Vec3 r = add3(p, scale3(n, radius_));
    for (int k = 0; k < 3; ++k)
      if (r[k] < lo[k] || r[k] > hi[k]) return;
    out.push_back({r, n});
  });
}

std::vector<Vec3> offset_feature_points(const TriMesh& m, const std::vector<double>& distances, double tolerance) {
  std::vector<Vec3> face(m.triangles.size(), Vec3{0, 0, 0}), vertex(m.positions.size(), Vec3{0, 0, 0});
  for (size_t f = 0; f < m.triangles.size(); ++f) {
    const auto& t = m.triangles[f];
    const Vec3 n = cross3(sub3(m.positions[t[1]], m.positions[t[0]]), sub3(m.positions[t[2]], m.positions[t[0]]));
    const double len = norm3(n);
    if (!(len > 0)) continue;
    face[f] = scale3(n, 1 / len);
    for (int k = 0; k < 3; ++k) {
      const Vec3 a = sub3(m.positions[t[(k + 1) % 3]], m.positions[t[k]]);
      const Vec3 b = sub3(m.positions[t[(k + 2) % 3]], m.positions[t[k]]);
      const double angle = std::atan2(norm3(cross3(a, b)), dot3(a, b));
      vertex[t[k]] = add3(vertex[t[k]], scale3(face[f], angle));
    }
  }
  const auto moved = [](const Vec3& p, const Vec3& n, double d) {
    const double len = norm3(n);
    return len > 0 ? add3(p, scale3(n, d / len)) : p;
  };
  const std::vector<std::pair<uint64_t, uint32_t>> edges = edge_faces(m);
  std::vector<Vec3> out;
  for (double d : distances) {
    // A round of radius |d| about faces meeting at angle a bulges |d| (1 - cos(a / 2)) off them.
    const double bulge = std::abs(d) > tolerance ? 2 * std::acos(1 - tolerance / std::abs(d)) : std::numbers::pi;
    const double min_cos = std::cos(std::min(std::numbers::pi / 18, bulge));
    std::vector<uint8_t> vertex_on(m.positions.size(), 0), face_on(m.triangles.size(), 0);
    for (size_t i = 0; i + 1 < edges.size(); ++i) {
      if (edges[i].first != edges[i + 1].first) continue;
      const uint32_t f1 = edges[i].second, f2 = edges[i + 1].second;
      ++i;
      if (!(dot3(face[f1], face[f2]) < min_cos)) continue;
      const uint32_t a = uint32_t(edges[i].first >> 32), b = uint32_t(edges[i].first & 0xffffffffu);
      vertex_on[a] = vertex_on[b] = face_on[f1] = face_on[f2] = 1;
      out.push_back(moved(scale3(add3(m.positions[a], m.positions[b]), 0.5),
                          add3(face[f1], face[f2]), d));
    }
    for (size_t v = 0; v < m.positions.size(); ++v)
      if (vertex_on[v]) out.push_back(moved(m.positions[v], vertex[v], d));
    for (size_t f = 0; f < m.triangles.size(); ++f)
      if (face_on[f]) {
        const auto& t = m.triangles[f];
        const Vec3 c = scale3(add3(add3(m.positions[t[0]], m.positions[t[1]]), m.positions[t[2]]), 1.0 / 3);
        out.push_back(moved(c, face[f], d));
      }
  }
  return out;
}

double bend_tolerance(const Cube& cube, int depth, double error) {
  const double cell = cube.size / double(int64_t{1} << depth);
  return std::min(cell / 2, 2 * std::sqrt(error) * cube.size);
}

}  // namespace pic::detail

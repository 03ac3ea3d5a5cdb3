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

/// Distance from p to triangle abc.
inline double point_triangle_distance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  return distance_to_mesh(TriMesh{{a, b, c}, {{0, 1, 2}}}, {p})[0];
}

inline double point_mesh_distance(const TriMesh& mesh, const Vec3& p) { return distance_to_mesh(mesh, {p})[0]; }

/// All vertices plus `samples` area-weighted random points on the surface (deterministic).
inline std::vector<Vec3> surface_points(const TriMesh& m, size_t samples, uint64_t seed = 12345) {
  return sample_surface(m, samples, seed);
}

/// max over points of `from` (vertices + area samples) of the distance to `to`.
inline double one_sided_distance(const TriMesh& from, const TriMesh& to, size_t samples = 20000) {
  return surface_distance(from, to, samples).a_to_b;
}

/// Hausdorff distance approximated from all vertices of each mesh plus area-weighted samples.
inline double two_sided_distance(const TriMesh& a, const TriMesh& b, size_t samples = 20000) {
  return surface_distance(a, b, samples).hausdorff;
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

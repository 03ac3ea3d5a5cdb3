// Distances between surfaces, for `pic compare`, tests and benchmarks: exact point-to-triangle
// distances over a median-split BVH, sampled at every vertex plus area-weighted points.
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "geometry/lattice.h"
#include "geometry/mesh_distance.h"
#include "geometry/tolerances.h"
#include "geometry/vec3.h"
#include "pic/measure.h"
#include "pic/types.h"

namespace pic {
namespace {

using detail::MeshDistance;
using detail::add3;
using detail::scale3;
using detail::cross3;
using detail::dot3;
using detail::norm3;
using detail::sub3;

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
std::vector<Vec3> surface_points(const TriMesh& m, size_t samples, uint64_t seed = 12345) {
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
    pts.push_back(add3(a, add3(scale3(sub3(b, a), u), scale3(sub3(c, a), v))));
  }
  return pts;
}

}  // namespace

std::vector<Vec3> sample_surface(const TriMesh& mesh, size_t samples, uint64_t seed) {
  return surface_points(mesh, samples, seed);
}

std::vector<double> distance_to_mesh(const TriMesh& mesh, const std::vector<Vec3>& points) {
  const MeshDistance d(mesh);
  std::vector<double> out(points.size());
  tbb::parallel_for(size_t{0}, points.size(), size_t{4096}, [&](size_t begin) {
    const size_t end = std::min(points.size(), begin + 4096);
    for (size_t i = begin; i < end; ++i) out[i] = d.distance(points[i]);
  });
  return out;
}

SurfaceDistance surface_distance(const TriMesh& a, const TriMesh& b, size_t samples) {
  SurfaceDistance r;
  auto side = [&](const TriMesh& from, const TriMesh& to, double& worst, double& mean, Vec3& where) {
    const std::vector<Vec3> pts = sample_surface(from, samples, 12345);
    const auto d = distance_to_mesh(to, pts);
    worst = 0;
    mean = 0;
    for (size_t i = 0; i < d.size(); ++i) {
      if (d[i] > worst) {
        worst = d[i];
        where = pts[i];
      }
      mean += d[i];
    }
    mean = d.empty() ? 0 : mean / double(d.size());
  };
  side(a, b, r.a_to_b, r.mean_a_to_b, r.worst_a);
  side(b, a, r.b_to_a, r.mean_b_to_a, r.worst_b);
  r.hausdorff = std::max(r.a_to_b, r.b_to_a);
  return r;
}

OffsetDistance offset_distance(const TriMesh& surface, const TriMesh& reference, double offset, size_t samples) {
  const MeshTopology t = analyze_topology(reference);
  if (!t.closed() || !t.manifold() || t.inconsistent_edges != 0)
    throw InvalidInput("the offset's reference must be closed, 2-manifold and consistently oriented");
  const detail::SignedDistance sd(reference);
  const std::vector<Vec3> pts = sample_surface(surface, samples, 12345);
  std::vector<double> d(pts.size());
  tbb::parallel_for(size_t{0}, pts.size(), size_t{4096}, [&](size_t begin) {
    const size_t end = std::min(pts.size(), begin + 4096);
    for (size_t i = begin; i < end; ++i) d[i] = std::abs(sd(pts[i]) - offset);
  });
  OffsetDistance r;
  for (size_t i = 0; i < d.size(); ++i) {
    if (d[i] > r.worst) r.worst = d[i], r.where = pts[i];
    if (i < surface.positions.size()) r.worst_vertex = std::max(r.worst_vertex, d[i]);
    r.mean += d[i];
  }
  if (!d.empty()) r.mean /= double(d.size());
  return r;
}

}  // namespace pic

// Distances between surfaces, for `pic compare`, tests and benchmarks: exact point-to-triangle
// distances over a median-split BVH, sampled at every vertex plus area-weighted points.
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>

#include "geometry/lattice.h"
#include "geometry/mesh_distance.h"
#include "geometry/tolerances.h"
#include "geometry/vec3.h"
#include "geometry/winding.h"
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

/// A uniform random point of triangle t of m.
Vec3 point_in_triangle(const TriMesh& m, const std::array<uint32_t, 3>& t, Rng& rng) {
  double u = rng.uniform(), v = rng.uniform();
  if (u + v > 1) {
    u = 1 - u;
    v = 1 - v;
  }
  const Vec3 &a = m.positions[t[0]], &b = m.positions[t[1]], &c = m.positions[t[2]];
  return add3(a, add3(scale3(sub3(b, a), u), scale3(sub3(c, a), v)));
}

/// The largest of `d` (and the point it was found at) and the mean.
void worst_and_mean(const std::vector<double>& d, const std::vector<Vec3>& pts, double& worst, double& mean,
                    Vec3& where) {
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
}

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
    pts.push_back(point_in_triangle(m, m.triangles[i], rng));
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
    worst_and_mean(distance_to_mesh(to, pts), pts, worst, mean, where);
  };
  side(a, b, r.a_to_b, r.mean_a_to_b, r.worst_a);
  side(b, a, r.b_to_a, r.mean_b_to_a, r.worst_b);
  r.hausdorff = std::max(r.a_to_b, r.b_to_a);
  return r;
}

namespace {

/// Where offset_surface_points draws from: a face, an edge's arc or a vertex's cap, with the
/// area its sweep covers.
struct Sweep {
  enum Kind : uint8_t { Face, Edge, Vertex } kind;
  uint32_t index;     // triangle, or vertex
  uint32_t other;     // an edge's second triangle
  int corner;         // an edge: corner k of `index` to k + 1
  double area;
};

Vec3 unit_normal(const TriMesh& m, uint32_t f) {
  const auto& t = m.triangles[f];
  const Vec3 n = cross3(sub3(m.positions[t[1]], m.positions[t[0]]), sub3(m.positions[t[2]], m.positions[t[0]]));
  const double l = norm3(n);
  return l > 0 ? scale3(n, 1 / l) : Vec3{0, 0, 0};
}

/// Spherical interpolation between unit vectors a and b at fraction w of the angle between them.
Vec3 slerp(const Vec3& a, const Vec3& b, double angle, double w) {
  if (angle < 1e-12) return a;
  const double s = std::sin(angle);
  return add3(scale3(a, std::sin((1 - w) * angle) / s), scale3(b, std::sin(w * angle) / s));
}

/// Every sweep of the offset surface by `r` (faces, edges' arcs, vertices' caps by their
/// angle defect, which is the area of the unit normal cone at a convex or concave corner).
std::vector<Sweep> offset_sweeps(const TriMesh& m, double r) {
  std::vector<Sweep> sweeps;
  std::vector<double> angle_sum(m.positions.size(), 0.0);
  std::vector<std::pair<uint64_t, std::pair<uint32_t, int>>> edges;
  for (uint32_t f = 0; f < m.triangles.size(); ++f) {
    const auto& t = m.triangles[f];
    const Vec3 e1 = sub3(m.positions[t[1]], m.positions[t[0]]), e2 = sub3(m.positions[t[2]], m.positions[t[0]]);
    sweeps.push_back({Sweep::Face, f, 0, 0, norm3(cross3(e1, e2)) / 2});
    for (int k = 0; k < 3; ++k) {
      const Vec3 a = sub3(m.positions[t[(k + 1) % 3]], m.positions[t[k]]);
      const Vec3 b = sub3(m.positions[t[(k + 2) % 3]], m.positions[t[k]]);
      angle_sum[t[k]] += std::atan2(norm3(cross3(a, b)), dot3(a, b));
      const uint32_t lo = std::min(t[k], t[(k + 1) % 3]), hi = std::max(t[k], t[(k + 1) % 3]);
      edges.push_back({uint64_t(lo) << 32 | hi, {f, k}});
    }
  }
  std::sort(edges.begin(), edges.end());
  for (size_t i = 0; i + 1 < edges.size(); ++i) {
    if (edges[i].first != edges[i + 1].first) continue;
    const auto [f, k] = edges[i].second;
    const uint32_t g = edges[i + 1].second.first;
    const auto& t = m.triangles[f];
    const double len = norm3(sub3(m.positions[t[(k + 1) % 3]], m.positions[t[k]]));
    const double angle = std::acos(std::clamp(dot3(unit_normal(m, f), unit_normal(m, g)), -1.0, 1.0));
    sweeps.push_back({Sweep::Edge, f, g, k, len * r * angle});
    ++i;
  }
  for (uint32_t v = 0; v < m.positions.size(); ++v)
    if (angle_sum[v] > 0)
      sweeps.push_back({Sweep::Vertex, v, 0, 0, r * r * std::abs(2 * std::numbers::pi - angle_sum[v])});
  return sweeps;
}

/// Signed distances to a closed, consistently oriented mesh. The nearest feature's
/// pseudonormal gives the side, exactly where the mesh around that feature is embedded; beside
/// a triangle that crosses another (a sliver folded over by rounding to floats, overlapping
/// shells) or has no area, that normal can point into the solid, and the side is taken from
/// the winding number instead (inside where it is 1/2 or more).
class SidedDistance {
 public:
  explicit SidedDistance(const TriMesh& mesh) : mesh_(mesh), sd_(mesh), suspect_(mesh.positions.size(), 0) {
    auto mark = [&](uint32_t f) {
      for (uint32_t v : mesh.triangles[f]) suspect_[v] = 1;
    };
    for (const auto& [i, j] : self_intersecting_pairs(mesh)) mark(i), mark(j);
    for (uint32_t f = 0; f < mesh.triangles.size(); ++f) {
      const auto& t = mesh.triangles[f];
      const Vec3 n = cross3(sub3(mesh.positions[t[1]], mesh.positions[t[0]]), sub3(mesh.positions[t[2]], mesh.positions[t[0]]));
      if (n[0] == 0 && n[1] == 0 && n[2] == 0) mark(f);
    }
  }
  /// The distance with its pseudonormal's sign, and whether that sign needs the winding number.
  double pseudonormal(const Vec3& p, bool& doubtful) const {
    Vec3 g;
    detail::Nearest n;
    const double d = sd_.with_gradient(p, g, nullptr, nullptr, &n);
    const auto& t = mesh_.triangles[n.triangle];
    doubtful = suspect_[t[0]] || suspect_[t[1]] || suspect_[t[2]];
    return d;
  }
  /// The distance signed by the winding number (every triangle: for the doubtful points only).
  double by_winding(const Vec3& p, double d) const {
    double w = 0;
    for (const auto& t : mesh_.triangles)
      w += detail::triangle_winding(p, mesh_.positions[t[0]], mesh_.positions[t[1]], mesh_.positions[t[2]]);
    return w >= 0.5 ? -std::abs(d) : std::abs(d);
  }
  /// Signed distances at `pts`; \throws InvalidInput when so many points lie beside crossing
  /// triangles that their winding numbers would take minutes.
  std::vector<double> operator()(const std::vector<Vec3>& pts) const {
    std::vector<double> d(pts.size());
    std::vector<char> doubtful(pts.size(), 0);
    tbb::parallel_for(size_t{0}, pts.size(), [&](size_t i) {
      bool x = false;
      d[i] = pseudonormal(pts[i], x);
      doubtful[i] = x;
    });
    const size_t n = size_t(std::count(doubtful.begin(), doubtful.end(), 1));
    if (double(n) * double(mesh_.triangles.size()) > 2e9)
      throw InvalidInput("the offset's reference crosses itself beside " + std::to_string(n) +
                         " of the points measured: too many to decide their side by the winding number");
    tbb::parallel_for(size_t{0}, pts.size(), [&](size_t i) {
      if (doubtful[i]) d[i] = by_winding(pts[i], d[i]);
    });
    return d;
  }

 private:
  const TriMesh& mesh_;
  detail::SignedDistance sd_;
  std::vector<char> suspect_;  // per vertex: of a crossing or zero-area triangle
};

std::vector<Vec3> offset_points(const TriMesh& reference, const SidedDistance& sided, double offset, size_t samples,
                                uint64_t seed) {
  const double r = std::abs(offset), side = offset < 0 ? -1 : 1;
  const std::vector<Sweep> sweeps = offset_sweeps(reference, r);
  std::vector<double> cum(sweeps.size());
  double total = 0;
  for (size_t i = 0; i < sweeps.size(); ++i) cum[i] = total += sweeps[i].area;
  if (!(total > 0) || !(r > 0)) return {};
  // A vertex's faces, for its caps.
  std::vector<std::vector<uint32_t>> faces(reference.positions.size());
  for (uint32_t f = 0; f < reference.triangles.size(); ++f)
    for (uint32_t v : reference.triangles[f]) faces[v].push_back(f);
  Rng rng(seed);
  std::vector<Vec3> candidates;
  candidates.reserve(samples);
  for (size_t n = 0; n < samples; ++n) {
    const Sweep& w = sweeps[size_t(std::upper_bound(cum.begin(), cum.end(), rng.uniform() * total) - cum.begin()) %
                            sweeps.size()];
    Vec3 q, u;
    if (w.kind == Sweep::Face) {
      q = point_in_triangle(reference, reference.triangles[w.index], rng);
      u = unit_normal(reference, w.index);
    } else if (w.kind == Sweep::Edge) {
      const auto& t = reference.triangles[w.index];
      const Vec3 &a = reference.positions[t[w.corner]], &b = reference.positions[t[(w.corner + 1) % 3]];
      q = add3(a, scale3(sub3(b, a), rng.uniform()));
      const Vec3 n1 = unit_normal(reference, w.index), n2 = unit_normal(reference, w.other);
      u = slerp(n1, n2, std::acos(std::clamp(dot3(n1, n2), -1.0, 1.0)), rng.uniform());
    } else {
      q = reference.positions[w.index];
      Vec3 sum{0, 0, 0};
      for (uint32_t f : faces[w.index]) sum = add3(sum, scale3(unit_normal(reference, f), -std::log(1 - rng.uniform())));
      const double l = norm3(sum);
      if (!(l > 0)) continue;
      u = scale3(sum, 1 / l);
    }
    candidates.push_back(add3(q, scale3(u, side * r)));
  }
  // Kept where the mesh is nowhere nearer than r (else the point lies inside the offset's
  // other parts, or on the wrong side of a concave crease or corner).
  // On the offset's side too: a face whose normal points into the solid (a folded sliver)
  // moves its points inside.
  const std::vector<double> d = sided(candidates);
  std::vector<Vec3> kept;
  for (size_t i = 0; i < candidates.size(); ++i)
    if (side * d[i] >= r * (1 - 1e-9)) kept.push_back(candidates[i]);
  return kept;
}

}  // namespace

std::vector<Vec3> offset_surface_points(const TriMesh& reference, double offset, size_t samples, uint64_t seed) {
  return offset_points(reference, SidedDistance(reference), offset, samples, seed);
}

OffsetDistance offset_distance(const TriMesh& surface, const TriMesh& reference, double offset, size_t samples) {
  const MeshTopology t = analyze_topology(reference);
  if (!t.closed() || !t.manifold() || t.inconsistent_edges != 0)
    throw InvalidInput("the offset's reference must be closed, 2-manifold and consistently oriented");
  const SidedDistance sided(reference);
  const std::vector<Vec3> pts = sample_surface(surface, samples, 12345);
  std::vector<double> d = sided(pts);
  for (double& x : d) x = std::abs(x - offset);
  OffsetDistance r;
  for (size_t i = 0; i < d.size(); ++i) {
    if (d[i] > r.worst) r.worst = d[i], r.where = pts[i];
    if (i < surface.positions.size()) r.worst_vertex = std::max(r.worst_vertex, d[i]);
    r.mean += d[i];
  }
  if (!d.empty()) r.mean /= double(d.size());
  const std::vector<Vec3> back = offset_points(reference, sided, offset, std::max<size_t>(samples, 1000), 777);
  worst_and_mean(distance_to_mesh(surface, back), back, r.back_worst, r.back_mean, r.back_where);
  r.back_points = back.size();
  return r;
}

}  // namespace pic

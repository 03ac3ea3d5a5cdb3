// Offsets, shells, rounds and thickened surfaces as implicit solids (pic/volume.h): a signed
// distance to a closed surface (exact, by the nearest feature's pseudonormal) or an unsigned
// distance to any surface, sampled by the implicit sampler.
#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>

#include "geometry/mesh_distance.h"
#include "geometry/stopwatch.h"
#include "geometry/tolerances.h"
#include "geometry/vec3.h"
#include "pic/contour.h"
#include "pic/measure.h"
#include "pic/volume.h"
#include "sample/round_body.h"
#include "sample/rounded_edges.h"

namespace pic {

namespace {

using detail::MeshDistance;
using detail::RoundBody;
using detail::RoundSum;
using detail::SignedDistance;

/// A cube holding the mesh's box grown by `grow` on every side, plus the sampling margin.
Cube cube_around(const TriMesh& mesh, double grow, const SampleOptions& options) {
  if (options.cube) return *options.cube;
  Vec3 lo{detail::kHuge, detail::kHuge, detail::kHuge}, hi{-detail::kHuge, -detail::kHuge, -detail::kHuge};
  for (const Vec3& p : mesh.positions)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
  double extent = 0;
  for (int k = 0; k < 3; ++k) extent = std::max(extent, hi[k] - lo[k] + 2 * std::max(grow, 0.0));
  const double size = extent * (1 + 2 * options.margin);
  Cube c;
  for (int k = 0; k < 3; ++k) c.origin[k] = (lo[k] + hi[k]) / 2 - size / 2;
  c.size = size;
  return c;
}

void check_finite(double x, const char* what) {
  if (!std::isfinite(x)) throw InvalidInput(std::string(what) + " must be finite");
}

/// The surface a signed distance can be taken to: the mesh itself when it is closed,
/// 2-manifold, consistently oriented, with positive volume and not crossing itself; otherwise
/// its PIC contour (signs by the winding number, the contour intersection-free). Where a closed
/// mesh crosses itself, a face lies inside the solid and the nearest feature's pseudonormal
/// gives the points beside it the outside sign (and equidistant points either sign).
TriMesh closed_surface(const TriMesh& mesh, const SampleOptions& options) {
  const MeshTopology t = analyze_topology(mesh);
  if (t.closed() && t.manifold() && t.inconsistent_edges == 0 && volume(mesh) > 0 &&
      self_intersecting_pairs(mesh).empty())
    return mesh;
  return contour(sample(mesh, options));
}

/// Samples f in options.cube and, when asked, contours it with its edge points on f's zero.
Octree sample_with_mesh(const ImplicitSolid& f, const SampleOptions& options, SampleStats* stats, VolumeMesh* mesh) {
  Octree tree = sample(f, options, stats);
  if (mesh) {
    const auto t0 = detail::Clock::now();
    ContourOptions co = mesh->options;
    co.surface = f.value;
    mesh->mesh = contour(tree, co, &mesh->stats);
    mesh->seconds = detail::since(t0);
  }
  return tree;
}

/// A range of distances [lo, hi] (signed or not) that holds a solid's surface.
struct Band {
  double lo, hi;
};

/// Whether a distance d to `mesh` stays out of each band over the box [lo, hi]; `d_centre`
/// is d at the box's centre and `nearest` the mesh point there. Towards the mesh from a band
/// (|d| below the band's near end r, on its side of 0), the box inside one ball of radius r
/// about a mesh point proves every point nearer than r; away from the mesh, no triangle within
/// the far end r of the box proves every point farther (and then the box does not meet the
/// mesh, so d keeps its sign too).
bool clear_of_bands(const MeshDistance& mesh, const std::vector<Band>& bands, const Vec3& lo, const Vec3& hi,
                    double d_centre, const Vec3& nearest) {
  const double half = detail::norm3(detail::sub3(hi, lo)) / 2;
  for (const Band& band : bands) {
    if (d_centre < band.lo - half || d_centre > band.hi + half) continue;  // the bound alone
    if (d_centre >= band.lo && d_centre <= band.hi) return false;
    const double end = d_centre < band.lo ? band.lo : band.hi;
    // A hair of margin towards the band either way: distances are rounded.
    const bool towards_mesh = end != 0 && (d_centre < band.lo) == (end > 0);
    if (!towards_mesh) {
      if (!mesh.farther_than(lo, hi, std::abs(end) * (1 + detail::kOnSurface))) return false;
      continue;
    }
    const double reach = std::abs(end) * (1 - detail::kOnSurface);
    for (int k = 0; k < 8; ++k) {
      const Vec3 x{k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1], k & 4 ? hi[2] : lo[2]};
      if (!(detail::norm3(detail::sub3(x, nearest)) < reach)) return false;
    }
  }
  return true;
}

/// clear_of_bands for a signed distance, asked at the box's centre.
bool clear_of_bands(const SignedDistance& sd, const std::vector<Band>& bands, const Vec3& lo, const Vec3& hi,
                    uint32_t* hint) {
  Vec3 grad, nearest;
  const double d = sd.with_gradient(detail::scale3(detail::add3(lo, hi), 0.5), grad, hint, &nearest);
  return clear_of_bands(sd.mesh_distance(), bands, lo, hi, d, nearest);
}

/// The solid {f < 0} for f = g(signed distance to `surface`), g of slope +-1 and zero at the
/// distances `levels`; `offset` when g(d) = d - offset (ImplicitSolid::offset).
template <class G>
Octree sample_distance(const TriMesh& surface, const Cube& cube, const SampleOptions& options, SampleStats* stats,
                       VolumeMesh* mesh, const std::vector<Band>& levels, G&& g,
                       std::optional<double> offset = std::nullopt) {
  const SignedDistance sd(surface);
  // Per thread, the triangle nearest the last point asked: the sampler asks in cell order,
  // so the next point's nearest triangle is usually that one or a neighbour.
  tbb::enumerable_thread_specific<uint32_t> hints(uint32_t{0});
  ImplicitSolid solid;
  solid.value = [&](const Vec3& p) { return g(sd(p, &hints.local())).first; };
  solid.gradient = [&](const Vec3& p) {
    Vec3 grad;
    const double d = sd.with_gradient(p, grad, &hints.local());
    return detail::scale3(grad, g(d).second);
  };
  solid.value_gradient = [&](const Vec3& p, Vec3& grad) {
    const auto [v, slope] = g(sd.with_gradient(p, grad, &hints.local()));
    grad = detail::scale3(grad, slope);
    return v;
  };
  solid.clear = [&](const Vec3& lo, const Vec3& hi) { return clear_of_bands(sd, levels, lo, hi, &hints.local()); };
  const double tolerance = detail::bend_tolerance(cube, options.depth, options.error);
  std::vector<detail::RoundedEdges> rounded;
  for (const Band& b : levels)
    if (b.lo == b.hi && b.lo != 0) rounded.emplace_back(surface, b.lo, tolerance);
  solid.bends = [&](const Vec3& lo, const Vec3& hi, const Vec3& vertex, std::vector<std::array<Vec3, 2>>& bends) {
    for (const detail::RoundedEdges& r : rounded) r.points(lo, hi, vertex, bends);
  };
  solid.distance = true;
  solid.offset = offset;
  solid.value_site = [&](const Vec3& p, uint32_t& site) {
    uint32_t& hint = hints.local();
    const double v = g(sd(p, &hint)).first;
    site = hint;
    return v;
  };
  solid.site_distance = [&](const Vec3& p, uint32_t site) { return sd.mesh_distance().distance_to_hint(p, site); };
  solid.features = [&](std::vector<Vec3>& points) {
    std::vector<double> distances;
    for (const Band& b : levels)
      if (b.lo == b.hi) distances.push_back(b.lo);
    points = detail::offset_feature_points(surface, distances, tolerance);
  };
  SampleOptions o = options;
  o.cube = cube;
  return sample_with_mesh(solid, o, stats, mesh);
}

}  // namespace

bool is_round_body(const std::vector<Vec3>& points) { return detail::round_body_if_round(points).has_value(); }

Octree minkowski_round(const TriMesh& solid, const std::vector<Vec3>& round, const SampleOptions& options,
                       SampleStats* stats, VolumeMesh* mesh) {
  std::optional<RoundBody> found = detail::round_body_if_round(round);
  if (!found)
    throw InvalidInput("the Minkowski sum takes a round body here: a faceted sphere, every vertex and facet "
                       "within 2 % of one radius from its centre");
  found->index_directions();
  const RoundBody& body = *found;
  TriMesh surface = closed_surface(solid, options);
  for (Vec3& p : surface.positions) p = detail::add3(p, body.centre);
  const Cube cube = cube_around(surface, body.outer, options);
  const RoundSum sum(surface, body);
  tbb::enumerable_thread_specific<uint32_t> hints(uint32_t{0});
  ImplicitSolid f;
  f.value_gradient = [&](const Vec3& p, Vec3& grad) { return sum(p, grad, &hints.local()); };
  f.value = [&](const Vec3& p) {
    Vec3 g;
    return sum(p, g, &hints.local());
  };
  f.gradient = [&](const Vec3& p) {
    Vec3 g;
    sum(p, g, &hints.local());
    return g;
  };
  // |f| is never more than the distance to the sum's surface, and next to it equal to it
  // (a polytope's signed distance, or below it off a facet by the cosine of half the angle
  // between two facets): it bounds as a distance does.
  f.lipschitz = 1;
  f.distance = true;
  // The surface lies where d = h(u), between the body's inner and outer radii; f's own
  // bound at the centre first (what the sampler would ask without this).
  f.clear = [&](const Vec3& lo, const Vec3& hi) {
    const Vec3 centre = detail::scale3(detail::add3(lo, hi), 0.5);
    Vec3 grad, nearest;
    double d = 0;
    uint32_t winner = 0;
    const double fc = sum(centre, grad, &hints.local(), &d, &nearest, &winner);
    if (std::abs(fc) > f.lipschitz * detail::norm3(detail::sub3(hi, lo)) / 2) return true;
    if (clear_of_bands(sum.distance().mesh_distance(), {{body.inner, body.outer}}, lo, hi, d, nearest)) return true;
    return sum.box_clear(lo, hi, d, fc, winner);
  };
  SampleOptions o = options;
  o.cube = cube;
  // The solid's creases moved by the body's radius: on the sum's surface where the body rounds
  // them, Newton steps away where it fills them.
  const double tolerance = detail::bend_tolerance(cube, o.depth, o.error);
  f.features = [&](std::vector<Vec3>& points) {
    points = detail::offset_feature_points(surface, {(body.inner + body.outer) / 2}, tolerance);
  };
  return sample_with_mesh(f, o, stats, mesh);
}

namespace {

/// The offset of a closed surface a signed distance may be taken to (closed_surface).
Octree offset_of_surface(const TriMesh& surface, double distance, const SampleOptions& options, SampleStats* stats,
                         VolumeMesh* mesh) {
  check_finite(distance, "the offset distance");
  const Cube cube = cube_around(surface, distance, options);
  try {
    return sample_distance(surface, cube, options, stats, mesh, {{distance, distance}},
                           [&](double d) { return std::pair{d - distance, 1.0}; }, distance);
  } catch (const EmptySolid&) {
    if (distance >= 0) throw;
    char what[160];
    std::snprintf(what, sizeof what, "shrinking by %g leaves nothing: no point of the solid lies deeper than that",
                  -distance);
    throw EmptySolid(what);
  }
}

}  // namespace

Octree offset(const TriMesh& solid, double distance, const SampleOptions& options, SampleStats* stats,
              VolumeMesh* mesh) {
  return offset_of_surface(closed_surface(solid, options), distance, options, stats, mesh);
}

Octree offset(const Octree& solid, double distance, const SampleOptions& options, SampleStats* stats,
              VolumeMesh* mesh) {
  SampleOptions o = options;
  if (!o.cube && distance <= 0) o.cube = solid.cube;
  // A PIC's contour is closed, 2-manifold and free of crossings by construction.
  return offset_of_surface(contour(solid), distance, o, stats, mesh);
}

Octree shell(const TriMesh& solid, double thickness, bool outward, const SampleOptions& options, SampleStats* stats,
             VolumeMesh* mesh) {
  check_finite(thickness, "the shell thickness");
  if (!(thickness > 0)) throw InvalidInput("the shell thickness must be positive");
  const TriMesh surface = closed_surface(solid, options);
  const Cube cube = cube_around(surface, outward ? thickness : 0, options);
  // Inward: inside the solid and farther than T from its surface's inside; outward: within T
  // outside it. max of two distances of slope 1 is a distance bound of slope 1.
  const std::vector<Band> levels{{0, 0}, outward ? Band{thickness, thickness} : Band{-thickness, -thickness}};
  return sample_distance(surface, cube, options, stats, mesh, levels, [&](double d) {
    const double a = outward ? d - thickness : d, b = outward ? -d : -d - thickness;
    return a >= b ? std::pair{a, 1.0} : std::pair{b, -1.0};
  });
}

Octree round_edges(const TriMesh& solid, double radius, bool convex, const SampleOptions& options,
                   SampleStats* stats, VolumeMesh* mesh) {
  check_finite(radius, "the rounding radius");
  if (!(radius > 0)) throw InvalidInput("the rounding radius must be positive");
  const TriMesh surface = closed_surface(solid, options);
  SampleOptions o = options;
  o.cube = cube_around(surface, convex ? 0 : radius, options);
  // The first offset's surface with its edge points on the exact offset, for the second.
  VolumeMesh first;
  try {
    offset_of_surface(surface, convex ? -radius : radius, o, nullptr, &first);
  } catch (const EmptySolid&) {
    char what[160];
    std::snprintf(what, sizeof what, "rounding with radius %g leaves nothing: no point of the solid lies deeper than that",
                  radius);
    throw EmptySolid(what);
  }
  // The contour of a sampled volume: closed, 2-manifold and free of crossings by construction.
  return offset_of_surface(first.mesh, convex ? radius : -radius, o, stats, mesh);
}

Octree thicken(const TriMesh& surface, double thickness, const SampleOptions& options, SampleStats* stats,
               VolumeMesh* mesh) {
  check_finite(thickness, "the thickness");
  if (!(thickness > 0)) throw InvalidInput("the thickness must be positive");
  if (surface.triangles.empty()) throw InvalidInput("nothing to thicken: the mesh has no triangles");
  const MeshDistance distance(surface);
  tbb::enumerable_thread_specific<uint32_t> hints(uint32_t{0});
  ImplicitSolid solid;
  const double half = thickness / 2;
  solid.value = [&](const Vec3& p) { return distance.nearest(p, &hints.local()).distance - half; };
  solid.gradient = [&](const Vec3& p) {
    const detail::Nearest n = distance.nearest(p, &hints.local());
    return n.distance > 0 ? detail::scale3(detail::sub3(p, n.point), 1 / n.distance) : Vec3{0, 0, 1};
  };
  solid.value_gradient = [&](const Vec3& p, Vec3& grad) {
    const detail::Nearest n = distance.nearest(p, &hints.local());
    grad = n.distance > 0 ? detail::scale3(detail::sub3(p, n.point), 1 / n.distance) : Vec3{0, 0, 1};
    return n.distance - half;
  };
  solid.clear = [&](const Vec3& lo, const Vec3& hi) {
    const Vec3 centre = detail::scale3(detail::add3(lo, hi), 0.5);
    const detail::Nearest n = distance.nearest(centre, &hints.local());
    return clear_of_bands(distance, {{half, half}}, lo, hi, n.distance, n.point);
  };
  solid.distance = true;
  SampleOptions o = options;
  o.cube = cube_around(surface, half, options);
  // Both faces of the slab have the surface's creases, moved either way.
  const double tolerance = detail::bend_tolerance(*o.cube, o.depth, o.error);
  solid.features = [&](std::vector<Vec3>& points) {
    points = detail::offset_feature_points(surface, {half, -half}, tolerance);
  };
  return sample_with_mesh(solid, o, stats, mesh);
}

}  // namespace pic

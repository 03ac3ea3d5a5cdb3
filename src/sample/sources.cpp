#include "sample/sources.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numbers>
#include <map>
#include <optional>
#include <unordered_map>

#include <Eigen/Dense>

#include "geometry/tolerances.h"
#include "geometry/union_find.h"
#include "geometry/vec3.h"
#include "mesh/clean.h"

namespace pic::detail {
namespace {

int sgn(i128 v) { return (v > 0) - (v < 0); }

constexpr i64 kGridMax = i64{1} << kGridBits;

Vec3 unit_vec(const Vec3& v) {
  const double l = norm3(v);
  return l > 0 ? Vec3{v[0] / l, v[1] / l, v[2] / l} : Vec3{0, 0, 0};
}

I3 along(I3 p, int axis, i64 offset) {
  p[axis] += offset;
  return p;
}

/// Bisects the edge of `cell` from corner c0 to c1 (signs differ) for the sign change, with
/// `inside_at(offset)` the sign at c0 + offset along the edge. Returns the unit-space point.
template <class F>
Vec3 bisect_edge(const Cell& cell, int c0, int axis, bool s0, F&& inside_at) {
  const I3 a = lattice_to_grid(cell.corner(c0));
  i64 lo = 0, hi = lattice_to_grid(cell.span());
  for (int it = 0; it < 16 && hi - lo > 1; ++it) {
    const i64 mid = lo + (hi - lo) / 2;
    (inside_at(mid) == s0 ? lo : hi) = mid;
  }
  return to_unit(along(a, axis, lo + (hi - lo) / 2));
}

/// The sign change on the edge of `cell` from corner c0 along `axis`, found on a smooth
/// function instead of on decisions: `level(offset)` is |w| - 1/2 at c0 + offset, which is
/// > 0 on c0's side (`s0` inside) and < 0 on the other when the approximate values agree with
/// the decided signs. Regula falsi with the Illinois step needs 2-4 values where bisection
/// needs 16 decisions, each of them a close call by construction. Returns nothing when the
/// end values disagree with the signs (the caller bisects the decisions then).
template <class G>
std::optional<Vec3> level_on_edge(const Cell& cell, int c0, int axis, bool s0, G&& level) {
  const double orient = s0 ? 1.0 : -1.0;  // f > 0 on c0's side
  i64 lo = 0, hi = lattice_to_grid(cell.span());
  double flo = orient * level(lo), fhi = orient * level(hi);
  if (!(flo > 0) || !(fhi < 0)) return std::nullopt;
  const i64 precision = std::max<i64>(1, hi / 1024);
  int last = 0;  // which end moved last (Illinois: halve the other end's value when it repeats)
  for (int it = 0; it < 8 && hi - lo > precision; ++it) {
    const double t = flo / (flo - fhi);
    const i64 x = std::clamp<i64>(lo + i64(std::llround(t * double(hi - lo))), lo + 1, hi - 1);
    const double fx = orient * level(x);
    if (fx > 0) {
      lo = x, flo = fx;
      if (last == 1) fhi /= 2;
      last = 1;
    } else {
      hi = x, fhi = fx;
      if (last == -1) flo /= 2;
      last = -1;
    }
    if (std::abs(fx) < kLevelRootValue) break;
  }
  return to_unit(along(lattice_to_grid(cell.corner(c0)), axis, lo + (hi - lo) / 2));
}


/// Integer winding number at b from w at a, along the axes in turn (x, then y, then z) through
/// the triangles `near` (all those the path can cross). Crossing a triangle along +axis changes
/// w by -sign(n_axis), along -axis by +sign(n_axis).
int32_t winding_along_axes(const std::vector<ITri>& tris, const std::vector<uint32_t>& near, I3 a, int32_t w,
                           const I3& b) {
  for (int axis = 0; axis < 3; ++axis) {
    const i64 len = b[axis] - a[axis];
    if (len == 0) continue;
    I3 from = a;
    if (len < 0) from[axis] = b[axis];
    for (uint32_t k : near)
      if (crosses(tris[k], from, axis, std::abs(len))) w -= len > 0 ? sgn(tris[k].n[axis]) : -sgn(tris[k].n[axis]);
    a[axis] = b[axis];
  }
  return w;
}

}  // namespace

int DecisionCache::find(const I3& p) const {
  const Entry& e = memo_.slot(memo_slot(p, 0, Memo::kBits));
  return e.filled && e.p == p ? int(e.inside) : -1;
}

void DecisionCache::store(const I3& p, bool inside) const { memo_.slot(memo_slot(p, 0, Memo::kBits)) = {p, true, inside}; }

// ---- triangle soups -----------------------------------------------------------------------

std::vector<ITri> grid_triangles(const std::vector<std::array<uint32_t, 3>>& tris, const std::vector<I3>& grid,
                                size_t room) {
  // Room first: reserving after sizing would move every triangle once more.
  std::vector<ITri> out;
  out.reserve(tris.size() + room);
  out.resize(tris.size());
  tbb::parallel_for(size_t{0}, tris.size(), [&](size_t i) {
    const auto& t = tris[i];
    out[i] = make_itri(grid[t[0]], grid[t[1]], grid[t[2]]);
  });
  return out;
}

/// Each boundary loop's box (unit space), grown by `margin` plus `spread` times its diagonal.
std::vector<Box> loop_boxes(const std::vector<std::vector<uint32_t>>& loops, const std::vector<I3>& grid,
                            double margin, double spread) {
  std::vector<Box> out;
  for (const auto& loop : loops) {
    Box b{{kHuge, kHuge, kHuge}, {-kHuge, -kHuge, -kHuge}};
    for (uint32_t v : loop) {
      const Vec3 p = to_unit(grid[v]);
      for (int k = 0; k < 3; ++k) b.lo[k] = std::min(b.lo[k], p[k]), b.hi[k] = std::max(b.hi[k], p[k]);
    }
    const double grow = margin + spread * norm3(sub3(b.hi, b.lo));
    for (int k = 0; k < 3; ++k) b.lo[k] -= grow, b.hi[k] += grow;
    out.push_back(b);
  }
  return out;
}

/// Each connected cap's oriented box: principal axes of its vertices.
std::vector<CapExtent> cap_extents(const std::vector<std::array<uint32_t, 3>>& cones, const std::vector<I3>& grid) {
  std::unordered_map<uint32_t, uint32_t> dense;
  std::vector<uint32_t> verts;
  for (const auto& t : cones)
    for (uint32_t v : t)
      if (dense.emplace(v, uint32_t(dense.size())).second) verts.push_back(v);
  UnionFind sets(dense.size());
  for (const auto& t : cones) sets.join(dense[t[0]], dense[t[1]]), sets.join(dense[t[0]], dense[t[2]]);
  std::map<size_t, std::vector<Eigen::Vector3d>> parts;  // ordered: deterministic
  for (size_t i = 0; i < verts.size(); ++i) {
    const Vec3 p = to_unit(grid[verts[i]]);
    parts[sets.root(i)].emplace_back(p[0], p[1], p[2]);
  }
  std::vector<CapExtent> out;
  for (const auto& [root, pts] : parts) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& p : pts) mean += p;
    mean /= double(pts.size());
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (const auto& p : pts) cov += (p - mean) * (p - mean).transpose();
    const Eigen::Matrix3d axes = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors();
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(kHuge), hi = -lo;
    for (const auto& p : pts) {
      const Eigen::Vector3d q = axes.transpose() * (p - mean);
      lo = lo.cwiseMin(q), hi = hi.cwiseMax(q);
    }
    const Eigen::Vector3d c = mean + axes * ((lo + hi) / 2), half = (hi - lo) / 2;
    CapExtent e;
    e.centre = {c[0], c[1], c[2]};
    for (int k = 0; k < 3; ++k) e.axes[k] = {axes(0, k), axes(1, k), axes(2, k)}, e.half[k] = half[k];
    out.push_back(e);
  }
  return out;
}

WindingInput winding_input(const TriMesh& mesh, const std::vector<I3>& grid, double cell, size_t* loop_count) {
  // Close the input's boundary with caps: input + caps has an exact integer winding number.
  const auto chain = boundary_chain(mesh);
  const auto cones = cap_loops(chain, loop_count);
  std::vector<ITri> tris = grid_triangles(mesh.triangles, grid, cones.size());
  for (ITri& t : grid_triangles(cones, grid)) {
    t.use = 0;  // a cap: counts in the winding number, is no part of the surface
    tris.push_back(t);
  }
  std::vector<std::array<Vec3, 2>> boundary;
  boundary.reserve(chain.size());
  for (const auto& [a, b] : chain) boundary.push_back({to_unit(grid[a]), to_unit(grid[b])});
  WindingInput in;
  in.loops = boundary_loops(chain);
  in.source = std::make_unique<WindingSource>(std::move(tris), mesh.triangles.size(), std::move(boundary),
                                              cap_extents(cones, grid), 2 * cell);
  return in;
}

namespace {

std::vector<CapExtent> grown(std::vector<CapExtent> caps, double margin) {
  for (CapExtent& c : caps)
    for (double& h : c.half) h += margin;
  return caps;
}

/// A cap in the ball (c, r) seen from distance D covers at most that ball's cone: its
/// |w| <= (1 - sqrt(1 - r^2 / D^2)) / 2 (unless it winds twice round some direction seen from
/// there). A cap reaches as far as that bound exceeds `far_share`.
double cone_cover(double r, double d) {
  if (d <= r) return 0.5;
  const double s = r / d;
  return (1 - std::sqrt(1 - s * s)) / 2;
}
std::vector<Box> reach_boxes(const std::vector<CapExtent>& caps, double far_share) {
  const double reach = 1 / std::sqrt(1 - (1 - 2 * far_share) * (1 - 2 * far_share));  // D / r
  std::vector<Box> boxes;
  for (const CapExtent& c : caps) {
    const double d = reach * c.radius();
    boxes.push_back({{c.centre[0] - d, c.centre[1] - d, c.centre[2] - d}, {c.centre[0] + d, c.centre[1] + d, c.centre[2] + d}});
  }
  return boxes;
}

}  // namespace

WindingSource::WindingSource(std::vector<ITri> tris, size_t mesh_count, std::vector<std::array<Vec3, 2>> boundary,
                             std::vector<CapExtent> caps, double margin)
    : all_(std::move(tris)),
      mesh_count_(mesh_count),
      cap_extents_(grown(std::move(caps), margin)),
      far_share_(0.25 / double(std::max<size_t>(cap_extents_.size(), 1))),
      cap_boxes_(reach_boxes(cap_extents_, far_share_)),
      boundary_(std::move(boundary)) {
  tris_ = &all_;
  if (all_.size() > mesh_count_) caps_.build_triangles({all_.begin() + long(mesh_count_), all_.end()});
}

int32_t WindingSource::ray_winding(const I3& p) const {
  // w(p) = sum over the triangles a ray from p out of the cube crosses of the sign of their
  // normal along it: w is 0 beyond the cube.
  // Only interior walls need rays: most inputs never build the hierarchy.
  std::call_once(bvh_built_, [&] { bvh_.build(all_); });
  // The shortest way out of the cube along an axis: fewer triangles to test.
  int axis = 0;
  bool up = true;
  i64 best = kGridMax;
  for (int k = 0; k < 3; ++k) {
    if (kGridMax - p[k] < best) axis = k, up = true, best = kGridMax - p[k];
    if (p[k] < best) axis = k, up = false, best = p[k];
  }
  I3 from = p, to = p;
  (up ? to : from)[axis] = up ? kGridMax : 0;
  thread_local std::vector<uint32_t> hits;
  hits.clear();
  bvh_.query(all_, from, to, hits);
  int32_t w = 0;
  for (uint32_t k : hits)
    if (crosses(all_[k], from, axis, to[axis] - from[axis])) w += up ? sgn(all_[k].n[axis]) : -sgn(all_[k].n[axis]);
  return w;
}

int32_t WindingSource::winding_from(const I3& a, int32_t w, const I3& b) const {
  // Through the few triangles near both: one long ray is enough for the two sides of a
  // triangle (the integer winding number is path-independent, the input and its cones being
  // a closed chain).
  std::call_once(bvh_built_, [&] { bvh_.build(all_); });
  I3 lo, hi;
  for (int k = 0; k < 3; ++k) lo[k] = std::min(a[k], b[k]), hi[k] = std::max(a[k], b[k]);
  thread_local std::vector<uint32_t> near;
  near.clear();
  bvh_.query(all_, lo, hi, near);
  return winding_along_axes(all_, near, a, w, b);
}

double CapExtent::cover(const Vec3& u) const {
  const Vec3 d = sub3(u, centre);
  const Vec3 q{dot3(d, axes[0]), dot3(d, axes[1]), dot3(d, axes[2])};
  double w = 0;
  bool outside = false;
  for (int i = 0; i < 3; ++i) {
    if (std::abs(q[i]) <= half[i]) continue;
    outside = true;  // the face on u's side along axis i is in view
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    Vec3 c[4];
    for (int m = 0; m < 4; ++m) {
      c[m][i] = q[i] > 0 ? half[i] : -half[i];
      c[m][j] = (m == 1 || m == 2) ? half[j] : -half[j];
      c[m][k] = m >= 2 ? half[k] : -half[k];
    }
    w += std::abs(triangle_winding(q, c[0], c[1], c[2])) + std::abs(triangle_winding(q, c[0], c[2], c[3]));
  }
  return outside ? w : 0.5;
}

bool CapExtent::apart(const Box& b) const {
  // Separated along one of the box's own axes (sufficient, not necessary).
  const Vec3 c{(b.lo[0] + b.hi[0]) / 2, (b.lo[1] + b.hi[1]) / 2, (b.lo[2] + b.hi[2]) / 2};
  const Vec3 h{(b.hi[0] - b.lo[0]) / 2, (b.hi[1] - b.lo[1]) / 2, (b.hi[2] - b.lo[2]) / 2};
  const Vec3 d = sub3(c, centre);
  for (int i = 0; i < 3; ++i) {
    const Vec3& a = axes[i];
    const double spread = std::abs(a[0]) * h[0] + std::abs(a[1]) * h[1] + std::abs(a[2]) * h[2];
    if (std::abs(dot3(d, a)) > half[i] + spread) return true;
  }
  return false;
}

bool WindingSource::caps_below_half(const Box& b) const {
  // Caps out of reach add at most far_share_ each; those in reach what their ball allows from
  // the nearest point of b, or for a point, if that is not enough, their box. A cap alone,
  // seen from outside its box, covers less than a hemisphere.
  thread_local std::vector<std::pair<uint32_t, double>> near;  // cap, ball bound
  near.clear();
  double sum = 0;
  cap_boxes_.query(b, [&](uint32_t k) {
    const CapExtent& c = cap_extents_[k];
    double d2 = 0;
    for (int i = 0; i < 3; ++i) {
      const double gap = std::max({b.lo[i] - c.centre[i], c.centre[i] - b.hi[i], 0.0});
      d2 += gap * gap;
    }
    near.push_back({k, cone_cover(c.radius(), std::sqrt(d2))});
    sum += near.back().second;
  });
  if (near.empty()) return true;
  if (cap_extents_.size() == 1 && cap_extents_[0].apart(b)) return true;
  const double far = far_share_ * double(cap_extents_.size() - near.size());
  if (sum + far < 0.5) return true;
  if (b.lo != b.hi) return false;
  sum = 0;
  for (const auto& [k, ball] : near) {
    sum += ball > 0.05 ? std::min(ball, cap_extents_[k].cover(b.lo)) : ball;
    if (sum + far >= 0.5) return false;
  }
  return true;
}

bool WindingSource::inside(const I3& p, int32_t w) const {
  if (caps_.empty()) return w != 0;
  // Where the caps' |w_C| < 1/2 is certain, |w - w_C| >= 1/2 exactly when w != 0. Most
  // decisions near the input's surface are settled here.
  const Vec3 u = to_unit(p);
  if (caps_below_half({u, u})) return w != 0;
  if (const auto far = caps_.inside_far(u, w)) return *far;
  if (const int known = cache_.find(p); known >= 0) return known;
  const bool in = caps_.inside(u, &p, w, kCapTolerance);
  cache_.store(p, in);
  return in;
}

void WindingSource::child_grid_signs(const Cell& cell, const std::vector<uint32_t>& idx,
                                     std::array<bool, 27>& g, Wind27* wind) const {
  // Crossing a triangle along +axis changes w by -sign(n_axis) (its normal points out).
  const i64 h = lattice_to_grid(cell.span() / 2);
  const I3 base = lattice_to_grid(cell.lat);
  std::array<int32_t, 27> jump{};
  for (uint32_t k : idx) {
    const ITri& t = all_[k];
    const LineMask mask = line_mask(t, base, h, 3);
    for (const GridSegment& s : kGridSegments) {
      if (!mask.may_cross(s.axis, s.i, s.ci, s.j, s.cj)) continue;
      if (crosses(t, child_grid_point(cell, s.from), s.axis, h)) jump[s.to] -= sgn(t.n[s.axis]);
    }
  }
  Wind27& w = *wind;
  for (const GridSegment& s : kGridSegments) {
    w[s.to] = w[s.from] + jump[s.to];
    g[s.to] = inside(child_grid_point(cell, s.to), w[s.to]);
  }
}

double WindingSource::cap_winding(const I3& p, bool memoize) const {
  if (!memoize) return caps_.evaluate(to_unit(p), &p).w;
  CapValue& e = cap_values_.slot(memo_slot(p, 0, CapValueMemo::kBits));
  if (!e.filled || e.p != p) e = {p, true, caps_.evaluate(to_unit(p), &p).w};
  return e.w;
}

void WindingSource::add_fill_planes(const Cell& cell, uint8_t signs, const Wind8* wind,
                                    const std::vector<uint32_t>& idx, Qef& q) const {
  if (!wind) return;
  if (boundary_.empty()) {
    if (dropped_any_) add_dropped_wall_planes(cell, signs, *wind, idx, q);
    return;
  }
  if (!dropped_any_) {
    // Away from the caps the signs are parity's: every sign change on an edge is a crossing of
    // the input's surface (all of it in the QEF) — unless a triangle dropped as an interior
    // wall was not one everywhere.
    if (caps_below_half({cell.min_unit(), cell.max_unit()})) return;
  }
  const i64 len = lattice_to_grid(cell.span());
  for (int e = 0; e < 12; ++e) {
    const int c0 = kEdgeCorners[e][0], c1 = kEdgeCorners[e][1], axis = edge_axis(e);
    const bool s0 = (signs >> c0) & 1;
    if (s0 == bool((signs >> c1) & 1)) continue;
    const I3 a = lattice_to_grid(cell.corner(c0));
    int surface = 0;
    for (uint32_t k : idx) surface += (all_[k].use & kUseQef) && crosses(all_[k], a, axis, len);
    if (surface & 1) continue;  // the input's own surface changes the sign here
    HoleCrossing& memo = crossings_.slot(edge_memo_slot(a, axis, len, HoleCrossingMemo::kBits));
    if (memo.filled && memo.a == a && memo.axis == axis && memo.len == len) {
      if (memo.n != Vec3{0, 0, 0}) q.add_plane(memo.n, dot3(memo.n, memo.x), 0.5);
      continue;
    }
    auto winding_at = [&](i64 off) {
      int32_t w = (*wind)[c0];
      for (uint32_t k : idx)
        if (crosses(all_[k], a, axis, off)) w -= sgn(all_[k].n[axis]);
      return w;
    };
    // Without the input's surface on the edge, w is continuous along it (a cap's jump in the
    // integer part cancels the cap's own jump).
    std::optional<Vec3> level;
    if (surface == 0)
      level = level_on_edge(cell, c0, axis, s0, [&](i64 off) {
        const I3 p = along(a, axis, off);
        return std::abs(double(winding_at(off)) - cap_winding(p, off == 0 || off == len)) - 0.5;
      });
    const Vec3 x = level ? *level : bisect_edge(cell, c0, axis, s0, [&](i64 off) {
      return inside(along(a, axis, off), winding_at(off));
    });
    // Across a hole the level set's normal is the gradient of w: the field of the boundary.
    const Vec3 n = unit_vec(boundary_field(boundary_, x));
    memo = {a, len, axis, true, x, n};
    if (n == Vec3{0, 0, 0}) continue;
    q.add_plane(n, dot3(n, x), 0.5);
  }
}

void WindingSource::add_dropped_wall_planes(const Cell& cell, uint8_t signs, const Wind8& wind,
                                            const std::vector<uint32_t>& idx, Qef& q) const {
  // Overlapping closed shells: a triangle dropped as an interior wall may still bound the
  // solid somewhere (its sample points were covered, a corner of it is not). Where a sign
  // change on an edge is not explained by the triangles left in the QEF, the crossing that
  // takes w to or from 0 gives the plane, so the vertex cannot ignore that piece of surface.
  const i64 len = lattice_to_grid(cell.span());
  thread_local std::vector<std::pair<double, uint32_t>> hits;
  for (int e = 0; e < 12; ++e) {
    const int c0 = kEdgeCorners[e][0], c1 = kEdgeCorners[e][1], axis = edge_axis(e);
    if ((((signs >> c0) ^ (signs >> c1)) & 1) == 0) continue;
    const I3 a = lattice_to_grid(cell.corner(c0));
    const Vec3 ua = to_unit(a);
    hits.clear();
    int surface = 0;
    for (uint32_t k : idx) {
      const ITri& t = all_[k];
      if (!crosses(t, a, axis, len)) continue;
      surface += (t.use & kUseQef) != 0;
      hits.push_back({(t.plane - dot3(t.unit_normal, ua)) / t.unit_normal[axis], k});
    }
    if (surface & 1) continue;  // a kept triangle changes the sign here
    std::sort(hits.begin(), hits.end());
    int32_t w = wind[c0];
    for (const auto& [s, k] : hits) {
      const bool was = w != 0;
      w -= sgn(all_[k].n[axis]);
      if (was == (w != 0)) continue;
      const ITri& t = all_[k];
      q.add_plane(t.unit_normal, t.plane, 0.5);
      break;
    }
  }
}

int32_t WindingSource::winding_in_cell(const Cell& cell, const Wind8& wind, const std::vector<uint32_t>& idx,
                                       const I3& p) const {
  return winding_along_axes(all_, idx, lattice_to_grid(cell.lat), wind[0], p);
}

bool WindingSource::surface_matters(const Cell& cell, uint8_t, const Wind8* wind,
                                    const std::vector<uint32_t>& idx) const {
  // Past this many triangles the test costs more than subdividing (coarse cells split anyway).
  constexpr size_t kMaxTested = 64;
  if (!wind || idx.size() > kMaxTested) return meets_box(all_, idx, cell.box());
  const IBox box = cell.box();
  const i64 delta = std::max<i64>(1, (box.hi[0] - box.lo[0]) / 1024);
  bool met = false;
  for (uint32_t k : idx) {
    const ITri& t = all_[k];
    if (!(t.use & kUseMeets) || is_degenerate(t)) continue;
    // A point of the triangle inside the cell, and one point on each side of it.
    const std::optional<Vec3> x = point_in_box(t, box);
    if (!x) continue;
    met = true;
    I3 side[2];
    for (int s = 0; s < 2; ++s) {
      const I3 g = to_grid(*x);
      for (int a = 0; a < 3; ++a) {
        const i64 off = i64(std::llround((s ? -1.0 : 1.0) * t.unit_normal[a] * double(delta)));
        side[s][a] = std::clamp<i64>(g[a] + off, box.lo[a], box.hi[a]);
      }
    }
    if (inside(side[0], winding_in_cell(cell, *wind, idx, side[0])) !=
        inside(side[1], winding_in_cell(cell, *wind, idx, side[1])))
      return true;
  }
  if (met) {
    const std::lock_guard lock(skipped_mutex_);
    skipped_.push_back(cell);
  }
  return false;
}

std::vector<Cell> WindingSource::skipped_cells() const {
  const std::lock_guard lock(skipped_mutex_);
  return skipped_;
}

size_t WindingSource::drop_interior_triangles() {
  std::atomic<size_t> dropped{0};
  tbb::parallel_for(size_t{0}, mesh_count_, [&](size_t i) {
    ITri& t = all_[i];
    if (is_degenerate(t)) return;
    const Vec3 v[3] = {to_unit(t.v[0]), to_unit(t.v[1]), to_unit(t.v[2])};
    const Vec3 c{(v[0][0] + v[1][0] + v[2][0]) / 3, (v[0][1] + v[1][1] + v[2][1]) / 3, (v[0][2] + v[1][2] + v[2][2]) / 3};
    const double delta = kInteriorProbe;
    // The centroid, then halfway to each vertex: a triangle is kept when the sign differs
    // across it anywhere we look.
    for (int s = 0; s < 4; ++s) {
      Vec3 p = c;
      if (s > 0)
        for (int k = 0; k < 3; ++k) p[k] = (c[k] + v[s - 1][k]) / 2;
      I3 side[2];
      for (int k = 0; k < 2; ++k) {
        const double o = k ? -delta : delta;
        side[k] = to_grid({p[0] + o * t.unit_normal[0], p[1] + o * t.unit_normal[1], p[2] + o * t.unit_normal[2]});
      }
      const int32_t w0 = ray_winding(side[0]);
      if (inside(side[0], w0) != inside(side[1], winding_from(side[0], w0, side[1]))) return;
    }
    t.use = 0;
    ++dropped;
  });
  dropped_any_ = dropped > 0;
  return dropped;
}

// ---- point clouds -------------------------------------------------------------------------

namespace {

/// Distance from each point to its k-th nearest neighbour (a uniform grid of buckets).
std::vector<double> kth_neighbour_distance(const std::vector<Vec3>& pos, int k) {
  const size_t n = pos.size();
  std::vector<double> out(n, 0);
  if (n < 2) return out;
  Vec3 lo = pos[0], hi = pos[0];
  for (const Vec3& p : pos)
    for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
  const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], kTinyDivisor});
  // Points on a surface: about 2 per bucket of this size.
  const double g = 2 * extent / std::sqrt(double(n));
  auto key_of = [&](int64_t x, int64_t y, int64_t z) { return (uint64_t(x) * 73856093u) ^ (uint64_t(y) * 19349663u) ^ (uint64_t(z) * 83492791u); };
  auto cell_of = [&](const Vec3& p) {
    return std::array<int64_t, 3>{int64_t((p[0] - lo[0]) / g), int64_t((p[1] - lo[1]) / g), int64_t((p[2] - lo[2]) / g)};
  };
  std::unordered_map<uint64_t, std::vector<uint32_t>> buckets;
  for (uint32_t i = 0; i < n; ++i) {
    const auto c = cell_of(pos[i]);
    buckets[key_of(c[0], c[1], c[2])].push_back(i);
  }
  const int64_t max_ring = int64_t(extent / g) + 2;
  tbb::parallel_for(size_t{0}, n, [&](size_t i) {
    const auto c = cell_of(pos[i]);
    std::vector<double> best;  // k smallest squared distances, sorted
    for (int64_t r = 0; r <= max_ring; ++r) {
      // Points in ring r are at least (r - 1) * g away.
      if (int(best.size()) == k && r > 0 && double(r - 1) * g * double(r - 1) * g > best.back()) break;
      for (int64_t dx = -r; dx <= r; ++dx)
        for (int64_t dy = -r; dy <= r; ++dy)
          for (int64_t dz = -r; dz <= r; ++dz) {
            if (std::max({std::abs(dx), std::abs(dy), std::abs(dz)}) != r) continue;
            const auto it = buckets.find(key_of(c[0] + dx, c[1] + dy, c[2] + dz));
            if (it == buckets.end()) continue;
            for (uint32_t j : it->second) {
              if (j == i) continue;
              const Vec3 d = sub3(pos[j], pos[i]);
              const double d2 = dot3(d, d);
              if (int(best.size()) < k || d2 < best.back()) {
                best.insert(std::upper_bound(best.begin(), best.end(), d2), d2);
                if (int(best.size()) > k) best.pop_back();
              }
            }
          }
    }
    out[i] = best.empty() ? 0 : std::sqrt(best.back());
  });
  return out;
}

ITri clamp_itri(I3 a, I3 b, I3 c) {
  for (I3* p : {&a, &b, &c})
    for (i64& x : *p) x = std::clamp<i64>(x, 1, kGridMax - 2);
  return make_itri(a, b, c);
}

}  // namespace

PointSource::PointSource(const std::vector<Vec3>& pos, const std::vector<Vec3>& normals) {
  constexpr int kNeighbours = 8;
  const std::vector<double> r = kth_neighbour_distance(pos, kNeighbours);
  std::vector<double> sorted = r;
  std::nth_element(sorted.begin(), sorted.begin() + long(sorted.size() / 2), sorted.end());
  spacing_ = sorted.empty() ? 0 : sorted[sorted.size() / 2];
  std::vector<double> area(pos.size());
  for (size_t i = 0; i < pos.size(); ++i) area[i] = std::numbers::pi * r[i] * r[i] / kNeighbours;
  tree_.build_points(pos, normals, area);
  prims_.reserve(2 * pos.size());
  for (size_t i = 0; i < pos.size(); ++i) {
    const Vec3 n = unit_vec(normals[i]);
    // A splat: an equilateral triangle in the tangent plane reaching the k-th neighbour.
    const Vec3 helper = std::abs(n[0]) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
    const Vec3 u = unit_vec(cross3(n, helper)), v = cross3(n, u);
    I3 corner[3];
    for (int k = 0; k < 3; ++k) {
      const double th = 2 * std::numbers::pi * k / 3;
      const double cu = std::cos(th) * r[i], cv = std::sin(th) * r[i];
      corner[k] = to_grid({pos[i][0] + cu * u[0] + cv * v[0], pos[i][1] + cu * u[1] + cv * v[1],
                           pos[i][2] + cu * u[2] + cv * v[2]});
    }
    ITri splat = clamp_itri(corner[0], corner[1], corner[2]);
    splat.use = kUseQef;
    // Its plane is the point's tangent plane, not the rounded corners'.
    splat.unit_normal = n;
    splat.plane = dot3(n, pos[i]);
    prims_.push_back(splat);
    // A marker the size of one grid step: "surface here" for the cells that hold the point.
    const I3 g = to_grid(pos[i]);
    ITri marker = clamp_itri(g, {g[0] + 1, g[1], g[2]}, {g[0], g[1] + 1, g[2]});
    marker.use = kUseMeets;
    prims_.push_back(marker);
  }
  tris_ = &prims_;
}

bool PointSource::inside(const I3& p) const {
  if (const int known = cache_.find(p); known >= 0) return known;
  const bool in = tree_.inside(to_unit(p), nullptr, 0, kPointTolerance);
  cache_.store(p, in);
  return in;
}

void PointSource::child_grid_signs(const Cell& cell, const std::vector<uint32_t>&, std::array<bool, 27>& g,
                                   Wind27*) const {
  for (const GridSegment& s : kGridSegments) g[s.to] = inside(child_grid_point(cell, s.to));
}

void PointSource::add_fill_planes(const Cell& cell, uint8_t signs, const Wind8*, const std::vector<uint32_t>&,
                                  Qef& q) const {
  if (!q.empty()) return;  // the splats in the cell say where the surface is
  for (int e = 0; e < 12; ++e) {
    const int c0 = kEdgeCorners[e][0], c1 = kEdgeCorners[e][1], axis = edge_axis(e);
    const bool s0 = (signs >> c0) & 1;
    if (s0 == bool((signs >> c1) & 1)) continue;
    const I3 a = lattice_to_grid(cell.corner(c0));
    const auto level = level_on_edge(cell, c0, axis, s0, [&](i64 off) {
      return std::abs(tree_.evaluate(to_unit(along(a, axis, off))).w) - 0.5;
    });
    const Vec3 x = level ? *level : bisect_edge(cell, c0, axis, s0, [&](i64 off) { return inside(along(a, axis, off)); });
    const double h = cell.size() / 16;
    Vec3 grad;
    for (int k = 0; k < 3; ++k) {
      Vec3 lo = x, hi = x;
      lo[k] -= h;
      hi[k] += h;
      grad[k] = std::abs(tree_.evaluate(lo).w) - std::abs(tree_.evaluate(hi).w);
    }
    const Vec3 n = unit_vec(grad);
    if (n == Vec3{0, 0, 0}) continue;
    q.add_plane(n, dot3(n, x), 0.5);
  }
}

}  // namespace pic::detail

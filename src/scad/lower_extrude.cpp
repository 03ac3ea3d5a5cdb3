// Lowering (lowering.h): linear_extrude and rotate_extrude of 2D subtrees, and moving solids.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "geometry/tolerances.h"
#include "scad/lowering.h"
#include "scad/region.h"
#include "geometry/vec3.h"

namespace pic::detail::scad {

namespace {

/// Distance from p to the segment ab.
double segment_distance(const P2& p, const P2& a, const P2& b) {
  const double dx = b[0] - a[0], dy = b[1] - a[1], len2 = dx * dx + dy * dy;
  const double t = len2 > 0 ? std::clamp(((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2, 0.0, 1.0) : 0.0;
  return std::hypot(p[0] - a[0] - t * dx, p[1] - a[1] - t * dy);
}

/// Length of an Archimedes spiral r = a phi from phi = 0 to theta.
double spiral_length(double a, double theta) {
  return a / 2 * (theta * std::sqrt(1 + theta * theta) + std::asinh(theta));
}

/// Slices of a linear_extrude given no `slices`, as OpenSCAD 2021.01 counts them (checked
/// against its output): a twist takes the fewer of |twist| / $fa and the path of the
/// outermost vertex / $fs, at least one per 120 degrees, or |twist| $fn / 360 with $fn set. The
/// path is a helix of the unscaled radius -- or, scaled evenly, a section of an Archimedes
/// spiral ending at that radius, as it measures it (a growing extrusion's spiral is taken to
/// shrink to the radius over the scale). A scale different along x and y adds (its longest
/// vertex path) / $fs, or $fn; otherwise one slice.
int default_slices(const Region& s, const LinearExtrude& e, double fn, double fs, double fa) {
  double r2 = 0, d2 = 0;
  for (const Ring& ring : s)
    for (const P2& p : ring) {
      r2 = std::max(r2, p[0] * p[0] + p[1] * p[1]);
      const double dx = p[0] * (e.scale[0] - 1), dy = p[1] * (e.scale[1] - 1);
      d2 = std::max(d2, dx * dx + dy * dy);
    }
  const bool uneven = e.scale[0] != e.scale[1];
  int diagonal = 1;
  if (uneven && std::sqrt(d2) >= kGridFine)
    diagonal = fn > 0 ? std::max(int(fn), 1) : std::max(int(std::ceil(std::sqrt(d2 + e.height * e.height) / fs)), 1);
  const double tw = std::abs(e.twist);
  if (tw == 0) return diagonal;
  const int least = std::max(int(std::ceil(tw / 120.0)), 1);
  const double r = std::sqrt(r2);
  int twisted = least;
  if (r >= kGridFine) {
    if (fn > 0) {
      twisted = std::max(int(std::ceil(tw / 360.0 * fn)), least);
    } else {
      const double th = tw * std::numbers::pi / 180;
      double flat = r * th;  // the helix's turn, flattened
      if (!uneven && e.scale[0] != 1) {
        const double sc = e.scale[0];
        const double end = sc > 1 ? th * sc / (sc - 1) : th / (1 - sc);
        flat = spiral_length(r / end, end) - spiral_length(r / end, end - th);
      }
      const int by_fs = int(std::ceil(std::hypot(flat, e.height) / fs)), by_fa = int(std::ceil(tw / fa));
      twisted = std::max(std::min(by_fa, by_fs), least);
    }
  }
  return uneven ? std::max(twisted, diagonal) : twisted;
}

}  // namespace

// A region's rings (which do not cross) -> Booleans of extruded simple rings: each ring at
// even nesting depth minus the rings directly inside it.
template <class Extrude>
Solid Lowering::extrude(const Region& region, const Extrude& ext) {
  std::vector<Ring> rings;
  for (const Ring& r : region)
    if (r.size() >= 3 && signed_area(r) != 0) rings.push_back(r);
  const size_t n = rings.size();
  auto inside = [](const P2& p, const Ring& r) {
    bool in = false;
    for (size_t i = 0, j = r.size() - 1; i < r.size(); j = i++)
      if ((r[i][1] > p[1]) != (r[j][1] > p[1]) &&
          p[0] < (r[j][0] - r[i][0]) * (p[1] - r[i][1]) / (r[j][1] - r[i][1]) + r[i][0])
        in = !in;
    return in;
  };
  const double touch = kStraightVertex * region_extent(rings);
  // Rings may touch at a vertex (a bow tie's two lobes): whether ring a lies inside ring b is
  // asked at a vertex of a, or the middle of a side, that is not on b.
  auto nested = [&](const Ring& a, const Ring& b) {
    for (int middles = 0; middles < 2; ++middles)
      for (size_t i = 0; i < a.size(); ++i) {
        const P2& q = a[(i + 1) % a.size()];
        const P2 p = middles ? P2{(a[i][0] + q[0]) / 2, (a[i][1] + q[1]) / 2} : a[i];
        bool on = false;
        for (size_t k = 0; k < b.size() && !on; ++k) on = segment_distance(p, b[k], b[(k + 1) % b.size()]) <= touch;
        if (!on) return inside(p, b);
      }
    return false;
  };
  std::vector<int> depth(n, 0), parent(n, -1);
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < n; ++j)
      if (i != j && nested(rings[i], rings[j])) {
        ++depth[i];
        if (parent[i] < 0 || std::abs(signed_area(rings[j])) < std::abs(signed_area(rings[size_t(parent[i])])))
          parent[i] = static_cast<int>(j);
      }
  std::vector<Solid> outers;
  for (size_t i = 0; i < n; ++i) {
    if (depth[i] % 2) continue;
    std::vector<Solid> parts;
    parts.push_back(leaf(ext(rings[i]), kIdentity));
    for (size_t j = 0; j < n; ++j)
      if (parent[j] == static_cast<int>(i) && depth[j] == depth[i] + 1) parts.push_back(leaf(ext(rings[j]), kIdentity));
    outers.push_back(combine(Solid::Kind::Difference, std::move(parts)));
  }
  return combine(Solid::Kind::Union, std::move(outers));
}

Region Lowering::shape_children(const Node& n, double st) {
  if (arg(n, "file") && arg(n, "file")->kind == Value::Kind::String && !arg(n, "file")->text.empty())
    return import_2d(n);
  stretch_3d_ = st;
  Region r = region_union(children2(n, kIdentity2));
  stretch_3d_ = 1;
  return r;
}

Solid Lowering::linear_extrude(const Node& n, const Affine& m) {
  const Region s = shape_children(n, stretch(m));
  LinearExtrude e;
  e.height = number(n, "height", 100);
  e.center = flag(n, "center", false);
  e.twist = number(n, "twist", 0);
  if (const Value* v = arg(n, "scale")) {
    const auto xs = numbers(n, *v, "scale");
    if (xs.size() == 1) e.scale = {xs[0], xs[0]};
    else if (xs.size() >= 2) e.scale = {xs[0], xs[1]};
  }
  e.scale = {std::max(0.0, e.scale[0]), std::max(0.0, e.scale[1])};
  check_finite(n, {e.height, e.twist, e.scale[0], e.scale[1]});
  int slices = static_cast<int>(number(n, "slices", 0));
  if (slices <= 0) slices = default_slices(s, e, number(n, "$fn", 0), number(n, "$fs", 2), number(n, "$fa", 12));
  if (opt_.smooth && e.twist != 0) {
    // The walls follow helices: keep the chord of the largest radius below the tolerance.
    const auto [lo, hi] = x_range(s);
    const double r = std::max(std::abs(lo), std::abs(hi)) * stretch(m);
    const int per_turn = frags(n, r, 1);
    slices = std::max(slices, static_cast<int>(std::ceil(per_turn * std::abs(e.twist) / 360)));
  }
  e.slices = std::max(slices, 1);
  if (!(e.height > 0)) return {};
  Solid out = extrude(s, [&](const Ring& r) { return extrude_linear(r, e); });
  transform(out, m);
  return out;
}

Solid Lowering::rotate_extrude(const Node& n, const Affine& m) {
  const Region s = shape_children(n, stretch(m));
  double angle = number(n, "angle", 360);
  check_finite(n, {angle});
  if (angle == 0 || s.empty()) return {};
  const auto [lo, hi] = x_range(s);
  if (lo < 0 && hi > 0) {
    // OpenSCAD reports this as an error, leaves the node out and renders the rest.
    left_out(n, "all points must have the same x coordinate sign");
    return {};
  }
  // OpenSCAD 2021: fragments(max |x|) |angle| / 360, at least 1.
  int f = static_cast<int>(std::fmax(
      fragments_from_r(hi - lo, number(n, "$fn", 0), number(n, "$fs", 2), number(n, "$fa", 12)) *
          std::abs(std::min(angle, 360.0)) / 360,
      1));
  if (opt_.smooth) f = std::max(f, static_cast<int>(std::ceil(frags(n, hi - lo, stretch(m)) * std::min(std::abs(angle), 360.0) / 360)));
  const bool mirrored = hi <= 0;  // profile left of the axis: revolve its mirror image
  Solid out = extrude(s, [&](Ring r) {
    if (mirrored)
      for (P2& p : r) p[0] = -p[0];
    return extrude_rotate(r, angle, f);
  });
  // OpenSCAD maps (x, y) at angle a to (x sin a, x cos a): a negative x lands half a turn on.
  transform(out, mirrored ? Affine{-1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1, 0} : kIdentity);
  transform(out, m);
  return out;
}

std::pair<double, double> Lowering::x_range(const Region& r) {
  double lo = 0, hi = 0;  // OpenSCAD's bounds include the origin
  for (const Ring& ring : r)
    for (const P2& p : ring) lo = std::min(lo, p[0]), hi = std::max(hi, p[0]);
  return {lo, hi};
}

void Lowering::transform(Solid& s, const Affine& m) {
  if (s.kind == Solid::Kind::Mesh) apply(m, s.mesh);
  if (s.kind == Solid::Kind::RoundSum) {
    // The body turns and scales with the sum; the move is the child's.
    TriMesh body;
    body.positions = s.body;
    body.positions.push_back({0, 0, 0});
    apply(m, body);
    const Vec3 origin = body.positions.back();
    body.positions.pop_back();
    for (Vec3& p : body.positions) p = detail::sub3(p, origin);
    s.body = std::move(body.positions);
  }
  for (Solid& c : s.children) transform(c, m);
}

}  // namespace pic::detail::scad

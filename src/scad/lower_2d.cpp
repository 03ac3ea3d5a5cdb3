// Lowering (lowering.h): 2D subtrees to regions.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "geometry/tolerances.h"
#include "io/file_util.h"
#include "scad/dxf.h"
#include "scad/lower.h"
#include "scad/lowering.h"
#include "scad/region.h"
#include "scad/svg.h"
#include "scad/text.h"
#include "geometry/tolerances.h"

namespace pic::detail::scad {

// ---- 2D: regions through Clipper, as OpenSCAD evaluates them ----
Region Lowering::shape(const Node& n, const Affine2& m) {
  ++nodes;
  const std::string& k = n.name;
  if (is_group(k)) return region_union(children2(n, m));
  if (k == "difference") return region_difference(children2(n, m));
  if (k == "intersection") return region_intersection(children2(n, m));
  if (k == "multmatrix") {
    const Affine a = matrix(n);
    return region_union(children2(n, compose2(m, {a[0], a[1], a[3], a[4], a[5], a[7]})));
  }
  if (k == "square") {
    double sx = 1, sy = 1;
    if (const Value* v = arg(n, "size")) {
      const auto xs = numbers(n, *v, "size");
      if (xs.size() == 1) sx = sy = xs[0];
      else if (xs.size() >= 2) sx = xs[0], sy = xs[1];
    }
    check_finite(n, {sx, sy});
    if (!(sx > 0 && sy > 0)) return {};
    const bool c = flag(n, "center", false);
    const double x0 = c ? -sx / 2 : 0, y0 = c ? -sy / 2 : 0;
    return {apply2(m, Ring{{x0, y0}, {x0 + sx, y0}, {x0 + sx, y0 + sy}, {x0, y0 + sy}})};
  }
  if (k == "circle") {
    const double r = radius(n, "r", "d", 1);
    check_finite(n, {r});
    if (!(r > 0)) return {};
    return {apply2(m, circle_ring(r, frags(n, r, stretch2(m) * stretch_3d_)))};
  }
  if (k == "polygon") return apply2(m, region_even_odd(polygon_rings(n)));
  if (k == "hull") {
    std::vector<P2> pts;
    for (const Region& c : children2(n, m))
      for (const Ring& r : c) pts.insert(pts.end(), r.begin(), r.end());
    Ring h = convex_hull_2d(pts);
    if (h.size() < 3) return {};
    return {std::move(h)};
  }
  if (k == "offset") return offset(n, m);
  if (k == "resize") {
    const Region r = region_union(children2(n, kIdentity2));
    double lo[2] = {kHuge, kHuge}, hi[2] = {-kHuge, -kHuge};
    for (const Ring& ring : r)
      for (const P2& p : ring)
        for (int a = 0; a < 2; ++a) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
    const auto f = resize_factors(n, {hi[0] - lo[0], hi[1] - lo[1], 0}, 2);
    return apply2(compose2(m, {f[0], 0, 0, 0, f[1], 0}), r);
  }
  if (k == "projection") {
    const Solid s = combine(Solid::Kind::Union, children3(n, kIdentity));
    if (s.kind == Solid::Kind::Empty) return {};
    return apply2(m, project(s.kind == Solid::Kind::Mesh ? s.mesh : solid_surface(s, opt_), flag(n, "cut", false)));
  }
  if (k == "text") return apply2(m, text(n, stretch2(m) * stretch_3d_));
  if (k == "import") return apply2(m, import_2d(n));
  if (k == "cube" || k == "sphere" || k == "cylinder" || k == "polyhedron" || k == "linear_extrude" ||
      k == "rotate_extrude")
    fail(n, "a 3D object inside a 2D subtree");
  if (k == "minkowski") return minkowski_2d(n, m);
  throw InvalidInput("line " + std::to_string(n.line) + ": unsupported node '" + k + "'");
}

// 2D minkowski(): each operand cut into convex parts that cover it, the sum the union of the
// hulls of the parts' vertex sums. Where the sums of two neighbouring parts meet along the sum's
// edge, the union leaves a vertex on that straight edge: dropped, so that the outline has the
// vertices of the sum itself, as OpenSCAD's has (a twisted extrusion splits every side quad,
// and one more vertex on a side changes its volume: 4 % for a notched pentagon).
Region Lowering::minkowski_2d(const Node& n, const Affine2& m) {
  std::vector<Ring> acc;
  bool first = true;
  for (const Node& c : n.children) {
    std::vector<Ring> parts;
    convex_parts_2d(c, kIdentity2, parts);
    if (parts.empty()) continue;
    if (first) {
      acc = std::move(parts);
      first = false;
      continue;
    }
    if (acc.size() * parts.size() > 100000) fail(n, "too many convex parts");
    std::vector<Ring> next;
    for (const Ring& p : acc)
      for (const Ring& q : parts) {
        std::vector<P2> sums;
        for (const P2& x : p)
          for (const P2& y : q) sums.push_back({x[0] + y[0], x[1] + y[1]});
        next.push_back(convex_hull_2d(std::move(sums)));
      }
    acc = std::move(next);
  }
  const Region sum = region_union({acc});
  return apply2(m, without_straight_vertices(sum, kStraightVertex * region_extent(sum)));
}

// The convex parts of a 2D operand: the children of its unions kept apart, each evaluated
// region's rings as they are when convex (no holes), else the region cut into convex pieces.
void Lowering::convex_parts_2d(const Node& n, const Affine2& m, std::vector<Ring>& out) {
  if (is_group(n.name)) {
    for (const Node& c : n.children) convex_parts_2d(c, m, out);
    return;
  }
  if (n.name == "multmatrix") {
    const Affine a = matrix(n);
    for (const Node& c : n.children) convex_parts_2d(c, compose2(m, {a[0], a[1], a[3], a[4], a[5], a[7]}), out);
    return;
  }
  const Region region = shape(n, m);
  const bool convex = std::all_of(region.begin(), region.end(), [](const Ring& ring) {
    const double area = signed_area(ring), hull = signed_area(convex_hull_2d(ring));
    return area > 0 && std::abs(hull - area) <= kConvexArea * hull;
  });
  if (convex) {
    out.insert(out.end(), region.begin(), region.end());
    return;
  }
  for (Ring& piece : convex_pieces(region)) out.push_back(std::move(piece));
}

std::vector<Region> Lowering::children2(const Node& n, const Affine2& m) {
  std::vector<Region> out;
  for (const Node& c : n.children) out.push_back(shape(c, m));
  return out;
}

std::vector<Ring> Lowering::polygon_rings(const Node& n) const {
  const Value* pv = arg(n, "points");
  if (!pv || pv->kind == Value::Kind::Undef) return {};  // OpenSCAD: empty, with a warning
  if (pv->kind != Value::Kind::Vector) fail(n, "points must be a vector");
  Ring pts;
  for (const Value& p : pv->items) {
    const auto xs = numbers(n, p, "points");
    if (xs.size() < 2) fail(n, "points must be [x, y]");
    check_finite(n, {xs[0], xs[1]});
    pts.push_back({xs[0], xs[1]});
  }
  const Value* paths = arg(n, "paths");
  if (!paths || paths->kind != Value::Kind::Vector || paths->items.empty()) return {pts};
  std::vector<Ring> rings;
  for (const Value& path : paths->items) {
    Ring r;
    for (double x : numbers(n, path, "paths")) {
      if (!(x >= 0 && x < double(pts.size()))) fail(n, "path index out of range");
      r.push_back(pts[static_cast<size_t>(x)]);
    }
    rings.push_back(std::move(r));
  }
  return rings;
}

// offset(r = ...) rounds, offset(delta = ...) mitres or, with chamfer, cuts the corners;
// applied in the children's frame (a uniform scale commutes with it, as OpenSCAD assumes).
Region Lowering::offset(const Node& n, const Affine2& m) {
  const Region in = region_union(children2(n, kIdentity2));
  const Value* rv = arg(n, "r");
  const bool by_r = rv && rv->kind == Value::Kind::Number;
  const double amount = by_r ? rv->number : number(n, "delta", 1);
  check_finite(n, {amount});
  OffsetJoin join = flag(n, "chamfer", false) ? OffsetJoin::kChamfer : OffsetJoin::kMiter;
  double tolerance = 0;
  if (by_r) {
    join = OffsetJoin::kRound;
    // OpenSCAD: arcs of fragments_from_r(|r|) pieces per turn. Clipper rounds a corner's
    // steps to the nearest whole number, and a square's corner with 6 pieces per turn asks for
    // 1.5: OpenSCAD's cosine of 30 degrees makes it one step.
    const int f = frags(n, std::abs(amount), stretch2(m) * stretch_3d_);
    tolerance = std::abs(amount) * (1 - cos_degrees(180.0 / f));
  }
  return apply2(m, region_offset(in, amount, join, tolerance));
}

// import() of a DXF or SVG drawing, or the legacy `file` argument of an extrusion.
Region Lowering::import_2d(const Node& n) const {
  const std::filesystem::path p = file_arg(n);
  if (missing(n, p)) return {};
  const std::string ext = lower_extension(p);
  if (ext == ".svg") return read_svg(p, number(n, "dpi", 72));
  if (ext != ".dxf") fail(n, "2D import of " + ext + " files is not supported (DXF and SVG are)");
  DxfImport how;
  if (const Value* v = arg(n, "layer"); v && v->kind == Value::Kind::String) how.layer = v->text;
  if (const Value* v = arg(n, "origin"); v && v->kind == Value::Kind::Vector) {
    const auto xs = numbers(n, *v, "origin");
    if (xs.size() >= 2) how.origin = {xs[0], xs[1]};
  }
  how.scale = number(n, "scale", 1);
  how.fn = number(n, "$fn", 0);
  how.fs = number(n, "$fs", 2);
  how.fa = number(n, "$fa", 12);
  check_finite(n, {how.origin[0], how.origin[1], how.scale});
  return read_dxf(p, how);
}

Region Lowering::text(const Node& n, double st) const {
  TextParams p;
  const auto str = [&](const char* key, const std::string& fallback) {
    const Value* v = arg(n, key);
    return v && v->kind == Value::Kind::String && !v->text.empty() ? v->text : fallback;
  };
  p.text = str("text", "");
  if (p.text.empty()) p.text = str("t", "");
  p.size = number(n, "size", 10);
  p.spacing = number(n, "spacing", 1);
  check_finite(n, {p.size, p.spacing});
  p.font = str("font", "");
  p.halign = str("halign", "left");
  p.valign = str("valign", "baseline");
  p.direction = str("direction", "");
  p.language = str("language", "en");
  p.script = str("script", "");
  // Straight pieces per curve of the outline: floor(fragments / 8) + 1 for the circle
  // fragments of the text's size, and never fewer than 2 (counted on OpenSCAD 2021's exports
  // for $fn 3 to 40 and sizes 0.5 to 30). With one chord per curve a small "o"'s outer ring cuts
  // through its hole.
  p.segments = std::max(2, frags(n, p.size, st) / 8 + 1);
  return text_region(p);
}

}  // namespace pic::detail::scad

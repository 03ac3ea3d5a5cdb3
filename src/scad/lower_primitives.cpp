// Lowering (lowering.h): the 3D primitives cube, cylinder, polyhedron and import.
#include <algorithm>
#include <string>

#include "pic/io.h"
#include "pic/measure.h"
#include "pic/primitives.h"
#include "io/file_util.h"
#include "scad/lowering.h"

namespace pic::detail::scad {

TriMesh Lowering::cube(const Node& n) const {
  Vec3 s{1, 1, 1};
  if (const Value* v = arg(n, "size")) {
    const auto xs = numbers(n, *v, "size");
    if (xs.size() == 1) s = {xs[0], xs[0], xs[0]};
    else if (xs.size() >= 3) s = {xs[0], xs[1], xs[2]};
    else fail(n, "size must be a number or [x, y, z]");
  }
  check_finite(n, {s[0], s[1], s[2]});
  if (!(s[0] > 0 && s[1] > 0 && s[2] > 0)) return {};
  const bool c = flag(n, "center", false);
  const Vec3 lo = c ? Vec3{-s[0] / 2, -s[1] / 2, -s[2] / 2} : Vec3{0, 0, 0};
  return make_box(lo, {lo[0] + s[0], lo[1] + s[1], lo[2] + s[2]});
}

TriMesh Lowering::cylinder(const Node& n, double st) {
  const double h = number(n, "h", 1);
  double r1 = number(n, "r1", 1), r2 = number(n, "r2", 1);
  if (const Value* v = arg(n, "r"); v && v->kind == Value::Kind::Number) r1 = r2 = v->number;
  check_finite(n, {h, r1, r2});
  if (!(h > 0) || r1 < 0 || r2 < 0 || (r1 <= 0 && r2 <= 0)) return {};
  const bool c = flag(n, "center", false);
  const double z1 = c ? -h / 2 : 0;
  return cylinder_mesh(r1, r2, z1, z1 + h, frags(n, std::max(r1, r2), st));
}

TriMesh Lowering::polyhedron(const Node& n) const {
  const Value* pv = arg(n, "points");
  const Value* fv = arg(n, "faces");
  if (!fv || fv->kind != Value::Kind::Vector) fv = arg(n, "triangles");
  if (!pv || !fv || pv->kind != Value::Kind::Vector || fv->kind != Value::Kind::Vector)
    fail(n, "needs points and faces");
  TriMesh m;
  for (const Value& p : pv->items) {
    const auto xs = numbers(n, p, "points");
    if (xs.size() < 3) fail(n, "points must be [x, y, z]");
    check_finite(n, {xs[0], xs[1], xs[2]});
    m.positions.push_back({xs[0], xs[1], xs[2]});
  }
  for (const Value& f : fv->items) {
    const auto xs = numbers(n, f, "faces");
    std::vector<uint32_t> ids;
    for (double x : xs) {
      if (!(x >= 0 && x < double(m.positions.size()))) fail(n, "face index out of range");
      ids.push_back(static_cast<uint32_t>(x));
    }
    // OpenSCAD's faces are clockwise seen from outside: reverse while fanning.
    for (size_t i = 1; i + 1 < ids.size(); ++i) m.triangles.push_back({ids[0], ids[i + 1], ids[i]});
  }
  if (volume(m) < 0)  // faces given counter-clockwise: OpenSCAD renders them anyway
    for (auto& t : m.triangles) std::swap(t[1], t[2]);
  return m;
}

TriMesh Lowering::import(const Node& n) const {
  const std::filesystem::path p = file_arg(n);
  if (missing(n, p)) return {};
  const std::string ext = lower_extension(p);
  if (ext == ".dxf" || ext == ".svg") fail(n, "a 2D drawing outside linear_extrude/rotate_extrude (the model must be 3D)");
  return read_mesh(p);
}

}  // namespace pic::detail::scad

// Lowering an OpenSCAD CSG tree to Booleans over closed meshes: see lower.h.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <string>

#include "pic/io.h"
#include "pic/measure.h"
#include "pic/primitives.h"
#include "io/file_util.h"
#include "scad/dxf.h"
#include "scad/lower.h"
#include "scad/region.h"
#include "scad/svg.h"
#include "scad/text.h"
#include "geometry/tolerances.h"

namespace pic::detail::scad {
namespace {

using Node = detail::scad::Node;  // not pic::Node (an octree cell)

// Row-major 3x4 affine map.
using Affine = std::array<double, 12>;
constexpr Affine kIdentity{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
// 2D affine map [a b tx; c d ty].
using Affine2 = std::array<double, 6>;
constexpr Affine2 kIdentity2{1, 0, 0, 0, 1, 0};

Affine compose(const Affine& a, const Affine& b) {  // a * b
  Affine r{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j) {
      double s = j == 3 ? a[i * 4 + 3] : 0;
      for (int k = 0; k < 3; ++k) s += a[i * 4 + k] * b[k * 4 + j];
      r[i * 4 + j] = s;
    }
  return r;
}
Affine2 compose2(const Affine2& a, const Affine2& b) {
  return {a[0] * b[0] + a[1] * b[3], a[0] * b[1] + a[1] * b[4], a[0] * b[2] + a[1] * b[5] + a[2],
          a[3] * b[0] + a[4] * b[3], a[3] * b[1] + a[4] * b[4], a[3] * b[2] + a[4] * b[5] + a[5]};
}
double det3(const Affine& m) {
  return m[0] * (m[5] * m[10] - m[6] * m[9]) - m[1] * (m[4] * m[10] - m[6] * m[8]) +
         m[2] * (m[4] * m[9] - m[5] * m[8]);
}
// Largest stretch of the linear part (max column norm; enough to size tessellations).
double stretch(const Affine& m) {
  double s = 0;
  for (int j = 0; j < 3; ++j)
    s = std::max(s, std::sqrt(m[j] * m[j] + m[4 + j] * m[4 + j] + m[8 + j] * m[8 + j]));
  return s;
}
double stretch2(const Affine2& m) {
  return std::max(std::hypot(m[0], m[3]), std::hypot(m[1], m[4]));
}

void apply(const Affine& m, TriMesh& mesh) {
  for (Vec3& p : mesh.positions) {
    const Vec3 q = p;
    for (int i = 0; i < 3; ++i) p[i] = m[i * 4] * q[0] + m[i * 4 + 1] * q[1] + m[i * 4 + 2] * q[2] + m[i * 4 + 3];
  }
  if (det3(m) < 0)
    for (auto& t : mesh.triangles) std::swap(t[1], t[2]);
}
// A mirroring map reverses the ring, so outer boundaries stay counter-clockwise.
Ring apply2(const Affine2& m, const Ring& r) {
  Ring out;
  out.reserve(r.size());
  for (const P2& p : r) out.push_back({m[0] * p[0] + m[1] * p[1] + m[2], m[3] * p[0] + m[4] * p[1] + m[5]});
  if (m[0] * m[4] - m[1] * m[3] < 0) std::reverse(out.begin(), out.end());
  return out;
}
Region apply2(const Affine2& m, const Region& r) {
  Region out;
  out.reserve(r.size());
  for (const Ring& ring : r) out.push_back(apply2(m, ring));
  return out;
}

[[noreturn]] void fail(const Node& n, const std::string& what) {
  throw InvalidInput("line " + std::to_string(n.line) + ": " + n.name + ": " + what);
}

const Value* arg(const Node& n, const std::string& key) {
  const auto it = n.args.find(key);
  return it == n.args.end() ? nullptr : &it->second;
}
double number(const Node& n, const std::string& key, double fallback) {
  const Value* v = arg(n, key);
  if (!v || v->kind == Value::Kind::Undef) return fallback;
  if (v->kind == Value::Kind::Bool) return v->boolean ? 1 : 0;
  if (v->kind != Value::Kind::Number) fail(n, "'" + key + "' must be a number");
  return v->number;
}
bool flag(const Node& n, const std::string& key, bool fallback) {
  const Value* v = arg(n, key);
  if (!v || v->kind == Value::Kind::Undef) return fallback;
  if (v->kind == Value::Kind::Bool) return v->boolean;
  if (v->kind == Value::Kind::Number) return v->number != 0;
  return fallback;
}
std::vector<double> numbers(const Node& n, const Value& v, const std::string& key) {
  std::vector<double> out;
  if (v.kind == Value::Kind::Number) return {v.number};
  if (v.kind != Value::Kind::Vector) fail(n, "'" + key + "' must be a vector of numbers");
  for (const Value& x : v.items) {
    if (x.kind != Value::Kind::Number) fail(n, "'" + key + "' must be a vector of numbers");
    out.push_back(x.number);
  }
  return out;
}
void check_finite(const Node& n, std::initializer_list<double> xs) {
  for (double x : xs)
    if (!std::isfinite(x)) fail(n, "non-finite parameter");
}

bool is_2d_node(const std::string& s) {
  return s == "square" || s == "circle" || s == "polygon" || s == "text" || s == "offset";
}
bool is_group(const std::string& s) {
  return s == "group" || s == "union" || s == "color" || s == "render";
}

class Lowering {
 public:
  Lowering(const EvalOptions& o, double finest_cell) : opt_(o), cell_(finest_cell) {}
  size_t nodes = 0;

  Region region(const Node& n) { return shape(n, kIdentity2); }

  Solid solid(const Node& n, const Affine& m) {
    ++nodes;
    const std::string& k = n.name;
    if (is_group(k)) return combine(Solid::Kind::Union, children3(n, m));
    if (k == "difference") return combine(Solid::Kind::Difference, children3(n, m));
    if (k == "intersection") return combine(Solid::Kind::Intersect, children3(n, m));
    if (k == "multmatrix") return combine(Solid::Kind::Union, children3(n, compose(m, matrix(n))));
    if (k == "hull") {
      Solid s;
      s.kind = Solid::Kind::Hull;
      s.children = children3(n, m);
      std::erase_if(s.children, [](const Solid& c) { return c.kind == Solid::Kind::Empty; });
      if (s.children.empty()) s.kind = Solid::Kind::Empty;
      return s;
    }
    if (k == "minkowski") {  // of the operands where they are, then moved (a sum is not moved twice)
      Solid s;
      try {
        s = scad::minkowski(children3(n, kIdentity), opt_);
      } catch (const InvalidInput& e) {
        fail(n, e.what());
      }
      transform(s, m);
      return s;
    }
    if (k == "resize") {  // sized where it is, then moved
      const Solid s = combine(Solid::Kind::Union, children3(n, kIdentity));
      if (s.kind == Solid::Kind::Empty) return s;
      const TriMesh surface = solid_surface(s, opt_);
      Vec3 lo{kHuge, kHuge, kHuge}, hi{-kHuge, -kHuge, -kHuge};
      for (const Vec3& p : surface.positions)
        for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
      const auto f = resize_factors(n, {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]}, 3);
      Solid out = s;
      transform(out, compose(m, Affine{f[0], 0, 0, 0, 0, f[1], 0, 0, 0, 0, f[2], 0}));
      return out;
    }
    if (k == "cube") return leaf(cube(n), m);
    if (k == "surface") {
      return leaf(surface_mesh(file_arg(n), flag(n, "center", false), flag(n, "invert", false)), m);
    }
    if (k == "sphere") {
      const double r = radius(n, "r", "d", 1);
      if (!(r > 0)) return {};
      return leaf(sphere_mesh(r, frags(n, r, stretch(m))), m);
    }
    if (k == "cylinder") return leaf(cylinder(n, stretch(m)), m);
    if (k == "polyhedron") return leaf(polyhedron(n), m);
    if (k == "import") return leaf(import(n), m);
    if (k == "linear_extrude") return linear_extrude(n, m);
    if (k == "rotate_extrude") return rotate_extrude(n, m);
    if (is_2d_node(k)) fail(n, "a 2D object outside linear_extrude/rotate_extrude (the model must be 3D)");
    throw InvalidInput("line " + std::to_string(n.line) + ": unsupported node '" + k + "'");
  }

 private:
  const EvalOptions& opt_;
  double cell_;  // finest cell, for --smooth

  // Fragments for a circle of radius r (model units) drawn `st` times larger in the world:
  // OpenSCAD's rule on r, or, with --smooth, enough that the chord's sagitta
  // r st (1 - cos(pi / n)) stays below smooth_chord finest cells.
  int frags(const Node& n, double r, double st) const {
    const double world_r = r * st;
    if (opt_.smooth && cell_ > 0 && world_r > 0) {
      const double e = opt_.smooth_chord * cell_;
      if (e >= world_r) return 8;
      return std::clamp(static_cast<int>(std::ceil(std::numbers::pi / std::acos(1 - e / world_r))), 8, 4096);
    }
    return fragments_from_r(r, number(n, "$fn", 0), number(n, "$fs", 2), number(n, "$fa", 12));
  }

  Affine matrix(const Node& n) const {
    const Value* v = arg(n, "m");
    if (!v) v = arg(n, "0");
    if (!v || v->kind != Value::Kind::Vector || v->items.size() < 3) fail(n, "needs a 4x4 matrix");
    Affine a{};
    for (int i = 0; i < 3; ++i) {
      const auto row = numbers(n, v->items[i], "m");
      if (row.size() < 4) fail(n, "needs a 4x4 matrix");
      for (int j = 0; j < 4; ++j) a[i * 4 + j] = row[j];
    }
    for (double x : a)
      if (!std::isfinite(x)) fail(n, "non-finite matrix");
    return a;
  }

  std::vector<Solid> children3(const Node& n, const Affine& m) {
    std::vector<Solid> out;
    for (const Node& c : n.children) out.push_back(solid(c, m));
    return out;
  }
  static Solid combine(Solid::Kind kind, std::vector<Solid> kids) {
    Solid s;
    if (kind == Solid::Kind::Difference) {
      if (kids.empty() || kids[0].kind == Solid::Kind::Empty) return s;
      Solid first = std::move(kids[0]);
      kids.erase(kids.begin());
      std::erase_if(kids, [](const Solid& c) { return c.kind == Solid::Kind::Empty; });
      if (kids.empty()) return first;
      s.kind = kind;
      s.children.push_back(std::move(first));
      for (auto& c : kids) s.children.push_back(std::move(c));
      return s;
    }
    if (kind == Solid::Kind::Intersect) {
      for (const auto& c : kids)
        if (c.kind == Solid::Kind::Empty) return s;
    }
    std::erase_if(kids, [](const Solid& c) { return c.kind == Solid::Kind::Empty; });
    if (kids.empty()) return s;
    if (kids.size() == 1) return std::move(kids[0]);
    s.kind = kind;
    s.children = std::move(kids);
    return s;
  }
  static Solid leaf(TriMesh mesh, const Affine& m) {
    Solid s;
    if (mesh.triangles.empty() || !(std::abs(det3(m)) > 0)) return s;
    apply(m, mesh);
    s.kind = Solid::Kind::Mesh;
    s.mesh = std::move(mesh);
    return s;
  }

  double radius(const Node& n, const char* r, const char* d, double fallback) const {
    if (const Value* v = arg(n, r); v && v->kind == Value::Kind::Number) return v->number;
    if (const Value* v = arg(n, d); v && v->kind == Value::Kind::Number) return v->number / 2;
    return fallback;
  }

  TriMesh cube(const Node& n) const {
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

  TriMesh cylinder(const Node& n, double st) {
    const double h = number(n, "h", 1);
    double r1 = number(n, "r1", 1), r2 = number(n, "r2", 1);
    if (const Value* v = arg(n, "r"); v && v->kind == Value::Kind::Number) r1 = r2 = v->number;
    check_finite(n, {h, r1, r2});
    if (!(h > 0) || r1 < 0 || r2 < 0 || (r1 <= 0 && r2 <= 0)) return {};
    const bool c = flag(n, "center", false);
    const double z1 = c ? -h / 2 : 0;
    return cylinder_mesh(r1, r2, z1, z1 + h, frags(n, std::max(r1, r2), st));
  }

  TriMesh polyhedron(const Node& n) const {
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

  // A node's `file` argument (or its first positional one), relative to the model's folder.
  std::filesystem::path file_arg(const Node& n) const {
    const Value* f = arg(n, "file");
    if (!f) f = arg(n, "0");
    if (!f || f->kind != Value::Kind::String) fail(n, "needs file = \"...\"");
    std::filesystem::path p = f->text;
    return p.is_relative() ? opt_.base_dir / p : p;
  }

  // OpenSCAD warns about an import() file that does not exist and goes on with nothing there.
  bool missing(const Node& n, const std::filesystem::path& p) const {
    std::error_code ec;
    if (std::filesystem::exists(p, ec)) return false;
    if (opt_.warning) opt_.warning("line " + std::to_string(n.line) + ": import: cannot open " + p.string() + " (left out)");
    return true;
  }
  TriMesh import(const Node& n) const {
    const std::filesystem::path p = file_arg(n);
    if (missing(n, p)) return {};
    const std::string ext = lower_extension(p);
    if (ext == ".dxf" || ext == ".svg") fail(n, "a 2D drawing outside linear_extrude/rotate_extrude (the model must be 3D)");
    return read_mesh(p);
  }

  // ---- 2D: regions through Clipper, as OpenSCAD evaluates them ----
  Region shape(const Node& n, const Affine2& m) {
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
  // resize(newsize, auto): per axis newsize / size where newsize > 0; an axis left at 0 keeps
  // its size, or with `auto` takes the largest factor of the axes given.
  std::array<double, 3> resize_factors(const Node& n, const std::array<double, 3>& size, int dims) const {
    std::array<double, 3> want{0, 0, 0}, f{1, 1, 1};
    std::array<bool, 3> automatic{false, false, false};
    if (const Value* v = arg(n, "newsize")) {
      const auto xs = numbers(n, *v, "newsize");
      for (size_t a = 0; a < std::min<size_t>(3, xs.size()); ++a) want[a] = xs[a];
    }
    if (const Value* v = arg(n, "auto")) {
      if (v->kind == Value::Kind::Vector) {
        for (size_t a = 0; a < std::min<size_t>(3, v->items.size()); ++a) {
          const Value& x = v->items[a];
          automatic[a] = x.kind == Value::Kind::Bool ? x.boolean : x.kind == Value::Kind::Number && x.number != 0;
        }
      } else {
        automatic.fill(flag(n, "auto", false));
      }
    }
    double largest = 0;
    for (int a = 0; a < dims; ++a) {
      check_finite(n, {want[a]});
      if (want[a] > 0 && size[a] > 0) largest = std::max(largest, f[a] = want[a] / size[a]);
    }
    for (int a = 0; a < dims; ++a)
      if (!(want[a] > 0) && automatic[a] && largest > 0) f[a] = largest;
    return f;
  }

  // 2D minkowski(): each operand cut into convex parts that cover it, the sum the union of the
  // hulls of the parts' vertex sums.
  Region minkowski_2d(const Node& n, const Affine2& m) {
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
    return apply2(m, region_union({acc}));
  }
  // The convex parts of a 2D operand: the children of its unions kept apart, each evaluated
  // region's rings as they are when convex (no holes), else the region cut into convex pieces.
  void convex_parts_2d(const Node& n, const Affine2& m, std::vector<Ring>& out) {
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

  std::vector<Region> children2(const Node& n, const Affine2& m) {
    std::vector<Region> out;
    for (const Node& c : n.children) out.push_back(shape(c, m));
    return out;
  }
  std::vector<Ring> polygon_rings(const Node& n) const {
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
  Region offset(const Node& n, const Affine2& m) {
    const Region in = region_union(children2(n, kIdentity2));
    const Value* rv = arg(n, "r");
    const bool by_r = rv && rv->kind == Value::Kind::Number;
    const double amount = by_r ? rv->number : number(n, "delta", 1);
    check_finite(n, {amount});
    OffsetJoin join = flag(n, "chamfer", false) ? OffsetJoin::kChamfer : OffsetJoin::kMiter;
    double tolerance = 0;
    if (by_r) {
      join = OffsetJoin::kRound;
      // OpenSCAD: arcs of fragments_from_r(|r|) pieces per turn.
      const int f = frags(n, std::abs(amount), stretch2(m) * stretch_3d_);
      tolerance = std::abs(amount) * (1 - std::cos(std::numbers::pi / f));
    }
    return apply2(m, region_offset(in, amount, join, tolerance));
  }
  // import() of a DXF or SVG drawing, or the legacy `file` argument of an extrusion.
  Region import_2d(const Node& n) const {
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

  Region text(const Node& n, double st) const {
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
    // fragments of the text's size (counted on OpenSCAD 2021's exports for $fn 8 to 40).
    p.segments = frags(n, p.size, st) / 8 + 1;
    return text_region(p);
  }

  // A region's rings (which do not cross) -> Booleans of extruded simple rings: each ring at
  // even nesting depth minus the rings directly inside it.
  template <class Extrude>
  Solid extrude(const Region& region, const Extrude& ext) {
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
    std::vector<int> depth(n, 0), parent(n, -1);
    for (size_t i = 0; i < n; ++i)
      for (size_t j = 0; j < n; ++j)
        if (i != j && inside(rings[i][0], rings[j])) {
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

  Region shape_children(const Node& n, double st) {
    if (arg(n, "file") && arg(n, "file")->kind == Value::Kind::String && !arg(n, "file")->text.empty())
      return import_2d(n);
    stretch_3d_ = st;
    Region r = region_union(children2(n, kIdentity2));
    stretch_3d_ = 1;
    return r;
  }
  double stretch_3d_ = 1;

  Solid linear_extrude(const Node& n, const Affine& m) {
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
    // Slices when `slices` is not given, as OpenSCAD 2021.01 does (measured against its
    // output; Calc::get_helix_slices / get_diagonal_slices): a twist takes the fewer of
    // |twist| / $fa and (helix length of the outermost vertex) / $fs, at least one per 120
    // degrees, or |twist| $fn / 360 when $fn is set; a non-uniform scale without twist takes
    // (length of the longest vertex path) / $fs; otherwise one slice.
    int slices = static_cast<int>(number(n, "slices", 0));
    if (slices <= 0) {
      const double fn = number(n, "$fn", 0), fs = number(n, "$fs", 2), fa = number(n, "$fa", 12);
      double r2 = 0, d2 = 0;
      for (const Ring& ring : s)
        for (const P2& p : ring) {
          r2 = std::max(r2, p[0] * p[0] + p[1] * p[1]);
          const double dx = p[0] * (e.scale[0] - 1), dy = p[1] * (e.scale[1] - 1);
          d2 = std::max(d2, dx * dx + dy * dy);
        }
      const double tw = std::abs(e.twist);
      slices = 1;
      if (tw > 0) {
        const int min_slices = std::max(static_cast<int>(std::ceil(tw / 120.0)), 1);
        if (fn > 0) {
          slices = std::max(static_cast<int>(std::ceil(tw / 360.0 * fn)), min_slices);
        } else if (std::sqrt(r2) >= 0.00000095367431640625) {
          // Length of the outermost vertex's path: a conical helix when scaled (Simpson's rule).
          const double r0 = std::sqrt(r2), th = tw * std::numbers::pi / 180;
          const double sc = std::max(e.scale[0], e.scale[1]);
          auto speed = [&](double t) {
            const double r = r0 * (1 + (sc - 1) * t), dr = r0 * (sc - 1);
            return std::sqrt(r * r * th * th + dr * dr + e.height * e.height);
          };
          constexpr int kSteps = 64;
          double len = speed(0) + speed(1);
          for (int i = 1; i < kSteps; ++i) len += (i % 2 ? 4 : 2) * speed(double(i) / kSteps);
          len /= 3.0 * kSteps;
          const int fa_slices = static_cast<int>(std::ceil(tw / fa));
          const int fs_slices = static_cast<int>(std::ceil(len / fs));
          slices = std::max(std::min(fa_slices, fs_slices), min_slices);
        } else {
          slices = min_slices;
        }
      } else if (e.scale[0] != e.scale[1]) {
        slices = fn > 0 ? std::max(static_cast<int>(fn), 1)
                        : std::max(static_cast<int>(std::ceil(std::sqrt(d2 + e.height * e.height) / fs)), 1);
      }
    }
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

  Solid rotate_extrude(const Node& n, const Affine& m) {
    const Region s = shape_children(n, stretch(m));
    double angle = number(n, "angle", 360);
    check_finite(n, {angle});
    if (angle == 0 || s.empty()) return {};
    const auto [lo, hi] = x_range(s);
    if (lo < 0 && hi > 0) fail(n, "all points must have the same x coordinate sign");
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

  static std::pair<double, double> x_range(const Region& r) {
    double lo = 0, hi = 0;  // OpenSCAD's bounds include the origin
    for (const Ring& ring : r)
      for (const P2& p : ring) lo = std::min(lo, p[0]), hi = std::max(hi, p[0]);
    return {lo, hi};
  }

  static void transform(Solid& s, const Affine& m) {
    if (s.kind == Solid::Kind::Mesh) apply(m, s.mesh);
    for (Solid& c : s.children) transform(c, m);
  }
};


}  // namespace

Solid lower(const Node& root, const EvalOptions& options, double finest_cell, size_t* nodes) {
  Lowering l(options, finest_cell);
  Solid s = l.solid(root, kIdentity);
  if (nodes) *nodes = l.nodes - 1;
  return s;
}

int dimension(const Node& n) {
  const std::string& k = n.name;
  if (is_2d_node(k) || k == "projection") return 2;
  if (k == "import") {
    const Value* f = arg(n, "file");
    const std::string ext = f && f->kind == Value::Kind::String ? lower_extension(f->text) : "";
    return ext == ".dxf" || ext == ".svg" ? 2 : 3;
  }
  if (n.children.empty())
    return k == "group" || k == "union" || k == "difference" || k == "intersection" || k == "multmatrix" ||
                   k == "color" || k == "render" || k == "hull" || k == "minkowski" || k == "resize"
               ? 0
               : 3;
  if (k == "linear_extrude" || k == "rotate_extrude") return 3;
  for (const Node& c : n.children)
    if (const int d = dimension(c)) return d;
  return 0;
}

std::vector<Ring> lower_2d(const Node& root, const EvalOptions& options, size_t* nodes) {
  Lowering l(options, 0);
  Region r = l.region(root);
  if (nodes) *nodes = l.nodes - 1;
  return r;
}

}  // namespace pic::detail::scad

// Lowering an OpenSCAD CSG tree to Booleans over closed meshes: see lower.h. Here the entry
// points and the walk over the 3D tree (Booleans, hull, minkowski, resize); lowering.h lists
// the files of the other node kinds.
#include <algorithm>
#include <string>

#include "io/file_util.h"
#include "scad/lower.h"
#include "pic/volume.h"
#include "scad/lowering.h"
#include "geometry/tolerances.h"

namespace pic::detail::scad {

Solid Lowering::solid(const Node& n, const Affine& m) {
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
    const std::vector<Solid> operands = children3(n, kIdentity);
    try {
      s = scad::minkowski(operands, opt_);
    } catch (const InvalidInput& e) {
      fail(n, e.what());
    }
    transform(s, m);
    // A sum moved by a transform that is not a similarity holds an ellipsoid: the exact path.
    if (s.kind == Solid::Kind::RoundSum && !is_round_body(s.body)) {
      s = scad::minkowski(operands, opt_, true);
      transform(s, m);
    }
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

std::vector<Solid> Lowering::children3(const Node& n, const Affine& m) {
  std::vector<Solid> out;
  for (const Node& c : n.children) out.push_back(solid(c, m));
  return out;
}

Solid Lowering::combine(Solid::Kind kind, std::vector<Solid> kids) {
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

Solid Lowering::leaf(TriMesh mesh, const Affine& m) {
  Solid s;
  if (mesh.triangles.empty() || !(std::abs(det3(m)) > 0)) return s;
  apply(m, mesh);
  s.kind = Solid::Kind::Mesh;
  s.mesh = std::move(mesh);
  return s;
}

// resize(newsize, auto): per axis newsize / size where newsize > 0; an axis left at 0 keeps
// its size, or with `auto` takes the factor of the axis given the largest new size (as
// OpenSCAD 2021 does: resize([2, 0, 3], auto = true) of a 1 x 1 x 4 box scales y by 3 / 4).
std::array<double, 3> Lowering::resize_factors(const Node& n, const std::array<double, 3>& size, int dims) const {
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
  int widest = 0;  // the axis given the largest new size
  for (int a = 0; a < dims; ++a) {
    check_finite(n, {want[a]});
    if (want[a] > 0 && size[a] > 0) f[a] = want[a] / size[a];
    if (want[a] > want[widest]) widest = a;
  }
  for (int a = 0; a < dims; ++a)
    if (!(want[a] > 0) && automatic[a]) f[a] = f[widest];
  return f;
}

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

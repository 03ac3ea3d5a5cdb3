// The module's free functions: one call into the library each, arguments converted in
// convert.cpp, the GIL released around the library call.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "convert.h"
#include "octree.h"
#include "pic/primitives.h"
#include "pic/scad.h"
#include "pic/volume.h"

namespace pic_python {

namespace {

namespace fs = std::filesystem;

bool is_path(py::handle obj) { return py::isinstance<py::str>(obj) || py::hasattr(obj, "__fspath__"); }
fs::path to_path(py::handle obj) { return fs::path(py::str(py::module_::import("os").attr("fspath")(obj)).cast<std::string>()); }

pic::SampleOptions sample_options(int depth, double error, py::handle cube, const std::string& inside, bool parallel,
                                  double margin) {
  pic::SampleOptions o;
  o.depth = depth;
  o.error = error;
  o.cube = to_cube(cube);
  o.margin = margin;
  o.parallel = parallel;
  const auto mode = pic::parse_inside_mode(inside);
  if (!mode) throw py::value_error("inside must be 'auto', 'parity' or 'winding', got '" + inside + "'");
  o.inside = *mode;
  return o;
}

std::unique_ptr<PyOctree> sample_cloud(const pic::PointCloud& cloud, const pic::SampleOptions& o) {
  pic::SampleStats st;
  pic::Octree tree;
  {
    py::gil_scoped_release nogil;
    tree = pic::sample(cloud, o, &st);
  }
  return wrap(std::move(tree), sample_stats(st));
}

std::unique_ptr<PyOctree> sample(py::object input, py::object faces, int depth, double error, py::object cube,
                                 const std::string& inside, bool parallel, double margin) {
  const pic::SampleOptions o = sample_options(depth, error, cube, inside, parallel, margin);
  pic::SampleStats st;
  pic::Octree tree;
  if (is_path(input)) {
    if (!faces.is_none()) throw py::value_error("sample(path) takes no faces");
    const fs::path path = to_path(input);
    {
      py::gil_scoped_release nogil;
      const pic::Geometry geo = pic::read_geometry(path);
      tree = geo.is_point_cloud() ? pic::sample(geo.points, o, &st) : pic::sample(geo.mesh, o, &st);
    }
    return wrap(std::move(tree), sample_stats(st));
  }
  std::optional<pic::TriMesh> mesh;
  if (faces.is_none()) {
    mesh = as_mesh(input);
    if (!mesh && py::isinstance<py::tuple>(input) && py::len(input) == 2) {
      // The old spelling of a point cloud: sample((points, normals)).
      PyErr_WarnEx(PyExc_DeprecationWarning, "sample((points, normals)) is deprecated: use sample_points(points, normals)", 1);
      const auto t = input.cast<py::tuple>();
      return sample_cloud(to_cloud(t[0], t[1]), o);
    }
    if (!mesh)
      throw py::value_error("faces is missing: a mesh is sample(vertices, faces) or sample(mesh), a point cloud "
                            "sample_points(points, normals)");
  } else {
    mesh = to_mesh(input, faces);
  }
  {
    py::gil_scoped_release nogil;
    tree = pic::sample(*mesh, o, &st);
  }
  return wrap(std::move(tree), sample_stats(st));
}

/// One operand of csg_meshes: a PIC object as it is, or a mesh.
pic::CsgOperand to_operand(py::handle x, size_t k) {
  pic::CsgOperand out;
  out.name = "operand " + std::to_string(k);
  if (py::isinstance<PyOctree>(x)) {
    const PyOctree& t = x.cast<const PyOctree&>();
    std::lock_guard lock(t.mutex);
    out.tree = t.tree;
  } else if (auto m = as_mesh(x)) {
    out.mesh = std::move(*m);
  } else if (is_path(x)) {
    out.mesh = pic::read_mesh(to_path(x));
  } else {
    throw py::value_error("csg_meshes operands are meshes (pic.Mesh, (vertices, faces), .vertices/.faces), mesh "
                          "paths or Octrees");
  }
  return out;
}

/// A leaf of a CSG tree: a PIC object (copied, so the tree owns what it evaluates) or a mesh.
pic::CsgTree to_tree_leaf(py::handle x, size_t k) {
  pic::CsgOperand op = to_operand(x, k);
  return op.tree ? pic::csg_leaf(std::move(*op.tree)) : pic::csg_leaf(std::move(op.mesh));
}
std::vector<pic::CsgTree> to_tree_leaves(py::iterable xs) {
  std::vector<pic::CsgTree> out;
  for (py::handle x : xs) out.push_back(to_tree_leaf(x, out.size()));
  return out;
}

/// A volumetric operation on a PIC object (through its contour) or a mesh, without the GIL.
/// A volume operation on an Octree (through its contour) or a mesh. With `mesh`, also its
/// contour with every point on the operation's exact surface (pic::VolumeMesh): a tuple
/// (Octree, (vertices, faces)).
using VolumeOp = std::function<pic::Octree(const pic::TriMesh&, const pic::SampleOptions&, pic::VolumeMesh*)>;
py::object volume_op(py::handle x, int depth, double error, py::handle cube, bool parallel, bool mesh,
                     const VolumeOp& op) {
  pic::SampleOptions o;
  o.depth = depth;
  o.error = error;
  o.cube = to_cube(cube);
  o.parallel = parallel;
  pic::CsgOperand operand = to_operand(x, 0);
  pic::Octree result;
  pic::VolumeMesh surface;
  {
    py::gil_scoped_release nogil;
    const pic::TriMesh input = operand.tree ? pic::contour(*operand.tree) : std::move(operand.mesh);
    result = op(input, o, mesh ? &surface : nullptr);
  }
  if (!mesh) return py::cast(wrap(std::move(result)));
  return py::make_tuple(wrap(std::move(result)), from_mesh(surface.mesh));
}

/// An implicit solid from a Python function of an (n, 3) array of points returning n values
/// (and optionally their (n, 3) gradients), called on each batch of the sampler's points.
std::unique_ptr<PyOctree> sample_function(py::object f, py::handle cube, int depth, double error, py::object gradient,
                                          double lipschitz) {
  pic::SampleOptions o;
  o.depth = depth;
  o.error = error;
  o.cube = to_cube(cube);
  if (!o.cube) throw py::value_error("sample_function needs a cube (x, y, z, size)");
  o.parallel = false;  // one Python function: calls are serial anyway
  auto as_rows = [](const std::vector<pic::Vec3>& p) {
    py::array_t<double> a({py::ssize_t(p.size()), py::ssize_t{3}});
    auto r = a.mutable_unchecked<2>();
    for (size_t i = 0; i < p.size(); ++i)
      for (int k = 0; k < 3; ++k) r(py::ssize_t(i), k) = p[i][k];
    return a;
  };
  pic::ImplicitSolid s;
  s.lipschitz = lipschitz;
  s.values = [&](const std::vector<pic::Vec3>& p, std::vector<double>& out) {
    py::gil_scoped_acquire gil;
    const py::array_t<double, py::array::c_style | py::array::forcecast> v = f(as_rows(p));
    if (size_t(v.size()) != p.size()) throw pic::InvalidInput("sample_function: f must return one value per point");
    out.assign(v.data(), v.data() + v.size());
  };
  if (!gradient.is_none())
    s.gradients = [&](const std::vector<pic::Vec3>& p, std::vector<pic::Vec3>& out) {
      py::gil_scoped_acquire gil;
      const py::array_t<double, py::array::c_style | py::array::forcecast> g = gradient(as_rows(p));
      if (size_t(g.size()) != 3 * p.size()) throw pic::InvalidInput("sample_function: the gradient must be an (n, 3) array");
      out.resize(p.size());
      for (size_t i = 0; i < p.size(); ++i) out[i] = {g.data()[3 * i], g.data()[3 * i + 1], g.data()[3 * i + 2]};
    };
  pic::SampleStats st;
  pic::Octree tree;
  {
    py::gil_scoped_release nogil;
    tree = pic::sample(s, o, &st);
  }
  return wrap(std::move(tree), sample_stats(st));
}

/// Evaluates an n-ary Boolean (pic::evaluate of a CsgTree) without the GIL.
std::unique_ptr<PyOctree> evaluate_tree(const pic::CsgTree& tree, int depth, double error, bool parallel) {
  pic::CsgChainOptions o;
  o.sampling.depth = depth;
  o.sampling.error = error;
  o.sampling.parallel = parallel;
  o.csg.error = error;
  o.csg.parallel = parallel;
  pic::Octree result;
  {
    py::gil_scoped_release nogil;
    result = pic::evaluate(tree, o);
  }
  return wrap(std::move(result));
}

std::unique_ptr<PyOctree> csg_meshes(py::args args, int depth, double error, bool parallel, py::object cube) {
  if (args.size() < 3 || args.size() % 2 == 0)
    throw py::value_error("csg_meshes(a, op, b [, op, c ...]): operands and operations alternate");
  std::vector<pic::CsgOperand> operands;
  std::vector<pic::CsgOp> ops;
  for (size_t k = 0; k < args.size(); ++k) {
    if (k % 2 == 0) operands.push_back(to_operand(args[k], k / 2));
    else ops.push_back(to_csg_op(args[k].cast<std::string>()));
  }
  pic::CsgChainOptions o;
  o.sampling.depth = depth;
  o.sampling.error = error;
  o.sampling.parallel = parallel;
  o.sampling.cube = to_cube(cube);
  o.csg.error = error;
  o.csg.parallel = parallel;
  py::list steps;
  std::vector<pic::CsgStats> stats(ops.size());
  o.on_step = [&](size_t k, const pic::CsgStats& st) { stats[k - 1] = st; };
  pic::Octree tree;
  {
    py::gil_scoped_release nogil;
    tree = pic::csg_chain(std::move(operands), ops, o);
  }
  for (size_t k = 0; k < ops.size(); ++k) steps.append(csg_stats(stats[k], ops[k], false));
  py::dict d;
  d["op"] = "csg_meshes";
  d["steps"] = steps;
  return wrap(std::move(tree), d);
}

pic::CsgOptions csg_options(double error, bool parallel) {
  pic::CsgOptions o;
  o.error = error;
  o.parallel = parallel;
  return o;
}

std::unique_ptr<PyOctree> eval(bool is_text, const std::string& input, int depth, double error, bool smooth,
                               bool parallel) {
  pic::EvalOptions o;
  o.depth = depth;
  o.error = error;
  o.smooth = smooth;
  o.parallel = parallel;
  pic::EvalStats st;
  pic::Octree tree;
  {
    py::gil_scoped_release nogil;
    tree = is_text ? pic::eval_csg(input, o, &st) : pic::eval_scad(input, o, &st);
  }
  py::dict d;
  d["op"] = "eval";
  add_fields(d, st);
  return wrap(std::move(tree), d);
}

pic::Vec3 to_vec3(const std::array<double, 3>& v) { return {v[0], v[1], v[2]}; }

// Primitives: a closed mesh as (vertices, faces), made without the GIL.
template <class F>
py::tuple primitive(F&& make) {
  pic::TriMesh mesh;
  {
    py::gil_scoped_release nogil;
    mesh = make();
  }
  return from_mesh(mesh);
}

}  // namespace

void bind_functions(py::module_& m) {
  m.attr("MAX_LEVEL") = pic::kMaxLevel;

  m.def("sample", &sample, py::arg("input"), py::arg("faces") = py::none(), py::arg("depth") = 12,
        py::arg("error") = 1e-8, py::arg("cube") = py::none(), py::arg("inside") = "auto", py::arg("parallel") = true,
        py::arg("margin") = 1.0 / 16,
        R"doc(Adaptively samples a solid into a PIC object (pic::sample).

input: an (n, 3) real array of vertices with faces an (m, 3) integer array; or a path to a mesh
(obj, stl, ply, off, gltf, glb) or point cloud (ply with normals, xyz); or a tuple
(points, normals) of two (n, 3) arrays, an oriented point cloud.
depth: maximum octree level (1..MAX_LEVEL). error: QEF residual threshold in root-cube units squared.
cube: root cube (x, y, z, size), default the bounding cube plus `margin` of the extent on each side;
share one cube between CSG operands. inside: 'auto', 'parity' or 'winding'.
parallel: use all cores (same bytes as serial).
Raises ValueError for bad input (empty, open with inside='parity', non-finite, wrong shape),
OSError for an unreadable file. The result's .stats hold the sampling statistics.)doc");
  m.def(
      "sample_points",
      [](py::object points, py::object normals, int depth, double error, py::object cube, bool parallel,
         double margin) {
        const pic::SampleOptions o = sample_options(depth, error, cube, "auto", parallel, margin);
        return sample_cloud(to_cloud(points, normals), o);
      },
      py::arg("points"), py::arg("normals"), py::arg("depth") = 12, py::arg("error") = 1e-8,
      py::arg("cube") = py::none(), py::arg("parallel") = true, py::arg("margin") = 1.0 / 16,
      R"doc(Samples an oriented point cloud (a scan) into a PIC object (pic::sample of a PointCloud).

points, normals: (n, 3) real arrays; normals point out of the solid (any length but zero).
Signs come from the points' winding number; the depth stops where a cell is half the points'
spacing (stats['depth_used']). Raises ValueError for an empty cloud or missing/zero normals.)doc");
  m.def("csg_meshes", &csg_meshes, py::kw_only(), py::arg("depth") = 12, py::arg("error") = 1e-8,
        py::arg("parallel") = true, py::arg("cube") = py::none(),
        R"doc(Booleans of meshes, left to right: csg_meshes(a, 'subtract', b [, 'union', c ...]).

Operands are meshes (pic.Mesh, a (vertices, faces) tuple, anything with .vertices and .faces),
mesh file paths, or Octrees. Mesh operands are sampled at `depth` into one cube around all of
them (or `cube`), so no cube needs choosing by hand (pic::csg_chain, as `pic csg` does).
The result's stats['steps'] hold each Boolean's statistics.)doc");
  m.def(
      "union",
      [](py::iterable xs, int depth, double error, bool parallel) {
        return evaluate_tree(pic::csg_union(to_tree_leaves(xs)), depth, error, parallel);
      },
      py::arg("solids"), py::kw_only(), py::arg("depth") = 12, py::arg("error") = 1e-8, py::arg("parallel") = true,
      R"doc(The union of PIC objects and meshes (pic::evaluate of a CsgTree): combined in a balanced
order, halves in parallel, no result copied per step; three combine as a | (b | c). Meshes are
sampled into one cube around them all at `depth`.)doc");
  m.def(
      "intersection",
      [](py::iterable xs, int depth, double error, bool parallel) {
        return evaluate_tree(pic::csg_intersection(to_tree_leaves(xs)), depth, error, parallel);
      },
      py::arg("solids"), py::kw_only(), py::arg("depth") = 12, py::arg("error") = 1e-8, py::arg("parallel") = true,
      "The intersection of PIC objects and meshes, as union() combines them.");
  m.def(
      "difference",
      [](py::handle a, py::iterable xs, int depth, double error, bool parallel) {
        return evaluate_tree(pic::csg_difference(to_tree_leaf(a, 0), to_tree_leaves(xs)), depth, error, parallel);
      },
      py::arg("a"), py::arg("solids"), py::kw_only(), py::arg("depth") = 12, py::arg("error") = 1e-8,
      py::arg("parallel") = true, "a minus the union of the others: difference(a, [b, c]) = a - (b | c).");
  m.def(
      "offset",
      [](py::handle x, double distance, int depth, double error, py::object cube, bool parallel, bool mesh) {
        return volume_op(x, depth, error, cube, parallel, mesh,
                         [&](const pic::TriMesh& m, const pic::SampleOptions& o, pic::VolumeMesh* vm) {
                           return pic::offset(m, distance, o, nullptr, vm);
                         });
      },
      py::arg("solid"), py::arg("distance"), py::kw_only(), py::arg("depth") = 12, py::arg("error") = 1e-8,
      py::arg("cube") = py::none(), py::arg("parallel") = true, py::arg("mesh") = false,
      R"doc(The solid grown by distance (> 0) or shrunk (< 0): pic::offset. solid: an Octree or a mesh.
mesh=True: returns (Octree, (vertices, faces)), the mesh's points on the exact offset surface.)doc");
  m.def(
      "shell",
      [](py::handle x, double thickness, bool outward, int depth, double error, py::object cube, bool parallel,
         bool mesh) {
        return volume_op(x, depth, error, cube, parallel, mesh,
                         [&](const pic::TriMesh& m, const pic::SampleOptions& o, pic::VolumeMesh* vm) {
                           return pic::shell(m, thickness, outward, o, nullptr, vm);
                         });
      },
      py::arg("solid"), py::arg("thickness"), py::kw_only(), py::arg("outward") = false, py::arg("depth") = 12,
      py::arg("error") = 1e-8, py::arg("cube") = py::none(), py::arg("parallel") = true, py::arg("mesh") = false,
      "The solid hollowed to walls `thickness` thick (outward: a skin around it): pic::shell.");
  m.def(
      "round",
      [](py::handle x, double radius, bool concave, int depth, double error, py::object cube, bool parallel,
         bool mesh) {
        return volume_op(x, depth, error, cube, parallel, mesh,
                         [&](const pic::TriMesh& m, const pic::SampleOptions& o, pic::VolumeMesh* vm) {
                           return pic::round_edges(m, radius, !concave, o, nullptr, vm);
                         });
      },
      py::arg("solid"), py::arg("radius"), py::kw_only(), py::arg("concave") = false, py::arg("depth") = 12,
      py::arg("error") = 1e-8, py::arg("cube") = py::none(), py::arg("parallel") = true, py::arg("mesh") = false,
      "Convex edges rounded to `radius` (concave=True: concave edges filled): pic::round_edges.");
  m.def(
      "minkowski_round",
      [](py::handle x, py::object body, int depth, double error, py::object cube, bool parallel, bool mesh) {
        const std::vector<pic::Vec3> points = to_points(body, "body");
        return volume_op(x, depth, error, cube, parallel, mesh,
                         [&](const pic::TriMesh& m, const pic::SampleOptions& o, pic::VolumeMesh* vm) {
                           return pic::minkowski_round(m, points, o, nullptr, vm);
                         });
      },
      py::arg("solid"), py::arg("body"), py::kw_only(), py::arg("depth") = 12, py::arg("error") = 1e-8,
      py::arg("cube") = py::none(), py::arg("parallel") = true, py::arg("mesh") = false,
      R"doc(The Minkowski sum of a solid with a round convex body given by its (n, 3) vertices (a faceted
sphere): pic::minkowski_round. Faces exact; rounds within the body's facet depth.)doc");
  m.def(
      "thicken",
      [](py::handle x, double thickness, int depth, double error, py::object cube, bool parallel, bool mesh) {
        return volume_op(x, depth, error, cube, parallel, mesh,
                         [&](const pic::TriMesh& m, const pic::SampleOptions& o, pic::VolumeMesh* vm) {
                           return pic::thicken(m, thickness, o, nullptr, vm);
                         });
      },
      py::arg("surface"), py::arg("thickness"), py::kw_only(), py::arg("depth") = 12, py::arg("error") = 1e-8,
      py::arg("cube") = py::none(), py::arg("parallel") = true, py::arg("mesh") = false,
      "The solid within thickness / 2 of a surface, open or closed: pic::thicken.");
  m.def("sample_function", &sample_function, py::arg("f"), py::arg("cube"), py::kw_only(), py::arg("depth") = 8,
        py::arg("error") = 1e-8, py::arg("gradient") = py::none(), py::arg("lipschitz") = 1.0,
        R"doc(Samples the solid f < 0 (pic::sample of an ImplicitSolid).

f: a function of an (n, 3) array of points returning n values, negative inside, with
|f(p) - f(q)| <= lipschitz |p - q| (a signed distance: 1). gradient: optional, (n, 3) -> (n, 3).
cube: (x, y, z, size), required.)doc");
  m.def(
      "bounding_cube",
      [](py::object vertices, double margin) {
        pic::TriMesh mesh;
        mesh.positions = to_points(vertices, "vertices");
        return from_cube(pic::bounding_cube(mesh, margin));
      },
      py::arg("vertices"), py::arg("margin") = 1.0 / 16,
      "The automatic root cube (x, y, z, size) around points: their bounding cube enlarged by margin of the "
      "extent on each side. Sample CSG operands into one cube around all of them.");

  m.def(
      "csg",
      [](const PyOctree& a, const PyOctree& b, const std::string& op, double error, bool parallel) {
        return csg(a, b, to_csg_op(op), csg_options(error, parallel));
      },
      py::arg("a"), py::arg("b"), py::arg("op"), py::arg("error") = 1e-8, py::arg("parallel") = true,
      R"doc(Boolean of two PIC objects on their octrees, as a new object (pic::csg).

op: 'union', 'intersect' ('intersection') or 'subtract' ('difference'). Operands should share a
root cube; otherwise b is resampled into a's cube. The result's .stats hold the operation's
statistics. Raises ValueError for an unknown op or an operand that cannot be resampled.)doc");
  m.def(
      "csg_inplace",
      [](PyOctree& a, const PyOctree& b, const std::string& op, double error, bool parallel) {
        csg_inplace(a, b, to_csg_op(op), csg_options(error, parallel));
      },
      py::arg("a"), py::arg("b"), py::arg("op"), py::arg("error") = 1e-8, py::arg("parallel") = true,
      "a := a op b (pic::csg_inplace, the sculpting path: only the overlap is rebuilt). a.stats become the "
      "operation's statistics.");
  m.def("contour", &contour, py::arg("tree"), py::arg("intersection_free") = true, py::arg("split") = true,
        py::arg("stats") = py::none(), "Same as tree.contour(...): (vertices, faces) of the closed surface.");

  m.def(
      "load",
      [](const fs::path& path) {
        pic::Octree tree;
        {
          py::gil_scoped_release nogil;
          tree = pic::load(path);
        }
        return wrap(std::move(tree));
      },
      py::arg("path"), "Reads a .pic file. Raises OSError for a missing, truncated, corrupted or foreign file.");
  m.def(
      "save", [](const PyOctree& t, const fs::path& path) { without_gil([&] { return pic::save(t.tree, path), 0; }, t); },
      py::arg("tree"), py::arg("path"), "Same as tree.save(path).");
  m.def(
      "deserialize",
      [](const py::bytes& data) {
        const std::string s = data;
        const std::vector<uint8_t> bytes(s.begin(), s.end());
        pic::Octree tree;
        {
          py::gil_scoped_release nogil;
          tree = pic::deserialize(bytes);
        }
        return wrap(std::move(tree));
      },
      py::arg("data"), "A PIC object from .pic bytes (Octree.serialize()). Raises OSError for corrupted bytes.");

  m.def(
      "eval_scad",
      [](const fs::path& path, int depth, double error, bool smooth, bool parallel) {
        return eval(false, path.string(), depth, error, smooth, parallel);
      },
      py::arg("path"), py::arg("depth") = 12, py::arg("error") = 1e-8, py::arg("smooth") = false,
      py::arg("parallel") = true,
      R"doc(Evaluates an OpenSCAD model on octrees (pic::eval_scad): a .scad file through the `openscad`
program, or its .csg export directly. smooth: tessellate curved primitives finely instead of by
$fn/$fa/$fs. Raises ValueError for an unsupported node or a missing `openscad`, OSError for an
unreadable file.)doc");
  m.def(
      "eval_csg",
      [](const std::string& text, int depth, double error, bool smooth, bool parallel) {
        return eval(true, text, depth, error, smooth, parallel);
      },
      py::arg("text"), py::arg("depth") = 12, py::arg("error") = 1e-8, py::arg("smooth") = false,
      py::arg("parallel") = true, "Evaluates OpenSCAD CSG-tree text (the .csg format) on octrees.");

  m.def(
      "read_mesh",
      [](const fs::path& path) {
        pic::TriMesh mesh;
        {
          py::gil_scoped_release nogil;
          mesh = pic::read_mesh(path);
        }
        return from_mesh(mesh);
      },
      py::arg("path"),
      "Reads OBJ, STL, PLY, OFF, glTF/GLB with duplicate vertices welded: (vertices float64 (n, 3), faces "
      "int64 (m, 3)). Raises OSError (missing, unreadable, unknown format) or ValueError (empty, non-finite).");
  m.def(
      "write_mesh",
      [](py::object a, py::object b, py::object c) {
        // write_mesh(mesh, path) or write_mesh(vertices, faces, path).
        const std::optional<pic::TriMesh> one = c.is_none() ? as_mesh(a) : std::nullopt;
        if (c.is_none() && !one) throw py::value_error("write_mesh(mesh, path) or write_mesh(vertices, faces, path)");
        const pic::TriMesh mesh = one ? *one : to_mesh(a, b);
        const fs::path path = to_path(c.is_none() ? b : c);
        py::gil_scoped_release nogil;
        pic::write_mesh(mesh, path);
      },
      py::arg("mesh_or_vertices"), py::arg("faces_or_path"), py::arg("path") = py::none(),
      "write_mesh(mesh, path) or write_mesh(vertices, faces, path): the format from the extension (obj, stl, ply, "
      "off, glb), written atomically. Raises OSError.");
  m.def(
      "volume",
      [](py::object a, py::object faces) {
        const std::optional<pic::TriMesh> one = faces.is_none() ? as_mesh(a) : std::nullopt;
        if (faces.is_none() && !one) throw py::value_error("volume(mesh) or volume(vertices, faces)");
        return pic::volume(one ? *one : to_mesh(a, faces));
      },
      py::arg("mesh_or_vertices"), py::arg("faces") = py::none(),
      "volume(mesh) or volume(vertices, faces): signed volume (positive for outward orientation).");
  m.def(
      "check_validity",
      [](py::object vertices, py::object faces, bool self_intersections) {
        const pic::TriMesh mesh = to_mesh(vertices, faces);
        pic::MeshValidity v;
        {
          py::gil_scoped_release nogil;
          v = pic::check_validity(mesh, self_intersections);
        }
        py::dict d;
        d["valid"] = v.valid();
        d["self_intersections"] = v.checked ? py::object(py::int_(v.self_intersections)) : py::none();
        d["collinear_triangles"] = v.collinear_triangles;
        d["nonmanifold_vertices"] = v.nonmanifold_vertices;
        d["nonmanifold_edges"] = v.nonmanifold_edges;
        d["boundary_edges"] = v.boundary_edges;
        d["degenerate_triangles"] = v.degenerate_triangles;
        d["components"] = v.components;
        return d;
      },
      py::arg("vertices"), py::arg("faces"), py::arg("self_intersections") = true,
      "Validity of a mesh as a solid's boundary (pic::check_validity), equal positions merged: a dict with "
      "'valid' and the counts.");

  m.def(
      "make_box", [](std::array<double, 3> lo, std::array<double, 3> hi) {
        return primitive([&] { return pic::make_box(to_vec3(lo), to_vec3(hi)); });
      },
      py::arg("lo"), py::arg("hi"), "Closed mesh of the axis-aligned box [lo, hi]: (vertices, faces).");
  m.def(
      "make_sphere",
      [](std::array<double, 3> c, double r, int segments) {
        return primitive([&] { return pic::make_sphere(to_vec3(c), r, segments); });
      },
      py::arg("center"), py::arg("radius"), py::arg("segments") = 64, "Closed UV sphere mesh: (vertices, faces).");
  m.def(
      "make_cylinder",
      [](std::array<double, 3> c, double r, double h, int axis, int segments) {
        return primitive([&] { return pic::make_cylinder(to_vec3(c), r, h, axis, segments); });
      },
      py::arg("center"), py::arg("radius"), py::arg("height"), py::arg("axis") = 2, py::arg("segments") = 64,
      "Closed cylinder mesh along axis 0, 1 or 2, centred at center, total height height: (vertices, faces).");
  m.def(
      "make_cone",
      [](std::array<double, 3> c, double r, double h, int axis, int segments) {
        return primitive([&] { return pic::make_cone(to_vec3(c), r, h, axis, segments); });
      },
      py::arg("center"), py::arg("radius"), py::arg("height"), py::arg("axis") = 2, py::arg("segments") = 64,
      "Closed cone mesh: base disk at center - height/2, apex at center + height/2: (vertices, faces).");
  m.def(
      "make_torus",
      [](std::array<double, 3> c, double major, double minor, int axis, int segments, int tube_segments) {
        return primitive([&] { return pic::make_torus(to_vec3(c), major, minor, axis, segments, tube_segments); });
      },
      py::arg("center"), py::arg("major"), py::arg("minor"), py::arg("axis") = 2, py::arg("segments") = 64,
      py::arg("tube_segments") = 32, "Closed torus mesh around axis: (vertices, faces).");

  m.def(
      "render",
      [](py::object obj, std::array<int, 2> size, bool octree, bool points, const std::string& view,
         std::optional<std::array<double, 9>> camera, bool perspective, int supersample) {
        pic::RenderOptions o;
        o.width = size[0];
        o.height = size[1];
        o.octree = octree;
        o.points = points;
        o.view = view;
        o.camera = camera;
        o.perspective = perspective;
        o.supersample = supersample;
        pic::Image img;
        if (py::isinstance<PyOctree>(obj)) {
          const PyOctree& t = obj.cast<const PyOctree&>();
          img = without_gil([&] { return pic::render(pic::unsplit_contour(t.tree), &t.tree, o); }, t);
        } else {
          if (octree) throw py::value_error("render: octree=True needs a pic.Octree");
          if (!py::isinstance<py::tuple>(obj) || py::len(obj) != 2)
            throw py::value_error("render: obj must be a pic.Octree or a mesh (vertices, faces)");
          const auto t = obj.cast<py::tuple>();
          const pic::TriMesh mesh = to_mesh(t[0], t[1]);
          py::gil_scoped_release nogil;
          img = pic::render(mesh, nullptr, o);
        }
        return from_image(img);
      },
      py::arg("obj"), py::arg("size") = std::array<int, 2>{640, 480}, py::arg("octree") = false,
      py::arg("points") = false, py::arg("view") = "iso", py::arg("camera") = py::none(),
      py::arg("perspective") = false, py::arg("supersample") = 2,
      R"doc(Renders a pic.Octree (its contour) or a mesh (vertices, faces) to an (h, w, 3) uint8 array.

size: (width, height). octree: draw the gray leaves' cells; points: the representative vertices
(a mesh's vertices). view: iso, front, back, left, right, top, bottom (+Z up); camera: eye xyz,
target xyz, up xyz. Raises ValueError for a bad size, view or camera.)doc");
  m.def(
      "write_png",
      [](py::object image, const fs::path& path) {
        const pic::Image img = to_image(image);
        py::gil_scoped_release nogil;
        pic::write_png(img, path);
      },
      py::arg("image"), py::arg("path"), "Writes an (h, w, 3) uint8 array as a PNG, atomically. Raises OSError.");
}

}  // namespace pic_python

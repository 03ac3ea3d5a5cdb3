#include "octree.h"

#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <chrono>
#include <cstdio>

#include "convert.h"

namespace pic_python {

namespace {

using Clock = std::chrono::steady_clock;

py::list vec_list(const pic::Vec3& v) { return py::cast(std::vector<double>(v.begin(), v.end())); }


// The same keys and values as `pic info --json` (apps/pic/main.cpp), file_bytes being the
// size of the .pic bytes.
struct Info {
  pic::OctreeStats stats;
  size_t file_bytes = 0;
  pic::MeshTopology topology;
  pic::MeshValidity validity;
};

py::dict info_dict(const pic::Octree& tree, const Info& in) {
  const auto& s = in.stats;
  py::dict d;
  d["pics"] = s.pics;
  d["nodes"] = s.nodes;
  d["depth"] = tree.max_depth;
  d["capped"] = s.capped;
  d["file_bytes"] = in.file_bytes;
  d["bytes_per_pic"] = s.pics ? double(in.file_bytes) / double(s.pics) : 0.0;
  d["memory_bytes"] = s.memory_bytes;
  py::dict cube, bbox;
  cube["origin"] = vec_list(tree.cube.origin);
  cube["size"] = tree.cube.size;
  bbox["min"] = vec_list(s.bbox_min);
  bbox["max"] = vec_list(s.bbox_max);
  d["cube"] = cube;
  d["bbox"] = bbox;
  py::list levels;
  for (size_t l = 0; l < s.levels.size(); ++l) {
    py::dict v;
    v["level"] = l;
    v["white"] = s.levels[l].white;
    v["black"] = s.levels[l].black;
    v["gray"] = s.levels[l].gray;
    v["internal"] = s.levels[l].internal;
    levels.append(v);
  }
  d["levels"] = levels;
  const auto& t = in.topology;
  py::dict topo;
  topo["closed"] = t.closed();
  topo["manifold"] = t.manifold();
  topo["boundary_edges"] = t.boundary_edges;
  topo["nonmanifold_edges"] = t.nonmanifold_edges;
  topo["nonmanifold_vertices"] = t.nonmanifold_vertices;
  d["contour"] = topo;
  const auto& v = in.validity;
  d["self_intersections"] = v.checked ? py::object(py::int_(v.self_intersections)) : py::none();
  d["nonmanifold_vertices"] = v.nonmanifold_vertices;
  d["nonmanifold_edges"] = v.nonmanifold_edges;
  d["components"] = v.components;
  return d;
}

std::string repr(const PyOctree& t) {
  const auto& c = t.tree.cube;
  char buf[200];
  std::snprintf(buf, sizeof buf, "<pic.Octree: %zu PICs, depth %d, cube (%g, %g, %g, %g)>", pic::analyze(t.tree).pics,
                t.tree.max_depth, c.origin[0], c.origin[1], c.origin[2], c.size);
  return buf;
}

std::unique_ptr<PyOctree> copy_of(const PyOctree& t) {
  auto r = std::make_unique<PyOctree>();
  r->tree = without_gil([&] { return t.tree; }, t);
  r->stats = py::dict(t.stats);
  return r;
}

}  // namespace

py::dict csg_stats(const pic::CsgStats& st, pic::CsgOp op, bool inplace) {
  py::dict d;
  d["op"] = pic::to_string(op);
  d["inplace"] = inplace;
  add_fields(d, st);
  return d;
}

std::unique_ptr<PyOctree> wrap(pic::Octree tree, py::dict stats) {
  auto r = std::make_unique<PyOctree>();
  r->tree = std::move(tree);
  r->stats = std::move(stats);
  return r;
}

pic::CsgOp to_csg_op(const std::string& op) {
  const auto o = pic::parse_csg_op(op);
  if (!o) throw py::value_error("unknown operation '" + op + "' (union, intersect, subtract)");
  return *o;
}

std::unique_ptr<PyOctree> csg(const PyOctree& a, const PyOctree& b, pic::CsgOp op, const pic::CsgOptions& options) {
  pic::CsgStats st;
  pic::Octree r = without_gil([&] { return pic::csg(a.tree, b.tree, op, options, &st); }, a, b);
  return wrap(std::move(r), csg_stats(st, op, false));
}

void csg_inplace(PyOctree& a, const PyOctree& b, pic::CsgOp op, const pic::CsgOptions& options) {
  pic::CsgStats st;
  without_gil(
      [&] {
        if (&a == &b) {  // a -= a: the library's operands must not alias
          const pic::Octree copy = b.tree;
          pic::csg_inplace(a.tree, copy, op, options, &st);
        } else {
          pic::csg_inplace(a.tree, b.tree, op, options, &st);
        }
        return 0;
      },
      a, b);
  a.stats = csg_stats(st, op, true);
}

py::tuple contour(const PyOctree& t, bool intersection_free, bool split, py::object stats) {
  pic::ContourOptions o;
  o.intersection_free = intersection_free;
  o.split_sheets = split;
  pic::ContourStats st;
  double seconds = 0;
  const pic::TriMesh mesh = without_gil(
      [&] {
        const auto t0 = Clock::now();
        pic::TriMesh m = pic::contour(t.tree, o, &st);
        seconds = std::chrono::duration<double>(Clock::now() - t0).count();
        return m;
      },
      t);
  if (!stats.is_none()) {
    stats["seconds"] = seconds;
    stats["vertices"] = mesh.positions.size();
    stats["triangles"] = mesh.triangles.size();
    py::dict d = stats.cast<py::dict>();
    add_fields(d, st);
  }
  return from_mesh(mesh);
}

py::dict sample_stats(const pic::SampleStats& st) {
  py::dict d;
  d["op"] = "sample";
  add_fields(d, st);
  return d;
}

void bind_octree(py::module_& m) {
  py::class_<PyOctree> c(m, "Octree", R"doc(A PIC object: an adaptive octree whose gray leaves each hold one
representative vertex and the in/out signs of the cell's corners.

Made by pic.sample, pic.load, pic.deserialize, pic.eval_scad or CSG. Operators: a | b (union),
a & b (intersect), a - b (subtract) return new objects; a |= b, a &= b, a -= b edit a in place
(the library's sculpting path: only the overlap is rebuilt). Pickles through its .pic bytes.)doc");
  c.attr("__module__") = "pic";

  c.def_property_readonly(
      "pics", [](const PyOctree& t) { return without_gil([&] { return pic::analyze(t.tree).pics; }, t); },
      "Number of PICs (gray leaves, one representative vertex each).");
  c.def_property_readonly(
      "nodes", [](const PyOctree& t) { return t.tree.nodes.size(); }, "Number of octree nodes.");
  c.def_property_readonly(
      "depth", [](const PyOctree& t) { return t.tree.max_depth; }, "Maximum octree level.");
  c.def_property_readonly(
      "cube", [](const PyOctree& t) { return from_cube(t.tree.cube); },
      "Root cube (x, y, z, size): minimum corner and side, in the input's coordinates.");
  c.def_property_readonly(
      "stats", [](const PyOctree& t) { return t.stats; },
      "Statistics (dict) of the operation that made or last changed this object: sample, csg, eval; "
      "empty after load.");

  c.def(
      "contour",
      [](const PyOctree& t, bool intersection_free, bool split, py::object stats) {
        return contour(t, intersection_free, split, std::move(stats));
      },
      py::arg("intersection_free") = true, py::arg("split") = true, py::arg("stats") = py::none(),
      R"doc(The closed surface by dual contouring: (vertices float64 (n, 3), faces int64 (m, 3)).

intersection_free: triangulate so that no two triangles can cross, by construction (False: the plain split, `pic mesh --plain`).
split: give touching sheets their own vertex copies (pic::split_nonmanifold), as `pic mesh` writes.
stats: a dict to fill with the contour's counts and seconds.)doc");
  c.def(
      "info",
      [](const PyOctree& t, bool check) {
        Info in;
        without_gil(
            [&] {
              in.stats = pic::analyze(t.tree);
              in.file_bytes = pic::serialize(t.tree).size();
              const pic::TriMesh mesh = pic::unsplit_contour(t.tree);
              in.topology = pic::analyze_topology(mesh);
              in.validity = pic::check_validity(mesh, check);
              return 0;
            },
            t);
        return info_dict(t.tree, in);
      },
      py::arg("check") = true,
      R"doc(Cells per level, PIC count, bytes, bounding box and the contour's validity: the dict that
`pic info --json` prints. check=False skips the exact self-intersection test (then
"self_intersections" is None), as --no-check.)doc");
  c.def(
      "save",
      [](const PyOctree& t, const std::filesystem::path& path) {
        without_gil([&] { return pic::save(t.tree, path), 0; }, t);
      },
      py::arg("path"), "Writes the .pic file atomically. Raises OSError.");
  c.def(
      "serialize",
      [](const PyOctree& t) {
        const auto bytes = without_gil([&] { return pic::serialize(t.tree); }, t);
        return py::bytes(reinterpret_cast<const char*>(bytes.data()), bytes.size());
      },
      "The .pic file's bytes.");
  c.def("copy", &copy_of, "An independent copy.");
  c.def("__copy__", &copy_of);
  c.def("__deepcopy__", [](const PyOctree& t, py::object) { return copy_of(t); }, py::arg("memo"));
  c.def("__repr__", &repr);
  c.def(py::pickle(
      [](const PyOctree& t) {
        const auto bytes = without_gil([&] { return pic::serialize(t.tree); }, t);
        return py::make_tuple(py::bytes(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
      },
      [](const py::tuple& state) {
        if (state.size() != 1) throw py::value_error("pic.Octree: bad pickle state");
        const std::string s = state[0].cast<std::string>();
        const std::vector<uint8_t> bytes(s.begin(), s.end());
        pic::Octree tree;
        {
          py::gil_scoped_release nogil;
          tree = pic::deserialize(bytes);
        }
        return wrap(std::move(tree));
      }));

  const pic::CsgOptions defaults;
  const std::pair<const char*, pic::CsgOp> ops[] = {
      {"or", pic::CsgOp::Union}, {"and", pic::CsgOp::Intersect}, {"sub", pic::CsgOp::Subtract}};
  for (const auto& [name, op] : ops) {
    const pic::CsgOp o = op;
    c.def(("__" + std::string(name) + "__").c_str(),
          [o, defaults](const PyOctree& a, const PyOctree& b) { return csg(a, b, o, defaults); }, py::is_operator());
    c.def(("__i" + std::string(name) + "__").c_str(),
          [o, defaults](py::object self, const PyOctree& b) {
            csg_inplace(self.cast<PyOctree&>(), b, o, defaults);
            return self;
          },
          py::is_operator());
  }
}

}  // namespace pic_python

#include "convert.h"

#include <cstring>
#include <string>

namespace pic_python {

namespace {

std::string shape_of(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t k = 0; k < a.ndim(); ++k) s += (k ? ", " : "") + std::to_string(a.shape(k));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

// np.asarray(obj), then the checks every (n, 3) input shares. `kinds`: accepted dtype kinds.
py::array as_n_by_3(py::handle obj, const char* what, const char* kinds, const char* kind_words) {
  if (obj.is_none()) throw py::value_error(std::string(what) + " is missing");
  py::array a = py::array::ensure(obj);
  if (!a) throw py::value_error(std::string(what) + " must be an (n, 3) array of " + kind_words);
  if (a.ndim() != 2 || a.shape(1) != 3)
    throw py::value_error(std::string(what) + " must be an (n, 3) array, got shape " + shape_of(a));
  const char kind = a.dtype().kind();
  if (!std::strchr(kinds, kind))
    throw py::value_error(std::string(what) + " must be an (n, 3) array of " + kind_words + ", got dtype " +
                          std::string(py::str(a.dtype())));
  return a;
}

}  // namespace

std::vector<pic::Vec3> to_points(py::handle obj, const char* what) {
  const py::array a = as_n_by_3(obj, what, "fiu", "real numbers");
  const auto d = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
  if (!d) throw py::error_already_set();
  std::vector<pic::Vec3> out(static_cast<size_t>(d.shape(0)));
  if (!out.empty()) std::memcpy(out.data(), d.data(), out.size() * sizeof(pic::Vec3));
  return out;
}

pic::TriMesh to_mesh(py::handle vertices, py::handle faces) {
  pic::TriMesh mesh;
  mesh.positions = to_points(vertices, "vertices");
  const py::array f = as_n_by_3(faces, "faces", "iu", "integers");
  const auto d = py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(f);
  if (!d) throw py::error_already_set();
  const auto n = static_cast<int64_t>(mesh.positions.size());
  const int64_t* p = d.data();
  mesh.triangles.resize(static_cast<size_t>(d.shape(0)));
  for (size_t t = 0; t < mesh.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int64_t v = p[3 * t + k];
      // Checked here, not in the library: a negative index would wrap around in uint32_t.
      if (v < 0 || v >= n)
        throw py::value_error("faces[" + std::to_string(t) + "] has vertex index " + std::to_string(v) +
                              ", outside 0.." + std::to_string(n - 1));
      mesh.triangles[t][k] = static_cast<uint32_t>(v);
    }
  return mesh;
}

pic::PointCloud to_cloud(py::handle points, py::handle normals) {
  pic::PointCloud cloud;
  cloud.positions = to_points(points, "points");
  cloud.normals = to_points(normals, "normals");
  if (cloud.normals.size() != cloud.positions.size())
    throw py::value_error("points and normals differ in length (" + std::to_string(cloud.positions.size()) +
                          " and " + std::to_string(cloud.normals.size()) + ")");
  return cloud;
}

py::tuple from_mesh(const pic::TriMesh& mesh) {
  const auto nv = static_cast<py::ssize_t>(mesh.positions.size());
  const auto nt = static_cast<py::ssize_t>(mesh.triangles.size());
  py::array_t<double> v({nv, py::ssize_t{3}});
  py::array_t<int64_t> f({nt, py::ssize_t{3}});
  if (nv) std::memcpy(v.mutable_data(), mesh.positions.data(), mesh.positions.size() * sizeof(pic::Vec3));
  int64_t* fp = f.mutable_data();
  for (const auto& t : mesh.triangles)
    for (uint32_t i : t) *fp++ = i;
  // pic.Mesh: a (vertices, faces) named tuple, so `v, f = ...` and `m.vertices` both work.
  return py::module_::import("pic").attr("Mesh")(v, f);
}

std::optional<pic::TriMesh> as_mesh(py::handle obj) {
  if (py::hasattr(obj, "vertices") && py::hasattr(obj, "faces")) return to_mesh(obj.attr("vertices"), obj.attr("faces"));
  if (!py::isinstance<py::tuple>(obj) || py::len(obj) != 2) return std::nullopt;
  const auto t = obj.cast<py::tuple>();
  const py::array second = py::array::ensure(t[1]);
  if (!second || (second.dtype().kind() != 'i' && second.dtype().kind() != 'u')) return std::nullopt;
  return to_mesh(t[0], t[1]);
}

std::optional<pic::Cube> to_cube(py::handle obj) {
  if (obj.is_none()) return std::nullopt;
  std::vector<double> v;
  try {
    for (py::handle x : obj) v.push_back(x.cast<double>());
  } catch (const py::error_already_set&) {
    throw py::value_error("cube must be (x, y, z, size): the minimum corner and the side");
  } catch (const py::cast_error&) {
    throw py::value_error("cube must be (x, y, z, size): the minimum corner and the side");
  }
  if (v.size() != 4) throw py::value_error("cube must be (x, y, z, size): the minimum corner and the side");
  return pic::Cube{{v[0], v[1], v[2]}, v[3]};
}

py::tuple from_cube(const pic::Cube& c) { return py::make_tuple(c.origin[0], c.origin[1], c.origin[2], c.size); }

py::array_t<uint8_t> from_image(const pic::Image& img) {
  py::array_t<uint8_t> a({py::ssize_t{img.height}, py::ssize_t{img.width}, py::ssize_t{3}});
  if (!img.rgb.empty()) std::memcpy(a.mutable_data(), img.rgb.data(), img.rgb.size());
  return a;
}

pic::Image to_image(py::handle obj) {
  py::array a = py::array::ensure(obj);
  if (!a || a.ndim() != 3 || a.shape(2) != 3 || a.dtype().kind() != 'u' || a.itemsize() != 1)
    throw py::value_error("image must be an (h, w, 3) uint8 array" + (a ? ", got shape " + shape_of(a) + " dtype " +
                                                                              std::string(py::str(a.dtype()))
                                                                        : std::string()));
  const auto d = py::array_t<uint8_t, py::array::c_style | py::array::forcecast>::ensure(a);
  pic::Image img;
  img.height = static_cast<int>(d.shape(0));
  img.width = static_cast<int>(d.shape(1));
  img.rgb.assign(d.data(), d.data() + d.size());
  return img;
}

}  // namespace pic_python

// numpy arrays <-> the library's plain data (TriMesh, PointCloud, Cube, Image). Copies only:
// the library keeps its own vectors, so an array may change or die after the call.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <optional>

#include "pic/pic.h"
#include "pic/render.h"

namespace pic_python {

namespace py = pybind11;

/// An (n, 3) array of real numbers (float32, float64, integers) as points.
/// \throws py::value_error naming `what` for another shape or dtype.
std::vector<pic::Vec3> to_points(py::handle array, const char* what);
/// `vertices` (n, 3) real and `faces` (m, 3) integer with indices in [0, n).
pic::TriMesh to_mesh(py::handle vertices, py::handle faces);
/// A mesh given as one object: anything with .vertices and .faces (pic.Mesh, trimesh.Trimesh),
/// or a (vertices, faces) tuple whose faces are integers. Nothing for anything else.
std::optional<pic::TriMesh> as_mesh(py::handle obj);
/// `points` and `normals`, both (n, 3) real.
pic::PointCloud to_cloud(py::handle points, py::handle normals);

/// pic.Mesh(vertices float64 (n, 3), faces int64 (m, 3)), a named tuple.
py::tuple from_mesh(const pic::TriMesh& mesh);

/// None, or (x, y, z, size) as the CLI's --cube X,Y,Z,SIZE: the minimum corner and the side.
std::optional<pic::Cube> to_cube(py::handle cube);
py::tuple from_cube(const pic::Cube& cube);

/// (height, width, 3) uint8, top row first.
py::array_t<uint8_t> from_image(const pic::Image& image);
/// An (h, w, 3) uint8 array as an Image.
pic::Image to_image(py::handle array);

}  // namespace pic_python

// The Python `pic.Octree`: a pic::Octree plus the statistics of the operation that made or last
// changed it. Long calls run without the GIL; each object's mutex then keeps a second Python
// thread from editing it in the meantime.
#pragma once

#include <pybind11/pybind11.h>

#include <memory>
#include <mutex>
#include <utility>

#include "pic/fields.h"
#include "pic/pic.h"

namespace pic_python {

namespace py = pybind11;

struct PyOctree {
  pic::Octree tree;
  py::dict stats;
  mutable std::mutex mutex;
};

/// Runs `f` without the GIL, holding the mutexes of `trees` (each once).
template <class F>
auto without_gil(F&& f, const PyOctree& a) {
  py::gil_scoped_release nogil;
  std::lock_guard lock(a.mutex);
  return f();
}
template <class F>
auto without_gil(F&& f, const PyOctree& a, const PyOctree& b) {
  py::gil_scoped_release nogil;
  if (&a == &b) {
    std::lock_guard lock(a.mutex);
    return f();
  }
  std::scoped_lock lock(a.mutex, b.mutex);
  return f();
}

/// A new Python object owning `tree`, with `stats`.
std::unique_ptr<PyOctree> wrap(pic::Octree tree, py::dict stats = {});

pic::CsgOp to_csg_op(const std::string& op);
/// A op B as a new object; its `stats` are the operation's.
std::unique_ptr<PyOctree> csg(const PyOctree& a, const PyOctree& b, pic::CsgOp op, const pic::CsgOptions& options);
/// A := A op B (pic::csg_inplace, the sculpting path); A's `stats` become the operation's.
void csg_inplace(PyOctree& a, const PyOctree& b, pic::CsgOp op, const pic::CsgOptions& options);
/// (vertices, faces) of the surface; fills `stats` (a dict, or None) with the contour's counts.
py::tuple contour(const PyOctree& t, bool intersection_free, bool split, py::object stats);

py::dict sample_stats(const pic::SampleStats& st);
py::dict csg_stats(const pic::CsgStats& st, pic::CsgOp op, bool inplace);

/// Adds a stats struct's fields (pic/fields.h) to `d`; nested structs become nested dicts.
template <class S>
void add_fields(py::dict& d, const S& stats) {
  pic::for_each_field(stats, [&](const char* name, const auto& value) {
    if constexpr (pic::HasFields<std::decay_t<decltype(value)>>) {
      py::dict sub;
      add_fields(sub, value);
      d[name] = sub;
    } else {
      d[name] = value;
    }
  });
}

void bind_octree(py::module_& m);

}  // namespace pic_python

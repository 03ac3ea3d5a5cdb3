// `import pic`: the library's sample, CSG, contour, render and I/O over numpy arrays.
// Thin: arguments are converted (convert.cpp), the library is called without the GIL, and its
// exceptions become ValueError (pic::InvalidInput) and OSError (pic::IoError).
#include <pybind11/pybind11.h>

#include "octree.h"

namespace pic_python {
void bind_functions(py::module_& m);
}

PYBIND11_MODULE(_pic, m) {
  namespace py = pybind11;
  m.doc() = "PIC: solids as points with implicit connectivity (adaptive octrees, dual contouring, CSG).";
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const pic::IoError& e) {
      PyErr_SetString(PyExc_OSError, e.what());
    } catch (const pic::InvalidInput& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });
  pic_python::bind_octree(m);
  pic_python::bind_functions(m);
}

// The compiled module dcg._core. Only the module definition lives here; each group of bindings
// has its own file. The Python package bindings/dcg wraps it (validation, Skeleton, CLI).
#include "common.h"

#include "dcg/errors.h"

namespace dcg_py {
void bind_weights(py::module_& m);  // bind_weights.cpp
}  // namespace dcg_py

PYBIND11_MODULE(_core, m) {
  m.doc() = "DCG skeleton engine (C++). Use the dcg package, not this module directly.";
  namespace py = pybind11;
  static py::exception<dcg::Cancelled> cancelled(m, "Cancelled", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const dcg::Cancelled& e) {
      cancelled(e.what());
    } catch (const dcg::InputError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const dcg::IoError& e) {
      PyErr_SetString(PyExc_OSError, e.what());
    }
  });
  dcg_py::bind_io(m);
  dcg_py::bind_pipeline(m);
  dcg_py::bind_weights(m);
}

// The compiled module dcg._core. Only the module definition lives here; each group of bindings
// has its own file. The Python package bindings/dcg wraps it (validation, Skeleton, CLI).
#include "common.h"

#include <cstring>
#include <memory>

#include <tbb/global_control.h>

#include "dcg/errors.h"

namespace {
// Messages quote file names and file content, which need not be UTF-8: decode with
// replacement characters (PyErr_SetString would fail and leave an empty ValueError).
void set_error(PyObject* type, const char* message) {
  PyObject* text =
      PyUnicode_DecodeUTF8(message, static_cast<Py_ssize_t>(std::strlen(message)), "replace");
  if (!text) return;  // the decoding error stays set
  PyErr_SetObject(type, text);
  Py_DECREF(text);
}
}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "DCG skeleton engine (C++). Use the dcg package, not this module directly.";
  namespace py = pybind11;
  static py::exception<dcg::Cancelled> cancelled(m, "Cancelled", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const dcg::Cancelled& e) {
      set_error(cancelled.ptr(), e.what());  // not cancelled(...): deprecated in pybind11 2.12
    } catch (const dcg::InputError& e) {
      set_error(PyExc_ValueError, e.what());
    } catch (const dcg::IoError& e) {
      set_error(PyExc_OSError, e.what());
    }
  });
  dcg_py::bind_io(m);
  // The pybind11 this module was built with: before 2.12 its numpy support calls C functions
  // that numpy 2 no longer has (a crash at the first array), so the package checks it on import.
  m.attr("pybind11_version") = py::make_tuple(PYBIND11_VERSION_MAJOR, PYBIND11_VERSION_MINOR);
  dcg_py::bind_options(m);
  dcg_py::bind_results(m);
  dcg_py::bind_pipeline(m);
  dcg_py::bind_weights(m);
  m.def(
      "limit_threads",
      [](int count) {
        // One limit per process, replaced by the next call; 0 lifts it (TBB's default: every
        // core). The engine's parallel loops then use at most `count` threads.
        static std::unique_ptr<tbb::global_control> limit;
        limit.reset();
        if (count > 0) {
          limit = std::make_unique<tbb::global_control>(
              tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(count));
        }
        return static_cast<int>(
            tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
      },
      pybind11::arg("count"));
}

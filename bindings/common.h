// Shared helpers of the binding files: array conversions and the progress bridge.
#pragma once

#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <optional>
#include <string>

#include "dcg/errors.h"
#include "dcg/options.h"
#include "dcg/progress.h"
#include "dcg/types.h"

namespace dcg_py {

namespace py = pybind11;

/// Faces as they cross from numpy (int64) before the range check.
using Faces64 = Eigen::Matrix<std::int64_t, Eigen::Dynamic, 3, Eigen::RowMajor>;
using Edges64 = Eigen::Matrix<std::int64_t, Eigen::Dynamic, 2, Eigen::RowMajor>;

/// int64 faces -> the engine's int faces; InputError (ValueError) naming the first face with an
/// index outside [0, vertex_count).
dcg::Faces to_faces(const Faces64& F, Eigen::Index vertex_count);
Faces64 to_faces64(const dcg::Faces& F);

/// An engine index array (int) as numpy int64: the type every index array of the Python API has.
template <typename Derived>
auto to_int64(const Eigen::MatrixBase<Derived>& a) {
  return a.template cast<std::int64_t>().eval();
}

/// A dict of options (public names, dcg/options.h) -> dcg::Options, defaults for the rest;
/// InputError (ValueError) for an unknown name or a value out of range.
dcg::Options options_from_dict(const py::dict& values);
/// Every option of `options` by its public name.
py::dict options_to_dict(const dcg::Options& options);

/// A numeric option's value; InputError (ValueError) "option NAME must be a number, got ..."
/// for anything Python cannot turn into a float.
double option_number(const std::string& name, const py::handle& value);

/// Wraps an optional Python callable(stage, fraction) -> bool|None as a ProgressCallback. The
/// engine runs with the GIL released; the wrapper takes it back for each call. An exception in
/// the callable cancels the run and is re-raised by rethrow_if_failed().
class ProgressBridge {
 public:
  explicit ProgressBridge(py::object callable) : callable_(std::move(callable)) {}
  dcg::ProgressCallback callback();
  /// Re-raises the exception the callable raised, if any (call with the GIL held).
  void rethrow_if_failed();

 private:
  py::object callable_;
  std::optional<py::error_already_set> error_;  // what the callable raised
};

/// Runs `compute()` with the GIL released; a Python exception the progress callable of `bridge`
/// raised (which cancelled the run) is re-raised as itself.
template <typename Compute>
auto run_released(ProgressBridge& bridge, Compute compute) -> decltype(compute()) {
  try {
    py::gil_scoped_release release;
    return compute();
  } catch (const dcg::Cancelled&) {
    bridge.rethrow_if_failed();
    throw;
  }
}

void bind_io(py::module_& m);
void bind_options(py::module_& m);
void bind_weights(py::module_& m);
void bind_pipeline(py::module_& m);
void bind_results(py::module_& m);

}  // namespace dcg_py

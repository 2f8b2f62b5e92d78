#include "common.h"

#include "dcg/errors.h"
#include "dcg/io.h"

namespace dcg_py {

dcg::Faces to_faces(const Faces64& F, Eigen::Index vertex_count) {
  dcg::Faces out(F.rows(), 3);
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    for (int c = 0; c < 3; ++c) {
      const std::int64_t index = F(f, c);
      if (index < 0 || index >= vertex_count) {
        throw dcg::InputError("face " + std::to_string(f) + " has vertex index " +
                              std::to_string(index) + ", outside [0, " +
                              std::to_string(vertex_count) + ")");
      }
      out(f, c) = static_cast<int>(index);
    }
  }
  return out;
}

Faces64 to_faces64(const dcg::Faces& F) { return F.cast<std::int64_t>(); }

double option_number(const std::string& name, const py::handle& value) {
  try {
    return value.cast<double>();
  } catch (const py::cast_error&) {
    throw dcg::InputError("option " + name + " must be a number, got " +
                          std::string(py::str(py::repr(value))));
  }
}

dcg::ProgressCallback ProgressBridge::callback() {
  if (callable_.is_none()) return {};
  return [this](const std::string& stage, double fraction) {
    py::gil_scoped_acquire gil;
    if (error_) return false;
    try {
      py::object result = callable_(stage, fraction);
      return result.is_none() || py::bool_(result);
    } catch (py::error_already_set& e) {
      error_.emplace(std::move(e));
      return false;
    }
  };
}

void ProgressBridge::rethrow_if_failed() {
  if (error_) {
    py::error_already_set error = std::move(*error_);
    error_.reset();
    throw error;
  }
}

void bind_io(py::module_& m) {
  m.def(
      "load_mesh",
      [](const std::string& path) {
        dcg::Mesh mesh;
        {
          py::gil_scoped_release release;
          mesh = dcg::read_mesh(path);
        }
        return py::make_tuple(mesh.V, to_faces64(mesh.F));
      },
      py::arg("path"), "Reads an OBJ, OFF, PLY or STL file: (V float64 #V x 3, F int64 #F x 3).");
}

}  // namespace dcg_py

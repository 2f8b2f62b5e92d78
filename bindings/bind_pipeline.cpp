#include "result_class.h"

#include <functional>

#include "dcg/errors.h"
#include "dcg/pipeline.h"
#include "dcg/prepare.h"

namespace dcg_py {
namespace {

/// The stepwise extractor as seen from Python: each method runs its stage (and those before it)
/// with the GIL released and returns the kept result itself (bind_results.cpp), which keeps the
/// extractor alive.
class PyExtractor {
 public:
  PyExtractor(const dcg::Vertices& V, const Faces64& F, const py::dict& options,
              py::object progress)
      : bridge_(std::move(progress)),
        extractor_(V, to_faces(F, V.rows()), options_from_dict(options), bridge_.callback()) {}

  /// A stage (a method of dcg::Extractor, or a callable taking one) with the GIL released.
  template <typename Stage>
  decltype(auto) run(Stage stage) {
    return run_released(bridge_,
                        [&]() -> decltype(auto) { return std::invoke(stage, extractor_); });
  }

  const dcg::PreparedMesh& prepare() { return run(&dcg::Extractor::prepare); }
  const dcg::Balls& voronoi_balls() { return run(&dcg::Extractor::voronoi_balls); }
  const dcg::DomainBalls& domain_balls() { return run(&dcg::Extractor::domain_balls); }
  /// At the extractor's tau with the features they come from, or re-thresholded at `tau`.
  ProngsView prongs(py::object tau) {
    if (tau.is_none()) {
      const dcg::ProngFeatures& pf = run(&dcg::Extractor::prongs);
      return ProngsView{pf.prongs, &pf};
    }
    const double t = tau.cast<double>();
    return ProngsView{run([t](dcg::Extractor& e) { return e.prongs_at(t); }), nullptr};
  }
  // The stages a retune drops (end points, graph, remap, skeleton) cross as copies: a Python
  // object holding one of them must outlive the next retune, which frees the extractor's own.
  dcg::EndPoints end_points() { return run(&dcg::Extractor::end_points); }
  /// Stage 4 at `points` (#P x 3, normalized units), or at the domain points when None.
  static py::object force_field(py::object self, py::object points) {
    PyExtractor& x = self.cast<PyExtractor&>();
    if (points.is_none()) {
      return py::cast(x.run(&dcg::Extractor::domain_field),
                      py::return_value_policy::reference_internal, self);
    }
    const dcg::Points P = points.cast<dcg::Points>();
    return py::cast(x.run([&P](dcg::Extractor& e) { return e.force_field().evaluate(P); }));
  }
  const dcg::ConnectionPoints& connection_points() {
    return run(&dcg::Extractor::connection_points);
  }
  dcg::DomainGraph domain_graph() { return run(&dcg::Extractor::domain_graph); }
  dcg::Remapped remap() { return run(&dcg::Extractor::remap); }
  dcg::Skeleton skeleton() { return run(&dcg::Extractor::skeleton); }
  void retune(double tau) {
    run([tau](dcg::Extractor& e) { e.retune(tau); });
  }
  py::list timings() const { return py::list(py::cast(extractor_.timings())); }
  py::dict options() const { return options_to_dict(extractor_.options()); }

 private:
  ProgressBridge bridge_;
  dcg::Extractor extractor_;
};

}  // namespace

void bind_pipeline(py::module_& m) {
  m.def(
      "validate_mesh",
      [](const dcg::Vertices& V, const Faces64& F) {
        dcg::validate_mesh(V, to_faces(F, V.rows()));
      },
      py::arg("V"), py::arg("F"));

  constexpr auto kept = py::return_value_policy::reference_internal;
  py::class_<PyExtractor>(m, "Extractor")
      .def(py::init<const dcg::Vertices&, const Faces64&, const py::dict&, py::object>(),
           py::arg("V"), py::arg("F"), py::arg("options"), py::arg("progress") = py::none())
      .def("prepare", &PyExtractor::prepare, kept)
      .def("voronoi_balls", &PyExtractor::voronoi_balls, kept)
      .def("domain_balls", &PyExtractor::domain_balls, kept)
      .def("prongs", &PyExtractor::prongs, py::arg("tau") = py::none(), py::keep_alive<0, 1>())
      .def("end_points", &PyExtractor::end_points)
      .def("force_field", &PyExtractor::force_field, py::arg("points") = py::none())
      .def("connection_points", &PyExtractor::connection_points, kept)
      .def("domain_graph", &PyExtractor::domain_graph)
      .def("remap", &PyExtractor::remap)
      .def("skeleton", &PyExtractor::skeleton)
      .def("retune", &PyExtractor::retune, py::arg("tau"))
      .def_property_readonly("timings", &PyExtractor::timings)
      .def_property_readonly("options", &PyExtractor::options);
}

}  // namespace dcg_py

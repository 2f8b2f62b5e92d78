#include "common.h"

#include "dcg/errors.h"
#include "dcg/pipeline.h"
#include "dcg/prepare.h"

namespace dcg_py {
namespace {

py::dict balls_dict(const dcg::Balls& balls) {
  py::dict d;
  d["centers"] = balls.centers;
  d["radii"] = balls.radii;
  return d;
}

py::dict prepared_dict(const dcg::PreparedMesh& pm) {
  py::dict d;
  d["vertices"] = pm.working.V;
  d["faces"] = to_faces64(pm.working.F);
  d["scale"] = pm.scale;
  d["offset"] = Eigen::Vector3d(pm.offset.transpose());
  d["repaired"] = pm.repaired;
  d["remeshed"] = pm.remeshed;
  d["wrap_alpha"] = pm.wrap_alpha;
  d["genus"] = pm.genus;
  d["map_face"] = to_int64(pm.map_face);
  d["map_barycentric"] = pm.map_barycentric;
  py::dict report;
  report["input_vertices"] = pm.report.input_vertices;
  report["input_faces"] = pm.report.input_faces;
  report["welded_vertices"] = pm.report.welded_vertices;
  report["dropped_faces"] = pm.report.dropped_faces;
  report["border_edges"] = pm.report.border_edges;
  report["border_loops"] = pm.report.border_loops;
  report["non_manifold_edges"] = pm.report.non_manifold_edges;
  report["non_manifold_vertices"] = pm.report.non_manifold_vertices;
  report["orientable"] = pm.report.orientable;
  report["components"] = pm.report.components;
  report["closed_manifold"] = pm.report.closed_manifold();
  d["report"] = report;
  return d;
}

py::dict skeleton_dict(const dcg::Skeleton& s) {
  py::dict d;
  d["positions"] = s.positions;
  py::list kinds;
  for (auto kind : s.kinds) kinds.append(dcg::node_kind_name(kind));
  d["kinds"] = kinds;
  d["radii"] = s.radii;
  d["significance"] = s.significance;
  d["links"] = to_int64(s.links);
  d["polylines"] = py::cast(s.polylines);
  d["root"] = s.root;
  d["face_labels"] = to_int64(s.face_labels);
  d["timings"] = py::cast(s.timings);
  d["input_vertices"] = s.input_vertices;
  d["input_faces"] = s.input_faces;
  d["genus"] = s.genus;
  d["repaired"] = s.repaired;
  d["method"] = s.method;
  return d;
}

py::dict prongs_dict(const dcg::Prongs& p) {
  py::dict d;
  d["tau"] = p.tau;
  d["vertices"] = to_int64(p.vertices);
  d["positions"] = p.positions;
  d["significance"] = p.significance;
  return d;
}

py::dict prong_features_dict(const dcg::ProngFeatures& pf) {
  py::dict d = prongs_dict(pf.prongs);
  d["scale_function"] = pf.scale.values;
  d["sources"] = to_int64(pf.scale.sources);
  d["source_weights"] = pf.scale.weights;
  const auto& peaks = pf.hierarchy.peaks();
  const auto n = static_cast<Eigen::Index>(peaks.size());
  Eigen::Matrix<std::int64_t, Eigen::Dynamic, 1> vertex(n);
  Eigen::VectorXd value(n), valley(n), ratio(n);
  Eigen::Matrix<bool, Eigen::Dynamic, 1> global(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    vertex[i] = peaks[i].vertex;
    value[i] = peaks[i].value;
    valley[i] = peaks[i].valley;
    ratio[i] = peaks[i].ratio;
    global[i] = peaks[i].global;
  }
  py::dict pd;
  pd["vertices"] = vertex;
  pd["values"] = value;
  pd["valleys"] = valley;
  pd["ratios"] = ratio;
  pd["global"] = global;
  d["peaks"] = pd;
  return d;
}

/// The stepwise extractor as seen from Python: each method runs its stage (and those before it)
/// with the GIL released and returns plain dicts of numpy arrays.
class PyExtractor {
 public:
  PyExtractor(const dcg::Vertices& V, const Faces64& F, const py::dict& options,
              py::object progress)
      : bridge_(std::move(progress)),
        extractor_(V, to_faces(F, V.rows()), options_from_dict(options), bridge_.callback()) {}

  template <typename Stage>
  auto run(Stage stage) -> decltype(stage(std::declval<dcg::Extractor&>())) {
    try {
      py::gil_scoped_release release;
      return stage(extractor_);
    } catch (const dcg::Cancelled&) {
      bridge_.rethrow_if_failed();
      throw;
    }
  }

  py::dict prepare() {
    return prepared_dict(run([](dcg::Extractor& e) -> const dcg::PreparedMesh& { return e.prepare(); }));
  }
  py::dict voronoi_balls() {
    return balls_dict(run([](dcg::Extractor& e) -> const dcg::Balls& { return e.voronoi_balls(); }));
  }
  py::dict domain_balls() {
    const dcg::DomainBalls& db =
        run([](dcg::Extractor& e) -> const dcg::DomainBalls& { return e.domain_balls(); });
    py::dict d = balls_dict(db.balls);
    d["source"] = db.source;
    return d;
  }
  py::dict prongs(py::object tau) {
    if (tau.is_none()) {
      return prong_features_dict(
          run([](dcg::Extractor& e) -> const dcg::ProngFeatures& { return e.prongs(); }));
    }
    const double t = tau.cast<double>();
    return prongs_dict(run([t](dcg::Extractor& e) { return e.prongs_at(t); }));
  }
  py::dict end_points() {
    const dcg::EndPoints& ep =
        run([](dcg::Extractor& e) -> const dcg::EndPoints& { return e.end_points(); });
    py::dict d;
    d["centers"] = ep.centers;
    d["radii"] = ep.radii;
    d["source"] = to_int64(ep.ball);
    return d;
  }
  /// Stage 4 at `points` (#P x 3, normalized units), or at the domain points when None.
  py::dict force_field(py::object points) {
    dcg::FieldSamples f;
    if (points.is_none()) {
      f = run([](dcg::Extractor& e) -> const dcg::FieldSamples& { return e.domain_field(); });
    } else {
      const dcg::Points P = points.cast<dcg::Points>();
      f = run([&P](dcg::Extractor& e) { return e.force_field().evaluate(P); });
    }
    py::dict d;
    d["force"] = f.force;
    d["magnitude"] = f.magnitude;
    d["r_min"] = f.r_min;
    d["outside_rays"] = to_int64(f.outside_rays);
    return d;
  }
  py::dict connection_points() {
    const dcg::ConnectionPoints& c =
        run([](dcg::Extractor& e) -> const dcg::ConnectionPoints& { return e.connection_points(); });
    py::dict d;
    d["shrunk"] = c.shrunk;
    d["shrunk_magnitude"] = c.shrunk_magnitude;
    d["shrunk_radii"] = c.shrunk_radii;
    d["steps"] = to_int64(c.steps);
    Eigen::Matrix<bool, Eigen::Dynamic, 1> converged(static_cast<Eigen::Index>(c.converged.size()));
    for (std::size_t i = 0; i < c.converged.size(); ++i) converged[static_cast<Eigen::Index>(i)] = c.converged[i] != 0;
    d["converged"] = converged;
    d["cluster"] = to_int64(c.cluster);
    d["positions"] = c.positions;
    d["radii"] = c.radii;
    d["magnitude"] = c.magnitude;
    d["source"] = to_int64(c.source);
    return d;
  }
  py::dict domain_graph() {
    const dcg::DomainGraph& g =
        run([](dcg::Extractor& e) -> const dcg::DomainGraph& { return e.domain_graph(); });
    py::dict d;
    d["points"] = g.points;
    d["radii"] = g.radii;
    d["prong"] = to_int64(g.prong);
    d["face_labels"] = to_int64(g.face_labels);
    d["primitive_face"] = to_int64(g.primitive_face);
    d["visible_owner"] = to_int64(g.visible_owner);
    d["faces_seeded"] = g.faces_seeded;
    d["faces_grown"] = g.faces_grown;
    d["faces_filled"] = g.faces_filled;
    d["candidates"] = to_int64(g.candidates);
    d["costs"] = g.costs;
    d["candidate_state"] = to_int64(g.candidate_state);
    d["cycles_rejected_visible"] = g.cycles_rejected_visible;
    d["cycles_rejected_duplicate"] = g.cycles_rejected_duplicate;
    Eigen::Matrix<std::int64_t, Eigen::Dynamic, 1> nodes(static_cast<Eigen::Index>(g.nodes.size()));
    for (std::size_t i = 0; i < g.nodes.size(); ++i) nodes[static_cast<Eigen::Index>(i)] = g.nodes[i];
    d["nodes"] = nodes;
    d["links"] = to_int64(g.links);
    py::list kinds;
    for (auto kind : g.kinds) kinds.append(dcg::node_kind_name(kind));
    d["kinds"] = kinds;
    d["node_of_point"] = to_int64(g.node_of_point);
    d["face_nodes"] = to_int64(g.face_nodes);
    d["cycles"] = g.cycles;
    d["components"] = g.components;
    d["pruned"] = g.pruned;
    d["contracted"] = g.contracted;
    d["ends_absorbed"] = g.ends_absorbed;
    d["joints_merged"] = g.joints_merged;
    return d;
  }
  py::dict remap() {
    const dcg::Remapped& r = run([](dcg::Extractor& e) -> const dcg::Remapped& { return e.remap(); });
    py::dict d;
    d["polylines"] = py::cast(r.polylines);
    d["iterations"] = to_int64(r.iterations);
    d["rerouted"] = to_int64(r.rerouted);
    d["moves_refused"] = r.moves_refused;
    d["unrouted"] = r.unrouted;
    return d;
  }
  py::list timings() const {
    return py::list(py::cast(extractor_.timings()));
  }
  py::dict skeleton() {
    return skeleton_dict(run([](dcg::Extractor& e) -> const dcg::Skeleton& { return e.skeleton(); }));
  }
  py::dict options() const { return options_to_dict(extractor_.options()); }

 private:
  ProgressBridge bridge_;
  dcg::Extractor extractor_;
};

}  // namespace

void bind_pipeline(py::module_& m) {
  m.def(
      "validate_mesh",
      [](const dcg::Vertices& V, const Faces64& F) { dcg::validate_mesh(V, to_faces(F, V.rows())); },
      py::arg("V"), py::arg("F"));

  py::class_<PyExtractor>(m, "Extractor")
      .def(py::init<const dcg::Vertices&, const Faces64&, const py::dict&, py::object>(),
           py::arg("V"), py::arg("F"), py::arg("options"), py::arg("progress") = py::none())
      .def("prepare", &PyExtractor::prepare)
      .def("voronoi_balls", &PyExtractor::voronoi_balls)
      .def("domain_balls", &PyExtractor::domain_balls)
      .def("prongs", &PyExtractor::prongs, py::arg("tau") = py::none())
      .def("end_points", &PyExtractor::end_points)
      .def("force_field", &PyExtractor::force_field, py::arg("points") = py::none())
      .def("connection_points", &PyExtractor::connection_points)
      .def("domain_graph", &PyExtractor::domain_graph)
      .def("remap", &PyExtractor::remap)
      .def("skeleton", &PyExtractor::skeleton)
      .def_property_readonly("timings", &PyExtractor::timings)
      .def_property_readonly("options", &PyExtractor::options);
}

}  // namespace dcg_py

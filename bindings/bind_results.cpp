// The results of stages 0-8 (cpp/include/dcg/<stage>.h) as read-only Python classes, and the
// stage-3 ProngHierarchy (re-threshold prongs at any tau without new geodesics). Each field is
// named once, here; what it holds is documented in the stage's header.
#include "result_class.h"

#include "dcg/connection_points.h"
#include "dcg/domain_balls.h"
#include "dcg/domain_graph.h"
#include "dcg/end_points.h"
#include "dcg/force_field.h"
#include "dcg/prepare.h"
#include "dcg/remap.h"

namespace dcg_py {

py::object to_python(const std::vector<int>& values, py::handle) {
  return py::cast(to_int64(
      Eigen::Map<const Eigen::VectorXi>(values.data(), static_cast<Eigen::Index>(values.size()))));
}

py::object to_python(const std::vector<char>& flags, py::handle) {
  Eigen::Matrix<bool, Eigen::Dynamic, 1> out(static_cast<Eigen::Index>(flags.size()));
  for (Eigen::Index i = 0; i < out.size(); ++i) out[i] = flags[static_cast<std::size_t>(i)] != 0;
  return py::cast(out);
}

py::object to_python(const std::vector<dcg::NodeKind>& kinds, py::handle) {
  py::list names;
  for (dcg::NodeKind kind : kinds) names.append(dcg::node_kind_name(kind));
  return py::module_::import("numpy").attr("array")(names, py::arg("dtype") = "str");
}

py::object to_python(const Timings& timings, py::handle) {
  py::dict d;
  for (const auto& [stage, seconds] : timings) d[py::str(stage)] = seconds;
  return py::object(std::move(d));  // dict -> object: no copy, no -Wredundant-move (GCC 14)
}

/// The report as a dict of every property its class binds.
py::object to_python(const dcg::MeshReport& report, py::handle owner) {
  py::object bound = py::cast(report, py::return_value_policy::reference_internal, owner);
  py::object property = py::module_::import("builtins").attr("property");
  py::dict d;
  for (auto item : py::type::of(bound).attr("__dict__").attr("items")()) {
    auto [name, value] = item.cast<std::pair<py::str, py::object>>();
    if (py::isinstance(value, property)) d[name] = bound.attr(name);
  }
  return py::object(std::move(d));  // dict -> object: no copy, no -Wredundant-move (GCC 14)
}

py::object to_python(const std::vector<dcg::Peak>& peaks, py::handle) {
  const auto n = static_cast<Eigen::Index>(peaks.size());
  Eigen::Matrix<std::int64_t, Eigen::Dynamic, 1> vertex(n), valley_vertex(n), partner(n);
  Eigen::VectorXd value(n), valley(n), ratio(n);
  Eigen::Matrix<bool, Eigen::Dynamic, 1> global(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const dcg::Peak& peak = peaks[static_cast<std::size_t>(i)];
    vertex[i] = peak.vertex;
    value[i] = peak.value;
    valley[i] = peak.valley;
    ratio[i] = peak.ratio;
    global[i] = peak.global;
    valley_vertex[i] = peak.valley_vertex;
    partner[i] = peak.partner;
  }
  py::dict d;
  d["vertices"] = vertex;
  d["values"] = value;
  d["valleys"] = valley;
  d["ratios"] = ratio;
  d["global"] = global;
  d["valley_vertices"] = valley_vertex;
  d["partners"] = partner;
  return py::object(std::move(d));  // dict -> object: no copy, no -Wredundant-move (GCC 14)
}

namespace {

void bind_prepared(py::module_& m) {
  using R = dcg::MeshReport;
  ResultClass<R>(m, "MeshReport", "What stage 0 found in the input (dcg/prepare.h).")
      .field("input_vertices", &R::input_vertices)
      .field("input_faces", &R::input_faces)
      .field("welded_vertices", &R::welded_vertices)
      .field("dropped_faces", &R::dropped_faces)
      .field("border_edges", &R::border_edges)
      .field("border_loops", &R::border_loops)
      .field("non_manifold_edges", &R::non_manifold_edges)
      .field("non_manifold_vertices", &R::non_manifold_vertices)
      .field("orientable", &R::orientable)
      .field("components", &R::components)
      .field("fin_faces", &R::fin_faces)
      .field("filled_holes", &R::filled_holes)
      .field("cavities", &R::cavities)
      .field("wrapped_parts", &R::wrapped_parts)
      .field("part_wrap_alpha", &R::part_wrap_alpha)
      .def_property_readonly("closed_manifold", &R::closed_manifold);

  using P = dcg::PreparedMesh;
  ResultClass<P>(m, "PreparedMesh",
                 "Stage 0 (dcg/prepare.h): vertices, faces: the working mesh in normalized units "
                 "(input = v * scale + offset); report: dict of MeshReport.")
      .field("vertices", &P::working, &dcg::Mesh::V)
      .field("faces", &P::working, &dcg::Mesh::F)
      .field("scale", &P::scale)
      .field("offset", &P::offset)
      .field("report", &P::report)
      .field("repaired", &P::repaired)
      .field("wrap_alpha", &P::wrap_alpha)
      .field("remeshed", &P::remeshed)
      .field("genus", &P::genus)
      .field("map_face", &P::map_face)
      .field("map_barycentric", &P::map_barycentric);
}

void bind_balls(py::module_& m) {
  ResultClass<dcg::Balls>(m, "Balls", "Stage 1: Voronoi balls, normalized units (dcg/types.h).")
      .field("centers", &dcg::Balls::centers)
      .field("radii", &dcg::Balls::radii);
  using D = dcg::DomainBalls;
  ResultClass<D>(m, "DomainBalls",
                 "Stage 2 (dcg/domain_balls.h); source: index among the stage-1 balls.")
      .field("centers", &D::balls, &dcg::Balls::centers)
      .field("radii", &D::balls, &dcg::Balls::radii)
      .field("source", &D::source);
  using E = dcg::EndPoints;
  ResultClass<E>(m, "EndPoints",
                 "Each prong's end point (dcg/end_points.h), strongest prong first; source: the "
                 "stage-1 ball, -1 (radius 0, the peak itself) when no ball near it sees the peak.")
      .field("centers", &E::centers)
      .field("radii", &E::radii)
      .field("source", &E::ball);
}

void bind_prongs(py::module_& m) {
  using F = dcg::ProngFeatures;
  ResultClass<ProngsView>(
      m, "Prongs",
      "Stage 3 (dcg/prongs.h) on the working mesh. scale_function, sources, source_weights, "
      "peaks and hierarchy come with Extractor.prongs() without tau, else None.")
      .field("tau", &ProngsView::tau)
      .field("vertices", &ProngsView::vertices)
      .field("positions", &ProngsView::positions)
      .field("significance", &ProngsView::significance)
      .field("mirror_twins", &ProngsView::mirror_twins)
      .field("fingers", &ProngsView::fingers)
      .field("midline", &ProngsView::midline)
      .field("tails", &ProngsView::tails)
      .field("scale_function", &ProngsView::features, &F::scale, &dcg::ScaleFunction::values)
      .field("sources", &ProngsView::features, &F::scale, &dcg::ScaleFunction::sources)
      .field("source_weights", &ProngsView::features, &F::scale, &dcg::ScaleFunction::weights)
      .field("peaks", &ProngsView::features, &F::hierarchy, &dcg::ProngHierarchy::peaks)
      .field("hierarchy", &ProngsView::features, &F::hierarchy);

  using H = dcg::ProngHierarchy;
  ResultClass<H>(m, "ProngHierarchy",
                 "The watershed of a scale function, done once (dcg/prongs.h): prongs(tau) "
                 "re-thresholds at any tau without new geodesics.")
      .field("peaks", &H::peaks)
      .def(py::init([](const dcg::Vertices& V, const Faces64& F, const Eigen::VectorXd& f) {
             dcg::Mesh mesh{V, to_faces(F, V.rows())};
             py::gil_scoped_release release;
             return H(mesh, f);
           }),
           py::arg("V"), py::arg("F"), py::arg("f"),
           "V #V x 3 float64, F #F x 3 int64 indices into V, f #V float64 scale function "
           "(Prongs.scale_function on the working mesh).")
      .def(
          "prongs",
          [](const H& h, py::handle tau) {
            return ProngsView{h.prongs(option_number("tau", tau)), nullptr};
          },
          py::arg("tau"), "The prongs at smoothness ratio tau (0 < tau <= 1).")
      .def(
          "global_cap_is_disk",
          [](const H& h, py::handle tau) {
            return h.global_cap_is_disk(option_number("tau", tau));
          },
          py::arg("tau"));
}

void bind_field_and_points(py::module_& m) {
  using S = dcg::FieldSamples;
  ResultClass<S>(m, "FieldSamples", "Stage 4 at some points (dcg/force_field.h).")
      .field("force", &S::force)
      .field("magnitude", &S::magnitude)
      .field("r_min", &S::r_min)
      .field("outside_rays", &S::outside_rays);
  using C = dcg::ConnectionPoints;
  ResultClass<C>(m, "ConnectionPoints", "Stage 5 (dcg/connection_points.h).")
      .field("shrunk", &C::shrunk)
      .field("shrunk_magnitude", &C::shrunk_magnitude)
      .field("shrunk_radii", &C::shrunk_radii)
      .field("steps", &C::steps)
      .field("converged", &C::converged)
      .field("cluster", &C::cluster)
      .field("positions", &C::positions)
      .field("radii", &C::radii)
      .field("magnitude", &C::magnitude)
      .field("source", &C::source);
}

void bind_graph(py::module_& m) {
  using G = dcg::DomainGraph;
  ResultClass<G>(m, "DomainGraph",
                 "Stage 6 (dcg/domain_graph.h); stats: the counts of its rules as a dict.")
      .field("points", &G::points)
      .field("radii", &G::radii)
      .field("prong", &G::prong)
      .field("face_labels", &G::face_labels)
      .field("primitive_face", &G::primitive_face)
      .field("visible_owner", &G::visible_owner)
      .field("candidates", &G::candidates)
      .field("costs", &G::costs)
      .field("candidate_state", &G::candidate_state)
      .field("nodes", &G::nodes)
      .field("links", &G::links)
      .field("kinds", &G::kinds)
      .field("node_of_point", &G::node_of_point)
      .field("face_nodes", &G::face_nodes)
      .field("cycles", &G::cycles)
      .field("components", &G::components)
      .counts("stats", {{"faces_seeded", &G::faces_seeded},
                        {"faces_grown", &G::faces_grown},
                        {"faces_filled", &G::faces_filled},
                        {"cycles_rejected_visible", &G::cycles_rejected_visible},
                        {"cycles_rejected_duplicate", &G::cycles_rejected_duplicate},
                        {"links_bridged", &G::links_bridged},
                        {"pruned", &G::pruned},
                        {"contracted", &G::contracted},
                        {"ends_absorbed", &G::ends_absorbed},
                        {"joints_merged", &G::joints_merged}});
}

void bind_skeleton(py::module_& m) {
  using R = dcg::Remapped;
  ResultClass<R>(m, "Remapped", "Stage 7 (dcg/remap.h), one polyline per DomainGraph link.")
      .field("polylines", &R::polylines)
      .field("iterations", &R::iterations)
      .field("rerouted", &R::rerouted)
      .field("moves_refused", &R::moves_refused)
      .field("unrouted", &R::unrouted);
  using S = dcg::Skeleton;
  ResultClass<S>(m, "Skeleton",
                 "The engine's skeleton (dcg/skeleton.h), in the input's coordinates; dcg.Skeleton "
                 "is the Python value made of these fields.")
      .field("positions", &S::positions)
      .field("kinds", &S::kinds)
      .field("radii", &S::radii)
      .field("significance", &S::significance)
      .field("links", &S::links)
      .field("polylines", &S::polylines)
      .field("polyline_radii", &S::polyline_radii)
      .field("root", &S::root)
      .field("face_labels", &S::face_labels)
      .field("timings", &S::timings)
      .field("input_vertices", &S::input_vertices)
      .field("input_faces", &S::input_faces)
      .field("genus", &S::genus)
      .field("repaired", &S::repaired)
      .field("method", &S::method)
      .field("mirror_plane", &S::mirror_plane)
      .field("mirror_error", &S::mirror_error);
}

}  // namespace

void bind_results(py::module_& m) {
  bind_prepared(m);
  bind_balls(m);
  bind_prongs(m);
  bind_field_and_points(m);
  bind_graph(m);
  bind_skeleton(m);
}

}  // namespace dcg_py

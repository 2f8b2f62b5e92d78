// Stage 8: the Skeleton type's helpers and its assembly from stages 6 and 7.
#include "dcg/skeleton.h"

#include "dcg/domain_graph.h"
#include "dcg/errors.h"
#include "dcg/prepare.h"
#include "dcg/remap.h"
#include "dcg/surface_query.h"

namespace dcg {

const char* node_kind_name(NodeKind kind) {
  switch (kind) {
    case NodeKind::End:
      return "end";
    case NodeKind::Joint:
      return "joint";
    case NodeKind::Connection:
      return "connection";
  }
  return "connection";
}

NodeKind node_kind_of_degree(std::size_t degree) {
  return degree == 1 ? NodeKind::End : degree >= 3 ? NodeKind::Joint : NodeKind::Connection;
}

void choose_root(Skeleton& s) {
  const int n = static_cast<int>(s.kinds.size());
  s.root = -1;
  for (int pass = 0; pass < 2 && s.root < 0; ++pass) {
    for (int i = 0; i < n; ++i) {
      if (pass == 0 && s.kinds[i] != NodeKind::Joint) continue;
      if (s.root < 0 || s.radii[i] > s.radii[s.root]) s.root = i;
    }
  }
}

Skeleton assemble_skeleton(const DomainGraph& graph, const Remapped& remapped,
                           const Eigen::VectorXd& prong_significance) {
  const int n = static_cast<int>(graph.nodes.size());
  if (remapped.polylines.size() != static_cast<std::size_t>(graph.links.rows())) {
    throw InputError("assemble_skeleton: one polyline per link is needed");
  }
  Skeleton s;
  s.method = "dcg";
  s.positions.resize(n, 3);
  s.radii.resize(n);
  s.significance = Eigen::VectorXd::Zero(n);
  s.kinds = graph.kinds;
  for (int i = 0; i < n; ++i) {
    const int p = graph.nodes[i];
    s.positions.row(i) = graph.points.row(p);
    s.radii[i] = graph.radii[p];
    if (s.kinds[i] == NodeKind::End) {
      const int prong = graph.prong[p];
      s.significance[i] =
          prong >= 0 && prong < prong_significance.size() ? prong_significance[prong] : 1.0;
    }
  }
  s.links = graph.links;
  s.polylines = remapped.polylines;
  choose_root(s);
  s.face_labels = graph.face_nodes;
  return s;
}

void measure_polyline_radii(Skeleton& s, const SurfaceQuery& surface) {
  s.polyline_radii.assign(s.polylines.size(), Eigen::VectorXd());
  for (std::size_t l = 0; l < s.polylines.size(); ++l) {
    const Points& polyline = s.polylines[l];
    Eigen::VectorXd& radii = s.polyline_radii[l];
    radii.resize(polyline.rows());
    for (Eigen::Index i = 0; i < polyline.rows(); ++i)
      radii[i] = surface.distance(polyline.row(i).transpose());
  }
}

void skeleton_to_input(Skeleton& s, const PreparedMesh& pm, const Faces& F_in,
                       Eigen::Index input_vertices) {
  for (Eigen::Index i = 0; i < s.positions.rows(); ++i) {
    s.positions.row(i) = pm.to_input(s.positions.row(i));
  }
  for (auto& polyline : s.polylines) {
    for (Eigen::Index i = 0; i < polyline.rows(); ++i)
      polyline.row(i) = pm.to_input(polyline.row(i));
  }
  s.radii *= pm.scale;
  for (Eigen::VectorXd& radii : s.polyline_radii) radii *= pm.scale;
  const Eigen::VectorXi working_labels = s.face_labels;
  s.face_labels = Eigen::VectorXi::Constant(F_in.rows(), -1);
  if (working_labels.size() == pm.working.F.rows() && pm.map_face.size() == input_vertices) {
    for (Eigen::Index f = 0; f < F_in.rows(); ++f) {
      int label[3];
      for (int k = 0; k < 3; ++k) {
        const int wf = pm.map_face[F_in(f, k)];
        label[k] = wf >= 0 && wf < working_labels.size() ? working_labels[wf] : -1;
      }
      int best = label[0];
      if (label[1] == label[2] && label[1] >= 0) best = label[1];
      if (best < 0) best = label[1] >= 0 ? label[1] : label[2];
      s.face_labels[f] = best;
    }
  }
  s.input_vertices = static_cast<int>(input_vertices);
  s.input_faces = static_cast<int>(F_in.rows());
  s.genus = pm.genus;
  s.repaired = pm.repaired;
}

}  // namespace dcg

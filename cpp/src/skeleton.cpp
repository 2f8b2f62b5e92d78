// Stage 8: the Skeleton type's helpers and its assembly from stages 6 and 7.
#include "dcg/skeleton.h"

#include "dcg/domain_graph.h"
#include "dcg/errors.h"
#include "dcg/remap.h"

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
      s.significance[i] = prong >= 0 && prong < prong_significance.size() ? prong_significance[prong] : 1.0;
    }
  }
  s.links = graph.links;
  s.polylines = remapped.polylines;
  choose_root(s);
  s.face_labels = graph.face_nodes;
  return s;
}

}  // namespace dcg

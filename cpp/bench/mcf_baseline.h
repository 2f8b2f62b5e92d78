// The benchmark's baseline: CGAL's mean curvature flow skeleton (Tagliasacchi et al. 2012) on
// the same triangles our engine gets. CGAL stays inside mcf_baseline.cpp (a slow translation
// unit); this header only needs Eigen through dcg/types.h.
#pragma once

#include <string>

#include "dcg/types.h"

namespace dcg::bench {

/// What the baseline did on one mesh. Failures and skips are data, not exceptions.
struct McfResult {
  enum class Status { Ok, Skipped, Failed };
  Status status = Status::Skipped;
  double seconds = 0;         ///< wall time of extract_mean_curvature_flow_skeleton only (Ok)
  double build_seconds = 0;   ///< welding, the manifold check and building the Surface_mesh
  int mesh_vertices = 0;      ///< vertices of the Surface_mesh handed to MCF
  bool welded = false;        ///< exact duplicate points had to be welded first
  int skeleton_vertices = 0;  ///< nodes of the MCF skeleton (Ok)
  int skeleton_edges = 0;     ///< edges of the MCF skeleton (Ok)
  Points points;              ///< #S by 3 MCF skeleton vertices, input coordinates (Ok)
  Edges edges;                ///< #E by 2 MCF skeleton edges into `points` (Ok)
  std::string note;           ///< why it was skipped or failed; empty when Ok
};

const char* status_name(McfResult::Status status);

/// Runs CGAL::extract_mean_curvature_flow_skeleton with its default parameters on
/// (V #V by 3, F #F by 3), unreferenced points dropped. When the triangles as given are not a
/// closed oriented 2-manifold, exactly repeated points are welded and the check is repeated
/// (welding is not repair: our stage 0 welds too); the mesh is skipped, with a note, when that
/// fails as well. An exception from CGAL is returned as Status::Failed with its message.
McfResult run_mcf_skeleton(const Vertices& V, const Faces& F);

/// CGAL's version string, e.g. "5.5.1".
std::string cgal_version();

}  // namespace dcg::bench

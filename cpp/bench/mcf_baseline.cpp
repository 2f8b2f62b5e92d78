// CGAL's mean curvature flow skeleton as the benchmark's baseline. See mcf_baseline.h.
#include "mcf_baseline.h"

#include <CGAL/Mean_curvature_flow_skeletonization.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/helpers.h>
#include <CGAL/extract_mean_curvature_flow_skeleton.h>
#include <CGAL/version.h>

#include <chrono>
#include <exception>
#include <vector>

namespace dcg::bench {
namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using Point = Kernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;
using Skeletonization = CGAL::Mean_curvature_flow_skeletonization<SurfaceMesh>;
namespace PMP = CGAL::Polygon_mesh_processing;

double now_seconds() {
  using Clock = std::chrono::steady_clock;
  return std::chrono::duration<double>(Clock::now().time_since_epoch()).count();
}

// Why (points, polygons) is not a closed oriented 2-manifold, or "" when it is; `mesh` is then
// built from them.
std::string build_closed_manifold(const std::vector<Point>& points,
                                  const std::vector<std::vector<std::size_t>>& polygons,
                                  SurfaceMesh& mesh) {
  if (!PMP::is_polygon_soup_a_polygon_mesh(polygons)) {
    return "not an oriented 2-manifold (non-manifold edges or vertices, or inconsistent "
           "orientation)";
  }
  mesh.clear();
  PMP::polygon_soup_to_polygon_mesh(points, polygons, mesh);
  if (!CGAL::is_closed(mesh)) {
    int border = 0;
    for (auto h : mesh.halfedges()) border += mesh.is_border(h) ? 1 : 0;
    return "not closed (" + std::to_string(border) + " border edges)";
  }
  return "";
}

}  // namespace

const char* status_name(McfResult::Status status) {
  switch (status) {
    case McfResult::Status::Ok:
      return "ok";
    case McfResult::Status::Skipped:
      return "skipped";
    case McfResult::Status::Failed:
      return "failed";
  }
  return "?";
}

std::string cgal_version() { return CGAL_VERSION_STR; }

McfResult run_mcf_skeleton(const Vertices& V, const Faces& F) {
  McfResult result;
  try {
    const double t0 = now_seconds();
    // The triangles as given (only referenced points kept).
    std::vector<int> new_index(static_cast<size_t>(V.rows()), -1);
    std::vector<Point> points;
    std::vector<std::vector<std::size_t>> polygons(static_cast<size_t>(F.rows()));
    for (Eigen::Index f = 0; f < F.rows(); ++f) {
      for (int k = 0; k < 3; ++k) {
        const int v = F(f, k);
        if (new_index[v] < 0) {
          new_index[v] = static_cast<int>(points.size());
          points.emplace_back(V(v, 0), V(v, 1), V(v, 2));
        }
        polygons[f].push_back(static_cast<std::size_t>(new_index[v]));
      }
    }
    SurfaceMesh mesh;
    const std::string as_given = build_closed_manifold(points, polygons, mesh);
    if (!as_given.empty()) {
      // Files that repeat points per face (STL, some OBJ) become closed once exact duplicates
      // are welded. Not the first try: welding can pinch a mesh that is fine as given.
      PMP::merge_duplicate_points_in_polygon_soup(points, polygons);
      const std::string welded = build_closed_manifold(points, polygons, mesh);
      result.welded = true;
      if (!welded.empty()) {
        result.note = as_given == welded ? as_given : as_given + "; after welding: " + welded;
        result.build_seconds = now_seconds() - t0;
        return result;
      }
    }
    result.mesh_vertices = static_cast<int>(mesh.number_of_vertices());
    result.build_seconds = now_seconds() - t0;

    Skeletonization::Skeleton skeleton;
    const double t1 = now_seconds();
    CGAL::extract_mean_curvature_flow_skeleton(mesh, skeleton);
    result.seconds = now_seconds() - t1;
    result.skeleton_vertices = static_cast<int>(boost::num_vertices(skeleton));
    result.skeleton_edges = static_cast<int>(boost::num_edges(skeleton));
    // The skeleton's geometry (outside the timing), for the bench's quality columns.
    result.points.resize(result.skeleton_vertices, 3);
    int i = 0;
    for (auto v : CGAL::make_range(vertices(skeleton))) {  // vecS: indices 0..n-1 in order
      const Point& p = skeleton[v].point;
      result.points.row(i++) << p.x(), p.y(), p.z();
    }
    result.edges.resize(result.skeleton_edges, 2);
    i = 0;
    for (auto e : CGAL::make_range(edges(skeleton))) {
      result.edges.row(i++) << static_cast<int>(source(e, skeleton)),
          static_cast<int>(target(e, skeleton));
    }
    result.status = McfResult::Status::Ok;
  } catch (const std::exception& e) {
    result.status = McfResult::Status::Failed;
    result.note = std::string("CGAL threw: ") + e.what();
  } catch (...) {
    result.status = McfResult::Status::Failed;
    result.note = "CGAL threw an unknown exception";
  }
  return result;
}

}  // namespace dcg::bench

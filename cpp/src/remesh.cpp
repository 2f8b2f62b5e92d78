// Uniform remeshing for stage 0. See remesh.h.
//
// Target edge length L from the area A: target_faces equilateral triangles of side L cover A,
// so L = sqrt(4 A / (sqrt(3) target_faces)). When the mesh has more than twice the target, it
// is first decimated by edge collapse to about the target (CGAL's stop predicate counts edges:
// a closed mesh has 3/2 edges per face): isotropic remeshing alone coarsens by large factors
// slowly (horse.ply, 97k -> 20k faces: 0.8 s for one iteration). The collapse takes the
// shortest edge first and puts the new vertex at its midpoint, refusing collapses that flip a
// face normal: about 3x faster than the Lindstrom-Turk default (0.5 s instead of 1.3 s on the
// horse) and, as it evens out edge lengths, a better start for the isotropic remeshing, which
// then makes the triangles uniform in 3 iterations.
#include <algorithm>
#include "remesh.h"

#include <cmath>
#include <string>
#include <vector>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/remesh.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Bounded_normal_change_placement.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Count_stop_predicate.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Edge_length_cost.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Midpoint_placement.h>
#include <CGAL/Surface_mesh_simplification/edge_collapse.h>

#include "dcg/errors.h"

namespace dcg::internal {

namespace PMP = CGAL::Polygon_mesh_processing;
namespace SMS = CGAL::Surface_mesh_simplification;
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;
using SM = CGAL::Surface_mesh<Point>;

Mesh remesh_uniform(const Mesh& mesh, int target_faces) {
  SM sm;
  std::vector<SM::Vertex_index> vs;
  vs.reserve(mesh.V.rows());
  for (Eigen::Index i = 0; i < mesh.V.rows(); ++i) vs.push_back(sm.add_vertex(Point(mesh.V(i, 0), mesh.V(i, 1), mesh.V(i, 2))));
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    if (sm.add_face(vs[mesh.F(f, 0)], vs[mesh.F(f, 1)], vs[mesh.F(f, 2)]) == SM::null_face()) {
      throw InputError("remeshing failed: face " + std::to_string(f) +
                       " does not fit a manifold surface");
    }
  }
  // CGAL's isotropic remeshing segfaults when its target edge is long compared with the shape
  // (a tetrahedron at target_faces 64 collapses into something it cannot handle; found by
  // fuzzing). So the working mesh keeps at least kMinFaces triangles and edges of at most 1/20
  // of the bounding-box diagonal, whatever target_faces asks.
  constexpr int kMinFaces = 200;
  target_faces = std::max(target_faces, kMinFaces);
  const double diagonal = (mesh.V.colwise().maxCoeff() - mesh.V.colwise().minCoeff()).norm();
  const double area = PMP::area(sm);
  const double L = std::min(std::sqrt(4.0 * area / (std::sqrt(3.0) * target_faces)),
                            diagonal / 20.0);
  if (static_cast<double>(sm.number_of_faces()) > 2.0 * target_faces) {
    SMS::Count_stop_predicate<SM> stop(static_cast<std::size_t>(1.5 * target_faces));
    SMS::edge_collapse(sm, stop,
                       CGAL::parameters::get_cost(SMS::Edge_length_cost<SM>())
                           .get_placement(SMS::Bounded_normal_change_placement<
                                          SMS::Midpoint_placement<SM>>()));
    sm.collect_garbage();
  }
  PMP::isotropic_remeshing(faces(sm), L, sm,
                           CGAL::parameters::number_of_iterations(3).number_of_relaxation_steps(1));
  sm.collect_garbage();
  Mesh out;
  out.V.resize(sm.number_of_vertices(), 3);
  std::vector<int> index(sm.num_vertices(), -1);
  int n = 0;
  for (auto v : sm.vertices()) {
    const Point& p = sm.point(v);
    out.V.row(n) << p.x(), p.y(), p.z();
    index[v.idx()] = n++;
  }
  out.F.resize(sm.number_of_faces(), 3);
  int f = 0;
  for (auto face : sm.faces()) {
    int k = 0;
    for (auto v : CGAL::vertices_around_face(sm.halfedge(face), sm)) {
      if (k < 3) out.F(f, k) = index[v.idx()];
      ++k;
    }
    ++f;
  }
  return out;
}

}  // namespace dcg::internal

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
#include "remesh.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/remesh.h>
#include <CGAL/Polygon_mesh_processing/tangential_relaxation.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Bounded_normal_change_placement.h>
// CGAL 6 renamed Count_stop_predicate (the same edge-count stop) and deprecated the old header;
// EdgeCountStop below is whichever this CGAL has.
#if CGAL_VERSION_NR >= CGAL_VERSION_NUMBER(6, 0, 0)
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Edge_count_stop_predicate.h>
#else
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Count_stop_predicate.h>
#endif
#include <CGAL/Surface_mesh_simplification/Edge_collapse_visitor_base.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Edge_length_cost.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Midpoint_placement.h>
#include <CGAL/Surface_mesh_simplification/edge_collapse.h>

#include "dcg/errors.h"
#include "edge_table.h"
#include "surface_mesh_convert.h"

namespace dcg::internal {
namespace {

namespace PMP = CGAL::Polygon_mesh_processing;
namespace SMS = CGAL::Surface_mesh_simplification;
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;
using SM = CGAL::Surface_mesh<Point>;
#if CGAL_VERSION_NR >= CGAL_VERSION_NUMBER(6, 0, 0)
using EdgeCountStop = SMS::Edge_count_stop_predicate<SM>;
#else
using EdgeCountStop = SMS::Count_stop_predicate<SM>;
#endif

// Cancellation from inside CGAL: the edge collapse calls its visitor for every edge it collects
// and every collapse it selects; the isotropic remeshing reads its vertex-is-constrained map for
// every edge it may collapse and every vertex it relaxes or projects. Both call `poll` (which
// throws Cancelled to stop; the half-made Surface_mesh is then simply dropped). The map always
// answers "not constrained", like CGAL's default, so the result does not change.
struct PollingCollapseVisitor : SMS::Edge_collapse_visitor_base<SM> {
  const std::function<void(double)>* poll = nullptr;
  double from = 0, to = 1;
  std::size_t collected = 0;
  template <class Profile, class Cost>
  void OnCollected(const Profile&, const Cost&) {
    if ((++collected & 1023) == 0) (*poll)(from);
  }
  template <class Profile, class Cost>
  void OnSelected(const Profile&, const Cost&, std::size_t initial, std::size_t current) {
    if ((current & 255) == 0 && initial > 0) {
      (*poll)(from + (to - from) * (1.0 - static_cast<double>(current) / initial));
    }
  }
};

struct PollingNotConstrained {
  using key_type = SM::Vertex_index;
  using value_type = bool;
  using reference = bool;
  using category = boost::readable_property_map_tag;
  const std::function<void(double)>* poll = nullptr;
  double fraction = 0;
  std::shared_ptr<std::size_t> reads = std::make_shared<std::size_t>(0);  // copies share it
  friend bool get(const PollingNotConstrained& map, key_type) {
    // CGAL reads the map for every vertex it touches: the poll (a clock read) every 256 reads.
    if ((++*map.reads & 255) == 0) (*map.poll)(map.fraction);
    return false;
  }
};

// Splits every triangle into four at its edge midpoints (the same surface). The input's
// vertices keep their indices; the midpoints come after them.
Mesh subdivide_midpoints(const Mesh& mesh) {
  const Eigen::Index nv = mesh.V.rows(), nf = mesh.F.rows();
  const EdgeTable table(mesh.F);
  std::vector<int> midpoint(3 * nf);  // corner 3 f + k -> vertex in the middle of edge k of f
  std::vector<Eigen::RowVector3d> added;
  table.for_each_edge([&](std::size_t b, std::size_t e) {
    const int corner = table.half[b].second, f = EdgeTable::face(corner), k = corner % 3;
    added.push_back(0.5 * (mesh.V.row(mesh.F(f, k)) + mesh.V.row(mesh.F(f, (k + 1) % 3))));
    for (std::size_t i = b; i < e; ++i)
      midpoint[table.half[i].second] = static_cast<int>(nv + added.size() - 1);
  });
  Mesh out;
  out.V.resize(nv + static_cast<Eigen::Index>(added.size()), 3);
  out.V.topRows(nv) = mesh.V;
  for (std::size_t i = 0; i < added.size(); ++i)
    out.V.row(nv + static_cast<Eigen::Index>(i)) = added[i];
  out.F.resize(4 * nf, 3);
  for (Eigen::Index f = 0; f < nf; ++f) {
    const int a = mesh.F(f, 0), b = mesh.F(f, 1), c = mesh.F(f, 2);
    const int ab = midpoint[3 * f], bc = midpoint[3 * f + 1], ca = midpoint[3 * f + 2];
    out.F.row(4 * f) << a, ab, ca;
    out.F.row(4 * f + 1) << ab, b, bc;
    out.F.row(4 * f + 2) << ca, bc, c;
    out.F.row(4 * f + 3) << ab, bc, ca;
  }
  return out;
}

}  // namespace

Mesh remesh_uniform(const Mesh& input, int target_faces,
                    const std::function<void(double)>& poll_in) {
  const std::function<void(double)> poll = poll_in ? poll_in : [](double) {};
  // A mesh of far fewer faces than the target is split 1-to-4 at its edge midpoints first (the
  // same surface): CGAL's isotropic remeshing segfaulted (in the remesher's own relaxation,
  // found by fuzzing; see the rounds below) on a 6-face bipyramid with 200 faces to reach, and
  // runs through the same bipyramid split twice.
  Mesh mesh = input;
  while (mesh.F.rows() > 0 && 2 * mesh.F.rows() < std::max(target_faces, kMinRemeshFaces)) {
    mesh = subdivide_midpoints(mesh);
  }
  SM sm;
  std::vector<SM::Vertex_index> vs;
  vs.reserve(mesh.V.rows());
  for (Eigen::Index i = 0; i < mesh.V.rows(); ++i)
    vs.push_back(sm.add_vertex(Point(mesh.V(i, 0), mesh.V(i, 1), mesh.V(i, 2))));
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    if (sm.add_face(vs[mesh.F(f, 0)], vs[mesh.F(f, 1)], vs[mesh.F(f, 2)]) == SM::null_face()) {
      throw InputError("remeshing failed: face " + std::to_string(f) +
                       " does not fit a manifold surface");
    }
  }
  // CGAL's isotropic remeshing segfaults when its target edge is long compared with the shape
  // (a tetrahedron at target_faces 64 collapses into something it cannot handle; found by
  // fuzzing). So the working mesh keeps at least kMinRemeshFaces triangles and edges of at most
  // 1/20 of the bounding-box diagonal, whatever target_faces asks.
  target_faces = std::max(target_faces, kMinRemeshFaces);
  const double diagonal = (mesh.V.colwise().maxCoeff() - mesh.V.colwise().minCoeff()).norm();
  const double area = PMP::area(sm);
  const double L =
      std::min(std::sqrt(4.0 * area / (std::sqrt(3.0) * target_faces)), diagonal / 20.0);
  if (static_cast<double>(sm.number_of_faces()) > 2.0 * target_faces) {
    EdgeCountStop stop(static_cast<std::size_t>(1.5 * target_faces));
    PollingCollapseVisitor visitor;
    visitor.poll = &poll;
    visitor.from = 0.0;
    visitor.to = 0.6;
    SMS::edge_collapse(
        sm, stop,
        CGAL::parameters::get_cost(SMS::Edge_length_cost<SM>())
            .get_placement(SMS::Bounded_normal_change_placement<SMS::Midpoint_placement<SM>>())
            .visitor(visitor));
    sm.collect_garbage();
  }
  poll(0.6);
  PollingNotConstrained not_constrained;
  not_constrained.poll = &poll;
  not_constrained.fraction = 0.8;
  // Three rounds of CGAL's isotropic remeshing (split, collapse, flip, project), each followed
  // by one tangential relaxation called on its own, not by the remesher: CGAL 5.5's remesher
  // relaxes with an edge-constraint map that reads its halfedge status at a null halfedge when
  // every face around a vertex has become degenerate (an out-of-bounds read, a segfault under
  // ASan: the fuzzer found it on a sliver tetrahedron, tests/fuzz/corpus/prepare/
  // crash-remesh-sliver-tetrahedron; CGAL issue 7345, fixed in 5.6). On its own the relaxation
  // reads a constant map there. Measured against one remeshing call of 3 iterations with 1
  // relaxation step each: the 43 public, stress and rigged meshes keep their ends, cycles and
  // joints but 3 (Fox 1 -> 2 joints, Mannequiny 3 -> 2, Q_Horse 2 -> 1), 40 instead of 38
  // stable, rig-quality mean 4.29 / 2.94 / 3.42 -> 4.25 / 2.90 / 3.36, stage 0 3-10% slower on
  // the 16 remeshed meshes.
  for (int iteration = 0; iteration < 3; ++iteration) {
    PMP::isotropic_remeshing(faces(sm), L, sm,
                             CGAL::parameters::number_of_iterations(1)
                                 .number_of_relaxation_steps(0)
                                 .vertex_is_constrained_map(not_constrained));
    PMP::tangential_relaxation(
        vertices(sm), sm,
        CGAL::parameters::number_of_iterations(1).vertex_is_constrained_map(not_constrained));
  }
  sm.collect_garbage();
  poll(1.0);
  return mesh_from_surface_mesh(sm, "remeshing failed: the result");
}

}  // namespace dcg::internal

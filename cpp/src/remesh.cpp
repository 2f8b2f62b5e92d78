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

#include <CGAL/AABB_tree.h>
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
#if CGAL_VERSION_NR >= CGAL_VERSION_NUMBER(6, 0, 0)
#include <CGAL/AABB_traits_3.h>
#include <CGAL/AABB_triangle_primitive_3.h>
#else
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_triangle_primitive.h>
#endif

#include "canonical_order.h"
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
using Triangles = std::vector<K::Triangle_3>;
#if CGAL_VERSION_NR >= CGAL_VERSION_NUMBER(6, 0, 0)
using Tree = CGAL::AABB_tree<
    CGAL::AABB_traits_3<K, CGAL::AABB_triangle_primitive_3<K, Triangles::const_iterator>>>;
#else
using Tree = CGAL::AABB_tree<
    CGAL::AABB_traits<K, CGAL::AABB_triangle_primitive<K, Triangles::const_iterator>>>;
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

// --- the same remeshing on every CGAL --------------------------------------------------------
// CGAL 5.5 (Debian 12) and CGAL 6 (Debian 13) split and collapse the same edges but number the
// vertices they make differently, and the valence flips after them visit the edges in that
// order: Q_Horse's working mesh had 5014 faces on one and 5032 on the other after 3 rounds, and
// 7 of the 14 rigged characters got other skeletons (rig-quality CD-J2J 3.50 against 3.57).
// So each round's steps run one at a time on a mesh in centred order (canonical_order.h), and
// the flips (`equalize_valences`) and the projection (`project_onto`) are ours; the input is
// snapped to a fine grid first (`snap_to_grid`). The working mesh is then the same on both, to
// the bit, for 38 of the 43 bench meshes (the other 5 are wrapped or united first, and CGAL's
// wrap and union differ between the two by more than rounding), and whatever the input's
// numbering (test_prepare). The centred order is one a rotation or a mirror keeps (but for
// ties): 38 of the 43 keep their ends and joints when rotated, scaled and shaken (36 with
// CGAL's own order; a lexicographic order gave 37 and left 4 of Mannequiny's limbs without
// pairing). It costs 0.05-0.13 s of stage 0 on the 25k-face remeshed meshes (horse.ply 0.40
// -> 0.47-0.53 s in the same runs).

// Rounds every coordinate of `mesh` to a multiple of the power of two nearest 2^-30 of its
// bounding box's diagonal (a billionth: no shape moves), so that inputs a rounding apart remesh
// alike. The splits and collapses take equally long edges in an order the last bits decide,
// and the skeleton follows the working mesh: a small ellipsoid of the tests scaled by 1e-6
// (normalized, it differs in the last bits) ended 12% of its diagonal short on one of its two
// ends, and numpy 1.24 and 2.2 draw its sines a bit apart.
void snap_to_grid(Mesh& mesh) {
  if (mesh.V.rows() == 0) return;
  const double diagonal = (mesh.V.colwise().maxCoeff() - mesh.V.colwise().minCoeff()).norm();
  if (!(diagonal > 0) || !std::isfinite(diagonal)) return;
  // The nearest power of two (a normalized mesh's diagonal is 1 give or take a last bit, where
  // the power of two below it would jump).
  const double step = std::ldexp(1.0, static_cast<int>(std::lround(std::log2(diagonal))) - 30);
  mesh.V = (mesh.V / step).array().round().matrix() * step;
}

// `mesh` as a Surface_mesh, in its own vertex and face order. InputError when a face does not
// fit a manifold surface.
SM to_surface_mesh(const Mesh& mesh) {
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
  return sm;
}

// `sm` rebuilt in centred order (canonical_order.h).
SM canonical(const SM& sm) {
  return to_surface_mesh(centred_order(mesh_from_surface_mesh(sm, "remeshing failed: the mesh")));
}

int valence(const SM& sm, SM::Vertex_index v) {
  return static_cast<int>(CGAL::halfedges_around_target(v, sm).size());
}

// Whether flipping the edge of h (faces a b c and b a d) to c d keeps the surface's way: both
// new faces (c a d, d b c) turn to the side the old ones did, and to each other's.
bool flip_keeps_normals(const SM& sm, SM::Halfedge_index h) {
  const Point& a = sm.point(sm.source(h));
  const Point& b = sm.point(sm.target(h));
  const Point& c = sm.point(sm.target(sm.next(h)));
  const Point& d = sm.point(sm.target(sm.next(sm.opposite(h))));
  const K::Vector_3 n1 = CGAL::cross_product(b - a, c - a);
  const K::Vector_3 n2 = CGAL::cross_product(a - b, d - b);
  const K::Vector_3 m1 = CGAL::cross_product(a - c, d - c);
  const K::Vector_3 m2 = CGAL::cross_product(b - d, c - d);
  const K::Vector_3 n = n1 + n2;
  return m1 * n > 0 && m2 * n > 0 && m1 * n1 > 0 && m2 * n2 > 0 && m1 * m2 > 0;
}

// The valence step of isotropic remeshing (Botsch and Kobbelt): each edge, in the order of its
// two vertices' indices, flips when that brings the four vertices it touches nearer to valence
// 6 and keeps the surface's way (`flip_keeps_normals`); never where the two opposite vertices
// are joined already or an end of the edge has valence 3.
void equalize_valences(SM& sm) {
  std::vector<std::pair<std::pair<int, int>, SM::Edge_index>> order;
  for (auto e : sm.edges()) {
    const int a = static_cast<int>(sm.source(sm.halfedge(e)));
    const int b = static_cast<int>(sm.target(sm.halfedge(e)));
    order.push_back({{std::min(a, b), std::max(a, b)}, e});
  }
  std::sort(order.begin(), order.end());
  for (const auto& entry : order) {
    const SM::Edge_index e = entry.second;
    if (sm.is_border(e)) continue;
    const SM::Halfedge_index h = sm.halfedge(e);
    const auto a = sm.source(h), b = sm.target(h);
    const auto c = sm.target(sm.next(h)), d = sm.target(sm.next(sm.opposite(h)));
    if (c == d || sm.halfedge(c, d) != SM::null_halfedge()) continue;
    const int va = valence(sm, a), vb = valence(sm, b), vc = valence(sm, c), vd = valence(sm, d);
    if (va <= 3 || vb <= 3) continue;
    const int before = std::abs(va - 6) + std::abs(vb - 6) + std::abs(vc - 6) + std::abs(vd - 6);
    const int after = std::abs(va - 7) + std::abs(vb - 7) + std::abs(vc - 5) + std::abs(vd - 5);
    if (after < before && flip_keeps_normals(sm, h)) CGAL::Euler::flip_edge(h, sm);
  }
}

// The faces of `sm` that are not degenerate, as triangles (what CGAL's remeshing projects onto).
Triangles surface_triangles(const SM& sm) {
  Triangles triangles;
  triangles.reserve(sm.number_of_faces());
  for (auto f : sm.faces()) {
    const SM::Halfedge_index h = sm.halfedge(f);
    const K::Triangle_3 t(sm.point(sm.source(h)), sm.point(sm.target(h)),
                          sm.point(sm.target(sm.next(h))));
    if (!t.is_degenerate()) triangles.push_back(t);
  }
  return triangles;
}

// Moves every vertex of `sm` to its closest point on `surface` (surface_triangles).
void project_onto(SM& sm, const Triangles& surface) {
  if (surface.empty()) return;
  const Tree tree(surface.begin(), surface.end());
  for (auto v : sm.vertices()) sm.point(v) = tree.closest_point(sm.point(v));
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
  snap_to_grid(mesh);
  SM sm = to_surface_mesh(mesh);
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
  // Three rounds of isotropic remeshing, each step on its own on a mesh in centred order (see
  // "the same remeshing on every CGAL" above): CGAL splits the edges longer than 4/3 L, then
  // collapses those shorter than 4/5 L; our flips even the valences; the vertices go back onto
  // the round's starting surface (CGAL projects onto the surface it is called with, so one call
  // per round did the same); then one tangential relaxation. The relaxation is called on its
  // own, not by the remesher: CGAL 5.5's remesher relaxes with an edge-constraint map that reads
  // its halfedge status at a null halfedge when every face around a vertex has become
  // degenerate (an out-of-bounds read, a segfault under ASan: the fuzzer found it on a sliver
  // tetrahedron, tests/fuzz/corpus/prepare/crash-remesh-sliver-tetrahedron; CGAL issue 7345,
  // fixed in 5.6). On its own the relaxation reads a constant map there. Measured against one
  // remeshing call of 3 iterations with 1 relaxation step each: the 43 public, stress and
  // rigged meshes keep their ends, cycles and joints but 3 (Fox 1 -> 2 joints, Mannequiny 3 ->
  // 2, Q_Horse 2 -> 1), 40 instead of 38 stable, rig-quality mean 4.29 / 2.94 / 3.42 -> 4.25 /
  // 2.90 / 3.36, stage 0 3-10% slower on the 16 remeshed meshes.
  const auto step = CGAL::parameters::number_of_iterations(1)
                        .number_of_relaxation_steps(0)
                        .do_split(false)
                        .do_collapse(false)
                        .do_flip(false)
                        .do_project(false)
                        .vertex_is_constrained_map(not_constrained);
  sm = canonical(sm);
  for (int iteration = 0; iteration < 3; ++iteration) {
    const Triangles start = surface_triangles(sm);
    PMP::isotropic_remeshing(faces(sm), L, sm, step.do_split(true));
    sm = canonical(sm);
    PMP::isotropic_remeshing(faces(sm), L, sm, step.do_collapse(true));
    sm = canonical(sm);
    equalize_valences(sm);
    project_onto(sm, start);
    poll(0.8);
    PMP::tangential_relaxation(
        vertices(sm), sm,
        CGAL::parameters::number_of_iterations(1).vertex_is_constrained_map(not_constrained));
    sm = canonical(sm);
  }
  sm.collect_garbage();
  poll(1.0);
  return mesh_from_surface_mesh(sm, "remeshing failed: the result");
}

}  // namespace dcg::internal

// The union of a mesh's closed parts for stage 0. See union.h.
//
// Why: multi-part characters (a body with detached eyes, game meshes whose limbs are separate
// closed shells pushed into the torso) are closed manifolds part by part, and the alpha wrap that
// repairs them at 1/100 of the diagonal took 2-4 s on 2k-5k faces (Q_Spider, Q_Snake): it
// rebuilds the whole surface from a Delaunay refinement of about 15,000 faces. Their union by
// corefinement takes 10-60 ms there and keeps the input's own surface (nothing offset, thin limbs
// and the gaps between them exactly as modelled).
#include "union.h"

#include <algorithm>
#include <array>
#include <exception>
#include <vector>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/bbox.h>
#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/Polygon_mesh_processing/corefinement.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include "dcg/errors.h"
#include "surface_mesh_convert.h"
#include "union_find.h"

namespace dcg::internal {
namespace {

namespace PMP = CGAL::Polygon_mesh_processing;
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;
using SM = CGAL::Surface_mesh<Point>;

// A part fit for corefinement: closed, not self-intersecting, enclosing a volume; turned
// outward in place.
bool closed_solid(SM& part) {
  if (!CGAL::is_closed(part) || !CGAL::is_triangle_mesh(part)) return false;
  if (PMP::does_self_intersect(part)) return false;
  if (!PMP::is_outward_oriented(part)) PMP::reverse_face_orientations(part);
  return PMP::volume(part) > 0;
}

// Groups of parts whose bounding boxes overlap (transitively): only these can intersect.
std::vector<std::vector<std::size_t>> overlapping_groups(const std::vector<SM>& parts) {
  std::vector<CGAL::Bbox_3> boxes;
  boxes.reserve(parts.size());
  for (const SM& p : parts) boxes.push_back(PMP::bbox(p));
  UnionFind uf(static_cast<int>(parts.size()));
  for (std::size_t i = 0; i < parts.size(); ++i)
    for (std::size_t j = i + 1; j < parts.size(); ++j)
      if (CGAL::do_overlap(boxes[i], boxes[j])) uf.unite(static_cast<int>(i), static_cast<int>(j));
  std::vector<std::vector<std::size_t>> groups(parts.size());
  for (std::size_t i = 0; i < parts.size(); ++i) {
    groups[uf.find(static_cast<int>(i))].push_back(i);
  }
  groups.erase(
      std::remove_if(groups.begin(), groups.end(), [](const auto& g) { return g.empty(); }),
      groups.end());
  return groups;
}

}  // namespace

std::optional<Mesh> union_of_closed_parts(const Mesh& mesh,
                                          const std::function<void(double)>& poll_in) {
  const std::function<void(double)> poll = poll_in ? poll_in : [](double) {};
  std::vector<Point> points;
  points.reserve(mesh.V.rows());
  for (Eigen::Index i = 0; i < mesh.V.rows(); ++i) {
    points.emplace_back(mesh.V(i, 0), mesh.V(i, 1), mesh.V(i, 2));
  }
  std::vector<std::array<std::size_t, 3>> faces;
  faces.reserve(mesh.F.rows());
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    faces.push_back({static_cast<std::size_t>(mesh.F(f, 0)), static_cast<std::size_t>(mesh.F(f, 1)),
                     static_cast<std::size_t>(mesh.F(f, 2))});
  }
  // Orienting the soup splits pinched vertices (and non-manifold edges, whose parts then come
  // out open and are refused below) into one vertex per fan.
  PMP::orient_polygon_soup(points, faces);
  if (!PMP::is_polygon_soup_a_polygon_mesh(faces)) return std::nullopt;
  SM whole;
  PMP::polygon_soup_to_polygon_mesh(points, faces, whole);
  poll(0.1);
  std::vector<SM> parts;
  PMP::split_connected_components(whole, parts);
  for (SM& part : parts) {
    if (!closed_solid(part)) return std::nullopt;
  }
  poll(0.3);
  Mesh out;
  std::vector<Mesh> shells;
  const auto groups = overlapping_groups(parts);
  std::size_t done = 0;
  try {
    for (const auto& group : groups) {
      SM united = parts[group[0]];
      for (std::size_t k = 1; k < group.size(); ++k) {
        poll(0.3 + 0.6 * static_cast<double>(done++) / static_cast<double>(parts.size()));
        SM result;
        if (!PMP::corefine_and_compute_union(united, parts[group[k]], result)) return std::nullopt;
        united = std::move(result);
      }
      if (group.size() > 1 && (!CGAL::is_closed(united) || PMP::does_self_intersect(united))) {
        return std::nullopt;
      }
      shells.push_back(mesh_from_surface_mesh(united, "the union of the parts"));
    }
  } catch (const Cancelled&) {
    throw;
  } catch (const std::exception&) {
    // CGAL's corefinement throws on input it cannot take (a self-intersection it found, a
    // degenerate configuration): the caller wraps instead.
    return std::nullopt;
  }
  poll(0.9);
  Eigen::Index nv = 0, nf = 0;
  for (const Mesh& s : shells) {
    nv += s.V.rows();
    nf += s.F.rows();
  }
  out.V.resize(nv, 3);
  out.F.resize(nf, 3);
  nv = nf = 0;
  for (const Mesh& s : shells) {
    out.V.middleRows(nv, s.V.rows()) = s.V;
    out.F.middleRows(nf, s.F.rows()) = s.F.array() + static_cast<int>(nv);
    nv += s.V.rows();
    nf += s.F.rows();
  }
  return out;
}

}  // namespace dcg::internal

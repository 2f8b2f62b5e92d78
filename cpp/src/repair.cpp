// CGAL alpha wrap for stage 0's repair. See repair.h.
#include "repair.h"

#include <array>
#include <string>
#include <vector>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/alpha_wrap_3.h>

#include "dcg/errors.h"

namespace dcg::internal {
namespace {

// Calls `poll` before each facet the flood fill treats (the fraction is unknown: reported as 0
// until the fill ends).
struct PollingVisitor : CGAL::Alpha_wraps_3::internal::Wrapping_default_visitor {
  const std::function<void(double)>* poll = nullptr;
  template <typename Wrapper, typename Gate>
  void before_facet_treatment(const Wrapper&, const Gate&) {
    if (*poll) (*poll)(0.0);
  }
  template <typename Wrapper>
  void on_flood_fill_end(const Wrapper&) {
    if (*poll) (*poll)(0.9);
  }
};

}  // namespace

Mesh alpha_wrap(const Mesh& soup, double alpha, double offset,
                const std::function<void(double)>& poll) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Point = K::Point_3;
  std::vector<Point> points;
  points.reserve(soup.V.rows());
  for (Eigen::Index i = 0; i < soup.V.rows(); ++i) points.emplace_back(soup.V(i, 0), soup.V(i, 1), soup.V(i, 2));
  std::vector<std::array<std::size_t, 3>> faces;
  faces.reserve(soup.F.rows());
  for (Eigen::Index f = 0; f < soup.F.rows(); ++f) {
    faces.push_back({static_cast<std::size_t>(soup.F(f, 0)), static_cast<std::size_t>(soup.F(f, 1)),
                     static_cast<std::size_t>(soup.F(f, 2))});
  }
  CGAL::Surface_mesh<Point> wrap;
  PollingVisitor visitor;
  visitor.poll = &poll;
  CGAL::alpha_wrap_3(points, faces, alpha, offset, wrap, CGAL::parameters::default_values(),
                     CGAL::parameters::visitor(visitor));
  if (poll) poll(1.0);
  if (wrap.number_of_faces() < 4) {
    throw InputError("repair failed: the alpha wrap (alpha " + std::to_string(alpha) +
                     ") of the mesh is empty");
  }
  Mesh out;
  out.V.resize(wrap.number_of_vertices(), 3);
  std::vector<int> index(wrap.num_vertices(), -1);
  int n = 0;
  for (auto v : wrap.vertices()) {
    const Point& p = wrap.point(v);
    out.V.row(n) << p.x(), p.y(), p.z();
    index[v.idx()] = n++;
  }
  out.F.resize(wrap.number_of_faces(), 3);
  int f = 0;
  for (auto face : wrap.faces()) {
    int k = 0;
    for (auto v : CGAL::vertices_around_face(wrap.halfedge(face), wrap)) {
      if (k < 3) out.F(f, k) = index[v.idx()];
      ++k;
    }
    if (k != 3) throw InputError("repair failed: the alpha wrap is not a triangle mesh");
    ++f;
  }
  return out;
}

}  // namespace dcg::internal

// SurfaceQuery: CGAL AABB tree over the mesh's triangles (a triangle soup, so any mesh can be
// queried), plus angle-weighted pseudo-normals for the inside test. See dcg/surface_query.h.
//
// Inside test: the closest point q of p on the surface and the pseudo-normal N of the feature
// (face, edge or vertex) that holds q give sign(dot(p - q, N)), exact for a closed, consistently
// oriented manifold (Baerentzen & Aanaes 2005) and one closest-point query cheap. When that
// sign is ambiguous (p on or extremely near the surface, or a degenerate feature) we fall back
// to ray-casting parity (majority of 3 rays; a ray that grazes an edge or vertex is re-drawn),
// which is what CGAL::Side_of_triangle_mesh does too.
#include "dcg/surface_query.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <random>
#include <vector>

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

namespace dcg {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;
using Triangle = K::Triangle_3;
using Iterator = std::vector<Triangle>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<K, Iterator>;
using Traits = CGAL::AABB_traits<K, Primitive>;
using Tree = CGAL::AABB_tree<Traits>;

inline Point to_cgal(const Eigen::Vector3d& p) { return Point(p.x(), p.y(), p.z()); }
inline Eigen::Vector3d to_eigen(const Point& p) { return {p.x(), p.y(), p.z()}; }

}  // namespace

struct SurfaceQuery::Impl {
  Mesh mesh;
  std::vector<Triangle> triangles;
  Tree tree;
  std::vector<Eigen::Vector3d> face_normal;    // unit (zero for degenerate faces)
  std::vector<Eigen::Vector3d> vertex_normal;  // angle-weighted pseudo-normals
  // Edge pseudo-normals: per face corner k, the edge (F(f,k), F(f,(k+1)%3)).
  std::vector<std::array<Eigen::Vector3d, 3>> edge_normal;
  double diag = 1.0;

  // Returns the closest point and its face; `normal` receives the pseudo-normal of the feature.
  Eigen::Vector3d closest(const Eigen::Vector3d& p, int* face, Eigen::Vector3d* normal) const {
    auto hit = tree.closest_point_and_primitive(to_cgal(p));
    const int f = static_cast<int>(hit.second - triangles.begin());
    Eigen::Vector3d q = to_eigen(hit.first);
    if (face) *face = f;
    if (normal) {
      const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)),
                            c = mesh.V.row(mesh.F(f, 2));
      // Barycentric coordinates of q in (a, b, c).
      const Eigen::Vector3d v0 = b - a, v1 = c - a, v2 = q - a;
      const double d00 = v0.dot(v0), d01 = v0.dot(v1), d11 = v1.dot(v1);
      const double d20 = v2.dot(v0), d21 = v2.dot(v1);
      const double den = d00 * d11 - d01 * d01;
      if (!(den > 0)) {
        *normal = Eigen::Vector3d::Zero();
      } else {
        const double l1 = (d11 * d20 - d01 * d21) / den, l2 = (d00 * d21 - d01 * d20) / den;
        const double l[3] = {1.0 - l1 - l2, l1, l2};
        const double eps = 1e-7;
        int small = 0, big = -1;
        for (int k = 0; k < 3; ++k) {
          if (l[k] < eps) ++small;
          else big = k;
        }
        if (small == 0) {
          *normal = face_normal[f];
        } else if (small == 1) {
          int k = 0;  // the corner with l ~ 0 is opposite to the edge holding q
          while (l[k] >= eps) ++k;
          *normal = edge_normal[f][(k + 1) % 3];
        } else {
          *normal = vertex_normal[mesh.F(f, big == -1 ? 0 : big)];
        }
      }
    }
    return q;
  }

  // Parity of ray crossings, majority of 3 non-grazing rays. Returns true when inside.
  bool ray_inside(const Eigen::Vector3d& p) const {
    std::mt19937 rng(12345);  // local, deterministic; thread-safe
    std::normal_distribution<double> g;
    int votes_in = 0, votes = 0;
    for (int attempt = 0; attempt < 30 && votes < 3; ++attempt) {
      Eigen::Vector3d d(g(rng), g(rng), g(rng));
      if (d.norm() < 1e-12) continue;
      d.normalize();
      K::Ray_3 ray(to_cgal(p), to_cgal(p + d));
      std::vector<Tree::Intersection_and_primitive_id<K::Ray_3>::Type> hits;
      tree.all_intersections(ray, std::back_inserter(hits));
      bool grazing = false;
      for (const auto& h : hits) {
        const Point* x = boost::get<Point>(&h.first);
        if (!x) { grazing = true; break; }  // a segment: the ray runs along a face
        const int f = static_cast<int>(h.second - triangles.begin());
        const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)),
                              c = mesh.V.row(mesh.F(f, 2));
        const Eigen::Vector3d n = (b - a).cross(c - a);
        const double area2 = n.norm();
        if (!(area2 > 0)) { grazing = true; break; }
        const Eigen::Vector3d q = to_eigen(*x);
        const double la = (c - b).cross(q - b).dot(n) / (area2 * area2);
        const double lb = (a - c).cross(q - c).dot(n) / (area2 * area2);
        const double lc = 1.0 - la - lb;
        if (std::min({la, lb, lc}) < 1e-9 || (q - p).norm() < 1e-12 * diag) { grazing = true; break; }
      }
      if (grazing) continue;
      ++votes;
      if (hits.size() % 2 == 1) ++votes_in;
    }
    return votes > 0 && 2 * votes_in > votes;
  }
};

SurfaceQuery::SurfaceQuery(const Mesh& mesh) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.mesh = mesh;
  const auto& V = m.mesh.V;
  const auto& F = m.mesh.F;
  const int nv = static_cast<int>(V.rows()), nf = static_cast<int>(F.rows());
  if (nv > 0) m.diag = (V.colwise().maxCoeff() - V.colwise().minCoeff()).norm();
  if (!(m.diag > 0)) m.diag = 1.0;
  m.triangles.reserve(nf);
  m.face_normal.resize(nf);
  m.vertex_normal.assign(nv, Eigen::Vector3d::Zero());
  m.edge_normal.resize(nf);
  std::map<std::pair<int, int>, Eigen::Vector3d> edge_sum;
  for (int f = 0; f < nf; ++f) {
    const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    m.triangles.emplace_back(to_cgal(a), to_cgal(b), to_cgal(c));
    Eigen::Vector3d n = (b - a).cross(c - a);
    const double len = n.norm();
    m.face_normal[f] = len > 0 ? Eigen::Vector3d(n / len) : Eigen::Vector3d::Zero();
    const Eigen::Vector3d P[3] = {a, b, c};
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d e1 = P[(k + 1) % 3] - P[k], e2 = P[(k + 2) % 3] - P[k];
      const double l1 = e1.norm(), l2 = e2.norm();
      double angle = 0;
      if (l1 > 0 && l2 > 0) angle = std::acos(std::clamp(e1.dot(e2) / (l1 * l2), -1.0, 1.0));
      m.vertex_normal[F(f, k)] += angle * m.face_normal[f];
      int i = F(f, k), j = F(f, (k + 1) % 3);
      if (i > j) std::swap(i, j);
      auto it = edge_sum.emplace(std::make_pair(i, j), Eigen::Vector3d::Zero()).first;
      it->second += m.face_normal[f];
    }
  }
  for (int f = 0; f < nf; ++f) {
    for (int k = 0; k < 3; ++k) {
      int i = F(f, k), j = F(f, (k + 1) % 3);
      if (i > j) std::swap(i, j);
      m.edge_normal[f][k] = edge_sum[{i, j}];
    }
  }
  m.tree.insert(m.triangles.begin(), m.triangles.end());
  m.tree.build();
  m.tree.accelerate_distance_queries();
  // Force the lazily built search structure now, so that const queries never mutate the tree.
  if (nf > 0) m.tree.closest_point(to_cgal(V.row(0).transpose()));
}

SurfaceQuery::~SurfaceQuery() = default;
SurfaceQuery::SurfaceQuery(SurfaceQuery&&) noexcept = default;
SurfaceQuery& SurfaceQuery::operator=(SurfaceQuery&&) noexcept = default;

Eigen::Vector3d SurfaceQuery::closest_point(const Eigen::Vector3d& p, int* face) const {
  return impl_->closest(p, face, nullptr);
}

double SurfaceQuery::distance(const Eigen::Vector3d& p) const {
  return (impl_->closest(p, nullptr, nullptr) - p).norm();
}

double SurfaceQuery::signed_distance(const Eigen::Vector3d& p) const {
  Eigen::Vector3d n;
  const Eigen::Vector3d q = impl_->closest(p, nullptr, &n);
  const Eigen::Vector3d d = p - q;
  const double dist = d.norm();
  if (dist == 0) return 0.0;
  const double s = d.dot(n);
  const double nn = n.norm();
  // Trust the pseudo-normal unless the sign is nearly undecided.
  if (nn > 1e-12 && std::abs(s) > 1e-6 * dist * nn && dist > 1e-12 * impl_->diag) {
    return s < 0 ? -dist : dist;
  }
  return impl_->ray_inside(p) ? -dist : dist;
}

bool SurfaceQuery::inside(const Eigen::Vector3d& p) const { return signed_distance(p) < 0; }

bool SurfaceQuery::segment_inside(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const {
  if (!inside(a) || !inside(b)) return false;
  if ((a - b).norm() == 0) return true;
  return !impl_->tree.do_intersect(K::Segment_3(to_cgal(a), to_cgal(b)));
}

}  // namespace dcg

// Inward chords (chords.h).
#include "chords.h"

#include <cmath>
#include <vector>

namespace dcg::internal {

std::optional<Eigen::Vector3d> chord_middle(const SurfaceQuery& query, const Eigen::Vector3d& start,
                                            const Eigen::Vector3d& d) {
  const double wall = query.ray_hit(start, d);
  if (!std::isfinite(wall)) return std::nullopt;
  const Eigen::Vector3d p = start + 0.5 * wall * d;
  if (!query.inside(p)) return std::nullopt;
  return p;
}

Eigen::Vector3d inward_point(const Mesh& mesh, const SurfaceQuery& query, int vertex,
                             const Eigen::Vector3d& toward, double* radius) {
  *radius = 0;
  if (vertex < 0 || vertex >= mesh.V.rows()) return Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero(), ring = Eigen::Vector3d::Zero();
  int corners = 0;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    if (mesh.F(f, 0) != vertex && mesh.F(f, 1) != vertex && mesh.F(f, 2) != vertex) continue;
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)),
                          c = mesh.V.row(mesh.F(f, 2));
    normal += (b - a).cross(c - a);
    ring += a + b + c;
    corners += 3;
  }
  const Eigen::Vector3d peak = mesh.V.row(vertex).transpose();
  std::vector<Eigen::Vector3d> directions;
  if (normal.norm() > 0) directions.push_back(-normal.normalized());
  if (corners > 0 && (ring / corners - peak).norm() > 0) {
    directions.push_back((ring / corners - peak).normalized());  // a folded tip: its 1-ring
  }
  if ((toward - peak).norm() > 0) directions.push_back((toward - peak).normalized());
  if (normal.norm() > 0) directions.push_back(normal.normalized());
  for (const Eigen::Vector3d& d : directions) {
    const Eigen::Vector3d start = peak + 1e-6 * d;
    if (!query.inside(start)) continue;
    if (const auto p = chord_middle(query, start, d)) {
      *radius = query.distance(*p);
      return *p;
    }
  }
  return Eigen::Vector3d::Zero();
}

}  // namespace dcg::internal

// Geometric queries against a closed triangle mesh: closest point, distance, inside tests.
// Shared by the stages that need them (Voronoi balls, domain balls, links). Built once per mesh
// (an AABB tree inside; CGAL stays in the .cpp). Thread-safe for concurrent const queries.
#pragma once

#include <memory>

#include <Eigen/Core>

#include "dcg/types.h"

namespace dcg {

class SurfaceQuery {
 public:
  /// `mesh` must be closed and oriented for the inside tests to mean anything.
  explicit SurfaceQuery(const Mesh& mesh);
  ~SurfaceQuery();
  SurfaceQuery(SurfaceQuery&&) noexcept;
  SurfaceQuery& operator=(SurfaceQuery&&) noexcept;

  /// Closest point on the surface to p; `face` (if given) receives its face index.
  Eigen::Vector3d closest_point(const Eigen::Vector3d& p, int* face = nullptr) const;
  /// Unsigned distance from p to the surface.
  double distance(const Eigen::Vector3d& p) const;
  /// Distance to the surface, negative inside (the sign of inside()); 0 on the surface.
  double signed_distance(const Eigen::Vector3d& p) const;
  /// True when p is strictly inside the closed surface (points on it count as outside).
  bool inside(const Eigen::Vector3d& p) const;
  /// True when both ends are inside and the segment a-b does not cross the surface.
  bool segment_inside(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dcg

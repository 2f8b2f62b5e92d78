// Geometric queries against a closed triangle mesh: closest point, distance, inside tests, rays.
// Shared by the stages that need them (Voronoi balls, domain balls, links). Built once per mesh
// (an Embree BVH inside; Embree stays in the .cpp). Thread-safe for concurrent const queries.
// Closest points and distances are exact in double precision; ray and segment tests run in
// Embree's float precision (about 1e-7 of the mesh's size).
#pragma once

#include <functional>
#include <memory>

#include <Eigen/Core>

#include "dcg/types.h"

namespace dcg {

class SurfaceQuery {
 public:
  /// `mesh` must be closed and oriented for the inside tests to mean anything. InputError when
  /// it has no faces or an index out of range.
  explicit SurfaceQuery(const Mesh& mesh);
  /// The same, calling `poll` every few milliseconds while it builds (for meshes of millions of
  /// faces); an exception from `poll` (Cancelled) stops the build and propagates.
  SurfaceQuery(const Mesh& mesh, const std::function<void()>& poll);
  ~SurfaceQuery();
  SurfaceQuery(SurfaceQuery&&) noexcept;
  SurfaceQuery& operator=(SurfaceQuery&&) noexcept;

  /// Closest point on the surface to p; `face` (if given) receives its face index.
  Eigen::Vector3d closest_point(const Eigen::Vector3d& p, int* face = nullptr) const;
  /// The same with a hint, a point on face `hint_face` near p (as for signed_distance below):
  /// the result does not depend on it. hint_face < 0: no hint.
  Eigen::Vector3d closest_point(const Eigen::Vector3d& p, const Eigen::Vector3d& hint,
                                int hint_face, int* face = nullptr) const;
  /// Unsigned distance from p to the surface.
  double distance(const Eigen::Vector3d& p) const;
  /// Distance to the surface, negative inside (the sign of inside()); 0 on the surface.
  double signed_distance(const Eigen::Vector3d& p) const;
  /// The same with a hint: `hint` is a point on face `hint_face` of the mesh, near p (e.g. the
  /// surface sample whose Delaunay cell gave p). Its distance bounds the search, which makes the
  /// query several times faster; the result does not depend on the hint. hint_face < 0: no hint.
  double signed_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& hint,
                         int hint_face) const;
  /// Number of triangles of the mesh the query was built on.
  int face_count() const;
  /// True when p is strictly inside the closed surface (points on it count as outside).
  bool inside(const Eigen::Vector3d& p) const;
  /// The same by ray parity alone (majority of 3 rays that graze no edge): slower, but it does
  /// not depend on the faces' orientation (a mirrored input's winding is inside out).
  bool inside_by_parity(const Eigen::Vector3d& p) const;
  /// Distance from `origin` along `direction` (any length) to the first surface hit, infinity
  /// when the ray hits nothing; `face` (if given) receives the face hit.
  double ray_hit(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                 int* face = nullptr) const;
  /// True when both ends are inside and the segment a-b does not cross the surface.
  bool segment_inside(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const;

  // --- batched rays (Embree packets of 8; the hot paths of stages 4-7) ---------------------

  /// One fan of rays from `origin`: for each of the `count` unit directions (count x 3 floats,
  /// row by row) the distance to the first surface hit in t[k] (infinity when none) and, when
  /// `from_inside` is given, whether that hit sees the back of the face (the ray leaves the
  /// shape there: 1) or its front / nothing (0). A point strictly inside a closed, outward
  /// oriented mesh gets 1 for every ray. Cast as Embree packets of 8.
  /// `faces` (if given) receives the face hit by each ray (-1 when none).
  void ray_fan(const Eigen::Vector3d& origin, const float* directions, int count, double* t,
               unsigned char* from_inside = nullptr, int* faces = nullptr) const;
  /// Unit outward normal of face f of the mesh (zero for a degenerate face).
  const Eigen::Vector3d& face_normal(int f) const;
  /// For each of `count` segments a_i-b_i (count x 3 doubles each, row by row): 1 in
  /// `blocked[i]` when the segment, trimmed by `trim` (a fraction of its length) at both ends,
  /// meets the surface, else 0. No inside test of the ends: the visibility test of a point and
  /// a surface point (a face's centroid), or of two points known to be inside.
  void segments_blocked(const double* a, const double* b, int count, double trim,
                        unsigned char* blocked) const;
  /// One segment, see segments_blocked().
  bool segment_blocked(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double trim = 0) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dcg

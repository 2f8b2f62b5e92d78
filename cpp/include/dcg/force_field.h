// Stage 4 (ALGORITHM.md "Repulsive force field", paper section 4): the visibility repulsive
// force of the surface on a point inside the shape,
//
//     F(p) = -(1/K) sum_k u_k / r_k^n,
//
// over K unit directions u_k (a Fibonacci sphere, `rays`), r_k the distance from p along u_k to
// the surface (an Embree ray), n = `force_exponent`. A wall near p in direction u pushes p away
// from it (the minus sign). |F(p)| is the paper's level iso-surface function: small on the
// "balanced" medial positions, large near the surface. F has the units of 1 / length^n.
//
// Rays are cast as Embree packets of 8 from each point; batches of points run in parallel (TBB).
// Every ray also says whether it left the shape through the back of a face: a point strictly
// inside a closed, outward-oriented mesh sees only backs, so `outside_rays` > 0 means that p is
// outside or on the surface (or that a ray slipped through a crack of the mesh).
#pragma once

#include <memory>
#include <vector>

#include <Eigen/Core>

#include "dcg/types.h"

namespace dcg {

class SurfaceQuery;

struct ForceFieldOptions {
  int rays = 64;                ///< K, directions per point (at least 6)
  double force_exponent = 1.0;  ///< n; larger n -> F dominated by the nearest wall (paper: 1)
};

/// The field at one point.
struct FieldSample {
  Eigen::Vector3d force = Eigen::Vector3d::Zero();  ///< F(p)
  double magnitude = 0;                             ///< |F(p)|
  double r_min = 0;      ///< shortest ray distance to the surface (>= the true distance)
  int outside_rays = 0;  ///< rays that hit nothing or the front of a face (0 inside)
  /// Gradient of |F| at p (filled by ForceField::at_with_gradient only): exact for the sampled
  /// field, each ray's distance differentiated against the plane of the face it hits,
  /// dr_k/dp = -N_k / (u_k . N_k) (|u_k . N_k| clamped at 0.2 for grazing hits).
  Eigen::Vector3d gradient = Eigen::Vector3d::Zero();
  bool inside() const { return outside_rays == 0; }
};

/// The field of a point set, row by row.
struct FieldSamples {
  Points force;                  ///< #P by 3 F(p)
  Eigen::VectorXd magnitude;     ///< #P |F(p)|
  Eigen::VectorXd r_min;         ///< #P shortest ray distance
  Eigen::VectorXi outside_rays;  ///< #P rays that did not leave through the back of a face
};

/// F on a closed mesh. Thread-safe for concurrent const calls; keeps the SurfaceQuery alive.
class ForceField {
 public:
  /// `query` on the closed working mesh (stage 0). InputError for rays < 6 or n <= 0.
  ForceField(std::shared_ptr<const SurfaceQuery> query, const ForceFieldOptions& options = {});

  /// F at one point (one fan of `rays` rays).
  FieldSample at(const Eigen::Vector3d& p) const;
  /// F at one point and the gradient of |F| there (the same fan of rays).
  FieldSample at_with_gradient(const Eigen::Vector3d& p) const;
  /// F at every row of `points` (#P by 3), in parallel.
  FieldSamples evaluate(const Points& points) const;
  /// Central-difference gradient of |F| at p along each of `axes` (unit vectors), step h:
  /// (|F|(p + h a) - |F|(p - h a)) / 2h per axis: a check on at_with_gradient's gradient
  /// (tests/cpp/test_force_field.cpp).
  Eigen::VectorXd magnitude_slopes(const Eigen::Vector3d& p,
                                   const std::vector<Eigen::Vector3d>& axes, double h) const;
  /// Mean |F| over `samples` points evenly spaced strictly inside the segment a-b (the link cost
  /// of stage 6), and whether every such point is inside (outside_rays == 0).
  double mean_magnitude(const Eigen::Vector3d& a, const Eigen::Vector3d& b, int samples,
                        bool* all_inside = nullptr) const;

  const ForceFieldOptions& options() const { return options_; }
  const SurfaceQuery& query() const { return *query_; }

 private:
  FieldSample sample(const Eigen::Vector3d& p, bool gradient) const;

  std::shared_ptr<const SurfaceQuery> query_;
  ForceFieldOptions options_;
  Eigen::Matrix<float, Eigen::Dynamic, 3, Eigen::RowMajor> directions_;
};

/// `count` unit directions spread evenly on the sphere (Fibonacci spiral), #count by 3.
Points fibonacci_sphere(int count);

}  // namespace dcg

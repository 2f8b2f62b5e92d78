// Stage 5 (ALGORITHM.md "Connection points", paper section 7): every domain point that is not an
// end point shrinks along the repulsive field of stage 4 to a local minimum of |F|, and the
// shrunk points are merged greedily into the connection points.
//
// Shrinking: p <- p + alpha * r_min(p)^(n+1) * F(p), with r_min the shortest ray distance at p
// and n the field's exponent, the step capped at r_min / 2 (|F| r_min^n <= 1, so with alpha
// <= 0.5 the cap never binds: a step cannot reach the wall it sees). A step that does not lower
// |F|, or whose segment meets the surface, or that ends with more rays escaping than at p, is
// refused and alpha halves. After an accepted step alpha doubles, up to max_growth x its start:
// near the medial "balance" |F| r_min^n is small and the plain rule of ALGORITHM.md crawls
// (a third of the points were still moving after 200 steps on a torus; with growth all stop,
// in a third of the steps, at the same minima). The point stops at a local minimum of |F|
// (max_halvings refusals in a row, a step below `arrived` x r_min, or three accepted steps in a
// row that lower |F| by less than 1e-4 of itself) or after max_steps steps. A point never leaves
// the shape: every accepted step is a segment that does not cross the surface.
//
// Merging: visit the shrunk points by increasing |F|; each one not yet absorbed absorbs every
// point not yet absorbed within merge_fraction times the smaller of their two radii (distance to
// the surface). Never by chaining: pairwise union would collapse a torus ring into a few points.
// The survivors, at their own positions, are the connection points.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "dcg/progress.h"
#include "dcg/types.h"

namespace dcg {

class ForceField;

struct ConnectionPointsOptions {
  double shrink_step = 0.5;  ///< alpha, the initial step factor (ALGORITHM.md: 0.5)
  int max_steps = 200;       ///< steps per point at most
  int max_halvings = 6;      ///< refused steps in a row that mean "local minimum"
  double max_growth = 8;     ///< alpha grows after accepted steps up to this x shrink_step
  /// A step below this x r_min ends the shrink. Near a minimum the steps shrink geometrically (by
  /// ~0.9 a step on the torus): 3e-3 stops within a few percent of r_min of where 1e-3 did, far
  /// inside the merge distance (merge_fraction x r), in 40% fewer fans on the torus, 12% on the
  /// hand. Against 1e-3 on all 43 public, stress and rigged meshes: the same ends, joints,
  /// cycles and stability; the torus's 6 connection points 0.4% of its extent away; merges that
  /// turned out otherwise (1-2 connection points more or fewer) on 10. 1e-2 changed the joints
  /// of 4 and the stability of 4.
  double arrived = 3e-3;
  double merge_fraction = 0.5;  ///< merge points closer than this x the smaller radius
};

struct ConnectionPoints {
  // Per domain point (#D), in the order given.
  Points shrunk;                     ///< #D by 3 positions after shrinking
  Eigen::VectorXd shrunk_magnitude;  ///< #D |F| there
  Eigen::VectorXd shrunk_radii;      ///< #D distance to the surface there
  Eigen::VectorXi steps;             ///< #D accepted steps
  std::vector<char> converged;       ///< #D stopped at a local minimum (else: step limit)
  Eigen::VectorXi cluster;           ///< #D index of the connection point that absorbed it
  // The connection points (#C), by increasing |F|.
  Points positions;           ///< #C by 3
  Eigen::VectorXd radii;      ///< #C distance to the surface
  Eigen::VectorXd magnitude;  ///< #C |F|
  Eigen::VectorXi source;     ///< #C the domain point each one is
};

/// domain_points: #D by 3 domain points (stage 2 centers; end points excluded), inside the closed
/// mesh of `field`. Points are shrunk in parallel (TBB); the result does not depend on threads.
/// Progress as stage "connection_points", see dcg/progress.h.
ConnectionPoints compute_connection_points(const Points& domain_points, const ForceField& field,
                                           const ConnectionPointsOptions& options = {},
                                           const Progress& progress = {}, double from = 0,
                                           double to = 1);

/// The greedy merge alone (exposed for tests): points #D by 3, magnitude #D, radii #D.
/// Returns #D cluster indices; survivors[c] is the point that cluster c keeps.
Eigen::VectorXi merge_greedily(const Points& points, const Eigen::VectorXd& magnitude,
                               const Eigen::VectorXd& radii, double merge_fraction,
                               std::vector<int>* survivors);

}  // namespace dcg

// Stage 7 (ALGORITHM.md "Re-mapping", paper section 8): every link of the graph becomes a
// polyline that follows the middle of the shape, fitted by a snake in the force field.
//
// A link a-b is sampled about every `spacing` x the larger radius of a and b, with at least
// `min_inner_points` and at most `max_inner_points` inner points.
// When the straight segment leaves the shape, the start is a path through `waypoints` (points
// known to be inside, e.g. the shrunk domain points) that see each other, shortest first.
//
// Snake: E = sum a |p[i+1] - 2p[i] + p[i-1]|^2 + b |p[i+1] - p[i]|^2 + c |F(p[i])| with the two
// nodes fixed; each inner point moves only in its plane normal to the chord a-b (the paper's
// cutting plane). The internal terms are solved semi-implicitly (one small solve per link and
// step: stable for any step), the external term is the gradient of |F| in the plane, scaled by
// r^(n+2) (r the local radius, n the field's exponent) so that it is a length. The gradient is
// the sampled field's own (ForceField::at_with_gradient, one fan of rays per point and step):
// four times cheaper than the central differences of ALGORITHM.md, which it matches (tested). At
// most `snake_iterations` steps; a link stops when no point moves more than `tolerance` x its
// radius (at least half the link's mean radius). A move whose segment meets the surface, or that
// would pull either of the point's polyline segments across it, is refused (the point stays).
#pragma once

#include <functional>
#include <vector>

#include <Eigen/Core>

#include "dcg/progress.h"
#include "dcg/types.h"

namespace dcg {

class ForceField;
class SurfaceQuery;

struct RemapOptions {
  int snake_iterations = 100;      ///< steps per link at most (ALGORITHM.md: 100)
  double curvature_weight = 0.05;  ///< a, weight of the second differences
  double stretch_weight = 0.005;   ///< b, weight of the first differences
  double field_weight = 1.0;       ///< c, weight of |F|
  double time_step = 0.5;          ///< step of the semi-implicit scheme
  double spacing = 1.0;            ///< inner points about every spacing x local radius
  int min_inner_points = 3;        ///< inner points per link at least
  int max_inner_points = 40;       ///< inner points per link at most
  double tolerance = 0.02;         ///< stop when moves are below this x the local radius
};

struct Remapped {
  std::vector<Points> polylines;  ///< #K polylines, node a .. node b inclusive (normalized units)
  Eigen::VectorXi iterations;     ///< #K snake steps run per link
  Eigen::VectorXi rerouted;       ///< #K 1 when the straight link left the shape and the snake
                                  ///<    started from a path through the waypoints
  int moves_refused = 0;          ///< point moves refused because they crossed the surface
  int unrouted = 0;               ///< links that left the shape with no path found (kept straight)
};

/// nodes: #N by 3 node positions inside the shape; radii: #N distance to the surface; links:
/// #K by 2 node pairs; waypoints: #W by 3 points inside the shape (for links that leave it).
/// more_waypoints (optional): called once when some link found no route through `waypoints`,
/// with the progress range it may report in; those links try again through both (denser points,
/// costlier to make: see pipeline.cpp's chord_midpoints below).
/// Links run in parallel (TBB); the result does not depend on threads.
/// Progress as stage "remap", see dcg/progress.h.
using MoreWaypoints = std::function<Points(const Progress& progress, double from, double to)>;
Remapped remap_links(const Points& nodes, const Eigen::VectorXd& radii, const Edges& links,
                     const ForceField& field, const Points& waypoints,
                     const RemapOptions& options = {}, const MoreWaypoints& more_waypoints = {},
                     const Progress& progress = {}, double from = 0, double to = 1);

/// Waypoints for links no other waypoint routes: the middle of the inward chord from each
/// face's centroid of `mesh` (along minus its normal), for the faces whose chord ends on the
/// surface and whose middle is inside: one point in the middle of the shape behind every face,
/// thin parts included. `surface` is a SurfaceQuery of `mesh`.
/// Progress as stage "remap", see dcg/progress.h.
Points chord_midpoints(const Mesh& mesh, const SurfaceQuery& surface, const Progress& progress = {},
                       double from = 0, double to = 1);

}  // namespace dcg

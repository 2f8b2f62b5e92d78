// Stage 3's end points (ALGORITHM.md "3. Prong features"): a ball inside the shape for each
// prong, and the points stage 6 links (connection points, then end points).
#pragma once

#include <Eigen/Core>

#include "dcg/connection_points.h"
#include "dcg/prongs.h"
#include "dcg/types.h"

namespace dcg {

class SurfaceQuery;

/// Each prong's end point (ALGORITHM.md stage 3): the Voronoi ball of stage 1 nearest to the
/// prong's peak (center distance), among those with radius >= min_radius and that see the peak
/// (the segment from the center to the peak meets the surface only at the peak's end), strongest
/// prongs first; two prongs never share a ball.
struct EndPoints {
  Eigen::VectorXi ball;   ///< #P index into the stage-1 balls; -1 when no ball sees the peak
  Points centers;         ///< #P by 3 end points (ball centers; the peak itself when ball is -1)
  Eigen::VectorXd radii;  ///< #P ball radii (0 when ball is -1)
};

/// prongs: from compute_prongs on the mesh of `query`; balls: stage 1 on the same mesh;
/// min_radius: ALGORITHM.md uses half the domain balls' min_radius.
EndPoints find_end_points(const Prongs& prongs, const Balls& balls, const SurfaceQuery& query,
                          double min_radius);

/// The points stage 6 links, in this order: the connection points (#C), the end points that
/// have a ball (by prong), then an end point for each prong that no stage-1 ball sees (a thin,
/// curled tip) and that unseen_end_point() finds.
struct GraphPoints {
  Points points;          ///< #P by 3 (normalized units)
  Eigen::VectorXd radii;  ///< #P distance to the surface
  Eigen::VectorXi prong;  ///< #P prong index of an end point, -1 for connection points
};

/// connection: stage 5; ends: find_end_points of `prongs`; working, query: stage 0's working
/// mesh and its SurfaceQuery; domain_points: the stage-2 centers (#D by 3).
GraphPoints graph_points(const ConnectionPoints& connection, const EndPoints& ends,
                         const Prongs& prongs, const Mesh& working, const SurfaceQuery& query,
                         const Points& domain_points);

/// The end point of prong `p` when no ball sees its peak: the middle of the inward chord from
/// the peak vertex; if that is not inside (a tip folded through itself by vertex noise), the
/// first point inside on the segment toward the nearest domain point; if none (a tip crumpled
/// all around its peak), the inward chord of the nearest working-mesh vertex within 0.03 of the
/// peak that lands inside by both inside tests. `radius` receives the distance to the surface,
/// 0 when nothing is found.
Eigen::Vector3d unseen_end_point(const Prongs& prongs, Eigen::Index p, const Mesh& working,
                                 const SurfaceQuery& query, const Points& domain_points,
                                 double* radius);

}  // namespace dcg

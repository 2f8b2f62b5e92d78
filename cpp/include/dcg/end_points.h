// Stage 3's end points (ALGORITHM.md "3. Prong features"): a ball inside the shape for each
// prong, and the points stage 6 links (connection points, then end points).
#pragma once

#include <Eigen/Core>

#include "dcg/connection_points.h"
#include "dcg/prongs.h"
#include "dcg/types.h"

namespace dcg {

class SurfaceQuery;

/// A ball that sees its peak from farther than both of these stands in for the prong poorly: it
/// sees the peak down a part too thin for any ball of min_radius (a spider's shin, a wing's
/// membrane), and a bone to it would stop short of the tip by the whole thin part. Radii of the
/// ball; the second in the working mesh's unit, its bounding-box diagonal. find_end_points passes
/// such balls over, up to kEndBallSearch times the first one's distance from the peak.
///
/// Of the 157 balls that ended a prong of the public and rigged meshes before this rule, 7 lie
/// beyond both (16-76 radii, 0.065-0.147 away): Q_Spider's and Q_Wasp's legs past the knee and
/// Q_Dragon's wing tips, whose bones now reach the tip (and no longer fold back at Q_Dragon's);
/// one of Q_Dragon's has a wider ball beside it that ends it instead. Beyond one only: 10 at 11-32
/// radii but at most 0.047 away (Q_Zombie's palms, 0.024 and 0.042, serve its hands well), and 3
/// at 0.052-0.136 but within 1.4 radii (the wide round ends of eight and SkinnedCylinder).
inline constexpr double kEndBallFarRadii = 10.0;
inline constexpr double kEndBallFarGap = 0.05;
/// How far past the first passed-over ball find_end_points looks for a nearer one (a capsule's
/// round tip can have a sliver of a ball in front of its own), as a multiple of its distance.
inline constexpr double kEndBallSearch = 2.0;

/// Each prong's end point (ALGORITHM.md stage 3): the Voronoi ball of stage 1 nearest to the
/// prong's peak (center distance), among those with radius >= min_radius and that see the peak
/// (the segment from the center to the peak meets the surface only at the peak's end), strongest
/// prongs first; two prongs never share a ball. A ball farther from the peak than
/// kEndBallFarRadii of its radii and kEndBallFarGap is passed over (up to kEndBallSearch times
/// the first such ball's distance); a prong left without a ball gets the point
/// unseen_end_point() finds by its peak.
struct EndPoints {
  Eigen::VectorXi ball;  ///< #P index into the stage-1 balls; -1 when no ball near it sees the peak
  Points centers;        ///< #P by 3 end points (ball centers; the peak itself when ball is -1)
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

/// The end point of prong `p` when no ball near it sees its peak: the middle of the inward chord
/// from the peak vertex; if that is not inside (a tip folded through itself by vertex noise), the
/// first point inside on the segment toward the nearest domain point; if none (a tip crumpled
/// all around its peak), the inward chord of the nearest working-mesh vertex within 0.03 of the
/// peak that lands inside by both inside tests. `radius` receives the distance to the surface,
/// 0 when nothing is found.
Eigen::Vector3d unseen_end_point(const Prongs& prongs, Eigen::Index p, const Mesh& working,
                                 const SurfaceQuery& query, const Points& domain_points,
                                 double* radius);

}  // namespace dcg

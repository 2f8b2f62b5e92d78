// The mirror plane of a shape (the issue "An animator's rig": a skeleton mirror-symmetric across
// the shape's own plane). The bone planner (bindings/dcg/symmetry.py) mirrors the skeleton across
// the plane of its nodes when they have one; an exactly symmetric shape whose skeleton is not
// (an end point on one of two horns, end balls placed a little differently on either side) gets
// this plane of the surface instead.
#pragma once

#include <Eigen/Core>

#include "dcg/types.h"

namespace dcg {

class SurfaceQuery;

/// A mirror plane normal . x = offset of a surface.
struct MirrorPlane {
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  ///< unit; its largest component positive
  double offset = 0;
  /// Mean distance from the sampled vertices mirrored across the plane to the surface, over
  /// the bounding-box diagonal; 1 when no candidate plane was tried (a flat or empty mesh).
  double error = 1;
};

/// Vertices sampled (evenly by index) for the mirror test.
constexpr int kMirrorSamples = 250;

/// The best mirror plane of the closed mesh behind `surface` (its vertices `mesh.V`): candidates
/// the coordinate planes and the principal planes through the centroid (a principal axis within
/// 10 degrees of a coordinate axis tried once), each refitted once (to the plane halfway between
/// the samples and the surface points nearest their mirror images), the best one then refitted
/// again while that lowers its error; a plane the shape nearly lies in (fewer than a quarter of the
/// samples farther than 3% of the diagonal from it) mirrors it trivially and is skipped. As
/// dcg.symmetry.mirror_plane does for points, with the surface instead of the points as the mirror
/// image's target.
MirrorPlane find_mirror_plane(const Mesh& mesh, const SurfaceQuery& surface);

}  // namespace dcg

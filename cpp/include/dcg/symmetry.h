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

/// The best mirror plane of the closed mesh behind `surface` (its vertices `mesh.V`): searched
/// from 13 start normals (a cube's axes of symmetry: its faces', edges' and corners' directions,
/// so one lies within 20 degrees of any plane) and the principal axes through the centroid, each
/// refitted a few times on a quarter of the samples, the three best then on all of them while
/// that lowers their error, the best of those chosen. A refit is a Gauss-Newton step of the
/// point-to-plane distances from the samples' mirror images to the surface (each along the
/// surface's normal at its nearest point), which converges on the plane in any orientation (to
/// a fraction of a degree on the rigged characters rotated at random) where the nearest points'
/// midpoints crept. A plane the shape nearly lies in (fewer than a quarter of the samples
/// farther than 3% of the diagonal from it) mirrors it trivially and is skipped.
MirrorPlane find_mirror_plane(const Mesh& mesh, const SurfaceQuery& surface);

}  // namespace dcg

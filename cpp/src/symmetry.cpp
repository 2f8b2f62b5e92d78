// The mirror plane of a surface. See dcg/symmetry.h.
#include "dcg/symmetry.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include <Eigen/Eigenvalues>

#include "dcg/surface_query.h"

namespace dcg {
namespace {

// A sample lies off a plane when farther than this from it (diagonals): a plane with fewer than
// kMinOffPlane of the samples off it is one the shape lies in.
constexpr double kOffPlane = 0.03;
constexpr double kMinOffPlane = 0.25;
constexpr int kPolishRounds = 6;
// Normals closer than this (cosine: 10 degrees) refine to the same plane.
constexpr double kSameAxis = 0.985;

// A plane normal . x = offset.
struct Plane {
  Eigen::Vector3d normal;
  double offset = 0;
};

// How far `samples` mirrored across `plane` land from the surface (mean distance), and the plane
// halfway between each sample and the surface point nearest its mirror image (the refit).
struct Fit {
  double error = 0;
  Plane refit;
};

Fit mirror_fit(const Eigen::MatrixX3d& samples, const Plane& plane, const SurfaceQuery& surface) {
  Fit fit;
  Eigen::Vector3d gaps = Eigen::Vector3d::Zero(), midpoints = Eigen::Vector3d::Zero();
  for (Eigen::Index i = 0; i < samples.rows(); ++i) {
    const Eigen::Vector3d p = samples.row(i).transpose();
    const Eigen::Vector3d mirrored = p - 2 * (plane.normal.dot(p) - plane.offset) * plane.normal;
    const Eigen::Vector3d partner = surface.closest_point(mirrored);
    fit.error += (partner - mirrored).norm();
    const Eigen::Vector3d gap = p - partner;
    gaps += gap.dot(plane.normal) < 0 ? -gap : gap;
    midpoints += (p + partner) / 2;
  }
  const double n = static_cast<double>(samples.rows());
  fit.error /= n;
  fit.refit.normal = gaps.norm() > 1e-12 ? gaps.normalized() : plane.normal;
  fit.refit.offset = fit.refit.normal.dot(midpoints / n);
  return fit;
}

// A plane tried: where it is, its error there, and its refit.
struct Tried {
  Plane plane;
  Fit fit;
};

}  // namespace

MirrorPlane find_mirror_plane(const Mesh& mesh, const SurfaceQuery& surface) {
  MirrorPlane best;
  const Eigen::Index nv = mesh.V.rows();
  if (nv < 4) return best;
  const Eigen::Index step = std::max<Eigen::Index>(1, nv / kMirrorSamples);
  Eigen::MatrixX3d samples((nv + step - 1) / step, 3);
  for (Eigen::Index i = 0; i < samples.rows(); ++i) samples.row(i) = mesh.V.row(i * step);
  const double diagonal = (mesh.V.colwise().maxCoeff() - mesh.V.colwise().minCoeff()).norm();
  if (!(diagonal > 0)) return best;
  const Eigen::RowVector3d centre = samples.colwise().mean();
  const Eigen::MatrixX3d centred = samples.rowwise() - centre;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> principal(centred.transpose() * centred);
  std::vector<Eigen::Vector3d> candidates = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                                             Eigen::Vector3d::UnitZ()};
  for (int k = 0; k < 3; ++k) {  // a principal axis along a coordinate axis is tried once
    const Eigen::Vector3d axis = principal.eigenvectors().col(k).normalized();
    if (axis.cwiseAbs().maxCoeff() < kSameAxis) candidates.push_back(axis);
  }
  // Each candidate refitted once; the best one then again while that lowers its error.
  std::optional<Tried> chosen;
  for (const Eigen::Vector3d& normal : candidates) {
    const Plane start{normal, normal.dot(centre.transpose())};
    const Plane refit = mirror_fit(samples, start, surface).refit;
    const Tried fitted{refit, mirror_fit(samples, refit, surface)};
    const Eigen::ArrayXd distance =
        ((samples * fitted.plane.normal).array() - fitted.plane.offset).abs();
    if ((distance > kOffPlane * diagonal).cast<double>().mean() < kMinOffPlane) continue;
    if (!chosen || fitted.fit.error < chosen->fit.error) chosen = fitted;
  }
  if (!chosen) return best;
  for (int round = 0; round < kPolishRounds; ++round) {
    const Tried next{chosen->fit.refit, mirror_fit(samples, chosen->fit.refit, surface)};
    if (!(next.fit.error < chosen->fit.error)) break;
    chosen = next;
  }
  best.normal = chosen->plane.normal;
  best.offset = chosen->plane.offset;
  best.error = chosen->fit.error / diagonal;
  Eigen::Index largest = 0;
  best.normal.cwiseAbs().maxCoeff(&largest);
  if (best.normal[largest] < 0) {
    best.normal = -best.normal;
    best.offset = -best.offset;
  }
  return best;
}

}  // namespace dcg

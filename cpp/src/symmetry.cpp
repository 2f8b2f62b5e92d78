// The mirror plane of a surface. See dcg/symmetry.h.
#include "dcg/symmetry.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "dcg/surface_query.h"

namespace dcg {
namespace {

// A sample lies off a plane when farther than this from it (diagonals): a plane with fewer than
// kMinOffPlane of the samples off it is one the shape lies in.
constexpr double kOffPlane = 0.03;
constexpr double kMinOffPlane = 0.25;
// Gauss-Newton refits of each start, then of the best one (each stops when the error does not
// fall).
constexpr int kStartRounds = 5;
constexpr Eigen::Index kStartStride = 4;
constexpr std::ptrdiff_t kFinalists = 3;
constexpr int kPolishRounds = 20;
// Normals closer than this (cosine: 10 degrees) refine to the same plane.
constexpr double kSameAxis = 0.985;

// A plane normal . x = offset.
struct Plane {
  Eigen::Vector3d normal;
  double offset = 0;
};

// How far `samples` mirrored across `plane` land from the surface (mean distance), and the plane
// one Gauss-Newton step closer to mirroring them onto it (the refit): point-to-plane, each mirror
// image's distance along the normal of the surface at its nearest point, which lets the images
// slide along the surface, so the step goes straight to the plane instead of creeping toward it
// as nearest points alone do (seen: 1-3 degrees off on a rotated model after 60 such steps).
struct Fit {
  double error = 0;
  Plane refit;
  std::vector<Eigen::Vector3d> partners;  // each mirrored sample's closest surface point
  std::vector<int> faces;                 // and its face (-1: none)
};

// `near` (the fit of the same samples across a plane close to this one, or null) gives each
// mirrored sample a hint, its partner there: the closest points come out the same, the searches
// bounded by it (the refits' planes move little, their partners too).
Fit mirror_fit(const Eigen::MatrixX3d& samples, const Plane& plane, const SurfaceQuery& surface,
               const Fit* near = nullptr) {
  Fit fit;
  fit.partners.resize(static_cast<std::size_t>(samples.rows()));
  fit.faces.assign(static_cast<std::size_t>(samples.rows()), -1);
  const bool hinted = near && near->faces.size() == fit.faces.size();
  const Eigen::Vector3d centre = samples.colwise().mean().transpose();
  const Eigen::Vector3d& n = plane.normal;
  const double d = plane.offset - n.dot(centre);  // the plane n . (x - centre) = d
  const Eigen::Vector3d u = n.unitOrthogonal(), v = n.cross(u);
  Eigen::Matrix3d normal_matrix = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  for (Eigen::Index i = 0; i < samples.rows(); ++i) {
    const Eigen::Vector3d p = samples.row(i).transpose() - centre;
    const double side = n.dot(p) - d;
    const Eigen::Vector3d mirrored = p - 2 * side * n;
    int face = -1;
    const auto k = static_cast<std::size_t>(i);
    const Eigen::Vector3d at = mirrored + centre;
    fit.partners[k] = hinted ? surface.closest_point(at, near->partners[k], near->faces[k], &face)
                             : surface.closest_point(at, &face);
    fit.faces[k] = face;
    const Eigen::Vector3d partner = fit.partners[k] - centre;
    fit.error += (partner - mirrored).norm();
    if (face < 0) continue;
    const Eigen::Vector3d& m = surface.face_normal(face);
    // residual m . (mirrored - partner); moving n by a u + b v and d by e changes `mirrored` by
    // -2 ((n_change . p - e) n + side n_change)
    const double along = m.dot(n);
    const Eigen::Vector3d lever = along * p + side * m;
    const Eigen::Vector3d row(-2 * lever.dot(u), -2 * lever.dot(v), 2 * along);
    const double residual = m.dot(mirrored - partner);
    normal_matrix += row * row.transpose();
    rhs -= row * residual;
  }
  fit.error /= static_cast<double>(samples.rows());
  normal_matrix.diagonal().array() += 1e-9 * (normal_matrix.trace() + 1e-300);  // damping
  const Eigen::Vector3d step = normal_matrix.ldlt().solve(rhs);
  fit.refit = plane;
  if (!step.allFinite()) return fit;
  fit.refit.normal = (n + step[0] * u + step[1] * v).normalized();
  fit.refit.offset = d + step[2] + fit.refit.normal.dot(centre);
  return fit;
}

// A plane tried: where it is, its error there, and its refit.
struct Tried {
  Plane plane;
  Fit fit;
};

Tried tried(const Eigen::MatrixX3d& samples, const Plane& plane, const SurfaceQuery& surface,
            const Fit* near = nullptr) {
  return {plane, mirror_fit(samples, plane, surface, near)};
}

// `start` refitted while that lowers its error, at most `rounds` times.
Tried polished(const Eigen::MatrixX3d& samples, Tried start, int rounds,
               const SurfaceQuery& surface) {
  for (int round = 0; round < rounds; ++round) {
    Tried next = tried(samples, start.fit.refit, surface, &start.fit);
    if (!(next.fit.error < start.fit.error)) break;
    start = std::move(next);
  }
  return start;
}

// The normals the search starts from: the 13 axes of a cube's symmetries (its faces', edges' and
// corners' directions), then the principal axes of `centred` (#S by 3) not within 10 degrees of
// one of those.
std::vector<Eigen::Vector3d> start_normals(const Eigen::MatrixX3d& centred) {
  std::vector<Eigen::Vector3d> normals;
  for (int x = -1; x <= 1; ++x)
    for (int y = -1; y <= 1; ++y)
      for (int z = -1; z <= 1; ++z) {
        const Eigen::Vector3d axis(x, y, z);
        const bool first_positive = x > 0 || (x == 0 && (y > 0 || (y == 0 && z > 0)));
        if (first_positive) normals.push_back(axis.normalized());  // one of each +- pair
      }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> principal(centred.transpose() * centred);
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d axis = principal.eigenvectors().col(k).normalized();
    const bool listed = std::any_of(normals.begin(), normals.end(), [&](const auto& normal) {
      return std::abs(normal.dot(axis)) >= kSameAxis;
    });
    if (!listed) normals.push_back(axis);
  }
  return normals;
}

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
  // Each start refitted a few times on every kStartStride-th sample; the kFinalists best then on
  // all of them while that lowers their error, the best of those chosen.
  const Eigen::Index stride = samples.rows() >= 4 * kStartStride ? kStartStride : 1;
  Eigen::MatrixX3d coarse((samples.rows() + stride - 1) / stride, 3);
  for (Eigen::Index i = 0; i < coarse.rows(); ++i) coarse.row(i) = samples.row(i * stride);
  std::vector<Tried> starts;
  for (const Eigen::Vector3d& normal : start_normals(samples.rowwise() - centre)) {
    const Plane start{normal, normal.dot(centre.transpose())};
    const Tried fitted = polished(coarse, tried(coarse, start, surface), kStartRounds, surface);
    const Eigen::ArrayXd distance =
        ((samples * fitted.plane.normal).array() - fitted.plane.offset).abs();
    if ((distance > kOffPlane * diagonal).cast<double>().mean() < kMinOffPlane) continue;
    starts.push_back(fitted);
  }
  if (starts.empty()) return best;
  const auto finalists = starts.begin() + std::min<std::ptrdiff_t>(kFinalists, starts.size());
  std::partial_sort(starts.begin(), finalists, starts.end(),
                    [](const Tried& a, const Tried& b) { return a.fit.error < b.fit.error; });
  std::optional<Tried> chosen;
  for (auto start = starts.begin(); start != finalists; ++start) {
    Tried fitted = polished(samples, tried(samples, start->plane, surface), kPolishRounds, surface);
    if (!chosen || fitted.fit.error < chosen->fit.error) chosen = std::move(fitted);
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

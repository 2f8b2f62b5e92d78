// The mirror plane of a shape (dcg/symmetry.h).
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "dcg/surface_query.h"
#include "dcg/symmetry.h"
#include "shapes.h"

namespace {

using dcg::Mesh;
namespace test = dcg::test;

// Smooth union of balls (centre, radius): negative inside.
Mesh blobs(const std::vector<std::pair<Eigen::Vector3d, double>>& balls) {
  return test::marching_tetrahedra(
      [&](const Eigen::Vector3d& p) {
        double sum = 0;
        for (const auto& [c, r] : balls) sum += std::exp(-((p - c).squaredNorm() / (r * r) - 1));
        return 1.0 - sum;
      },
      -3, 3, 40);
}

dcg::MirrorPlane plane_of(const Mesh& m) { return dcg::find_mirror_plane(m, dcg::SurfaceQuery(m)); }

TEST(Symmetry, AMirrorSymmetricShapeIsFoundWhereverItLies) {
  // Two arms mirrored across x = 0, a head and a tail on it, the four centres not in one plane
  // (balls about three centres mirror across the centres' plane too): x = 0 is the only one.
  const Mesh shape = blobs({{Eigen::Vector3d(-1.2, 0, 0), 0.6},
                            {Eigen::Vector3d(1.2, 0, 0), 0.6},
                            {Eigen::Vector3d(0, 0.9, 0.4), 0.7},
                            {Eigen::Vector3d(0, -0.8, 0.9), 0.5}});
  std::mt19937 rng(3);
  const Eigen::Matrix3d R = test::random_rotation(rng);
  const Eigen::Vector3d move(0.7, -2.0, 1.5);
  const Mesh moved = test::transformed(shape, R, 2.5, move);
  const dcg::MirrorPlane p = plane_of(moved);
  EXPECT_LT(p.error, 0.005);  // the grid's tetrahedra are not quite symmetric
  const Eigen::Vector3d expected = R * Eigen::Vector3d::UnitX();
  EXPECT_GT(std::abs(p.normal.dot(expected)), 0.999) << p.normal.transpose();
  EXPECT_NEAR(p.normal.norm(), 1, 1e-12);
  Eigen::Index largest = 0;
  p.normal.cwiseAbs().maxCoeff(&largest);
  EXPECT_GT(p.normal[largest], 0) << "the largest component is positive";
  // The plane passes through where the origin (on x = 0) went.
  EXPECT_NEAR(p.normal.dot(move), p.offset, 0.05);
}

TEST(Symmetry, TheRefitConvergesOnThePlaneWhateverTheRotation) {
  // Nearest points alone crept toward the plane and stopped 1-3 degrees off on rotated models
  // (the rigged Fox, Q_Horse); the point-to-plane refit and the 13 starts find it in every
  // orientation, within a fraction of a degree (here 0.25).
  const Mesh shape = blobs({{Eigen::Vector3d(-1.3, 0.2, 0), 0.5},
                            {Eigen::Vector3d(1.3, 0.2, 0), 0.5},
                            {Eigen::Vector3d(0, 0.8, -0.6), 0.8},
                            {Eigen::Vector3d(0, -1.1, 0.5), 0.6}});
  std::mt19937 rng(11);
  for (int trial = 0; trial < 6; ++trial) {
    const Eigen::Matrix3d R = test::random_rotation(rng);
    const dcg::MirrorPlane p =
        plane_of(test::transformed(shape, R, 0.3 + trial, Eigen::Vector3d(trial, 1, -2)));
    const Eigen::Vector3d expected = R * Eigen::Vector3d::UnitX();
    EXPECT_GT(std::abs(p.normal.dot(expected)), std::cos(0.25 * M_PI / 180)) << "trial " << trial;
  }
}

TEST(Symmetry, AnAsymmetricShapeMirrorsBadlyAndAFlatOneIsNotTried) {
  const Mesh lumpy = blobs({{Eigen::Vector3d(-1.2, 0, 0), 0.8},
                            {Eigen::Vector3d(1.0, 0.2, 0), 0.5},
                            {Eigen::Vector3d(0.3, 1.1, 0.5), 0.6},
                            {Eigen::Vector3d(-0.2, -0.6, -1.0), 0.45}});
  EXPECT_GT(plane_of(lumpy).error, 0.01);
  const Mesh triangle = test::make_mesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 2}});
  EXPECT_EQ(plane_of(triangle).error, 1.0) << "too few vertices to sample";
}

}  // namespace

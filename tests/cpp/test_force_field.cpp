// dcg/force_field.h (stage 4): the repulsive field's direction and magnitude on a sphere and a
// torus, its exact gradient against central differences, the inside flag of the ray fans, the
// batched evaluation, and the batched rays of SurfaceQuery that it runs on.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "dcg/errors.h"
#include "dcg/force_field.h"
#include "dcg/surface_query.h"
#include "shapes.h"

namespace {

using dcg::Mesh;
namespace test = dcg::test;

std::shared_ptr<const dcg::SurfaceQuery> query_of(const Mesh& m) {
  return std::make_shared<const dcg::SurfaceQuery>(m);
}

TEST(ForceField, FibonacciDirectionsAreUnitAndBalanced) {
  const dcg::Points d = dcg::fibonacci_sphere(64);
  ASSERT_EQ(d.rows(), 64);
  for (Eigen::Index i = 0; i < d.rows(); ++i) EXPECT_NEAR(d.row(i).norm(), 1.0, 1e-12);
  EXPECT_LT(d.colwise().sum().norm() / 64, 0.003);  // nearly balanced: the mean is almost 0
}

TEST(ForceField, SphereCenterIsBalancedAndWallsPushInward) {
  const dcg::ForceField field(query_of(test::icosphere(4)));
  const dcg::FieldSample center = field.at(Eigen::Vector3d::Zero());
  EXPECT_TRUE(center.inside());
  EXPECT_LT(center.magnitude, 0.05);
  EXPECT_NEAR(center.r_min, 1.0, 0.02);
  // Off center: F points back to the center, |F| grows toward the wall.
  double last = center.magnitude;
  const Eigen::Vector3d dir = Eigen::Vector3d(1, 2, -0.5).normalized();
  for (double t : {0.2, 0.4, 0.6, 0.8}) {
    const dcg::FieldSample s = field.at(t * dir);
    EXPECT_TRUE(s.inside()) << t;
    EXPECT_GT(s.magnitude, last) << t;
    EXPECT_LT(s.force.normalized().dot(dir), -0.95) << t;
    last = s.magnitude;
  }
  // Outside: rays see the front of faces or nothing.
  EXPECT_GT(field.at(Eigen::Vector3d(2, 0, 0)).outside_rays, 0);
}

TEST(ForceField, GradientMatchesCentralDifferences) {
  const dcg::ForceField field(query_of(test::torus(1.0, 0.4, 96, 48)));
  const std::vector<Eigen::Vector3d> axes = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                                             Eigen::Vector3d::UnitZ()};
  for (const Eigen::Vector3d& p :
       {Eigen::Vector3d(0.8, 0.1, 0.05), Eigen::Vector3d(-1.15, 0.2, -0.1),
        Eigen::Vector3d(0.3, 0.9, 0.2)}) {
    const dcg::FieldSample s = field.at_with_gradient(p);
    ASSERT_TRUE(s.inside());
    EXPECT_NEAR(s.magnitude, field.at(p).magnitude, 1e-12);
    const Eigen::VectorXd fd = field.magnitude_slopes(p, axes, 1e-5);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(s.gradient[k], fd[k], 0.02 * fd.norm() + 1e-6)
          << "point " << p.transpose() << " axis " << k;
    }
  }
}

TEST(ForceField, TorusMinimumLiesNearTheCoreCircle) {
  const dcg::ForceField field(query_of(test::torus(1.0, 0.3, 96, 48)));
  // Along the x axis through the tube: |F| is smallest within 0.05 of x = 1.
  double best = 1e300, at = 0;
  for (double x = 0.75; x <= 1.25; x += 0.01) {
    const double m = field.at(Eigen::Vector3d(x, 0, 0)).magnitude;
    if (m < best) {
      best = m;
      at = x;
    }
  }
  EXPECT_NEAR(at, 1.0, 0.05);
}

TEST(ForceField, BatchesEqualSinglePointsAndCostsAreMeans) {
  const dcg::ForceField field(query_of(test::capsule(0.5, 2.0)));
  dcg::Points points(5, 3);
  points << 0, 0, 0, 0.2, 0, 0.5, 0, -0.3, -0.9, 0.1, 0.1, 1.1, 0, 0, 3.0;
  const dcg::FieldSamples batch = field.evaluate(points);
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    const dcg::FieldSample s = field.at(points.row(i).transpose());
    EXPECT_EQ(batch.magnitude[i], s.magnitude);
    EXPECT_EQ(batch.outside_rays[i], s.outside_rays);
    EXPECT_TRUE(batch.force.row(i).transpose().isApprox(s.force) || s.magnitude == 0);
  }
  EXPECT_EQ(batch.outside_rays[4], field.options().rays) << "a point far outside sees no back face";
  bool inside = false;
  const double cost =
      field.mean_magnitude(Eigen::Vector3d(0, 0, -0.8), Eigen::Vector3d(0, 0, 0.8), 4, &inside);
  EXPECT_TRUE(inside);
  double sum = 0;
  for (int i = 1; i <= 4; ++i) sum += field.at(Eigen::Vector3d(0, 0, -0.8 + 1.6 * i / 5)).magnitude;
  EXPECT_NEAR(cost, sum / 4, 1e-12);
}

TEST(ForceField, OptionsAreChecked) {
  auto q = query_of(test::icosphere(1));
  dcg::ForceFieldOptions o;
  o.rays = 5;
  EXPECT_THROW(dcg::ForceField(q, o), dcg::InputError);
  o.rays = 16;
  o.force_exponent = 0;
  EXPECT_THROW(dcg::ForceField(q, o), dcg::InputError);
  EXPECT_THROW(dcg::ForceField(nullptr), dcg::InputError);
}

TEST(SurfaceQueryRays, FansAndSegmentBatchesAgreeWithSingleRays) {
  const Mesh m = test::torus(1.0, 0.4);
  const dcg::SurfaceQuery q(m);
  const dcg::Points dirs = dcg::fibonacci_sphere(21);  // not a multiple of the packet width
  const Eigen::Matrix<float, Eigen::Dynamic, 3, Eigen::RowMajor> d = dirs.cast<float>();
  const Eigen::Vector3d origin(1.1, 0.1, 0.05);
  std::vector<double> t(21);
  std::vector<unsigned char> in(21);
  std::vector<int> faces(21);
  q.ray_fan(origin, d.data(), 21, t.data(), in.data(), faces.data());
  for (int k = 0; k < 21; ++k) {
    int face = -1;
    const double single = q.ray_hit(origin, dirs.row(k).transpose(), &face);
    EXPECT_NEAR(t[k], single, 1e-5) << k;
    EXPECT_EQ(faces[k], face) << k;
    EXPECT_EQ(in[k], 1) << k;
  }
  // Segments: across the hole (blocked), along the tube (clear), trimmed onto the surface.
  dcg::Points a(3, 3), b(3, 3);
  a << 1, 0, 0, 1, 0, 0, 0, 0, 0;
  b << -1, 0, 0, std::cos(0.3), std::sin(0.3), 0, 0, 0, 1;
  std::vector<unsigned char> blocked(3);
  q.segments_blocked(a.data(), b.data(), 3, 0.0, blocked.data());
  EXPECT_EQ(blocked[0], 1);
  EXPECT_EQ(blocked[1], 0);
  EXPECT_EQ(blocked[2], 0) << "the hole of the torus: nothing on the z axis";
  EXPECT_TRUE(q.segment_blocked(Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(1, 0, 1)));
  EXPECT_FALSE(q.segment_blocked(Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(1, 0, 0.4), 1e-3))
      << "a segment to a surface point, trimmed at its end, does not count that point";
  EXPECT_TRUE(q.inside_by_parity(Eigen::Vector3d(1, 0, 0)));
  EXPECT_FALSE(q.inside_by_parity(Eigen::Vector3d(0, 0, 0)));
}

}  // namespace

// dcg/connection_points.h (stage 5): shrinking stays inside and lowers |F|, stops at minima,
// greedy merging never chains (a torus ring keeps its points), results do not depend on threads.
#include <gtest/gtest.h>

#include <memory>
#include <random>

#include <tbb/global_control.h>

#include "dcg/connection_points.h"
#include "dcg/errors.h"
#include "dcg/force_field.h"
#include "dcg/surface_query.h"
#include "shapes.h"

namespace {

using dcg::Mesh;
namespace test = dcg::test;

// Points inside a shape: random points of its bounding box kept when inside.
dcg::Points random_inside(const dcg::SurfaceQuery& q, const Mesh& m, int count, unsigned seed) {
  std::mt19937 rng(seed);
  const Eigen::RowVector3d lo = m.V.colwise().minCoeff(), hi = m.V.colwise().maxCoeff();
  std::uniform_real_distribution<double> u(0, 1);
  dcg::Points out(count, 3);
  for (int i = 0; i < count;) {
    const Eigen::RowVector3d p =
        lo.array() + (hi - lo).array() * Eigen::RowVector3d(u(rng), u(rng), u(rng)).array();
    if (q.distance(p.transpose()) > 0.02 && q.inside(p.transpose())) out.row(i++) = p;
  }
  return out;
}

TEST(ConnectionPoints, ShrinkingStaysInsideLowersTheFieldAndStops) {
  const Mesh m = test::capsule(0.5, 2.0);
  auto q = std::make_shared<const dcg::SurfaceQuery>(m);
  const dcg::ForceField field(q);
  const dcg::Points start = random_inside(*q, m, 60, 1);
  const dcg::ConnectionPoints cp = dcg::compute_connection_points(start, field);
  ASSERT_EQ(cp.shrunk.rows(), start.rows());
  for (Eigen::Index i = 0; i < start.rows(); ++i) {
    const Eigen::Vector3d p = cp.shrunk.row(i).transpose();
    EXPECT_TRUE(q->inside(p)) << i;
    EXPECT_LE(cp.shrunk_magnitude[i], field.at(start.row(i).transpose()).magnitude + 1e-12) << i;
    EXPECT_TRUE(cp.converged[i]) << i << " still moving after " << cp.steps[i] << " steps";
    // Shrunk onto the axis of the capsule.
    EXPECT_LT(p.head<2>().norm(), 0.08) << i;
    EXPECT_NEAR(cp.shrunk_radii[i], q->distance(p), 1e-12);
  }
  // Merged: survivors are the lowest-|F| member of their cluster and far enough apart.
  const int c = static_cast<int>(cp.positions.rows());
  ASSERT_GT(c, 0);
  ASSERT_LT(c, start.rows());
  for (int a = 0; a < c; ++a) {
    for (int b = a + 1; b < c; ++b) {
      EXPECT_GE((cp.positions.row(a) - cp.positions.row(b)).norm(),
                0.5 * std::min(cp.radii[a], cp.radii[b]) - 1e-12);
    }
    EXPECT_EQ(cp.cluster[cp.source[a]], a);
    if (a > 0) {
      EXPECT_GE(cp.magnitude[a], cp.magnitude[a - 1]);
    }
  }
  for (Eigen::Index i = 0; i < start.rows(); ++i) {
    EXPECT_LE(cp.magnitude[cp.cluster[i]], cp.shrunk_magnitude[i] + 1e-12);
  }
}

TEST(ConnectionPoints, ArrivedTradesStepsForHowCloseToTheMinimumAPointStops) {
  const Mesh m = test::capsule(0.5, 2.0);
  auto q = std::make_shared<const dcg::SurfaceQuery>(m);
  const dcg::ForceField field(q);
  const dcg::Points start = random_inside(*q, m, 40, 2);
  auto run = [&](double arrived, int* steps, double* off_axis) {
    dcg::ConnectionPointsOptions o;
    o.arrived = arrived;
    const dcg::ConnectionPoints cp = dcg::compute_connection_points(start, field, o);
    *steps = cp.steps.sum();
    *off_axis = 0;
    for (Eigen::Index i = 0; i < start.rows(); ++i) {
      EXPECT_TRUE(cp.converged[i]) << arrived << " " << i;
      EXPECT_TRUE(q->inside(cp.shrunk.row(i).transpose())) << arrived << " " << i;
      *off_axis += cp.shrunk.row(i).head<2>().norm() / static_cast<double>(start.rows());
    }
  };
  int fine_steps = 0, coarse_steps = 0;
  double fine_off = 0, coarse_off = 0;
  run(1e-3, &fine_steps, &fine_off);
  run(3e-2, &coarse_steps, &coarse_off);
  EXPECT_LT(coarse_steps, fine_steps);  // fewer fans...
  EXPECT_LT(fine_off, coarse_off);      // ...for points left farther from the axis
  EXPECT_LT(coarse_off, 0.1);           // still near it (radius 0.5)
  dcg::ConnectionPointsOptions bad;
  bad.arrived = -1;
  EXPECT_THROW(dcg::compute_connection_points(start, field, bad), dcg::InputError);
}

TEST(ConnectionPoints, GreedyMergingNeverChains) {
  // 40 points 0.1 apart on a line, radius 0.3: merging within 0.15. Pairwise union would merge
  // the whole line into one point; the greedy rule keeps one point in every ~0.2.
  dcg::Points line(40, 3);
  Eigen::VectorXd magnitude(40), radii = Eigen::VectorXd::Constant(40, 0.3);
  for (int i = 0; i < 40; ++i) {
    line.row(i) << 0.1 * i, 0, 0;
    magnitude[i] = 1.0 + 0.001 * ((i * 7) % 5);
  }
  std::vector<int> survivors;
  const Eigen::VectorXi cluster = dcg::merge_greedily(line, magnitude, radii, 0.5, &survivors);
  EXPECT_GE(survivors.size(), 13u);
  EXPECT_LE(survivors.size(), 20u);
  for (int i = 0; i < 40; ++i) {
    EXPECT_LT((line.row(i) - line.row(survivors[cluster[i]])).norm(), 0.15 + 1e-12);
  }
}

TEST(ConnectionPoints, TorusRingKeepsItsPointsAndThreadsDoNotMatter) {
  const Mesh m = test::torus(1.0, 0.3, 64, 24);
  auto q = std::make_shared<const dcg::SurfaceQuery>(m);
  const dcg::ForceField field(q);
  const dcg::Points start = random_inside(*q, m, 80, 2);
  const dcg::ConnectionPoints many = dcg::compute_connection_points(start, field);
  dcg::ConnectionPoints one;
  {
    tbb::global_control serial(tbb::global_control::max_allowed_parallelism, 1);
    one = dcg::compute_connection_points(start, field);
  }
  EXPECT_EQ(many.shrunk, one.shrunk);
  EXPECT_EQ(many.positions, one.positions);
  // Spread around the ring: points in at least 6 of 8 sectors.
  std::vector<int> sectors(8, 0);
  for (Eigen::Index i = 0; i < many.positions.rows(); ++i) {
    const double angle = std::atan2(many.positions(i, 1), many.positions(i, 0));
    ++sectors[static_cast<int>(std::floor((angle + M_PI) / (2 * M_PI) * 8)) % 8];
    const double rho = std::hypot(many.positions(i, 0), many.positions(i, 1));
    EXPECT_LT(std::hypot(rho - 1.0, many.positions(i, 2)), 0.1) << "connection point " << i;
  }
  int filled = 0;
  for (int s : sectors) filled += s > 0;
  EXPECT_GE(filled, 6);
}

}  // namespace

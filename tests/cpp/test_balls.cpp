// dcg/surface_query.h, dcg/voronoi_balls.h and dcg/domain_balls.h (stages 1-2) against
// brute-force references: distances to every triangle, winding numbers, all pairs of balls.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "dcg/domain_balls.h"
#include "dcg/errors.h"
#include "dcg/prepare.h"
#include "dcg/surface_query.h"
#include "dcg/voronoi_balls.h"
#include "shapes.h"

namespace {

using dcg::Mesh;
namespace test = dcg::test;

// A small closed working mesh (normalized units): a capsule bent off its axes.
const dcg::PreparedMesh& small_mesh() {
  static const dcg::PreparedMesh pm = [] {
    std::mt19937 rng(11);
    const Mesh m =
        test::transformed(test::capsule(0.2, 2.0, 6, 16, 10), test::random_rotation(rng), 3.0);
    dcg::PrepareOptions o;
    o.target_faces = 0;  // keep it small: brute force is O(balls x faces)
    return dcg::prepare_mesh(m.V, m.F, o);
  }();
  return pm;
}

TEST(SurfaceQuery, ClosestPointAndInsideMatchBruteForce) {
  const Mesh& m = small_mesh().working;
  const dcg::SurfaceQuery& q = *small_mesh().query;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.6, 0.6);
  for (int i = 0; i < 400; ++i) {
    const Eigen::Vector3d p(u(rng), u(rng), u(rng));
    const double reference = test::brute_force_distance(m, p);
    int face = -1;
    const Eigen::Vector3d c = q.closest_point(p, &face);
    EXPECT_NEAR((c - p).norm(), reference, 1e-9);
    EXPECT_NEAR(q.distance(p), reference, 1e-9);
    ASSERT_GE(face, 0);
    EXPECT_NEAR(test::triangle_distance(c, m.V.row(m.F(face, 0)), m.V.row(m.F(face, 1)),
                                        m.V.row(m.F(face, 2))),
                0.0, 1e-9);
    const bool inside = test::winding_number(m, p) > 0.5;
    EXPECT_EQ(q.inside(p), inside) << p.transpose();
    EXPECT_NEAR(std::abs(q.signed_distance(p)), reference, 1e-9);
    EXPECT_EQ(q.signed_distance(p) < 0, inside);
    // A hint anywhere on the surface gives the same answer.
    EXPECT_NEAR(q.signed_distance(p, m.V.row(m.F(7, 0)).transpose(), 7), q.signed_distance(p),
                1e-12);
    // The closest point too, bit for bit, with a far hint or the answer itself as the hint.
    for (const auto& [hint, hint_face] :
         {std::pair<Eigen::Vector3d, int>{m.V.row(m.F(7, 0)).transpose(), 7}, {c, face}}) {
      int hinted_face = -1;
      EXPECT_EQ(q.closest_point(p, hint, hint_face, &hinted_face), c);
      EXPECT_EQ(hinted_face, face);
    }
  }
}

TEST(SurfaceQuery, RaysAndSegments) {
  const dcg::SurfaceQuery q(test::icosphere(3));
  EXPECT_NEAR(q.ray_hit(Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 2)), 1.0, 0.01);
  EXPECT_TRUE(std::isinf(q.ray_hit(Eigen::Vector3d(0, 0, 2), Eigen::Vector3d(0, 0, 1))));
  EXPECT_TRUE(q.segment_inside(Eigen::Vector3d(-0.5, 0, 0), Eigen::Vector3d(0.5, 0.2, 0)));
  EXPECT_FALSE(q.segment_inside(Eigen::Vector3d(-0.5, 0, 0), Eigen::Vector3d(1.5, 0, 0)));
  // A torus: the segment across the hole leaves the shape although both ends are inside.
  const dcg::SurfaceQuery t(test::torus(1.0, 0.3));
  EXPECT_TRUE(t.inside(Eigen::Vector3d(1, 0, 0)));
  EXPECT_FALSE(t.inside(Eigen::Vector3d(0, 0, 0)));
  EXPECT_FALSE(t.segment_inside(Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(-1, 0, 0)));
  EXPECT_THROW(dcg::SurfaceQuery(Mesh{}), dcg::InputError);
}

TEST(VoronoiBalls, CentersInsideAndRadiusIsTheDistanceToTheSurface) {
  const dcg::PreparedMesh& pm = small_mesh();
  dcg::VoronoiBallsOptions o;
  o.samples = 600;
  const dcg::Balls balls = dcg::compute_voronoi_balls(pm.working, *pm.query, o);
  ASSERT_GT(balls.radii.size(), 100);
  for (Eigen::Index i = 0; i < balls.radii.size(); ++i) {
    const Eigen::Vector3d c = balls.centers.row(i).transpose();
    EXPECT_GT(test::winding_number(pm.working, c), 0.5) << "ball " << i;
    EXPECT_NEAR(balls.radii[i], test::brute_force_distance(pm.working, c), 1e-6) << "ball " << i;
  }
  // Deterministic for a seed.
  const dcg::Balls again = dcg::compute_voronoi_balls(pm.working, *pm.query, o);
  EXPECT_EQ(again.centers, balls.centers);
  EXPECT_EQ(again.radii, balls.radii);
  o.samples = 3;
  EXPECT_THROW(dcg::compute_voronoi_balls(pm.working, *pm.query, o), dcg::InputError);
}

TEST(VoronoiBalls, SamplesCoverTheWholeSurface) {
  // Every part of the surface is touched by some ball: for every vertex v, some ball's sphere
  // passes within a few sample spacings of v (a sampling that skips a region, e.g. an arm of a
  // star, leaves that region without balls).
  const Mesh shape = test::star(6, 3.0, 0.35, 40);
  dcg::PrepareOptions po;
  po.target_faces = 8000;
  const dcg::PreparedMesh pm = dcg::prepare_mesh(shape.V, shape.F, po);
  dcg::VoronoiBallsOptions o;
  o.samples = 2000;
  const dcg::Balls balls = dcg::compute_voronoi_balls(pm.working, *pm.query, o);
  double area = 0;
  for (Eigen::Index f = 0; f < pm.working.F.rows(); ++f) {
    const Eigen::Vector3d a = pm.working.V.row(pm.working.F(f, 0)),
                          b = pm.working.V.row(pm.working.F(f, 1)),
                          c = pm.working.V.row(pm.working.F(f, 2));
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  const double spacing = std::sqrt(area / o.samples);
  double worst = 0;
  for (Eigen::Index v = 0; v < pm.working.V.rows(); v += 7) {
    double gap = std::numeric_limits<double>::infinity();
    for (Eigen::Index b = 0; b < balls.radii.size(); ++b)
      gap = std::min(gap, (pm.working.V.row(v) - balls.centers.row(b)).norm() - balls.radii[b]);
    worst = std::max(worst, gap);
  }
  EXPECT_LT(worst, 3 * spacing) << "sample spacing " << spacing;
}

TEST(DomainBalls, DisjointInsideGreedyAndExact) {
  const dcg::PreparedMesh& pm = small_mesh();
  dcg::VoronoiBallsOptions vo;
  vo.samples = 600;
  const dcg::Balls candidates = dcg::compute_voronoi_balls(pm.working, *pm.query, vo);
  dcg::DomainBallsOptions o;  // min_gap 0.005, min_radius 0.002
  const dcg::DomainBalls db = dcg::compute_domain_balls(candidates, o);
  const auto& B = db.balls;
  const Eigen::Index k = B.radii.size();
  ASSERT_GT(k, 3);
  ASSERT_EQ(db.source.size(), static_cast<size_t>(k));
  for (Eigen::Index i = 0; i < k; ++i) {
    const Eigen::Vector3d c = B.centers.row(i).transpose();
    EXPECT_GE(B.radii[i], o.min_radius);
    if (i > 0) {
      EXPECT_LE(B.radii[i], B.radii[i - 1]) << "largest first";
    }
    EXPECT_GT(test::winding_number(pm.working, c), 0.5) << "center " << i << " inside";
    EXPECT_NEAR(B.radii[i], test::brute_force_distance(pm.working, c), 1e-6) << "ball " << i;
    EXPECT_EQ(B.centers.row(i), candidates.centers.row(db.source[i]));
    for (Eigen::Index j = 0; j < i; ++j) {
      EXPECT_GT((B.centers.row(i) - B.centers.row(j)).norm(), B.radii[i] + B.radii[j] + o.min_gap)
          << "balls " << i << " and " << j << " intersect";
    }
  }
  // Greedy and maximal: every candidate left out is too small or conflicts with an accepted ball
  // at least as large.
  std::vector<char> accepted(candidates.radii.size(), 0);
  for (int s : db.source) accepted[s] = 1;
  for (Eigen::Index c = 0; c < candidates.radii.size(); ++c) {
    if (accepted[c] || candidates.radii[c] < o.min_radius) continue;
    bool conflict = false;
    for (Eigen::Index i = 0; i < k && !conflict; ++i) {
      conflict = B.radii[i] >= candidates.radii[c] &&
                 (B.centers.row(i) - candidates.centers.row(c)).norm() <=
                     B.radii[i] + candidates.radii[c] + o.min_gap;
    }
    EXPECT_TRUE(conflict) << "candidate " << c << " could have been accepted";
  }
}

TEST(DomainBalls, OptionsAndEdgeCases) {
  dcg::Balls none;
  none.centers.resize(0, 3);
  none.radii.resize(0);
  EXPECT_EQ(dcg::compute_domain_balls(none).balls.radii.size(), 0);
  dcg::Balls two;
  two.centers.resize(2, 3);
  two.centers << 0, 0, 0, 0.05, 0, 0;
  two.radii.resize(2);
  two.radii << 0.03, 0.02;
  EXPECT_EQ(dcg::compute_domain_balls(two).balls.radii.size(), 1);  // they intersect
  two.centers(1, 0) = 0.06;  // 0.06 > 0.03 + 0.02 + 0.005: disjoint with the gap
  EXPECT_EQ(dcg::compute_domain_balls(two).balls.radii.size(), 2);
  dcg::DomainBallsOptions bad;
  bad.min_gap = -1;
  EXPECT_THROW(dcg::compute_domain_balls(two, bad), dcg::InputError);
  two.radii[0] = std::nan("");
  EXPECT_THROW(dcg::compute_domain_balls(two), dcg::InputError);
}

}  // namespace

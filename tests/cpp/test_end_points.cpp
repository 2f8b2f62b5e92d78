// Stage 3's end points for the prongs no ball sees, the points stage 6 links (dcg/end_points.h),
// and the keep-inside pass after stage 8 (dcg/keep_inside.h).
#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "dcg/connection_points.h"
#include "dcg/end_points.h"
#include "dcg/keep_inside.h"
#include "dcg/prepare.h"
#include "dcg/prongs.h"
#include "dcg/skeleton.h"
#include "dcg/surface_query.h"
#include "shapes.h"

namespace {

namespace test = dcg::test;
using dcg::Mesh;

struct Star {
  Mesh mesh = test::star(4, 3.0, 0.35);
  dcg::PreparedMesh pm = dcg::prepare_mesh(mesh.V, mesh.F);
  dcg::ProngFeatures pf = dcg::compute_prongs(pm.working);
};

TEST(EndPoints, AProngNoBallSeesGetsAPointInsideNearItsPeak) {
  const Star star;
  ASSERT_EQ(star.pf.prongs.vertices.size(), 4);
  const dcg::Points center = dcg::Points::Zero(1, 3);  // the star's middle, inside
  for (Eigen::Index p = 0; p < 4; ++p) {
    double r = 0;
    const Eigen::Vector3d q =
        dcg::unseen_end_point(star.pf.prongs, p, star.pm.working, *star.pm.query, center, &r);
    const Eigen::Vector3d peak = star.pf.prongs.positions.row(p).transpose();
    EXPECT_GT(r, 0) << "prong " << p;
    EXPECT_TRUE(star.pm.query->inside(q)) << "prong " << p;
    EXPECT_NEAR(r, star.pm.query->distance(q), 1e-12);
    // The middle of the inward chord from the round tip (along the arm): in the prong's arm,
    // nearer its peak than the star's middle is.
    EXPECT_LT((q - peak).norm(), 0.75 * peak.norm()) << "prong " << p;
  }
}

TEST(EndPoints, GraphPointsAreConnectionPointsThenSeenThenUnseenEnds) {
  const Star star;
  dcg::ConnectionPoints cp;
  cp.positions = dcg::Points::Zero(2, 3);
  cp.positions(1, 0) = 0.01;
  cp.radii = Eigen::VectorXd::Constant(2, 0.03);
  dcg::EndPoints ends;  // prongs 0 and 2 have a ball, 1 and 3 none
  ends.ball = Eigen::Vector4i(5, -1, 7, -1);
  ends.centers = star.pf.prongs.positions;
  ends.radii = Eigen::Vector4d(0.01, 0, 0.02, 0);
  const dcg::GraphPoints g =
      dcg::graph_points(cp, ends, star.pf.prongs, star.pm.working, *star.pm.query, cp.positions);
  ASSERT_EQ(g.points.rows(), 6);
  EXPECT_EQ(g.prong, (Eigen::VectorXi(6) << -1, -1, 0, 2, 1, 3).finished());
  EXPECT_EQ(g.points.row(2), ends.centers.row(0));
  EXPECT_DOUBLE_EQ(g.radii[3], 0.02);
  EXPECT_GT(g.radii[4], 0);
  EXPECT_GT(g.radii[5], 0);
}

// Balls on the lines from the star's middle to its peaks: for each (away, radius) of `rings`, one
// per prong (ball r * P + p for prong p), `away` from the peak (normalized units).
dcg::Balls balls_toward_peaks(const Star& star,
                              const std::vector<std::pair<double, double>>& rings) {
  const Eigen::Index P = star.pf.prongs.positions.rows(),
                     R = static_cast<Eigen::Index>(rings.size());
  dcg::Balls balls{dcg::Points(R * P, 3), Eigen::VectorXd(R * P)};
  for (Eigen::Index r = 0; r < R; ++r) {
    for (Eigen::Index p = 0; p < P; ++p) {
      const Eigen::Vector3d peak = star.pf.prongs.positions.row(p).transpose();
      balls.centers.row(r * P + p) = (peak * (1.0 - rings[r].first / peak.norm())).transpose();
      balls.radii[r * P + p] = rings[r].second;
    }
  }
  return balls;
}

// A ball that sees its peak only from afar, down a part too thin for a larger ball, ends no prong
// (the prong gets the unseen end point by its peak); one as far but wide enough, or one near the
// peak however small, does; past a far, small ball the search goes on for a wider one, but not
// beyond kEndBallSearch times its distance.
TEST(EndPoints, ABallThatSeesItsPeakFromAfarAndIsSmallEndsNoProng) {
  const Star star;
  const Eigen::Index P = star.pf.prongs.positions.rows();
  ASSERT_EQ(P, 4);
  const double arm = star.pf.prongs.positions.row(0).norm();  // the middle is inside, at 0
  const double far = 0.3 * arm, thin = far / dcg::kEndBallFarRadii;
  ASSERT_GT(far, 2 * dcg::kEndBallFarGap);
  const double near = 0.8 * dcg::kEndBallFarGap, wide = 0.5 * far;
  const double beyond = 1.1 * dcg::kEndBallSearch * far;
  ASSERT_LT(beyond, arm);
  struct Case {
    std::vector<std::pair<double, double>> rings;
    int ring;  // the ring whose ball ends each prong, -1 for none
  };
  const std::vector<Case> cases = {{{{far, 0.5 * thin}}, -1},
                                   {{{far, 2 * thin}}, 0},
                                   {{{near, 0.1 * near / dcg::kEndBallFarRadii}}, 0},
                                   {{{far, 0.5 * thin}, {1.5 * far, wide}}, 1},
                                   {{{far, 0.5 * thin}, {beyond, wide}}, -1}};
  for (const Case& c : cases) {
    const dcg::Balls balls = balls_toward_peaks(star, c.rings);
    const dcg::EndPoints ends = dcg::find_end_points(star.pf.prongs, balls, *star.pm.query, 0.0);
    for (Eigen::Index i = 0; i < balls.radii.size(); ++i) {
      const Eigen::Vector3d center = balls.centers.row(i).transpose();
      const Eigen::Vector3d peak = star.pf.prongs.positions.row(i % P).transpose();
      ASSERT_TRUE(star.pm.query->inside(center));  // and it sees its peak along the arm:
      ASSERT_GE(star.pm.query->ray_hit(center, peak - center), (peak - center).norm() - 1e-6);
    }
    for (Eigen::Index p = 0; p < P; ++p) {
      EXPECT_EQ(ends.ball[p], c.ring < 0 ? -1 : c.ring * P + p)
          << "prong " << p << ", balls " << c.rings[0].first << " away first";
    }
  }
}

// A skeleton whose node and link stick out of a sphere: the node moves inside, and the link
// that crosses the surface is split until every segment is inside.
TEST(KeepInside, NodesAndLinksOutsideTheSurfaceMoveIn) {
  const Mesh sphere = test::icosphere(4, 1.0);
  const dcg::SurfaceQuery surface(sphere);
  dcg::Skeleton s;
  s.positions = (dcg::Points(2, 3) << 0, 0, 0, 0.7, 0.7, 0.2).finished();  // the second: outside
  s.radii = Eigen::Vector2d(0.9, 0.1);
  s.links = (dcg::Edges(1, 2) << 0, 1).finished();
  s.polylines = {(dcg::Points(3, 3) << 0, 0, 0, 0.4, 0.4, 0.1, 0.7, 0.7, 0.2).finished()};
  ASSERT_FALSE(surface.inside(s.positions.row(1).transpose()));
  int reports = 0;
  dcg::keep_inside(s, surface, dcg::Progress([&](const std::string& stage, double) {
                     EXPECT_EQ(stage, "skeleton");
                     ++reports;
                     return true;
                   }));
  EXPECT_GT(reports, 0);
  EXPECT_TRUE(surface.inside(s.positions.row(1).transpose()));
  EXPECT_EQ(s.positions.row(0), Eigen::RowVector3d(0, 0, 0));  // inside: left alone
  const dcg::Points& poly = s.polylines[0];
  EXPECT_EQ(poly.row(poly.rows() - 1), s.positions.row(1));
  for (Eigen::Index i = 0; i + 1 < poly.rows(); ++i) {
    EXPECT_TRUE(surface.inside(poly.row(i).transpose()));
    EXPECT_FALSE(surface.segment_blocked(poly.row(i).transpose(), poly.row(i + 1).transpose()));
  }
}

}  // namespace

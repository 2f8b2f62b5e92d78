// dcg/remap.h (stage 7): the snake pulls a straight link into the middle of a curved tube, moves
// each point only in its plane normal to the link, keeps the ends, stays inside, and a link that
// leaves the shape starts from a path through the waypoints.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "dcg/force_field.h"
#include "dcg/remap.h"
#include "dcg/surface_query.h"
#include "shapes.h"

namespace {

namespace test = dcg::test;

double off_core(const Eigen::Vector3d& p) {
  return std::hypot(std::hypot(p.x(), p.y()) - 1.0, p.z());
}

struct TorusField {
  dcg::Mesh mesh = test::torus(1.0, 0.3, 96, 48);
  std::shared_ptr<const dcg::SurfaceQuery> query = std::make_shared<const dcg::SurfaceQuery>(mesh);
  dcg::ForceField field{query};
};

// One link between two points on opposite sides of the ring: its chord crosses the hole.
struct AcrossTheHole {
  dcg::Points nodes = (dcg::Points(2, 3) << 1, 0, 0, -1, 0, 0).finished();
  dcg::Edges links = (dcg::Edges(1, 2) << 0, 1).finished();
  Eigen::VectorXd radii = Eigen::VectorXd::Constant(2, 0.3);
};

// n points on the torus's core circle.
dcg::Points core_circle(int n) {
  dcg::Points pts(n, 3);
  for (int i = 0; i < n; ++i)
    pts.row(i) << std::cos(2 * M_PI * i / n), std::sin(2 * M_PI * i / n), 0;
  return pts;
}

// Every segment of each polyline stays inside (a segment between two inside points may not
// cross the surface either).
void expect_segments_inside(const dcg::Remapped& r, const dcg::SurfaceQuery& query) {
  for (const dcg::Points& p : r.polylines) {
    for (Eigen::Index i = 0; i + 1 < p.rows(); ++i) {
      EXPECT_FALSE(query.segment_blocked(p.row(i).transpose(), p.row(i + 1).transpose())) << i;
    }
  }
}

TEST(Remap, SnakeFollowsTheMiddleOfACurvedTube) {
  TorusField t;
  const double a = 60 * M_PI / 180;
  dcg::Points nodes(2, 3);
  nodes << 1, 0, 0, std::cos(a), std::sin(a), 0;
  const Eigen::VectorXd radii = Eigen::VectorXd::Constant(2, 0.3);
  dcg::Edges links(1, 2);
  links << 0, 1;
  const dcg::Remapped r = dcg::remap_links(nodes, radii, links, t.field, dcg::Points(0, 3));
  ASSERT_EQ(r.polylines.size(), 1u);
  const dcg::Points& p = r.polylines[0];
  ASSERT_GE(p.rows(), 5);
  EXPECT_EQ(p.row(0), nodes.row(0));
  EXPECT_EQ(p.row(p.rows() - 1), nodes.row(1));
  EXPECT_EQ(r.rerouted[0], 0);
  const Eigen::Vector3d chord = (nodes.row(1) - nodes.row(0)).transpose().normalized();
  const double straight_mid = 1.0 - std::cos(a / 2);  // the chord's middle, off the core circle
  for (Eigen::Index i = 1; i + 1 < p.rows(); ++i) {
    const Eigen::Vector3d q = p.row(i).transpose();
    EXPECT_TRUE(t.query->inside(q)) << i;
    EXPECT_LT(off_core(q), 0.5 * straight_mid) << "point " << i << " stayed near the chord";
    // In its plane: its coordinate along the chord is the one it started with (evenly spaced).
    const double s = (q - nodes.row(0).transpose()).dot(chord);
    EXPECT_NEAR(s, (nodes.row(1) - nodes.row(0)).norm() * i / (p.rows() - 1), 1e-9) << i;
  }
  EXPECT_GT(r.iterations[0], 0);
  EXPECT_LE(r.iterations[0], 100);
}

TEST(Remap, ALinkThatLeavesTheShapeIsRouted) {
  TorusField t;
  const AcrossTheHole link;
  const dcg::Remapped r =
      dcg::remap_links(link.nodes, link.radii, link.links, t.field, core_circle(24));
  EXPECT_EQ(r.rerouted[0], 1);
  EXPECT_EQ(r.unrouted, 0);
  const dcg::Points& p = r.polylines[0];
  for (Eigen::Index i = 0; i < p.rows(); ++i) {
    EXPECT_TRUE(t.query->inside(p.row(i).transpose())) << i;
    EXPECT_LT(off_core(p.row(i).transpose()), 0.25) << i;
  }
  expect_segments_inside(r, *t.query);
}

TEST(Remap, ARouteThroughThousandsOfWaypointsFindsItsWay) {
  // Past 1500 waypoints in the ellipsoid each point tries only its nearest (a grid). 4000
  // points inside the ring, none near the straight link's middle (the hole).
  TorusField t;
  const AcrossTheHole link;
  dcg::Points cloud(4000, 3);
  for (int i = 0; i < 4000; ++i) {
    const double u = 2 * M_PI * i / 4000, v = 2 * M_PI * ((i * 37) % 4000) / 4000.0,
                 rho = 0.2 * ((i * 53) % 100) / 100.0;
    cloud.row(i) << (1 + rho * std::cos(v)) * std::cos(u), (1 + rho * std::cos(v)) * std::sin(u),
        rho * std::sin(v);
  }
  const dcg::Remapped r = dcg::remap_links(link.nodes, link.radii, link.links, t.field, cloud);
  EXPECT_EQ(r.rerouted[0], 1);
  EXPECT_EQ(r.unrouted, 0);
  expect_segments_inside(r, *t.query);
  for (Eigen::Index i = 0; i < r.polylines[0].rows(); ++i) {
    EXPECT_LT(off_core(r.polylines[0].row(i).transpose()), 0.3) << i;
  }
}

TEST(Remap, ALinkWithNoRouteTriesTheExtraWaypoints) {
  // No waypoint at all: the link has no route until the extra ones (asked for once) come.
  TorusField t;
  const AcrossTheHole link;
  int asked = 0;
  auto ring = [&](const dcg::Progress&, double, double) {
    ++asked;
    return core_circle(24);
  };
  const dcg::Remapped r =
      dcg::remap_links(link.nodes, link.radii, link.links, t.field, dcg::Points(0, 3), {}, ring);
  EXPECT_EQ(asked, 1);
  EXPECT_EQ(r.unrouted, 0);
  EXPECT_EQ(r.rerouted[0], 1);
  expect_segments_inside(r, *t.query);
}

TEST(Remap, NoIterationsKeepsTheStraightLink) {
  TorusField t;
  dcg::Points nodes(2, 3);
  nodes << 1, 0, 0, std::cos(0.5), std::sin(0.5), 0;
  dcg::Edges links(1, 2);
  links << 0, 1;
  dcg::RemapOptions o;
  o.snake_iterations = 0;
  const dcg::Remapped r = dcg::remap_links(nodes, Eigen::VectorXd::Constant(2, 0.3), links, t.field,
                                           dcg::Points(0, 3), o);
  const dcg::Points& p = r.polylines[0];
  EXPECT_EQ(p.rows(), 5);  // at least 3 inner points
  for (Eigen::Index i = 0; i < p.rows(); ++i) {
    const Eigen::RowVector3d expected =
        nodes.row(0) + (nodes.row(1) - nodes.row(0)) * (double(i) / (p.rows() - 1));
    EXPECT_TRUE(p.row(i).isApprox(expected, 1e-12)) << i;
  }
}

}  // namespace

// Stage 3's end points and the points of stage 6 (dcg/end_points.h).
#include "dcg/end_points.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <utility>
#include <vector>

#include "chords.h"
#include "dcg/errors.h"
#include "dcg/surface_query.h"

namespace dcg {
namespace {

Eigen::Vector3d nearest_row(const Points& points, const Eigen::Vector3d& p) {
  Eigen::Vector3d nearest = p;
  double best = std::numeric_limits<double>::infinity();
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    const double d = (points.row(i).transpose() - p).squaredNorm();
    if (d < best) {
      best = d;
      nearest = points.row(i).transpose();
    }
  }
  return nearest;
}

// The first point inside (by the distance's sign and by ray parity) at 5%, 10%, ... 50% of the
// way from `peak` toward `toward`.
void first_inside_toward(const SurfaceQuery& query, const Eigen::Vector3d& peak,
                         const Eigen::Vector3d& toward, Eigen::Vector3d* p, double* radius) {
  for (int k = 1; k <= 10; ++k) {
    const Eigen::Vector3d q = peak + 0.05 * k * (toward - peak);
    if (query.inside(q) && query.inside_by_parity(q)) {
      *p = q;
      *radius = query.distance(q);
    }
    if (*radius > 0) break;
  }
}

// The inward chord of the working-mesh vertices within 0.03 of `peak`, nearest first: the first
// one inside by both tests.
void nearby_inward_point(const Mesh& working, const SurfaceQuery& query,
                         const Eigen::Vector3d& peak, const Eigen::Vector3d& toward,
                         Eigen::Vector3d* p, double* radius) {
  std::vector<std::pair<double, int>> near;
  for (Eigen::Index v = 0; v < working.V.rows(); ++v) {
    const double d = (working.V.row(v).transpose() - peak).norm();
    if (d < 0.03) near.emplace_back(d, static_cast<int>(v));
  }
  std::sort(near.begin(), near.end());
  for (const auto& candidate : near) {
    double rv = 0;
    const Eigen::Vector3d q = internal::inward_point(working, query, candidate.second, toward, &rv);
    if (rv > 0 && query.inside_by_parity(q)) {
      *p = q;
      *radius = rv;
      return;
    }
  }
}

}  // namespace

EndPoints find_end_points(const Prongs& prongs, const Balls& balls, const SurfaceQuery& query,
                          double min_radius) {
  const Eigen::Index P = prongs.vertices.size(), B = balls.radii.size();
  if (balls.centers.rows() != B) throw InputError("end points: centers and radii differ in size");
  EndPoints out;
  out.ball = Eigen::VectorXi::Constant(P, -1);
  out.centers = prongs.positions;
  out.radii = Eigen::VectorXd::Zero(P);
  std::vector<char> taken(B, 0);
  std::vector<std::pair<double, int>> order;
  order.reserve(B);
  for (Eigen::Index p = 0; p < P; ++p) {
    const Eigen::Vector3d peak = prongs.positions.row(p).transpose();
    order.clear();
    for (Eigen::Index b = 0; b < B; ++b) {
      if (taken[b] || !(balls.radii[b] >= min_radius)) continue;
      order.emplace_back((balls.centers.row(b).transpose() - peak).squaredNorm(),
                         static_cast<int>(b));
    }
    // Nearest first, taken off a heap one at a time: the first few balls usually see the peak,
    // so sorting all of them (a stage-1 ball set has thousands) cost most of the stage.
    const auto farther = std::greater<std::pair<double, int>>();
    std::make_heap(order.begin(), order.end(), farther);
    double bound = std::numeric_limits<double>::infinity();  // set by the first far, small ball
    while (!order.empty()) {
      std::pop_heap(order.begin(), order.end(), farther);
      const auto [d2, b] = order.back();
      order.pop_back();
      // Sees the peak: the first surface hit from the center toward the peak is the peak itself
      // (up to a tolerance for the peak's own triangles and float rounding).
      const Eigen::Vector3d c = balls.centers.row(b).transpose();
      const double length = std::sqrt(d2);
      if (length > bound) break;
      const double hit = query.ray_hit(c, peak - c);
      if (!(hit >= length - std::max(1e-6, 1e-3 * length))) continue;
      if (length > kEndBallFarRadii * balls.radii[b] && length > kEndBallFarGap) {
        bound = std::min(bound, kEndBallSearch * length);
        continue;
      }
      out.ball[p] = b;
      out.centers.row(p) = c.transpose();
      out.radii[p] = balls.radii[b];
      taken[b] = 1;
      break;
    }
  }
  return out;
}

Eigen::Vector3d unseen_end_point(const Prongs& prongs, Eigen::Index p, const Mesh& working,
                                 const SurfaceQuery& query, const Points& domain_points,
                                 double* radius) {
  const Eigen::Vector3d peak = prongs.positions.row(p).transpose();
  const Eigen::Vector3d toward = nearest_row(domain_points, peak);
  Eigen::Vector3d point =
      internal::inward_point(working, query, prongs.vertices[p], toward, radius);
  if (!(*radius > 0)) first_inside_toward(query, peak, toward, &point, radius);
  if (!(*radius > 0)) nearby_inward_point(working, query, peak, toward, &point, radius);
  return point;
}

GraphPoints graph_points(const ConnectionPoints& connection, const EndPoints& ends,
                         const Prongs& prongs, const Mesh& working, const SurfaceQuery& query,
                         const Points& domain_points) {
  std::vector<Eigen::Vector3d> points;
  std::vector<double> radii;
  std::vector<int> prong;
  for (Eigen::Index i = 0; i < connection.positions.rows(); ++i) {
    points.push_back(connection.positions.row(i).transpose());
    radii.push_back(connection.radii[i]);
    prong.push_back(-1);
  }
  for (Eigen::Index e = 0; e < ends.ball.size(); ++e) {
    if (ends.ball[e] < 0) continue;
    points.push_back(ends.centers.row(e).transpose());
    radii.push_back(ends.radii[e]);
    prong.push_back(static_cast<int>(e));
  }
  for (Eigen::Index e = 0; e < ends.ball.size(); ++e) {
    if (ends.ball[e] >= 0) continue;
    double r = 0;
    const Eigen::Vector3d p = unseen_end_point(prongs, e, working, query, domain_points, &r);
    if (!(r > 0)) continue;
    points.push_back(p);
    radii.push_back(r);
    prong.push_back(static_cast<int>(e));
  }
  GraphPoints out;
  const auto n = static_cast<Eigen::Index>(points.size());
  out.points.resize(n, 3);
  out.radii.resize(n);
  out.prong.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    out.points.row(i) = points[i].transpose();
    out.radii[i] = radii[i];
    out.prong[i] = prong[i];
  }
  return out;
}

}  // namespace dcg

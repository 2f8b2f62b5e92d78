// Stage 7: snake re-mapping of the links. See dcg/remap.h.
#include "dcg/remap.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>

#include <Eigen/Dense>
#include <tbb/parallel_for.h>

#include "dcg/errors.h"
#include "dcg/force_field.h"
#include "dcg/surface_query.h"

namespace dcg {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Resamples the polyline `path` into `count` points evenly spaced by arc length (ends kept).
Points resample(const std::vector<Eigen::Vector3d>& path, int count) {
  std::vector<double> arc(path.size(), 0.0);
  for (std::size_t i = 1; i < path.size(); ++i) arc[i] = arc[i - 1] + (path[i] - path[i - 1]).norm();
  Points out(count, 3);
  std::size_t seg = 0;
  for (int k = 0; k < count; ++k) {
    const double s = arc.back() * k / (count - 1);
    while (seg + 2 < path.size() && arc[seg + 1] < s) ++seg;
    const double len = arc[seg + 1] - arc[seg];
    const double t = len > 0 ? std::clamp((s - arc[seg]) / len, 0.0, 1.0) : 0.0;
    out.row(k) = ((1 - t) * path[seg] + t * path[seg + 1]).transpose();
  }
  out.row(0) = path.front().transpose();
  out.row(count - 1) = path.back().transpose();
  return out;
}

// Shortest path from a to b through waypoints that see each other (each hop a segment that does
// not meet the surface), among the waypoints in the ellipsoid |w - a| + |w - b| <= stretch |a - b|.
// Empty when there is none.
std::vector<Eigen::Vector3d> route(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                   const Points& waypoints, const SurfaceQuery& query,
                                   double stretch) {
  const double chord = (b - a).norm();
  std::vector<Eigen::Vector3d> pts = {a, b};
  for (Eigen::Index i = 0; i < waypoints.rows(); ++i) {
    const Eigen::Vector3d w = waypoints.row(i).transpose();
    if ((w - a).norm() + (w - b).norm() <= stretch * chord) pts.push_back(w);
  }
  if (pts.size() > 1500) pts.resize(1500);  // bounds the O(k^2) visibility tests
  const int n = static_cast<int>(pts.size());
  std::vector<double> dist(n, kInf);
  std::vector<int> prev(n, -1);
  std::vector<char> done(n, 0);
  dist[0] = 0;
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> heap;
  heap.push({0.0, 0});
  while (!heap.empty()) {
    const auto [d, u] = heap.top();
    heap.pop();
    if (done[u]) continue;
    done[u] = 1;
    if (u == 1) break;
    for (int v = 0; v < n; ++v) {
      if (done[v]) continue;
      const double nd = d + (pts[u] - pts[v]).norm();
      if (nd >= dist[v]) continue;
      if (query.segment_blocked(pts[u], pts[v])) continue;
      dist[v] = nd;
      prev[v] = u;
      heap.push({nd, v});
    }
  }
  if (!done[1]) return {};
  std::vector<Eigen::Vector3d> path;
  for (int u = 1; u >= 0; u = prev[u]) path.push_back(pts[u]);
  std::reverse(path.begin(), path.end());
  return path;
}

struct LinkResult {
  Points polyline;
  int iterations = 0;
  bool rerouted = false;
  bool unrouted = false;
  int refused = 0;
};

LinkResult snake_link(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double ra, double rb,
                      const ForceField& field, const Points& waypoints, const RemapOptions& o) {
  const SurfaceQuery& query = field.query();
  LinkResult out;
  const double chord = (b - a).norm();
  // Spacing by the larger radius: a link into a needle tip (radius ~0) would get dozens of points.
  const double mean_radius = std::max(0.5 * (ra + rb), 1e-9), big_radius = std::max({ra, rb, 1e-9});
  const int inner = std::clamp(static_cast<int>(std::ceil(chord / (o.spacing * big_radius))) - 1,
                               o.min_inner_points, std::max(o.min_inner_points, o.max_inner_points));
  const int count = inner + 2;
  // The start: the straight link, or a path through the waypoints when it leaves the shape.
  std::vector<Eigen::Vector3d> path = {a, b};
  if (chord > 0 && query.segment_blocked(a, b)) {
    std::vector<Eigen::Vector3d> routed = route(a, b, waypoints, query, 1.5);
    if (routed.empty()) routed = route(a, b, waypoints, query, 3.0);
    if (routed.empty()) {
      out.unrouted = true;
    } else {
      path = routed;
      out.rerouted = true;
    }
  }
  Points p = resample(path, count);
  out.polyline = p;
  if (chord <= 0 || o.snake_iterations <= 0) return out;

  // The plane of each inner point: normal to the chord.
  const Eigen::Vector3d dir = (b - a) / chord;
  Eigen::Vector3d e1 = dir.unitOrthogonal(), e2 = dir.cross(e1);
  // Radii along the link (interpolated by the chord coordinate).
  Eigen::VectorXd r(count);
  for (int i = 0; i < count; ++i) {
    const double s = std::clamp((p.row(i).transpose() - a).dot(dir) / chord, 0.0, 1.0);
    r[i] = std::max((1 - s) * ra + s * rb, 1e-9);
  }
  // Internal stiffness on the inner points (ends fixed): K = a D'D + b G'G.
  const int m = inner;
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(m, m + 2), G = Eigen::MatrixXd::Zero(m + 1, m + 2);
  for (int j = 0; j < m; ++j) {
    D(j, j) = 1;
    D(j, j + 1) = -2;
    D(j, j + 2) = 1;
  }
  for (int j = 0; j <= m; ++j) {
    G(j, j) = -1;
    G(j, j + 1) = 1;
  }
  const Eigen::MatrixXd Kfull = o.curvature_weight * D.transpose() * D + o.stretch_weight * G.transpose() * G;
  const Eigen::MatrixXd K = Kfull.block(1, 1, m, m);
  const Eigen::MatrixXd Kb = Kfull.block(1, 0, m, m + 2);  // for the fixed ends' contribution
  const Eigen::LDLT<Eigen::MatrixXd> solver(Eigen::MatrixXd::Identity(m, m) + 2 * o.time_step * K);
  const double n = field.options().force_exponent;
  Eigen::MatrixXd uv(m + 2, 2), force(m, 2), last_gradient = Eigen::MatrixXd::Zero(m, 2);
  std::vector<double> damping(m, 1.0);
  // The fixed ends' part of the semi-implicit step below (the ends never move).
  Eigen::MatrixXd ends = Eigen::MatrixXd::Zero(m + 2, 2);
  for (const int i : {0, m + 1}) {
    const Eigen::Vector3d q = p.row(i).transpose() - a;
    ends(i, 0) = q.dot(e1);
    ends(i, 1) = q.dot(e2);
  }
  const Eigen::MatrixXd boundary = 2 * o.time_step * Kb * ends;
  for (int it = 0; it < o.snake_iterations; ++it) {
    // In-plane coordinates (relative to a).
    for (int i = 0; i < count; ++i) {
      const Eigen::Vector3d q = p.row(i).transpose() - a;
      uv(i, 0) = q.dot(e1);
      uv(i, 1) = q.dot(e2);
    }
    // External force: - c r^(n+2) grad |F| in the plane (the field's own gradient, one fan).
    for (int j = 0; j < m; ++j) {
      const int i = j + 1;
      const FieldSample f = field.at_with_gradient(p.row(i).transpose());
      if (!f.inside()) {  // on or past the surface (it cannot be: the start is inside)
        force.row(j).setZero();
        continue;
      }
      // Keep the local radius honest where the shape narrows.
      r[i] = std::min(r[i], std::max(f.r_min, 1e-9));
      // Per-point damping: a gradient that turns back (the point stepped over the valley of
      // |F|) halves the point's step, one that keeps its way lets it grow back.
      const Eigen::Vector2d grad(f.gradient.dot(e1), f.gradient.dot(e2));
      if (grad.dot(last_gradient.row(j).transpose()) < 0) {
        damping[j] *= 0.5;
      } else {
        damping[j] = std::min(1.0, 1.25 * damping[j]);
      }
      last_gradient.row(j) = grad.transpose();
      const double scale = damping[j] * o.field_weight * std::pow(r[i], n + 2);
      force.row(j) = -scale * grad.transpose();
    }
    // Semi-implicit step: (I + 2 tau K) x' = x + tau f - 2 tau Kb_ends x_ends.
    const Eigen::MatrixXd rhs = uv.block(1, 0, m, 2) + o.time_step * force - boundary;
    const Eigen::MatrixXd next = solver.solve(rhs);
    double worst = 0;
    for (int j = 0; j < m; ++j) {
      const int i = j + 1;
      Eigen::Vector2d delta = (next.row(j) - uv.row(i)).transpose();
      const double cap = 0.5 * r[i];
      if (delta.norm() > cap) delta *= cap / delta.norm();
      const Eigen::Vector3d from = p.row(i).transpose();
      const Eigen::Vector3d to = from + delta.x() * e1 + delta.y() * e2;
      if (query.segment_blocked(from, to)) {
        ++out.refused;
        continue;
      }
      p.row(i) = to.transpose();
      worst = std::max(worst, delta.norm() / std::max(r[i], 0.5 * mean_radius));
    }
    out.iterations = it + 1;
    if (worst < o.tolerance) break;
  }
  out.polyline = p;
  return out;
}

}  // namespace

Remapped remap_links(const Points& nodes, const Eigen::VectorXd& radii, const Edges& links,
                     const ForceField& field, const Points& waypoints, const RemapOptions& options) {
  if (options.snake_iterations < 0 || options.min_inner_points < 1 || options.spacing <= 0) {
    throw InputError("remap: bad options (snake_iterations >= 0, min_inner_points >= 1)");
  }
  const int K = static_cast<int>(links.rows());
  Remapped out;
  out.polylines.resize(K);
  out.iterations = Eigen::VectorXi::Zero(K);
  out.rerouted = Eigen::VectorXi::Zero(K);
  std::vector<LinkResult> results(K);
  tbb::parallel_for(0, K, [&](int l) {
    const int a = links(l, 0), b = links(l, 1);
    results[l] = snake_link(nodes.row(a).transpose(), nodes.row(b).transpose(), radii[a], radii[b],
                            field, waypoints, options);
  });
  for (int l = 0; l < K; ++l) {
    out.polylines[l] = std::move(results[l].polyline);
    out.iterations[l] = results[l].iterations;
    out.rerouted[l] = results[l].rerouted ? 1 : 0;
    out.moves_refused += results[l].refused;
    out.unrouted += results[l].unrouted ? 1 : 0;
  }
  return out;
}

}  // namespace dcg

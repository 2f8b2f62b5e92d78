// Stage 5: shrinking along the field and greedy merging. See dcg/connection_points.h.
#include "dcg/connection_points.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <unordered_map>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "dcg/errors.h"
#include "dcg/force_field.h"
#include "dcg/options.h"
#include "dcg/surface_query.h"
#include "polling.h"

namespace dcg {
namespace {

struct ShrinkResult {
  Eigen::Vector3d p;
  double magnitude = 0;
  int steps = 0;
  bool converged = false;
};

ShrinkResult shrink(const Eigen::Vector3d& start, const ForceField& field,
                    const ConnectionPointsOptions& o) {
  const double n = field.options().force_exponent;
  ShrinkResult out;
  Eigen::Vector3d p = start;
  FieldSample s = field.at(p);
  double alpha = o.shrink_step;
  int refused = 0, stalled = 0;
  for (int step = 0; step < o.max_steps; ++step) {
    if (!std::isfinite(s.r_min)) break;  // not inside anything: leave it where it is
    Eigen::Vector3d d = alpha * std::pow(s.r_min, n + 1) * s.force;
    if (d.norm() > 0.5 * s.r_min) d *= 0.5 * s.r_min / d.norm();
    if (d.norm() < o.arrived * s.r_min) {
      out.converged = true;
      break;
    }
    const Eigen::Vector3d q = p + d;
    const FieldSample t = field.at(q);
    if (t.magnitude < s.magnitude && t.outside_rays <= s.outside_rays &&
        !field.query().segment_blocked(p, q)) {
      // Along a medial ridge |F| barely changes: a few steps in a row that lower it by less
      // than 1e-4 of itself mean the point has arrived.
      stalled = s.magnitude - t.magnitude < 1e-4 * s.magnitude ? stalled + 1 : 0;
      p = q;
      s = t;
      ++out.steps;
      refused = 0;
      alpha = std::min(o.max_growth * o.shrink_step, 2 * alpha);
      if (stalled >= 3) {
        out.converged = true;
        break;
      }
    } else {
      alpha *= 0.5;
      if (++refused >= o.max_halvings) {
        out.converged = true;
        break;
      }
    }
  }
  out.p = p;
  out.magnitude = s.magnitude;
  return out;
}

}  // namespace

Eigen::VectorXi merge_greedily(const Points& points, const Eigen::VectorXd& magnitude,
                               const Eigen::VectorXd& radii, double merge_fraction,
                               std::vector<int>* survivors) {
  const int count = static_cast<int>(points.rows());
  Eigen::VectorXi cluster = Eigen::VectorXi::Constant(count, -1);
  if (survivors) survivors->clear();
  if (count == 0) return cluster;
  std::vector<int> order(count);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return magnitude[a] < magnitude[b]; });
  // A grid of cell size = the largest merge distance, so that neighbours lie in 27 cells.
  const double reach = std::max(merge_fraction * radii.maxCoeff(), 1e-12);
  const Eigen::RowVector3d lo = points.colwise().minCoeff();
  auto key_of = [&](const Eigen::RowVector3d& p, int dx, int dy, int dz) {
    const Eigen::RowVector3d c = ((p - lo) / reach).array().floor();
    const std::int64_t x = static_cast<std::int64_t>(c.x()) + dx,
                       y = static_cast<std::int64_t>(c.y()) + dy,
                       z = static_cast<std::int64_t>(c.z()) + dz;
    return (x * 73856093) ^ (y * 19349663) ^ (z * 83492791);
  };
  std::unordered_map<std::int64_t, std::vector<int>> grid;
  for (int i = 0; i < count; ++i) grid[key_of(points.row(i), 0, 0, 0)].push_back(i);
  int clusters = 0;
  for (int i : order) {
    if (cluster[i] >= 0) continue;
    const int c = clusters++;
    cluster[i] = c;
    if (survivors) survivors->push_back(i);
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          auto it = grid.find(key_of(points.row(i), dx, dy, dz));
          if (it == grid.end()) continue;
          for (int j : it->second) {
            if (cluster[j] >= 0) continue;
            const double limit = merge_fraction * std::min(radii[i], radii[j]);
            if ((points.row(i) - points.row(j)).squaredNorm() < limit * limit) cluster[j] = c;
          }
        }
  }
  return cluster;
}

ConnectionPoints compute_connection_points(const Points& domain_points, const ForceField& field,
                                           const ConnectionPointsOptions& options,
                                           const Progress& progress, double from, double to) {
  check_option("shrink_step", options.shrink_step);
  if (options.max_steps < 0 || options.max_halvings < 1 || !(options.arrived >= 0)) {
    throw InputError("connection points: max_steps and arrived must be >= 0 and max_halvings >= 1");
  }
  const int count = static_cast<int>(domain_points.rows());
  ConnectionPoints out;
  out.shrunk.resize(count, 3);
  out.shrunk_magnitude.resize(count);
  out.shrunk_radii.resize(count);
  out.steps.resize(count);
  out.converged.assign(count, 0);
  internal::ThrottledProgress tick(progress, "connection_points", from, to);
  tick(0);
  // Points shrink independently: 16 per thread at a time (a point takes up to a few ms: 200
  // steps of 64 rays; with 4, a thread waited behind each chunk's slowest point: 10% of the
  // stage on the torus, knight and elephant), polled between.
  internal::parallel_chunks(count, internal::per_thread(16), 1, tick.part(0, 0.95),
                            [&](const tbb::blocked_range<int>& r) {
                              for (int i = r.begin(); i != r.end(); ++i) {
                                const ShrinkResult s =
                                    shrink(domain_points.row(i).transpose(), field, options);
                                out.shrunk.row(i) = s.p.transpose();
                                out.shrunk_magnitude[i] = s.magnitude;
                                out.shrunk_radii[i] = field.query().distance(s.p);
                                out.steps[i] = s.steps;
                                out.converged[i] = s.converged ? 1 : 0;
                              }
                            });
  tick(0.95);
  std::vector<int> survivors;
  out.cluster = merge_greedily(out.shrunk, out.shrunk_magnitude, out.shrunk_radii,
                               options.merge_fraction, &survivors);
  const int c = static_cast<int>(survivors.size());
  out.positions.resize(c, 3);
  out.radii.resize(c);
  out.magnitude.resize(c);
  out.source.resize(c);
  for (int k = 0; k < c; ++k) {
    const int i = survivors[k];
    out.positions.row(k) = out.shrunk.row(i);
    out.radii[k] = out.shrunk_radii[i];
    out.magnitude[k] = out.shrunk_magnitude[i];
    out.source[k] = i;
  }
  return out;
}

}  // namespace dcg

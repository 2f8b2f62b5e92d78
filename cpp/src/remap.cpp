// Stage 7: snake re-mapping of the links. See dcg/remap.h.
#include "dcg/remap.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>
#include <limits>
#include <numeric>
#include <optional>
#include <queue>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <Eigen/Dense>

#include "chords.h"
#include "dcg/errors.h"
#include "dcg/force_field.h"
#include "dcg/options.h"
#include "dcg/surface_query.h"
#include "polling.h"

namespace dcg {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
const char* const kStage = "remap";

// Resamples the polyline `path` into at least `count` points spaced by arc length, with every
// corner of `path` among them: each hop gets a share of the points by its length (at least one
// segment), so every resampled segment lies on a hop. A hop of a route sees its end from its
// start, so the resampled polyline stays inside; resampling across a corner would cut it, and a
// corner next to the surface is where such a cut leaves the shape.
Points resample(const std::vector<Eigen::Vector3d>& path, int count) {
  const int hops = static_cast<int>(path.size()) - 1;
  auto length = [&](int h) { return (path[h + 1] - path[h]).norm(); };
  double total = 0;
  for (int h = 0; h < hops; ++h) total += length(h);
  std::vector<int> pieces(hops, 1);
  int used = hops;
  for (int h = 0; h < hops && total > 0; ++h) {
    const int share = static_cast<int>(std::floor((count - 1) * length(h) / total));
    if (share > 1) {
      used += share - 1;
      pieces[h] = share;
    }
  }
  // What rounding left goes to the hops with the longest pieces.
  for (; used < count - 1; ++used) {
    int best = 0;
    for (int h = 1; h < hops; ++h)
      if (length(h) / pieces[h] > length(best) / pieces[best]) best = h;
    ++pieces[best];
  }
  Points out(used + 1, 3);
  Eigen::Index k = 0;
  for (int h = 0; h < hops; ++h)
    for (int j = 0; j < pieces[h]; ++j)
      out.row(k++) =
          (path[h] + (path[h + 1] - path[h]) * (static_cast<double>(j) / pieces[h])).transpose();
  out.row(k) = path.back().transpose();
  return out;
}

// The nearest other points of a point (unordered), by a uniform grid of about one point a cell
// searched in growing shells of cells.
class NeighbourGrid {
 public:
  explicit NeighbourGrid(const std::vector<Eigen::Vector3d>& pts) : pts_(pts) {
    lo_ = hi_ = pts[0];
    for (const auto& p : pts) {
      lo_ = lo_.cwiseMin(p);
      hi_ = hi_.cwiseMax(p);
    }
    // Each side at least 1/100 of the longest, so that points spread on a plane or a line get
    // cells of a few points each, not a million empty ones.
    const Eigen::Vector3d extent =
        (hi_ - lo_).cwiseMax(1e-2 * (hi_ - lo_).maxCoeff()).cwiseMax(1e-12);
    cell_ = std::cbrt(extent.prod() / static_cast<double>(pts.size()));
    dims_ = (extent / cell_).array().floor().cast<int>().cwiseMax(0) + 1;
    grid_.resize(static_cast<std::size_t>(dims_.prod()));
    for (int i = 0; i < static_cast<int>(pts.size()); ++i)
      grid_[index(cell_of(pts[i]))].push_back(i);
  }

  /// The k nearest points to point i (i excluded).
  void nearest(int i, int k, std::vector<int>& out) const {
    const Eigen::Vector3i c = cell_of(pts_[i]);
    found_.clear();
    for (int ring = 0;; ++ring) {
      // The cells at Chebyshev distance `ring` from c.
      for (int z = c.z() - ring; z <= c.z() + ring; ++z) {
        for (int y = c.y() - ring; y <= c.y() + ring; ++y) {
          for (int x = c.x() - ring; x <= c.x() + ring; ++x) {
            if (std::max({std::abs(x - c.x()), std::abs(y - c.y()), std::abs(z - c.z())}) != ring)
              continue;
            if (x < 0 || y < 0 || z < 0 || x >= dims_.x() || y >= dims_.y() || z >= dims_.z())
              continue;
            for (const int j : grid_[index(Eigen::Vector3i(x, y, z))]) {
              if (j != i) found_.emplace_back((pts_[j] - pts_[i]).squaredNorm(), j);
            }
          }
        }
      }
      if (ring >= dims_.maxCoeff()) break;  // every cell seen
      // A point not seen yet is more than ring cells away; found_[k - 1] is the k-th nearest
      // seen once partitioned.
      if (static_cast<int>(found_.size()) < k) continue;
      std::nth_element(found_.begin(), found_.begin() + (k - 1), found_.end());
      if (found_[k - 1].first <= (ring * cell_) * (ring * cell_)) break;
    }
    if (static_cast<int>(found_.size()) > k) {
      std::nth_element(found_.begin(), found_.begin() + (k - 1), found_.end());
      found_.resize(k);
    }
    out.clear();
    for (const auto& f : found_) out.push_back(f.second);
  }

 private:
  Eigen::Vector3i cell_of(const Eigen::Vector3d& p) const {
    return ((p - lo_) / cell_).array().floor().cast<int>().min(dims_.array() - 1).max(0).matrix();
  }
  int index(const Eigen::Vector3i& c) const {
    return (c.z() * dims_.y() + c.y()) * dims_.x() + c.x();
  }

  const std::vector<Eigen::Vector3d>& pts_;
  Eigen::Vector3d lo_, hi_;
  double cell_ = 1;
  Eigen::Vector3i dims_;
  std::vector<std::vector<int>> grid_;
  mutable std::vector<std::pair<double, int>> found_;  // scratch (one grid per route call)
};

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
  // Up to 1500 points every popped point tries all the others (the shortest route, long hops
  // allowed). Past that, O(k^2) rays would cost seconds when no route exists, so a point tries
  // only its 48 nearest (at most 48 rays a point). Cutting the list to 1500 instead dropped the
  // waypoints that a route through a thin part needed.
  constexpr int kAllPairs = 1500, kNearest = 48;
  const int n = static_cast<int>(pts.size());
  std::optional<NeighbourGrid> grid;
  if (n > kAllPairs) grid.emplace(pts);
  std::vector<int> near;
  std::vector<double> dist(n, kInf);
  std::vector<int> prev(n, -1);
  std::vector<char> done(n, 0);
  // A* towards b: the straight distance to b never overestimates what is left (and never
  // drops by more than a hop's length), so a point is final when popped, as in Dijkstra, but
  // the search spreads towards b instead of through the whole ellipsoid (5-10x fewer points
  // popped on the elephant's routes).
  auto to_b = [&](int v) { return (pts[v] - b).norm(); };
  dist[0] = 0;
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> heap;
  heap.push({to_b(0), 0});
  // The hops from u that would shorten a way, their rays cast 8 at a time (Embree packets),
  // then taken in order: each hop's test depends on u alone, so the order of the searches is
  // the one a ray per hop gives.
  std::vector<int> hops;
  std::vector<double> ways, from, to;  // ways: dist[u] plus the hop's length
  std::vector<unsigned char> blocked;
  auto relax = [&](int u, const auto& candidates) {
    hops.clear();
    ways.clear();
    from.clear();
    to.clear();
    for (const int v : candidates) {
      const double nd = dist[u] + (pts[u] - pts[v]).norm();
      if (done[v] || nd >= dist[v]) continue;
      hops.push_back(v);
      ways.push_back(nd);
      from.insert(from.end(), pts[u].data(), pts[u].data() + 3);
      to.insert(to.end(), pts[v].data(), pts[v].data() + 3);
    }
    blocked.assign(hops.size(), 0);
    query.segments_blocked(from.data(), to.data(), static_cast<int>(hops.size()), 0,
                           blocked.data());
    for (std::size_t h = 0; h < hops.size(); ++h) {
      const int v = hops[h];
      const double nd = ways[h];
      if (blocked[h] || nd >= dist[v]) continue;  // >=: v listed twice (b among the nearest)
      dist[v] = nd;
      prev[v] = u;
      heap.push({nd + to_b(v), v});
    }
  };
  std::vector<int> everyone(n);
  std::iota(everyone.begin(), everyone.end(), 0);
  while (!heap.empty()) {
    const int u = heap.top().second;
    heap.pop();
    if (done[u]) continue;
    done[u] = 1;
    if (u == 1) break;
    if (!grid) {
      relax(u, everyone);
    } else {
      grid->nearest(u, kNearest, near);
      near.push_back(1);  // b itself may be farther than the nearest, and in view
      relax(u, near);
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

// `retried`: a link with no route will be tried again with more waypoints, so it is left
// unfitted (its snake would be thrown away).
LinkResult snake_link(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double ra, double rb,
                      const ForceField& field, const Points& waypoints, const RemapOptions& o,
                      bool retried) {
  const SurfaceQuery& query = field.query();
  LinkResult out;
  const double chord = (b - a).norm();
  // Spacing by the larger radius: a link into a needle tip (radius ~0) would get dozens of points.
  const double mean_radius = std::max(0.5 * (ra + rb), 1e-9), big_radius = std::max({ra, rb, 1e-9});
  const int inner =
      std::clamp(static_cast<int>(std::ceil(chord / (o.spacing * big_radius))) - 1,
                 o.min_inner_points, std::max(o.min_inner_points, o.max_inner_points));
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
  Points p = resample(path, inner + 2);
  const int count = static_cast<int>(p.rows());  // more than inner + 2 on a route of many hops
  out.polyline = p;
  if (chord <= 0 || o.snake_iterations <= 0 || (out.unrouted && retried)) return out;

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
  const int m = count - 2;
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
  const Eigen::MatrixXd Kfull =
      o.curvature_weight * D.transpose() * D + o.stretch_weight * G.transpose() * G;
  const Eigen::MatrixXd K = Kfull.block(1, 1, m, m);
  const Eigen::MatrixXd Kb = Kfull.block(1, 0, m, m + 2);  // for the fixed ends' contribution
  const Eigen::LDLT<Eigen::MatrixXd> solver(Eigen::MatrixXd::Identity(m, m) + 2 * o.time_step * K);
  const double n = field.options().force_exponent;
  Eigen::MatrixXd uv(m + 2, 2), force(m, 2), last_gradient = Eigen::MatrixXd::Zero(m, 2);
  std::vector<double> damping(m, 1.0);
  std::vector<FieldSample> samples(m);
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
    // External force: - c r^(n+2) grad |F| in the plane (the field's own gradient, one fan a
    // point). The fans run in parallel: a long link would otherwise keep one thread busy while
    // the others wait for it.
    tbb::parallel_for(tbb::blocked_range<int>(0, m, 4), [&](const tbb::blocked_range<int>& range) {
      for (int j = range.begin(); j != range.end(); ++j)
        samples[j] = field.at_with_gradient(p.row(j + 1).transpose());
    });
    for (int j = 0; j < m; ++j) {
      const int i = j + 1;
      const FieldSample& f = samples[j];
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
      // The point must get there without crossing the surface, and its polyline segments to
      // both neighbours (the one before already moved this iteration) must stay inside too: a
      // point that is inside can still pull its segment across a concave fold of the surface.
      if (query.segment_blocked(from, to) || query.segment_blocked(p.row(i - 1).transpose(), to) ||
          query.segment_blocked(to, p.row(i + 1).transpose())) {
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

// The links in the order their snakes should start: first those whose chord leaves the shape
// (they are routed through waypoints: more points, more steps), then by decreasing chord, so
// that no thread takes a long snake when the others are nearly done. Each link's result is its
// own: the order changes only the waiting (octopus-low: 8 routed links of 56, remap 17.6 -> 16.7
// ms; torus 0.98 -> 0.86 ms).
std::vector<int> costliest_first(const Points& nodes, const Edges& links,
                                 const SurfaceQuery& query) {
  const int K = static_cast<int>(links.rows());
  std::vector<double> a(3 * static_cast<std::size_t>(K)), b(3 * static_cast<std::size_t>(K));
  std::vector<double> chord(K);
  for (int l = 0; l < K; ++l) {
    for (int k = 0; k < 3; ++k) {
      a[3 * l + k] = nodes(links(l, 0), k);
      b[3 * l + k] = nodes(links(l, 1), k);
    }
    chord[l] = (nodes.row(links(l, 0)) - nodes.row(links(l, 1))).norm();
  }
  std::vector<unsigned char> blocked(K, 0);
  query.segments_blocked(a.data(), b.data(), K, 0, blocked.data());
  std::vector<int> order(K);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int x, int y) {
    if (blocked[x] != blocked[y]) return blocked[x] > blocked[y];
    return chord[x] > chord[y];
  });
  return order;
}

}  // namespace

Remapped remap_links(const Points& nodes, const Eigen::VectorXd& radii, const Edges& links,
                     const ForceField& field, const Points& waypoints, const RemapOptions& options,
                     const MoreWaypoints& more_waypoints, const Progress& progress, double from,
                     double to) {
  check_option("snake_iterations", options.snake_iterations);
  if (options.min_inner_points < 1 || !(options.spacing > 0)) {
    throw InputError("remap: min_inner_points must be >= 1 and spacing > 0");
  }
  const int K = static_cast<int>(links.rows());
  Remapped out;
  out.polylines.resize(K);
  out.iterations = Eigen::VectorXi::Zero(K);
  out.rerouted = Eigen::VectorXi::Zero(K);
  std::vector<LinkResult> results(K);
  internal::ThrottledProgress tick(progress, kStage, from, to);
  tick(0);
  // Links are independent: 8 per thread at a time (a link takes up to a few ms; 2 per thread
  // left threads idle behind the slowest link of each chunk), polled between.
  auto snake_links = [&](const std::vector<int>& which, const Points& through, bool retried,
                         double a, double b) {
    internal::parallel_chunks(static_cast<int>(which.size()), internal::per_thread(8), 1,
                              tick.part(a, b), [&](const tbb::blocked_range<int>& r) {
                                for (int k = r.begin(); k != r.end(); ++k) {
                                  const int l = which[k], p = links(l, 0), q = links(l, 1);
                                  results[l] = snake_link(
                                      nodes.row(p).transpose(), nodes.row(q).transpose(), radii[p],
                                      radii[q], field, through, options, retried);
                                }
                              });
  };
  snake_links(costliest_first(nodes, links, field.query()), waypoints,
              static_cast<bool>(more_waypoints), 0, 0.7);
  // Links with no route: again, with the extra waypoints as well.
  std::vector<int> unrouted;
  for (int l = 0; l < K; ++l)
    if (results[l].unrouted) unrouted.push_back(l);
  if (!unrouted.empty() && more_waypoints) {
    tick(0.7);
    const Points more =
        more_waypoints(progress, from + 0.7 * (to - from), from + 0.8 * (to - from));
    Points all(waypoints.rows() + more.rows(), 3);
    all << waypoints, more;
    snake_links(unrouted, all, false, 0.8, 1);
  }
  for (int l = 0; l < K; ++l) {
    out.polylines[l] = std::move(results[l].polyline);
    out.iterations[l] = results[l].iterations;
    out.rerouted[l] = results[l].rerouted ? 1 : 0;
    out.moves_refused += results[l].refused;
    out.unrouted += results[l].unrouted ? 1 : 0;
  }
  return out;
}

Points chord_midpoints(const Mesh& mesh, const SurfaceQuery& surface, const Progress& progress,
                       double from, double to) {
  const Eigen::Index nf = mesh.F.rows();
  Points mid(nf, 3);
  std::vector<char> ok(static_cast<std::size_t>(nf), 0);
  internal::ThrottledProgress tick(progress, kStage, from, to);
  // Faces are independent: in chunks, polled between.
  const auto chunk = static_cast<Eigen::Index>(internal::per_thread(2048));
  internal::parallel_chunks(
      nf, chunk, Eigen::Index{512}, tick.part(0, 1),
      [&](const tbb::blocked_range<Eigen::Index>& range) {
        for (Eigen::Index f = range.begin(); f != range.end(); ++f) {
          const Eigen::Vector3d& n = surface.face_normal(static_cast<int>(f));
          if (n.isZero()) continue;
          const Eigen::Vector3d c =
              (mesh.V.row(mesh.F(f, 0)) + mesh.V.row(mesh.F(f, 1)) + mesh.V.row(mesh.F(f, 2)))
                  .transpose() /
              3.0;
          if (const auto m = internal::chord_middle(surface, c - 1e-7 * n, -n)) {
            mid.row(f) = m->transpose();
            ok[static_cast<std::size_t>(f)] = 1;
          }
        }
      });
  Eigen::Index k = 0;
  for (Eigen::Index f = 0; f < nf; ++f)
    if (ok[static_cast<std::size_t>(f)]) mid.row(k++) = mid.row(f);
  mid.conservativeResize(k, 3);
  return mid;
}

}  // namespace dcg

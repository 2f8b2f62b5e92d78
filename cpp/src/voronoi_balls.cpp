// Stage 1: Voronoi balls. See dcg/voronoi_balls.h and ALGORITHM.md "1. Voronoi balls".
//
// Sampling: farthest-point sampling (FPS) over a dense candidate set on the surface: the mesh's
// vertices (they hold the tips) plus area-weighted random points (seeded) up to 6 x `samples`
// candidates. FPS uses a uniform grid and a lazy max-heap of each cell's farthest candidate:
// each new sample only updates the candidates within the current sampling radius, so the cost
// is about N log(samples), not N x samples.
// Balls: circumcenters of the finite Delaunay cells (CGAL, Epick), kept when strictly inside
// the surface; radius = distance to the surface (SurfaceQuery), computed in parallel (TBB). Each
// query starts from one of the cell's samples, a surface point at the circumradius: that bound
// prunes the AABB tree search (about 3x faster than an unhinted query). A center in front of
// the faces of its cell's four samples, and whose ray from there meets a face from the front or
// nothing, is outside and skips the query.
#include "dcg/voronoi_balls.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <queue>
#include <random>
#include <string>
#include <vector>

#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "dcg/errors.h"
#include "dcg/options.h"
#include "dcg/surface_query.h"
#include "polling.h"

namespace dcg {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
// Each Delaunay vertex keeps its sample's index (for the closest-point hint).
using Vb = CGAL::Triangulation_vertex_base_with_info_3<int, K>;
using Tds = CGAL::Triangulation_data_structure_3<Vb>;
using Delaunay = CGAL::Delaunay_triangulation_3<K, Tds>;

// A uniform double in [0, 1) from a 32-bit Mersenne twister, the same on every platform.
inline double uniform01(std::mt19937& rng) { return (rng() + 0.5) * (1.0 / 4294967296.0); }

// Candidate points on the surface and, for each, a face that holds it.
std::vector<Eigen::Vector3d> surface_candidates(const Mesh& mesh, int count, unsigned seed,
                                                std::vector<int>& face_of) {
  std::vector<Eigen::Vector3d> pts;
  const int nv = static_cast<int>(mesh.V.rows()), nf = static_cast<int>(mesh.F.rows());
  pts.reserve(std::max(count, nv));
  face_of.clear();
  face_of.reserve(std::max(count, nv));
  // Vertices that some face uses.
  std::vector<int> used(nv, -1);
  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) used[mesh.F(f, k)] = f;
  for (int v = 0; v < nv; ++v) {
    if (used[v] < 0) continue;
    pts.emplace_back(mesh.V.row(v).transpose());
    face_of.push_back(used[v]);
  }
  const int extra = count - static_cast<int>(pts.size());
  if (extra <= 0 || nf == 0) return pts;
  std::vector<double> cumulative(nf);
  double total = 0;
  for (int f = 0; f < nf; ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)),
                          c = mesh.V.row(mesh.F(f, 2));
    total += 0.5 * (b - a).cross(c - a).norm();
    cumulative[f] = total;
  }
  if (!(total > 0)) return pts;
  std::mt19937 rng(seed);
  for (int i = 0; i < extra; ++i) {
    const double u = uniform01(rng) * total;
    int f = static_cast<int>(std::upper_bound(cumulative.begin(), cumulative.end(), u) -
                             cumulative.begin());
    f = std::min(f, nf - 1);
    double r1 = std::sqrt(uniform01(rng)), r2 = uniform01(rng);
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)),
                          c = mesh.V.row(mesh.F(f, 2));
    pts.push_back((1 - r1) * a + r1 * (1 - r2) * b + r1 * r2 * c);
    face_of.push_back(f);
  }
  return pts;
}

// Farthest-point sampling of `k` points among `pts` (Euclidean), first one chosen by `seed`;
// `at` (if set) is polled with the fraction picked every 64 points.
std::vector<int> farthest_points(const std::vector<Eigen::Vector3d>& pts, int k, unsigned seed,
                                 const std::function<void(double)>& at) {
  const int n = static_cast<int>(pts.size());
  if (k >= n) {
    std::vector<int> all(n);
    for (int i = 0; i < n; ++i) all[i] = i;
    return all;
  }
  Eigen::Vector3d lo = pts[0], hi = pts[0];
  for (const auto& p : pts) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Eigen::Vector3d ext = (hi - lo).cwiseMax(1e-12);
  // About k / 4 occupied cells for a surface: cell ~ 2 x the final sample spacing. Cap the cell
  // count so that degenerate extents stay cheap.
  double cell = std::sqrt(ext.x() * ext.y() + ext.y() * ext.z() + ext.z() * ext.x()) * 2.0 /
                std::sqrt(static_cast<double>(k));
  cell = std::max(cell, ext.maxCoeff() / 128.0);
  const Eigen::Vector3i dims = ((ext / cell).array().floor().cast<int>() + 1).matrix();
  // (An explicit return type: `auto` would return an Eigen expression that refers to the local
  // `c`, read after it is gone. That bug made the sampling skip whole regions, e.g. 4 of the 6
  // arms of a star got no Voronoi ball.)
  auto cell_of = [&](const Eigen::Vector3d& p) -> Eigen::Vector3i {
    const Eigen::Vector3i c = ((p - lo) / cell).array().floor().cast<int>().matrix();
    return c.cwiseMax(0).cwiseMin(dims - Eigen::Vector3i::Ones());
  };
  auto flat3 = [&](int x, int y, int z) {
    return (static_cast<std::int64_t>(z) * dims.y() + y) * dims.x() + x;
  };
  auto flat = [&](const Eigen::Vector3i& c) { return flat3(c.x(), c.y(), c.z()); };
  const std::int64_t ncells = static_cast<std::int64_t>(dims.x()) * dims.y() * dims.z();
  std::vector<int> start(ncells + 1, 0), order(n);
  std::vector<std::int64_t> cell_index(n);
  for (int i = 0; i < n; ++i) {
    cell_index[i] = flat(cell_of(pts[i]));
    ++start[cell_index[i] + 1];
  }
  for (std::int64_t c = 0; c < ncells; ++c) start[c + 1] += start[c];
  {
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (int i = 0; i < n; ++i) order[fill[cell_index[i]]++] = i;
  }
  std::vector<double> d2(n, std::numeric_limits<double>::infinity());
  // Each cell's farthest point (largest d2, ties: the larger index) and a max-heap of those
  // (stale entries are dropped when they come up): the next sample is the top, the same point
  // as a heap of every candidate would give, at a tenth of the heap traffic (a push per cell
  // that changed instead of one per candidate that got closer; that heap was half of the
  // sampling's time). A cell that lies farther from a new sample than its farthest point's
  // distance cannot get closer to it and is skipped (1e-9 on the safe side of rounding).
  std::vector<double> best_d(ncells, -1);
  std::vector<int> best_i(ncells, -1);
  std::priority_queue<std::pair<double, int>> heap;
  auto refresh = [&](std::int64_t c) {
    double d = -1;
    int best = -1;
    for (int j = start[c]; j < start[c + 1]; ++j) {
      const int i = order[j];
      if (d2[i] > d || (d2[i] == d && i > best)) {
        d = d2[i];
        best = i;
      }
    }
    if (d == best_d[c] && best == best_i[c]) return;
    best_d[c] = d;
    best_i[c] = best;
    heap.emplace(d, best);
  };
  auto box_distance2 = [&](const Eigen::Vector3d& p, int x, int y, int z) {
    double sum = 0;
    const int c[3] = {x, y, z};
    for (int k = 0; k < 3; ++k) {
      const double a = lo[k] + c[k] * cell, b = a + cell;
      const double gap = p[k] < a ? a - p[k] : (p[k] > b ? p[k] - b : 0.0);
      sum += gap * gap;
    }
    return sum;
  };
  std::vector<int> chosen;
  chosen.reserve(k);
  std::mt19937 rng(seed);
  int next = static_cast<int>(rng() % static_cast<unsigned>(n));
  double radius2 = std::numeric_limits<double>::infinity();
  while (static_cast<int>(chosen.size()) < k) {
    if (at && (chosen.size() & 63) == 0) at(static_cast<double>(chosen.size()) / k);
    chosen.push_back(next);
    const Eigen::Vector3d s = pts[next];
    d2[next] = 0;
    if (std::isinf(radius2)) {
      for (int i = 0; i < n; ++i) d2[i] = (pts[i] - s).squaredNorm();
      for (std::int64_t c = 0; c < ncells; ++c)
        if (start[c] < start[c + 1]) refresh(c);
    } else {
      const double r = std::sqrt(radius2);
      const Eigen::Vector3i c0 = cell_of(s - Eigen::Vector3d::Constant(r)),
                            c1 = cell_of(s + Eigen::Vector3d::Constant(r));
      for (int z = c0.z(); z <= c1.z(); ++z)
        for (int y = c0.y(); y <= c1.y(); ++y)
          for (int x = c0.x(); x <= c1.x(); ++x) {
            const std::int64_t c = flat3(x, y, z);
            if (start[c] == start[c + 1] || box_distance2(s, x, y, z) * (1 - 1e-9) >= best_d[c])
              continue;
            for (int j = start[c]; j < start[c + 1]; ++j) {
              const int i = order[j];
              d2[i] = std::min(d2[i], (pts[i] - s).squaredNorm());
            }
            refresh(c);
          }
    }
    // The farthest candidate: drop stale heap entries.
    while (!heap.empty()) {
      const auto [d, i] = heap.top();
      const std::int64_t c = cell_index[i];
      if (best_i[c] == i && best_d[c] == d) break;
      heap.pop();
    }
    if (heap.empty() || heap.top().first <= 0) break;  // fewer distinct points than k
    next = heap.top().second;
    radius2 = heap.top().first;
  }
  return chosen;
}

// True when the ray from p along d (any length) first meets a face from behind (p is inside a
// closed, outward-oriented mesh; from outside a ray meets a front or nothing).
bool first_hit_from_behind(const SurfaceQuery& query, const Eigen::Vector3d& p,
                           const Eigen::Vector3d& d) {
  int face = -1;
  const double t = query.ray_hit(p, d, &face);
  return std::isfinite(t) && face >= 0 && query.face_normal(face).dot(d) > 0;
}

// Whether ball `i`'s center c is inside: both of its two rays (golden-angle spiral directions,
// indexed by ball and ray) first meet a face from behind, or, where a ray meets a face from the
// front inside the shape because the mesh intersects itself (cow: ears through the head), ray
// parity, which counts every crossing, says so.
bool seen_inside(const SurfaceQuery& query, const Eigen::Vector3d& c, Eigen::Index i) {
  for (int k = 0; k < 2; ++k) {
    const double j = static_cast<double>(2 * i + k) + 0.5;
    const double z = 1.0 - 2.0 * std::fmod(j * 0.6180339887498949, 1.0);
    const double phi = j * 2.399963229728653;
    const double s = std::sqrt(std::max(0.0, 1.0 - z * z));
    if (!first_hit_from_behind(query, c, Eigen::Vector3d(s * std::cos(phi), s * std::sin(phi), z)))
      return query.inside_by_parity(c);
  }
  return true;
}

// Stage 1 keeps a Voronoi vertex when its signed distance is negative, a sign taken from the
// nearest face's orientation. Where the working mesh folds through itself (0.3% vertex noise on
// an octopus's thin tentacles) that sign is wrong near the fold, and circumcenters OUTSIDE the
// shape pass as balls of radius up to three times the largest true one: they then win the domain
// balls around them and take the end points of the tentacles (they "see" the tips from outside),
// and the tentacles lose their ends. A ball is dropped when two rays from its center (spread
// directions, different for each ball) do not both first meet the surface from behind (every
// ray from a point inside a closed, outward-oriented mesh leaves the shape there; a ray from
// outside meets a face from the front or nothing) AND ray parity puts it outside too. Cost: two
// first-hit rays per ball, parity only for the few that fail them (~7 ms on the hand's 13k
// balls; parity for every ball took 40 ms); on the closed public meshes it drops nothing.
// In chunks of balls, with `at` polled between them.
Balls drop_balls_outside(Balls balls, const SurfaceQuery& query,
                         const std::function<void(double)>& at) {
  const Eigen::Index n = balls.radii.size();
  std::vector<char> keep(static_cast<std::size_t>(n), 1);
  internal::parallel_chunks(n, static_cast<Eigen::Index>(internal::per_thread(1024)),
                            Eigen::Index{256}, at, [&](const tbb::blocked_range<Eigen::Index>& r) {
                              for (Eigen::Index i = r.begin(); i != r.end(); ++i)
                                keep[i] = seen_inside(query, balls.centers.row(i).transpose(), i);
                            });
  Eigen::Index m = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!keep[i]) continue;
    balls.centers.row(m) = balls.centers.row(i);
    balls.radii[m] = balls.radii[i];
    ++m;
  }
  if (m == n) return balls;
  balls.centers.conservativeResize(m, 3);
  balls.radii.conservativeResize(m);
  return balls;
}

// True when point e lies strictly in front of the face of each of the Delaunay cell's four
// samples: then e is the centre of an empty ball that is almost always outside the shape (a ball
// inside touches each sample from behind its face). Not always: the circumcenter of a flat cell
// can lie far from its samples, inside another part of the shape (one on lowpoly-biped), hence
// the ray of first_hit_from_behind before a center is dropped.
template <class Cell>
bool in_front_of_all(const Eigen::Vector3d& e, const Cell& cell,
                     const std::vector<Eigen::Vector3d>& candidates,
                     const std::vector<int>& candidate_face, const SurfaceQuery& query) {
  for (int k = 0; k < 4; ++k) {
    const int i = cell->vertex(k)->info();
    if ((e - candidates[i]).dot(query.face_normal(candidate_face[i])) <= 0) return false;
  }
  return true;
}

// Indices of `points` (inside the box lo-hi) in Morton order (10 bits per axis; ties keep their
// order).
std::vector<std::size_t> morton_order(const std::vector<Eigen::Vector3d>& points,
                                      const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  auto spread = [](std::uint64_t v) {  // bits b of v to bits 3b
    std::uint64_t r = 0;
    for (int bit = 0; bit < 10; ++bit) r |= ((v >> bit) & 1) << (3 * bit);
    return r;
  };
  const Eigen::Vector3d scale = 1023.0 * (hi - lo).cwiseMax(1e-300).cwiseInverse();
  std::vector<std::uint64_t> key(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d u = ((points[i] - lo).cwiseProduct(scale)).cwiseMax(0.0).cwiseMin(1023.0);
    key[i] = spread(static_cast<std::uint64_t>(u.x())) |
             spread(static_cast<std::uint64_t>(u.y())) << 1 |
             spread(static_cast<std::uint64_t>(u.z())) << 2;
  }
  std::vector<std::size_t> order(points.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return key[a] < key[b]; });
  return order;
}

}  // namespace

Balls compute_voronoi_balls(const Mesh& mesh, const SurfaceQuery& query,
                            const VoronoiBallsOptions& options, const Progress& progress,
                            double from, double to) {
  check_option("samples", options.samples);
  if (mesh.F.rows() < 4 || mesh.V.rows() < 4) throw InputError("voronoi balls: empty mesh");
  internal::ThrottledProgress tick(progress, "voronoi_balls", from, to);
  tick(0);
  std::vector<int> candidate_face;
  const std::vector<Eigen::Vector3d> candidates =
      surface_candidates(mesh, 6 * options.samples, options.seed, candidate_face);
  const std::vector<int> picked =
      farthest_points(candidates, options.samples, options.seed, tick.part(0, 0.3));

  std::vector<std::pair<Delaunay::Point, int>> points;
  points.reserve(picked.size());
  for (int i : picked)
    points.emplace_back(Delaunay::Point(candidates[i].x(), candidates[i].y(), candidates[i].z()),
                        i);
  tick(0.3);
  Delaunay dt(points.begin(), points.end());
  tick(0.45);

  const Eigen::RowVector3d lo = mesh.V.colwise().minCoeff(), hi = mesh.V.colwise().maxCoeff();
  std::vector<Eigen::Vector3d> centers;
  std::vector<int> hint;    // a sample on the cell's circumsphere: its distance bounds the search
  std::vector<char> front;  // in front of the faces of all four samples (in_front_of_all)
  centers.reserve(dt.number_of_finite_cells());
  hint.reserve(dt.number_of_finite_cells());
  front.reserve(dt.number_of_finite_cells());
  for (auto c = dt.finite_cells_begin(); c != dt.finite_cells_end(); ++c) {
    const auto p = CGAL::circumcenter(c->vertex(0)->point(), c->vertex(1)->point(),
                                      c->vertex(2)->point(), c->vertex(3)->point());
    const Eigen::Vector3d e(p.x(), p.y(), p.z());
    if (!e.allFinite()) continue;
    if ((e.transpose().array() <= lo.array()).any() || (e.transpose().array() >= hi.array()).any())
      continue;
    centers.push_back(e);
    hint.push_back(c->vertex(0)->info());
    front.push_back(in_front_of_all(e, c, candidates, candidate_face, query) ? 1 : 0);
  }
  std::vector<double> radius(centers.size(), -1.0);
  // In chunks, polling between them (never from TBB's workers).
  // In Morton order of the centers: neighbouring queries walk the same part of the BVH (the
  // stage's closest points: 27 -> 22 ms on the hand; each center's distance is its own).
  const std::vector<std::size_t> order = morton_order(centers, lo.transpose(), hi.transpose());
  internal::parallel_chunks(
      centers.size(), std::size_t(internal::per_thread(1024)), std::size_t{256},
      tick.part(0.45, 0.9), [&](const tbb::blocked_range<std::size_t>& range) {
        for (std::size_t o = range.begin(); o != range.end(); ++o) {
          const std::size_t i = order[o];
          // Outside, by one ray instead of the closest-point query: the same balls on every
          // public, stress and rigged mesh, stage 1 16-19% faster on the hand and the elephant.
          if (front[i] &&
              !first_hit_from_behind(query, centers[i], centers[i] - candidates[hint[i]]))
            continue;
          const double sd =
              query.signed_distance(centers[i], candidates[hint[i]], candidate_face[hint[i]]);
          if (sd < 0) radius[i] = -sd;
        }
      });
  std::size_t kept = 0;
  for (double r : radius)
    if (r > 0) ++kept;
  Balls balls;
  balls.centers.resize(static_cast<Eigen::Index>(kept), 3);
  balls.radii.resize(static_cast<Eigen::Index>(kept));
  Eigen::Index j = 0;
  for (std::size_t i = 0; i < centers.size(); ++i) {
    if (!(radius[i] > 0)) continue;
    balls.centers.row(j) = centers[i].transpose();
    balls.radii[j] = radius[i];
    ++j;
  }
  return drop_balls_outside(std::move(balls), query, tick.part(0.9, 1));
}

int voronoi_samples(const VoronoiBallsOptions& options, const PrepareOptions& prepare,
                    Eigen::Index working_faces) {
  // One sample per two faces, at least 500, for a small input kept as it is: 4000 samples
  // would cost more than the rest of the pipeline there, and the public meshes of 898 to 5,856
  // faces keep their ends, joints and loops with these.
  const double faces = static_cast<double>(working_faces);
  if (prepare.upsample || !small_for_target(faces, prepare.target_faces)) return options.samples;
  return std::min(options.samples, std::max(kMinSmallSamples, static_cast<int>(faces / 2)));
}

}  // namespace dcg

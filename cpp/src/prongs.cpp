// Stage 3: scale function and prong features. See dcg/prongs.h and ALGORITHM.md "3. Prong
// features".
//
// Implementation notes:
// - Geodesics: Dijkstra on the mesh's edge graph (CSR, bucket queue, see DijkstraQueue). The
//   working mesh is uniform (stage 0 remeshes it), which keeps the metrication error of edge
//   paths small and, above all, the same everywhere, so ratios of f are meaningful.
// - Sources: geodesic farthest-point sampling. The first source is the vertex farthest from a
//   vertex picked by the seed (a tip); each next one is the vertex farthest from all sources so
//   far. Each new source runs a pruned Dijkstra that only visits vertices it brings closer, so
//   the whole sampling costs about one Dijkstra per source over its own Voronoi cell: together a
//   few full Dijkstras. The final nearest-source labels are the geodesic Voronoi cells; a
//   source's weight is the area of its cell (vertex areas: a third of the incident faces).
// - Full fields: one Dijkstra per source, in parallel (TBB) in chunks of sources (a few per
//   thread, so that the progress is polled every few ms between them) whose fields are then
//   added in source order: the sums are the same for any number of threads and any chunk size.
// - Watershed: vertices by decreasing f (ties by index), union-find regions with their peaks;
//   the elder rule (the region with the lower peak ends where it meets a higher one) gives each
//   peak one valley, whatever tau is, so re-thresholding needs no new pass.
#include "dcg/prongs.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "dcg/errors.h"
#include "dcg/options.h"
#include "dcg/surface_query.h"
#include "polling.h"
#include "vertex_grid.h"

namespace dcg {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
const char* const kStage = "prongs";

using Poll = std::function<void(double)>;  // fraction of the current step done, may throw

void poll_at(const Poll& at, double fraction) {
  if (at) at(fraction);
}

// Undirected edge graph of a triangle mesh in CSR form.
struct EdgeGraph {
  int n = 0;
  std::vector<int> start;      // n + 1 offsets
  std::vector<int> neighbour;  // neighbours of each vertex
  std::vector<double> length;  // edge lengths, parallel to neighbour
};

void check_mesh(const Mesh& mesh) {
  const Eigen::Index nv = mesh.V.rows();
  if (nv == 0 || mesh.F.rows() == 0) throw InputError("prong features: the mesh is empty");
  if (mesh.F.size() > 0 && (mesh.F.minCoeff() < 0 || mesh.F.maxCoeff() >= nv)) {
    throw InputError("prong features: a face index is out of range");
  }
}

EdgeGraph build_graph(const Mesh& mesh, const std::function<void()>& poll = {}) {
  EdgeGraph g;
  g.n = static_cast<int>(mesh.V.rows());
  std::vector<std::uint64_t> directed;
  directed.reserve(static_cast<std::size_t>(mesh.F.rows()) * 6);
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const auto a = static_cast<std::uint32_t>(mesh.F(f, k));
      const auto b = static_cast<std::uint32_t>(mesh.F(f, (k + 1) % 3));
      if (a == b) continue;
      directed.push_back((static_cast<std::uint64_t>(a) << 32) | b);
      directed.push_back((static_cast<std::uint64_t>(b) << 32) | a);
    }
  }
  internal::sort_polling(directed, poll);
  directed.erase(std::unique(directed.begin(), directed.end()), directed.end());
  g.start.assign(g.n + 1, 0);
  g.neighbour.resize(directed.size());
  g.length.resize(directed.size());
  for (std::size_t i = 0; i < directed.size(); ++i) {
    const int a = static_cast<int>(directed[i] >> 32),
              b = static_cast<int>(directed[i] & 0xffffffffu);
    ++g.start[a + 1];
    g.neighbour[i] = b;
    g.length[i] = (mesh.V.row(a) - mesh.V.row(b)).norm();
  }
  for (int v = 0; v < g.n; ++v) g.start[v + 1] += g.start[v];
  return g;
}

// Vertex areas: a third of the area of every incident face.
std::vector<double> vertex_areas(const Mesh& mesh) {
  std::vector<double> area(mesh.V.rows(), 0.0);
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)),
                          c = mesh.V.row(mesh.F(f, 2));
    const double third = (b - a).cross(c - a).norm() / 6.0;
    for (int k = 0; k < 3; ++k) area[mesh.F(f, k)] += third;
  }
  return area;
}

using HeapItem = std::pair<double, int>;

// Scratch space of Dijkstra runs on one graph (one per thread). The queue is a ring of buckets of
// width delta just below the shortest edge (Dinitz): relaxing an edge moves a vertex at least one
// bucket ahead, so every vertex in the current bucket is final and no heap is needed; O(1) per
// push and pop, about 2.5x faster than a binary heap here. Graphs whose edge lengths span more
// than 4096 bucket widths (or that have edges of length 0) use a binary heap instead.
class DijkstraQueue {
 public:
  explicit DijkstraQueue(const EdgeGraph& g) : g_(g), done_(g.n, 0) {
    double shortest = kInf, longest = 0;
    for (const double l : g.length) {
      shortest = std::min(shortest, l);
      longest = std::max(longest, l);
    }
    if (shortest > 0 && std::isfinite(longest) && longest / shortest < 4000.0) {
      inv_width_ = 1.0 / (0.999 * shortest);
      ring_.resize(static_cast<std::size_t>(longest * inv_width_) + 2);
    }
  }

  // Dijkstra from `source` over the vertices whose distance it lowers: dist holds the current
  // distances (infinity: not reached) and is updated; label[v] = tag for every vertex updated.
  // With dist all infinity this is the plain single-source Dijkstra.
  void run(int source, double* dist, int* label, int tag) {
    dist[source] = 0;
    if (label) label[source] = tag;
    if (ring_.empty()) return run_heap(source, dist, label, tag);
    if (++stamp_ == 0) {  // the stamps wrapped around: clear them
      std::fill(done_.begin(), done_.end(), 0);
      stamp_ = 1;
    }
    const std::size_t R = ring_.size();
    ring_[0].push_back(source);
    std::size_t pending = 1;
    for (std::size_t k = 0; pending > 0; ++k) {
      std::vector<int>& bucket = ring_[k % R];
      for (std::size_t i = 0; i < bucket.size(); ++i) {
        const int u = bucket[i];
        --pending;
        if (done_[u] == stamp_ || static_cast<std::size_t>(dist[u] * inv_width_) != k) continue;
        done_[u] = stamp_;
        const double du = dist[u];
        for (int e = g_.start[u]; e < g_.start[u + 1]; ++e) {
          const int v = g_.neighbour[e];
          const double nd = du + g_.length[e];
          if (nd < dist[v]) {
            dist[v] = nd;
            if (label) label[v] = tag;
            ring_[static_cast<std::size_t>(nd * inv_width_) % R].push_back(v);
            ++pending;
          }
        }
      }
      bucket.clear();
    }
  }

 private:
  void run_heap(int source, double* dist, int* label, int tag) {
    const auto greater = std::greater<HeapItem>();
    heap_.clear();
    heap_.emplace_back(0.0, source);
    while (!heap_.empty()) {
      std::pop_heap(heap_.begin(), heap_.end(), greater);
      const auto [d, u] = heap_.back();
      heap_.pop_back();
      if (d > dist[u]) continue;
      for (int e = g_.start[u]; e < g_.start[u + 1]; ++e) {
        const int v = g_.neighbour[e];
        const double nd = d + g_.length[e];
        if (nd < dist[v]) {
          dist[v] = nd;
          if (label) label[v] = tag;
          heap_.emplace_back(nd, v);
          std::push_heap(heap_.begin(), heap_.end(), greater);
        }
      }
    }
  }

  const EdgeGraph& g_;
  double inv_width_ = 0;
  std::vector<std::vector<int>> ring_;
  std::vector<unsigned> done_;
  unsigned stamp_ = 0;
  std::vector<HeapItem> heap_;
};

// Sum over sources of weight * distance, by chunks of sources in parallel, added in source order
// (whatever the chunk size); `at` is polled between the chunks.
Eigen::VectorXd weighted_distance_sum(const EdgeGraph& g, const std::vector<int>& sources,
                                      const std::vector<double>& weights, const Poll& at) {
  const int n = g.n, S = static_cast<int>(sources.size());
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(n), reached = Eigen::VectorXd::Zero(n);
  // Sources in chunks of about 2^20 vertex visits (at least 2 per thread, all of them on a small
  // mesh): one parallel_for per chunk, a cancel poll between chunks. Chunks of 4 sources cost
  // the torus's 576 vertices more in TBB's start-up than in the Dijkstras. The sums add the
  // sources in order whatever the chunk, so the values do not depend on it.
  // (std::max, not std::clamp: with fewer sources than the floor, clamp's bounds would cross.)
  const int chunk = std::max({(1 << 20) / std::max(n, 1), 4, internal::per_thread(2)});
  std::vector<float> fields(static_cast<std::size_t>(std::min(chunk, S)) * n);
  for (int first = 0; first < S; first += chunk) {
    poll_at(at, static_cast<double>(first) / S);
    const int count = std::min(chunk, S - first);
    tbb::parallel_for(tbb::blocked_range<int>(0, count, 1), [&](const tbb::blocked_range<int>& r) {
      std::vector<double> dist(n);
      DijkstraQueue queue(g);
      for (int i = r.begin(); i != r.end(); ++i) {
        std::fill(dist.begin(), dist.end(), kInf);
        queue.run(sources[first + i], dist.data(), nullptr, 0);
        float* out = fields.data() + static_cast<std::size_t>(i) * n;
        for (int v = 0; v < n; ++v) out[v] = static_cast<float>(dist[v]);
      }
    });
    tbb::parallel_for(tbb::blocked_range<int>(0, n, 4096), [&](const tbb::blocked_range<int>& r) {
      for (int i = 0; i < count; ++i) {
        const double w = weights[first + i];
        const float* in = fields.data() + static_cast<std::size_t>(i) * n;
        for (int v = r.begin(); v != r.end(); ++v) {
          if (std::isinf(in[v])) continue;  // another component
          sum[v] += w * in[v];
          reached[v] += w;
        }
      }
    });
  }
  for (int v = 0; v < n; ++v) sum[v] = reached[v] > 0 ? sum[v] / reached[v] : 0.0;
  return sum;
}

}  // namespace

Eigen::VectorXd edge_geodesics(const Mesh& mesh, int source) {
  check_mesh(mesh);
  if (source < 0 || source >= mesh.V.rows()) throw InputError("edge_geodesics: bad source vertex");
  const EdgeGraph g = build_graph(mesh);
  Eigen::VectorXd dist = Eigen::VectorXd::Constant(g.n, kInf);
  DijkstraQueue(g).run(source, dist.data(), nullptr, 0);
  return dist;
}

namespace {

// f(v) from v's own Dijkstra (d is symmetric) with vertex weights w: independent per vertex, O(n)
// memory; in chunks of vertices with `at` polled between them.
Eigen::VectorXd exact_values(const EdgeGraph& g, const std::vector<double>& w, const Poll& at) {
  const int n = g.n;
  Eigen::VectorXd f(n);
  internal::parallel_chunks(n, internal::per_thread(16), 16, at,
                            [&](const tbb::blocked_range<int>& r) {
                              std::vector<double> dist(n);
                              DijkstraQueue queue(g);
                              for (int v = r.begin(); v != r.end(); ++v) {
                                std::fill(dist.begin(), dist.end(), kInf);
                                queue.run(v, dist.data(), nullptr, 0);
                                double sum = 0, total = 0;
                                for (int i = 0; i < n; ++i) {
                                  if (std::isinf(dist[i])) continue;
                                  sum += w[i] * dist[i];
                                  total += w[i];
                                }
                                f[v] = total > 0 ? sum / total : 0.0;
                              }
                            });
  return f;
}

// Geodesic farthest-point sampling of `count` sources with incremental (pruned) Dijkstra; each
// source's weight is the area of its geodesic Voronoi cell. `at` is polled after each source.
void sample_sources(const EdgeGraph& g, const std::vector<double>& area, int count, unsigned seed,
                    const Poll& at, std::vector<int>& sources, std::vector<double>& weights) {
  const int n = g.n;
  std::vector<double> dist(n, kInf);
  std::vector<int> label(n, -1);
  DijkstraQueue queue(g);
  {
    std::mt19937 rng(seed);
    const int start = static_cast<int>(rng() % static_cast<unsigned>(n));
    std::vector<double> from_start(n, kInf);
    queue.run(start, from_start.data(), nullptr, 0);
    int first = start;
    for (int v = 0; v < n; ++v)
      if (!std::isinf(from_start[v]) && from_start[v] > from_start[first]) first = v;
    sources.push_back(first);
    queue.run(first, dist.data(), label.data(), 0);
  }
  while (static_cast<int>(sources.size()) < count) {
    poll_at(at, static_cast<double>(sources.size()) / count);
    int next = 0;
    for (int v = 1; v < n; ++v)
      if (dist[v] > dist[next]) next = v;  // an unreached vertex (infinity) comes first
    if (!(dist[next] > 0)) break;          // every vertex is a source already
    const int tag = static_cast<int>(sources.size());
    sources.push_back(next);
    queue.run(next, dist.data(), label.data(), tag);
  }
  weights.assign(sources.size(), 0.0);
  for (int v = 0; v < n; ++v)
    if (label[v] >= 0) weights[label[v]] += area[v];
}

}  // namespace

Eigen::VectorXd exact_scale_function(const Mesh& mesh, bool area_weighted) {
  check_mesh(mesh);
  const EdgeGraph g = build_graph(mesh);
  const std::vector<double> w = area_weighted ? vertex_areas(mesh) : std::vector<double>(g.n, 1.0);
  return exact_values(g, w, {});
}

ScaleFunction compute_scale_function(const Mesh& mesh, const ScaleFunctionOptions& options,
                                     const Progress& progress, double from, double to) {
  check_mesh(mesh);
  check_option("geodesic_sources", options.geodesic_sources);
  internal::ThrottledProgress tick(progress, kStage, from, to);
  tick(0);
  const EdgeGraph g = build_graph(mesh, [&] { tick(0); });
  const int n = g.n;
  const std::vector<double> area = vertex_areas(mesh);
  ScaleFunction out;
  if (options.geodesic_sources == 0 || options.geodesic_sources >= n) {
    out.values = exact_values(g, area, tick.part(0, 1));
    out.sources.resize(n);
    std::iota(out.sources.data(), out.sources.data() + n, 0);
    out.weights = Eigen::Map<const Eigen::VectorXd>(area.data(), n);
    return out;
  }
  std::vector<int> sources;
  std::vector<double> weights;
  sample_sources(g, area, options.geodesic_sources, options.seed, tick.part(0, 0.1), sources,
                 weights);
  out.values = weighted_distance_sum(g, sources, weights, tick.part(0.1, 1));
  out.sources =
      Eigen::Map<const Eigen::VectorXi>(sources.data(), static_cast<Eigen::Index>(sources.size()));
  out.weights =
      Eigen::Map<const Eigen::VectorXd>(weights.data(), static_cast<Eigen::Index>(weights.size()));
  return out;
}

// --- watershed -------------------------------------------------------------------------------

ProngHierarchy::ProngHierarchy(const Mesh& mesh, const Eigen::VectorXd& f, const Progress& progress,
                               double from, double to)
    : mesh_(mesh), f_(f) {
  check_mesh(mesh);
  const int n = static_cast<int>(mesh.V.rows());
  if (f.size() != n) {
    throw InputError("prong hierarchy: " + std::to_string(f.size()) + " values for " +
                     std::to_string(n) + " vertices");
  }
  if (!f.allFinite()) throw InputError("prong hierarchy: the scale function is not finite");
  grid_ = std::make_shared<const internal::VertexGrid>(mesh.V);
  internal::ThrottledProgress tick(progress, kStage, from, to);
  tick(0);
  const EdgeGraph g = build_graph(mesh, [&] { tick(0); });
  adjacency_start_ = g.start;
  adjacency_ = g.neighbour;

  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return f[a] != f[b] ? f[a] > f[b] : a < b; });
  std::vector<int> rank(n);
  for (int i = 0; i < n; ++i) rank[order[i]] = i;

  std::vector<int> parent(n, -1);   // -1: not visited yet
  std::vector<int> peak_of(n, -1);  // root -> index into peaks_
  std::vector<int> lowest(n, -1);   // root -> its lowest vertex so far
  auto find = [&](int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  std::vector<int> roots;
  for (int i = 0; i < n; ++i) {
    if ((i & 1023) == 0) tick(static_cast<double>(i) / n);
    const int v = order[i];
    roots.clear();
    for (int e = adjacency_start_[v]; e < adjacency_start_[v + 1]; ++e) {
      const int u = adjacency_[e];
      if (parent[u] < 0) continue;
      const int r = find(u);
      if (std::find(roots.begin(), roots.end(), r) == roots.end()) roots.push_back(r);
    }
    if (roots.empty()) {  // a new local maximum
      parent[v] = v;
      peak_of[v] = static_cast<int>(peaks_.size());
      lowest[v] = v;
      Peak p;
      p.vertex = v;
      p.value = f[v];
      peaks_.push_back(p);
      continue;
    }
    // The region whose peak is highest (first in the order) survives; the others end here.
    int best = roots[0];
    for (const int r : roots)
      if (rank[peaks_[peak_of[r]].vertex] < rank[peaks_[peak_of[best]].vertex]) best = r;
    for (const int r : roots) {
      if (r == best) continue;
      Peak& p = peaks_[peak_of[r]];
      p.valley = f[v];
      p.ratio = p.value > 0 ? f[v] / p.value : 1.0;
      p.valley_vertex = v;
      p.partner = peaks_[peak_of[best]].vertex;
      parent[r] = best;
    }
    parent[v] = best;
    lowest[best] = v;
  }
  // Regions still open at the end (one per connected component) hold the global maxima.
  for (int v = 0; v < n; ++v) {
    if (parent[v] != v) continue;
    Peak& p = peaks_[peak_of[v]];
    p.global = true;
    p.valley = f[lowest[v]];
    p.valley_vertex = lowest[v];
    p.ratio = p.value > 0 ? p.valley / p.value : 1.0;
  }
  std::sort(peaks_.begin(), peaks_.end(), [&](const Peak& a, const Peak& b) {
    if (a.ratio != b.ratio) return a.ratio < b.ratio;
    return rank[a.vertex] < rank[b.vertex];
  });
  // The global maximum of the whole mesh: the peak first in the order.
  for (int i = 0; i < static_cast<int>(peaks_.size()); ++i) {
    peak_at_[peaks_[i].vertex] = i;
    if (peaks_[i].global &&
        (global_ < 0 || rank[peaks_[i].vertex] < rank[peaks_[global_].vertex])) {
      global_ = i;
    }
  }
}

bool ProngHierarchy::global_cap_is_disk(double tau) const {
  if (global_ < 0) return false;
  return cap_is_disk(peaks_[global_].vertex, tau);
}

bool ProngHierarchy::cap_is_disk(int peak_vertex, double tau) const {
  const int n = static_cast<int>(f_.size());
  const double level = tau * f_[peak_vertex];
  // The connected region with f >= level around the peak.
  std::vector<char> in(n, 0);
  std::vector<int> stack = {peak_vertex};
  in[peak_vertex] = 1;
  while (!stack.empty()) {
    const int u = stack.back();
    stack.pop_back();
    for (int e = adjacency_start_[u]; e < adjacency_start_[u + 1]; ++e) {
      const int v = adjacency_[e];
      if (!in[v] && f_[v] >= level) {
        in[v] = 1;
        stack.push_back(v);
      }
    }
  }
  // Its faces (all three corners inside) and their border edges (used by one such face).
  std::vector<std::uint64_t> edges;
  for (Eigen::Index f = 0; f < mesh_.F.rows(); ++f) {
    if (!in[mesh_.F(f, 0)] || !in[mesh_.F(f, 1)] || !in[mesh_.F(f, 2)]) continue;
    for (int k = 0; k < 3; ++k) {
      auto a = static_cast<std::uint32_t>(mesh_.F(f, k)),
           b = static_cast<std::uint32_t>(mesh_.F(f, (k + 1) % 3));
      if (a > b) std::swap(a, b);
      edges.push_back((static_cast<std::uint64_t>(a) << 32) | b);
    }
  }
  if (edges.empty()) return true;  // a cap smaller than a triangle: a point, a disk
  std::sort(edges.begin(), edges.end());
  // Border loops: connected components of the border edges (union-find on their vertices).
  std::vector<int> parent(n, -1);
  auto find = [&](int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  int loops = 0;
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i + 1;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    if (j - i == 1) {
      const int a = static_cast<int>(edges[i] >> 32), b = static_cast<int>(edges[i] & 0xffffffffu);
      for (const int x : {a, b}) {
        if (parent[x] < 0) {
          parent[x] = x;
          ++loops;
        }
      }
      const int ra = find(a), rb = find(b);
      if (ra != rb) {
        parent[rb] = ra;
        --loops;
      }
    }
    i = j;
  }
  return loops == 1;
}

bool ProngHierarchy::mirrors_mesh(int a, int b) const {
  const Eigen::Vector3d pa = mesh_.V.row(a), pb = mesh_.V.row(b);
  if ((pa - pb).norm() == 0 || !grid_) return false;
  const Eigen::Vector3d normal = (pa - pb).normalized();
  const double offset = normal.dot(pa + pb) / 2;
  const Eigen::Index n = mesh_.V.rows();
  const Eigen::Index step = std::max<Eigen::Index>(1, n / 1000);  // about 1000 samples
  const Eigen::Index samples = (n + step - 1) / step;
  // The mean is at most kTwinMirror diagonals: the sum can stop as soon as it is past that
  // (a plane that does not mirror the mesh is told from its first few dozen samples).
  const double most = kTwinMirror * grid_->diagonal() * static_cast<double>(samples);
  double sum = 0;
  for (Eigen::Index i = 0; i < n && sum <= most; i += step) {
    const Eigen::Vector3d p = mesh_.V.row(i).transpose();
    sum += grid_->nearest(p - 2 * (p.dot(normal) - offset) * normal);
  }
  return sum <= most;
}

double ProngHierarchy::off_halfway(int a, int b, int v) const {
  const Eigen::Vector3d pa = mesh_.V.row(a), pb = mesh_.V.row(b), at = mesh_.V.row(v);
  return std::abs((pa - pb).normalized().dot(at - (pa + pb) / 2));
}

bool ProngHierarchy::as_high(const Peak& q, const Peak& p) const {
  return std::abs(q.value - p.value) <= kTwinValue * p.value;
}

bool ProngHierarchy::mirror_image(const Peak& q, const Peak& p) const {
  return as_high(q, p) && mirrors_mesh(q.vertex, p.vertex);
}

bool ProngHierarchy::is_mirror_twin(const Peak& twin, const Peak& partner) const {
  if (!as_high(twin, partner)) return false;  // the geodesics below cost most: tested last but one
  for (int peak : {twin.vertex, partner.vertex}) {  // both limbs, the crotch off the plane
    if (edge_geodesics(mesh_, peak)[twin.valley_vertex] < kTwinLength * f_.mean()) return false;
  }
  return mirrors_mesh(twin.vertex, partner.vertex);
}

int ProngHierarchy::region_prong(const Peak& q,
                                 const std::unordered_set<int>& prong_vertices) const {
  int at = q.partner < 0 ? q.vertex : q.partner;
  for (std::size_t steps = 0; steps < peaks_.size() && !prong_vertices.count(at); ++steps) {
    const auto next = peak_at_.find(at);
    if (next == peak_at_.end() || peaks_[next->second].partner < 0) break;
    at = peaks_[next->second].partner;
  }
  return at;
}

Prongs ProngHierarchy::prongs(double tau) const {
  check_option("tau", tau);
  std::vector<const Peak*> kept;
  for (const Peak& p : peaks_) {
    if (!(p.ratio < tau)) break;  // sorted by ratio
    if (p.global && !cap_is_disk(p.vertex, tau)) continue;
    kept.push_back(&p);
  }
  // Mirror twins of the prongs (see the class comment): peaks past tau whose partner is kept.
  std::vector<const Peak*> twins;
  for (const Peak& q : peaks_) {
    if (!(q.ratio < kTwinRatio)) break;
    if (q.ratio < tau || q.global) continue;
    const auto partner = std::find_if(kept.begin(), kept.end(),
                                      [&](const Peak* p) { return p->vertex == q.partner; });
    if (partner != kept.end() && is_mirror_twin(q, **partner)) twins.push_back(&q);
  }
  kept.insert(kept.end(), twins.begin(), twins.end());
  // Fingers of a hand (see the class comment; cpp/src/prong_fingers.cpp).
  const std::vector<const Peak*> hand = fingers(tau, kept);
  kept.insert(kept.end(), hand.begin(), hand.end());
  // A tail between a pair of limbs (cpp/src/prong_tails.cpp).
  const std::vector<const Peak*> tail = tails(kept);
  kept.insert(kept.end(), tail.begin(), tail.end());
  // A head's end on one of two horns moved to its middle (cpp/src/prong_midline.cpp).
  const int midline = move_to_midline(kept);
  std::stable_sort(kept.begin(), kept.end(),
                   [](const Peak* a, const Peak* b) { return a->ratio < b->ratio; });
  Prongs out;
  out.tau = tau;
  out.mirror_twins = static_cast<int>(twins.size());
  out.fingers = static_cast<int>(hand.size());
  out.midline = midline;
  out.tails = static_cast<int>(tail.size());
  const auto k = static_cast<Eigen::Index>(kept.size());
  out.vertices.resize(k);
  out.positions.resize(k, 3);
  out.significance.resize(k);
  for (Eigen::Index i = 0; i < k; ++i) {
    out.vertices[i] = kept[i]->vertex;
    out.positions.row(i) = mesh_.V.row(kept[i]->vertex);
    out.significance[i] = kept[i]->ratio;
  }
  return out;
}

ProngFeatures compute_prongs(const Mesh& mesh, const ProngOptions& options,
                             const Progress& progress, double from, double to) {
  check_option("tau", options.tau);
  const double split = from + 0.9 * (to - from);  // the geodesics take most of the time
  ProngFeatures out;
  out.scale = compute_scale_function(mesh, options, progress, from, split);
  out.hierarchy = ProngHierarchy(mesh, out.scale.values, progress, split, to);
  out.prongs = out.hierarchy.prongs(options.tau);
  return out;
}

}  // namespace dcg

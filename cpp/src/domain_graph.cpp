// Stage 6: domain surfaces, links and the kept graph. See dcg/domain_graph.h.
#include "dcg/domain_graph.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <numeric>
#include <queue>
#include <set>
#include <tuple>
#include <utility>

#include <Eigen/Eigenvalues>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "dcg/errors.h"
#include "dcg/force_field.h"
#include "dcg/skeleton.h"
#include "dcg/surface_query.h"
#include "dcg/weights.h"
#include "edge_table.h"
#include "union_find.h"

namespace dcg {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// How far (in tube radii) an end point's ball may reach out of the body's tube at its junction
// and still be a bump on it (see the bumps pass).
constexpr double kBumpReach = 0.6;

using internal::UnionFind;

// Faces sharing an edge: adjacency[3f + k] is the face across edge (F(f,k), F(f,k+1)), -1 on a
// border. Non-manifold edges chain their faces pairwise (the working mesh has none).
std::vector<int> face_adjacency(const Faces& F) {
  const internal::EdgeTable table(F);
  std::vector<int> adjacency(table.half.size(), -1);
  table.for_each_edge([&](std::size_t i, std::size_t j) {
    for (std::size_t h = i; h + 1 < j; h += 2) {
      adjacency[table.half[h].second] = internal::EdgeTable::face(table.half[h + 1].second);
      adjacency[table.half[h + 1].second] = internal::EdgeTable::face(table.half[h].second);
    }
  });
  return adjacency;
}

// Distance from p to the circle arc that starts at a, passes through b and ends at c (the
// segments a-b-c when the three points are about collinear).
double arc_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                    const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, n = ab.cross(ac);
  if (n.norm() <= 1e-9 * ab.norm() * ac.norm()) {
    return std::min(point_segment_distance(p, a, b), point_segment_distance(p, b, c));
  }
  // Circumcenter o of a, b, c in their plane.
  const Eigen::Vector3d o =
      a + (ab.squaredNorm() * ac.cross(n) + ac.squaredNorm() * n.cross(ab)) / (2 * n.squaredNorm());
  const double R = (a - o).norm();
  const Eigen::Vector3d normal = n.normalized();
  const Eigen::Vector3d u = (a - o) / R, w = normal.cross(u);
  auto angle = [&](const Eigen::Vector3d& x) {
    const double t = std::atan2((x - o).dot(w), (x - o).dot(u));
    return t < 0 ? t + 2 * M_PI : t;
  };
  const double tb = angle(b), tc = angle(c);
  // The point of the whole circle nearest to p, then whether it lies on the arc a -> b -> c.
  const Eigen::Vector3d q = p - (p - o).dot(normal) * normal;
  double on_circle = std::hypot(R, (p - o).dot(normal));  // p above the center: every point
  double tq = 0;
  if ((q - o).norm() > 1e-12 * R) {
    const Eigen::Vector3d nearest = o + R * (q - o).normalized();
    on_circle = (p - nearest).norm();
    tq = angle(nearest);
  }
  const bool on_arc = tb <= tc ? tq <= tc : tq >= tc || tq == 0;
  return on_arc ? on_circle : std::min((p - a).norm(), (p - c).norm());
}

// Whether every pair of `pts` sees each other (no segment between two of them meets the surface).
bool all_see_each_other(const SurfaceQuery& query, const Points& points, const std::vector<int>& pts) {
  std::vector<double> a, b;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    for (std::size_t j = i + 1; j < pts.size(); ++j) {
      for (int k = 0; k < 3; ++k) {
        a.push_back(points(pts[i], k));
        b.push_back(points(pts[j], k));
      }
    }
  }
  const int count = static_cast<int>(a.size() / 3);
  if (count == 0) return true;
  std::vector<unsigned char> blocked(count);
  query.segments_blocked(a.data(), b.data(), count, 0.0, blocked.data());
  return std::none_of(blocked.begin(), blocked.end(), [](unsigned char x) { return x != 0; });
}

// The widest chord of the shape through the midpoint of a and b, across the segment between
// them: the longest of 12 lines through the midpoint, every 15 degrees in the plane normal to
// b - a, each cut at the first surface hit on either side. A tube gives about its diameter, a
// slab (a palm) its breadth.
double widest_chord(const SurfaceQuery& query, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d mid = 0.5 * (a + b), axis = (b - a).normalized();
  const Eigen::Vector3d u = axis.unitOrthogonal(), w = axis.cross(u);
  double widest = 0;
  for (int k = 0; k < 12; ++k) {
    const double angle = M_PI * k / 12;
    const Eigen::Vector3d d = std::cos(angle) * u + std::sin(angle) * w;
    widest = std::max(widest, query.ray_hit(mid, d) + query.ray_hit(mid, -d));
  }
  return widest;
}

// --- the graph being edited: adjacency sets over point indices --------------------------------
// `alive` is read directly but changed only through set_alive and merge, which keep `live` (its
// count) up to date: the pruning loops ask for it once per step.
struct Graph {
  std::vector<std::set<int>> adj;
  std::vector<char> alive;
  std::vector<int> absorbed_by;  // point -> point that absorbed it (-1: none)
  int live = 0;

  explicit Graph(int n) : adj(n), alive(n, 0), absorbed_by(n, -1) {}
  void link(int a, int b) {
    if (a == b) return;
    adj[a].insert(b);
    adj[b].insert(a);
  }
  void unlink(int a, int b) {
    adj[a].erase(b);
    adj[b].erase(a);
  }
  int degree(int a) const { return static_cast<int>(adj[a].size()); }
  // Removes `gone` and hands its links to `keep`.
  void merge(int keep, int gone) {
    const std::set<int> others = adj[gone];
    for (int o : others) {
      unlink(gone, o);
      if (o != keep) link(keep, o);
    }
    set_alive(gone, false);
    absorbed_by[gone] = keep;
  }
  void set_alive(int p, bool value) {
    live += static_cast<int>(value) - static_cast<int>(alive[p] != 0);
    alive[p] = value;
  }
  int count_alive() const { return live; }
};

}  // namespace

DomainGraph compute_domain_graph(const Mesh& mesh, const ForceField& field, const Points& points,
                                 const Eigen::VectorXd& radii, const Eigen::VectorXi& prong,
                                 int genus, const DomainGraphOptions& options) {
  int P = static_cast<int>(points.rows());
  const int nf = static_cast<int>(mesh.F.rows());
  if (radii.size() != P || prong.size() != P) {
    throw InputError("domain graph: points, radii and prong differ in length");
  }
  if (nf == 0) throw InputError("domain graph: the mesh has no faces");
  if (P == 0) throw InputError("the shape has no interior: no point to build a graph from");
  const SurfaceQuery& query = field.query();
  DomainGraph g;
  g.points = points;
  g.radii = radii;
  g.prong = prong;
  auto is_end = [&](int p) { return prong[p] >= 0; };

  // --- 1. primitive visible faces ------------------------------------------------------------
  std::vector<int> closest_face(P);
  std::vector<double> closest_distance(P);
  tbb::parallel_for(0, P, [&](int p) {
    int f = -1;
    const Eigen::Vector3d q = query.closest_point(points.row(p).transpose(), &f);
    closest_face[p] = f;
    closest_distance[p] = (q - points.row(p).transpose()).norm();
  });
  std::vector<int> claim_order(P);
  std::iota(claim_order.begin(), claim_order.end(), 0);
  std::stable_sort(claim_order.begin(), claim_order.end(), [&](int a, int b) {
    if (is_end(a) != is_end(b)) return is_end(a);
    return closest_distance[a] < closest_distance[b];
  });
  g.face_labels = Eigen::VectorXi::Constant(nf, -1);
  g.primitive_face = Eigen::VectorXi::Constant(P, -1);
  for (int p : claim_order) {
    const int f = closest_face[p];
    if (f < 0 || g.face_labels[f] >= 0) continue;
    g.face_labels[f] = p;
    g.primitive_face[p] = f;
    ++g.faces_seeded;
  }

  // --- nearest visible point of every face ---------------------------------------------------
  Points centroid(nf, 3);
  for (int f = 0; f < nf; ++f) {
    centroid.row(f) = (mesh.V.row(mesh.F(f, 0)) + mesh.V.row(mesh.F(f, 1)) + mesh.V.row(mesh.F(f, 2))) / 3.0;
  }
  g.visible_owner = Eigen::VectorXi::Constant(nf, -1);
  const int candidates = std::max(1, std::min(options.visibility_candidates, P));
  tbb::parallel_for(tbb::blocked_range<int>(0, nf, 64), [&](const tbb::blocked_range<int>& range) {
    std::vector<std::pair<double, int>> d(P);
    std::vector<double> a(3 * 8), b(3 * 8);
    unsigned char blocked[8];
    for (int f = range.begin(); f != range.end(); ++f) {
      const Eigen::RowVector3d c = centroid.row(f);
      for (int p = 0; p < P; ++p) d[p] = {(points.row(p) - c).norm() - radii[p], p};
      std::partial_sort(d.begin(), d.begin() + candidates, d.end());
      // The nearest candidate alone first (it usually sees the face), then packets of 8.
      for (int start = 0; start < candidates && g.visible_owner[f] < 0; start += start == 0 ? 1 : 8) {
        const int n = std::min(start == 0 ? 1 : 8, candidates - start);
        for (int k = 0; k < n; ++k) {
          for (int j = 0; j < 3; ++j) {
            a[3 * k + j] = points(d[start + k].second, j);
            b[3 * k + j] = c[j];
          }
        }
        query.segments_blocked(a.data(), b.data(), n, 1e-4, blocked);
        for (int k = 0; k < n; ++k) {
          if (!blocked[k]) {
            g.visible_owner[f] = d[start + k].second;
            break;
          }
        }
      }
    }
  });

  // --- 2. region growing ---------------------------------------------------------------------
  const std::vector<int> adjacency = face_adjacency(mesh.F);
  {
    std::vector<int> queue;
    for (int f = 0; f < nf; ++f)
      if (g.face_labels[f] >= 0) queue.push_back(f);
    for (std::size_t head = 0; head < queue.size(); ++head) {
      const int f = queue[head];
      const int label = g.face_labels[f];
      for (int k = 0; k < 3; ++k) {
        const int h = adjacency[3 * f + k];
        if (h < 0 || g.face_labels[h] >= 0 || g.visible_owner[h] != label) continue;
        g.face_labels[h] = label;
        ++g.faces_grown;
        queue.push_back(h);
      }
    }
  }
  // --- 3. flood fill, nearest first ----------------------------------------------------------
  {
    std::vector<double> dist(nf, kInf);
    using Item = std::pair<double, int>;
    std::priority_queue<Item, std::vector<Item>, std::greater<Item>> heap;
    for (int f = 0; f < nf; ++f) {
      if (g.face_labels[f] >= 0) {
        dist[f] = 0;
        heap.push({0.0, f});
      }
    }
    std::vector<char> done(nf, 0);
    while (!heap.empty()) {
      const auto [d, f] = heap.top();
      heap.pop();
      if (done[f]) continue;
      done[f] = 1;
      for (int k = 0; k < 3; ++k) {
        const int h = adjacency[3 * f + k];
        if (h < 0 || done[h]) continue;
        const double nd = d + (centroid.row(f) - centroid.row(h)).norm();
        if (nd < dist[h]) {  // only unlabelled faces can improve (labelled ones are at 0)
          dist[h] = nd;
          g.face_labels[h] = g.face_labels[f];
          heap.push({nd, h});
        }
      }
    }
    g.faces_filled = static_cast<int>((g.face_labels.array() >= 0).count()) - g.faces_seeded - g.faces_grown;
  }

  // --- links from shared edges, their costs --------------------------------------------------
  {
    std::vector<std::pair<int, int>> pairs;
    for (int f = 0; f < nf; ++f) {
      for (int k = 0; k < 3; ++k) {
        const int h = adjacency[3 * f + k];
        if (h < 0) continue;
        int a = g.face_labels[f], b = g.face_labels[h];
        if (a < 0 || b < 0 || a == b) continue;
        if (a > b) std::swap(a, b);
        pairs.emplace_back(a, b);
      }
    }
    std::sort(pairs.begin(), pairs.end());
    pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
    const int L = static_cast<int>(pairs.size());
    g.candidates.resize(L, 2);
    g.costs.resize(L);
    g.candidate_state = Eigen::VectorXi::Zero(L);
    for (int l = 0; l < L; ++l) g.candidates.row(l) << pairs[l].first, pairs[l].second;
    tbb::parallel_for(0, L, [&](int l) {
      const Eigen::Vector3d a = points.row(pairs[l].first).transpose(),
                            b = points.row(pairs[l].second).transpose();
      // Both points are inside, so the link is inside unless its segment crosses the surface.
      // (Requiring also that every sample on it see only backs of faces in all 64 directions
      // failed at any 0.3% noise fold in view: a noisy kitten lost the link that closes its
      // tail's loop in 5 of 10 draws.) The field is sampled only along links that stay inside.
      g.costs[l] = query.segment_blocked(a, b) ? kInf : field.mean_magnitude(a, b, options.cost_samples);
    });
  }

  // --- spanning tree ----------------------------------------------------------------------
  const int L = static_cast<int>(g.candidates.rows());
  std::vector<char> has_face(P, 0);
  for (int f = 0; f < nf; ++f)
    if (g.face_labels[f] >= 0) has_face[g.face_labels[f]] = 1;
  Graph graph(P);
  for (int p = 0; p < P; ++p) graph.set_alive(p, has_face[p] != 0);
  std::vector<int> order(L);
  std::iota(order.begin(), order.end(), 0);
  auto touches_end = [&](int l) { return is_end(g.candidates(l, 0)) || is_end(g.candidates(l, 1)); };
  std::stable_sort(order.begin(), order.end(), [&](int x, int y) {
    if (touches_end(x) != touches_end(y)) return !touches_end(x);
    return g.costs[x] < g.costs[y];
  });
  UnionFind uf(P);
  std::vector<std::vector<std::pair<int, int>>> tree(P);  // (neighbour, link)
  for (int l : order) {
    const int a = g.candidates(l, 0), b = g.candidates(l, 1);
    if (uf.unite(a, b)) {
      g.candidate_state[l] = 1;
      tree[a].push_back({b, l});
      tree[b].push_back({a, l});
      graph.link(a, b);
    }
  }

  // --- handle cycles ------------------------------------------------------------------------
  std::vector<std::vector<int>> kept;  // link sets of the kept cycles
  if (genus > 0) {
    // Parent pointers of the spanning forest, for tree paths.
    std::vector<int> parent(P, -1), parent_link(P, -1), depth(P, -1);
    for (int r = 0; r < P; ++r) {
      if (!has_face[r] || depth[r] >= 0) continue;
      depth[r] = 0;
      std::vector<int> stack = {r};
      while (!stack.empty()) {
        const int u = stack.back();
        stack.pop_back();
        for (const auto& [v, l] : tree[u]) {
          if (depth[v] >= 0) continue;
          depth[v] = depth[u] + 1;
          parent[v] = u;
          parent_link[v] = l;
          stack.push_back(v);
        }
      }
    }
    auto cycle_of = [&](int l, std::vector<int>& pts, std::vector<int>& links) {
      int a = g.candidates(l, 0), b = g.candidates(l, 1);
      std::vector<int> left, right;
      links = {l};
      while (a != b) {
        if (depth[a] >= depth[b]) {
          left.push_back(a);
          links.push_back(parent_link[a]);
          a = parent[a];
        } else {
          right.push_back(b);
          links.push_back(parent_link[b]);
          b = parent[b];
        }
      }
      pts = left;
      pts.push_back(a);
      pts.insert(pts.end(), right.rbegin(), right.rend());
      std::sort(links.begin(), links.end());
    };
    std::vector<int> non_tree;
    for (int l : order) {
      if (g.candidate_state[l] == 0 && std::isfinite(g.costs[l])) non_tree.push_back(l);
    }
    std::stable_sort(non_tree.begin(), non_tree.end(),
                     [&](int x, int y) { return g.costs[x] < g.costs[y]; });
    for (int l : non_tree) {
      if (static_cast<int>(kept.size()) >= genus) break;
      std::vector<int> pts, links;
      cycle_of(l, pts, links);
      if (all_see_each_other(query, points, pts)) {
        ++g.cycles_rejected_visible;
        continue;
      }
      bool duplicate = false;
      for (const auto& other : kept) {
        std::vector<int> diff;
        std::set_symmetric_difference(links.begin(), links.end(), other.begin(), other.end(),
                                      std::back_inserter(diff));
        if (diff.empty()) {
          duplicate = true;
          break;
        }
        // Components of the symmetric difference (over its links' points).
        std::vector<int> members;
        for (int x : diff) {
          members.push_back(g.candidates(x, 0));
          members.push_back(g.candidates(x, 1));
        }
        std::sort(members.begin(), members.end());
        members.erase(std::unique(members.begin(), members.end()), members.end());
        UnionFind local(static_cast<int>(members.size()));
        auto index = [&](int p) {
          return static_cast<int>(std::lower_bound(members.begin(), members.end(), p) - members.begin());
        };
        for (int x : diff) local.unite(index(g.candidates(x, 0)), index(g.candidates(x, 1)));
        std::vector<std::vector<int>> groups(members.size());
        for (std::size_t i = 0; i < members.size(); ++i) groups[local.find(static_cast<int>(i))].push_back(members[i]);
        bool all_visible = true;
        for (const auto& group : groups) {
          if (!group.empty() && !all_see_each_other(query, points, group)) {
            all_visible = false;
            break;
          }
        }
        if (all_visible) {
          duplicate = true;
          break;
        }
      }
      if (duplicate) {
        ++g.cycles_rejected_duplicate;
        continue;
      }
      kept.push_back(links);
      g.candidate_state[l] = 2;
      graph.link(g.candidates(l, 0), g.candidates(l, 1));
    }
  }

  // --- pruning ----------------------------------------------------------------------------
  int live_ends = 0;
  for (int p = 0; p < P; ++p) live_ends += graph.alive[p] && is_end(p);
  if (options.prune && live_ends <= 1 && kept.empty()) {
    // No limb to keep: the longest path of the tree (from the end point when there is one).
    auto farthest = [&](int from, std::vector<int>& prev) {
      std::vector<double> dist(P, -1);
      prev.assign(P, -1);
      dist[from] = 0;
      std::vector<int> stack = {from};
      int best = from;
      while (!stack.empty()) {
        const int u = stack.back();
        stack.pop_back();
        if (dist[u] > dist[best]) best = u;
        for (int v : graph.adj[u]) {
          if (dist[v] >= 0) continue;
          dist[v] = dist[u] + (points.row(u) - points.row(v)).norm();
          prev[v] = u;
          stack.push_back(v);
        }
      }
      return best;
    };
    int start = -1;
    for (int p = 0; p < P; ++p) {
      if (!graph.alive[p]) continue;
      if (start < 0 || (is_end(p) && !is_end(start)) ||
          (is_end(p) == is_end(start) && radii[p] > radii[start])) {
        start = p;
      }
    }
    std::vector<int> prev;
    if (live_ends == 0) start = farthest(start, prev);
    const int stop = farthest(start, prev);
    std::vector<char> on_path(P, 0);
    for (int u = stop; u >= 0; u = prev[u]) on_path[u] = 1;
    // Everything off the path is absorbed by the path node its branch hangs from.
    std::vector<int> queue;
    for (int p = 0; p < P; ++p)
      if (on_path[p]) queue.push_back(p);
    std::vector<char> seen(on_path.begin(), on_path.end());
    std::vector<std::pair<int, int>> absorbed;  // (point, by)
    for (std::size_t head = 0; head < queue.size(); ++head) {
      const int u = queue[head];
      for (int v : graph.adj[u]) {
        if (seen[v]) continue;
        seen[v] = 1;
        absorbed.emplace_back(v, u);
        queue.push_back(v);
      }
    }
    for (auto it = absorbed.rbegin(); it != absorbed.rend(); ++it) {
      graph.merge(it->second, it->first);
      ++g.pruned;
    }
  } else if (options.prune) {
    std::vector<int> queue;
    for (int p = 0; p < P; ++p)
      if (graph.alive[p] && graph.degree(p) <= 1 && !is_end(p)) queue.push_back(p);
    while (!queue.empty()) {
      const int p = queue.back();
      queue.pop_back();
      if (!graph.alive[p] || graph.degree(p) > 1 || is_end(p)) continue;
      if (graph.count_alive() <= 2) break;
      if (graph.degree(p) == 0) {
        graph.set_alive(p, false);  // an isolated point (cannot happen on a connected surface)
        ++g.pruned;
        continue;
      }
      const int q = *graph.adj[p].begin();
      graph.merge(q, p);
      ++g.pruned;
      if (graph.degree(q) <= 1 && !is_end(q)) queue.push_back(q);
    }
  }

  // --- contraction of short links ------------------------------------------------------------
  if (options.contract) {
    for (bool changed = true; changed;) {
      changed = false;
      // Shortest (relative to the larger radius) first.
      std::vector<std::tuple<double, int, int>> shorts;
      for (int a = 0; a < P; ++a) {
        if (!graph.alive[a]) continue;
        for (int b : graph.adj[a]) {
          if (b < a) continue;
          const double length = (points.row(a) - points.row(b)).norm();
          const double reach = std::max(radii[a], radii[b]);
          if (length < reach) shorts.emplace_back(length / reach, a, b);
        }
      }
      std::sort(shorts.begin(), shorts.end());
      for (const auto& [ratio, a0, b0] : shorts) {
        (void)ratio;
        int a = a0, b = b0;
        if (!graph.alive[a] || !graph.alive[b] || !graph.adj[a].count(b)) continue;
        if (graph.count_alive() <= 2) break;
        bool shared = false;
        for (int x : graph.adj[a]) {
          if (x != b && graph.adj[b].count(x)) {
            shared = true;
            break;
          }
        }
        if (shared) continue;
        if (is_end(a) && is_end(b)) continue;
        if (is_end(b) && !is_end(a)) std::swap(a, b);
        if (is_end(a)) {
          // a is an end point (b is not): a tip absorbs the chain node next to it. An end
          // next to a junction stays (the bumps pass below decides with the tube test).
          if (graph.degree(a) == 1 && graph.degree(b) == 2) {
            graph.merge(a, b);
          } else {
            continue;  // an end point inside a cycle or a chain, or next to a junction
          }
        } else {
          if (radii[b] > radii[a]) std::swap(a, b);
          graph.merge(a, b);
        }
        ++g.contracted;
        changed = true;
      }
    }
  }

  // --- bumps: an end point that lies inside the tube of another link of its junction ----------
  // (within the smaller radius of that link's nodes), or whose ball barely reaches out of the
  // bent tube through its junction and two other neighbours, is part of the body, not a limb:
  // the digit eight's prongs sit on its loops. It merges into its junction.
  if (options.contract) {
    for (int e = 0; e < P; ++e) {
      if (!graph.alive[e] || !is_end(e) || graph.degree(e) != 1) continue;
      const int v = *graph.adj[e].begin();
      if (graph.degree(v) < 3 || graph.count_alive() <= 2) continue;
      const Eigen::Vector3d pe = points.row(e).transpose(), pv = points.row(v).transpose();
      std::vector<int> others;
      for (int w : graph.adj[v])
        if (w != e) others.push_back(w);
      bool bump = false;
      for (std::size_t i = 0; i < others.size() && !bump; ++i) {
        const int w = others[i];
        const Eigen::Vector3d pw = points.row(w).transpose();
        bump = point_segment_distance(pe, pv, pw) < std::min(radii[v], radii[w]);
        // The body may bend at v (a loop of the eight): its center line through w, v and
        // another neighbour x beyond v is about the circle arc through them, and a straight
        // link cuts inside that bend by up to a radius. The end is a bump when its ball reaches
        // out of that tube (the smallest radius of the three) by less than kBumpReach of it;
        // a limb reaches out by more than one (fertility's closest head: 1.1, the eight's
        // bumps under noise: 0.2-0.25).
        for (std::size_t j = i + 1; j < others.size() && !bump; ++j) {
          const int x = others[j];
          const Eigen::Vector3d px = points.row(x).transpose();
          // Only where the body runs through v (w and x on either side of it): through two
          // neighbours on one side (two limbs' roots) the arc is most of a circle, far from
          // the body.
          if ((pw - pv).dot(px - pv) >= 0) continue;
          const double tube = std::min({radii[v], radii[w], radii[x]});
          bump = arc_distance(pe, pw, pv, px) + radii[e] <
                 (1 + kBumpReach) * tube;
        }
      }
      if (bump) {
        graph.merge(v, e);
        ++g.ends_absorbed;
      }
    }
  }

  // --- joints close along their path, or closer than the body is wide, are one junction --------
  if (options.merge_joints) {
    std::vector<std::vector<int>> members(P);
    for (int p = 0; p < P; ++p) members[p] = {p};
    for (bool changed = true; changed;) {
      changed = false;
      for (int a = 0; a < P && !changed; ++a) {
        if (!graph.alive[a] || graph.degree(a) < 3) continue;
        for (int first : graph.adj[a]) {
          // Walk the chain of degree-2 points from a through `first`.
          std::vector<int> chain;
          int prev = a, cur = first;
          while (graph.degree(cur) == 2 && cur != a) {
            chain.push_back(cur);
            const int next = *graph.adj[cur].begin() == prev ? *std::next(graph.adj[cur].begin())
                                                              : *graph.adj[cur].begin();
            prev = cur;
            cur = next;
          }
          const int b = cur;
          if (b == a || graph.degree(b) < 3) continue;
          // The gap between the two junctions' balls along the chain, each junction being the
          // union of the joints merged into it so far (the chain hangs from one of them).
          double gap = 0;
          if (chain.empty()) {
            gap = std::numeric_limits<double>::infinity();
            for (int m : members[a])
              for (int n : members[b])
                gap = std::min(gap, (points.row(m) - points.row(n)).norm() - radii[m] - radii[n]);
          } else {
            double inner = 0;
            for (std::size_t k = 0; k + 1 < chain.size(); ++k) {
              inner += (points.row(chain[k]) - points.row(chain[k + 1])).norm();
            }
            double head = std::numeric_limits<double>::infinity(), tail = head;
            for (int m : members[a]) head = std::min(head, (points.row(m) - points.row(chain.front())).norm() - radii[m]);
            for (int n : members[b]) tail = std::min(tail, (points.row(n) - points.row(chain.back())).norm() - radii[n]);
            gap = head + inner + tail;
          }
          // Directly linked junctions (their domain surfaces touch: no body part between them)
          // are one junction while their balls are less than a ball apart; across a chain only
          // overlapping balls merge (a chain a ball long can be a torso: the cheetah's front and
          // hind junctions, perturbed, came 0.94 balls apart along theirs).
          const double reach = chain.empty() ? std::min(radii[a], radii[b]) : 0.0;
          if (gap >= reach) {
            // Nor is a body part one that is shorter than the body is wide across it: two
            // junctions closer to each other than the widest chord through their midpoint are
            // one, whatever lies between them (a palm with fingers hanging from two of its
            // points, a chunky torso, or one junction split in two whose balls overlap, joined
            // through a point beside them). A torso or a limb between two junctions is longer
            // than it is wide. The straight segment must stay inside, or the chord measures
            // another part.
            const Eigen::Vector3d pa = points.row(a).transpose(), pb = points.row(b).transpose();
            const double apart = (pa - pb).norm();
            if (apart <= 0 || !query.segment_inside(pa, pb)) continue;
            const double chord = widest_chord(query, pa, pb);
            if (!std::isfinite(chord) || apart >= chord) continue;
          }
          // Only across a bridge: merging the two ends of a cycle would fold it.
          std::vector<char> seen(graph.alive.size(), 0);
          for (int c : chain) seen[c] = 1;
          seen[a] = 1;
          std::vector<int> stack;
          for (int n : graph.adj[a]) {
            if (n == (chain.empty() ? b : chain.front())) continue;
            if (!seen[n]) {
              seen[n] = 1;
              stack.push_back(n);
            }
          }
          bool other_path = false;
          while (!stack.empty() && !other_path) {
            const int u = stack.back();
            stack.pop_back();
            for (int n : graph.adj[u]) {
              if (n == b) other_path = true;
              if (!seen[n]) {
                seen[n] = 1;
                stack.push_back(n);
              }
            }
          }
          if (other_path) continue;
          const int keep = radii[b] > radii[a] ? b : a, gone = keep == a ? b : a;
          for (int c : chain) graph.merge(keep, c);
          graph.merge(keep, gone);
          members[keep].insert(members[keep].end(), members[gone].begin(), members[gone].end());
          ++g.joints_merged;
          changed = true;
          break;
        }
      }
    }
  }

  // --- a spine for a shape that shrank to one point ------------------------------------------
  // (a sphere: every domain point reaches its center) so that it still gets a bone: two points
  // on its principal axis, half way from the center to the surface on either side.
  if (graph.count_alive() == 1) {
    int c = 0;
    while (!graph.alive[c]) ++c;
    const Eigen::RowVector3d mean = mesh.V.colwise().mean();
    const Eigen::MatrixXd centered = mesh.V.rowwise() - mean;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> pca(centered.transpose() * centered);
    const Eigen::Vector3d axis = pca.eigenvectors().col(2);
    const Eigen::Vector3d pc = g.points.row(c).transpose();
    std::vector<Eigen::Vector3d> spine;
    for (double side : {1.0, -1.0}) {
      const double wall = query.ray_hit(pc, side * axis);
      if (!std::isfinite(wall) || wall <= 0) continue;
      const Eigen::Vector3d q = pc + 0.5 * wall * side * axis;
      if (query.inside(q)) spine.push_back(q);
    }
    for (const Eigen::Vector3d& q : spine) {
      const int index = static_cast<int>(g.points.rows());
      g.points.conservativeResize(index + 1, 3);
      g.points.row(index) = q.transpose();
      g.radii.conservativeResize(index + 1);
      g.radii[index] = query.distance(q);
      g.prong.conservativeResize(index + 1);
      g.prong[index] = -1;
      has_face.push_back(0);
      graph.adj.emplace_back();
      graph.alive.push_back(0);
      graph.set_alive(index, true);
      graph.absorbed_by.push_back(-1);
      graph.link(c, index);
    }
  }

  // --- the kept graph -----------------------------------------------------------------------
  P = static_cast<int>(g.points.rows());
  g.node_of_point = Eigen::VectorXi::Constant(P, -1);
  for (int p = 0; p < P; ++p) {
    if (graph.alive[p]) {
      g.node_of_point[p] = static_cast<int>(g.nodes.size());
      g.nodes.push_back(p);
    }
  }
  for (int p = 0; p < P; ++p) {
    if (graph.alive[p] || !has_face[p]) continue;
    int q = p;
    for (int guard = 0; guard <= P && !graph.alive[q] && graph.absorbed_by[q] >= 0; ++guard) q = graph.absorbed_by[q];
    g.node_of_point[p] = graph.alive[q] ? g.node_of_point[q] : -1;
  }
  std::vector<std::pair<int, int>> links;
  for (int a : g.nodes) {
    for (int b : graph.adj[a]) {
      if (b > a) links.emplace_back(g.node_of_point[a], g.node_of_point[b]);
    }
  }
  g.links.resize(static_cast<Eigen::Index>(links.size()), 2);
  for (std::size_t l = 0; l < links.size(); ++l) g.links.row(l) << links[l].first, links[l].second;
  const int N = static_cast<int>(g.nodes.size());
  std::vector<int> degree(N, 0);
  UnionFind comp(std::max(N, 1));
  for (const auto& [a, b] : links) {
    ++degree[a];
    ++degree[b];
    comp.unite(a, b);
  }
  g.kinds.resize(N);
  for (int i = 0; i < N; ++i) {
    g.kinds[i] = node_kind_of_degree(static_cast<std::size_t>(degree[i]));
  }
  for (int i = 0; i < N; ++i) g.components += comp.find(i) == i;
  g.cycles = static_cast<int>(links.size()) - N + g.components;
  g.face_nodes.resize(nf);
  for (int f = 0; f < nf; ++f) {
    g.face_nodes[f] = g.face_labels[f] >= 0 ? g.node_of_point[g.face_labels[f]] : -1;
  }
  return g;
}

}  // namespace dcg

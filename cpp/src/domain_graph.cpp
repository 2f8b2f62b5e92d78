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

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <Eigen/Eigenvalues>

#include "dcg/errors.h"
#include "dcg/force_field.h"
#include "dcg/skeleton.h"
#include "dcg/surface_query.h"
#include "dcg/weights.h"
#include "domain_graph_passes.h"
#include "edge_table.h"
#include "polling.h"
#include "union_find.h"

namespace dcg {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// How far (in tube radii) an end point's ball may reach out of the body's tube at its junction
// and still be a bump on it (see is_bump).
constexpr double kBumpReach = 0.6;
// A cycle whose points see each other but across cracks, out of the shape along no segment
// between two of them for more than this many times the smaller of their radii, runs around a
// pinhole tunnel or a slit where parts barely meet, not around a handle (see keep_handle_cycles).
constexpr double kCrack = 1.0;
// A link whose segment leaves the shape is no link (its cost is infinite), but one that only
// grazes the surface, out of it for at most this many times the smaller of its points' radii,
// may still close a cycle (keep_handle_cycles; remap routes it inside). A curved tube sampled
// sparsely: kitten's tail loop under 1e-5 of noise closed only across its inner side's
// surface (0.19 radii out), and was lost in 6 of 29 draws. Links between touching parts
// leave for 2.5 radii or more (Q_Male_Casual's legs), around Mannequiny's pinholes 0.47.
constexpr double kGraze = 0.25;

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

// For each segment a[i]-b[i] (xyz triples, one after the other), whether it meets the surface.
std::vector<unsigned char> blocked_segments(const SurfaceQuery& query, const std::vector<double>& a,
                                            const std::vector<double>& b) {
  const int count = static_cast<int>(a.size() / 3);
  std::vector<unsigned char> blocked(count);
  if (count > 0) query.segments_blocked(a.data(), b.data(), count, 0.0, blocked.data());
  return blocked;
}

// Whether none of the segments a[i]-b[i] meets the surface.
bool none_blocked(const SurfaceQuery& query, const std::vector<double>& a,
                  const std::vector<double>& b) {
  const std::vector<unsigned char> blocked = blocked_segments(query, a, b);
  return std::none_of(blocked.begin(), blocked.end(), [](unsigned char x) { return x != 0; });
}

// Each pair of `pts` once (into `pairs`), and whether the segment between the two meets the
// surface.
std::vector<unsigned char> blocked_pairs(const SurfaceQuery& query, const Points& points,
                                         const std::vector<int>& pts,
                                         std::vector<std::pair<int, int>>& pairs) {
  std::vector<double> a, b;
  pairs.clear();
  for (std::size_t i = 0; i < pts.size(); ++i) {
    for (std::size_t j = i + 1; j < pts.size(); ++j) {
      pairs.emplace_back(pts[i], pts[j]);
      for (int k = 0; k < 3; ++k) {
        a.push_back(points(pts[i], k));
        b.push_back(points(pts[j], k));
      }
    }
  }
  return blocked_segments(query, a, b);
}

// Whether every pair of `pts` sees each other (no segment between two of them meets the surface).
bool all_see_each_other(const SurfaceQuery& query, const Points& points,
                        const std::vector<int>& pts) {
  std::vector<std::pair<int, int>> pairs;
  const std::vector<unsigned char> blocked = blocked_pairs(query, points, pts, pairs);
  return std::none_of(blocked.begin(), blocked.end(), [](unsigned char x) { return x != 0; });
}

// How long the segment a-b runs outside the shape, a inside: the stretches from where it
// leaves (through the back of a face) to where it comes in again, or to b.
double outside_length(const SurfaceQuery& query, const Eigen::Vector3d& a,
                      const Eigen::Vector3d& b) {
  const double length = (b - a).norm();
  if (!(length > 0)) return 0;
  const Eigen::Vector3d d = (b - a) / length;
  // Past the face just hit: Embree hits in float, so a step of 1e-9 of the segment hit the same
  // face again (in normalized units, where the working mesh's diagonal is 1).
  const double step = 1e-6;
  double t = 0, left = -1, outside = 0;
  for (int hit = 0; hit < 64; ++hit) {
    int f = -1;
    const double h = query.ray_hit(a + t * d, d, &f);
    if (!(t + h < length) || f < 0) break;
    t += h;
    if (query.face_normal(f).dot(d) > 0) {
      if (left < 0) left = t;
    } else if (left >= 0) {
      outside += t - left;
      left = -1;
    }
    t += step;
  }
  return left >= 0 ? outside + length - left : outside;
}

// Whether every pair of `pts` sees each other, or but across a crack: the segment between two
// of them is outside the shape for at most kCrack times the smaller of their radii.
bool see_each_other_across_cracks(const SurfaceQuery& query, const Points& points,
                                  const Eigen::VectorXd& radii, const std::vector<int>& pts) {
  std::vector<std::pair<int, int>> pairs;
  const std::vector<unsigned char> blocked = blocked_pairs(query, points, pts, pairs);
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const auto [p, q] = pairs[k];
    if (blocked[k] && outside_length(query, points.row(p).transpose(), points.row(q).transpose()) >
                          kCrack * std::min(radii[p], radii[q]))
      return false;
  }
  return true;
}

// Whether the cycle through `pts` spans a disk inside the shape: its centroid is inside and
// sees every point of it (a fan of segments from the centroid). Such a cycle is contractible:
// it runs around a concave corner (a crotch, an armpit), not around a handle, even where some
// of its points do not see each other.
bool spans_inner_disk(const SurfaceQuery& query, const Points& points,
                      const std::vector<int>& pts) {
  if (pts.empty()) return false;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (int p : pts) centroid += points.row(p).transpose();
  centroid /= static_cast<double>(pts.size());
  if (!query.inside(centroid)) return false;
  std::vector<double> a, b;
  for (int p : pts) {
    for (int k = 0; k < 3; ++k) {
      a.push_back(centroid[k]);
      b.push_back(points(p, k));
    }
  }
  return none_blocked(query, a, b);
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

// --- helpers of the passes below ------------------------------------------------------------

using internal::Graph;
using internal::GraphWork;

// Parent pointers of the spanning forest, for the tree path between two points.
struct TreePaths {
  std::vector<int> parent, parent_link, depth;

  explicit TreePaths(const GraphWork& w) {
    const int P = w.point_count();
    parent.assign(P, -1);
    parent_link.assign(P, -1);
    depth.assign(P, -1);
    for (int r = 0; r < P; ++r) {
      if (!w.has_face[r] || depth[r] >= 0) continue;
      depth[r] = 0;
      std::vector<int> stack = {r};
      while (!stack.empty()) {
        const int u = stack.back();
        stack.pop_back();
        for (const auto& [v, l] : w.tree[u]) {
          if (depth[v] >= 0) continue;
          depth[v] = depth[u] + 1;
          parent[v] = u;
          parent_link[v] = l;
          stack.push_back(v);
        }
      }
    }
  }

  // The cycle that candidate l closes with the tree: its points in order and its links, sorted.
  void cycle(const Edges& candidates, int l, std::vector<int>& pts, std::vector<int>& links) const {
    int a = candidates(l, 0), b = candidates(l, 1);
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
  }
};

// Whether the cycle with sorted link set `links` duplicates a kept cycle: their symmetric
// difference is empty or splits into loops whose points all see each other.
bool duplicates_kept_cycle(const GraphWork& w, const std::vector<int>& links) {
  const Edges& candidates = w.g.candidates;
  for (const auto& other : w.kept_cycles) {
    std::vector<int> diff;
    std::set_symmetric_difference(links.begin(), links.end(), other.begin(), other.end(),
                                  std::back_inserter(diff));
    if (diff.empty()) return true;
    // Components of the symmetric difference (over its links' points).
    std::vector<int> members;
    for (int x : diff) {
      members.push_back(candidates(x, 0));
      members.push_back(candidates(x, 1));
    }
    std::sort(members.begin(), members.end());
    members.erase(std::unique(members.begin(), members.end()), members.end());
    UnionFind local(static_cast<int>(members.size()));
    auto index = [&](int p) {
      return static_cast<int>(std::lower_bound(members.begin(), members.end(), p) -
                              members.begin());
    };
    for (int x : diff) local.unite(index(candidates(x, 0)), index(candidates(x, 1)));
    std::vector<std::vector<int>> groups(members.size());
    for (std::size_t i = 0; i < members.size(); ++i) {
      groups[local.find(static_cast<int>(i))].push_back(members[i]);
    }
    bool all_visible = true;
    for (const auto& group : groups) {
      if (!group.empty() && !all_see_each_other(w.query, w.g.points, group)) {
        all_visible = false;
        break;
      }
    }
    if (all_visible) return true;
  }
  return false;
}

// The live point farthest from `from` along the graph (a tree), with the path back in `prev`.
int farthest(const Graph& graph, const Points& points, int from, std::vector<int>& prev) {
  const int P = static_cast<int>(graph.adj.size());
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
}

// No limb to keep: the longest path of the tree (from the end point when there is one); every
// branch off it is absorbed by the path node it hangs from.
void keep_longest_path(GraphWork& w, int live_ends) {
  Graph& graph = w.graph;
  const int P = w.point_count();
  int start = -1;
  for (int p = 0; p < P; ++p) {
    if (!graph.alive[p]) continue;
    if (start < 0 || (w.is_end(p) && !w.is_end(start)) ||
        (w.is_end(p) == w.is_end(start) && w.g.radii[p] > w.g.radii[start])) {
      start = p;
    }
  }
  std::vector<int> prev;
  if (live_ends == 0) start = farthest(graph, w.g.points, start, prev);
  const int stop = farthest(graph, w.g.points, start, prev);
  std::vector<char> on_path(P, 0);
  for (int u = stop; u >= 0; u = prev[u]) on_path[u] = 1;
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
    ++w.g.pruned;
  }
}

// Non-end leaves are pruned repeatedly (their parent may become one), while more than two
// points live.
void prune_leaves(GraphWork& w) {
  Graph& graph = w.graph;
  std::vector<int> queue;
  for (int p = 0; p < w.point_count(); ++p)
    if (graph.alive[p] && graph.degree(p) <= 1 && !w.is_end(p)) queue.push_back(p);
  while (!queue.empty()) {
    const int p = queue.back();
    queue.pop_back();
    if (!graph.alive[p] || graph.degree(p) > 1 || w.is_end(p)) continue;
    if (graph.count_alive() <= 2) break;
    if (graph.degree(p) == 0) {
      graph.set_alive(p, false);  // an isolated point (cannot happen on a connected surface)
      ++w.g.pruned;
      continue;
    }
    const int q = *graph.adj[p].begin();
    graph.merge(q, p);
    ++w.g.pruned;
    if (graph.degree(q) <= 1 && !w.is_end(q)) queue.push_back(q);
  }
}

// Links shorter than the larger radius of their nodes, by that ratio (shortest first).
std::vector<std::tuple<double, int, int>> short_links(const GraphWork& w) {
  std::vector<std::tuple<double, int, int>> shorts;
  for (int a = 0; a < w.point_count(); ++a) {
    if (!w.graph.alive[a]) continue;
    for (int b : w.graph.adj[a]) {
      if (b < a) continue;
      const double length = (w.g.points.row(a) - w.g.points.row(b)).norm();
      const double reach = std::max(w.g.radii[a], w.g.radii[b]);
      if (length < reach) shorts.emplace_back(length / reach, a, b);
    }
  }
  std::sort(shorts.begin(), shorts.end());
  return shorts;
}

bool share_a_neighbour(const Graph& graph, int a, int b) {
  for (int x : graph.adj[a]) {
    if (x != b && graph.adj[b].count(x)) return true;
  }
  return false;
}

// The neighbour of `node`, a point of degree 2, other than `from`.
int other_neighbour(const Graph& graph, int node, int from) {
  const auto first = graph.adj[node].begin();
  return *first == from ? *std::next(first) : *first;
}

// Whether the end point e, a leaf on the junction v, is a bump on the body at v: inside the tube
// of another link of v (within the smaller radius of its nodes), or with its ball reaching out
// of the bent tube through v and two other neighbours by less than kBumpReach of that tube.
bool is_bump(const GraphWork& w, int e, int v) {
  const Points& points = w.g.points;
  const Eigen::VectorXd& radii = w.g.radii;
  const Eigen::Vector3d pe = points.row(e).transpose(), pv = points.row(v).transpose();
  std::vector<int> others;
  for (int x : w.graph.adj[v])
    if (x != e) others.push_back(x);
  for (std::size_t i = 0; i < others.size(); ++i) {
    const int a = others[i];
    const Eigen::Vector3d pa = points.row(a).transpose();
    if (point_segment_distance(pe, pv, pa) < std::min(radii[v], radii[a])) return true;
    // The body may bend at v (a loop of the eight): its center line through a, v and another
    // neighbour b beyond v is about the circle arc through them, and a straight link cuts
    // inside that bend by up to a radius. A limb reaches out of that tube (the smallest radius
    // of the three) by more than one radius (fertility's closest head: 1.1, the eight's bumps
    // under noise: 0.2-0.25).
    for (std::size_t j = i + 1; j < others.size(); ++j) {
      const int b = others[j];
      const Eigen::Vector3d pb = points.row(b).transpose();
      // Only where the body runs through v (a and b on either side of it): through two
      // neighbours on one side (two limbs' roots) the arc is most of a circle, far from the body.
      if ((pa - pv).dot(pb - pv) >= 0) continue;
      const double tube = std::min({radii[v], radii[a], radii[b]});
      if (arc_distance(pe, pa, pv, pb) + radii[e] < (1 + kBumpReach) * tube) return true;
    }
    // One step further along the body: the end may lie inside the tube of the next stretch of
    // a chain through v (an end ball on the eight's rim, under noise, linked to a point of the
    // loop one step down from it: a stray end in 2 of 29 draws). Only the straight tube there:
    // its bent tube held kitten's ears too, which end past a point of the head.
    if (w.graph.degree(a) != 2) continue;
    const int b = other_neighbour(w.graph, a, v);
    if (point_segment_distance(pe, pa, points.row(b).transpose()) < std::min(radii[a], radii[b]))
      return true;
  }
  return false;
}

// Walks the chain of degree-2 points from the junction a through its neighbour `first`; returns
// the point where it stops (a junction, an end, or a itself around a cycle).
int walk_chain(const Graph& graph, int a, int first, std::vector<int>& chain) {
  chain.clear();
  int prev = a, cur = first;
  while (graph.degree(cur) == 2 && cur != a) {
    chain.push_back(cur);
    const int next = other_neighbour(graph, cur, prev);
    prev = cur;
    cur = next;
  }
  return cur;
}

// The gap between the balls of junctions a and b along the chain between them, each junction
// being the union of the points merged into it so far (`members`).
double junction_gap(const GraphWork& w, const std::vector<int>& members_a,
                    const std::vector<int>& members_b, const std::vector<int>& chain) {
  const Points& points = w.g.points;
  const Eigen::VectorXd& radii = w.g.radii;
  if (chain.empty()) {
    double gap = std::numeric_limits<double>::infinity();
    for (int m : members_a)
      for (int n : members_b)
        gap = std::min(gap, (points.row(m) - points.row(n)).norm() - radii[m] - radii[n]);
    return gap;
  }
  double inner = 0;
  for (std::size_t k = 0; k + 1 < chain.size(); ++k) {
    inner += (points.row(chain[k]) - points.row(chain[k + 1])).norm();
  }
  double head = std::numeric_limits<double>::infinity(), tail = head;
  for (int m : members_a) {
    head = std::min(head, (points.row(m) - points.row(chain.front())).norm() - radii[m]);
  }
  for (int n : members_b) {
    tail = std::min(tail, (points.row(n) - points.row(chain.back())).norm() - radii[n]);
  }
  return head + inner + tail;
}

// Whether junctions a and b are closer to each other than the widest chord of the shape through
// their midpoint: a body part shorter than it is wide is no part (a palm with fingers hanging
// from two of its points, a chunky torso, or one junction split in two whose balls overlap,
// joined through a point beside them); a torso or a limb is longer than it is wide. The straight
// segment must stay inside, or the chord measures another part.
bool closer_than_wide(const GraphWork& w, int a, int b) {
  const Eigen::Vector3d pa = w.g.points.row(a).transpose(), pb = w.g.points.row(b).transpose();
  const double apart = (pa - pb).norm();
  if (apart <= 0 || !w.query.segment_inside(pa, pb)) return false;
  const double chord = widest_chord(w.query, pa, pb);
  return std::isfinite(chord) && apart < chord;
}

// Whether a reaches b other than through `chain` (or their direct link): the two lie on a cycle.
bool on_a_cycle(const Graph& graph, int a, int b, const std::vector<int>& chain) {
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
  return other_path;
}

// One merge of two junctions (see merge_joints); false when no pair qualifies.
bool merge_one_joint_pair(GraphWork& w, std::vector<std::vector<int>>& members) {
  Graph& graph = w.graph;
  const Eigen::VectorXd& radii = w.g.radii;
  std::vector<int> chain;
  for (int a = 0; a < w.point_count(); ++a) {
    if (!graph.alive[a] || graph.degree(a) < 3) continue;
    for (int first : graph.adj[a]) {
      const int b = walk_chain(graph, a, first, chain);
      if (b == a || graph.degree(b) < 3) continue;
      // Directly linked junctions (their domain surfaces touch: no body part between them) are
      // one junction while their balls are less than the larger ball's radius apart (the
      // smaller's split Mannequiny's hand, wrist and palm balls 1.1 smaller radii apart, on
      // one CGAL version and not on another); across a chain only
      // overlapping balls merge (a chain a ball long can be a torso: the cheetah's front and
      // hind junctions, perturbed, came 0.94 balls apart along theirs).
      const double reach = chain.empty() ? std::max(radii[a], radii[b]) : 0.0;
      if (junction_gap(w, members[a], members[b], chain) >= reach && !closer_than_wide(w, a, b)) {
        continue;
      }
      if (on_a_cycle(graph, a, b, chain)) continue;  // merging would fold the cycle
      const int keep = radii[b] > radii[a] ? b : a, gone = keep == a ? b : a;
      for (int c : chain) graph.merge(keep, c);
      graph.merge(keep, gone);
      members[keep].insert(members[keep].end(), members[gone].begin(), members[gone].end());
      ++w.g.joints_merged;
      return true;
    }
  }
  return false;
}

// Which points own a face (#P; only they come alive in the graph).
std::vector<char> face_owners(const DomainGraph& g) {
  std::vector<char> owns(g.points.rows(), 0);
  for (int f = 0; f < g.face_labels.size(); ++f)
    if (g.face_labels[f] >= 0) owns[g.face_labels[f]] = 1;
  return owns;
}

// Groups the points by the candidate links that stay inside (finite cost): uf's components.
void inside_parts(const GraphWork& w, UnionFind& uf) {
  const DomainGraph& g = w.g;
  for (int l = 0; l < g.candidates.rows(); ++l) {
    if (std::isfinite(g.costs[l])) uf.unite(g.candidates(l, 0), g.candidates(l, 1));
  }
}

}  // namespace

namespace internal {

GraphWork::GraphWork(const Mesh& mesh_, const ForceField& field_, const Points& points,
                     const Eigen::VectorXd& radii, const Eigen::VectorXi& prong)
    : mesh(mesh_),
      field(field_),
      query(field_.query()),
      centroid(mesh_.F.rows(), 3),
      adjacency(face_adjacency(mesh_.F)),
      graph(static_cast<int>(points.rows())) {
  g.points = points;
  g.radii = radii;
  g.prong = prong;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    centroid.row(f) =
        (mesh.V.row(mesh.F(f, 0)) + mesh.V.row(mesh.F(f, 1)) + mesh.V.row(mesh.F(f, 2))) / 3.0;
  }
}

void seed_primitive_faces(GraphWork& w) {
  DomainGraph& g = w.g;
  const int P = w.point_count();
  std::vector<int> closest_face(P);
  std::vector<double> closest_distance(P);
  parallel_chunks(P, per_thread(256), 16, w.poll, [&](const tbb::blocked_range<int>& r) {
    for (int p = r.begin(); p != r.end(); ++p) {
      int f = -1;
      const Eigen::Vector3d q = w.query.closest_point(g.points.row(p).transpose(), &f);
      closest_face[p] = f;
      closest_distance[p] = (q - g.points.row(p).transpose()).norm();
    }
  });
  std::vector<int> claim_order(P);
  std::iota(claim_order.begin(), claim_order.end(), 0);
  std::stable_sort(claim_order.begin(), claim_order.end(), [&](int a, int b) {
    if (w.is_end(a) != w.is_end(b)) return w.is_end(a);
    return closest_distance[a] < closest_distance[b];
  });
  g.face_labels = Eigen::VectorXi::Constant(w.mesh.F.rows(), -1);
  g.primitive_face = Eigen::VectorXi::Constant(P, -1);
  for (int p : claim_order) {
    const int f = closest_face[p];
    if (f < 0 || g.face_labels[f] >= 0) continue;
    g.face_labels[f] = p;
    g.primitive_face[p] = f;
    ++g.faces_seeded;
  }
}

void find_visible_owners(GraphWork& w, int candidates) {
  DomainGraph& g = w.g;
  const int P = w.point_count(), nf = static_cast<int>(w.mesh.F.rows());
  candidates = std::max(1, std::min(candidates, P));
  g.visible_owner = Eigen::VectorXi::Constant(nf, -1);
  // Faces are independent: in chunks, polled between.
  parallel_chunks(nf, per_thread(32), 16, w.poll, [&](const tbb::blocked_range<int>& range) {
    std::vector<std::pair<double, int>> d(P);
    std::vector<double> a(3 * 8), b(3 * 8);
    unsigned char blocked[8];
    for (int f = range.begin(); f != range.end(); ++f) {
      const Eigen::RowVector3d c = w.centroid.row(f);
      for (int p = 0; p < P; ++p) d[p] = {(g.points.row(p) - c).norm() - g.radii[p], p};
      std::partial_sort(d.begin(), d.begin() + candidates, d.end());
      // The nearest candidate alone first (it usually sees the face), then packets of 8.
      for (int start = 0; start < candidates && g.visible_owner[f] < 0;
           start += start == 0 ? 1 : 8) {
        const int n = std::min(start == 0 ? 1 : 8, candidates - start);
        for (int k = 0; k < n; ++k) {
          for (int j = 0; j < 3; ++j) {
            a[3 * k + j] = g.points(d[start + k].second, j);
            b[3 * k + j] = c[j];
          }
        }
        w.query.segments_blocked(a.data(), b.data(), n, 1e-4, blocked);
        for (int k = 0; k < n; ++k) {
          if (!blocked[k]) {
            g.visible_owner[f] = d[start + k].second;
            break;
          }
        }
      }
    }
  });
}

void grow_regions(GraphWork& w) {
  DomainGraph& g = w.g;
  std::vector<int> queue;
  for (int f = 0; f < g.face_labels.size(); ++f)
    if (g.face_labels[f] >= 0) queue.push_back(f);
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const int f = queue[head];
    const int label = g.face_labels[f];
    for (int k = 0; k < 3; ++k) {
      const int h = w.adjacency[3 * f + k];
      if (h < 0 || g.face_labels[h] >= 0 || g.visible_owner[h] != label) continue;
      g.face_labels[h] = label;
      ++g.faces_grown;
      queue.push_back(h);
    }
  }
}

void flood_fill_labels(GraphWork& w) {
  DomainGraph& g = w.g;
  const int nf = static_cast<int>(g.face_labels.size());
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
      const int h = w.adjacency[3 * f + k];
      if (h < 0 || done[h]) continue;
      const double nd = d + (w.centroid.row(f) - w.centroid.row(h)).norm();
      if (nd < dist[h]) {  // only unlabelled faces can improve (labelled ones are at 0)
        dist[h] = nd;
        g.face_labels[h] = g.face_labels[f];
        heap.push({nd, h});
      }
    }
  }
  g.faces_filled =
      static_cast<int>((g.face_labels.array() >= 0).count()) - g.faces_seeded - g.faces_grown;
}

void label_faces(GraphWork& w, int visibility_candidates) {
  const std::function<void(double)> whole = w.poll;
  auto part = [&](double a, double b) {
    if (whole) w.poll = [whole, a, b](double f) { whole(a + (b - a) * f); };
    w.at(0);
  };
  part(0, 0.1);
  seed_primitive_faces(w);
  part(0.1, 0.9);  // the visibility tests: most of the labelling's time
  find_visible_owners(w, visibility_candidates);
  part(0.9, 1);
  grow_regions(w);
  flood_fill_labels(w);
  w.poll = whole;
}

void link_candidates(GraphWork& w, int cost_samples) {
  DomainGraph& g = w.g;
  std::vector<std::pair<int, int>> pairs;
  for (int f = 0; f < g.face_labels.size(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int h = w.adjacency[3 * f + k];
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
  parallel_chunks(L, per_thread(32), 1, w.poll, [&](const tbb::blocked_range<int>& r) {
    for (int l = r.begin(); l != r.end(); ++l) {
      const Eigen::Vector3d a = g.points.row(pairs[l].first).transpose(),
                            b = g.points.row(pairs[l].second).transpose();
      // Both points are inside, so the link is inside unless its segment crosses the surface.
      // (Requiring also that every sample on it see only backs of faces in all 64 directions
      // failed at any 0.3% noise fold in view: a noisy kitten lost the link that closes its
      // tail's loop in 5 of 10 draws.) The field is sampled only along links that stay inside.
      g.costs[l] =
          w.query.segment_blocked(a, b) ? kInf : w.field.mean_magnitude(a, b, cost_samples);
    }
  });
}

void bridge_outside_links(GraphWork& w, int cost_samples) {
  DomainGraph& g = w.g;
  const int P = w.point_count();
  const std::vector<char> owns = face_owners(g);
  UnionFind uf(P);
  inside_parts(w, uf);
  std::vector<std::vector<int>> neighbours(P);
  for (int l = 0; l < g.candidates.rows(); ++l) {
    neighbours[g.candidates(l, 0)].push_back(g.candidates(l, 1));
    neighbours[g.candidates(l, 1)].push_back(g.candidates(l, 0));
  }
  // (distance, from, to): each link that leaves the shape between two parts, from either of its
  // points to a neighbour of the other in the other's part (one step along the other side).
  std::vector<std::tuple<double, int, int>> tries;
  for (int l = 0; l < g.candidates.rows(); ++l) {
    const int a = g.candidates(l, 0), b = g.candidates(l, 1);
    if (std::isfinite(g.costs[l]) || uf.find(a) == uf.find(b)) continue;
    for (const auto& [from, via] : {std::pair{a, b}, std::pair{b, a}}) {
      for (int n : neighbours[via]) {
        if (owns[n] && uf.find(n) == uf.find(via))
          tries.emplace_back((g.points.row(from) - g.points.row(n)).norm(), from, n);
      }
    }
  }
  std::sort(tries.begin(), tries.end());
  std::vector<std::pair<int, int>> bridges;
  for (const auto& [distance, p, q] : tries) {
    if (uf.find(p) == uf.find(q) ||
        w.query.segment_blocked(g.points.row(p).transpose(), g.points.row(q).transpose()))
      continue;
    uf.unite(p, q);
    bridges.emplace_back(std::min(p, q), std::max(p, q));
  }
  const Eigen::Index L = g.candidates.rows(), B = static_cast<Eigen::Index>(bridges.size());
  g.candidates.conservativeResize(L + B, 2);
  g.costs.conservativeResize(L + B);
  g.candidate_state.conservativeResize(L + B);
  for (Eigen::Index k = 0; k < B; ++k) {
    const auto [p, q] = bridges[k];
    g.candidates.row(L + k) << p, q;
    g.costs[L + k] = w.field.mean_magnitude(g.points.row(p).transpose(),
                                            g.points.row(q).transpose(), cost_samples);
    g.candidate_state[L + k] = 0;
  }
  g.links_bridged += static_cast<int>(B);
}

void spanning_tree(GraphWork& w) {
  DomainGraph& g = w.g;
  const int P = w.point_count(), L = static_cast<int>(g.candidates.rows());
  w.has_face = face_owners(g);
  for (int p = 0; p < P; ++p) w.graph.set_alive(p, w.has_face[p] != 0);
  w.tree_order.resize(L);
  std::iota(w.tree_order.begin(), w.tree_order.end(), 0);
  auto touches_end = [&](int l) {
    return w.is_end(g.candidates(l, 0)) || w.is_end(g.candidates(l, 1));
  };
  std::stable_sort(w.tree_order.begin(), w.tree_order.end(), [&](int x, int y) {
    if (touches_end(x) != touches_end(y)) return !touches_end(x);
    return g.costs[x] < g.costs[y];
  });
  UnionFind uf(P);
  w.tree.assign(P, {});
  for (int l : w.tree_order) {
    const int a = g.candidates(l, 0), b = g.candidates(l, 1);
    if (uf.unite(a, b)) {
      g.candidate_state[l] = 1;
      w.tree[a].push_back({b, l});
      w.tree[b].push_back({a, l});
      w.graph.link(a, b);
    }
  }
}

void keep_handle_cycles(GraphWork& w, int genus) {
  DomainGraph& g = w.g;
  if (genus <= 0) return;
  const TreePaths paths(w);
  // A link that leaves the shape by at most kGraze of its points' smaller radius.
  const auto grazes = [&](int l) {
    const int a = g.candidates(l, 0), b = g.candidates(l, 1);
    return outside_length(w.query, g.points.row(a).transpose(), g.points.row(b).transpose()) <=
           kGraze * std::min(g.radii[a], g.radii[b]);
  };
  std::vector<int> non_tree;  // the finite links by cost, then those that graze (infinite cost)
  for (int l : w.tree_order) {
    if (g.candidate_state[l] == 0 && (std::isfinite(g.costs[l]) || grazes(l)))
      non_tree.push_back(l);
  }
  std::stable_sort(non_tree.begin(), non_tree.end(),
                   [&](int x, int y) { return g.costs[x] < g.costs[y]; });
  for (int l : non_tree) {
    if (static_cast<int>(w.kept_cycles.size()) >= genus) break;
    std::vector<int> pts, links;
    paths.cycle(g.candidates, l, pts, links);
    // The fan (one segment per point) before the pairs (one per pair of points).
    if (spans_inner_disk(w.query, g.points, pts) ||
        see_each_other_across_cracks(w.query, g.points, g.radii, pts)) {
      ++g.cycles_rejected_visible;
      continue;
    }
    if (duplicates_kept_cycle(w, links)) {
      ++g.cycles_rejected_duplicate;
      continue;
    }
    w.kept_cycles.push_back(links);
    g.candidate_state[l] = 2;
    w.graph.link(g.candidates(l, 0), g.candidates(l, 1));
  }
}

void prune(GraphWork& w) {
  int live_ends = 0;
  for (int p = 0; p < w.point_count(); ++p) live_ends += w.graph.alive[p] && w.is_end(p);
  if (live_ends <= 1 && w.kept_cycles.empty()) {
    keep_longest_path(w, live_ends);
  } else {
    prune_leaves(w);
  }
}

void contract_short_links(GraphWork& w) {
  Graph& graph = w.graph;
  for (bool changed = true; changed;) {
    changed = false;
    for (const auto& [ratio, a0, b0] : short_links(w)) {
      (void)ratio;
      int a = a0, b = b0;
      if (!graph.alive[a] || !graph.alive[b] || !graph.adj[a].count(b)) continue;
      if (graph.count_alive() <= 2) break;
      if (share_a_neighbour(graph, a, b)) continue;  // contracting would fold a cycle
      if (w.is_end(a) && w.is_end(b)) continue;
      if (w.is_end(b) && !w.is_end(a)) std::swap(a, b);
      if (w.is_end(a)) {
        // A tip absorbs the chain node next to it. An end inside a cycle or a chain stays, and
        // so does one next to a junction (absorb_bumps decides with the tube test).
        if (graph.degree(a) != 1 || graph.degree(b) != 2) continue;
        graph.merge(a, b);
      } else {
        if (w.g.radii[b] > w.g.radii[a]) std::swap(a, b);
        graph.merge(a, b);
      }
      ++w.g.contracted;
      changed = true;
    }
  }
}

void absorb_bumps(GraphWork& w) {
  Graph& graph = w.graph;
  for (int e = 0; e < w.point_count(); ++e) {
    if (!graph.alive[e] || !w.is_end(e) || graph.degree(e) != 1) continue;
    const int v = *graph.adj[e].begin();
    if (graph.degree(v) < 3 || graph.count_alive() <= 2) continue;
    if (is_bump(w, e, v)) {
      graph.merge(v, e);
      ++w.g.ends_absorbed;
    }
  }
}

void merge_joints(GraphWork& w) {
  std::vector<std::vector<int>> members(w.point_count());
  for (int p = 0; p < w.point_count(); ++p) members[p] = {p};
  while (merge_one_joint_pair(w, members)) {
  }
}

void add_spine(GraphWork& w) {
  // A sphere: every domain point reaches its center. Two points on its principal axis, half way
  // from the center to the surface on either side, give it a bone.
  Graph& graph = w.graph;
  DomainGraph& g = w.g;
  if (graph.count_alive() != 1) return;
  int c = 0;
  while (!graph.alive[c]) ++c;
  const Eigen::RowVector3d mean = w.mesh.V.colwise().mean();
  const Eigen::MatrixXd centered = w.mesh.V.rowwise() - mean;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> pca(centered.transpose() * centered);
  const Eigen::Vector3d axis = pca.eigenvectors().col(2);
  const Eigen::Vector3d pc = g.points.row(c).transpose();
  std::vector<Eigen::Vector3d> spine;
  for (double side : {1.0, -1.0}) {
    const double wall = w.query.ray_hit(pc, side * axis);
    if (!std::isfinite(wall) || wall <= 0) continue;
    const Eigen::Vector3d q = pc + 0.5 * wall * side * axis;
    if (w.query.inside(q)) spine.push_back(q);
  }
  for (const Eigen::Vector3d& q : spine) {
    const int index = static_cast<int>(g.points.rows());
    g.points.conservativeResize(index + 1, 3);
    g.points.row(index) = q.transpose();
    g.radii.conservativeResize(index + 1);
    g.radii[index] = w.query.distance(q);
    g.prong.conservativeResize(index + 1);
    g.prong[index] = -1;
    w.has_face.push_back(0);
    graph.adj.emplace_back();
    graph.alive.push_back(0);
    graph.set_alive(index, true);
    graph.absorbed_by.push_back(-1);
    graph.link(c, index);
  }
}

void classify(GraphWork& w) {
  DomainGraph& g = w.g;
  const Graph& graph = w.graph;
  const int P = w.point_count();
  g.node_of_point = Eigen::VectorXi::Constant(P, -1);
  for (int p = 0; p < P; ++p) {
    if (graph.alive[p]) {
      g.node_of_point[p] = static_cast<int>(g.nodes.size());
      g.nodes.push_back(p);
    }
  }
  for (int p = 0; p < P; ++p) {
    if (graph.alive[p] || !w.has_face[p]) continue;
    int q = p;
    for (int guard = 0; guard <= P && !graph.alive[q] && graph.absorbed_by[q] >= 0; ++guard) {
      q = graph.absorbed_by[q];
    }
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
  for (int i = 0; i < N; ++i) g.kinds[i] = node_kind_of_degree(static_cast<std::size_t>(degree[i]));
  for (int i = 0; i < N; ++i) g.components += comp.find(i) == i;
  g.cycles = static_cast<int>(links.size()) - N + g.components;
  g.face_nodes.resize(g.face_labels.size());
  for (int f = 0; f < g.face_labels.size(); ++f) {
    g.face_nodes[f] = g.face_labels[f] >= 0 ? g.node_of_point[g.face_labels[f]] : -1;
  }
}

}  // namespace internal

DomainGraph compute_domain_graph(const Mesh& mesh, const ForceField& field, const Points& points,
                                 const Eigen::VectorXd& radii, const Eigen::VectorXi& prong,
                                 int genus, const DomainGraphOptions& options,
                                 const Progress& progress, double from, double to) {
  const Eigen::Index P = points.rows();
  if (radii.size() != P || prong.size() != P) {
    throw InputError("domain graph: points, radii and prong differ in length");
  }
  if (mesh.F.rows() == 0) throw InputError("domain graph: the mesh has no faces");
  if (P == 0) throw InputError("the shape has no interior: no point to build a graph from");
  using namespace internal;
  ThrottledProgress tick(progress, "domain_graph", from, to);
  GraphWork w(mesh, field, points, radii, prong);
  auto pass = [&](double a, double b) {
    w.poll = tick.part(a, b);
    w.at(0);
  };
  pass(0, 0.6);
  label_faces(w, options.visibility_candidates);
  pass(0.6, 0.9);
  link_candidates(w, options.cost_samples);
  bridge_outside_links(w, options.cost_samples);
  pass(0.9, 1);  // the graph passes: no loop long enough to need a poll inside
  spanning_tree(w);
  keep_handle_cycles(w, genus);
  if (options.prune) prune(w);
  if (options.contract) {
    contract_short_links(w);
    absorb_bumps(w);
  }
  if (options.merge_joints) merge_joints(w);
  add_spine(w);
  classify(w);
  return std::move(w.g);
}

}  // namespace dcg

// The interim graph (dcg/interim_graph.h): the fallback skeleton of the domain points.
#include "dcg/interim_graph.h"

#include <algorithm>
#include <limits>
#include <utility>
#include <vector>

#include "dcg/errors.h"

namespace dcg {
namespace {

// Minimum spanning tree of the complete Euclidean graph on `points` (Prim, O(k^2) time, O(k)
// memory). Fine for the few thousand domain points of stage 2.
std::vector<std::vector<int>> euclidean_mst(const Points& points) {
  const int k = static_cast<int>(points.rows());
  std::vector<std::vector<int>> adjacency(k);
  if (k == 0) return adjacency;
  std::vector<double> best(k, std::numeric_limits<double>::infinity());
  std::vector<int> parent(k, -1);
  std::vector<char> done(k, 0);
  best[0] = 0;
  for (int iter = 0; iter < k; ++iter) {
    int u = -1;
    for (int i = 0; i < k; ++i) {
      if (!done[i] && (u < 0 || best[i] < best[u])) u = i;
    }
    done[u] = 1;
    if (parent[u] >= 0) {
      adjacency[u].push_back(parent[u]);
      adjacency[parent[u]].push_back(u);
    }
    for (int i = 0; i < k; ++i) {
      if (done[i]) continue;
      const double d = (points.row(i) - points.row(u)).squaredNorm();
      if (d < best[i]) {
        best[i] = d;
        parent[i] = u;
      }
    }
  }
  return adjacency;
}

void remove_edge(std::vector<std::vector<int>>& adjacency, int a, int b) {
  auto& la = adjacency[a];
  la.erase(std::remove(la.begin(), la.end(), b), la.end());
  auto& lb = adjacency[b];
  lb.erase(std::remove(lb.begin(), lb.end(), a), lb.end());
}

// Removes leaf branches (leaf .. first junction) shorter than twice the junction's radius: they
// stand for surface bumps, not limbs. Repeats until nothing changes.
void prune_twigs(const Points& points, const Eigen::VectorXd& radii,
                 std::vector<std::vector<int>>& adjacency) {
  const int k = static_cast<int>(points.rows());
  for (bool changed = true; changed;) {
    changed = false;
    for (int leaf = 0; leaf < k; ++leaf) {
      if (adjacency[leaf].size() != 1) continue;
      std::vector<int> branch = {leaf};
      double length = 0;
      int prev = leaf, cur = adjacency[leaf][0];
      while (adjacency[cur].size() == 2) {
        length += (points.row(cur) - points.row(prev)).norm();
        branch.push_back(cur);
        const int next = adjacency[cur][0] == prev ? adjacency[cur][1] : adjacency[cur][0];
        prev = cur;
        cur = next;
      }
      if (adjacency[cur].size() < 3) continue;  // the whole tree is one path: keep it
      length += (points.row(cur) - points.row(prev)).norm();
      if (length >= 2.0 * radii[cur]) continue;
      remove_edge(adjacency, prev, cur);
      for (size_t i = 0; i + 1 < branch.size(); ++i)
        remove_edge(adjacency, branch[i], branch[i + 1]);
      changed = true;
    }
  }
}

}  // namespace

Skeleton build_interim_graph(const Balls& domain) {
  const Points& points = domain.centers;
  const int k = static_cast<int>(points.rows());
  Skeleton s;
  s.method = "interim_graph";
  if (k == 0) throw InputError("the shape has no interior: no domain ball was found");
  auto adjacency = euclidean_mst(points);
  prune_twigs(points, domain.radii, adjacency);

  // The largest ball always survives pruning (a junction's radius never shrinks its own branch),
  // so the component that holds it is the tree.
  int start = 0;
  for (int i = 1; i < k; ++i) {
    if (domain.radii[i] > domain.radii[start]) start = i;
  }
  std::vector<int> node_of(k, -1);
  std::vector<int> keys;
  {
    std::vector<char> seen(k, 0);
    std::vector<int> stack = {start};
    seen[start] = 1;
    while (!stack.empty()) {
      const int u = stack.back();
      stack.pop_back();
      if (adjacency[u].size() != 2) {
        node_of[u] = static_cast<int>(keys.size());
        keys.push_back(u);
      }
      for (int v : adjacency[u]) {
        if (!seen[v]) {
          seen[v] = 1;
          stack.push_back(v);
        }
      }
    }
  }
  if (keys.empty()) {  // a closed chain cannot come out of a tree; keep the largest ball alone
    node_of[start] = 0;
    keys.push_back(start);
  }

  const int n = static_cast<int>(keys.size());
  s.positions.resize(n, 3);
  s.radii.resize(n);
  s.significance = Eigen::VectorXd::Zero(n);
  s.kinds.resize(n);
  for (int i = 0; i < n; ++i) {
    const int u = keys[i];
    s.positions.row(i) = points.row(u);
    s.radii[i] = domain.radii[u];
    s.kinds[i] = node_kind_of_degree(adjacency[u].size());
  }
  // Walk every chain once, from each key node along each of its edges to the next key node.
  std::vector<std::pair<int, int>> links;
  for (int i = 0; i < n; ++i) {
    const int a = keys[i];
    for (int first : adjacency[a]) {
      std::vector<int> chain = {a};
      int prev = a, cur = first;
      while (node_of[cur] < 0) {
        chain.push_back(cur);
        const int next = adjacency[cur][0] == prev ? adjacency[cur][1] : adjacency[cur][0];
        prev = cur;
        cur = next;
      }
      chain.push_back(cur);
      if (node_of[cur] < i) continue;  // the same chain was walked from its other end
      links.emplace_back(i, node_of[cur]);
      Points polyline(static_cast<Eigen::Index>(chain.size()), 3);
      for (size_t j = 0; j < chain.size(); ++j) polyline.row(j) = points.row(chain[j]);
      s.polylines.push_back(std::move(polyline));
    }
  }
  s.links.resize(static_cast<Eigen::Index>(links.size()), 2);
  for (size_t l = 0; l < links.size(); ++l) s.links.row(l) << links[l].first, links[l].second;

  choose_root(s);
  return s;
}

void mark_prong_ends(const Prongs& prongs, Skeleton& s) {
  const int n = static_cast<int>(s.positions.rows());
  std::vector<char> taken(n, 0);
  for (int i = 0; i < n; ++i)
    if (s.kinds[i] == NodeKind::End) s.significance[i] = 1.0;
  for (Eigen::Index p = 0; p < prongs.vertices.size(); ++p) {
    int best = -1;
    double best_d2 = std::numeric_limits<double>::infinity();
    for (int i = 0; i < n; ++i) {
      if (s.kinds[i] != NodeKind::End || taken[i]) continue;
      const double d2 = (s.positions.row(i) - prongs.positions.row(p)).squaredNorm();
      if (d2 < best_d2) {
        best_d2 = d2;
        best = i;
      }
    }
    if (best < 0) break;
    taken[best] = 1;
    s.significance[best] = prongs.significance[p];
  }
}

}  // namespace dcg

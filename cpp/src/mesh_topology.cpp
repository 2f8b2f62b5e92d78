// Mesh connectivity for stage 0: see mesh_topology.h. Everything here goes by index, in one
// sorted pass over the edges (EdgeTable), so that it stays O(n log n) on millions of faces.
#include "mesh_topology.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <tuple>
#include <unordered_map>

#include "compact_mesh.h"
#include "dcg/errors.h"
#include "dcg/prepare.h"
#include "edge_table.h"
#include "union_find.h"

namespace dcg {
namespace internal {
namespace {

// The two vertices of the edge with key `key` (see edge_key), the smaller first.
std::pair<int, int> edge_ends(std::uint64_t key) {
  return {static_cast<int>(key >> 32), static_cast<int>(key & 0xffffffffu)};
}

// The edge counts, manifold neighbours and components of `t`; the border edges into `border`.
void scan_edges(const Faces& F, const std::function<void()>& poll, Topology& t,
                std::vector<std::pair<int, int>>& border) {
  const int nf = static_cast<int>(F.rows());
  const EdgeTable table(F, poll);
  std::size_t polled = 0;
  UnionFind faces_uf(nf);
  t.neighbours.assign(nf, {-1, -1, -1});
  table.for_each_edge([&](std::size_t b, std::size_t e) {
    if (poll && (++polled & 16383) == 0) poll();
    ++t.edges;
    for (std::size_t i = b + 1; i < e; ++i) {
      faces_uf.unite(EdgeTable::face(table.half[b].second), EdgeTable::face(table.half[i].second));
    }
    if (e - b == 1) {
      ++t.border_edges;
      border.push_back(edge_ends(table.half[b].first));
    } else if (e - b > 2) {
      ++t.non_manifold_edges;
    } else {
      const int cf = table.half[b].second, cg = table.half[b + 1].second;
      t.neighbours[EdgeTable::face(cf)][cf % 3] = EdgeTable::face(cg);
      t.neighbours[EdgeTable::face(cg)][cg % 3] = EdgeTable::face(cf);
    }
  });
  t.component.assign(nf, -1);
  for (int f = 0; f < nf; ++f) {
    const int r = faces_uf.find(f);
    if (t.component[r] < 0) t.component[r] = t.components++;
    t.component[f] = t.component[r];
  }
}

// Vertices whose faces, connected through the edges at the vertex, form more than one fan.
int count_non_manifold_vertices(int nv, const Faces& F, const std::function<void()>& poll) {
  const int nf = static_cast<int>(F.rows());
  // The faces around each vertex: ring[start[v] .. start[v + 1]).
  std::vector<int> start(nv + 1, 0);
  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) ++start[F(f, k) + 1];
  for (int v = 0; v < nv; ++v) start[v + 1] += start[v];
  std::vector<int> ring(start[nv]);
  std::vector<int> fill(start.begin(), start.end() - 1);
  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) ring[fill[F(f, k)]++] = f;
  int pinched = 0;
  std::vector<std::pair<int, int>> corner_edges;  // (other vertex, face)
  for (int v = 0; v < nv; ++v) {
    if (poll && (v & 8191) == 0) poll();
    const int n = start[v + 1] - start[v];
    if (n == 0) continue;
    corner_edges.clear();
    for (int i = start[v]; i < start[v + 1]; ++i) {
      const int f = ring[i];
      for (int k = 0; k < 3; ++k) {
        if (F(f, k) != v) corner_edges.emplace_back(F(f, k), i - start[v]);
      }
    }
    std::sort(corner_edges.begin(), corner_edges.end());
    UnionFind uf(n);
    int groups = n;
    for (std::size_t i = 1; i < corner_edges.size(); ++i) {
      if (corner_edges[i].first == corner_edges[i - 1].first &&
          uf.unite(corner_edges[i].second, corner_edges[i - 1].second)) {
        --groups;
      }
    }
    if (groups > 1) ++pinched;
  }
  return pinched;
}

// Breadth-first search over the manifold neighbours, flipping each newly reached face that runs
// the shared edge the same way as the face it was reached from. False when a face already
// reached runs it the same way (the surface cannot be oriented).
bool orient_consistently(Faces& F, const std::vector<std::array<int, 3>>& neighbours,
                         const std::function<void()>& poll) {
  const int nf = static_cast<int>(F.rows());
  bool orientable = true;
  std::size_t polled = 0;
  std::vector<char> seen(nf, 0);
  std::vector<int> queue;
  auto has_directed = [&](int g, int a, int b) {
    for (int k = 0; k < 3; ++k)
      if (F(g, k) == a && F(g, (k + 1) % 3) == b) return true;
    return false;
  };
  for (int s = 0; s < nf; ++s) {
    if (seen[s]) continue;
    seen[s] = 1;
    queue.assign(1, s);
    for (std::size_t qi = 0; qi < queue.size(); ++qi) {
      if (poll && (++polled & 16383) == 0) poll();
      const int f = queue[qi];
      for (int slot = 0; slot < 3; ++slot) {
        const int g = neighbours[f][slot];
        if (g < 0) continue;
        // The shared edge, as f runs it now (orientations change as faces get flipped).
        int a = -1, b = -1;
        for (int k = 0; k < 3 && a < 0; ++k) {
          const int u = F(f, k), w = F(f, (k + 1) % 3);
          const bool gu = F(g, 0) == u || F(g, 1) == u || F(g, 2) == u;
          const bool gw = F(g, 0) == w || F(g, 1) == w || F(g, 2) == w;
          if (gu && gw) {
            a = u;
            b = w;
          }
        }
        if (a < 0) continue;
        const bool same = has_directed(g, a, b);  // g runs the edge the same way: flip g
        if (!seen[g]) {
          if (same) std::swap(F(g, 1), F(g, 2));
          seen[g] = 1;
          queue.push_back(g);
        } else if (same) {
          orientable = false;
        }
      }
    }
  }
  return orientable;
}

// Six times the signed volume enclosed by each component of (V, F) (divergence theorem: positive
// when it faces outward).
std::vector<double> six_volumes(const Vertices& V, const Faces& F, const Topology& topology) {
  std::vector<double> volume(topology.components, 0.0);
  for (int f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    volume[topology.component[f]] += a.dot(b.cross(c));
  }
  return volume;
}

}  // namespace

std::pair<int, double> border_loops(const Vertices& V,
                                    const std::vector<std::pair<int, int>>& border_edges) {
  if (border_edges.empty()) return {0, 0.0};
  // Union-find over the border vertices only (local indices), then one bounding box per loop.
  std::unordered_map<int, int> local;
  for (auto& [a, b] : border_edges) {
    local.emplace(a, static_cast<int>(local.size()));
    local.emplace(b, static_cast<int>(local.size()));
  }
  UnionFind uf(static_cast<int>(local.size()));
  for (auto& [a, b] : border_edges) uf.unite(local[a], local[b]);
  std::unordered_map<int, std::pair<Eigen::RowVector3d, Eigen::RowVector3d>> box;
  for (auto& [v, i] : local) {
    const int r = uf.find(i);
    auto it = box.find(r);
    if (it == box.end()) {
      box.emplace(r, std::make_pair(Eigen::RowVector3d(V.row(v)), Eigen::RowVector3d(V.row(v))));
    } else {
      it->second.first = it->second.first.cwiseMin(V.row(v));
      it->second.second = it->second.second.cwiseMax(V.row(v));
    }
  }
  double largest = 0;
  for (auto& [r, b] : box) largest = std::max(largest, (b.second - b.first).norm());
  return {static_cast<int>(box.size()), largest};
}

Topology analyze_topology(const Vertices& V, const Faces& F, const std::function<void()>& poll) {
  Topology t;
  std::vector<std::pair<int, int>> border;
  scan_edges(F, poll, t, border);
  std::tie(t.border_loops, t.largest_hole) = border_loops(V, border);
  t.non_manifold_vertices = count_non_manifold_vertices(static_cast<int>(V.rows()), F, poll);
  return t;
}

Orientation orient_outward(const Vertices& V, Faces& F, const Topology& topology,
                           const std::function<void()>& poll) {
  Orientation o;
  o.orientable = orient_consistently(F, topology.neighbours, poll);
  // Outward: positive signed volume per component.
  const std::vector<double> volume = six_volumes(V, F, topology);
  for (int f = 0; f < F.rows(); ++f) {
    if (volume[topology.component[f]] < 0) std::swap(F(f, 1), F(f, 2));
  }
  for (double v : volume) o.enclosed_volume += std::abs(v) / 6.0;
  return o;
}

int drop_cavities(Mesh& mesh) {
  const Topology topology = analyze_topology(mesh.V, mesh.F);
  const std::vector<double> volume = six_volumes(mesh.V, mesh.F, topology);
  const auto cavities = std::count_if(volume.begin(), volume.end(), [](double v) { return v < 0; });
  if (cavities == 0 || cavities == static_cast<long>(volume.size())) return 0;
  std::vector<std::array<int, 3>> kept;
  for (int f = 0; f < mesh.F.rows(); ++f) {
    if (volume[topology.component[f]] >= 0)
      kept.push_back({mesh.F(f, 0), mesh.F(f, 1), mesh.F(f, 2)});
  }
  mesh = compact_mesh(mesh.V, kept);
  return static_cast<int>(cavities);
}

int folded_edges(const Mesh& mesh) {
  const Eigen::Index nf = mesh.F.rows();
  Eigen::MatrixX3d normal(nf, 3);
  for (Eigen::Index f = 0; f < nf; ++f) {
    const Eigen::RowVector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)),
                             c = mesh.V.row(mesh.F(f, 2));
    const Eigen::RowVector3d n = (b - a).cross(c - a);
    normal.row(f) = n.norm() > 0 ? (n / n.norm()).eval() : Eigen::RowVector3d::Zero();
  }
  const EdgeTable table(mesh.F);
  int folds = 0;
  table.for_each_edge([&](std::size_t i, std::size_t j) {
    if (j - i != 2) return;
    const double dot = normal.row(EdgeTable::face(table.half[i].second))
                           .dot(normal.row(EdgeTable::face(table.half[i + 1].second)));
    folds += dot < -1.0 + 1e-8;
  });
  return folds;
}

Eigen::Vector3d face_barycentric(const Mesh& mesh, int f, const Eigen::Vector3d& q) {
  const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)),
                        c = mesh.V.row(mesh.F(f, 2));
  const Eigen::Vector3d n = (b - a).cross(c - a);
  const double n2 = n.squaredNorm();
  Eigen::Vector3d l(1.0 / 3, 1.0 / 3, 1.0 / 3);
  if (n2 > 0) {
    l[0] = (c - b).cross(q - b).dot(n) / n2;
    l[1] = (a - c).cross(q - c).dot(n) / n2;
    l[0] = std::clamp(l[0], 0.0, 1.0);
    l[1] = std::clamp(l[1], 0.0, 1.0 - l[0]);
    l[2] = 1.0 - l[0] - l[1];
  }
  return l;
}

}  // namespace internal

int mesh_genus(const Mesh& mesh) {
  const auto& F = mesh.F;
  const int nv = static_cast<int>(mesh.V.rows());
  if (F.rows() == 0) return 0;
  std::vector<char> used(nv, 0);
  internal::UnionFind uf(nv);
  for (int f = 0; f < F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int a = F(f, k), b = F(f, (k + 1) % 3);
      if (a < 0 || a >= nv || b < 0 || b >= nv) throw InputError("mesh_genus: index out of range");
      used[a] = 1;
      uf.unite(a, b);
    }
  }
  long n_edges = 0;
  std::vector<std::pair<int, int>> border;
  const internal::EdgeTable table(F);
  table.for_each_edge([&](std::size_t i, std::size_t j) {
    ++n_edges;
    if (j - i == 1) border.push_back(internal::edge_ends(table.half[i].first));
  });
  long n_vertices = 0, n_components = 0;
  for (int v = 0; v < nv; ++v) {
    if (!used[v]) continue;
    ++n_vertices;
    if (uf.find(v) == v) ++n_components;
  }
  // Border edges (one face) close up as loops: chi + loops = 2C - 2g.
  const long n_loops = internal::border_loops(mesh.V, border).first;
  const long chi = n_vertices - n_edges + static_cast<long>(F.rows());
  const long twice_g = 2 * n_components - chi - n_loops;
  return static_cast<int>(std::max(0L, twice_g / 2));
}

}  // namespace dcg

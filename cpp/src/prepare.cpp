// Stage 0: validate, weld, clean, orient, check, repair, remesh, normalize, map back.
// See dcg/prepare.h and ALGORITHM.md "0. Prepare". CGAL only enters through repair.h and
// remesh.h (their own translation units), so this file compiles fast.
//
// Choices made here (the docs leave them open):
// - Normalization: offset = bounding-box center, scale = bounding-box diagonal, so the working
//   mesh is centered at the origin with diagonal 1 (input = working * scale + offset).
// - Welding closes cracks: only vertices on border edges of the input (edges with one face, by
//   index) are welded, each into an earlier border vertex within weld_tolerance (normalized;
//   uniform grid of that cell size, 27 neighbouring cells). Vertices inside the surface are never
//   welded: two distinct vertices that happen to coincide on a closed mesh (cow.off, dino.off)
//   would otherwise pinch it into a non-manifold one and force a needless repair. A triangle
//   soup (STL) has only border edges, so all of it is welded. Unreferenced vertices are dropped
//   from the working mesh (they still get a map entry).
// - Flat input (every vertex within 1e-9 of one plane, normalized) encloses nothing: InputError.
// - Degenerate faces: a repeated index after welding, or zero area (twice the area below
//   1e-16 in normalized units, i.e. round-off). Duplicate faces: the same three vertices in any
//   order (a second, reversed copy of a face is a zero-volume double wall).
// - "Needs repair" = border edges, non-manifold edges or vertices, a non-orientable surface, or
//   more than one component. Several closed shells are wrapped too: ALGORITHM.md counts
//   "several parts" as a problem (an eye ball inside a head, overlapping limbs); the wrap turns
//   overlapping parts into one surface (their union), and disjoint parts stay separate shells.
// - Wrap size: alpha = 1/100 of the diagonal (keeps fingers and thin limbs apart), raised to
//   0.6 x the diagonal of the largest hole (border loop) so the wrapping ball cannot enter the
//   hole and wrap both sides of an open sheet (a hollow shell has a useless medial axis), capped
//   at 1/10 of the diagonal. offset = alpha / 30 (CGAL's example ratio: 1/20 and 1/600).
// - Remeshing: skipped when the mesh already has between 1/2.5 and 2.5 times target_faces and
//   its edge lengths are uniform (coefficient of variation below 0.5): such a mesh is as good a
//   geodesic domain as a remeshed one, and remeshing costs more than all of stages 1-3.
// - Huge inputs (more than max(8 x target_faces, 150,000) faces) are first reduced to
//   4 x target_faces by fast_reduce() below, an O(n log n) pass-wise edge collapse without a
//   priority queue: CGAL's quality edge collapse in remesh_uniform() costs about 30 us per
//   collapse (23 s of the 35 s on a 1.4M-face mesh) and then only does the last factor of 4.
//   Meshes under 150,000 faces (every public test mesh) never take this path.
// - Cancellation: stage 0 polls the progress callback at most every 10 ms (between steps, in
//   the loops over the input, and from inside CGAL's wrap, collapse and remeshing), so that a
//   cancel request stops it quickly even on millions of faces.
#include "dcg/prepare.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <numeric>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include <Eigen/Eigenvalues>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "dcg/errors.h"
#include "dcg/surface_query.h"
#include "edge_table.h"
#include "polling.h"
#include "remesh.h"
#include "repair.h"
#include "union_find.h"

namespace dcg {
namespace {

using internal::edge_key;
using internal::EdgeTable;
using internal::UnionFind;

struct CellHash {
  std::size_t operator()(const std::array<std::int64_t, 3>& c) const {
    return static_cast<std::size_t>(c[0] * 73856093LL ^ c[1] * 19349663LL ^ c[2] * 83492791LL);
  }
};

// Edges of a closed, consistently oriented mesh whose two faces fold flat onto each other:
// their unit normals opposite to within 1e-8 (a dihedral angle of about 1e-4 rad or less).
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

struct Topology {
  int edges = 0;
  int border_edges = 0;
  int non_manifold_edges = 0;
  int non_manifold_vertices = 0;
  int components = 0;
  int border_loops = 0;
  bool orientable = true;
  double largest_hole = 0;  // bbox diagonal of the largest border loop
  double enclosed_volume = 0;  // sum over components of |signed volume| (only when orienting)
};

// Counts edges, borders, non-manifold edges / vertices and components of (V, F); when `orient`
// is true, also makes the faces' orientation consistent per component and outward (positive
// signed volume). `poll` is called every few thousand faces or vertices.
Topology analyze(const Vertices& V, Faces& F, bool orient, const std::function<void()>& poll) {
  Topology t;
  const int nf = static_cast<int>(F.rows()), nv = static_cast<int>(V.rows());
  EdgeTable table(F, poll);
  std::size_t polled = 0;
  UnionFind faces_uf(nf);
  // Manifold adjacency: face -> up to 3 neighbours over edges with exactly 2 faces.
  std::vector<std::array<int, 3>> adj(nf, {-1, -1, -1});
  std::vector<std::pair<int, int>> border;  // border edges (vertex pairs)
  table.for_each_edge([&](std::size_t b, std::size_t e) {
    if ((++polled & 16383) == 0) poll();
    ++t.edges;
    const std::size_t n = e - b;
    for (std::size_t i = b + 1; i < e; ++i) {
      faces_uf.unite(EdgeTable::face(table.half[b].second), EdgeTable::face(table.half[i].second));
    }
    if (n == 1) {
      ++t.border_edges;
      const std::uint64_t key = table.half[b].first;
      border.emplace_back(static_cast<int>(key >> 32), static_cast<int>(key & 0xffffffffu));
    } else if (n > 2) {
      ++t.non_manifold_edges;
    } else {
      const int cf = table.half[b].second, cg = table.half[b + 1].second;
      adj[EdgeTable::face(cf)][cf % 3] = EdgeTable::face(cg);
      adj[EdgeTable::face(cg)][cg % 3] = EdgeTable::face(cf);
    }
  });
  std::vector<int> comp_of(nf, -1);
  for (int f = 0; f < nf; ++f) {
    const int r = faces_uf.find(f);
    if (comp_of[r] < 0) comp_of[r] = t.components++;
    comp_of[f] = comp_of[r];
  }
  // Border loops (connected sets of border edges) and their extents.
  if (!border.empty()) {
    std::unordered_map<int, int> local;
    for (auto& [a, b] : border) {
      local.emplace(a, static_cast<int>(local.size()));
      local.emplace(b, static_cast<int>(local.size()));
    }
    UnionFind uf(static_cast<int>(local.size()));
    for (auto& [a, b] : border) uf.unite(local[a], local[b]);
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
    t.border_loops = static_cast<int>(box.size());
    for (auto& [r, b] : box) t.largest_hole = std::max(t.largest_hole, (b.second - b.first).norm());
  }
  // Non-manifold vertices: the faces around a vertex, connected through edges at that vertex,
  // must form one fan.
  {
    std::vector<int> start(nv + 1, 0);
    for (int f = 0; f < nf; ++f)
      for (int k = 0; k < 3; ++k) ++start[F(f, k) + 1];
    for (int v = 0; v < nv; ++v) start[v + 1] += start[v];
    std::vector<int> ring(start[nv]);
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (int f = 0; f < nf; ++f)
      for (int k = 0; k < 3; ++k) ring[fill[F(f, k)]++] = f;
    std::vector<std::pair<int, int>> corner_edges;  // (other vertex, face)
    for (int v = 0; v < nv; ++v) {
      if ((v & 8191) == 0) poll();
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
      if (groups > 1) ++t.non_manifold_vertices;
    }
  }
  if (!orient) return t;
  // Consistent orientation by breadth-first search over manifold edges.
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
      if ((++polled & 16383) == 0) poll();
      const int f = queue[qi];
      for (int slot = 0; slot < 3; ++slot) {
        const int g = adj[f][slot];
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
          t.orientable = false;
        }
      }
    }
  }
  // Outward: positive signed volume per component.
  std::vector<double> volume(t.components, 0.0);
  for (int f = 0; f < nf; ++f) {
    const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    volume[comp_of[f]] += a.dot(b.cross(c));
  }
  for (int f = 0; f < nf; ++f) {
    if (volume[comp_of[f]] < 0) std::swap(F(f, 1), F(f, 2));
  }
  for (double v : volume) t.enclosed_volume += std::abs(v) / 6.0;
  return t;
}

// Edge-length coefficient of variation (std / mean) of (V, F).
double edge_length_variation(const Vertices& V, const Faces& F) {
  double sum = 0, sum2 = 0;
  const double n = 3.0 * static_cast<double>(F.rows());
  for (int f = 0; f < F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const double l = (V.row(F(f, k)) - V.row(F(f, (k + 1) % 3))).norm();
      sum += l;
      sum2 += l * l;
    }
  }
  if (n == 0 || sum == 0) return 0;
  const double mean = sum / n;
  return std::sqrt(std::max(0.0, sum2 / n - mean * mean)) / mean;
}

std::string problem_list(const Topology& t) {
  std::string s;
  auto add = [&](const std::string& part) { s += (s.empty() ? "" : ", ") + part; };
  if (t.border_edges) add(std::to_string(t.border_edges) + " border edges (holes, " +
                          std::to_string(t.border_loops) + " border loops)");
  if (t.non_manifold_edges) add(std::to_string(t.non_manifold_edges) + " non-manifold edges");
  if (t.non_manifold_vertices) add(std::to_string(t.non_manifold_vertices) + " non-manifold vertices");
  if (!t.orientable) add("a non-orientable surface");
  if (t.components > 1) add(std::to_string(t.components) + " components");
  return s;
}

// Fast first reduction of a huge closed manifold (oriented, one or more shells) to about
// `goal` faces. In passes: take the shorter half of the edges, shortest first, and collapse each
// to its midpoint unless
// - an end was moved earlier in the same pass (its edges' lengths are stale),
// - the link condition fails (the ends share a neighbour besides the two opposite vertices):
//   the collapse would pinch the surface, so the result stays a closed 2-manifold,
// - a face around it would turn by more than 60 degrees or become degenerate (no fold-overs).
// Each pass is O(n log n) with no priority queue (about 1 us per collapse against CGAL's 30);
// quality comes afterwards from CGAL's collapse and isotropic remeshing, which this only
// relieves of the bulk. Stops early when a pass collapses nothing.
Mesh fast_reduce(const Mesh& mesh, int goal, const std::function<void(double)>& poll) {
  const int nv = static_cast<int>(mesh.V.rows()), nf = static_cast<int>(mesh.F.rows());
  poll(0);
  std::vector<Eigen::Vector3d> P(nv);
  for (int i = 0; i < nv; ++i) P[i] = mesh.V.row(i).transpose();
  poll(0);
  std::vector<std::array<int, 3>> T(nf);
  std::vector<char> face_alive(nf, 1), vertex_alive(nv, 1), moved(nv, 0);
  std::vector<std::vector<int>> vf(nv);  // vertex -> its alive faces
  poll(0);
  {
    std::vector<int> degree(nv, 0);
    for (int f = 0; f < nf; ++f)
      for (int k = 0; k < 3; ++k) ++degree[mesh.F(f, k)];
    for (int v = 0; v < nv; ++v) {
      if ((v & 65535) == 0) poll(0);
      vf[v].reserve(degree[v] + 2);
    }
  }
  for (int f = 0; f < nf; ++f) {
    if ((f & 65535) == 0) poll(0);
    for (int k = 0; k < 3; ++k) {
      T[f][k] = mesh.F(f, k);
      vf[T[f][k]].push_back(f);
    }
  }
  std::vector<int> mark(nv, 0);  // neighbour stamps for the link condition
  int stamp = 0;
  int alive_faces = nf;
  const double cos_limit = 0.5;  // 60 degrees
  auto normal = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
    return Eigen::Vector3d((b - a).cross(c - a));
  };
  auto try_collapse = [&](int a, int b) -> bool {
    // The two faces on edge a-b and their opposite vertices.
    int shared = 0, opposite[2] = {-1, -1};
    for (int f : vf[a]) {
      const auto& t = T[f];
      if (t[0] != b && t[1] != b && t[2] != b) continue;
      if (shared == 2) return false;
      for (int k = 0; k < 3; ++k)
        if (t[k] != a && t[k] != b) opposite[shared] = t[k];
      ++shared;
    }
    if (shared != 2 || opposite[0] == opposite[1]) return false;
    // Link condition: the ends' only common neighbours are the two opposite vertices.
    ++stamp;
    for (int f : vf[a])
      for (int v : T[f])
        if (v != a) mark[v] = stamp;
    int common = 0;
    for (int f : vf[b]) {
      for (int v : T[f]) {
        if (v != b && mark[v] == stamp) {
          mark[v] = 0;  // count each common neighbour once
          ++common;
        }
      }
    }
    if (common != 2) return false;
    // No face turns by more than 60 degrees or degenerates.
    const Eigen::Vector3d m = 0.5 * (P[a] + P[b]);
    for (int end = 0; end < 2; ++end) {
      const int v = end == 0 ? a : b;
      for (int f : vf[v]) {
        const auto& t = T[f];
        if ((t[0] == a || t[1] == a || t[2] == a) && (t[0] == b || t[1] == b || t[2] == b)) continue;
        Eigen::Vector3d q[3] = {P[t[0]], P[t[1]], P[t[2]]};
        const Eigen::Vector3d n0 = normal(q[0], q[1], q[2]);
        for (int k = 0; k < 3; ++k)
          if (t[k] == v) q[k] = m;
        const Eigen::Vector3d n1 = normal(q[0], q[1], q[2]);
        const double l0 = n0.norm(), l1 = n1.norm();
        if (n0.dot(n1) <= cos_limit * l0 * l1) return false;
      }
    }
    // Collapse b into a at the midpoint.
    P[a] = m;
    for (int f : vf[b]) {
      auto& t = T[f];
      if (t[0] == a || t[1] == a || t[2] == a) {
        face_alive[f] = 0;
        --alive_faces;
        for (int v : t) {
          if (v == b) continue;
          auto& list = vf[v];
          list.erase(std::find(list.begin(), list.end(), f));
        }
      } else {
        for (int& v : t)
          if (v == b) v = a;
        vf[a].push_back(f);
      }
    }
    vf[b].clear();
    vertex_alive[b] = 0;
    moved[a] = 1;
    return true;
  };

  struct Candidate {
    float length2;
    int a, b;
    bool operator<(const Candidate& o) const {
      return length2 < o.length2 || (length2 == o.length2 && (a < o.a || (a == o.a && b < o.b)));
    }
  };
  std::vector<Candidate> candidates;
  auto fraction_done = [&] { return 1.0 - static_cast<double>(alive_faces - goal) / (nf - goal); };
  for (int pass = 0; alive_faces > goal && pass < 64; ++pass) {
    poll(fraction_done());
    candidates.clear();
    for (int f = 0; f < nf; ++f) {
      if ((f & 65535) == 0) poll(fraction_done());
      if (!face_alive[f]) continue;
      for (int k = 0; k < 3; ++k) {
        const int a = T[f][k], b = T[f][(k + 1) % 3];
        // Each edge once: its half-edge from the lower index (a closed, consistently oriented
        // surface has both).
        if (a < b) candidates.push_back({static_cast<float>((P[a] - P[b]).squaredNorm()), a, b});
      }
    }
    const double pass_start = fraction_done();
    poll(pass_start);
    // The shorter half, sorted: nth_element, then sorted in chunks between polls.
    const auto half = candidates.begin() + static_cast<std::ptrdiff_t>(candidates.size() / 2);
    std::nth_element(candidates.begin(), half, candidates.end());
    poll(pass_start);
    candidates.resize(candidates.size() / 2);
    internal::sort_polling(candidates, [&] { poll(pass_start); });
    std::fill(moved.begin(), moved.end(), 0);
    int collapsed = 0;
    for (auto it = candidates.begin(); it != candidates.end() && alive_faces > goal; ++it) {
      if (((it - candidates.begin()) & 4095) == 0) poll(fraction_done());
      if (!vertex_alive[it->a] || !vertex_alive[it->b] || moved[it->a] || moved[it->b]) continue;
      if (try_collapse(it->a, it->b)) ++collapsed;
    }
    if (collapsed == 0) break;
  }
  // Compact.
  Mesh out;
  std::vector<int> index(nv, -1);
  int n = 0;
  for (int f = 0; f < nf; ++f)
    if (face_alive[f])
      for (int v : T[f])
        if (index[v] < 0) index[v] = n++;
  out.V.resize(n, 3);
  for (int v = 0; v < nv; ++v)
    if (index[v] >= 0) out.V.row(index[v]) = P[v].transpose();
  out.F.resize(alive_faces, 3);
  int row = 0;
  for (int f = 0; f < nf; ++f) {
    if (!face_alive[f]) continue;
    for (int k = 0; k < 3; ++k) out.F(row, k) = index[T[f][k]];
    ++row;
  }
  return out;
}

}  // namespace

void validate_mesh(const Vertices& V, const Faces& F) {
  if (V.rows() < 4) {
    throw InputError("the mesh needs at least 4 vertices, got " + std::to_string(V.rows()));
  }
  if (F.rows() < 4) {
    throw InputError("the mesh needs at least 4 faces, got " + std::to_string(F.rows()));
  }
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    for (int k = 0; k < 3; ++k) {
      if (!std::isfinite(V(i, k))) {
        throw InputError("vertex " + std::to_string(i) + " has a non-finite coordinate (" +
                         std::to_string(V(i, k)) + ")");
      }
    }
  }
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      if (F(f, k) < 0 || F(f, k) >= V.rows()) {
        throw InputError("face " + std::to_string(f) + " has vertex index " +
                         std::to_string(F(f, k)) + " out of range [0, " +
                         std::to_string(V.rows()) + ")");
      }
    }
  }
}

int mesh_genus(const Mesh& mesh) {
  const auto& F = mesh.F;
  const int nv = static_cast<int>(mesh.V.rows());
  if (F.rows() == 0) return 0;
  std::vector<char> used(nv, 0);
  UnionFind uf(nv);
  std::vector<std::uint64_t> edges;
  edges.reserve(F.rows() * 3);
  for (int f = 0; f < F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int a = F(f, k), b = F(f, (k + 1) % 3);
      if (a < 0 || a >= nv || b < 0 || b >= nv) throw InputError("mesh_genus: index out of range");
      used[a] = 1;
      uf.unite(a, b);
      edges.push_back(edge_key(a, b));
    }
  }
  std::sort(edges.begin(), edges.end());
  // Border edges (one face) close up as loops: chi + loops = 2C - 2g.
  long n_edges = 0, n_border = 0;
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    ++n_edges;
    if (j - i == 1) ++n_border;
    i = j;
  }
  long n_vertices = 0, n_components = 0, n_loops = 0;
  for (int v = 0; v < nv; ++v) {
    if (!used[v]) continue;
    ++n_vertices;
    if (uf.find(v) == v) ++n_components;
  }
  if (n_border > 0) {
    // Count border loops over border edges only.
    UnionFind bl(nv);
    std::vector<char> on_border(nv, 0);
    for (std::size_t i = 0; i < edges.size();) {
      std::size_t j = i;
      while (j < edges.size() && edges[j] == edges[i]) ++j;
      if (j - i == 1) {
        const int a = static_cast<int>(edges[i] >> 32), b = static_cast<int>(edges[i] & 0xffffffffu);
        bl.unite(a, b);
        on_border[a] = on_border[b] = 1;
      }
      i = j;
    }
    for (int v = 0; v < nv; ++v)
      if (on_border[v] && bl.find(v) == v) ++n_loops;
  }
  const long chi = n_vertices - n_edges + static_cast<long>(F.rows());
  const long twice_g = 2 * n_components - chi - n_loops;
  return static_cast<int>(std::max(0L, twice_g / 2));
}

PreparedMesh prepare_mesh(const Vertices& V_in, const Faces& F_in, const PrepareOptions& options,
                          const Progress& progress, double from, double to) {
  internal::ThrottledProgress poll(progress, "prepare", from, to);
  poll(0);
  validate_mesh(V_in, F_in);
  if (!(options.weld_tolerance >= 0) || !std::isfinite(options.weld_tolerance)) {
    throw InputError("weld_tolerance must be finite and >= 0");
  }
  if (options.target_faces < 0) throw InputError("target_faces must be >= 0");

  PreparedMesh out;
  MeshReport& rep = out.report;
  rep.input_vertices = static_cast<int>(V_in.rows());
  rep.input_faces = static_cast<int>(F_in.rows());

  // Normalize.
  const Eigen::RowVector3d lo = V_in.colwise().minCoeff(), hi = V_in.colwise().maxCoeff();
  const double diag = (hi - lo).norm();
  if (!(diag > 0) || !std::isfinite(diag)) {
    throw InputError("the mesh has no extent (all vertices coincide or coordinates overflow)");
  }
  out.scale = diag;
  out.offset = 0.5 * (lo + hi);
  poll(0);
  Vertices Vn = (V_in.rowwise() - out.offset) / diag;
  poll(0);

  // Flat input: every vertex within 1e-9 of the plane of least extent (normalized units).
  {
    const Eigen::RowVector3d mean = Vn.colwise().mean();
    const Eigen::Matrix3d cov = (Vn.rowwise() - mean).transpose() * (Vn.rowwise() - mean);
    const Eigen::Vector3d normal = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors().col(0);
    if (((Vn.rowwise() - mean) * normal).cwiseAbs().maxCoeff() < 1e-9) {
      throw InputError("the mesh is flat: all its vertices lie in one plane, so it encloses no "
                       "volume");
    }
  }

  poll(0.01);
  // Border vertices (on an edge with one face, by index): the only ones that get welded.
  const int nv = static_cast<int>(Vn.rows());
  std::vector<char> on_border(nv, 0);
  {
    std::vector<std::uint64_t> keys;
    keys.reserve(F_in.rows() * 3);
    for (Eigen::Index f = 0; f < F_in.rows(); ++f) {
      if ((f & 65535) == 0) poll(0.01);
      for (int k = 0; k < 3; ++k) {
        const int a = F_in(f, k), b = F_in(f, (k + 1) % 3);
        if (a != b) keys.push_back(edge_key(a, b));
      }
    }
    internal::sort_polling(keys, [&] { poll(0.01); });
    for (std::size_t i = 0; i < keys.size();) {
      std::size_t j = i + 1;
      while (j < keys.size() && keys[j] == keys[i]) ++j;
      if (j - i == 1) {
        on_border[keys[i] >> 32] = 1;
        on_border[keys[i] & 0xffffffffu] = 1;
      }
      i = j;
    }
  }

  poll(0.02);

  // Weld.
  std::vector<int> rep_of(nv);
  {
    const double tol = options.weld_tolerance;
    const double cell = tol > 0 ? tol : 1.0;
    std::unordered_map<std::array<std::int64_t, 3>, std::vector<int>, CellHash> grid;
    grid.reserve(nv * 2);
    auto cell_of = [&](int i) {
      return std::array<std::int64_t, 3>{static_cast<std::int64_t>(std::floor(Vn(i, 0) / cell)),
                                         static_cast<std::int64_t>(std::floor(Vn(i, 1) / cell)),
                                         static_cast<std::int64_t>(std::floor(Vn(i, 2) / cell))};
    };
    for (int i = 0; i < nv; ++i) {
      if ((i & 4095) == 0) poll(0.02 + 0.02 * i / nv);
      rep_of[i] = i;
      if (!on_border[i]) continue;
      const auto c = cell_of(i);
      int found = -1;
      if (tol > 0) {
        for (int dx = -1; dx <= 1 && found < 0; ++dx)
          for (int dy = -1; dy <= 1 && found < 0; ++dy)
            for (int dz = -1; dz <= 1 && found < 0; ++dz) {
              auto it = grid.find({c[0] + dx, c[1] + dy, c[2] + dz});
              if (it == grid.end()) continue;
              for (int j : it->second) {
                if ((Vn.row(i) - Vn.row(j)).norm() <= tol) {
                  found = j;
                  break;
                }
              }
            }
      } else {
        auto it = grid.find(c);
        if (it != grid.end()) {
          for (int j : it->second)
            if (Vn.row(i) == Vn.row(j)) {
              found = j;
              break;
            }
        }
      }
      if (found >= 0) {
        rep_of[i] = found;
        ++rep.welded_vertices;
      } else {
        grid[c].push_back(i);
      }
    }
  }

  // Drop degenerate and duplicate faces.
  std::vector<std::array<int, 3>> faces;
  faces.reserve(F_in.rows());
  {
    std::unordered_set<std::array<std::int64_t, 3>, CellHash> seen;
    seen.reserve(F_in.rows() * 2);
    for (int f = 0; f < F_in.rows(); ++f) {
      if ((f & 4095) == 0) poll(0.04 + 0.02 * f / F_in.rows());
      const int a = rep_of[F_in(f, 0)], b = rep_of[F_in(f, 1)], c = rep_of[F_in(f, 2)];
      if (a == b || b == c || a == c) {
        ++rep.dropped_faces;
        continue;
      }
      const Eigen::Vector3d pa = Vn.row(a), pb = Vn.row(b), pc = Vn.row(c);
      if (!((pb - pa).cross(pc - pa).norm() > 1e-16)) {
        ++rep.dropped_faces;
        continue;
      }
      std::array<std::int64_t, 3> key = {a, b, c};
      std::sort(key.begin(), key.end());
      if (!seen.insert(key).second) {
        ++rep.dropped_faces;
        continue;
      }
      faces.push_back({a, b, c});
    }
  }
  if (faces.size() < 4) {
    throw InputError("fewer than 4 faces are left after welding and dropping degenerate faces (" +
                     std::to_string(faces.size()) + ")");
  }
  // Compact: keep referenced vertices only.
  Mesh clean;
  std::vector<int> index(nv, -1);  // input (welded) vertex -> clean vertex, -1 if unreferenced
  {
    int n = 0;
    for (auto& t : faces)
      for (int& v : t)
        if (index[v] < 0) index[v] = n++;
    clean.V.resize(n, 3);
    for (int v = 0; v < nv; ++v)
      if (index[v] >= 0) clean.V.row(index[v]) = Vn.row(v);
    clean.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
    for (std::size_t f = 0; f < faces.size(); ++f)
      for (int k = 0; k < 3; ++k) clean.F(f, k) = index[faces[f][k]];
  }

  poll(0.06);
  const Topology topo = analyze(clean.V, clean.F, true, [&] { poll(0.08); });
  poll(0.1);
  rep.border_edges = topo.border_edges;
  rep.border_loops = topo.border_loops;
  rep.non_manifold_edges = topo.non_manifold_edges;
  rep.non_manifold_vertices = topo.non_manifold_vertices;
  rep.components = topo.components;
  rep.orientable = topo.orientable;
  const bool closed = rep.closed_manifold() && rep.components <= 1;
  if (closed) {
    // A closed manifold whose faces fold flat onto each other (found by fuzzing: an octahedron
    // with its centre on an edge) encloses no volume, and CGAL's isotropic remeshing crashes
    // on it (SEGV in tangential_relaxation). Its vertices are not in one plane, so the flat
    // check above lets it through; the enclosed volume (divergence theorem, from analyze(), in
    // normalized units, so a real shape has about 1e-3 or more) tells.
    if (!(topo.enclosed_volume > 1e-10)) {
      throw InputError("the mesh encloses no volume: it is closed, but its faces lie flat on "
                       "each other");
    }
  }
  const bool needs_repair = !closed;

  if (needs_repair) {
    if (options.repair == Repair::None) {
      throw InputError("the mesh is not a single closed manifold: " + problem_list(topo) +
                       "; use repair='auto' to wrap it into a closed proxy");
    }
    double alpha = std::clamp(0.6 * topo.largest_hole, 0.01, 0.1);
    if (topo.border_edges == 0) alpha = 0.01;
    out.working = internal::alpha_wrap(clean, alpha, alpha / 30.0, poll.part(0.1, 0.3));
    out.repaired = true;
    out.wrap_alpha = alpha;
  } else {
    out.working = std::move(clean);
  }

  // Remesh to a uniform mesh of about target_faces triangles.
  if (options.target_faces > 0) {
    const double nf = static_cast<double>(out.working.F.rows());
    int target = options.target_faces;
    bool skip = false;
    const bool small = small_for_target(nf, target), large = nf > kNearTarget * target;
    if (options.upsample) {
      // Kept only near the target size and with even edge lengths.
      skip = !small && !large && edge_length_variation(out.working.V, out.working.F) < 0.5;
    } else if (!large) {
      // Not larger than the target: kept, unless it is tiny or its triangles are very uneven
      // (then remeshed, a small input only to kSmallRemeshFaces). The public meshes of 898 to
      // 12,000 faces give the same skeletons from their own faces as remeshed to 20,000, at a
      // fraction of the cost.
      skip = nf >= kMinKeptFaces &&
             edge_length_variation(out.working.V, out.working.F) < kMaxKeptVariation;
      if (small) target = std::min(target, kSmallRemeshFaces);
    }
    if (!skip && !out.repaired) {
      // One flat fold is enough for the same crash of the remeshing (fuzzing again: two faces
      // folded onto each other on a pyramid that does enclose a volume): a mesh to be remeshed
      // that has one is repaired like a broken one first. (Kept as it is, a fold does no harm:
      // two vertices of a closed mesh moved onto each other make one.)
      const int folds = folded_edges(out.working);
      if (folds > 0) {
        if (options.repair == Repair::None) {
          throw InputError("the surface folds flat onto itself at " + std::to_string(folds) +
                           " edge(s) (two faces lie on each other), which the remeshing cannot "
                           "take; use repair='auto' to wrap it into a closed proxy");
        }
        out.working = internal::alpha_wrap(out.working, 0.01, 0.01 / 30.0, poll.part(0.1, 0.3));
        out.repaired = true;
        out.wrap_alpha = 0.01;
      }
    }
    if (!skip) {
      const int goal = 4 * std::max(options.target_faces, internal::kMinRemeshFaces);
      if (nf > std::max(2.0 * goal, 150000.0)) {
        out.working = fast_reduce(out.working, goal, poll.part(0.3, 0.5));
      }
      out.working = internal::remesh_uniform(out.working, target, poll.part(0.5, 0.85));
      out.remeshed = true;
    }
  }
  poll(0.85);
  out.genus = mesh_genus(out.working);

  // Map every input vertex to the working mesh: onto its own corner when the working mesh is the
  // cleaned input, else to its closest point (in parallel, on the shared SurfaceQuery).
  out.query = std::make_shared<const SurfaceQuery>(out.working, [&] { poll(0.86); });
  {
    const auto& W = out.working;
    out.map_face.resize(nv);
    out.map_barycentric.resize(nv, 3);
    const bool same = !out.repaired && !out.remeshed;
    std::vector<int> corner_face;  // clean vertex -> (face * 3 + corner) of one face using it
    if (same) {
      corner_face.assign(W.V.rows(), -1);
      for (int f = 0; f < W.F.rows(); ++f)
        for (int k = 0; k < 3; ++k)
          if (corner_face[W.F(f, k)] < 0) corner_face[W.F(f, k)] = 3 * f + k;
    }
    const SurfaceQuery& query = *out.query;
    // In chunks, polling between them (the callback is not called from TBB's workers).
    constexpr int kChunk = 1 << 15;
    for (int chunk = 0; chunk < nv; chunk += kChunk) {
      poll(0.87 + 0.13 * chunk / nv);
      tbb::parallel_for(tbb::blocked_range<int>(chunk, std::min(nv, chunk + kChunk), 1024),
                        [&](const tbb::blocked_range<int>& r) {
        for (int i = r.begin(); i != r.end(); ++i) {
          const int c = same ? index[rep_of[i]] : -1;
          if (c >= 0) {
            out.map_face[i] = corner_face[c] / 3;
            out.map_barycentric.row(i).setZero();
            out.map_barycentric(i, corner_face[c] % 3) = 1.0;
            continue;
          }
          int f = 0;
          const Eigen::Vector3d q = query.closest_point(Vn.row(i).transpose(), &f);
          const Eigen::Vector3d a = W.V.row(W.F(f, 0)), b = W.V.row(W.F(f, 1)),
                                cc = W.V.row(W.F(f, 2));
          const Eigen::Vector3d n = (b - a).cross(cc - a);
          const double n2 = n.squaredNorm();
          Eigen::Vector3d l(1.0 / 3, 1.0 / 3, 1.0 / 3);
          if (n2 > 0) {
            l[0] = (cc - b).cross(q - b).dot(n) / n2;
            l[1] = (a - cc).cross(q - cc).dot(n) / n2;
            l[0] = std::clamp(l[0], 0.0, 1.0);
            l[1] = std::clamp(l[1], 0.0, 1.0 - l[0]);
            l[2] = 1.0 - l[0] - l[1];
          }
          out.map_face[i] = f;
          out.map_barycentric.row(i) = l.transpose();
        }
      });
    }
  }
  poll(1);
  return out;
}

}  // namespace dcg

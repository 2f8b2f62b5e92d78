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
#include "union_find.h"
#include "dcg/prepare.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
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
#include "remesh.h"
#include "repair.h"

namespace dcg {
namespace {

using internal::UnionFind;

inline std::uint64_t edge_key(int a, int b) {
  if (a > b) std::swap(a, b);
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) |
         static_cast<std::uint32_t>(b);
}

struct CellHash {
  std::size_t operator()(const std::array<std::int64_t, 3>& c) const {
    return static_cast<std::size_t>(c[0] * 73856093LL ^ c[1] * 19349663LL ^ c[2] * 83492791LL);
  }
};

// Undirected edges with their incident faces, sorted by key.
struct EdgeTable {
  std::vector<std::pair<std::uint64_t, int>> half;  // (edge key, face), sorted by key
  explicit EdgeTable(const Faces& F) {
    half.reserve(F.rows() * 3);
    for (int f = 0; f < F.rows(); ++f) {
      for (int k = 0; k < 3; ++k) half.emplace_back(edge_key(F(f, k), F(f, (k + 1) % 3)), f);
    }
    std::sort(half.begin(), half.end());
  }
  // Calls fn(begin, end) for each run of equal keys.
  template <class Fn>
  void for_each_edge(Fn fn) const {
    for (std::size_t i = 0; i < half.size();) {
      std::size_t j = i;
      while (j < half.size() && half[j].first == half[i].first) ++j;
      fn(i, j);
      i = j;
    }
  }
};

struct Topology {
  int edges = 0;
  int border_edges = 0;
  int non_manifold_edges = 0;
  int non_manifold_vertices = 0;
  int components = 0;
  int border_loops = 0;
  bool orientable = true;
  double largest_hole = 0;  // bbox diagonal of the largest border loop
};

// Counts edges, borders, non-manifold edges / vertices and components of (V, F); when `orient`
// is true, also makes the faces' orientation consistent per component and outward (positive
// signed volume).
Topology analyze(const Vertices& V, Faces& F, bool orient) {
  Topology t;
  const int nf = static_cast<int>(F.rows()), nv = static_cast<int>(V.rows());
  EdgeTable table(F);
  UnionFind faces_uf(nf);
  // Manifold adjacency: face -> up to 3 neighbours over edges with exactly 2 faces.
  std::vector<std::array<int, 3>> adj(nf, {-1, -1, -1});
  std::vector<std::pair<int, int>> border;  // border edges (vertex pairs)
  table.for_each_edge([&](std::size_t b, std::size_t e) {
    ++t.edges;
    const std::size_t n = e - b;
    for (std::size_t i = b + 1; i < e; ++i) faces_uf.unite(table.half[b].second, table.half[i].second);
    if (n == 1) {
      ++t.border_edges;
      const std::uint64_t key = table.half[b].first;
      border.emplace_back(static_cast<int>(key >> 32), static_cast<int>(key & 0xffffffffu));
    } else if (n > 2) {
      ++t.non_manifold_edges;
    } else {
      const int f = table.half[b].second, g = table.half[b + 1].second;
      for (int k = 0; k < 3; ++k) {
        if (edge_key(F(f, k), F(f, (k + 1) % 3)) == table.half[b].first && adj[f][k] < 0) {
          adj[f][k] = g;
          break;
        }
      }
      for (int k = 0; k < 3; ++k) {
        if (edge_key(F(g, k), F(g, (k + 1) % 3)) == table.half[b].first && adj[g][k] < 0) {
          adj[g][k] = f;
          break;
        }
      }
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

PreparedMesh prepare_mesh(const Vertices& V_in, const Faces& F_in, const PrepareOptions& options) {
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
  Vertices Vn = (V_in.rowwise() - out.offset) / diag;

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

  // Border vertices (on an edge with one face, by index): the only ones that get welded.
  const int nv = static_cast<int>(Vn.rows());
  std::vector<char> on_border(nv, 0);
  {
    std::vector<std::uint64_t> keys;
    keys.reserve(F_in.rows() * 3);
    for (Eigen::Index f = 0; f < F_in.rows(); ++f) {
      for (int k = 0; k < 3; ++k) {
        const int a = F_in(f, k), b = F_in(f, (k + 1) % 3);
        if (a != b) keys.push_back(edge_key(a, b));
      }
    }
    std::sort(keys.begin(), keys.end());
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

  const Topology topo = analyze(clean.V, clean.F, true);
  rep.border_edges = topo.border_edges;
  rep.border_loops = topo.border_loops;
  rep.non_manifold_edges = topo.non_manifold_edges;
  rep.non_manifold_vertices = topo.non_manifold_vertices;
  rep.components = topo.components;
  rep.orientable = topo.orientable;
  const bool needs_repair = !rep.closed_manifold() || rep.components > 1;

  if (needs_repair) {
    if (options.repair == Repair::None) {
      throw InputError("the mesh is not a single closed manifold: " + problem_list(topo) +
                       "; use repair='auto' to wrap it into a closed proxy");
    }
    double alpha = std::clamp(0.6 * topo.largest_hole, 0.01, 0.1);
    if (topo.border_edges == 0) alpha = 0.01;
    out.working = internal::alpha_wrap(clean, alpha, alpha / 30.0);
    out.repaired = true;
    out.wrap_alpha = alpha;
  } else {
    // A closed manifold whose faces fold flat onto each other (found by fuzzing: an octahedron
    // with its centre on an edge) encloses no volume, and CGAL's isotropic remeshing crashes
    // on it (SEGV in tangential_relaxation). Its vertices are not in one plane, so the flat
    // check above lets it through; the enclosed volume (divergence theorem, normalized units,
    // so a real shape has about 1e-3 or more) tells.
    double volume = 0;
    for (Eigen::Index f = 0; f < clean.F.rows(); ++f) {
      const Eigen::Vector3d a = clean.V.row(clean.F(f, 0)), b = clean.V.row(clean.F(f, 1)),
                            c = clean.V.row(clean.F(f, 2));
      volume += a.dot(b.cross(c)) / 6.0;
    }
    if (!(std::abs(volume) > 1e-10)) {
      throw InputError("the mesh encloses no volume: it is closed, but its faces lie flat on "
                       "each other");
    }
    out.working = std::move(clean);
  }

  // Remesh to a uniform mesh of about target_faces triangles.
  if (options.target_faces > 0) {
    const double nf = static_cast<double>(out.working.F.rows());
    const double target = options.target_faces;
    const bool near = nf >= target / 2.5 && nf <= target * 2.5;
    const bool skip = near && edge_length_variation(out.working.V, out.working.F) < 0.5;
    if (!skip) {
      out.working = internal::remesh_uniform(out.working, options.target_faces);
      out.remeshed = true;
    }
  }
  out.genus = mesh_genus(out.working);

  // Map every input vertex to the working mesh: onto its own corner when the working mesh is the
  // cleaned input, else to its closest point (in parallel, on the shared SurfaceQuery).
  out.query = std::make_shared<const SurfaceQuery>(out.working);
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
    tbb::parallel_for(tbb::blocked_range<int>(0, nv, 1024), [&](const tbb::blocked_range<int>& r) {
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
  return out;
}

}  // namespace dcg

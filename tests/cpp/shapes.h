// Synthetic closed meshes for the tests (outward-oriented, closed 2-manifolds), and helpers to
// rotate, scale, perturb, open or merge them. Header-only; every random helper takes its own
// generator so tests are deterministic.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <limits>
#include <map>
#include <random>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "dcg/types.h"

namespace dcg::test {

/// A file of this repository, by its path from the repository's root.
inline std::string repo_file(const std::string& relative) {
  return std::string(DCG_SOURCE_DIR) + "/" + relative;
}

/// The folder of the public meshes: $DCG_MESHES, else ../shared/meshes next to the repository.
inline std::string meshes_dir() {
  if (const char* env = std::getenv("DCG_MESHES")) return env;
  return std::string(DCG_SOURCE_DIR) + "/../shared/meshes";
}

inline Mesh make_mesh(const std::vector<Eigen::Vector3d>& V,
                      const std::vector<std::array<int, 3>>& F) {
  Mesh m;
  m.V.resize(static_cast<Eigen::Index>(V.size()), 3);
  for (std::size_t i = 0; i < V.size(); ++i) m.V.row(i) = V[i].transpose();
  m.F.resize(static_cast<Eigen::Index>(F.size()), 3);
  for (std::size_t i = 0; i < F.size(); ++i) m.F.row(i) << F[i][0], F[i][1], F[i][2];
  return m;
}

/// Icosahedron subdivided `level` times, projected on the sphere of `radius` at the origin.
inline Mesh icosphere(int level, double radius = 1.0) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> V = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                                    {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                                    {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::vector<std::array<int, 3>> F = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                       {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (auto& v : V) v.normalize();
  for (int l = 0; l < level; ++l) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      V.push_back((V[a] + V[b]).normalized());
      const int i = static_cast<int>(V.size()) - 1;
      mid.emplace(key, i);
      return i;
    };
    std::vector<std::array<int, 3>> next;
    for (const auto& f : F) {
      const int a = midpoint(f[0], f[1]), b = midpoint(f[1], f[2]), c = midpoint(f[2], f[0]);
      next.push_back({f[0], a, c});
      next.push_back({f[1], b, a});
      next.push_back({f[2], c, b});
      next.push_back({a, b, c});
    }
    F.swap(next);
  }
  for (auto& v : V) v *= radius;
  return make_mesh(V, F);
}

/// Torus around the z axis: ring radius R, tube radius r, nu x nv quads split in triangles.
inline Mesh torus(double R, double r, int nu = 48, int nv = 24) {
  std::vector<Eigen::Vector3d> V;
  std::vector<std::array<int, 3>> F;
  for (int i = 0; i < nu; ++i) {
    const double u = 2 * M_PI * i / nu;
    for (int j = 0; j < nv; ++j) {
      const double v = 2 * M_PI * j / nv;
      V.emplace_back((R + r * std::cos(v)) * std::cos(u), (R + r * std::cos(v)) * std::sin(u),
                     r * std::sin(v));
    }
  }
  auto id = [&](int i, int j) { return ((i + nu) % nu) * nv + (j + nv) % nv; };
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) {
      F.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      F.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  }
  return make_mesh(V, F);
}

/// Capsule along z: a cylinder of `radius` and straight `length`, closed by two hemispheres.
/// `rings` latitude steps per hemisphere, `segments` around, `sections` along the cylinder.
/// Vertices: the top pole, the latitude rows from top to bottom, the bottom pole; `ring`, when
/// given, receives each vertex's row (-1 for the top pole, the row count for the bottom one).
inline Mesh capsule(double radius, double length, int rings = 12, int segments = 32,
                    int sections = 12, std::vector<int>* ring = nullptr) {
  std::vector<Eigen::Vector3d> V;
  std::vector<std::array<int, 3>> F;
  // Latitude rows from the top pole to the bottom pole (poles excluded).
  std::vector<std::pair<double, double>> rows;  // (z, ring radius)
  for (int i = 1; i <= rings; ++i) {
    const double theta = 0.5 * M_PI * i / rings;
    rows.emplace_back(0.5 * length + radius * std::cos(theta), radius * std::sin(theta));
  }
  for (int i = 1; i < sections; ++i)
    rows.emplace_back(0.5 * length - length * i / sections, radius);
  for (int i = 0; i < rings; ++i) {
    const double theta = 0.5 * M_PI + 0.5 * M_PI * i / rings;
    rows.emplace_back(-0.5 * length + radius * std::cos(theta), radius * std::sin(theta));
  }
  V.emplace_back(0, 0, 0.5 * length + radius);
  for (const auto& [z, rr] : rows)
    for (int j = 0; j < segments; ++j) {
      const double phi = 2 * M_PI * j / segments;
      V.emplace_back(rr * std::cos(phi), rr * std::sin(phi), z);
    }
  V.emplace_back(0, 0, -0.5 * length - radius);
  const int nrows = static_cast<int>(rows.size()), bottom = static_cast<int>(V.size()) - 1;
  if (ring) {
    ring->assign(V.size(), nrows);
    (*ring)[0] = -1;
    for (int v = 1; v < bottom; ++v) (*ring)[v] = (v - 1) / segments;
  }
  auto id = [&](int row, int j) { return 1 + row * segments + (j + segments) % segments; };
  for (int j = 0; j < segments; ++j) {
    F.push_back({0, id(0, j), id(0, j + 1)});
    F.push_back({bottom, id(nrows - 1, j + 1), id(nrows - 1, j)});
  }
  for (int i = 0; i + 1 < nrows; ++i)
    for (int j = 0; j < segments; ++j) {
      F.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      F.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return make_mesh(V, F);
}

/// Closed, outward surface {phi = 0} of phi (negative inside) on a grid of n^3 cells over the box
/// [lo, hi]^3, by marching tetrahedra (6 tetrahedra per cell around the main diagonal, so the
/// surface is a closed 2-manifold when phi > 0 on the box's boundary).
inline Mesh marching_tetrahedra(const std::function<double(const Eigen::Vector3d&)>& phi, double lo,
                                double hi, int n) {
  const int m = n + 1;
  const double h = (hi - lo) / n;
  auto grid_point = [&](int id) {
    const int i = id % m, j = (id / m) % m, k = id / (m * m);
    return Eigen::Vector3d(lo + i * h, lo + j * h, lo + k * h);
  };
  std::vector<double> value(static_cast<std::size_t>(m) * m * m);
  for (int id = 0; id < m * m * m; ++id) {
    double v = phi(grid_point(id));
    if (std::abs(v) < 1e-9) v = 1e-9;  // no grid point exactly on the surface
    value[id] = v;
  }
  std::vector<Eigen::Vector3d> V;
  std::vector<std::array<int, 3>> F;
  std::unordered_map<std::uint64_t, int> on_edge;
  auto vertex = [&](int a, int b) {
    if (a > b) std::swap(a, b);
    const std::uint64_t key = (static_cast<std::uint64_t>(a) << 32) | static_cast<std::uint32_t>(b);
    auto it = on_edge.find(key);
    if (it != on_edge.end()) return it->second;
    double t = value[a] / (value[a] - value[b]);
    t = std::min(0.95, std::max(0.05, t));  // keeps triangles away from degenerate
    V.push_back((1 - t) * grid_point(a) + t * grid_point(b));
    const int index = static_cast<int>(V.size()) - 1;
    on_edge.emplace(key, index);
    return index;
  };
  auto triangle = [&](int a, int b, int c, const Eigen::Vector3d& outward) {
    const Eigen::Vector3d nrm = (V[b] - V[a]).cross(V[c] - V[a]);
    if (nrm.dot(outward) < 0) std::swap(b, c);
    F.push_back({a, b, c});
  };
  static const int tets[6][4] = {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7},
                                 {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}};
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        int corner[8];
        for (int b = 0; b < 8; ++b)
          corner[b] = (i + (b & 1)) + (j + ((b >> 1) & 1)) * m + (k + ((b >> 2) & 1)) * m * m;
        for (const auto& tet : tets) {
          std::vector<int> in, out;
          for (int c : tet) (value[corner[c]] < 0 ? in : out).push_back(corner[c]);
          if (in.empty() || out.empty()) continue;
          const Eigen::Vector3d outward = grid_point(out[0]) - grid_point(in[0]);
          if (in.size() == 1) {
            triangle(vertex(in[0], out[0]), vertex(in[0], out[1]), vertex(in[0], out[2]), outward);
          } else if (out.size() == 1) {
            triangle(vertex(in[0], out[0]), vertex(in[1], out[0]), vertex(in[2], out[0]), outward);
          } else {  // two in, two out: a quad (a,c) (a,d) (b,d) (b,c)
            const int q0 = vertex(in[0], out[0]), q1 = vertex(in[0], out[1]),
                      q2 = vertex(in[1], out[1]), q3 = vertex(in[1], out[0]);
            triangle(q0, q1, q2, outward);
            triangle(q0, q2, q3, outward);
          }
        }
      }
  return make_mesh(V, F);
}

/// Unit directions spread on the sphere (Fibonacci), `count` of them.
inline std::vector<Eigen::Vector3d> fibonacci_directions(int count) {
  std::vector<Eigen::Vector3d> d;
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < count; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / count, r = std::sqrt(1.0 - z * z);
    d.emplace_back(r * std::cos(golden * i), r * std::sin(golden * i), z);
  }
  return d;
}

/// A star: a ball of radius 1 with `arms` capsule arms (radius arm_radius, reaching
/// arm_length from the center) along spread-out directions, smoothly blended; marching
/// tetrahedra on `n`^3 cells.
inline Mesh star(int arms, double arm_length = 3.0, double arm_radius = 0.35, int n = 56) {
  const auto dirs = fibonacci_directions(arms);
  auto phi = [&](const Eigen::Vector3d& x) {
    double d = x.norm() - 1.0;
    const double k = 0.25;  // blend radius of the smooth minimum
    for (const auto& a : dirs) {
      const double t = std::min(std::max(x.dot(a), 0.0), arm_length - arm_radius);
      const double c = (x - t * a).norm() - arm_radius;
      const double hh = std::max(k - std::abs(d - c), 0.0) / k;
      d = std::min(d, c) - hh * hh * k * 0.25;
    }
    return d;
  };
  const double extent = arm_length + 0.3;
  return marching_tetrahedra(phi, -extent, extent, n);
}

/// A random rotation (uniform on SO(3)).
inline Eigen::Matrix3d random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> g;
  Eigen::Quaterniond q(g(rng), g(rng), g(rng), g(rng));
  q.normalize();
  return q.toRotationMatrix();
}

/// x -> scale * R x + t for every vertex.
inline Mesh transformed(Mesh m, const Eigen::Matrix3d& R, double scale,
                        const Eigen::Vector3d& t = Eigen::Vector3d::Zero()) {
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
    m.V.row(i) = (scale * (R * m.V.row(i).transpose()) + t).transpose();
  }
  return m;
}

/// Moves every vertex by a random offset, each coordinate uniform in +-fraction of the bounding
/// box diagonal (fraction 0.003: "0.3% vertex noise").
inline Mesh with_noise(Mesh m, double fraction, std::mt19937& rng) {
  const double diag = (m.V.colwise().maxCoeff() - m.V.colwise().minCoeff()).norm();
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (Eigen::Index i = 0; i < m.V.rows(); ++i)
    for (int k = 0; k < 3; ++k) m.V(i, k) += fraction * diag * u(rng);
  return m;
}

/// Removes the faces whose centroid has a z above `z` (opens a hole).
inline Mesh cut_above(const Mesh& m, double z) {
  std::vector<int> keep;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    const double cz = (m.V(m.F(f, 0), 2) + m.V(m.F(f, 1), 2) + m.V(m.F(f, 2), 2)) / 3.0;
    if (cz <= z) keep.push_back(static_cast<int>(f));
  }
  Mesh out;
  out.V = m.V;
  out.F.resize(static_cast<Eigen::Index>(keep.size()), 3);
  for (std::size_t i = 0; i < keep.size(); ++i) out.F.row(i) = m.F.row(keep[i]);
  return out;
}

/// The union of two meshes as one (V, F) with two components.
inline Mesh merged(const Mesh& a, const Mesh& b) {
  Mesh out;
  out.V.resize(a.V.rows() + b.V.rows(), 3);
  out.V << a.V, b.V;
  out.F.resize(a.F.rows() + b.F.rows(), 3);
  out.F << a.F, (b.F.array() + static_cast<int>(a.V.rows())).matrix();
  return out;
}

// --- brute-force references (independent of the engine's code) --------------------------------

/// Distance from p to the triangle (a, b, c): to its plane when p projects inside it, else to
/// the nearest of its three sides.
inline double triangle_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  auto segment = [&](const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
    const Eigen::Vector3d d = v - u;
    const double len2 = d.squaredNorm();
    const double t = len2 > 0 ? std::min(1.0, std::max(0.0, (p - u).dot(d) / len2)) : 0.0;
    return (p - (u + t * d)).norm();
  };
  const Eigen::Vector3d n = (b - a).cross(c - a);
  const double n2 = n.squaredNorm();
  if (n2 > 0) {
    const Eigen::Vector3d q = p - n * ((p - a).dot(n) / n2);
    const bool in = (b - a).cross(q - a).dot(n) >= 0 && (c - b).cross(q - b).dot(n) >= 0 &&
                    (a - c).cross(q - c).dot(n) >= 0;
    if (in) return (p - q).norm();
  }
  return std::min({segment(a, b), segment(b, c), segment(c, a)});
}

/// Distance from p to the mesh: the minimum over every triangle.
inline double brute_force_distance(const Mesh& m, const Eigen::Vector3d& p) {
  double best = std::numeric_limits<double>::infinity();
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    best = std::min(
        best, triangle_distance(p, m.V.row(m.F(f, 0)), m.V.row(m.F(f, 1)), m.V.row(m.F(f, 2))));
  }
  return best;
}

/// Generalized winding number of the closed, outward mesh around p (1 inside, 0 outside): the
/// sum of the triangles' signed solid angles (Van Oosterom & Strackee) over 4 pi.
inline double winding_number(const Mesh& m, const Eigen::Vector3d& p) {
  double sum = 0;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    const Eigen::Vector3d a = m.V.row(m.F(f, 0)).transpose() - p,
                          b = m.V.row(m.F(f, 1)).transpose() - p,
                          c = m.V.row(m.F(f, 2)).transpose() - p;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    const double num = a.dot(b.cross(c));
    const double den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    sum += 2.0 * std::atan2(num, den);
  }
  return sum / (4.0 * M_PI);
}

/// Every edge has exactly two faces, each used once in each direction (closed, oriented), and
/// the faces around every vertex form one fan (no pinched vertex).
inline bool is_closed_oriented_manifold(const Mesh& m) {
  std::map<std::pair<int, int>, int> directed;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) ++directed[{m.F(f, k), m.F(f, (k + 1) % 3)}];
  for (const auto& [e, count] : directed) {
    if (count != 1) return false;
    auto it = directed.find({e.second, e.first});
    if (it == directed.end() || it->second != 1) return false;
  }
  // One fan per vertex: walk the faces around it through the next-corner map.
  std::vector<std::map<int, int>> next(m.V.rows());  // vertex -> (corner a -> corner b)
  std::vector<int> used(m.V.rows(), 0);
  for (Eigen::Index f = 0; f < m.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      next[m.F(f, k)][m.F(f, (k + 1) % 3)] = m.F(f, (k + 2) % 3);
      ++used[m.F(f, k)];
    }
  for (Eigen::Index v = 0; v < m.V.rows(); ++v) {
    if (used[v] == 0) continue;
    const int start = next[v].begin()->first;
    int cur = start, steps = 0;
    do {
      auto it = next[v].find(cur);
      if (it == next[v].end()) return false;
      cur = it->second;
      ++steps;
    } while (cur != start && steps <= used[v]);
    if (steps != used[v]) return false;
  }
  return true;
}

/// Connected components over shared vertices.
inline int component_count(const Mesh& m) {
  std::vector<int> parent(m.V.rows());
  for (std::size_t i = 0; i < parent.size(); ++i) parent[i] = static_cast<int>(i);
  std::function<int(int)> find = [&](int x) {
    return parent[x] == x ? x : parent[x] = find(parent[x]);
  };
  std::vector<char> used(m.V.rows(), 0);
  for (Eigen::Index f = 0; f < m.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      used[m.F(f, k)] = 1;
      parent[find(m.F(f, k))] = find(m.F(f, (k + 1) % 3));
    }
  int count = 0;
  for (Eigen::Index v = 0; v < m.V.rows(); ++v)
    if (used[v] && find(static_cast<int>(v)) == v) ++count;
  return count;
}

}  // namespace dcg::test

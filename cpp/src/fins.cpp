// Fins and inner walls (fins.h). Game characters often come in closed parts stitched together
// with zero-volume sheets: Q_Wasp's wings are single quads hung on the body along non-manifold
// edges, Q_Frog's warts are caps closing holes in the body with a disc under each (every rim
// edge then has three faces: body, cap, disc). The alpha wrap repairs such a mesh, at about
// 0.1 ms per output face (2-3 s on these 4-5k-face characters), into a proxy of the shape; a
// sheet encloses no volume, so it has no medial axis to give the skeleton anyway. Taking the
// sheets away leaves closed parts that the union (union.h, 10-90 ms) joins on the input's own
// surface.
//
// Each round: count the live faces of every edge; components of faces over edges with exactly
// two; a component is a fin when it touches an edge of three or more faces and leaving it out
// leaves each of its edges with zero faces or at least two (it never opens a hole). The fin of
// smallest area goes (ties: its smallest face index, for repeatable results), until no edge has
// other than two faces (success) or no fin is left (nullopt). Of a shell and the wall that
// divides it, both are fins of the same edges; the wall is the smaller, and once it is gone the
// shell's edges have two faces again.
#include "fins.h"

#include <array>
#include <cstdint>
#include <limits>
#include <vector>

#include "compact_mesh.h"
#include "edge_table.h"
#include "union_find.h"

namespace dcg::internal {
namespace {

// At most this many fins (each round is a pass over the mesh); more and the mesh is wrapped.
constexpr int kMaxFins = 256;

struct Edges {
  std::vector<int> start;  // CSR over edges: faces start[e] .. start[e + 1] of `faces`
  std::vector<int> faces;  // the face of each corner, grouped by edge
};

Edges edges_of(const Faces& F) {
  const EdgeTable table(F);
  Edges e;
  e.faces.reserve(table.half.size());
  table.for_each_edge([&](std::size_t b, std::size_t end) {
    e.start.push_back(static_cast<int>(e.faces.size()));
    for (std::size_t i = b; i < end; ++i) e.faces.push_back(EdgeTable::face(table.half[i].second));
  });
  e.start.push_back(static_cast<int>(e.faces.size()));
  return e;
}

double face_area(const Mesh& m, int f) {
  const Eigen::RowVector3d a = m.V.row(m.F(f, 0)), b = m.V.row(m.F(f, 1)), c = m.V.row(m.F(f, 2));
  return 0.5 * (b - a).cross(c - a).norm();
}

// One round: the smallest fin's root in `parts` (component roots of live faces), or -1 when
// there is none; `done` is set when every edge already has zero or two live faces.
int smallest_fin(const Edges& edges, const std::vector<char>& alive,
                 const std::vector<double>& area, UnionFind& parts, bool& done) {
  const int nf = static_cast<int>(alive.size()), ne = static_cast<int>(edges.start.size()) - 1;
  std::vector<int> live(ne, 0);
  done = true;
  for (int e = 0; e < ne; ++e) {
    for (int i = edges.start[e]; i < edges.start[e + 1]; ++i) live[e] += alive[edges.faces[i]];
    if (live[e] != 0 && live[e] != 2) done = false;
  }
  if (done) return -1;
  for (int e = 0; e < ne; ++e) {
    if (live[e] != 2) continue;
    int a = -1;
    for (int i = edges.start[e]; i < edges.start[e + 1]; ++i) {
      const int f = edges.faces[i];
      if (!alive[f]) continue;
      if (a < 0)
        a = f;
      else
        parts.unite(a, f);
    }
  }
  std::vector<char> touches(nf, 0), blocked(nf, 0);
  for (int e = 0; e < ne; ++e) {
    if (live[e] < 3) continue;
    // Each component's faces on this edge: leaving it out must not leave exactly one.
    std::vector<std::pair<int, int>> mine;  // (root, faces)
    for (int i = edges.start[e]; i < edges.start[e + 1]; ++i) {
      const int f = edges.faces[i];
      if (!alive[f]) continue;
      const int r = parts.find(f);
      bool found = false;
      for (auto& [root, n] : mine)
        if (root == r) found = (++n, true);
      if (!found) mine.emplace_back(r, 1);
    }
    for (const auto& [root, n] : mine) {
      touches[root] = 1;
      if (live[e] - n == 1) blocked[root] = 1;
    }
  }
  std::vector<double> part_area(nf, 0);
  std::vector<int> first(nf, std::numeric_limits<int>::max());
  for (int f = 0; f < nf; ++f) {
    if (!alive[f]) continue;
    const int r = parts.find(f);
    part_area[r] += area[f];
    first[r] = std::min(first[r], f);
  }
  int best = -1;
  for (int r = 0; r < nf; ++r) {
    if (!alive[r] || parts.find(r) != r || !touches[r] || blocked[r]) continue;
    if (best < 0 || part_area[r] < part_area[best] ||
        (part_area[r] == part_area[best] && first[r] < first[best]))
      best = r;
  }
  return best;
}

}  // namespace

std::optional<FinlessMesh> drop_fins(const Mesh& mesh, const std::function<void()>& poll) {
  const int nf = static_cast<int>(mesh.F.rows());
  const Edges edges = edges_of(mesh.F);
  std::vector<double> area(nf);
  double total = 0;
  for (int f = 0; f < nf; ++f) total += (area[f] = face_area(mesh, f));
  std::vector<char> alive(nf, 1);
  double dropped_area = 0;
  int dropped = 0;
  for (int round = 0;; ++round) {
    if (poll) poll();
    UnionFind parts(nf);
    bool done = false;
    const int fin = smallest_fin(edges, alive, area, parts, done);
    if (done) break;
    if (fin < 0 || round == kMaxFins) return std::nullopt;
    for (int f = 0; f < nf; ++f) {
      if (!alive[f] || parts.find(f) != fin) continue;
      alive[f] = 0;
      dropped_area += area[f];
      ++dropped;
    }
    if (dropped_area > 0.5 * total || dropped == nf) return std::nullopt;
  }
  if (dropped == 0) return std::nullopt;
  std::vector<std::array<int, 3>> kept;
  kept.reserve(static_cast<std::size_t>(nf - dropped));
  for (int f = 0; f < nf; ++f)
    if (alive[f]) kept.push_back({mesh.F(f, 0), mesh.F(f, 1), mesh.F(f, 2)});
  return FinlessMesh{compact_mesh(mesh.V, kept), dropped};
}

}  // namespace dcg::internal

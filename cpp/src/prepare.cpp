// Stage 0 as a chain of steps (prepare_mesh at the end): validate, normalize, weld and clean,
// analyze and orient, repair, remesh, map back. See dcg/prepare.h and ALGORITHM.md "0. Prepare".
// The mesh topology is in mesh_topology.h, the decimator for huge inputs in decimate.h; CGAL only
// enters through repair.h and remesh.h (their own translation units), so this file compiles fast.
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
//   more than one component: ALGORITHM.md counts "several parts" as a problem (an eye ball
//   inside a head, overlapping limbs). When every part is a closed solid (closed, orientable,
//   enclosing a volume; pinched vertices split into one copy per fan), the working mesh is the
//   union of the parts by CGAL's corefinement (union.h): overlapping parts become one surface,
//   nested ones vanish, disjoint ones stay separate shells, and the surface is the input's own.
//   A void the parts enclose between them is filled (report.cavities): its inward shell would
//   otherwise own domain points of its own, a stray skeleton node or a loop.
//   It costs 10-90 ms on the multi-part game characters and pinched meshes where the wrap below
//   took 2-4 s. A pinched mesh of one part is only split. Non-manifold edges where zero-volume
//   fins or inner walls hang on closed parts (fins.h: Q_Wasp's one-quad wings, Q_Frog's discs
//   under its warts) lose those sheets and are united the same way. A part to be united that
//   crosses itself (where its faces nearly touch, a tiny noise or a float32 rounding makes them
//   cross) is replaced by its own alpha wrap first, at the size the whole would be wrapped at
//   (report.wrapped_parts), while at most a quarter of the parts cross. Anything else (an open
//   part, other non-manifold edges, a union that fails) is wrapped whole, which gives the same kind
//   of result (the union, disjoint parts as shells) with every part's details smoothed. Before
//   that, a mesh whose holes are all small (bounding box at most 1/10 of the diagonal, at most 256
//   edges: an eye socket, a neck opening, a cut at a scan's base) gets them triangulated and is
//   united the same way: a wrap sized to such a hole smoothed over 4-7% of the diagonal
//   (Mannequiny), fingers and thin limbs with it. A part that crosses itself is wrapped at
//   kFilledWrapAlpha (Q_Male_Casual's body, 1 of its 7 parts); when the union fails (wolf-open: all
//   3 of its parts cross themselves, too many to wrap one by one, union.cpp), the filled mesh is
//   wrapped whole, at kFilledWrapAlpha: its holes are closed, so the wrap need not be sized to
//   them.
// - Wrap size: alpha = 1/100 of the diagonal (keeps fingers and thin limbs apart), raised to
//   0.6 x the diagonal of the largest hole (border loop) so the wrapping ball cannot enter the
//   hole and wrap both sides of an open sheet (a hollow shell has a useless medial axis), capped
//   at 1/10 of the diagonal; kFilledWrapAlpha for a mesh whose holes were filled. offset =
//   alpha / 30 (CGAL's example ratio: 1/20 and 1/600).
// - Remeshing: skipped when the mesh already has between 1/2.5 and 2.5 times target_faces and
//   its edge lengths are uniform (coefficient of variation below 0.5): such a mesh is as good a
//   geodesic domain as a remeshed one, and remeshing costs more than all of stages 1-3.
// - Before the remeshing, fast_reduce() (decimate.h), an O(n log n) pass-wise edge collapse
//   without a priority queue, takes a mesh of more than 3 x target_faces to 1.5 x (CGAL's quality
//   edge collapse in remesh_uniform() costs about 30 us per collapse: 23 s of the 35 s on a
//   1.4M-face mesh) and an uneven one above target_faces to 0.6 x (fast_reduce_goal below).
// - Cancellation: stage 0 polls the progress callback at most every 10 ms (between steps, in
//   the loops over the input, and from inside CGAL's wrap, collapse and remeshing), so that a
//   cancel request stops it quickly even on millions of faces.
#include "dcg/prepare.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include <Eigen/Eigenvalues>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "compact_mesh.h"
#include "dcg/errors.h"
#include "dcg/surface_query.h"
#include "decimate.h"
#include "edge_table.h"
#include "fins.h"
#include "mesh_topology.h"
#include "polling.h"
#include "remesh.h"
#include "repair.h"
#include "union.h"

namespace dcg {
namespace {

using internal::ThrottledProgress;
using Cell = std::array<std::int64_t, 3>;

struct CellHash {
  std::size_t operator()(const Cell& c) const {
    return static_cast<std::size_t>(c[0] * 73856093LL ^ c[1] * 19349663LL ^ c[2] * 83492791LL);
  }
};

// --- validate and normalize ---------------------------------------------------------------------

// validate_mesh, and the options' ranges.
void validate_input(const Vertices& V, const Faces& F, const PrepareOptions& options) {
  validate_mesh(V, F);
  if (!(options.weld_tolerance >= 0) || !std::isfinite(options.weld_tolerance)) {
    throw InputError("weld_tolerance must be finite and >= 0");
  }
  if (options.target_faces < 0) throw InputError("target_faces must be >= 0");
}

// V (#V by 3) centered at its bounding box's center and scaled to diagonal 1; the offset and
// scale go into `out`. Throws when V has no extent (or overflows).
Vertices normalize(const Vertices& V, ThrottledProgress& poll, PreparedMesh& out) {
  const Eigen::RowVector3d lo = V.colwise().minCoeff(), hi = V.colwise().maxCoeff();
  const double diag = (hi - lo).norm();
  if (!(diag > 0) || !std::isfinite(diag)) {
    throw InputError("the mesh has no extent (all vertices coincide or coordinates overflow)");
  }
  out.scale = diag;
  out.offset = 0.5 * (lo + hi);
  poll(0);
  Vertices Vn = (V.rowwise() - out.offset) / diag;
  poll(0);
  return Vn;
}

// Throws when every vertex of Vn (#V by 3, normalized) is within 1e-9 of the plane of least
// extent: such a mesh encloses nothing.
void reject_flat(const Vertices& Vn) {
  const Eigen::RowVector3d mean = Vn.colwise().mean();
  const Eigen::Matrix3d cov = (Vn.rowwise() - mean).transpose() * (Vn.rowwise() - mean);
  const Eigen::Vector3d normal =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors().col(0);
  if (((Vn.rowwise() - mean) * normal).cwiseAbs().maxCoeff() < 1e-9) {
    throw InputError(
        "the mesh is flat: all its vertices lie in one plane, so it encloses no "
        "volume");
  }
}

// --- weld and clean -----------------------------------------------------------------------------

// #V flags: the vertex is on an edge of F with one face (by index; an edge from a vertex to
// itself does not count). These are the only vertices that get welded.
std::vector<char> border_vertices(int nv, const Faces& F, ThrottledProgress& poll) {
  std::vector<char> on_border(nv, 0);
  std::vector<std::uint64_t> keys;
  keys.reserve(F.rows() * 3);
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    if ((f & 65535) == 0) poll(0.01);
    for (int k = 0; k < 3; ++k) {
      const int a = F(f, k), b = F(f, (k + 1) % 3);
      if (a != b) keys.push_back(internal::edge_key(a, b));
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
  return on_border;
}

using WeldGrid = std::unordered_map<Cell, std::vector<int>, CellHash>;

// The first vertex in `grid` within `tol` of vertex i of Vn (in cell c or the 26 around it; with
// tol 0, an exact copy in cell c), -1 when there is none.
int weld_partner(const WeldGrid& grid, const Vertices& Vn, int i, const Cell& c, double tol) {
  if (tol == 0) {
    auto it = grid.find(c);
    if (it == grid.end()) return -1;
    for (int j : it->second)
      if (Vn.row(i) == Vn.row(j)) return j;
    return -1;
  }
  for (int dx = -1; dx <= 1; ++dx)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dz = -1; dz <= 1; ++dz) {
        auto it = grid.find({c[0] + dx, c[1] + dy, c[2] + dz});
        if (it == grid.end()) continue;
        for (int j : it->second)
          if ((Vn.row(i) - Vn.row(j)).norm() <= tol) return j;
      }
  return -1;
}

// #V: the vertex each vertex of Vn (#V by 3, normalized) is welded into (itself when not
// welded). Each border vertex goes into the first earlier border vertex within `tol`; the count
// of welded vertices goes into `welded`.
std::vector<int> weld_border_vertices(const Vertices& Vn, const std::vector<char>& on_border,
                                      double tol, ThrottledProgress& poll, int& welded) {
  const int nv = static_cast<int>(Vn.rows());
  std::vector<int> rep_of(nv);
  const double cell = tol > 0 ? tol : 1.0;
  WeldGrid grid;
  grid.reserve(nv * 2);
  for (int i = 0; i < nv; ++i) {
    if ((i & 4095) == 0) poll(0.02 + 0.02 * i / nv);
    rep_of[i] = i;
    if (!on_border[i]) continue;
    const Cell c = {static_cast<std::int64_t>(std::floor(Vn(i, 0) / cell)),
                    static_cast<std::int64_t>(std::floor(Vn(i, 1) / cell)),
                    static_cast<std::int64_t>(std::floor(Vn(i, 2) / cell))};
    const int found = weld_partner(grid, Vn, i, c, tol);
    if (found >= 0) {
      rep_of[i] = found;
      ++welded;
    } else {
      grid[c].push_back(i);
    }
  }
  return rep_of;
}

// The faces of F (#F by 3) on the welded vertices rep_of, in order, without the degenerate ones
// (a repeated index, or twice the area at most 1e-16) and the duplicates (the same three
// vertices in any order); their count goes into `dropped`.
std::vector<std::array<int, 3>> clean_faces(const Vertices& Vn, const Faces& F,
                                            const std::vector<int>& rep_of, ThrottledProgress& poll,
                                            int& dropped) {
  std::vector<std::array<int, 3>> faces;
  faces.reserve(F.rows());
  std::unordered_set<Cell, CellHash> seen;
  seen.reserve(F.rows() * 2);
  for (int f = 0; f < F.rows(); ++f) {
    if ((f & 4095) == 0) poll(0.04 + 0.02 * f / F.rows());
    const int a = rep_of[F(f, 0)], b = rep_of[F(f, 1)], c = rep_of[F(f, 2)];
    bool keep = a != b && b != c && a != c;
    if (keep) {
      const Eigen::Vector3d pa = Vn.row(a), pb = Vn.row(b), pc = Vn.row(c);
      keep = (pb - pa).cross(pc - pa).norm() > 1e-16;
    }
    if (keep) {
      Cell key = {a, b, c};
      std::sort(key.begin(), key.end());
      keep = seen.insert(key).second;
    }
    if (keep) {
      faces.push_back({a, b, c});
    } else {
      ++dropped;
    }
  }
  return faces;
}

// The cleaned input: welded, without degenerate and duplicate faces, on the vertices its faces
// use.
struct CleanMesh {
  Mesh mesh;
  std::vector<int> vertex_of;  ///< #V_in: each input vertex's vertex in mesh, -1 if unused
};

// Welds Vn (#V by 3, normalized) over the faces F and drops the faces that then degenerate,
// counting both in `report`. Throws when fewer than 4 faces are left.
CleanMesh weld_and_clean(const Vertices& Vn, const Faces& F, double weld_tolerance,
                         ThrottledProgress& poll, MeshReport& report) {
  const int nv = static_cast<int>(Vn.rows());
  poll(0.01);
  const std::vector<char> on_border = border_vertices(nv, F, poll);
  poll(0.02);
  const std::vector<int> rep_of =
      weld_border_vertices(Vn, on_border, weld_tolerance, poll, report.welded_vertices);
  const auto faces = clean_faces(Vn, F, rep_of, poll, report.dropped_faces);
  if (faces.size() < 4) {
    throw InputError("fewer than 4 faces are left after welding and dropping degenerate faces (" +
                     std::to_string(faces.size()) + ")");
  }
  CleanMesh clean;
  std::vector<int> index;
  clean.mesh = internal::compact_mesh(Vn, faces, &index);
  clean.vertex_of.resize(nv);
  for (int i = 0; i < nv; ++i) clean.vertex_of[i] = index[rep_of[i]];
  return clean;
}

// --- analyze, orient, repair --------------------------------------------------------------------

// What is wrong with a mesh that is not a single closed manifold, for the error message.
std::string problem_list(const MeshReport& r) {
  std::string s;
  auto add = [&](const std::string& part) { s += (s.empty() ? "" : ", ") + part; };
  if (r.border_edges) {
    add(std::to_string(r.border_edges) + " border edges (holes, " + std::to_string(r.border_loops) +
        " border loops)");
  }
  if (r.non_manifold_edges) add(std::to_string(r.non_manifold_edges) + " non-manifold edges");
  if (r.non_manifold_vertices) {
    add(std::to_string(r.non_manifold_vertices) + " non-manifold vertices");
  }
  if (!r.orientable) add("a non-orientable surface");
  if (r.components > 1) add(std::to_string(r.components) + " components");
  return s;
}

// Analyzes the topology of `mesh`, orients its faces outward (in place) and fills `report`.
// Returns whether it is a single closed manifold; throws when it is one that encloses no volume.
bool analyze_and_orient(Mesh& mesh, ThrottledProgress& poll, MeshReport& report,
                        double& largest_hole) {
  poll(0.06);
  const auto tick = [&] { poll(0.08); };
  const internal::Topology topo = internal::analyze_topology(mesh.V, mesh.F, tick);
  const internal::Orientation orientation = internal::orient_outward(mesh.V, mesh.F, topo, tick);
  poll(0.1);
  report.border_edges = topo.border_edges;
  report.border_loops = topo.border_loops;
  report.non_manifold_edges = topo.non_manifold_edges;
  report.non_manifold_vertices = topo.non_manifold_vertices;
  report.components = topo.components;
  report.orientable = orientation.orientable;
  largest_hole = topo.largest_hole;
  const bool closed = report.closed_manifold() && report.components <= 1;
  // A closed manifold whose faces fold flat onto each other (found by fuzzing: an octahedron
  // with its centre on an edge) encloses no volume, and CGAL's isotropic remeshing crashes on it
  // (SEGV in tangential_relaxation). Its vertices are not in one plane, so reject_flat lets it
  // through; the enclosed volume (in normalized units, so a real shape has about 1e-3 or more)
  // tells.
  if (closed && !(orientation.enclosed_volume > 1e-10)) {
    throw InputError(
        "the mesh encloses no volume: it is closed, but its faces lie flat on "
        "each other");
  }
  return closed;
}

// Makes out.working the alpha wrap of `mesh` (alpha and offset in normalized units).
void wrap(const Mesh& mesh, double alpha, ThrottledProgress& poll, PreparedMesh& out) {
  out.working = internal::alpha_wrap(mesh, alpha, alpha / 30.0, poll.part(0.1, 0.3));
  out.repaired = true;
  out.wrap_alpha = alpha;
}

// out.working = the union of the closed parts of `mesh` (union.h), a part that crosses itself
// replaced by its alpha wrap at `alpha` (the size the caller would wrap all of `mesh` at, were
// the union to fail: a tiny noise, or a float32 rounding, makes a part cross itself where faces
// nearly touch, and the whole wrap smoothed every part's details away for it); false when they
// are not all closed solids or the union fails.
bool unite_closed_parts(const Mesh& mesh, double alpha, ThrottledProgress& poll,
                        PreparedMesh& out) {
  const internal::PartWrap rewrap = [&](const Mesh& part) {
    return internal::alpha_wrap(part, alpha, alpha / 30.0, poll.part(0.1, 0.3));
  };
  std::optional<internal::United> united =
      internal::union_of_closed_parts(mesh, poll.part(0.1, 0.3), rewrap);
  if (!united) return false;
  out.working = std::move(united->mesh);
  out.report.cavities = united->cavities;
  out.report.wrapped_parts = united->rewrapped;
  out.report.part_wrap_alpha = united->rewrapped > 0 ? alpha : 0.0;
  out.repaired = true;
  return true;
}

// unite_closed_parts of a mesh that a repair step made, once it has checked that every edge has
// two faces and oriented it (in place).
bool orient_and_unite(Mesh& mesh, double alpha, ThrottledProgress& poll, PreparedMesh& out) {
  const internal::Topology topo = internal::analyze_topology(mesh.V, mesh.F);
  if (topo.border_edges != 0 || topo.non_manifold_edges != 0) return false;
  if (!internal::orient_outward(mesh.V, mesh.F, topo).orientable) return false;
  return unite_closed_parts(mesh, alpha, poll, out);
}

// The union of what is left of `mesh` without its fins and inner walls (fins.h), when that is
// closed parts that orient consistently; out.report.fin_faces counts the faces left out.
bool unite_without_fins(const Mesh& mesh, double alpha, ThrottledProgress& poll,
                        PreparedMesh& out) {
  std::optional<internal::FinlessMesh> finless = internal::drop_fins(mesh, [&] { poll(0.1); });
  if (!finless || !orient_and_unite(finless->mesh, alpha, poll, out)) return false;
  out.report.fin_faces = finless->dropped_faces;
  return true;
}

// Holes that stage 0 fills (above either, the mesh is wrapped): bounding-box diagonal (of the
// mesh's diagonal, which is 1 here) and edges of the border loop.
constexpr double kMaxFilledHole = 0.1;
constexpr int kMaxFilledHoleEdges = 256;

// The wrap of a mesh whose holes were filled (in normalized units). Not the 1/100 of other
// wraps: on the two inputs that take it, 1/100 (16,618 and 7,790 faces) took wolf-open (10k
// faces) 1.5 s and Q_Male_Casual 0.61 s, 2/100 0.70 and 0.22 s with the same ends (6 and 5),
// joints and inside share (99.5 and 100%); 3/100 lost an end of the wolf. The wrap sized to
// their holes (4.1 and 4.3/100) webbed the legs together: 4 ends each, and 64% of Q_Male_Casual's
// skeleton outside it.
constexpr double kFilledWrapAlpha = 0.02;

// Once each hole of `mesh` is small (largest_hole: the largest one's bounding-box diagonal, at
// most kMaxFilledHole; and kMaxFilledHoleEdges) and filled: the union of its closed parts, else
// (the parts cross) the wrap of the filled mesh at kFilledWrapAlpha; out.report.filled_holes
// counts the holes. False when the holes are too large or cannot be filled.
bool close_small_holes(const Mesh& mesh, double largest_hole, ThrottledProgress& poll,
                       PreparedMesh& out) {
  if (largest_hole > kMaxFilledHole) return false;
  std::optional<internal::FilledMesh> filled = internal::fill_holes(mesh, kMaxFilledHoleEdges);
  poll(0.1);
  if (!filled) return false;
  Mesh oriented = filled->mesh;  // orient_and_unite orients it in place
  if (!orient_and_unite(oriented, kFilledWrapAlpha, poll, out))
    wrap(filled->mesh, kFilledWrapAlpha, poll, out);
  out.report.filled_holes = filled->holes;
  return true;
}

// out.working: `clean` itself when it is a single closed manifold, else (Repair::Auto) its alpha
// wrap, sized to the largest hole (see the top of this file); Repair::None throws instead.
void make_working_mesh(Mesh clean, bool closed, double largest_hole, const PrepareOptions& options,
                       ThrottledProgress& poll, PreparedMesh& out) {
  if (closed) {
    out.working = std::move(clean);
    return;
  }
  if (options.repair == Repair::None) {
    throw InputError("the mesh is not a single closed manifold: " + problem_list(out.report) +
                     "; use repair='auto' to wrap it into a closed proxy");
  }
  const MeshReport& r = out.report;
  double alpha = std::clamp(0.6 * largest_hole, 0.01, 0.1);  // of the wrap if all else fails
  if (r.border_edges == 0) alpha = 0.01;
  if (r.border_edges == 0 && r.non_manifold_edges == 0 && r.orientable) {
    // Only several parts or pinched vertices: the union of the parts when each is a closed solid.
    if (unite_closed_parts(clean, alpha, poll, out)) return;
  }
  if (r.non_manifold_edges > 0 && unite_without_fins(clean, alpha, poll, out)) return;
  if (r.border_edges > 0 && r.non_manifold_edges == 0 &&
      close_small_holes(clean, largest_hole, poll, out))
    return;
  wrap(clean, alpha, poll, out);
}

// --- remesh -------------------------------------------------------------------------------------

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

// The face count to remesh `mesh` to, or 0 to keep it as it is (see PrepareOptions::upsample).
// options.target_faces > 0.
int remesh_target(const Mesh& mesh, const PrepareOptions& options) {
  const double nf = static_cast<double>(mesh.F.rows());
  const int target = options.target_faces;
  const bool small = small_for_target(nf, target), large = nf > kNearTarget * target;
  if (options.upsample) {
    // Kept only near the target size and with even edge lengths.
    const bool keep = !small && !large && edge_length_variation(mesh.V, mesh.F) < 0.5;
    return keep ? 0 : target;
  }
  if (large) return target;
  // Not larger than the target: kept, unless it is tiny or its triangles are very uneven (then
  // remeshed, a small input only to kSmallRemeshFaces). The public meshes of 898 to 12,000 faces
  // give the same skeletons from their own faces as remeshed to 20,000, at a fraction of the
  // cost.
  const bool keep =
      nf >= kMinKeptFaces && edge_length_variation(mesh.V, mesh.F) < kMaxKeptVariation;
  if (keep) return 0;
  return small ? std::min(target, kSmallRemeshFaces) : target;
}

// One flat fold is enough for the remeshing to crash (fuzzing again: two faces folded onto each
// other on a pyramid that does enclose a volume): a closed input to be remeshed that has one is
// wrapped like a broken one first, or refused with Repair::None. (Kept as it is, a fold does no
// harm: two vertices of a closed mesh moved onto each other make one.)
void wrap_flat_folds(const PrepareOptions& options, ThrottledProgress& poll, PreparedMesh& out) {
  const int folds = internal::folded_edges(out.working);
  if (folds == 0) return;
  if (options.repair == Repair::None) {
    throw InputError("the surface folds flat onto itself at " + std::to_string(folds) +
                     " edge(s) (two faces lie on each other), which the remeshing cannot "
                     "take; use repair='auto' to wrap it into a closed proxy");
  }
  wrap(out.working, 0.01, poll, out);
}

// The face count fast_reduce takes a mesh of `nf` faces to before remesh_uniform remeshes it to
// `target`, or 0 for none.
// - More than 3 x the target: 1.5 x (CGAL's quality collapse in remesh_uniform then has nothing
//   left to do): that collapse cost 1.3 s of the horse's (97k faces) 1.8 s stage 0, fast_reduce
//   0.1 s, with the same skeleton's ends, joints and stability, the isotropic remeshing after it
//   evening the triangles out either way.
// - Above the target with uneven edges (variation kMaxKeptVariation or more): 0.6 x. The
//   isotropic remeshing splits every edge longer than 4/3 L in two before it collapses those
//   under 4/5 L, so an uneven mesh is first refined where it is coarse, and the halves of many
//   of those splits, with the fine parts, are then collapsed again: biped-30k's union (23k faces,
//   variation 1.7) took 41,555 splits and 40,403 collapses in the first of 3 iterations (300 of
//   its 440 ms). The shortest edges collapsed first, it takes 22,682 and 16,129 (remeshing 245
//   ms), quadruped-100k's stage 0 1.61 -> 1.27 s, with the same ends and joints (0.4 x and 0.8 x
//   saved less). Not below the target: Mannequiny (17k faces, variation 1.05) gained nothing.
int fast_reduce_goal(double nf, const Mesh& mesh, int target) {
  const int large_goal = static_cast<int>(1.5 * std::max(target, internal::kMinRemeshFaces));
  if (nf > target && edge_length_variation(mesh.V, mesh.F) >= kMaxKeptVariation) {
    return std::max(static_cast<int>(0.6 * target), internal::kMinRemeshFaces);
  }
  return nf > 2.0 * large_goal ? large_goal : 0;
}

// Remeshes out.working to a uniform mesh of about target_faces triangles unless remesh_target
// keeps it, reduced first by fast_reduce as fast_reduce_goal says.
void remesh_to_target(const PrepareOptions& options, ThrottledProgress& poll, PreparedMesh& out) {
  // The mesh before any fold wrap decides on the fast reduction.
  const double nf = static_cast<double>(out.working.F.rows());
  const int target = remesh_target(out.working, options);
  if (target == 0) return;
  const int goal = fast_reduce_goal(nf, out.working, target);
  if (out.wrap_alpha == 0) wrap_flat_folds(options, poll, out);  // not a wrap (maybe a union)
  if (out.repaired && out.wrap_alpha == 0) out.united = out.working;
  if (goal > 0) out.working = internal::fast_reduce(out.working, goal, poll.part(0.3, 0.5));
  out.working = internal::remesh_uniform(out.working, target, poll.part(0.5, 0.85));
  out.remeshed = true;
}

// --- map back -----------------------------------------------------------------------------------

// #V of W: one corner (3 x face + k) of a face using each vertex, its first; -1 when unused.
std::vector<int> first_corners(const Mesh& W) {
  std::vector<int> corner(W.V.rows(), -1);
  for (int f = 0; f < W.F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      if (corner[W.F(f, k)] < 0) corner[W.F(f, k)] = 3 * f + k;
  return corner;
}

// Maps every input vertex (Vn, #V_in by 3, normalized) to out.working: onto its own corner when
// the working mesh is the cleaned input (vertex_of), else to its closest point on out.query (in
// parallel, in chunks polled between: the callback is not called from TBB's workers).
void map_input_vertices(const Vertices& Vn, const std::vector<int>& vertex_of,
                        ThrottledProgress& poll, PreparedMesh& out) {
  const int nv = static_cast<int>(Vn.rows());
  const Mesh& W = out.working;
  out.map_face.resize(nv);
  out.map_barycentric.resize(nv, 3);
  const bool same = !out.repaired && !out.remeshed;
  const std::vector<int> corner = same ? first_corners(W) : std::vector<int>();
  const SurfaceQuery* query = out.query.get();  // null when every vertex is referenced
  constexpr int kChunk = 1 << 15;
  for (int chunk = 0; chunk < nv; chunk += kChunk) {
    poll(0.87 + 0.13 * chunk / nv);
    tbb::parallel_for(tbb::blocked_range<int>(chunk, std::min(nv, chunk + kChunk), 1024),
                      [&](const tbb::blocked_range<int>& r) {
                        for (int i = r.begin(); i != r.end(); ++i) {
                          const int c = same ? vertex_of[i] : -1;
                          if (c >= 0) {
                            out.map_face[i] = corner[c] / 3;
                            out.map_barycentric.row(i).setZero();
                            out.map_barycentric(i, corner[c] % 3) = 1.0;
                            continue;
                          }
                          int f = 0;
                          const Eigen::Vector3d q = query->closest_point(Vn.row(i).transpose(), &f);
                          out.map_face[i] = f;
                          out.map_barycentric.row(i) =
                              internal::face_barycentric(W, f, q).transpose();
                        }
                      });
  }
}

// The steps prepare_mesh and prepare_input share: validate, normalize (scale and offset into
// `out`), reject a flat input (when `reject_flat_input`), weld and clean, analyze and orient.
struct Cleaned {
  Vertices Vn;  // the input's vertices, normalized
  CleanMesh clean;
  bool closed = false;  // a single closed manifold
  double largest_hole = 0;
};

Cleaned clean_input(const Vertices& V_in, const Faces& F_in, const PrepareOptions& options,
                    bool reject_flat_input, ThrottledProgress& poll, PreparedMesh& out) {
  poll(0);
  validate_input(V_in, F_in, options);
  out.report.input_vertices = static_cast<int>(V_in.rows());
  out.report.input_faces = static_cast<int>(F_in.rows());
  Cleaned c;
  c.Vn = normalize(V_in, poll, out);
  if (reject_flat_input) reject_flat(c.Vn);
  c.clean = weld_and_clean(c.Vn, F_in, options.weld_tolerance, poll, out.report);
  c.closed = analyze_and_orient(c.clean.mesh, poll, out.report, c.largest_hole);
  return c;
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
                         std::to_string(F(f, k)) + " out of range [0, " + std::to_string(V.rows()) +
                         ")");
      }
    }
  }
}

PreparedMesh prepare_mesh(const Vertices& V_in, const Faces& F_in, const PrepareOptions& options,
                          const Progress& progress, double from, double to) {
  ThrottledProgress poll(progress, "prepare", from, to);
  PreparedMesh out;
  Cleaned c = clean_input(V_in, F_in, options, true, poll, out);
  make_working_mesh(std::move(c.clean.mesh), c.closed, c.largest_hole, options, poll, out);
  if (options.target_faces > 0) remesh_to_target(options, poll, out);
  poll(0.85);
  out.genus = mesh_genus(out.working);
  out.query = std::make_shared<const SurfaceQuery>(out.working, [&] { poll(0.86); });
  map_input_vertices(c.Vn, c.clean.vertex_of, poll, out);
  poll(1);
  return out;
}

PreparedMesh prepare_input(const Vertices& V_in, const Faces& F_in, const PrepareOptions& options,
                           const Progress& progress, double from, double to) {
  ThrottledProgress poll(progress, "prepare", from, to);
  PreparedMesh out;
  Cleaned c = clean_input(V_in, F_in, options, false, poll, out);
  out.working = std::move(c.clean.mesh);
  out.genus = mesh_genus(out.working);
  // Only input vertices in no face need the closest-point query: built for them alone.
  const auto& vertex_of = c.clean.vertex_of;
  if (std::any_of(vertex_of.begin(), vertex_of.end(), [](int v) { return v < 0; })) {
    out.query = std::make_shared<const SurfaceQuery>(out.working, [&] { poll(0.86); });
  }
  map_input_vertices(c.Vn, vertex_of, poll, out);
  poll(1);
  return out;
}

}  // namespace dcg

// Stage 0 (ALGORITHM.md "Prepare"): from the user's V, F to a closed, oriented, uniform working
// mesh in normalized units (bounding-box diagonal 1), with a map back to the input vertices.
#pragma once

#include <memory>
#include <string>

#include <Eigen/Core>

#include "dcg/progress.h"
#include "dcg/types.h"

namespace dcg {

class SurfaceQuery;

enum class Repair {
  Auto,  ///< not a closed manifold -> closed parts united, else a proxy by CGAL alpha_wrap_3
  None,  ///< not a closed manifold -> InputError naming the problem
};

struct PrepareOptions {
  Repair repair = Repair::Auto;
  /// Uniform remeshing target (triangles of the working mesh); 0 keeps the welded input.
  int target_faces = 20000;
  /// true: every input is remeshed to target_faces unless it already has between 1/2.5 and 2.5
  /// times as many faces with even edge lengths (coefficient of variation below 0.5). false:
  /// inputs of at most 2.5 x target_faces faces are kept as they are when they have at least
  /// kMinKeptFaces faces with a variation below kMaxKeptVariation, so that small inputs cost
  /// little (else remeshed; one under target_faces / 2.5 only to kSmallRemeshFaces).
  bool upsample = false;
  /// Vertices closer than this (normalized units) are welded.
  double weld_tolerance = 1e-7;
  /// Seed for every randomized step of the stage.
  unsigned seed = kDefaultSeed;
};

/// An input with fewer than target_faces / kNearTarget faces is small (see upsample), one with
/// more than kNearTarget x target_faces large.
constexpr double kNearTarget = 2.5;
/// Whether a mesh of `faces` faces is small for `target_faces` (never when that is 0).
inline bool small_for_target(double faces, int target_faces) {
  return faces * kNearTarget < target_faces;
}

/// With upsample off (PrepareOptions::upsample).
constexpr int kMinKeptFaces = 800;
constexpr double kMaxKeptVariation = 1.0;
constexpr int kSmallRemeshFaces = 4000;

/// What stage 0 found in the input (after welding and dropping degenerate faces).
struct MeshReport {
  int input_vertices = 0;
  int input_faces = 0;
  int welded_vertices = 0;        ///< vertices merged into others
  int dropped_faces = 0;          ///< degenerate (zero-area, repeated index) or duplicate faces
  int border_edges = 0;           ///< edges with one incident face
  int border_loops = 0;           ///< connected sets of border edges (holes)
  int non_manifold_edges = 0;     ///< edges with more than two incident faces
  int non_manifold_vertices = 0;  ///< vertices whose faces form several fans (pinched)
  int components = 0;             ///< connected components (over shared edges)
  bool orientable = true;         ///< faces can be oriented consistently over shared edges
  /// Faces of zero-volume fins and inner walls (hung on closed parts along non-manifold edges)
  /// left out of the working mesh, which is then the union of those parts (no wrap).
  int fin_faces = 0;
  /// Holes (border loops) triangulated to close the mesh, which is then the union of its parts
  /// (no wrap): only when every hole is small.
  int filled_holes = 0;
  /// Voids enclosed by the parts once united (not by any one part), filled: their inner shells
  /// are left out of the working mesh.
  int cavities = 0;
  /// Parts that crossed themselves where they were to be united with others, each replaced by
  /// its alpha wrap (at part_wrap_alpha, normalized; 0 when none) before the union.
  int wrapped_parts = 0;
  double part_wrap_alpha = 0;
  bool closed_manifold() const {
    return border_edges == 0 && non_manifold_edges == 0 && non_manifold_vertices == 0 && orientable;
  }
};

struct PreparedMesh {
  /// The working mesh, normalized: input = working * scale + offset.
  Mesh working;
  double scale = 1.0;
  Eigen::RowVector3d offset = Eigen::RowVector3d::Zero();
  MeshReport report;
  /// The working mesh is a repaired proxy of the input: the union of its closed parts
  /// (wrap_alpha 0) or its alpha wrap.
  bool repaired = false;
  double wrap_alpha = 0;  ///< alpha of the wrap when wrapped (normalized units), else 0
  bool remeshed = false;  ///< the working mesh was remeshed (false: the input was kept)
  /// The union of the input's closed parts before it was remeshed, when the working mesh is that
  /// union remeshed (else empty): the input's own surface, which keep_inside_input holds the
  /// skeleton in (the remeshed one bulges out of it a little at concave places).
  Mesh united;
  int genus = 0;  ///< total genus of the working mesh, from its Euler characteristic
  /// Map from each input vertex to the working mesh: #V_in face indices into working.F and
  /// #V_in by 3 barycentric coordinates of the closest working-mesh point. When the working
  /// mesh is the cleaned input itself, a vertex maps exactly onto its own corner.
  Eigen::VectorXi map_face;
  Vertices map_barycentric;
  /// Closest-point / inside queries on `working`, built once here and shared by later stages.
  std::shared_ptr<const SurfaceQuery> query;

  /// Normalized -> input coordinates.
  Eigen::RowVector3d to_input(const Eigen::RowVector3d& p) const { return p * scale + offset; }
};

/// Checks V, F without changing them: finite coordinates, at least 4 vertices and 4 faces,
/// indices in range. Throws InputError with the reason (which face, which index, ...).
void validate_mesh(const Vertices& V, const Faces& F);

/// Runs stage 0. Throws InputError for invalid input (see validate_mesh; also a mesh whose
/// vertices all lie in one plane, or that has fewer than 4 faces left after dropping degenerate
/// ones), or when the mesh is not a single closed manifold and options.repair is Repair::None
/// (the message gives border edges and loops, non-manifold edges and vertices, components).
/// Progress as stage "prepare" (also from inside the CGAL steps), see dcg/progress.h.
PreparedMesh prepare_mesh(const Vertices& V, const Faces& F, const PrepareOptions& options = {},
                          const Progress& progress = {}, double from = 0, double to = 1);

/// Stage 0's cleaning only, for work done on the input itself (the weights): validate, normalize,
/// weld cracks, drop degenerate and duplicate faces, orient; then the working mesh is that
/// cleaned input whatever it is (open, several parts, non-manifold, flat: nothing is repaired or
/// remeshed, repaired and remeshed stay false) and every input vertex maps onto its own corner.
/// `query` is built only when some input vertex is in no face (it maps to its closest point).
/// Throws InputError (validate_mesh; fewer than 4 faces left), Cancelled.
PreparedMesh prepare_input(const Vertices& V, const Faces& F, const PrepareOptions& options = {},
                           const Progress& progress = Progress(), double from = 0, double to = 0);

/// Genus from the Euler characteristic, summed over the connected components of (V, F):
/// V - E + F = 2 - 2g per closed component.
int mesh_genus(const Mesh& mesh);

}  // namespace dcg

// Stage 9 (ALGORITHM.md "Weights", beyond the paper): skinning weights by bone heat, computed on
// the input mesh itself (welded; per connected part, each with the bones it sees) or, for a large
// input, on the working mesh of stage 0 and carried to the input vertices through its map; open,
// multi-part and non-manifold inputs are weighted everywhere, at any scale.
//
// Bone heat (Baran & Popovic 2007, "Automatic rigging and animation of 3D characters"), with
// the details of Blender's implementation (meshlaplacian.cc), which deforms closer to artists'
// weights than the paper's plain form: the weights w_i of bone i on the mesh solve
//
//     (-L + M H) w_i = M H p_i
//
// L  #W by #W cotangent Laplacian (L_jk = (cot a + cot b) / 2, rows summing to 0),
// M  #W diagonal mixed Voronoi vertex areas (Meyer et al. 2003; they sum to the surface area),
// H  #W diagonal heat: H_j = k c / d_j^2 for the k bones tied nearest to vertex j (each gets the
//    full heat), d_j = |x_j - q| / ((1.001 + cos) / 2), q the closest point of the bone, cos the
//    cosine between x_j - q and the vertex normal: a bone behind the surface (the normal points
//    towards it) counts as far,
// p_i  #W 1/k where bone i is one of those k nearest bones, else 0.
//
// Which bones heat a vertex, per connected part of the mesh, strictest rule first: the nearest
// bones if *visible* (the segment from the vertex to q crosses no surface; where the vertex's
// part is closed and holds the bone's head, no surface but that part's faces crossed from
// behind, as Blender's back-face culling: the end of a leaf bone that pokes out of a hand; a
// hidden nearest bone leaves the vertex unheated, as in Blender); for a part where that heats no
// vertex, the nearest visible bones; for a part that sees no bone at all, the nearest bones
// through the volume (plain distance), so that the system is never singular (Blender fails
// there).
// (M^-1 L is the paper's area-normalized Laplacian; multiplying by M makes the matrix
// symmetric positive definite, so one sparse Cholesky factorization (LDL^T) serves every bone.)
// Two rules of rigs beyond Blender's (measured against artists' weights, weights.cpp):
// - a leaf bone that stops short of the head of a bone it points at, with the shape's inside
//   between them, reaches that head for the distances above (a shin ending above an IK foot
//   that hangs from the root: the ankle follows the shin);
// - a closed part that holds no bone (an eye, a brow, a tooth) moves rigidly with one bone: the
//   one that weighs most on the other parts' surface where it is attached.
// An unheated vertex gets whatever diffuses to it along the surface from its neighbours. Since
// the p_i sum to 1 wherever H > 0, the w_i sum to 1 everywhere; small negative values (obtuse
// triangles) are clipped.
//
// Everything runs in normalized units (bounding-box diagonal 1), so the result does not depend
// on the input's scale: Blender's bone heat fails on small meshes, this does not.
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "dcg/prepare.h"
#include "dcg/progress.h"
#include "dcg/types.h"

namespace dcg {

struct Options;  // dcg/options.h

struct WeightsOptions {
  /// Largest number of bones weighting one input vertex (the strongest are kept, then the row is
  /// renormalized). Blender's Armature modifier takes any number; game engines want 4.
  int max_influences = 4;
  /// c of H = c / d^2: larger values bind vertices more rigidly to their nearest bone, smaller
  /// ones blend more widely. Baran & Popovic use 1 with M^-1 L; Blender's bone heat uses 1 with
  /// L / (4 M), which is 4 here, and 4 also measures best against artists' weights (mean L1 on
  /// the rigged characters: 0.42 at 2, 0.40 at 4, 0.42 at 8).
  double heat = 4.0;
  /// Faint weights fade out: a weight w below min_weight becomes (w - m/2) / (m/2) * m with
  /// m = min_weight, and 0 below m/2 (Blender's bone heat does the same with 0.05), so far
  /// influences vanish without a visible step. The strongest bone of a vertex is always kept.
  double min_weight = 0.05;
  /// A vertex's other bones lie within this many links of its strongest bone in the bone tree
  /// (Bones::parents), unless they weigh at least far_weight; 0: no limit. Heat leaks between
  /// parts that touch or lie close (a coiled snake's turns, a hand at a thigh): on the rigged
  /// characters, 3 raises the precision against the artists' weights from 82% to 86% (Q_Snake
  /// 46% -> 91%) and lowers the mean deformation error from 0.76 to 0.67% (1 and 2 lose recall:
  /// artists blend over three bones of a chain).
  int bone_reach = 3;
  /// Bones beyond bone_reach keep their weight from this weight up.
  double far_weight = 0.1;
  /// Bones within this relative distance of the nearest visible one count as equally near
  /// (p = 1/k), as in Pinocchio: a vertex at a joint lies as near to both bones there. On the
  /// rigged characters, 3e-4 and 1e-3 deform closest to the artists' weights (mean error
  /// 0.6663%, against 0.6668 at Blender's 1e-4, 0.6750 at 0, 0.6682 at 3e-3, 0.7715 at 0.1).
  double tie_tolerance = 3e-4;
  /// Throws InputError naming the first option out of range.
  void validate() const;
};

/// The bones weights are computed for: segments from heads to tails, in the coordinates of the
/// mesh they weight (the input's for compute_skin_weights; Blender's world space in the add-on).
struct Bones {
  Points heads;  ///< #B by 3 bone heads
  Points tails;  ///< #B by 3 bone tails
  /// #B parent bone of each bone, -1 at a root; empty: a bone's parent is the first bone whose
  /// tail is at its head (within 1e-9 of the bones' extent), else none.
  Eigen::VectorXi parents;
  /// #B 0 for a bone that takes no weight (a control: the root on the floor), else 1; empty:
  /// every bone deforms. compute_skin_weights and BoneHeat::solve solve for the deforming bones
  /// alone (a control's parent role passes to its nearest deforming ancestor) and keep the
  /// bones' numbering (a control's column is empty).
  std::vector<char> deform;
  Eigen::Index count() const { return heads.rows(); }
};

/// Per-vertex bone weights as sparse triplets, sorted by vertex then by decreasing weight. Every
/// vertex has between 1 and max_influences entries, positive, summing to 1.
struct SkinWeights {
  Eigen::VectorXi rows;    ///< #E vertex index of each entry (input vertices)
  Eigen::VectorXi cols;    ///< #E bone index of each entry
  Eigen::VectorXd values;  ///< #E weight of each entry, in (0, 1]
  int vertex_count = 0;    ///< #V the rows index into
  int bone_count = 0;      ///< #B the cols index into
  // What happened, as data (ALGORITHM.md: failures are reported, never silent).
  int working_vertices = 0;   ///< vertices the heat was solved on (the welded input's, or
                              ///<    the working mesh's for a large input)
  int unseen_vertices = 0;    ///< working vertices that saw no bone (weights by diffusion)
  int blind_components = 0;   ///< working-mesh parts that saw no bone at all (nearest bone used)
  int rigid_parts = 0;        ///< working-mesh parts that hold no bone, moved rigidly with the
                              ///<    bone of the surface they are attached to (eyes, teeth)
  int fallback_vertices = 0;  ///< input vertices whose interpolated weights were all <= 0
                              ///< (given their nearest bone instead; should be 0)
  /// Seconds per step ("prepare" when stage 0 ran here, "laplacian", "visibility", "factor",
  /// "solve", "accessories", "transfer"), then "total".
  std::vector<std::pair<std::string, double>> timings;

  /// The weights as a dense #V by #B matrix (tests, small meshes).
  Eigen::MatrixXd dense() const;
};

/// Bone heat on a closed mesh, the reusable part: the cotangent Laplacian, the vertex areas and
/// the ray-tracing structure are built once; solve() then takes any set of bones (an interactive
/// bone-detail slider re-solves without rebuilding). Not thread-safe; solve() is parallel inside.
class BoneHeat {
 public:
  /// `mesh` in any units (the working mesh of stage 0: normalized units, closed, oriented).
  /// InputError when it has no faces or an index out of range.
  explicit BoneHeat(const Mesh& mesh);
  ~BoneHeat();
  BoneHeat(BoneHeat&&) noexcept;
  BoneHeat& operator=(BoneHeat&&) noexcept;

  /// What solve() found besides the weights.
  struct Report {
    int unseen_vertices = 0;
    int blind_components = 0;
    int rigid_parts = 0;
    /// "visibility", "factor", "solve", "accessories"
    std::vector<std::pair<std::string, double>> timings;
  };

  /// #V by #B weights of the mesh's vertices for `bones` (in the mesh's coordinates), clipped to
  /// [0, 1]; each row sums to about 1 (exactly 1 before clipping). `report` (if set) gets what
  /// it found besides. Progress as stage "weights", see dcg/progress.h. Throws Cancelled,
  /// InputError (no bones, a non-finite coordinate).
  Eigen::MatrixXd solve(const Bones& bones, const WeightsOptions& options = {},
                        Report* report = nullptr, const Progress& progress = {}, double from = 0,
                        double to = 1) const;

  /// The cotangent Laplacian L (#V by #V, negative semi-definite, rows summing to 0).
  const Eigen::SparseMatrix<double>& laplacian() const;
  /// The #V mixed Voronoi vertex areas (Meyer et al. 2003; they sum to the surface area).
  const Eigen::VectorXd& areas() const;
  /// Index of the nearest visible bone of each vertex (-1: sees none) and the distance to it
  /// (the normal-weighted d of the equations; infinity when none), ties resolved to the lowest
  /// index.
  void nearest_visible_bones(const Bones& bones, Eigen::VectorXi& bone,
                             Eigen::VectorXd& distance) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Skinning weights of the input vertices of `prepared` (stage 0's result) for `bones` in the
/// INPUT's coordinates: bone heat on the working mesh, interpolated at each input vertex's
/// mapped point (map_face, map_barycentric), then pruned to max_influences and normalized.
/// The weights are for #V = prepared.map_face.size() vertices. Throws InputError, Cancelled.
/// Progress as stage "weights", see dcg/progress.h.
SkinWeights compute_skin_weights(const PreparedMesh& prepared, const Bones& bones,
                                 const WeightsOptions& options = {}, const Progress& progress = {},
                                 double from = 0, double to = 1);

/// The same from the input mesh itself, with options.weights: bone heat on the input (stage 0's
/// cleaning only, prepare_input: welded cracks, no repair, no remeshing), each connected part
/// weighted by the bones it sees, as Blender's bone heat does, so that parts are never glued
/// together and the weights follow the artist's surface exactly. A large input (see
/// weights_on_working_mesh) is solved on stage 0's working mesh instead (prepare_mesh with
/// options.prepare_options(), the mesh the skeleton gets) and carried back through its map.
/// V #V by 3, F #F by 3 indices into V; bones in V's coordinates.
/// Progress as stages "prepare" (the first half of [from, to]) and "weights", see
/// dcg/progress.h (as for the overload above).
SkinWeights compute_skin_weights(const Vertices& V, const Faces& F, const Bones& bones,
                                 const Options& options, const Progress& progress = {},
                                 double from = 0, double to = 1);

/// Whether compute_skin_weights solves an input of `faces` faces on stage 0's working mesh: when
/// it has more than kNearTarget x target_faces faces (target_faces > 0), where one solve per
/// bone on every input vertex would cost more than the remeshed working mesh and the transfer.
bool weights_on_working_mesh(Eigen::Index faces, const PrepareOptions& options);

/// Distance from p to the segment a-b; `t` (if given) receives the parameter of the closest
/// point a + t (b - a), in [0, 1].
double point_segment_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                              const Eigen::Vector3d& b, double* t = nullptr);

}  // namespace dcg

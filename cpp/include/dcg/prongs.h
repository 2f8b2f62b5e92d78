// Stage 3 (ALGORITHM.md "Prong features", paper section 6): the scale function f on the working
// mesh and its prongs, the local maxima of f that a watershed with smoothness ratio tau keeps.
//
// Scale function (paper: f(v) = sum over all vertices v_i of geodesic(v, v_i), O(n^2)): here
// f(v) = sum_s w_s d(v, s) / sum_s w_s over `geodesic_sources` sources s picked by geodesic
// farthest-point sampling, w_s the area of the surface closer to s than to any other source
// (its geodesic Voronoi cell), d the Dijkstra distance along mesh edges. So f(v) is the mean
// geodesic distance from v to the surface, in the mesh's units; only ratios of f matter.
//
// Watershed: vertices visited by decreasing f grow regions (union-find). When regions meet at a
// vertex of value s (the valley), each one but the region of the highest peak ends there: its
// peak p gets the ratio s / p, its significance (lower = more significant). A peak is a prong at
// smoothness ratio tau when its ratio is below tau. The global maximum never meets a higher one:
// its ratio is min f / max f, and it is a prong when that is below tau AND its cap (the connected
// region with f >= tau * max f around it) is a disk (one boundary loop): a sphere's or a fat
// torus's cap is everything or a band (no prong), a capsule's end is a disk (2 prongs).
//
// Two tiers (as geometry-central): compute_prongs() for the default case, and ProngHierarchy
// that keeps every peak with its ratio, so that prongs(tau) for another tau costs O(#peaks) plus
// one flood fill of the global cap: no new geodesics.
#pragma once

#include <memory>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include <Eigen/Core>

#include "dcg/progress.h"
#include "dcg/types.h"

namespace dcg {

class SurfaceQuery;
namespace internal {
class VertexGrid;
}

struct ScaleFunctionOptions {
  /// Geodesic sources (ALGORITHM.md default 128). 0, or at least #V: every vertex is a source
  /// weighted by its own area (the exact O(n^2) sum).
  int geodesic_sources = 128;
  /// Picks the first source (then farthest-point sampling is deterministic).
  unsigned seed = kDefaultSeed;
};

struct ScaleFunction {
  Eigen::VectorXd values;   ///< #V f(v): area-weighted mean geodesic distance to the surface
  Eigen::VectorXi sources;  ///< #S source vertices
  Eigen::VectorXd weights;  ///< #S area each source stands for (sums to the mesh's area)
};

/// The sampled scale function on (V, F). Sources run in parallel (TBB); the result does not
/// depend on the number of threads. Throws InputError for an empty mesh or bad indices.
/// Progress as stage "prongs", see dcg/progress.h.
ScaleFunction compute_scale_function(const Mesh& mesh, const ScaleFunctionOptions& options = {},
                                     const Progress& progress = {}, double from = 0, double to = 1);

/// The exact O(n^2) sums, for tests and small meshes: f(v) = sum_i A_i d(v, v_i) / sum_i A_i with
/// A_i the vertex areas (area_weighted), or the paper's plain mean (1/n) sum_i d(v, v_i).
Eigen::VectorXd exact_scale_function(const Mesh& mesh, bool area_weighted = true);

/// Dijkstra distances along the edges of (V, F) from `source` to every vertex (infinity where
/// unreachable).
Eigen::VectorXd edge_geodesics(const Mesh& mesh, int source);

/// One local maximum of f and how it ends in the watershed.
struct Peak {
  int vertex = -1;      ///< the vertex holding the maximum
  double value = 0;     ///< f at the peak, p
  double valley = 0;    ///< f where its region met a region with a higher peak, s (global: min f)
  double ratio = 1;     ///< s / p: the significance (lower = stronger)
  bool global = false;  ///< the global maximum (also needs a disk-shaped cap to be a prong)
  int valley_vertex = -1;  ///< the vertex where its region ended (global: the lowest vertex)
  int partner = -1;        ///< the peak vertex of the region it ended in (-1 for a global maximum)
};

/// Prongs at one tau, strongest first.
struct Prongs {
  double tau = 0.85;             ///< the smoothness ratio they were selected with
  Eigen::VectorXi vertices;      ///< #P peak vertices in the mesh
  Points positions;              ///< #P by 3 peak positions (the mesh's units)
  Eigen::VectorXd significance;  ///< #P ratios valley / peak, increasing
  /// Of those, prongs kept as the mirror twin of a prong (ratio >= tau; see ProngHierarchy).
  int mirror_twins = 0;
  /// Of those, prongs kept as fingers of a hand (ratio >= tau; see ProngHierarchy).
  int fingers = 0;
  /// Of those, prongs moved from one of a pair (a horn, an ear) to the mirror plane between
  /// them (see ProngHierarchy).
  int midline = 0;
  /// Of those, prongs kept as a tail: a pointed tip on the mirror plane (see ProngHierarchy).
  int tails = 0;
};

/// The watershed of f, done once: every peak with its ratio. Re-thresholding is cheap.
///
/// Mirror twins: two limbs that mirror each other and stand close (a cow's hind legs) meet high
/// up, at the crotch, so the weaker one ends there with a ratio near 1 and only one of them
/// would be a prong, leaving the skeleton lopsided. A peak is also a prong, at any tau, when its
/// region ended in a prong's region (its partner) and it is that prong's mirror image: f within
/// kTwinValue of the partner's, its ratio below kTwinRatio, the plane halfway between the two
/// peaks a mirror plane of the whole mesh (mean distance from the mirrored vertices to the
/// mesh at most kTwinMirror of its bounding-box diagonal), and it is a limb, not a feature on
/// one (an ear beside an ear): its geodesic distance to the crotch at least kTwinLength times
/// the mean of f (f being the mean geodesic distance, that is the shape's own size), and so is
/// its partner's. (The crotch is a vertex where the two regions met, seldom on the plane: which
/// of Q_Goblin's ears was the twin, the one 0.07 from it or the one 0.15 from it, a noise of
/// 1e-5 of the diagonal decided, and with it whether its head got one end or one per ear.)
///
/// Fingers: a hand's fingers are small next to the body, so their ratios lie past tau (0.94 on
/// a character whose body is 30 finger lengths tall), with a horn's or an ear's. What tells
/// them apart is their shape and number: a finger is long and thin, and a hand has several
/// side by side. A peak is also a prong, at any tau, when its ratio is below kFingerRatio, its
/// region above its valley (or above the valley of a finger beside it that ended in its region:
/// its own finger, not both; at most kFingerVertices of the mesh) is at least kFingerAspect
/// times as long (from its base's centre to its farthest point) as its base is wide (the mean
/// distance of the base's vertices to their centre), and at least kFingerCount such peaks that
/// end in one prong's region stand within kFingerSpread lengths of each other; then also the
/// peaks beside them (within kFingerSpread lengths) at least kThumbAspect times as long as
/// wide (a thumb, shorter); then also the peaks that mirror one of those on the other hand
/// (f within kTwinValue, the plane halfway between the two a mirror plane of the whole mesh, as
/// for mirror twins), whatever their shape, since a noise moves a thumb's valley.
///
/// Midline: a head's highest point is often one of a pair, a horn or an ear (spot, cow.off,
/// armadillo.obj, Q_Goblin), whose twin stays below tau; the head's end then sits on one side of a
/// symmetric shape. A prong moves to the middle when it has such a twin (a peak whose region
/// ended in the prong's region, not kept, its ratio below kMidlineRatio, f within kTwinValue of
/// the prong's, the plane halfway between the two a mirror plane of the whole mesh as for
/// mirror twins): to the strongest other peak of its region on that plane (within kMidlinePlane
/// of half the pair's distance from it) whose ratio is below kMidlineRatio, a muzzle or a
/// snout. Without one it stays where it is.
///
/// Tails: a small tail is a weak peak (spot's, a flap at the rump: ratio 0.973), as weak as the
/// middle of a block's edge (fertility.off's base: 0.966). What tells them apart is where it
/// stands and its shape: between a pair of limbs, on their mirror plane, and pointed. A peak is
/// also a prong, at any tau, when its ratio is below kMidlineRatio, f at it is at least the mean
/// of f (an extremity, not a dimple of the body), its region ended in a prong's region that has a
/// mirror twin among the prongs (f within kTwinValue, the plane halfway between the two a mirror
/// plane of the whole mesh, as for mirror twins), it stands at least kTwinLength times the mean
/// of f from that prong's peak (not a bump beside a paw), it lies within kTailPlane diagonals of
/// that plane, and some disc around it (along the edges) of at most kTailRadius diagonals holds at
/// least kTailTip full turns of curvature: a point, not a ridge (Gauss-Bonnet). A nose
/// ends in the head's region, and the head has no twin: it stays out (homer.obj); so do a
/// cow's teats (off the plane) and a scan whose halves mirror each other too loosely
/// (horse.ply's tail stub).
class ProngHierarchy {
 public:
  ProngHierarchy() = default;
  /// mesh: V #V by 3, F #F by 3; f: #V scale function values. Throws InputError on size mismatch.
  /// Progress as stage "prongs", see dcg/progress.h.
  ProngHierarchy(const Mesh& mesh, const Eigen::VectorXd& f, const Progress& progress = {},
                 double from = 0, double to = 1);

  /// Every local maximum of f (plateaus count once), sorted by increasing ratio.
  const std::vector<Peak>& peaks() const { return peaks_; }
  /// The prongs at smoothness ratio tau (0 < tau <= 1).
  Prongs prongs(double tau) const;

  static constexpr double kTwinValue = 0.05;
  static constexpr double kTwinRatio = 0.9;
  static constexpr double kTwinMirror = 0.02;
  static constexpr double kTwinLength = 0.35;
  static constexpr double kFingerRatio = 0.99;
  static constexpr double kFingerVertices = 0.02;
  static constexpr double kFingerAspect = 4.0;
  static constexpr int kFingerCount = 2;
  static constexpr double kFingerSpread = 3.0;
  static constexpr double kThumbAspect = 2.0;
  static constexpr double kMidlineRatio = 0.98;
  static constexpr double kMidlinePlane = 0.25;
  static constexpr int kMidlineTwinTests = 4;  // mirror tests per prong (1000 samples each)
  static constexpr double kTailPlane = 0.02;
  static constexpr double kTailRadius = 0.04;
  static constexpr double kTailTip = 0.25;
  /// True when the cap {f >= tau * max f} around the global maximum has one boundary loop.
  bool global_cap_is_disk(double tau) const;

 private:
  bool cap_is_disk(int peak_vertex, double tau) const;
  bool is_mirror_twin(const Peak& twin, const Peak& partner) const;
  bool mirrors_mesh(int a, int b) const;  // the plane halfway between a and b mirrors it
  // Whether f at peak q is within kTwinValue of f at peak p (p's value the unit).
  bool as_high(const Peak& q, const Peak& p) const;
  // Whether q is p's mirror image: as_high, and the plane halfway between them mirrors the mesh.
  bool mirror_image(const Peak& q, const Peak& p) const;
  // The distance of vertex v from the plane halfway between vertices a and b (a != b).
  double off_halfway(int a, int b, int v) const;
  // The peaks past tau kept as fingers (see the class comment); `kept`: the prongs so far.
  std::vector<const Peak*> fingers(double tau, const std::vector<const Peak*>& kept) const;
  // The peaks past tau kept as tails (see the class comment); `kept`: the prongs so far.
  std::vector<const Peak*> tails(const std::vector<const Peak*>& kept) const;
  // The prongs of `kept` moved to the middle (see the class comment), in place; how many moved.
  int move_to_midline(std::vector<const Peak*>& kept) const;
  // The vertex of the prong (in `prong_vertices`) whose region `q`'s region ended in, following
  // partners; the last peak reached when none is a prong.
  int region_prong(const Peak& q, const std::unordered_set<int>& prong_vertices) const;

  Mesh mesh_;
  Eigen::VectorXd f_;
  std::vector<int> adjacency_start_, adjacency_;  // vertex -> neighbours (CSR)
  std::vector<Peak> peaks_;
  std::unordered_map<int, int> peak_at_;              // peak vertex -> index in peaks_
  std::shared_ptr<const internal::VertexGrid> grid_;  // mesh_'s vertices, for mirror tests
  int global_ = -1;                                   // index of the global peak in peaks_
};

/// The scale function's options (geodesic_sources, seed) and the prong threshold.
struct ProngOptions : ScaleFunctionOptions {
  double tau = 0.85;  ///< smoothness ratio: a peak is a prong when valley / peak < tau
};

/// Everything stage 3 computes.
struct ProngFeatures {
  ScaleFunction scale;
  ProngHierarchy hierarchy;
  Prongs prongs;  ///< at options.tau
};

/// Stage 3 on a closed working mesh (normalized units). Throws InputError for bad options.
/// Progress as stage "prongs" (the geodesics, then the watershed), see dcg/progress.h.
ProngFeatures compute_prongs(const Mesh& mesh, const ProngOptions& options = {},
                             const Progress& progress = {}, double from = 0, double to = 1);

}  // namespace dcg

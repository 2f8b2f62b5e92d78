// The whole DCG pipeline: options, a stepwise extractor (one method per stage, every result
// kept for inspection) and the one-call extract_skeleton().
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "dcg/connection_points.h"
#include "dcg/domain_balls.h"
#include "dcg/domain_graph.h"
#include "dcg/end_points.h"
#include "dcg/force_field.h"
#include "dcg/options.h"
#include "dcg/prepare.h"
#include "dcg/progress.h"
#include "dcg/prongs.h"
#include "dcg/remap.h"
#include "dcg/skeleton.h"
#include "dcg/symmetry.h"
#include "dcg/types.h"
#include "dcg/voronoi_balls.h"

namespace dcg {

class SurfaceQuery;

/// Runs the stages one at a time, keeping each result. A stage runs the ones it needs first;
/// asking twice returns the kept result. Not thread-safe (use one extractor per thread).
class Extractor {
 public:
  /// Validates V, F and the options (InputError) but computes nothing yet.
  Extractor(Vertices V, Faces F, Options options = {}, ProgressCallback progress = {});
  ~Extractor();

  const Options& options() const { return options_; }
  const Vertices& input_vertices() const { return V_; }
  const Faces& input_faces() const { return F_; }

  /// Stage 0: the working mesh (normalized units).
  const PreparedMesh& prepare();
  /// Stage 1: Voronoi balls (normalized units), without those whose center ray parity puts
  /// outside the working mesh (the sign of the distance is wrong near a fold of a noisy mesh).
  const Balls& voronoi_balls();
  /// Stage 2: domain balls (normalized units).
  const DomainBalls& domain_balls();
  /// Stage 3: scale function and prongs at options().tau (working-mesh vertices, normalized
  /// units). Needs stage 0 only.
  const ProngFeatures& prongs();
  /// Stage 3 re-thresholded at another smoothness ratio: no new geodesics (InputError for tau
  /// outside (0, 1]).
  Prongs prongs_at(double tau);
  /// A live tau: makes `tau` the extractor's smoothness ratio (options().prongs.tau). When stage
  /// 3 has run, its prongs are re-thresholded (no new geodesics) and the stages that follow from
  /// them are dropped: end_points(), domain_graph(), remap() and skeleton() compute again at the
  /// next call, from the kept stages 0-2, 4 and 5. References to the dropped results become
  /// invalid. InputError for tau outside (0, 1]; nothing changes then.
  void retune(double tau);
  /// Each prong's end point: a stage-1 ball (radius >= min_radius / 2) that sees its peak
  /// (normalized units). Needs stages 0, 1 and 3.
  const EndPoints& end_points();
  /// Stage 4: the repulsive force field on the working mesh (normalized units).
  const ForceField& force_field();
  /// Stage 4 at the domain points of stage 2 (what the shrinking of stage 5 starts from).
  const FieldSamples& domain_field();
  /// Stage 5: the domain points shrunk along the field and merged (normalized units).
  const ConnectionPoints& connection_points();
  /// Stage 6: face labels of the working mesh, candidate links and the kept graph. Its points
  /// are the connection points followed by the end points that have a ball (normalized units).
  const DomainGraph& domain_graph();
  /// Stage 7: one snake-fitted polyline per link of domain_graph() (normalized units).
  const Remapped& remap();
  /// Stage 8 (all stages): the skeleton in input coordinates, method "dcg". Should stages 4-8
  /// fail (an exception other than Cancelled, or an empty graph), the interim graph of the
  /// domain points stands in and `method` says "interim_graph (fallback: <reason>)".
  const Skeleton& skeleton();
  /// The skeleton built from the domain points alone (minimum spanning tree, twigs pruned,
  /// method "interim_graph"), in input coordinates: the fallback of skeleton().
  Skeleton interim_skeleton();
  /// The working mesh's mirror plane (dcg/symmetry.h; normalized units), found once: each
  /// skeleton carries it in input coordinates (Skeleton::mirror_plane).
  const MirrorPlane& mirror_plane();
  /// Seconds per stage run so far, in the order they ran. skeleton() runs stage 3 on a thread of
  /// its own beside stages 1-2 (when the engine may use more than one thread): each stage's
  /// seconds are its own, and the skeleton's "total" is the time the run took, less than their
  /// sum by the time the two overlapped.

  const std::vector<std::pair<std::string, double>>& timings() const { return timings_; }

 private:
  const SurfaceQuery& query();
  ProngFeatures compute_prongs_stage(const Progress& progress);
  // Stage 3 on its own thread while this one runs stages 1 and 2.
  void prongs_beside_balls();
  void timed(const std::string& stage, double seconds);
  double timings_seconds(const std::string& stage) const;  // 0 when it has not run
  // Normalized skeleton -> input coordinates, input face labels, mesh facts and timings.
  void finish(Skeleton& s);

  Vertices V_;
  Faces F_;
  Options options_;
  Progress progress_;
  std::optional<PreparedMesh> prepared_;
  std::optional<Balls> voronoi_;
  std::optional<DomainBalls> domain_;
  std::optional<ProngFeatures> prongs_;
  std::optional<EndPoints> end_points_;
  std::optional<ForceField> field_;
  std::optional<FieldSamples> domain_field_;
  std::optional<ConnectionPoints> connection_;
  std::optional<DomainGraph> graph_;
  std::optional<Remapped> remapped_;
  std::optional<Skeleton> skeleton_;
  std::optional<MirrorPlane> mirror_;
  std::vector<std::pair<std::string, double>> timings_;
  double overlapped_ = 0;  // seconds stages ran at the same time (prongs_beside_balls)
};

/// One call: all stages with `options`. Throws InputError, Cancelled.
Skeleton extract_skeleton(const Vertices& V, const Faces& F, const Options& options = {},
                          ProgressCallback progress = {});

}  // namespace dcg

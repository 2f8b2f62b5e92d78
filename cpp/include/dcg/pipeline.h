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
#include "dcg/force_field.h"
#include "dcg/prepare.h"
#include "dcg/progress.h"
#include "dcg/prongs.h"
#include "dcg/remap.h"
#include "dcg/skeleton.h"
#include "dcg/types.h"
#include "dcg/voronoi_balls.h"

namespace dcg {

class SurfaceQuery;

/// Every option of the pipeline with ALGORITHM.md's defaults. Lengths are in normalized units
/// (the input's bounding-box diagonal is 1). The Python names are the field names.
struct Options {
  // Stage 0
  Repair repair = Repair::Auto;  ///< "auto": wrap open / non-manifold input; "none": raise
  int target_faces = 20000;      ///< working-mesh size after uniform remeshing (0: no remesh)
  int upsample = 0;              ///< 1: remesh small inputs up to target_faces (slower; see
                                 ///<    PrepareOptions::upsample); 0: keep them as they are
  // Stage 1
  int samples = 4000;            ///< surface samples for the Voronoi balls (at most; a small
                                 ///<    working mesh gets max(500, faces / 2), see voronoi_balls)
  // Stage 2
  double min_gap = 0.005;        ///< gap between domain balls
  double min_radius = 0.002;     ///< smallest domain ball
  // Stage 3
  double tau = 0.85;             ///< prong smoothness ratio (paper section 6)
  int geodesic_sources = 128;    ///< sources of the sampled scale function
  // Stages 4-5
  int rays = 64;                 ///< rays per point of the repulsive force field
  double force_exponent = 1.0;   ///< n in F(p) = -(1/K) sum u_k / r_k^n
  double shrink_step = 0.5;      ///< alpha of the shrinking step
  // Stage 7
  int snake_iterations = 100;    ///< re-mapping iterations per link
  // All stages
  unsigned seed = 0;             ///< seed of every randomized step (runs are deterministic)

  /// Throws InputError naming the first option out of range.
  void validate() const;
};

/// A numeric option's name (the Options field), meaning and valid range: the one table behind
/// Options::validate(), the Python keyword arguments, the CLI flags and the add-on's properties.
struct OptionSpec {
  std::string name;
  std::string description;
  double minimum;
  double maximum;
  bool integer;      ///< int-valued (target_faces, samples, ...)
  std::string unit;  ///< "" or "normalized length" (fraction of the bounding-box diagonal)
};

/// Every numeric option, in pipeline order. `repair` (a choice) is not in this list.
const std::vector<OptionSpec>& numeric_option_specs();
/// Reads / writes a numeric option by name; InputError for an unknown name (set also checks
/// the range and, for integer options, that the value is whole).
double get_numeric_option(const Options& options, const std::string& name);
void set_numeric_option(Options& options, const std::string& name, double value);
/// "auto" / "none" <-> Repair; InputError for any other string.
Repair parse_repair(const std::string& text);
const char* repair_name(Repair repair);

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
  /// Seconds per stage run so far, in the order they ran.
  const std::vector<std::pair<std::string, double>>& timings() const { return timings_; }

 private:
  const SurfaceQuery& query();
  void timed(const std::string& stage, double seconds);
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
  std::vector<std::pair<std::string, double>> timings_;
};

/// One call: all stages with `options`. Throws InputError, Cancelled.
Skeleton extract_skeleton(const Vertices& V, const Faces& F, const Options& options = {},
                          ProgressCallback progress = {});

}  // namespace dcg

// Progress reporting and cancellation for long computations.
//
// The convention of every stage function (prepare_mesh, compute_voronoi_balls,
// compute_domain_balls, compute_prongs and its steps, compute_connection_points,
// compute_domain_graph, remap_links, chord_midpoints, keep_inside, compute_skin_weights,
// BoneHeat::solve): its last parameters are
//
//   const Progress& progress = {}, double from = 0, double to = 1
//
// and it reports its stage's name ("prepare", "voronoi_balls", "domain_balls", "prongs",
// "connection_points", "domain_graph", "remap", "skeleton", "weights") with fractions from
// `from` to `to` (its share of the caller's whole run, increasing), from the calling thread only:
// once as it starts, then at most every 10 ms while it works (between chunks of its parallel
// loops, never from TBB's workers), so that a cancel waits for at most a few ms of work. When
// the callback returns false, the function throws Cancelled at once, dropping what it computed.
// The Extractor (dcg/pipeline.h) runs the stages with consecutive ranges of [0, 1]; a stage
// called directly reports and cancels the same way. (SurfaceQuery's constructor, a building
// block that stages call, takes a plain `poll` instead.)
#pragma once

#include <functional>
#include <string>
#include <type_traits>
#include <utility>

#include "dcg/errors.h"

namespace dcg {

/// Called with the current stage's name and the fraction of the whole pipeline done (0..1).
/// Return false to cancel: the computation then throws dcg::Cancelled at its next check.
/// It may be called from the computing thread only (never from TBB workers).
using ProgressCallback = std::function<bool(const std::string& stage, double fraction)>;

/// Reports progress through an optional callback; throws Cancelled when it returns false.
/// Made from a ProgressCallback or any callable like it (a lambda), so that a stage function's
/// `const Progress& progress` parameter takes the callback itself; `{}` reports nothing.
class Progress {
 public:
  Progress() = default;
  template <class F, class = std::enable_if_t<!std::is_same_v<std::decay_t<F>, Progress> &&
                                              std::is_constructible_v<ProgressCallback, F>>>
  Progress(F&& callback) : callback_(std::forward<F>(callback)) {}  // NOLINT: implicit on purpose
  /// Stage `stage` is at `fraction` of the whole run.
  void report(const std::string& stage, double fraction) const {
    if (callback_ && !callback_(stage, fraction)) throw Cancelled();
  }

 private:
  ProgressCallback callback_;
};

}  // namespace dcg

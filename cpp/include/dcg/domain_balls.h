// Stage 2 (ALGORITHM.md "Domain balls", paper Def. 1): a greedy set of non-intersecting balls.
#pragma once

#include <vector>

#include "dcg/progress.h"
#include "dcg/types.h"

namespace dcg {

struct DomainBallsOptions {
  /// Required gap between accepted balls: |c_i - c_j| > r_i + r_j + min_gap (normalized units).
  double min_gap = 0.005;
  /// Balls with a smaller radius are dropped (normalized units).
  double min_radius = 0.002;
};

struct DomainBalls {
  Balls balls;              ///< the accepted balls, largest first; centers = domain points
  std::vector<int> source;  ///< for each accepted ball, its index among the candidates
};

/// Accepts candidates largest first when they intersect no accepted ball (spatial grid, never
/// all pairs).
/// Progress as stage "domain_balls", see dcg/progress.h.
DomainBalls compute_domain_balls(const Balls& candidates, const DomainBallsOptions& options = {},
                                 const Progress& progress = {}, double from = 0, double to = 1);

}  // namespace dcg

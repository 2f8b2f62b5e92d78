// Stage 1 (ALGORITHM.md "Voronoi balls", paper section 5): candidate balls inside the shape from
// the Voronoi vertices (Delaunay circumcenters) of surface samples.
#pragma once

#include "dcg/prepare.h"
#include "dcg/progress.h"
#include "dcg/types.h"

namespace dcg {

class SurfaceQuery;

struct VoronoiBallsOptions {
  /// Farthest-point samples on the working mesh's surface (paper: the vertices; more samples
  /// are needed so that thin tips get a ball).
  int samples = 4000;
  unsigned seed = kDefaultSeed;
};

/// Candidate balls: the circumcenters of the finite Delaunay cells of the samples that lie
/// strictly inside `mesh`, each with radius = distance to the surface (not to the samples).
/// `mesh` is the closed working mesh of stage 0; `query` is a SurfaceQuery built on it.
/// A circumcenter that a fold of a noisy mesh puts on the wrong side passes the sign test; the
/// balls whose centers two rays and ray parity put outside are dropped as well.
/// Progress as stage "voronoi_balls", see dcg/progress.h.
Balls compute_voronoi_balls(const Mesh& mesh, const SurfaceQuery& query,
                            const VoronoiBallsOptions& options = {}, const Progress& progress = {},
                            double from = 0, double to = 1);

/// The samples stage 1 takes (at most options.samples) on a working mesh of `working_faces`
/// faces made by stage 0 with `prepare`: a small input kept as it is (upsample off) gets one per
/// two faces, at least kMinSmallSamples.
int voronoi_samples(const VoronoiBallsOptions& options, const PrepareOptions& prepare,
                    Eigen::Index working_faces);
constexpr int kMinSmallSamples = 500;

}  // namespace dcg

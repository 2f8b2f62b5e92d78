// After stage 8: the skeleton held inside the input's own surface. The working mesh of stage 0
// may bulge out of a remeshed input in concave places and thin parts, and a link the snake of
// stage 7 could not route round a bend may cross the surface: such nodes, polyline points and
// segments are moved inside.
#pragma once

#include "dcg/prepare.h"
#include "dcg/progress.h"
#include "dcg/skeleton.h"
#include "dcg/types.h"

namespace dcg {

class SurfaceQuery;

/// The skeleton `s` (normalized units) against `surface`: nodes first, then polyline points
/// (the ends of each polyline are its nodes), then the segments between them. A point that is
/// not at least 1e-7 inside moves along the way to its closest surface point to the deepest of
/// a few depths (a fraction of its radius, half the part's thickness there) that is inside; a
/// segment that crosses the surface is split at its midpoint (held inside the same way), at most
/// 6 halvings deep. Progress as stage "skeleton" (between nodes and links), see dcg/progress.h;
/// a cancelled call leaves `s` partly moved.
void keep_inside(Skeleton& s, const SurfaceQuery& surface, const Progress& progress = {},
                 double from = 0, double to = 1);

/// keep_inside() against the input's own surface (V #V by 3, F #F by 3) when stage 0 remeshed a
/// closed manifold input (`prepared`), against the union of its parts (prepared.united) when it
/// remeshed that union, else against the working mesh (`working_surface`).
/// Progress as stage "skeleton" (also while it indexes the input), see dcg/progress.h.
void keep_inside_input(Skeleton& s, const PreparedMesh& prepared, const Vertices& V, const Faces& F,
                       const SurfaceQuery& working_surface, const Progress& progress = {},
                       double from = 0, double to = 1);

}  // namespace dcg

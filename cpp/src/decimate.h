// Internal (not installed): stage 0's fast first reduction of huge inputs, before the quality
// collapse and remeshing of remesh_uniform (remesh.h).
#pragma once

#include <functional>

#include "dcg/types.h"

namespace dcg::internal {

/// Reduces a huge closed, consistently oriented 2-manifold (one or more shells) to about `goal`
/// faces by edge collapse, in passes: each pass takes the shorter half of the edges, shortest
/// first, and collapses each to its midpoint unless an end already moved in the pass, the link
/// condition fails (the collapse would pinch the surface) or a face around it would turn by more
/// than 60 degrees or degenerate. So the result stays a closed 2-manifold without fold-overs.
/// O(n log n) per pass with no priority queue (about 1 us per collapse against CGAL's 30); the
/// quality comes afterwards from remesh_uniform. Stops at `goal`, after 64 passes, or when a
/// pass collapses nothing (then with more than `goal` faces).
///   mesh  V #V by 3 vertex positions, F #F by 3 face indices into V
/// Returns the reduced mesh, on the vertices its faces use only.
/// `poll` (if set) is called every few thousand collapses or faces with the fraction done
/// (0..1); it may throw (Cancelled) to stop.
Mesh fast_reduce(const Mesh& mesh, int goal, const std::function<void(double)>& poll = {});

}  // namespace dcg::internal

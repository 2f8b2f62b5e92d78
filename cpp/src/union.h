// Internal (not installed): the union of a mesh's closed parts, stage 0's repair of multi-part
// and pinched input before the alpha wrap (union.cpp; CGAL's corefinement takes long to compile,
// so it has its own translation unit).
#pragma once

#include <functional>
#include <optional>

#include "dcg/types.h"

namespace dcg::internal {

/// The union of the closed parts of (V, F) as one closed, oriented 2-manifold (a shell per
/// disjoint part; a part inside another one disappears into it), when every part allows it:
/// each connected component (after splitting pinched vertices into one vertex per fan) must be
/// a closed, orientable, not self-intersecting 2-manifold that encloses a volume. Parts whose
/// bounding boxes overlap are united with CGAL's corefinement (exact predicates); the others are
/// kept as they are, face for face. std::nullopt when any part is open, non-manifold along an
/// edge or self-intersecting, or when a union fails or comes out non-manifold or
/// self-intersecting (parts that touch along an edge or at a point): the caller wraps instead.
///   mesh  #V by 3 vertices, #F by 3 faces (any orientation: each part is turned outward)
/// `poll` (if set) is called between the steps and the unions; it may throw (Cancelled).
std::optional<Mesh> union_of_closed_parts(const Mesh& mesh,
                                          const std::function<void(double)>& poll = {});

}  // namespace dcg::internal

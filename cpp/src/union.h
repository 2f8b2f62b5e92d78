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
/// a closed, orientable 2-manifold that encloses a volume, and one that is to be united with
/// another must not intersect itself. Parts whose
/// bounding boxes overlap are united with CGAL's corefinement (exact predicates); the others are
/// kept as they are, face for face. Parts may touch themselves or each other at a point (a split
/// pinched vertex), never cross. std::nullopt when any part is open, one to be united
/// self-intersecting, or when a union fails or comes out open or self-intersecting (parts that
/// touch along an edge): the caller wraps instead.
///   mesh  #V by 3 vertices, #F by 3 faces, every edge in exactly two faces, consistently
///         oriented (each part is turned outward here)
/// `poll` (if set) is called between the steps and the unions; it may throw (Cancelled).
std::optional<Mesh> union_of_closed_parts(const Mesh& mesh,
                                          const std::function<void(double)>& poll = {});

}  // namespace dcg::internal

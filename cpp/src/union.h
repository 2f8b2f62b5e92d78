// Internal (not installed): stage 0's repairs that keep the input's own surface, tried before the
// alpha wrap: the union of a mesh's closed parts (multi-part and pinched input) and the filling
// of small holes (union.cpp; CGAL's corefinement takes long to compile, so it has its own
// translation unit).
#pragma once

#include <functional>
#include <optional>

#include "dcg/types.h"

namespace dcg::internal {

/// What union_of_closed_parts made.
struct United {
  Mesh mesh;          ///< the union, a shell per disjoint part
  int cavities = 0;   ///< voids enclosed by the united parts, filled (their inner shells dropped)
  int rewrapped = 0;  ///< parts that crossed themselves, each replaced by `rewrap` of it
};

/// What replaces a closed part that crosses itself before it is united with others: a closed
/// surface about it that does not cross itself (stage 0 passes its alpha wrap).
using PartWrap = std::function<Mesh(const Mesh& part)>;

/// The union of the closed parts of (V, F) as one closed, oriented 2-manifold (a shell per
/// disjoint part; a part inside another one disappears into it, and so does a void that parts
/// enclose between them: Mannequiny's ankles and feet enclose two, each the size of a grain
/// of sand, that the remeshing turned into tetrahedra facing inward), when every part allows it:
/// each connected component (after splitting pinched vertices into one vertex per fan) must be
/// a closed, orientable 2-manifold that encloses a volume, and one that is to be united with
/// another must not intersect itself (with `rewrap`, such a part is replaced by rewrap(part)
/// instead, while at most a quarter of those parts cross: a noise of 1e-4 of the diagonal made
/// Mannequiny's head cross itself, and without it all 59 parts went to the wrap, which smoothed
/// the fingers away). Parts whose bounding boxes overlap are united with CGAL's corefinement
/// (exact predicates; again with exact constructions when that union crosses itself, comes out
/// open or throws); the others are kept as they are, face for face. Parts may touch themselves
/// or each other at a point (a split pinched vertex), never cross. std::nullopt when any part
/// is open, one to be united self-intersecting (without `rewrap`; with it, when more than a
/// quarter are or a replacement is no closed solid), or when a union fails or comes out open
/// or self-intersecting (parts that touch along an edge): the caller wraps instead.
///   mesh  #V by 3 vertices, #F by 3 faces, every edge in exactly two faces, consistently
///         oriented (each part is turned outward here)
/// `poll` (if set) is called between the steps and the unions; it may throw (Cancelled).
std::optional<United> union_of_closed_parts(const Mesh& mesh,
                                            const std::function<void(double)>& poll = {},
                                            const PartWrap& rewrap = {});

/// What fill_holes made.
struct FilledMesh {
  Mesh mesh;      ///< the input with its holes triangulated
  int holes = 0;  ///< holes (border loops) filled
};

/// (V, F) with every hole (border loop) triangulated (CGAL's triangulate_hole: the patch of
/// least area and best angles over the loop's own vertices), when every hole has at most
/// `max_edges` edges (how large a hole may be is the caller's: Topology::largest_hole).
/// std::nullopt when there is no hole, some hole has more edges, the mesh is not a manifold with
/// border (non-manifold edges) or a triangulation fails: the caller wraps instead.
std::optional<FilledMesh> fill_holes(const Mesh& mesh, int max_edges);

}  // namespace dcg::internal

// Internal (not installed): a mesh numbered by its geometry alone, for the steps of stage 0
// whose output CGAL numbers differently from call to call or version to version (union.cpp,
// remesh.cpp).
#pragma once

#include "dcg/types.h"

namespace dcg::internal {

/// `mesh` with its vertices in lexicographic order of position (equal ones in their old order)
/// and its faces, each starting at its smallest vertex (orientation kept), in lexicographic
/// order of corners: the same surface, numbered the same whatever order it was made in.
Mesh canonical_order(const Mesh& mesh);

/// The same, with the vertices ordered by their distance from the vertices' centroid first
/// (then by position): an order that a rotation, a move, a scaling or a mirror of the mesh
/// keeps (but for ties), and that takes the two sides of a mirror-symmetric shape by turns.
Mesh centred_order(const Mesh& mesh);

}  // namespace dcg::internal

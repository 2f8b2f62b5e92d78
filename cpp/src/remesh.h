// Internal (not installed): uniform remeshing behind stage 0. Kept in its own translation unit
// (remesh.cpp) because CGAL's remeshing takes ~40 s to compile.
#pragma once

#include "dcg/types.h"

namespace dcg::internal {

/// Uniform isotropic remeshing of the closed manifold `mesh` to about `target_faces` triangles
/// (target edge length from the surface area, equilateral triangles). Large reductions are
/// first decimated by edge collapse. Throws InputError when `mesh` is not a valid polygon mesh.
Mesh remesh_uniform(const Mesh& mesh, int target_faces);

}  // namespace dcg::internal

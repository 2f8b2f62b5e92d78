// Internal (not installed): uniform remeshing behind stage 0. Kept in its own translation unit
// (remesh.cpp) because CGAL's remeshing takes ~40 s to compile.
#pragma once

#include <functional>

#include "dcg/types.h"

namespace dcg::internal {

/// The fewest triangles remesh_uniform makes, whatever it is asked (see remesh.cpp).
constexpr int kMinRemeshFaces = 200;

/// Uniform isotropic remeshing of the closed manifold `mesh` to about `target_faces` triangles
/// (target edge length from the surface area, equilateral triangles). Large reductions are
/// first decimated by edge collapse. Throws InputError when `mesh` is not a valid polygon mesh.
/// `poll` (if set) is called often with the fraction done (0..1), also from inside CGAL's edge
/// collapse and remeshing; it may throw (Cancelled) to stop.
Mesh remesh_uniform(const Mesh& mesh, int target_faces,
                    const std::function<void(double)>& poll = {});

}  // namespace dcg::internal

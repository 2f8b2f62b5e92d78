// Internal: inward chords of a closed surface, the way into thin parts where no ball reaches
// (stage 3's end points of unseen prongs, stage 7's extra waypoints).
#pragma once

#include <optional>

#include <Eigen/Core>

#include "dcg/surface_query.h"
#include "dcg/types.h"

namespace dcg::internal {

/// The middle of the chord from `start` (a point just inside) along the unit direction d to the
/// first wall it meets; none when the ray meets no wall or the middle is not inside.
std::optional<Eigen::Vector3d> chord_middle(const SurfaceQuery& query, const Eigen::Vector3d& start,
                                            const Eigen::Vector3d& d);

/// The middle of the chord from `vertex` of `mesh` inward to the opposite wall. Inward: against
/// the vertex normal (area-weighted face normals), else toward the centroid of its faces, else
/// toward `toward` (a point inside, e.g. the nearest ball center), else along the normal (the
/// normal of a needle tip after remeshing can point in). `radius` receives the point's distance
/// to the surface, 0 when no direction gives a point inside.
Eigen::Vector3d inward_point(const Mesh& mesh, const SurfaceQuery& query, int vertex,
                             const Eigen::Vector3d& toward, double* radius);

}  // namespace dcg::internal

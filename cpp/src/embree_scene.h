// Internal: the one Embree device of the process and a triangle scene built from a mesh, shared by
// SurfaceQuery (closest points, rays, inside tests) and the weights' visibility rays.
#pragma once

#include <functional>

#include <embree3/rtcore.h>

#include "dcg/types.h"

namespace dcg::internal {

/// The process's Embree device (creating one costs a few milliseconds); never released, as the
/// scenes made from it may live in static storage.
RTCDevice embree_device();

/// A committed, robust Embree scene of the triangles (V, F), with `center` subtracted from every
/// vertex first (Embree works in floats: rays must be cast relative to the same center). The
/// caller owns the scene (rtcReleaseScene).
/// With `poll` set, the BVH is built on a helper thread while this one calls `poll` every 5 ms;
/// when `poll` throws (Cancelled), the build is aborted through Embree's progress monitor, the
/// scene released and the exception rethrown.
RTCScene triangle_scene(const Vertices& V, const Faces& F, const double center[3],
                        const std::function<void()>& poll = {});

}  // namespace dcg::internal

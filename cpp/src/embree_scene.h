// Internal: the one Embree device of the process and a triangle scene built from a mesh, shared by
// SurfaceQuery (closest points, rays, inside tests) and the weights' visibility rays.
#pragma once

#include <functional>

#include <Eigen/Core>
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

/// One ray origin + t * direction, t in [tnear, tfar]; `origin` is relative to the scene's
/// center (see triangle_scene). The direction need not be unit length (t is then in its units).
RTCRay single_ray(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double tnear,
                  double tfar);

/// Lane k of an 8-wide packet, set the same way as single_ray (floats already centered).
void set_ray_lane(RTCRay8& ray, int k, const float origin[3], const float direction[3],
                  float tnear, float tfar);

/// True when some triangle of `scene` lies on the ray (rtcOccluded1).
bool occluded(RTCScene scene, const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
              double tnear, double tfar);

}  // namespace dcg::internal

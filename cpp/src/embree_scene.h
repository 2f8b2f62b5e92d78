// Internal: the one Embree device of the process and a triangle scene built from a mesh, shared by
// SurfaceQuery (closest points, rays, inside tests) and the weights' visibility rays.
#pragma once

#include <functional>

#include <Eigen/Core>
// Embree 3 (Debian 12) or 4 (Debian 13): CMake defines DCG_EMBREE_MAJOR for the sources that
// include this header (CMakeLists.txt lists them). Code outside this header and
// embree_scene.cpp calls the ray queries through the wrappers below, which hide the one API
// difference that matters here (Embree 3's per-call intersect context, Embree 4's arguments).
#ifndef DCG_EMBREE_MAJOR
#error "DCG_EMBREE_MAJOR is not defined: add this source to the embree list in CMakeLists.txt"
#endif
#if DCG_EMBREE_MAJOR >= 4
#include <embree4/rtcore.h>
#else
#include <embree3/rtcore.h>
#endif

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
void set_ray_lane(RTCRay8& ray, int k, const float origin[3], const float direction[3], float tnear,
                  float tfar);

/// rtcIntersect1 / rtcOccluded1 / rtcIntersect8 with default arguments, on Embree 3 or 4.
/// `coherent`: the rays of the packet share an origin (a hint for Embree's traversal).
void intersect1(RTCScene scene, RTCRayHit* rayhit);
void occluded1(RTCScene scene, RTCRay* ray);
void intersect8(const int* valid, RTCScene scene, RTCRayHit8* rayhit, bool coherent);

/// The first triangle of `scene` on the ray (rtcIntersect1): its index, -1 for none; its t and
/// barycentric u, v where asked.
int first_hit(RTCScene scene, const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
              double tnear, double tfar, double* t, double* u = nullptr, double* v = nullptr);

/// True when some triangle of `scene` lies on the ray (rtcOccluded1).
bool occluded(RTCScene scene, const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
              double tnear, double tfar);

}  // namespace dcg::internal

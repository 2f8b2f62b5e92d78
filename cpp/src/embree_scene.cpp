#include "embree_scene.h"

#include <atomic>
#include <cstdlib>
#include <exception>
#include <stdexcept>
#include <thread>

#include "polling.h"

namespace dcg::internal {

// Embree's device configuration (its `rtcNewDevice` string) is DCG_EMBREE_CONFIG's when that is
// set: "isa=sse2" runs the kernels another CPU would pick, "verbose=1" names the chosen ones
// (tests/python/test_determinism.py). Results do not depend on it: every distance
// the stages read is recomputed in double (SurfaceQuery's exact_hit) and ties go to the lowest
// face.
RTCDevice embree_device() {
  static RTCDevice device = [] {
    RTCDevice d = rtcNewDevice(std::getenv("DCG_EMBREE_CONFIG"));
    if (!d) throw std::runtime_error("Embree: cannot create a device");
    return d;
  }();
  return device;
}

// Below this many faces the BVH builds in a few milliseconds at most: on this thread, without
// the polling thread (whose start and join cost the torus's 1,152 faces more than the build).
constexpr std::size_t kPolledBuildFaces = 50000;

RTCScene triangle_scene(const Vertices& V, const Faces& F, const double center[3],
                        const std::function<void()>& poll) {
  const auto nv = static_cast<std::size_t>(V.rows()), nf = static_cast<std::size_t>(F.rows());
  RTCDevice device = embree_device();
  RTCScene scene = rtcNewScene(device);
  rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
  RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0,
                                                         RTC_FORMAT_FLOAT3, 3 * sizeof(float), nv));
  auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
      geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), nf));
  if (!vb || !ib) {
    rtcReleaseGeometry(geometry);
    rtcReleaseScene(scene);
    throw std::runtime_error("Embree: cannot allocate the mesh buffers");
  }
  for (std::size_t i = 0; i < nv; ++i)
    for (int k = 0; k < 3; ++k) vb[3 * i + k] = static_cast<float>(V(i, k) - center[k]);
  for (std::size_t f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) ib[3 * f + k] = static_cast<unsigned>(F(f, k));
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(scene, geometry);
  rtcReleaseGeometry(geometry);
  if (!poll || nf < kPolledBuildFaces) {
    rtcCommitScene(scene);
    return scene;
  }
  std::atomic<bool> stop{false};
  rtcSetSceneProgressMonitorFunction(
      scene, [](void* flag, double) { return !static_cast<std::atomic<bool>*>(flag)->load(); },
      &stop);
  Completion built;
  std::thread builder([&] {
    rtcCommitScene(scene);
    built.set();
  });
  try {
    built.wait_polling(poll);
  } catch (...) {
    stop = true;
    builder.join();
    rtcReleaseScene(scene);
    throw;
  }
  builder.join();
  rtcSetSceneProgressMonitorFunction(scene, nullptr, nullptr);
  return scene;
}

RTCRay single_ray(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double tnear,
                  double tfar) {
  RTCRay ray;
  ray.org_x = static_cast<float>(origin.x());
  ray.org_y = static_cast<float>(origin.y());
  ray.org_z = static_cast<float>(origin.z());
  ray.dir_x = static_cast<float>(direction.x());
  ray.dir_y = static_cast<float>(direction.y());
  ray.dir_z = static_cast<float>(direction.z());
  ray.tnear = static_cast<float>(tnear);
  ray.tfar = static_cast<float>(tfar);
  ray.time = 0.f;
  ray.mask = 0xFFFFFFFFu;
  ray.id = 0;
  ray.flags = 0;
  return ray;
}

void set_ray_lane(RTCRay8& ray, int k, const float origin[3], const float direction[3], float tnear,
                  float tfar) {
  ray.org_x[k] = origin[0];
  ray.org_y[k] = origin[1];
  ray.org_z[k] = origin[2];
  ray.dir_x[k] = direction[0];
  ray.dir_y[k] = direction[1];
  ray.dir_z[k] = direction[2];
  ray.tnear[k] = tnear;
  ray.tfar[k] = tfar;
  ray.time[k] = 0.f;
  ray.mask[k] = 0xFFFFFFFFu;
  ray.id[k] = static_cast<unsigned>(k);
  ray.flags[k] = 0;
}

#if DCG_EMBREE_MAJOR >= 4
void intersect1(RTCScene scene, RTCRayHit* rayhit) { rtcIntersect1(scene, rayhit); }
void occluded1(RTCScene scene, RTCRay* ray) { rtcOccluded1(scene, ray); }
void intersect8(const int* valid, RTCScene scene, RTCRayHit8* rayhit, bool coherent) {
  RTCIntersectArguments arguments;
  rtcInitIntersectArguments(&arguments);
  if (coherent) arguments.flags = RTC_RAY_QUERY_FLAG_COHERENT;
  rtcIntersect8(valid, scene, rayhit, &arguments);
}
#else
namespace {
RTCIntersectContext intersect_context(bool coherent = false) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  if (coherent) context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  return context;
}
}  // namespace
void intersect1(RTCScene scene, RTCRayHit* rayhit) {
  RTCIntersectContext context = intersect_context();
  rtcIntersect1(scene, &context, rayhit);
}
void occluded1(RTCScene scene, RTCRay* ray) {
  RTCIntersectContext context = intersect_context();
  rtcOccluded1(scene, &context, ray);
}
void intersect8(const int* valid, RTCScene scene, RTCRayHit8* rayhit, bool coherent) {
  RTCIntersectContext context = intersect_context(coherent);
  rtcIntersect8(valid, scene, &context, rayhit);
}
#endif

int first_hit(RTCScene scene, const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
              double tnear, double tfar, double* t, double* u, double* v) {
  RTCRayHit rh;
  rh.ray = single_ray(origin, direction, tnear, tfar);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  intersect1(scene, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return -1;
  *t = rh.ray.tfar;
  if (u) *u = rh.hit.u;
  if (v) *v = rh.hit.v;
  return static_cast<int>(rh.hit.primID);
}

bool occluded(RTCScene scene, const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
              double tnear, double tfar) {
  RTCRay ray = single_ray(origin, direction, tnear, tfar);
  occluded1(scene, &ray);
  return ray.tfar < 0;  // Embree sets tfar to -inf when the ray hits a triangle
}

}  // namespace dcg::internal

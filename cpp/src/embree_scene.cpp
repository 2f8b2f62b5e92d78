#include "embree_scene.h"

#include <atomic>
#include <exception>
#include <stdexcept>
#include <thread>

#include "polling.h"

namespace dcg::internal {

RTCDevice embree_device() {
  static RTCDevice device = [] {
    RTCDevice d = rtcNewDevice(nullptr);
    if (!d) throw std::runtime_error("Embree: cannot create a device");
    return d;
  }();
  return device;
}

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
  if (!poll) {
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

}  // namespace dcg::internal

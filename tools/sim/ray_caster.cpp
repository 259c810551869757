#include "tools/sim/ray_caster.hpp"

#include <embree3/rtcore.h>

#include <limits>
#include <stdexcept>
#include <string>

namespace storey::tools::sim {

struct RayCaster::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  ~Impl() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

RayCaster::RayCaster(const Mesh& mesh) : impl_(std::make_unique<Impl>()) {
  if (mesh.empty() || !mesh.valid()) throw std::runtime_error("ray caster: empty or invalid mesh");
  impl_->device = rtcNewDevice("threads=1");
  if (!impl_->device)
    throw std::runtime_error("ray caster: rtcNewDevice failed (" +
                             std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
  impl_->scene = rtcNewScene(impl_->device);
  rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_HIGH);
  RTCGeometry geom = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
      geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), mesh.vertices.size()));
  auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
      geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), mesh.size()));
  if (!v || !idx) {
    rtcReleaseGeometry(geom);
    throw std::runtime_error("ray caster: Embree buffer allocation failed");
  }
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i)
    for (int k = 0; k < 3; ++k) v[3 * i + k] = mesh.vertices[i][k];
  for (std::size_t i = 0; i < mesh.size(); ++i)
    for (int k = 0; k < 3; ++k) idx[3 * i + k] = mesh.triangles[i][k];
  rtcCommitGeometry(geom);
  rtcAttachGeometry(impl_->scene, geom);
  rtcReleaseGeometry(geom);
  rtcCommitScene(impl_->scene);
}

RayCaster::~RayCaster() = default;

bool RayCaster::cast(const Eigen::Vector3f& o, const Eigen::Vector3f& d, float tmax,
                     RayHit* hit) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRayHit rh;
  rh.ray.org_x = o.x(), rh.ray.org_y = o.y(), rh.ray.org_z = o.z();
  rh.ray.dir_x = d.x(), rh.ray.dir_y = d.y(), rh.ray.dir_z = d.z();
  rh.ray.tnear = 0.f, rh.ray.tfar = tmax, rh.ray.time = 0.f;
  rh.ray.mask = 0xFFFFFFFFu, rh.ray.id = 0, rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->scene, &ctx, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  if (hit) {
    hit->distance = rh.ray.tfar;
    hit->normal = Eigen::Vector3f(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z).normalized();
  }
  return true;
}

bool RayCaster::blocked(const Eigen::Vector3f& a, const Eigen::Vector3f& b) const {
  const Eigen::Vector3f d = b - a;
  const float len = d.norm();
  if (len <= 0.f) return false;
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRay r;
  r.org_x = a.x(), r.org_y = a.y(), r.org_z = a.z();
  r.dir_x = d.x() / len, r.dir_y = d.y() / len, r.dir_z = d.z() / len;
  r.tnear = 0.f, r.tfar = len, r.time = 0.f, r.mask = 0xFFFFFFFFu, r.id = 0, r.flags = 0;
  rtcOccluded1(impl_->scene, &ctx, &r);
  return r.tfar < 0.f;  // Embree sets tfar = -inf on occlusion
}

void RayCaster::cast16(RayPacket16& p) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  alignas(64) RTCRayHit16 rh;
  alignas(64) int valid[16];
  for (int i = 0; i < 16; ++i) {
    valid[i] = p.valid[i] ? -1 : 0;
    rh.ray.org_x[i] = p.ox[i], rh.ray.org_y[i] = p.oy[i], rh.ray.org_z[i] = p.oz[i];
    rh.ray.dir_x[i] = p.dx[i], rh.ray.dir_y[i] = p.dy[i], rh.ray.dir_z[i] = p.dz[i];
    rh.ray.tnear[i] = 0.f, rh.ray.tfar[i] = p.tmax[i], rh.ray.time[i] = 0.f;
    rh.ray.mask[i] = 0xFFFFFFFFu, rh.ray.id[i] = unsigned(i), rh.ray.flags[i] = 0;
    rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
  }
  rtcIntersect16(valid, impl_->scene, &ctx, &rh);
  for (int i = 0; i < 16; ++i)
    p.distance[i] =
        (p.valid[i] && rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID) ? rh.ray.tfar[i] : -1.f;
}

}  // namespace storey::tools::sim

// Embree 3 scene of a world mesh: first-hit ray casts, single or 16-wide packets. One device per
// caster, single-threaded (the lockstep simulator must be deterministic and share the CPU).
// Not thread-safe for concurrent builds; casts are const and may run from several threads.
#pragma once

#include <Eigen/Core>
#include <array>
#include <memory>

#include "tools/sim/mesh.hpp"

namespace storey::tools::sim {

struct RayHit {
  float distance = 0.f;             // [m] along the unit direction
  Eigen::Vector3f normal{0, 0, 0};  // unit geometric normal (either side)
};

// 16 rays for cast16: fill origin/direction (unit) and tmax; valid[i] = false skips ray i.
struct RayPacket16 {
  alignas(64) std::array<float, 16> ox, oy, oz, dx, dy, dz, tmax;
  std::array<bool, 16> valid{};
  // Outputs: distance < 0 means no hit within [tnear, tmax].
  alignas(64) std::array<float, 16> distance;
};

class RayCaster {
 public:
  explicit RayCaster(const Mesh& mesh);
  ~RayCaster();
  RayCaster(const RayCaster&) = delete;
  RayCaster& operator=(const RayCaster&) = delete;

  // First hit of the ray origin + t * dir, t in [0, tmax]; dir must be unit length.
  bool cast(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float tmax,
            RayHit* hit = nullptr) const;
  // True when anything lies on the segment a -> b.
  bool blocked(const Eigen::Vector3f& a, const Eigen::Vector3f& b) const;
  // 16 coherent rays at once (rtcIntersect16).
  void cast16(RayPacket16& p) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace storey::tools::sim

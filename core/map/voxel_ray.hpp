#pragma once
// 3D DDA (Amanatides & Woo, 1987) over the voxel grid, the ray caster of the map insertion.
#include <cmath>
#include <cstdint>
#include <cstdlib>

#include "core/map/voxel_block.hpp"

namespace storey::core::map {

inline VoxelKey floor_key(double x, double y, double z) {
  return VoxelKey{int32_t(std::floor(x)), int32_t(std::floor(y)), int32_t(std::floor(z))};
}

// Visits, in order, every voxel the segment a -> b passes through (a, b in voxel units, i.e.
// metres / voxel size), starting with floor(a) and ending just before floor(b): exactly
// |dx|+|dy|+|dz| voxels (6-connected walk). The step count is fixed up front and an axis is only
// stepped while it has steps left, so rounding can never overshoot or loop. `visit(key)` returns
// false to stop early. Returns the number of voxels visited.
template <class Visit>
inline uint32_t walk_ray(double ax, double ay, double az, double bx, double by, double bz,
                         Visit&& visit) {
  VoxelKey k = floor_key(ax, ay, az);
  const VoxelKey e = floor_key(bx, by, bz);
  int32_t left[3] = {std::abs(e.x - k.x), std::abs(e.y - k.y), std::abs(e.z - k.z)};
  const double a[3] = {ax, ay, az};
  const double d[3] = {bx - ax, by - ay, bz - az};
  const int32_t kk[3] = {k.x, k.y, k.z};
  int32_t step[3];
  double t_max[3], t_delta[3];
  for (int i = 0; i < 3; ++i) {
    step[i] = d[i] > 0 ? 1 : -1;
    if (left[i] == 0) {
      t_max[i] = t_delta[i] = INFINITY;
      continue;
    }
    const double inv = 1.0 / std::abs(d[i]);  // d != 0 since the end voxel differs on this axis
    const double boundary = d[i] > 0 ? double(kk[i]) + 1.0 : double(kk[i]);
    t_max[i] = std::abs(boundary - a[i]) * inv;
    t_delta[i] = inv;
  }
  uint32_t n = uint32_t(left[0] + left[1] + left[2]);
  for (uint32_t s = 0; s < n; ++s) {
    if (!visit(k)) return s + 1;
    // Axis with the nearest boundary among those with steps left.
    int ax_i;
    if (t_max[0] <= t_max[1]) {
      ax_i = t_max[0] <= t_max[2] ? 0 : 2;
    } else {
      ax_i = t_max[1] <= t_max[2] ? 1 : 2;
    }
    if (ax_i == 0) {
      k.x += step[0];
      t_max[0] = --left[0] ? t_max[0] + t_delta[0] : INFINITY;
    } else if (ax_i == 1) {
      k.y += step[1];
      t_max[1] = --left[1] ? t_max[1] + t_delta[1] : INFINITY;
    } else {
      k.z += step[2];
      t_max[2] = --left[2] ? t_max[2] + t_delta[2] : INFINITY;
    }
  }
  return n;
}

}  // namespace storey::core::map

#pragma once
// Test helpers: occupied voxel centres of axis-aligned boxes on a 0.1 m grid (for checks that take
// voxel lists), and maps built from the map module's synthetic LiDAR worlds (for MapView-based
// checks).
#include <cmath>
#include <vector>

#include <Eigen/Core>

#include "core/map/traversability_map.hpp"
#include "tests/core_map/synthetic_world.hpp"

namespace storey::test {

// Centres of every 0.1 m voxel whose centre lies inside [lo, hi].
inline void fill_voxels(std::vector<Eigen::Vector3f>& out, Eigen::Vector3f lo, Eigen::Vector3f hi,
                        float s = 0.1f) {
  const Eigen::Vector3i a = (lo / s).array().floor().cast<int>();
  const Eigen::Vector3i b = (hi / s).array().ceil().cast<int>();
  for (int x = a.x(); x < b.x(); ++x)
    for (int y = a.y(); y < b.y(); ++y)
      for (int z = a.z(); z < b.z(); ++z) {
        const Eigen::Vector3f c((x + 0.5f) * s, (y + 0.5f) * s, (z + 0.5f) * s);
        if ((c.array() >= lo.array()).all() && (c.array() <= hi.array()).all()) out.push_back(c);
      }
}

// Scans `w` from each origin (dense random rays), then evaluates traversability and C_reach from
// the first origin's foot point.
inline void scan_world(core::map::TraversabilityMap& map, const World& w,
                       const std::vector<Eigen::Vector3f>& origins, int rays = 60000,
                       float sensor_height = 0.5f) {
  uint32_t seed = 1;
  for (const Eigen::Vector3f& o : origins) {
    for (int rep = 0; rep < 3; ++rep) {
      const auto pts = scan_dense(w, o, rays, seed++, -1.4f, 0.9f, 15.f, 0.002f);
      map.insert_scan(o, pts);
    }
  }
  map.update_traversability();
  map.update_reachable(origins.front() - Eigen::Vector3f(0, 0, sensor_height));
}

}  // namespace storey::test

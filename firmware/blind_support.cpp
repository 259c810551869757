#include "firmware/blind_support.hpp"

#include <cmath>

namespace storey::firmware {
namespace {
// Ground observed more than a step under a foot-height point, within a metre: the point lies over
// a drop or the treads of a flight going down, not on the floor the robot stands on.
bool below_foot(const core::map::MapView& view, const Eigen::Vector3f& p) {
  const float vs = float(view.voxel_size_m());
  for (float dz = float(view.robot().step_height_m) + vs; dz <= 1.0f; dz += vs)
    if (view.is_occupied(view.key_of(p - Eigen::Vector3f(0, 0, dz)))) return true;
  return false;
}
}  // namespace

std::vector<Eigen::Vector3f> blind_support_points(const core::map::MapView& view,
                                                  const Eigen::Vector3f& foot,
                                                  double mount_height_m, double radius_m) {
  std::vector<Eigen::Vector3f> pts;
  const float r = float(radius_m);
  const Eigen::Vector3f origin = foot + Eigen::Vector3f(0, 0, float(mount_height_m));
  const float step = 0.033f;
  for (float x = -r; x <= r; x += step)
    for (float y = -r; y <= r; y += step) {
      if (x * x + y * y > r * r) continue;
      const Eigen::Vector3f p = foot + Eigen::Vector3f(x, y, -0.01f);
      if (view.first_occupied(origin, p + Eigen::Vector3f(0, 0, 0.12f))) continue;
      if (below_foot(view, p)) continue;
      pts.push_back(p);
    }
  return pts;
}

float support_fraction(const core::map::MapView& view, const Eigen::Vector3f& foot) {
  const float vs = float(view.voxel_size_m());
  int n = 0, with = 0;
  for (float x = -0.5f; x <= 0.5f + 1e-4f; x += vs)
    for (float y = -0.5f; y <= 0.5f + 1e-4f; y += vs) {
      if (x * x + y * y > 0.25f + 1e-4f) continue;
      ++n;
      with += view.support_surface_near(foot + Eigen::Vector3f(x, y, 0), 0.15).has_value();
    }
  return n ? float(with) / float(n) : 1.0f;
}

}  // namespace storey::firmware

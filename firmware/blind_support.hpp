#pragma once
// Ground in the LiDAR's blind ring: the LiDAR cannot see the floor within h / tan(-v_min) of the
// robot (VLP-16 at 0.5 m: 1.9 m), but the legs stand on it. The firmware enters it into the map as
// observed support (a disc at foot height) at start-up and, with plan.climb_blind, after stepping
// onto ground the LiDAR has not seen (a landing reached from a flight whose pitch kept the LiDAR
// looking over it). A flat disc is only true where the robot stands on level ground.
#include <cmath>
#include <vector>

#include <Eigen/Core>

#include "core/map/map_view.hpp"

namespace storey::firmware {

// Points at foot height (1 cm under it) on a 3.3 cm grid within radius_m of the foot, each kept
// only if the line of sight from the sensor (mount_height_m above the foot) to it is free in the
// map (walls already seen clip it) and no ground lies more than a step under it (a drop, a
// flight going down).
std::vector<Eigen::Vector3f> blind_support_points(const core::map::MapView& view,
                                                  const Eigen::Vector3f& foot,
                                                  double mount_height_m, double radius_m);

// Share of the columns within 0.5 m of the foot that hold support at its height.
float support_fraction(const core::map::MapView& view, const Eigen::Vector3f& foot);

// Whether the robot walks level: its foot has stayed within kTolM of one height for more than
// kRunM of horizontal travel (longer than any tread, 0.25-0.35 m), so not on a flight.
class LevelTracker {
 public:
  static constexpr float kTolM = 0.05f;  // one level (less than any riser)
  static constexpr float kRunM = 0.4f;   // walked on it

  void update(const Eigen::Vector3f& foot) {
    if (!(std::abs(foot.z() - from_.z()) <= kTolM)) from_ = foot;
    foot_ = foot;
  }
  bool level() const { return (foot_ - from_).head<2>().norm() >= kRunM; }

 private:
  Eigen::Vector3f from_ = Eigen::Vector3f::Constant(1e9f);  // where the current level began
  Eigen::Vector3f foot_ = Eigen::Vector3f::Constant(1e9f);
};

}  // namespace storey::firmware

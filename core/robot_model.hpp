#pragma once
// The robot as the method sees it: body box, locomotion limits. Units in every name.
#include <cmath>

namespace storey::core {

struct RobotModel {
  double body_length_m = 0.70;                // Go2 body box (x)
  double body_width_m = 0.31;                 // (y)
  double body_height_m = 0.40;                // (z), above the support surface
  double body_margin_m = 0.05;                // inflation of the box for collision checks
  double step_height_m = 0.18;                // largest step the legs climb
  double max_slope_rad = 0.5235987755982988;  // 30 deg
  double max_speed_mps = 1.0;                 // planar speed limit
  double max_yaw_rate_rps = 1.0;              // yaw rate limit
  double max_accel_mps2 = 1.0;                // planar acceleration limit
  double max_yaw_accel_rps2 = 2.0;
};

// A level change of `rise_m` over `run_m` (horizontal) is a flight of stairs, not a ramp: more
// than half a step and steeper than 0.6 max_slope (stairs are ~30 deg, ramps well under 20).
inline bool is_flight(const RobotModel& r, double rise_m, double run_m) {
  return rise_m > 0.5 * r.step_height_m && rise_m > std::tan(0.6 * r.max_slope_rad) * run_m;
}

}  // namespace storey::core

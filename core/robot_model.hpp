#pragma once
// The robot as the method sees it: body box, locomotion limits. Units in every name.
namespace storey::core {

struct RobotModel {
  double body_length_m = 0.70;     // Go2 body box (x)
  double body_width_m = 0.31;      // (y)
  double body_height_m = 0.40;     // (z), above the support surface
  double body_margin_m = 0.05;     // inflation of the box for collision checks
  double step_height_m = 0.18;     // largest step the legs climb
  double max_slope_rad = 0.5235987755982988;  // 30 deg
  double max_speed_mps = 1.0;      // planar speed limit
  double max_yaw_rate_rps = 1.0;   // yaw rate limit
  double max_accel_mps2 = 1.0;     // planar acceleration limit
  double max_yaw_accel_rps2 = 2.0;
};

}  // namespace storey::core

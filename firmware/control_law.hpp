#pragma once
// Trajectory tracking for the control task (DESIGN §3): body velocity command = feedforward
// velocity of the reference + proportional correction of the position and yaw errors, clamped to
// the robot's limits (planar speed, yaw rate) and rate-limited (planar acceleration, yaw
// acceleration) against the previous command. Pure function of its inputs: no state, no clock.
#include "core/plan/bspline_trajectory.hpp"
#include "core/robot_model.hpp"
#include "firmware/platform.hpp"

namespace storey::firmware {

struct ControlGains {
  double k_position = 1.2;  // [1/s] position error -> world velocity correction
  double k_yaw = 2.0;       // [1/s] yaw error -> yaw rate correction
};

class ControlLaw {
 public:
  ControlLaw(const core::RobotModel& robot, const ControlGains& gains = {})
      : robot_(robot), gains_(gains) {}
  // ref: the trajectory sample for now; pose: odometry; prev: the last command sent; dt_s: the
  // control period (bounds the change of the command by the acceleration limits).
  VelocityCommand track(const core::plan::TrajectorySample& ref, const PoseSample& pose,
                        const VelocityCommand& prev, double dt_s) const;
  // Clamps a command to speed / yaw-rate limits and rate-limits it against prev (exposed for
  // tests).
  VelocityCommand limit(VelocityCommand cmd, const VelocityCommand& prev, double dt_s) const;
  const core::RobotModel& robot() const { return robot_; }

 private:
  core::RobotModel robot_;
  ControlGains gains_;
};

// Wraps an angle to (-pi, pi].
double wrap_angle(double a);

}  // namespace storey::firmware

// Go2-like robot (DESIGN §4-5): a body box following body-frame velocity commands with
// acceleration limits, integrated at a fixed physics rate. It stands on the support surface
// under it (downward Embree probes), climbs steps up to the step height and slopes up to the max
// slope, is blocked by walls (collision recorded), falls off ledges (fall recorded) and reports
// being stuck. Odometry with optional drift and noise (seeded).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>

#include "tools/sim/ray_caster.hpp"
#include "tools/sim/rng.hpp"
#include "tools/sim/scene.hpp"

namespace storey::tools::sim {

struct RobotOptions {
  double length = 0.70, width = 0.31, height = 0.40;  // [m] body box, ground to body top
  double step_height = 0.18;                          // [m] highest step the legs climb
  double max_slope_deg = 30.0;                        // [deg] steepest walkable surface
  double max_speed = 1.5;                             // [m/s] command clamp
  double max_yaw_rate = 2.0;                          // [rad/s] command clamp
  double max_accel = 2.0;                             // [m/s^2]
  double max_yaw_accel = 4.0;                         // [rad/s^2]
  double physics_rate = 200.0;                        // [Hz] fixed integration step
  double stuck_time = 2.0;       // [s] commanded motion without progress before "stuck"
  double stuck_distance = 0.05;  // [m] progress below this within stuck_time = stuck
  // Odometry errors (all zero = perfect odometry).
  double odom_scale_error = 0.0;     // relative speed scale error
  double odom_speed_noise = 0.0;     // [m/s] gaussian per physics step
  double odom_yaw_rate_bias = 0.0;   // [rad/s] yaw drift
  double odom_yaw_rate_noise = 0.0;  // [rad/s] gaussian per physics step
  uint64_t seed = 1;
};

struct VelocityCommand {
  double vx = 0.0, vy = 0.0;  // [m/s] body frame
  double yaw_rate = 0.0;      // [rad/s]
};

// Planar speed above which the robot counts as walking (RobotState::walking_s): below it it
// turns on the spot, waits for a plan, or creeps.
inline constexpr double kWalkingSpeed = 0.2;  // [m/s]

struct RobotState {
  double t = 0.0;                             // [s] virtual time
  Eigen::Vector3d position{0, 0, 0};          // [m] ground point under the body centre
  double yaw = 0.0, pitch = 0.0, roll = 0.0;  // [rad]
  Eigen::Vector3d velocity{0, 0, 0};          // body frame: vx, vy [m/s], yaw rate [rad/s]
  bool blocked = false;                       // the last physics step was refused
  bool stuck = false;                         // commanded motion without progress
  uint32_t collisions = 0;                    // events: body met the world (rising edges)
  uint32_t falls = 0;                         // events: support vanished beyond step height
  uint32_t stuck_events = 0;
  double distance = 0.0;   // [m] path length travelled
  double walking_s = 0.0;  // [s] time the body moved at more than kWalkingSpeed
  // world <- body: origin at `position`, rotated by yaw, pitch, roll.
  Eigen::Isometry3d body_pose() const;
};

struct Odometry {
  double t = 0.0;
  Eigen::Vector3d position{0, 0, 0};
  double yaw = 0.0;
  Eigen::Vector3d velocity{0, 0, 0};  // body frame, as measured
};

class RobotModel {
 public:
  RobotModel(const RayCaster& world, const StartPose& start, const RobotOptions& options = {});
  // Advances by dt [s] in fixed physics steps (a remainder is carried to the next call).
  void step(double dt, const VelocityCommand& cmd);
  const RobotState& state() const { return s_; }
  const Odometry& odometry() const { return odom_; }
  const RobotOptions& options() const { return opt_; }
  double physics_step() const { return 1.0 / opt_.physics_rate; }

 private:
  struct Probe {
    bool hit = false;
    double z = 0.0;     // surface height [m]
    double tilt = 0.0;  // surface normal angle from vertical [rad]
  };
  Probe probe(double x, double y, double z_ref) const;
  void physics_step(const VelocityCommand& cmd);
  // Pitch/roll of the mean support plane under the footprint (level when too little is seen).
  void attitude(double x, double y, double yaw, double z, double* pitch, double* roll) const;
  bool body_collides(const Eigen::Isometry3d& body) const;

  const RayCaster& world_;
  RobotOptions opt_;
  RobotState s_;
  Odometry odom_;
  Rng rng_;
  double carry_ = 0.0;
  uint64_t steps_ = 0;
  // Stuck detection: anchor position and time of the last progress.
  Eigen::Vector3d stuck_anchor_{0, 0, 0};
  double stuck_since_ = 0.0;
};

}  // namespace storey::tools::sim

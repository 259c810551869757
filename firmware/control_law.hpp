#pragma once
// Trajectory tracking for the control task (DESIGN §3): body velocity command = feedforward
// velocity of the reference + proportional correction of the position and yaw errors, clamped to
// the robot's limits (planar speed, yaw rate) and rate-limited (planar acceleration, yaw
// acceleration) against the previous command. Pure function of its inputs: no state, no clock.
#include <vector>

#include "core/plan/bspline_trajectory.hpp"
#include "core/robot_model.hpp"
#include "firmware/platform.hpp"

namespace storey::firmware {

struct ControlGains {
  double k_position = 1.2;  // [1/s] position error -> world velocity correction
  double k_yaw = 2.0;       // [1/s] yaw error -> yaw rate correction
  // on_reference(): full yaw authority within the first, none from the second [m]
  // (safety.turn_on_reference_full_m / _zero_m).
  double on_reference_full_m = 0.15;
  double on_reference_zero_m = 0.3;
};

class ControlLaw {
 public:
  ControlLaw(const core::RobotModel& robot, const ControlGains& gains = {})
      : robot_(robot), gains_(gains) {}
  // ref: the trajectory sample for now; pose: odometry; prev: the last command sent; dt_s: the
  // control period (bounds the change of the command by the acceleration limits).
  // yaw_scale [0, 1] scales the yaw command: safety.turn_on_reference's gate while entering a
  // new trajectory (yaw_gate), 0 while safety.check_body_turn slides the body onto its reference.
  VelocityCommand track(const core::plan::TrajectorySample& ref, const PoseSample& pose,
                        const VelocityCommand& prev, double dt_s, double yaw_scale = 1.0) const;
  // safety.turn_on_reference: the yaw authority [0, 1] of a robot entering trajectory t (until it
  // first came to be on it) at entry_tau (ControlLaw::entry_time), reference at tau: the larger
  // of on_reference() and on_path() over the path the reference came along, from entry_tau, at
  // most 2 s back from tau (the path before the entry was never the reference). The robot turns
  // only where it will come to rest on the trajectory. Once on it, full yaw authority (a robot
  // lagging its reference on a flight, the gate held the yaw off the axis and the climbs failed).
  double yaw_gate(const core::plan::BsplineTrajectory& t, double entry_tau, double tau,
                  const core::plan::TrajectorySample& ref, const PoseSample& pose) const;
  // 1 while the point where the robot would stop if it braked now is within 0.15 m of the
  // reference's, falling to 0 at 0.3 m (ControlGains::on_reference_full_m / _zero_m). A new
  // trajectory starts at rest where the robot was when it was planned; a robot arriving at walking
  // speed overshoots that start by up to v^2 / (2 a_max) (0.5 m at 1 m/s) before it is back, and
  // turning the 0.7 m body there, off the poses FCL checked, swept it into a door frame
  // (teaching_building seed 1, 842 s).
  double on_reference(const core::plan::TrajectorySample& ref, const PoseSample& pose) const;
  // 1 while the robot's rest point is within kOnPathFullM of t's path between from_s and to_s
  // (sampled every kPathStepS), falling to 0 at kOnPathZeroM. A body entering a trajectory
  // mid-way from rest (ControlLaw::entry_time) lags a reference at walking speed by up to 0.3 m
  // (progress_rate) and never comes to rest at it, so on_reference alone held its yaw off the
  // path's for good: it met a jamb turning late (office, nearest-frontier seed 5, 184 s). Where
  // it rests on the path, the path's poses were checked. A tighter ramp than on_reference's: with
  // the same, a body coming back from overshooting a trajectory's start turned 0.35 m off it
  // (the start is nearer than the reference) into a wall (teaching building seed 2, 533.9 s).
  double on_path(const core::plan::BsplineTrajectory& t, double from_s, double to_s,
                 const PoseSample& pose) const;
  static constexpr double kPathStepS = 0.05, kOnPathFullM = 0.05, kOnPathZeroM = 0.15;
  // Where the robot comes to rest if it brakes now at a_max, world frame [m] (planar).
  Eigen::Vector2d rest_point(const PoseSample& pose) const;
  // Where on a new trajectory tracking starts: its point nearest `at` (the robot) within its first
  // 2 s (the robot kept moving while it was planned). With plan.brake_start the control task
  // enters a trajectory that turns away only once braked to rest on the old one, where the
  // planner started it: entered while moving, a trajectory that turns back passes the robot's
  // position later, and tracking from there cut the turn short into a railing (house seed 2).
  static double entry_time(const core::plan::BsplineTrajectory& t, const Eigen::Vector2d& at);
  // plan.reference_catch_up: the reference time to follow from tau for a robot at `at`. A robot
  // ahead of its reference (a new trajectory starts at rest; one entered at walking speed is
  // overshot by up to v^2 / (2 a_max)): the first point of the path from tau (up to tau + 2 s and
  // tau_end) nearest the robot, if more than 0.1 m nearer than the reference; else tau. Only the
  // first closest approach counts: a path that doubles back past the robot is not cut short.
  static double catch_up_time(const core::plan::BsplineTrajectory& t, double tau, double tau_end,
                              const Eigen::Vector2d& at);
  // A new trajectory that, within twice the robot's stopping distance + 0.3 m of path (judged
  // along the curve, whatever its timing), heads more than 60 deg off the robot's velocity v
  // (world frame), turns the body more than 0.5 rad, or ends: the robot brakes on the trajectory
  // it follows before it enters this one (plan.brake_start). One that carries on along v is
  // entered at once (a stop at every replan would halve the speed), and so is one that leaves
  // its start moving within 60 deg of v (plan.start_at_speed): its profile slows for its bends.
  bool turns_away(const core::plan::BsplineTrajectory& t, const Eigen::Vector2d& v) const;
  // The rate [0, 1] at which the reference moves on along its curve while the robot tracks it
  // with these planar position and yaw errors: 1 within 0.3 m and yaw_gate_rad, 0 from 0.6 m or
  // twice yaw_gate_rad (linear between): after a stop or a lag the reference waits for the robot
  // instead of running away from it. The body turned behind its reference sweeps poses FCL
  // never checked (safety.reference_yaw_gate_rad).
  static double progress_rate(double position_err_m, double yaw_err_rad, double yaw_gate_rad);
  // safety.reference_speed_lead_mps: the rate [0, 1] at which a reference moving at ref_v (world,
  // planar) may advance for a robot moving at robot_v: its speed is held to the robot's speed
  // along it plus lead_mps. Entered mid-way (ControlLaw::entry_time) or after a stop, a reference
  // at walking speed leaves a robot near rest behind: it needs v / a_max to catch up and cuts the
  // corners the reference goes round. 1 with lead_mps <= 0 (off).
  static double speed_rate(const Eigen::Vector2d& ref_v, const Eigen::Vector2d& robot_v,
                           double lead_mps);
  // safety.check_body_turn: the poses the body sweeps from `pose` as it closes its yaw error to
  // ref, at most kTurnStepRad apart, ending at ref's yaw; empty under kTurnMinRad of error. The
  // proportional law closes the yaw error at k_yaw and the position error at k_position, so at
  // a fraction f of the turn the body has covered 1 - (1 - f)^(k_position / k_yaw) of the way to
  // ref's position: it turns mostly where it is, which is not where the trajectory's poses were
  // checked when the body is off its reference (pitch 0: the checker puts it on the terrain;
  // t_s: the pose's stamp).
  void turn_poses(const core::plan::TrajectorySample& ref, const PoseSample& pose,
                  std::vector<core::plan::BodyPose>& out) const;
  static constexpr double kTurnStepRad = 0.1, kTurnMinRad = 0.15;
  // safety.check_body_turn's answer when turn_poses collide: the poses of a body that holds its
  // yaw while it slides to ref's position (at most kSlideStepM apart), then turns there to ref's
  // yaw, where the trajectory's own poses were checked. Empty when the body is more than
  // kSlideMaxM off (the reference waits for it from 0.6 m anyway) or under kTurnMinRad off.
  void slide_poses(const core::plan::TrajectorySample& ref, const PoseSample& pose,
                   std::vector<core::plan::BodyPose>& out) const;
  static constexpr double kSlideStepM = 0.1, kSlideMaxM = 0.6;
  // Upper bound on the poses turn_poses and slide_poses yield (to reserve, never to allocate in
  // the control task).
  static size_t max_swept_poses();
  // Clamps a command to speed / yaw-rate limits and rate-limits it against prev (exposed for
  // tests).
  VelocityCommand limit(VelocityCommand cmd, const VelocityCommand& prev, double dt_s) const;
  const core::RobotModel& robot() const { return robot_; }

 private:
  // Distance between the points where the robot and the reference would come to rest if both
  // braked at a_max now [m]: 0 when the robot is on the reference at its speed.
  double braking_gap(const core::plan::TrajectorySample& ref, const PoseSample& pose) const;

  core::RobotModel robot_;
  ControlGains gains_;
};

// Wraps an angle to (-pi, pi].
double wrap_angle(double a);

}  // namespace storey::firmware

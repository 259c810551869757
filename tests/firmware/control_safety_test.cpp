// Control law limits and the safety monitor's stop reasons (DESIGN §3).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/map/traversability_map.hpp"
#include "firmware/control_law.hpp"
#include "firmware/safety_monitor.hpp"

namespace storey::firmware {
namespace {

core::plan::TrajectorySample ref_at(double x, double y, double vx, double vy, double yaw) {
  core::plan::TrajectorySample s;
  s.p_m = {x, y, 0};
  s.v_mps = {vx, vy, 0};
  s.yaw_rad = yaw;
  return s;
}

TEST(ControlLaw, ClampsSpeedYawRateAndAcceleration) {
  core::RobotModel robot;  // 1 m/s, 1 rad/s, 1 m/s^2, 2 rad/s^2
  ControlLaw law(robot);
  PoseSample pose;
  pose.stamp_s = 0;
  VelocityCommand prev;
  // Far away target moving at twice the speed limit: the speed saturates, but only by a*dt per
  // period.
  const double dt = 0.02;
  VelocityCommand c = law.track(ref_at(10, 0, 2, 0, 0.0), pose, prev, dt);
  EXPECT_NEAR(std::hypot(c.vx_mps, c.vy_mps), robot.max_accel_mps2 * dt, 1e-9);
  for (int i = 0; i < 500; ++i) {
    const VelocityCommand n = law.track(ref_at(10, 0, 2, 0, 0.0), pose, c, dt);
    EXPECT_LE(std::hypot(n.vx_mps - c.vx_mps, n.vy_mps - c.vy_mps),
              robot.max_accel_mps2 * dt + 1e-9);
    c = n;
  }
  EXPECT_NEAR(std::hypot(c.vx_mps, c.vy_mps), robot.max_speed_mps, 1e-9);
  EXPECT_GT(c.vx_mps, 0.99);  // heading +x in the body frame (yaw 0)
  // On the reference at rest, large yaw error: the yaw rate saturates, by yaw_acc*dt per period.
  c = law.track(ref_at(0, 0, 0, 0, 3.0), pose, prev, dt);
  EXPECT_NEAR(c.yaw_rate_rps, robot.max_yaw_accel_rps2 * dt, 1e-9);
  for (int i = 0; i < 500; ++i) {
    const VelocityCommand n = law.track(ref_at(0, 0, 0, 0, 3.0), pose, c, dt);
    EXPECT_LE(std::abs(n.yaw_rate_rps - c.yaw_rate_rps), robot.max_yaw_accel_rps2 * dt + 1e-9);
    c = n;
  }
  EXPECT_NEAR(c.yaw_rate_rps, robot.max_yaw_rate_rps, 1e-9);
}

// A new trajectory that starts at rest, turning in place, reaches a robot walking past its start
// at 0.95 m/s (teaching_building seed 1, 842 s): the robot brakes and comes back before it turns.
TEST(ControlLaw, TurnsOnlyWhereItWillComeToRestOnTheReference) {
  core::RobotModel robot;
  ControlLaw law(robot);
  const auto start = ref_at(0, 0, 0, 0, 1.5);  // the new trajectory's start: turn left in place
  PoseSample pose;
  pose.vx_mps = 0.95;  // walking +x past it
  EXPECT_EQ(law.on_reference(start, pose), 0.0);
  VelocityCommand prev;
  prev.vx_mps = 0.95;
  // Closed loop with a robot that does what it is told: no yaw until it is back on the start.
  const double dt = 0.02;
  double max_x = 0, yaw_when_far = 0;
  for (int i = 0; i < 400; ++i) {
    const VelocityCommand c = law.track(start, pose, prev, dt, law.on_reference(start, pose));
    pose.x_m += dt * (std::cos(pose.yaw_rad) * c.vx_mps - std::sin(pose.yaw_rad) * c.vy_mps);
    pose.y_m += dt * (std::sin(pose.yaw_rad) * c.vx_mps + std::cos(pose.yaw_rad) * c.vy_mps);
    pose.yaw_rad += dt * c.yaw_rate_rps;
    pose.vx_mps = c.vx_mps, pose.vy_mps = c.vy_mps, pose.yaw_rate_rps = c.yaw_rate_rps;
    max_x = std::max(max_x, pose.x_m);
    if (std::hypot(pose.x_m, pose.y_m) > 0.3) yaw_when_far = std::max(yaw_when_far, pose.yaw_rad);
    prev = c;
  }
  EXPECT_GT(max_x, 0.4);                 // the overshoot is real (0.95^2 / 2 = 0.45 m)...
  EXPECT_LT(yaw_when_far, 0.05);         // ...but the body does not turn out there
  EXPECT_NEAR(pose.yaw_rad, 1.5, 0.05);  // it turns once back on the start
  EXPECT_LT(std::hypot(pose.x_m, pose.y_m), 0.05);
  // Tracking a moving reference closely (same braking point): full yaw authority.
  PoseSample moving;
  moving.vx_mps = 0.9;
  EXPECT_EQ(law.on_reference(ref_at(0.05, 0, 0.9, 0, 0), moving), 1.0);
  // Once the robot has been on the trajectory (not `entering` it), a lag does not gate the yaw
  // (on a flight the robot trails its reference; gated, it drifted off the axis).
  PoseSample lagging;
  lagging.x_m = -0.5;
  EXPECT_EQ(law.track(start, lagging, VelocityCommand{}, dt, law.on_reference(start, lagging))
                .yaw_rate_rps,
            0.0);
  EXPECT_GT(law.track(start, lagging, VelocityCommand{}, dt).yaw_rate_rps, 0.0);
}

// safety.turn_on_reference_full_m / _zero_m set on_reference's ramp: a rest point 0.2 m from the
// reference's has 2/3 of full yaw with the defaults (0.15 / 0.3), none with 0.05 / 0.15.
TEST(ControlLaw, OnReferenceRampFromTheGains) {
  core::RobotModel robot;
  const auto ref = ref_at(0, 0, 0, 0, 1.5);
  PoseSample pose;
  pose.x_m = 0.2;  // at rest, 0.2 m past a turn-in-place start
  EXPECT_NEAR(ControlLaw(robot).on_reference(ref, pose), 2.0 / 3.0, 1e-9);
  ControlGains tight;
  tight.on_reference_full_m = 0.05;
  tight.on_reference_zero_m = 0.15;
  const ControlLaw law(robot, tight);
  EXPECT_EQ(law.on_reference(ref, pose), 0.0);
  pose.x_m = 0.1;
  EXPECT_NEAR(law.on_reference(ref, pose), 0.5, 1e-9);
  pose.x_m = 0.04;
  EXPECT_EQ(law.on_reference(ref, pose), 1.0);
}

// A body entering a trajectory mid-way from rest (ControlLaw::entry_time) lags a reference at
// walking speed and never comes to rest at it: on_reference alone held its yaw 16 deg off the
// path's until it met a jamb (office, nearest-frontier seed 5, 184 s). Where it rests on the path
// the gate opens; a body overshooting the start of a path that turns away, or coming back from
// it 0.2 m off (teaching building seed 2, 533.9 s: gated by the ramp on_reference uses, it
// turned into a wall), is still gated.
TEST(ControlLaw, ABodyLaggingItsReferenceOnThePathTurns) {
  core::RobotModel robot;
  ControlLaw law(robot);
  // Along +x from rest at x = 0, 1 s per knot, to x = 3, heading +x.
  std::vector<Eigen::Vector3d> ctrl;
  for (double x : {0.0, 0.0, 0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.0, 3.0})
    ctrl.emplace_back(x, 0.0, 0.0);
  const core::plan::BsplineTrajectory t(ctrl, std::vector<double>(ctrl.size(), 0.0), 1.0, 10.0);
  const double tau = 13.0;  // at x = 1, 0.5 m/s
  const core::plan::TrajectorySample ref = t.sample(tau);
  ASSERT_GT(ref.v_mps.x(), 0.4);
  PoseSample pose;  // at rest on the path, 0.28 m behind the reference, 0.3 rad off its yaw
  pose.x_m = ref.p_m.x() - 0.28;
  pose.yaw_rad = -0.3;
  EXPECT_EQ(law.on_reference(ref, pose), 0.0);
  EXPECT_EQ(law.on_path(t, tau - 2.0, tau, pose), 1.0);
  EXPECT_EQ(law.yaw_gate(t, 12.0, tau, ref, pose), 1.0);  // entered at x = 0.5
  EXPECT_GT(law.track(ref, pose, VelocityCommand{}, 0.02, law.yaw_gate(t, 12.0, tau, ref, pose))
                .yaw_rate_rps,
            0.0);
  // Not the path before the entry, which the reference never came along: entered at tau
  // itself, the body 0.28 m behind it is still gated.
  EXPECT_LT(law.yaw_gate(t, tau, tau, ref, pose), 0.2);
  // Beside the path: the ramp from 0.05 m to 0.15 m, tighter than on_reference's.
  pose.y_m = 0.1;
  EXPECT_NEAR(law.on_path(t, tau - 2.0, tau, pose), 0.5, 0.01);  // sampled path
  pose.y_m = 0.2;
  EXPECT_EQ(law.on_path(t, tau - 2.0, tau, pose), 0.0);
  // Only the path the reference has come along within the window counts: the same body ahead
  // of a reference that just left the start is off it.
  pose.y_m = 0.0;
  EXPECT_EQ(law.on_path(t, 8.0, 10.5, pose), 0.0);
  // Walking at 0.95 m/s past the start of a path that turns away (+y): the rest point is off
  // the path, no yaw.
  std::vector<Eigen::Vector3d> side;
  for (double y : {0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0}) side.emplace_back(0.0, y, 0.0);
  const core::plan::BsplineTrajectory u(side, std::vector<double>(side.size(), M_PI / 2), 1.0, 0.0);
  PoseSample walking;
  walking.vx_mps = 0.95;
  EXPECT_EQ(law.yaw_gate(u, 0.0, 0.0, u.sample(0.0), walking), 0.0);
  EXPECT_EQ(law.on_path(core::plan::BsplineTrajectory{}, 0.0, 1.0, walking), 0.0);
}

// plan.brake_start: the planner starts a moving robot's new trajectory where it comes to rest.
// Tracking enters a trajectory at its point nearest the robot within its first 2 s; nearest the
// rest point, that is its start. A trajectory that starts there and turns back passes the
// robot's own position later: entered there, its turn at the start was cut short (house seed 2,
// session 16: the body swept into the stairwell's railing).
TEST(ControlLaw, ANewTrajectoryIsEnteredNearestWhereTheRobotComesToRest) {
  core::RobotModel robot;
  ControlLaw law(robot);
  PoseSample pose;
  pose.yaw_rad = M_PI / 2;
  pose.vx_mps = 0.8;  // body forward = world +y
  const Eigen::Vector2d rest = law.rest_point(pose);
  EXPECT_NEAR(rest.x(), 0.0, 1e-9);
  EXPECT_NEAR(rest.y(), 0.8 * 0.8 / (2 * robot.max_accel_mps2), 1e-9);
  // From the rest point (0, 0.32) back through the robot's position (0, 0) to (0, -1.5), 1 s per
  // knot: the start at rest, the robot's position passed about 1 s in.
  std::vector<Eigen::Vector3d> ctrl;
  for (double y : {0.32, 0.32, 0.32, 0.0, -0.5, -1.0, -1.5, -1.5, -1.5})
    ctrl.emplace_back(0.0, y, 0.0);
  const core::plan::BsplineTrajectory t(ctrl, std::vector<double>(ctrl.size(), M_PI / 2), 1.0,
                                        10.0);
  EXPECT_NEAR(ControlLaw::entry_time(t, rest), 10.0, 0.05);
  EXPECT_GT(ControlLaw::entry_time(t, {pose.x_m, pose.y_m}), 10.5);
  // It leaves its start against the robot's velocity: the robot brakes on the trajectory it
  // follows first. One carrying on along the velocity is entered at once; one turning the body
  // in place at its start is not.
  EXPECT_TRUE(law.turns_away(t, {0.0, 0.8}));
  EXPECT_FALSE(law.turns_away(t, {0.0, -0.8}));
  EXPECT_FALSE(law.turns_away(t, {0.3, -0.8}));
  std::vector<double> turning(ctrl.size(), M_PI / 2);
  turning[2] = turning[3] = turning[4] = -0.5;
  const core::plan::BsplineTrajectory turn(ctrl, turning, 1.0, 10.0);
  EXPECT_TRUE(law.turns_away(turn, {0.0, -0.8}));
}

// plan.reference_catch_up: a new trajectory starts at rest, and a robot entering it at walking
// speed runs ahead of its reference (office seed 2 with graph.close_probes_at_wall_faces, 419 s:
// the body 0.47 m ahead and 0.11 m to the side of it met a table leg). The reference moves on to
// the path's point nearest the robot; it never moves for a robot behind it or beside it, and a
// path that doubles back past the robot is followed round, not cut short.
TEST(ControlLaw, TheReferenceCatchesUpWithARobotAheadOfIt) {
  // Along +x from rest at x = 0, 1 s per knot, to x = 3.
  std::vector<Eigen::Vector3d> ctrl;
  for (double x : {0.0, 0.0, 0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.0, 3.0})
    ctrl.emplace_back(x, 0.0, 0.0);
  const core::plan::BsplineTrajectory t(ctrl, std::vector<double>(ctrl.size(), 0.0), 1.0, 10.0);
  const double end = t.t_end();
  const double s = ControlLaw::catch_up_time(t, 10.0, end, {0.5, 0.05});  // 0.5 m ahead
  EXPECT_GT(s, 10.0);
  EXPECT_NEAR(t.sample(s).p_m.x(), 0.5, 0.06);
  EXPECT_EQ(ControlLaw::catch_up_time(t, 10.0, end, {0.05, 0.0}), 10.0);   // within 0.1 m
  EXPECT_EQ(ControlLaw::catch_up_time(t, 10.0, end, {-0.6, 0.0}), 10.0);   // behind
  EXPECT_EQ(ControlLaw::catch_up_time(t, 10.0, end, {0.0, 0.5}), 10.0);    // beside the start
  EXPECT_EQ(ControlLaw::catch_up_time(t, 12.0, 12.0, {2.0, 0.0}), 12.0);   // at tau_end
  const double far = ControlLaw::catch_up_time(t, 10.0, end, {3.0, 0.0});  // at most 2 s on
  EXPECT_LE(far, 12.0 + 1e-9);
  // Out along +x to x = 1 and back through the start to x = -1: a robot at x = -0.5 (where the
  // path passes again later) is behind the reference at the start, not ahead of it.
  std::vector<Eigen::Vector3d> back;
  for (double x : {0.0, 0.0, 0.0, 0.5, 1.0, 0.5, 0.0, -0.5, -1.0, -1.0, -1.0})
    back.emplace_back(x, 0.0, 0.0);
  const core::plan::BsplineTrajectory u(back, std::vector<double>(back.size(), 0.0), 0.2, 10.0);
  EXPECT_EQ(ControlLaw::catch_up_time(u, 10.0, u.t_end(), {-0.5, 0.0}), 10.0);
}

// Judged along the curve, not its clock: a re-timed trajectory leaves its start at rest at the
// acceleration limit, so its first second covers under 0.5 m and a bend just beyond went unseen
// (maze seed 1, 1030 s: entered at 0.97 m/s, the body overshot 0.45 m into a wall).
TEST(ControlLaw, ANewTrajectoryThatBendsWithinTheRobotsReachIsBrakedInto) {
  core::RobotModel robot;
  ControlLaw law(robot);
  const auto retimed = [&](std::vector<Eigen::Vector3d> path) {
    std::vector<Eigen::Vector3d> ctrl{path.front(), path.front()};
    for (size_t i = 0; i + 1 < path.size(); ++i)  // 0.25 m spacing, the ends clamped
      for (double k = 0; k < 1.0; k += 0.25 / (path[i + 1] - path[i]).norm())
        ctrl.push_back(path[i] + k * (path[i + 1] - path[i]));
    ctrl.insert(ctrl.end(), 3, path.back());
    std::vector<double> yaw;
    for (size_t i = 0; i < ctrl.size(); ++i) {
      const Eigen::Vector3d d = ctrl[std::min(i + 1, ctrl.size() - 1)] - ctrl[i > 0 ? i - 1 : 0];
      yaw.push_back(d.head<2>().norm() > 1e-9 ? std::atan2(d.y(), d.x()) : 0.0);
    }
    for (size_t i = 1; i < yaw.size(); ++i)  // continuous, as the planner's
      yaw[i] = yaw[i - 1] + wrap_angle(yaw[i] - yaw[i - 1]);
    core::plan::BsplineTrajectory t(ctrl, yaw, 0.5, 0.0);
    t.retime(robot);
    return t;
  };
  const Eigen::Vector2d v(0.97, 0.0);  // walking east at the speed limit
  // East for 0.6 m, then north: the bend is reached after the first second.
  const auto bend = retimed({{0, 0, 0}, {0.6, 0, 0}, {0.6, 3, 0}});
  ASSERT_TRUE(bend.retimed());
  EXPECT_LT((bend.sample(bend.t_start() + 1.0).p_m - bend.sample(bend.t_start()).p_m).norm(), 0.55);
  EXPECT_TRUE(law.turns_away(bend, v));
  // Straight on for 3 m: entered at once. The same walk ending 0.5 m on: braked into.
  EXPECT_FALSE(law.turns_away(retimed({{0, 0, 0}, {3, 0, 0}}), v));
  EXPECT_TRUE(law.turns_away(retimed({{0, 0, 0}, {0.5, 0, 0}}), v));
  // Slow enough to fall in behind the reference within 0.6 m: the bend is out of reach.
  EXPECT_FALSE(law.turns_away(bend, {0.4, 0.0}));
  // plan.start_at_speed: the same bend planned from the robot's velocity leaves its start at
  // 0.97 m/s and slows for the bend itself: entered at once. Not by a robot walking north.
  core::map::TraversabilityMap empty;
  core::plan::CollisionChecker cc(robot, 0.1);
  const std::vector<Eigen::Vector3d> path{{0, 0, 0}, {0.6, 0, 0}, {0.6, 3, 0}};
  const core::plan::TrajectoryResult at_speed =
      core::plan::TrajectoryBuilder(robot, {.retime = true})
          .build(empty.view(), cc, path, 0.0, std::nullopt, 0.0, v);
  ASSERT_GT(at_speed.start_speed_mps, 0.5);
  EXPECT_FALSE(law.turns_away(at_speed.trajectory, v));
  EXPECT_TRUE(law.turns_away(at_speed.trajectory, {0.0, 0.97}));
}

// safety.reference_yaw_gate_rad: the reference moves on at full rate within 0.3 m and the gate,
// slows linearly, and waits from 0.6 m or twice the gate; either sign of the yaw error.
TEST(ControlLaw, TheReferenceWaitsForABodyBehindItInPositionOrYaw) {
  EXPECT_DOUBLE_EQ(ControlLaw::progress_rate(0.0, 0.0, 0.6), 1.0);
  EXPECT_DOUBLE_EQ(ControlLaw::progress_rate(0.3, 0.6, 0.6), 1.0);
  EXPECT_NEAR(ControlLaw::progress_rate(0.45, 0.0, 0.6), 0.5, 1e-12);
  EXPECT_DOUBLE_EQ(ControlLaw::progress_rate(0.6, 0.0, 0.6), 0.0);
  EXPECT_NEAR(ControlLaw::progress_rate(0.0, 0.9, 0.6), 0.5, 1e-12);
  EXPECT_NEAR(ControlLaw::progress_rate(0.0, -0.9, 0.6), 0.5, 1e-12);
  EXPECT_DOUBLE_EQ(ControlLaw::progress_rate(0.0, 1.2, 0.6), 0.0);
  // A tighter gate: a body 34 deg behind (0.6 rad) holds the reference still.
  EXPECT_NEAR(ControlLaw::progress_rate(0.0, 0.45, 0.3), 0.5, 1e-12);
  EXPECT_DOUBLE_EQ(ControlLaw::progress_rate(0.0, 0.6, 0.3), 0.0);
  EXPECT_NEAR(ControlLaw::progress_rate(0.45, 0.45, 0.3), 0.25, 1e-12);
}

// safety.reference_speed_lead_mps: a robot near rest that enters a trajectory mid-way, where its
// reference walks at 0.7 m/s into a bend, trails the reference and cuts the bend (house seed 1,
// session 32: 0.31 m behind it, the body met a wall). Held to the robot's speed plus the lead,
// the reference waits for it, and the body stays on the curve the planner checked.
TEST(ControlLaw, TheReferenceIsNoFasterThanTheRobotCanFollow) {
  EXPECT_DOUBLE_EQ(ControlLaw::speed_rate({0.7, 0}, {0, 0}, 0.0), 1.0);  // off
  EXPECT_NEAR(ControlLaw::speed_rate({0.7, 0}, {0, 0}, 0.35), 0.5, 1e-12);
  EXPECT_NEAR(ControlLaw::speed_rate({0.7, 0}, {0.2, 0}, 0.3), 5.0 / 7.0, 1e-12);
  EXPECT_NEAR(ControlLaw::speed_rate({0.7, 0}, {0.2, 0}, 0.1), 3.0 / 7.0, 1e-12);
  EXPECT_NEAR(ControlLaw::speed_rate({0.7, 0}, {0, 0.5}, 0.35), 0.5, 1e-12);  // sideways: none
  EXPECT_NEAR(ControlLaw::speed_rate({0.7, 0}, {-0.5, 0}, 0.35), 0.5, 1e-12);
  EXPECT_DOUBLE_EQ(ControlLaw::speed_rate({0.7, 0}, {0.5, 0}, 0.3), 1.0);
  EXPECT_DOUBLE_EQ(ControlLaw::speed_rate({0, 0}, {0, 0}, 0.3), 1.0);  // at rest

  core::RobotModel robot;
  ControlLaw law(robot);
  // 0.5 m per knot at 0.7 s: 0.7 m/s along +x, then a right-angle bend to +y at x = 1.5.
  std::vector<Eigen::Vector3d> ctrl;
  std::vector<double> yaws;
  for (const auto& [x, y] : std::vector<std::pair<double, double>>{{0, 0},
                                                                   {0, 0},
                                                                   {0, 0},
                                                                   {0.5, 0},
                                                                   {1, 0},
                                                                   {1.5, 0},
                                                                   {1.5, 0.5},
                                                                   {1.5, 1},
                                                                   {1.5, 1.5},
                                                                   {1.5, 1.5},
                                                                   {1.5, 1.5}}) {
    ctrl.emplace_back(x, y, 0.0);
    yaws.push_back(y > 0 ? M_PI / 2 : 0.0);
  }
  const core::plan::BsplineTrajectory t(ctrl, yaws, 0.7, 0.0);
  std::vector<Eigen::Vector2d> curve;
  for (double s = t.t_start(); s <= t.t_end(); s += 0.005)
    curve.push_back(t.sample(s).p_m.head<2>());
  const auto off_curve = [&](const PoseSample& p) {
    double d = 1e9;
    for (const auto& c : curve) d = std::min(d, (c - Eigen::Vector2d(p.x_m, p.y_m)).norm());
    return d;
  };
  const auto follow = [&](double lead_mps, double enter_x, double v0) {
    PoseSample pose;
    double tau = ControlLaw::entry_time(t, {enter_x, 0.0});
    pose.x_m = t.sample(tau).p_m.x();
    pose.vx_mps = v0;
    VelocityCommand prev;
    prev.vx_mps = v0;
    double worst = 0;
    const double dt = 0.02;
    for (int i = 0; i < 500; ++i) {
      core::plan::TrajectorySample ref = t.sample(std::min(tau, t.t_end()));
      const double k = ControlLaw::speed_rate(ref.v_mps.head<2>(), pose.velocity_world(), lead_mps);
      ref.v_mps *= k, ref.yaw_rate_rps *= k;
      const VelocityCommand c = law.track(ref, pose, prev, dt);
      pose.x_m += dt * (std::cos(pose.yaw_rad) * c.vx_mps - std::sin(pose.yaw_rad) * c.vy_mps);
      pose.y_m += dt * (std::sin(pose.yaw_rad) * c.vx_mps + std::cos(pose.yaw_rad) * c.vy_mps);
      pose.yaw_rad += dt * c.yaw_rate_rps;
      pose.vx_mps = c.vx_mps, pose.vy_mps = c.vy_mps, pose.yaw_rate_rps = c.yaw_rate_rps;
      const double err = std::hypot(ref.p_m.x() - pose.x_m, ref.p_m.y() - pose.y_m);
      tau += dt * k * ControlLaw::progress_rate(err, wrap_angle(ref.yaw_rad - pose.yaw_rad), 0.6);
      worst = std::max(worst, off_curve(pose));
      prev = c;
    }
    EXPECT_LT(std::hypot(pose.x_m - 1.5, pose.y_m - 1.5), 0.05) << "lead " << lead_mps;
    return worst;
  };
  // Entered where it starts, at rest: what tracking the curve costs anyway.
  const double from_start = follow(0.0, 0.0, 0.0);
  // Entered mid-way, braked nearly to rest.
  const double free_running = follow(0.0, 1.1, 0.1), held = follow(0.1, 1.1, 0.1);
  std::printf("body off the curve: %.3f m from the start, %.3f m free running, %.3f m held\n",
              from_start, free_running, held);
  EXPECT_LT(from_start, 0.01);
  EXPECT_GT(free_running, 0.06);
  EXPECT_LT(held, 0.03);
}

// A door jamb along +x 0.3 m to the left of a body at the origin (0.1 m voxels, 0.2-0.4 m up).
std::vector<Eigen::Vector3f> jamb_left_of_origin() {
  std::vector<Eigen::Vector3f> jamb;
  for (float x = 0.25f; x < 0.6f; x += 0.1f)
    for (float z = 0.25f; z < 0.4f; z += 0.1f) jamb.emplace_back(x, 0.3f, z);
  return jamb;
}

// safety.check_body_turn (office seed 2, session 40): a body 0.3 m ahead of a new trajectory's
// start, beside a door jamb, turns 0.6 rad towards the reference's yaw mostly where it stands.
// The reference's own pose is clear of the jamb; the body's turn is not.
TEST(ControlLaw, TheBodysTurnTowardsItsReferenceIsSweptWhereTheBodyIs) {
  core::RobotModel robot;
  ControlLaw law(robot);
  PoseSample pose;  // at the origin, yaw 0
  pose.stamp_s = 12.0;
  const auto ref = ref_at(-0.3, 0, 0, 0, 0.6);
  std::vector<core::plan::BodyPose> poses;
  law.turn_poses(ref, pose, poses);
  ASSERT_EQ(poses.size(), 6u);  // 0.6 rad in steps of at most 0.1
  double prev_yaw = pose.yaw_rad, prev_x = 0;
  for (const core::plan::BodyPose& p : poses) {
    EXPECT_LE(p.yaw_rad - prev_yaw, ControlLaw::kTurnStepRad + 1e-9);
    EXPECT_GT(p.yaw_rad, prev_yaw);
    EXPECT_LE(p.foot_m.x(), prev_x);  // on the way to the reference
    // The yaw error closes faster than the position error (k_yaw 2 > k_position 1.2).
    EXPECT_GE(p.yaw_rad / 0.6, p.foot_m.x() / -0.3 - 1e-9);
    EXPECT_EQ(p.t_s, 12.0);
    prev_yaw = p.yaw_rad, prev_x = p.foot_m.x();
  }
  EXPECT_NEAR(poses.back().yaw_rad, 0.6, 1e-12);
  EXPECT_NEAR((poses.back().foot_m - ref.p_m).norm(), 0.0, 1e-12);
  EXPECT_LT(poses[2].foot_m.x(), 0.0);
  EXPECT_GT(poses[2].foot_m.x(), -0.15);  // half turned, under half way

  const std::vector<Eigen::Vector3f> jamb = jamb_left_of_origin();
  core::plan::CollisionChecker checker(robot, 0.1);
  const core::plan::BodyPose here{pose.position(), 0.0, 0.0, 12.0};
  const core::plan::BodyPose at_ref{ref.p_m, ref.yaw_rad, 0.0, 12.0};
  EXPECT_FALSE(checker.check_poses(std::span(&here, 1), jamb).collides);
  EXPECT_FALSE(checker.check_poses(std::span(&at_ref, 1), jamb).collides);
  EXPECT_TRUE(checker.check_poses(poses, jamb).collides);

  // Under 0.15 rad of yaw error nothing is swept (tracking closes it on the way).
  law.turn_poses(ref_at(-0.3, 0, 0, 0, 0.14), pose, poses);
  EXPECT_TRUE(poses.empty());
  law.turn_poses(ref_at(-0.3, 0, 0, 0, -0.16), pose, poses);
  EXPECT_EQ(poses.size(), 2u);
  EXPECT_NEAR(poses.back().yaw_rad, -0.16, 1e-12);
}

// safety.check_body_turn's answer (session 42): where the proportional turn would sweep the jamb,
// the body slides onto its reference at its own yaw and turns there.
TEST(ControlLaw, ABodyWhoseTurnWouldSweepAJambSlidesOntoItsReferenceAndTurnsThere) {
  core::RobotModel robot;
  ControlLaw law(robot);
  PoseSample pose;  // at the origin, yaw 0
  pose.stamp_s = 3.0;
  const auto ref = ref_at(-0.3, 0, 0, 0, 0.6);
  std::vector<core::plan::BodyPose> poses;
  law.slide_poses(ref, pose, poses);
  ASSERT_EQ(poses.size(), 3u + 6u);  // 0.3 m in 0.1 m steps, then 0.6 rad in 0.1 rad steps
  for (size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(poses[k].yaw_rad, 0.0);  // the yaw held while it slides
    EXPECT_NEAR(poses[k].foot_m.x(), -0.1 * double(k + 1), 1e-12);
  }
  for (size_t k = 3; k < poses.size(); ++k) {
    EXPECT_NEAR((poses[k].foot_m - ref.p_m).norm(), 0.0, 1e-12);  // turns on the reference
    EXPECT_NEAR(poses[k].yaw_rad, 0.1 * double(k - 2), 1e-12);
    EXPECT_EQ(poses[k].t_s, 3.0);
  }
  EXPECT_LE(poses.size(), ControlLaw::max_swept_poses());

  // The jamb the proportional turn sweeps (TheBodysTurnTowardsItsReferenceIsSweptWhereTheBodyIs)
  // is clear of the slide and of the turn on the reference.
  const std::vector<Eigen::Vector3f> jamb = jamb_left_of_origin();
  core::plan::CollisionChecker checker(robot, 0.1);
  std::vector<core::plan::BodyPose> turn;
  law.turn_poses(ref, pose, turn);
  EXPECT_TRUE(checker.check_poses(turn, jamb).collides);
  EXPECT_FALSE(checker.check_poses(poses, jamb).collides);

  // While it slides no yaw is commanded; the position is still tracked.
  const VelocityCommand held = law.track(ref, pose, VelocityCommand{}, 0.02, 0.0);
  EXPECT_EQ(held.yaw_rate_rps, 0.0);
  EXPECT_LT(held.vx_mps, 0.0);
  EXPECT_GT(law.track(ref, pose, VelocityCommand{}, 0.02).yaw_rate_rps, 0.0);

  // Nothing to slide: under kTurnMinRad off, or further off than kSlideMaxM (the reference waits
  // for the robot from 0.6 m), or a non-finite reference.
  law.slide_poses(ref_at(-0.3, 0, 0, 0, 0.1), pose, poses);
  EXPECT_TRUE(poses.empty());
  law.slide_poses(ref_at(-0.7, 0, 0, 0, 0.6), pose, poses);
  EXPECT_TRUE(poses.empty());
  law.slide_poses(ref_at(std::nan(""), 0, 0, 0, 0.6), pose, poses);
  EXPECT_TRUE(poses.empty());
}

TEST(ControlLaw, FeedforwardInBodyFrameAndNanGuard) {
  core::RobotModel robot;
  ControlLaw law(robot);
  PoseSample pose;
  pose.yaw_rad = M_PI / 2;  // facing +y
  VelocityCommand prev;
  prev.vy_mps = -0.5;  // already moving: world +x is body -y
  const VelocityCommand c = law.track(ref_at(0, 0, 0.5, 0, M_PI / 2), pose, prev, 0.02);
  EXPECT_NEAR(c.vx_mps, 0.0, 1e-9);
  EXPECT_NEAR(c.vy_mps, -0.5, 1e-9);
  VelocityCommand bad;
  bad.vx_mps = std::nan("");
  const VelocityCommand z = law.limit(bad, VelocityCommand{}, 0.02);
  EXPECT_TRUE(z.is_zero());
}

SafetyInputs fresh(double now) {
  SafetyInputs in;
  in.now_s = now;
  in.last_scan_s = now - 0.05;
  in.pose_stamp_s = now - 0.01;
  in.following = true;
  in.trajectory_vouched_s = now - 0.2;
  in.link_connected = true;
  in.link_last_state_s = now - 0.01;
  return in;
}

TEST(SafetyMonitor, WaitsUntilArmedWithoutCountingAStop) {
  SafetyMonitor m(config::SafetyConfig{});
  SafetyInputs in = fresh(1.0);
  in.last_scan_s = -1;  // no scan yet
  SafetyDecision d = m.evaluate(in);
  EXPECT_TRUE(d.stop);
  EXPECT_FALSE(m.armed());
  EXPECT_EQ(m.stops(), 0u);
  d = m.evaluate(fresh(1.02));
  EXPECT_FALSE(d.stop);
  EXPECT_TRUE(m.armed());
}

// Each reason: the evaluation in which the condition first holds commands the stop (so the
// command of that same control period is zero), is reported once, counted, and clears.
TEST(SafetyMonitor, EveryReasonStopsOnceAndClears) {
  const config::SafetyConfig cfg;
  struct Case {
    StopReason reason;
    void (*apply)(SafetyInputs&, const config::SafetyConfig&);
  };
  const Case cases[] = {
      {StopReason::kLidarStale,
       [](SafetyInputs& in, const config::SafetyConfig& c) {
         in.last_scan_s = in.now_s - c.lidar_stale_s - 1e-3;
       }},
      {StopReason::kPoseStale,
       [](SafetyInputs& in, const config::SafetyConfig& c) {
         in.pose_stamp_s = in.now_s - c.pose_stale_s - 1e-3;
       }},
      {StopReason::kTrajectoryStale,
       [](SafetyInputs& in, const config::SafetyConfig& c) {
         in.trajectory_vouched_s = in.now_s - c.trajectory_stale_s - 1e-3;
       }},
      {StopReason::kLinkLoss,
       [](SafetyInputs& in, const config::SafetyConfig&) { in.link_connected = false; }},
      {StopReason::kPredictedCollision,
       [](SafetyInputs& in, const config::SafetyConfig&) { in.collision_predicted = true; }},
      {StopReason::kOperatorStop,
       [](SafetyInputs& in, const config::SafetyConfig&) { in.operator_stop = true; }},
      {StopReason::kOverruns,
       [](SafetyInputs& in, const config::SafetyConfig&) { in.overruns = true; }},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(to_string(c.reason));
    SafetyMonitor m(cfg);
    double t = 10.0;
    ASSERT_FALSE(m.evaluate(fresh(t)).stop);
    for (int period = 0; period < 3; ++period) {
      t += 0.02;
      SafetyInputs in = fresh(t);
      c.apply(in, cfg);
      const SafetyDecision d = m.evaluate(in);
      EXPECT_TRUE(d.stop);
      EXPECT_EQ(d.mask, bit(c.reason));
      EXPECT_EQ(d.raised, period == 0 ? bit(c.reason) : 0u);
      EXPECT_EQ(d.new_stop, period == 0);
    }
    EXPECT_EQ(m.stops(), 1u);
    EXPECT_EQ(m.events(c.reason), 1u);
    t += 0.02;
    const SafetyDecision d = m.evaluate(fresh(t));
    EXPECT_FALSE(d.stop);
    EXPECT_EQ(d.cleared, bit(c.reason));
  }
}

TEST(SafetyMonitor, StaleTrajectoryOnlyWhileFollowing) {
  SafetyMonitor m(config::SafetyConfig{});
  ASSERT_FALSE(m.evaluate(fresh(5.0)).stop);
  SafetyInputs in = fresh(5.02);
  in.following = false;  // holding still: no trajectory to be stale
  in.trajectory_vouched_s = 0.0;
  EXPECT_FALSE(m.evaluate(in).stop);
}

TEST(SafetyMonitor, OverlappingReasonsAreOneStop) {
  SafetyMonitor m(config::SafetyConfig{});
  ASSERT_FALSE(m.evaluate(fresh(1.0)).stop);
  SafetyInputs a = fresh(1.02);
  a.operator_stop = true;
  EXPECT_TRUE(m.evaluate(a).new_stop);
  SafetyInputs b = fresh(1.04);
  b.operator_stop = true;
  b.link_connected = false;
  const SafetyDecision d = m.evaluate(b);
  EXPECT_FALSE(d.new_stop);
  EXPECT_EQ(d.raised, bit(StopReason::kLinkLoss));
  EXPECT_EQ(m.stops(), 1u);
}

}  // namespace
}  // namespace storey::firmware

// Control law limits and the safety monitor's stop reasons (DESIGN §3).
#include <gtest/gtest.h>

#include <cmath>

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
  // Far away target, large yaw error: the command saturates, but only by a*dt per period.
  const double dt = 0.02;
  VelocityCommand c = law.track(ref_at(10, 0, 2, 0, 3.0), pose, prev, dt);
  EXPECT_NEAR(std::hypot(c.vx_mps, c.vy_mps), robot.max_accel_mps2 * dt, 1e-9);
  EXPECT_NEAR(c.yaw_rate_rps, robot.max_yaw_accel_rps2 * dt, 1e-9);
  for (int i = 0; i < 500; ++i) {
    const VelocityCommand n = law.track(ref_at(10, 0, 2, 0, 3.0), pose, c, dt);
    EXPECT_LE(std::hypot(n.vx_mps - c.vx_mps, n.vy_mps - c.vy_mps),
              robot.max_accel_mps2 * dt + 1e-9);
    EXPECT_LE(std::abs(n.yaw_rate_rps - c.yaw_rate_rps), robot.max_yaw_accel_rps2 * dt + 1e-9);
    c = n;
  }
  EXPECT_NEAR(std::hypot(c.vx_mps, c.vy_mps), robot.max_speed_mps, 1e-9);
  EXPECT_NEAR(c.yaw_rate_rps, robot.max_yaw_rate_rps, 1e-9);
  EXPECT_GT(c.vx_mps, 0.99);  // heading +x in the body frame (yaw 0)
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

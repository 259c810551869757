// DESIGN §3 fault drills in lockstep (deterministic): the full task table on the `house` scene
// through the simulator's Platform, with its fault switches. Each fault must end in a commanded
// stop (zero velocity) with the right reason within one control period of its threshold, be
// counted once, and exploration must resume when the cause ends.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "firmware/autonomy.hpp"
#include "rt/clock.hpp"
#include "tools/sim/scene.hpp"
#include "tools/sim/sim_platform.hpp"
#include "tools/sim/world_sim.hpp"

namespace storey::tools::sim {
namespace {

using firmware::StopReason;

struct Drill {
  Scene scene = load_scene("house");
  std::unique_ptr<WorldSim> world;
  std::unique_ptr<SimPlatform> platform;
  rt::VirtualClock clock{0};
  std::unique_ptr<firmware::Autonomy> autonomy;
  std::vector<std::string> log;
  std::int64_t t_ns = 0;

  Drill() {
    SimOptions so;
    so.seed = 3;
    world = std::make_unique<WorldSim>(scene, so);
    platform = std::make_unique<SimPlatform>(*world);
    firmware::AutonomyOptions ao;
    ao.stop_on_overruns = false;  // lockstep: wall-time overruns are not an input
    ao.log = [this](const std::string& l) { log.push_back(l); };
    autonomy = std::make_unique<firmware::Autonomy>(*platform, clock, ao);
  }
  // Runs until simulated time t [s]; `each` is called after every 10 ms slice.
  void run_to(double t, const std::function<void()>& each = {}) {
    while (t_ns < std::int64_t(std::llround(t * 1e9))) {
      autonomy->run_until(clock, t_ns + 10'000'000);
      platform->step(0.01);
      t_ns += 10'000'000;
      if (each) each();
    }
  }
  double now() const { return double(t_ns) * 1e-9; }
  double distance() const { return world->robot_state().distance; }

  // Inject a fault at `at`, hold it for `hold` s, check the stop, clear it, check recovery.
  void drill(StopReason reason, double threshold_s, const std::function<void(bool)>& set) {
    run_to(10.0);
    ASSERT_GT(distance(), 0.2) << "the robot should be exploring before the drill";
    ASSERT_EQ(autonomy->active_stop_mask(), 0u);
    ASSERT_EQ(autonomy->stop_events(reason), 0u);
    const double t0 = now();
    set(true);
    double stopped_at = -1;
    run_to(t0 + threshold_s + 0.5, [&] {
      if (stopped_at < 0 && (autonomy->active_stop_mask() & firmware::bit(reason)))
        stopped_at = now();
    });
    ASSERT_GE(stopped_at, 0) << "no " << firmware::to_string(reason) << " stop";
    // The stop comes within one control period (20 ms) of the threshold (+ one 10 ms slice).
    EXPECT_LE(stopped_at - t0, threshold_s + 0.02 + 0.01 + 1e-9);
    EXPECT_EQ(autonomy->stop_events(reason), 1u);
    EXPECT_TRUE(autonomy->last_command().is_zero());
    EXPECT_TRUE(platform->command().is_zero() || reason == StopReason::kLinkLoss);
    const double d_stopped = distance();
    set(false);
    run_to(now() + 1.0);
    EXPECT_EQ(autonomy->active_stop_mask() & firmware::bit(reason), 0u) << "not cleared";
    run_to(now() + 8.0);
    EXPECT_GT(distance(), d_stopped + 0.3) << "exploration did not resume";
    EXPECT_EQ(world->robot_state().collisions, 0u);
    EXPECT_EQ(world->robot_state().falls, 0u);
    bool raised = false, cleared = false;
    for (const auto& l : log) {
      if (l.find(std::string("raised: ") + firmware::to_string(reason)) != std::string::npos)
        raised = true;
      if (l.find(std::string("cleared: ") + firmware::to_string(reason)) != std::string::npos)
        cleared = true;
    }
    EXPECT_TRUE(raised && cleared) << "stop not logged with its reason";
  }
};

TEST(FaultDrill, LidarPacketsStopped) {
  Drill d;
  d.drill(StopReason::kLidarStale, 0.3, [&](bool on) { d.platform->set_lidar_silent(on); });
}

TEST(FaultDrill, RobotLinkCut) {
  Drill d;
  d.drill(StopReason::kLinkLoss, 0.25, [&](bool on) { d.platform->set_link_down(on); });
}

TEST(FaultDrill, PoseFrozen) {
  Drill d;
  d.drill(StopReason::kPoseStale, 0.1, [&](bool on) { d.platform->set_pose_frozen(on); });
}

TEST(FaultDrill, OperatorStop) {
  Drill d;
  d.drill(StopReason::kOperatorStop, 0.0, [&](bool on) { d.autonomy->set_operator_stop(on); });
}

}  // namespace
}  // namespace storey::tools::sim

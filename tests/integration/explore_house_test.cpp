// The full stack (firmware task table, map, graph, local planner, control, safety) explores the
// two-floor `house` scene in lockstep. With the local layer alone (no macro layer / prior yet)
// the robot explores the ground floor and finds the stairs; the upper floor arrives with the
// ExplorationPlanner, so this test asserts what holds today: ground-floor coverage, completion,
// zero collisions and falls, and bit-for-bit repeatability for a seed.
#include <gtest/gtest.h>

#include "tools/sim/sim_run.hpp"

namespace storey::tools::sim {
namespace {

SimRunResult explore_house(uint64_t seed) {
  SimRunOptions o;
  o.scene = "house";
  o.seed = seed;
  o.time_limit_s = 300;
  o.progress_period_s = 0;  // no progress lines; coverage still sampled at the end
  o.progress = [](const std::string&) {};
  return run_exploration(o);
}

TEST(ExploreHouse, GroundFloorSafelyAndDeterministically) {
  const SimRunResult a = explore_house(1);
  const RunMetrics& m = a.metrics;
  EXPECT_TRUE(a.completed) << a.end_reason;
  EXPECT_EQ(m.collisions, 0u);
  EXPECT_EQ(m.falls, 0u);
  ASSERT_EQ(m.floors_total, 2);
  // Measured 0.871 with the local layer alone, complete at 101 s (docs/RESULTS.md); the DESIGN
  // bar is 0.95 on every floor. The upper floor needs the macro layer (ExplorationPlanner).
  EXPECT_GE(m.per_floor[0].traversable_coverage, 0.8);
  EXPECT_GT(m.trajectory_length_m, 5.0);
  EXPECT_LT(m.exploration_time_s, 300.0);

  const SimRunResult b = explore_house(1);
  const RunMetrics& n = b.metrics;
  // Everything but the latency profile (real CPU time) is a function of the inputs.
  EXPECT_EQ(a.end_reason, b.end_reason);
  EXPECT_EQ(m.exploration_time_s, n.exploration_time_s);
  EXPECT_EQ(m.trajectory_length_m, n.trajectory_length_m);
  EXPECT_EQ(m.traversable_coverage, n.traversable_coverage);
  EXPECT_EQ(m.traversable_volume_m3, n.traversable_volume_m3);
  EXPECT_EQ(m.occupied_volume_m3, n.occupied_volume_m3);
  EXPECT_EQ(m.safety_stops, n.safety_stops);
  EXPECT_EQ(m.coverage_over_time, n.coverage_over_time);
}

TEST(ExploreHouse, RefusesWhatIsNotAvailable) {
  SimRunOptions o;
  o.scene = "house";
  o.method = "fael-like";
  EXPECT_THROW(run_exploration(o), std::invalid_argument);
  o.method = "storey";
  o.ablation = "no-prior";
  EXPECT_THROW(run_exploration(o), std::invalid_argument);
  o.ablation = "no-such-thing";
  EXPECT_THROW(run_exploration(o), std::invalid_argument);
  o.ablation = "";
  o.scene = "no_such_scene";
  EXPECT_THROW(run_exploration(o), std::invalid_argument);
}

}  // namespace
}  // namespace storey::tools::sim

// The full stack climbs test_stair's one straight flight (18 risers, 3.0 m) blind and explores
// the floor above, in lockstep. The flight ends 0.8 m short of the box's end wall: the climb,
// planned from below before that wall is seen, runs into it on the new map, is dropped on the
// flight and must go on up from there; the flight climbed blind is then left out of the
// firmware's completion check, as it is out of the planner's targets.
#include <gtest/gtest.h>

#include "tests/integration/expectations.hpp"
#include "tools/sim/sim_run.hpp"

namespace storey::tools::sim {
namespace {

TEST(ExploreStair, AClimbStoppedOnTheFlightGoesOnUpAndTheRunEndsComplete) {
  const SimRunResult r = run_exploration(quiet_run("test_stair", 1, 300));
  const RunMetrics& m = r.metrics;
  // Measured (seed 1, session 12): complete at 85.5 s, floors 0.858 / 0.811. Before: the climb
  // ended mid-flight (z ~ 1.5 m), no graph node grew there and the run ended complete at 71.0 s
  // with the upper floor at 0.058; with that fixed but the completion check counting the climbed
  // flight's frontiers, it ran to the 300 s limit.
  EXPECT_TRUE(r.completed) << r.end_reason;
  EXPECT_LT(m.exploration_time_s, 200.0);
  EXPECT_EQ(m.collisions, 0u);
  EXPECT_EQ(m.falls, 0u);
  ASSERT_EQ(m.per_floor.size(), 2u);
  EXPECT_GE(m.per_floor[0].traversable_coverage, 0.75);
  EXPECT_GE(m.per_floor[1].traversable_coverage, 0.8) << "the upper floor was not explored";
}

}  // namespace
}  // namespace storey::tools::sim

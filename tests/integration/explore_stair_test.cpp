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

// Ended complete, no collision or fall, the floor at >= 75 % and the upper floor at >= 80 % (the
// flight's stairwell and landing walls leave less to see than the house's 90 % bar).
void expect_both_floors_safely(const SimRunResult& r) {
  const RunMetrics& m = r.metrics;
  EXPECT_TRUE(r.completed) << r.end_reason;
  EXPECT_EQ(m.collisions, 0u);
  EXPECT_EQ(m.falls, 0u);
  ASSERT_EQ(m.per_floor.size(), 2u);
  EXPECT_GE(m.per_floor[0].traversable_coverage, 0.75);
  EXPECT_GE(m.per_floor[1].traversable_coverage, 0.8) << "the upper floor was not explored";
}

TEST(ExploreStair, AClimbStoppedOnTheFlightGoesOnUpAndTheRunEndsComplete) {
  const SimRunResult r = run_exploration(quiet_run("test_stair", 1, 300));
  const RunMetrics& m = r.metrics;
  // Measured (seed 1, session 26): complete at 113.5 s, floors 0.893 / 0.855. Session 23: 86.5 s,
  // 0.870 / 0.835 (session 22: 122.5 s,
  // 0.870 / 0.852; session 18: 135.0 s, 0.884 / 0.847; with session 22's braking fix and not yet
  // the no-retry-after-a-climb rule, the robot climbed, walked back down toward old path failures
  // and ended with 0.295 upstairs). With flight_foot, near a climb deferred beside the flight but
  // facing away, it walks to the deferral's pose again (session 17 dropped it there and ended
  // at 86.5 s with the upper floor at 0.0). Session 12 (before flight_foot): 85.5 s, 0.858 / 0.811.
  // Before that: the climb ended mid-flight (z ~ 1.5 m), no graph node grew there and the run ended
  // complete at 71.0 s with the upper floor at 0.058; with that fixed but the completion check
  // counting the climbed flight's frontiers, it ran to the 300 s limit.
  expect_both_floors_safely(r);
  EXPECT_LT(m.exploration_time_s, 260.0);
}

// Seed 2 climbs test_stair's flight to its 1.07 m landing (top riser to wall) and must turn
// there to reach the upper floor. With plan.flight_foot, the blind-ring ground entered on the top
// tread while climbing laid the landing 0.17 m low in the map: every trajectory onto it pitched
// the body into the railing, each upper-floor cluster was set aside in turn and the run ended
// "complete" with the upper floor at 18.4 % (session 16). Now that ground is entered only where
// the robot walks level or a climb has ended on its landing (firmware/blind_support.hpp).
TEST(ExploreStair, TheNarrowLandingIsEnteredAtItsOwnHeight) {
  // Measured (seed 2, session 26): complete at 108.5 s, floors 0.862 / 0.852. Session 23: 103.5 s,
  // 0.865 / 0.848 (session 22: 145.0 s,
  // 0.874 / 0.856; session 18: 142.0 s, 0.892 / 0.872; session 17, flight_foot alone: 148.0 s,
  // 0.893 / 0.847).
  expect_both_floors_safely(run_exploration(quiet_run("test_stair", 2, 300)));
}

}  // namespace
}  // namespace storey::tools::sim

// The full stack crosses floors: the two-floor `test_ramp` scene (a 10 deg ramp, 17 m long,
// from floor 0 to floor 1 between side walls) explored in lockstep (stairs: explore_house_test).
#include <gtest/gtest.h>

#include "tests/integration/expectations.hpp"
#include "tools/sim/sim_run.hpp"

namespace storey::tools::sim {
namespace {

TEST(ExploreRamp, ReachesAndExploresTheUpperFloorSafely) {
  const SimRunResult r = run_exploration(quiet_run("test_ramp", 1, 600));
  const RunMetrics& m = r.metrics;
  EXPECT_EQ(m.collisions, 0u);
  EXPECT_EQ(m.falls, 0u);
  ASSERT_EQ(m.floors_total, 2);
  ASSERT_EQ(m.per_floor.size(), 2u);
  // Measured 0.938 / 0.899, complete at 431.5 s (seed 1, session 26, plan.arrive_along_path and
  // reach_off_graph on). Session 22: 0.914 / 0.942 at 275.0 s (seeds 2-3: upper floor 0.916 /
  // 0.947). Session 18: 0.918 / 0.945 at 515.5 s (seeds 2-4: upper floor 0.921 / 0.863 / 0.945).
  // Session 12: 0.938 / 0.730 at 596.5 s (seeds 2-4: 0.929 / 0.935 / 0.944; docs/RESULTS.md).
  // Session 11: 0.845 / 0.930 (0.916 / 0.916 with the session 9-11 switches off). Earlier: 0.893 /
  // 0.900 at 600 s. Since stair nosings are step edges (session 5) the robot takes the ramp before
  // floor 0 is done and comes back for it: at 360 s floor 0 stood at 0.40, floor 1 at 0.91 (before:
  // 0.87 / 0.73, floor 0 first). Before ramps were centred like level ground the robot never left
  // floor 0.
  EXPECT_GE(m.per_floor[0].traversable_coverage, 0.8);
  EXPECT_GE(m.per_floor[1].traversable_coverage, 0.7) << "the upper floor was not explored";
}

}  // namespace
}  // namespace storey::tools::sim

#pragma once
// Issue #9's bar for a whole exploration, shared by the integration tests: ended complete, every
// one of the scene's floors explored (>= 90 % of its traversable ground truth), no collision or
// fall.
#include <gtest/gtest.h>

#include "tools/sim/sim_run.hpp"

namespace storey::tools::sim {

inline void expect_every_floor_explored_safely(const SimRunResult& r, int floors) {
  const RunMetrics& m = r.metrics;
  EXPECT_TRUE(r.completed) << r.end_reason;
  EXPECT_EQ(m.collisions, 0u);
  EXPECT_EQ(m.falls, 0u);
  EXPECT_EQ(m.floors_total, floors);
  EXPECT_EQ(m.floors_explored, floors);
  for (const auto& f : m.per_floor) EXPECT_GE(f.traversable_coverage, 0.9) << "floor at " << f.z_m;
}

}  // namespace storey::tools::sim

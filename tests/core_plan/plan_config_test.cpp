#include "core/plan/plan_config.hpp"

#include <gtest/gtest.h>

namespace storey::core::plan {
namespace {

TEST(PlanConfig, OptionsFlowIntoComponents) {
  PlanOptions o;
  o.window_w = 3;
  o.lambda_psi = 0.7;
  o.lambda_a = 0.2;
  o.heading_via_viewpoint_yaw = true;
  o.tsp_exact_max_n = 9;
  o.astar_max_expansions = 1234;
  o.astar_reachable_only = false;
  o.traj_control_spacing_m = 0.4;
  o.traj_grade_corners = true;
  o.traj_retime = true;
  EXPECT_EQ(tsp_options(o).exact_max_n, 9);
  const ViewpointDpOptions d = dp_options(o);
  EXPECT_EQ(d.window_w, 3);
  EXPECT_DOUBLE_EQ(d.lambda_psi, 0.7);
  EXPECT_DOUBLE_EQ(d.lambda_a, 0.2);
  EXPECT_EQ(d.heading, HeadingModel::kViaViewpointYaw);
  EXPECT_EQ(astar_options(o).max_expansions, 1234u);
  EXPECT_FALSE(astar_options(o).reachable_only);
  EXPECT_DOUBLE_EQ(trajectory_options(o).control_spacing_m, 0.4);
  EXPECT_FALSE(trajectory_options(o).reachable_only);
  EXPECT_TRUE(trajectory_options(o).grade_corners);
  EXPECT_TRUE(trajectory_options(o).retime);
  o.astar_max_expansions = -5;  // nonsense from a config: still a bounded, non-zero search
  EXPECT_EQ(astar_options(o).max_expansions, 1u);
}

}  // namespace
}  // namespace storey::core::plan

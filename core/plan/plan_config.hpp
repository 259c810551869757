#pragma once
// PlanOptions (the configured parameters, config/ fills them) -> each component's options.
#include "core/plan/bspline_trajectory.hpp"
#include "core/plan/plan_options.hpp"
#include "core/plan/tsp.hpp"
#include "core/plan/viewpoint_dp.hpp"
#include "core/plan/voxel_astar.hpp"

namespace storey::core::plan {

inline TspOptions tsp_options(const PlanOptions& o) {
  TspOptions t;
  t.exact_max_n = o.tsp_exact_max_n;
  return t;
}

inline ViewpointDpOptions dp_options(const PlanOptions& o) {
  ViewpointDpOptions d;
  d.window_w = o.window_w;
  d.lambda_psi = o.lambda_psi;
  d.lambda_a = o.lambda_a;
  d.heading =
      o.heading_via_viewpoint_yaw ? HeadingModel::kViaViewpointYaw : HeadingModel::kTravelDirection;
  return d;
}

inline VoxelAStarOptions astar_options(const PlanOptions& o) {
  VoxelAStarOptions a;
  a.max_expansions = uint32_t(o.astar_max_expansions > 0 ? o.astar_max_expansions : 1);
  a.reachable_only = o.astar_reachable_only;
  a.cost_weight = o.astar_cost_weight;
  a.clearance_weight = o.astar_clearance_weight;
  a.goal_tolerance_m = o.astar_goal_tolerance_m;
  return a;
}

inline TrajectoryOptions trajectory_options(const PlanOptions& o) {
  TrajectoryOptions t;
  t.control_spacing_m = o.traj_control_spacing_m;
  t.max_repairs = o.traj_max_repairs;
  t.grade_corners = o.traj_grade_corners;
  t.retime = o.traj_retime;
  t.retime_yaw_share = o.traj_retime_yaw_share;
  t.reachable_only = o.astar_reachable_only;
  return t;
}

}  // namespace storey::core::plan

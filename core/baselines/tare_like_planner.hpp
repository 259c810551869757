#pragma once
// Baseline `tare-like` (issue 10; in the style of TARE, Cao et al. 2021): a hierarchical
// viewpoint planner whose connectivity links two viewpoints only when their height difference is
// below a fixed threshold (height_threshold_m per link_spacing_m of horizontal distance): it
// crosses gentle ramps, not stairs. Viewpoints are the reachable graph's nodes (the same graph
// input as every method), links its real edges that pass the height rule. Global layer: space cut
// into global_cell_m subspaces (and floor-height bins); the subspaces holding reachable frontier
// clusters are ordered by an open TSP from the robot (TspSolver, costs on the filtered graph).
// Local layer: in the first subspace of that tour, the cluster nearest along the filtered graph;
// its best viewpoint is the goal. Stage 3 is the shared voxel A* + B-spline, with paths that
// climb faster than the height rule rejected (then the filtered graph's own path is driven).
#include <cstdint>
#include <span>
#include <vector>

#include "core/baselines/goal_driver.hpp"
#include "core/plan/graph_search.hpp"
#include "core/plan/tsp.hpp"

namespace storey::core::baselines {

// TARE-like connectivity: |dz| <= threshold and |dz| <= threshold * horizontal / spacing (a short
// link on a stair flight is refused like a long one).
bool tare_link_ok(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double threshold_m,
                  double spacing_m);
// A support polyline obeys the rule between every pair of its points about spacing_m apart.
bool tare_path_ok(const std::vector<Eigen::Vector3d>& path_m, double threshold_m, double spacing_m);

// Of `starts` (in order of preference), the first whose connected part of `sg` is largest
// (UINT32_MAX if none is a node of sg): where the robot stands between parts of its viewpoint
// graph, it plans from the part that holds the map's work.
uint32_t largest_part_start(const plan::SearchGraph& sg, std::span<const uint32_t> starts,
                            plan::GraphSearch& search);

class TareLikePlanner {
 public:
  TareLikePlanner(const RobotModel& robot, const plan::PlanOptions& plan, double voxel_size_m,
                  const BaselineOptions& options = {});
  plan::ExplorationResult plan(const plan::ExplorationInput& in);
  void drop_target() { driver_.drop_target(); }
  const GoalDriver& driver() const { return driver_; }
  GoalDriver& driver() { return driver_; }
  // Goals of one cycle: clusters of the first global subspace first, each by graph distance.
  std::vector<Goal> goals(const plan::ExplorationInput& in);
  // Number of graph edges the last cycle kept / refused by the height rule.
  size_t links_kept() const { return kept_; }
  size_t links_refused() const { return refused_; }

 private:
  BaselineOptions opt_;
  GoalDriver driver_;
  plan::TspSolver tsp_;
  plan::GraphSearch search_, path_search_;
  plan::SearchGraph sg_;
  uint32_t robot_node_ = UINT32_MAX;  // this cycle's robot node on sg_
  std::vector<graph::NodeId> near_;   // scratch: nodes near the robot
  size_t kept_ = 0, refused_ = 0;
};

}  // namespace storey::core::baselines

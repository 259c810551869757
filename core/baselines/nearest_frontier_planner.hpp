#pragma once
// Baseline `nearest-frontier` (issue 10; Yamauchi's classic frontier exploration in a voxel
// map): frontiers are support voxels of the reachable set C_reach (known free space at the
// robot's level: the layer just above a reachable surface) with a horizontal neighbour whose
// column is unknown around that level. They are clustered (26-connected), and the robot drives
// to the nearest cluster by voxel A* path cost. No reachable graph, no topological frontiers, no
// viewpoint scoring, no prior. Since the voxel A* climbs stairs, it can change floors.
#include <vector>

#include "core/baselines/goal_driver.hpp"

namespace storey::core::baselines {

struct FrontierVoxelCluster {
  std::vector<map::VoxelKey> voxels;
  Eigen::Vector3d centroid_m = Eigen::Vector3d::Zero();
  Eigen::Vector2d unknown_dir = Eigen::Vector2d::Zero();  // mean direction toward the unknown
};

// Frontier voxels of the map at the robot's level (see above), clustered; clusters smaller
// than min_cells dropped. Deterministic order (by first voxel key).
std::vector<FrontierVoxelCluster> volumetric_frontiers(const map::MapView& view, int min_cells);

class NearestFrontierPlanner {
 public:
  NearestFrontierPlanner(const RobotModel& robot, const plan::PlanOptions& plan,
                         double voxel_size_m, const BaselineOptions& options = {});
  plan::ExplorationResult plan(const plan::ExplorationInput& in);
  void drop_target() { driver_.drop_target(); }
  const GoalDriver& driver() const { return driver_; }

  // Goals of one cycle, nearest first (A* path cost for the nearest few by straight line).
  std::vector<Goal> goals(const plan::ExplorationInput& in);

 private:
  BaselineOptions opt_;
  GoalDriver driver_;
};

}  // namespace storey::core::baselines

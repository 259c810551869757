// Why an exploration stopped where it did (run record `diagnostics.md`): every frontier cluster
// left in the final world model with its nodes' flags (C_sur with rho_i, C_exp with the open
// probe count), distance to the robot and, when the local planner set a node aside, the reason
// and time; and the ground-truth traversable voxels the map does not cover, broken down by what
// the map holds in their column (nothing, under-observed support with its point count,
// untraversable with the Eq. 3 reason, traversable at another height). The second part checks
// that the coverage metric is fair: a gap should be ground the robot never looked at, not ground
// the map holds at a different height.
#pragma once

#include <string>

#include <Eigen/Core>

#include "firmware/autonomy.hpp"
#include "tools/sim/ground_truth.hpp"

namespace storey::tools::sim {

// Markdown text. `robot_m`: the robot's ground point at the end of the run.
std::string exploration_diagnostics(const firmware::Autonomy& autonomy, const GroundTruth& gt,
                                    const Eigen::Vector3d& robot_m);

}  // namespace storey::tools::sim

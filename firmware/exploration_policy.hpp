#pragma once
// The plan task's exploration policy (DESIGN §5, issue 10): the one object the plan task calls
// each cycle, chosen by name, so that the paper's method and the baselines run over the SAME
// world model (map snapshot, reachable graph, frontier clusters, viewpoints), the same speed
// limits and the same Stage-3 trajectory machinery, and differ only in how they pick targets.
//
//   storey            core::plan::ExplorationPlanner (paper Sec. IV: floors, task zones, hybrid
//                     graph, global guidance over the local layer)
//   nearest-frontier  core::baselines::NearestFrontierPlanner
//   fael-like         core::baselines::FaelLikePlanner
//   tare-like         core::baselines::TareLikePlanner
//
// Every policy answers with core::plan::ExplorationResult (kNewTrajectory / kKeep / kExploring
// / kComplete / kFailed); the plan task publishes, holds or ends the run from that alone.
// Single-threaded: owned and called by the plan task only.
#include <memory>
#include <string>
#include <vector>

#include "config/parameters.hpp"
#include "core/baselines/goal_driver.hpp"
#include "core/plan/exploration_planner.hpp"

namespace storey::firmware {

class ExplorationPolicy {
 public:
  virtual ~ExplorationPolicy() = default;
  virtual const char* name() const = 0;
  // One plan-task cycle. The input's pointers must stay valid during the call.
  virtual core::plan::ExplorationResult plan(const core::plan::ExplorationInput& in) = 0;
  // Forget the current target (the control task predicted a collision on the trajectory, or a
  // safety stop left the robot away from it); the next plan() replans.
  virtual void drop_target() = 0;
  // The storey method's local layer (set-aside frontier nodes for the run record); nullptr for
  // policies without one.
  virtual const core::plan::LocalPlanner* local_layer() const { return nullptr; }
  // The storey method's macro layer (floors, zones); nullptr for the baselines.
  virtual const core::plan::ExplorationPlanner* macro_layer() const { return nullptr; }
  // A baseline's own goals set aside, by why (why it ended); nullptr for the storey method (its
  // clusters are counted instead).
  virtual const core::baselines::GoalDriver::SetAsideCounts* goals_set_aside() const {
    return nullptr;
  }
};

// Known policy names, in the order of the DESIGN's command-line contract.
const std::vector<std::string>& exploration_methods();

// The policy named `method` (see exploration_methods()) over the configured robot, planning and
// map parameters. Throws std::invalid_argument naming the method when it is unknown.
std::unique_ptr<ExplorationPolicy> make_exploration_policy(const std::string& method,
                                                           const config::Parameters& params);

}  // namespace storey::firmware

#pragma once
// The local layer of the exploration planner (paper Sec. IV-D), on its own: what the robot runs
// on the initial floor, where "the local layer directly schedules the observed TF clusters"
// (Sec. IV, no macro guidance). One call per planning cycle:
//   Stage 1  TSP over the TF cluster representatives (graph path costs from Dijkstra on G_real),
//            open tour from the robot, optionally ending at the macro layer's anchor c_anc;
//   Stage 2  heading-aware DP (Eq. 6) choosing one viewpoint per cluster in the first W;
//   Stage 3  voxel A* to the first viewpoint, then the collision-checked B-spline.
// Between cycles it keeps its target (no dithering): it replans when the target cluster is gone,
// the target is reached, the rest of the trajectory collides on the new map, or replan_period_s
// passed. Frontier nodes that stay frontiers after the robot stood at their viewpoint, or whose
// cluster repeatedly fails Stage 3, are set aside (they are not observable from where the robot
// can stand), so exploration ends when no reachable, observable frontier is left.
//
// Single-threaded: the firmware's plan task owns it. The macro layer (ExplorationPlanner) can
// replace or wrap it: the interface is the one plan(input) -> result call.
#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "core/graph/frontier_clusters.hpp"
#include "core/graph/reachable_graph.hpp"
#include "core/graph/viewpoint_generator.hpp"
#include "core/map/map_view.hpp"
#include "core/plan/bspline_trajectory.hpp"
#include "core/plan/collision_checker.hpp"
#include "core/plan/graph_search.hpp"
#include "core/plan/plan_options.hpp"
#include "core/plan/tsp.hpp"
#include "core/plan/viewpoint_dp.hpp"
#include "core/plan/voxel_astar.hpp"
#include "core/robot_model.hpp"

namespace storey::core::plan {

struct LocalPlanInput {
  const map::MapView* view = nullptr;
  const graph::ReachableGraph* graph = nullptr;
  const std::vector<graph::FrontierCluster>* clusters = nullptr;
  const std::vector<graph::ClusterViewpoints>* viewpoints = nullptr;
  Eigen::Vector3d robot_foot_m = Eigen::Vector3d::Zero();  // ground point under the robot [m]
  double robot_yaw_rad = 0;
  double t_s = 0;                           // now, on the trajectory's time base [s]
  std::optional<Eigen::Vector3d> anchor_m;  // c_anc from the macro layer (Stage 1 terminal)
};

enum class LocalPlanStatus : uint8_t {
  kNewTrajectory = 0,  // `trajectory` replaces the current one
  kKeep,               // the current trajectory stays valid
  kNoFrontiers,        // no TF cluster left
  kNoReachableTarget,  // clusters left, but none reachable / observable (see counts)
  kNoRobotNode,        // the robot has no node in G_real yet (map still growing)
  kBadInput,
};
const char* to_string(LocalPlanStatus s);

struct LocalPlanResult {
  LocalPlanStatus status = LocalPlanStatus::kBadInput;
  const char* replan_reason = "";  // why a new trajectory was made
  BsplineTrajectory trajectory;    // for kNewTrajectory
  double real_until_s = 0;         // follow only up to here (real prefix, Sec. IV-C)
  int32_t target_cluster = -1;
  Eigen::Vector3d target_m = Eigen::Vector3d::Zero();
  double target_yaw_rad = 0;
  std::vector<int32_t> cluster_order;   // Stage 1 order (cluster ids)
  std::vector<Eigen::Vector3d> path_m;  // Stage 3 A* path (support points)
  int clusters_total = 0, clusters_set_aside = 0, clusters_unreachable = 0;
  uint32_t astar_calls = 0;
  uint32_t graph_fallbacks = 0;  // Stage 3 paths taken along G_real (voxel A* failed)
};

struct LocalPlannerOptions {
  int max_tsp_clusters = 12;        // nearest clusters (graph distance) entering Stage 1
  double replan_period_s = 4.0;     // re-optimise a kept target this often
  double reached_radius_m = 0.5;    // robot this close to the viewpoint = reached
  double set_aside_radius_m = 0.3;  // a frontier node this close to a set-aside one is ignored
  int max_failures = 2;             // Stage 3 failures before a cluster is set aside
  int max_stage3_attempts = 6;      // viewpoints tried per cycle (bounded work)
};

class LocalPlanner {
 public:
  LocalPlanner(const RobotModel& robot, const PlanOptions& plan, double voxel_size_m,
               const LocalPlannerOptions& options = {});
  LocalPlanResult plan(const LocalPlanInput& in);
  // Forget the current target (after a safety stop the robot may be far from its trajectory).
  void drop_target() { has_target_ = false; }
  bool has_target() const { return has_target_; }
  size_t set_aside_nodes() const { return set_aside_.size(); }

 private:
  struct Candidate {
    int32_t cluster_id;
    size_t cluster_index;
    uint32_t rep;  // representative node (nearest the centroid)
  };
  bool ignored(const Eigen::Vector3f& p) const;
  const graph::FrontierCluster* find_cluster(const LocalPlanInput& in, int32_t id) const;
  void build_search_graph(const graph::ReachableGraph& g);
  bool try_target(const LocalPlanInput& in, const Viewpoint& vp, LocalPlanResult& out);

  RobotModel robot_;
  PlanOptions plan_opt_;
  LocalPlannerOptions opt_;
  TspSolver tsp_;
  ViewpointDp dp_;
  VoxelAStar astar_;
  TrajectoryBuilder builder_;
  CollisionChecker checker_;
  GraphSearch search_, pair_search_;
  SearchGraph sg_;
  std::vector<SearchGraph::Edge> edges_scratch_;
  std::vector<Eigen::Vector3d> pos_scratch_;

  uint32_t robot_node_ = 0xFFFFFFFFu;
  std::vector<Eigen::Vector3d> start_nodes_m_;  // nearest confirmed nodes (blind-ring starts)
  // Current target.
  bool has_target_ = false;
  int32_t target_cluster_ = -1;
  Eigen::Vector3d target_m_ = Eigen::Vector3d::Zero();
  BsplineTrajectory current_;
  double planned_at_s_ = 0;
  // Frontier nodes set aside (positions: node ids are recycled) and Stage 3 failures per cluster.
  std::vector<Eigen::Vector3f> set_aside_;
  std::vector<std::pair<int32_t, int>> failures_;
  std::vector<int32_t>
      approached_;  // clusters whose viewpoint was reached once (walk onto them next)
};

}  // namespace storey::core::plan

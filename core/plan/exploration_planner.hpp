#pragma once
// The exploration planner of paper Sec. IV: macro layer (floors, task zones, hybrid graph,
// global guidance) over the local layer (LocalPlanner, Sec. IV-D). One call per plan-task cycle:
//
//   ExplorationPlanner planner(robot, plan_options, map_options.voxel_size_m);
//   ExplorationInput in{&view, snapshot->version(), &graph, &clusters, &viewpoints,
//                       robot_foot_m, robot_yaw_rad, t_s};
//   ExplorationResult r = planner.plan(in);
//   switch (r.status) { kNewTrajectory: publish r.trajectory (drive only up to r.real_until_s);
//                       kKeep: keep the current one; kExploring: hold/wait (no target yet);
//                       kComplete: stop, log r.reason; kFailed: stop, log r.reason; }
//
// Each call: 1) floor tracking from the robot's support height; 2) on arrival on a new floor
// with an adjacent explored floor (and use_prior): partition the reference floor's nodes into
// task zones (IV-A) and project them by dz into G_hyp; 3) hybrid-graph maintenance (IV-B);
// 4) global guidance (IV-C) on the prior's target floor: TSP over uncompleted zones, the local
// layer gets the TF clusters of the first guidance_zones zones of the sequence and the centre
// of the next zone as terminal anchor c_anc (plus, if guidance_near_m > 0, every cluster within
// that distance along G_real of the robot); when those zones hold no cluster, the robot drives
// the real prefix of the two-stage path toward the first zone's centre (a zone whose real prefix
// ends at the robot is set aside); 5) otherwise (first floor, no prior, ablation) the local
// layer over all clusters; 6) completion: no reachable frontier and no uncompleted zone left.
// Deterministic; single-threaded (the plan task owns it). Inputs must stay valid during plan().
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/plan/floor_tracker.hpp"
#include "core/plan/global_planner.hpp"
#include "core/plan/hybrid_graph.hpp"
#include "core/plan/local_planner.hpp"
#include "core/plan/stage_probe.hpp"
#include "core/plan/task_zones.hpp"

namespace storey::core::plan {

struct ExplorationInput {
  const map::MapView* view = nullptr;
  uint64_t map_version = 0;  // MapSnapshot::version(): negative evidence counts once per version
  const graph::ReachableGraph* graph = nullptr;
  const std::vector<graph::FrontierCluster>* clusters = nullptr;
  const std::vector<graph::ClusterViewpoints>* viewpoints = nullptr;
  Eigen::Vector3d robot_foot_m = Eigen::Vector3d::Zero();  // ground point under the robot [m]
  double robot_yaw_rad = 0;
  double t_s = 0;               // now, on the trajectory's time base [s]
  double trajectory_lag_s = 0;  // LocalPlanInput::trajectory_lag_s
  Eigen::Vector2d robot_velocity_mps = Eigen::Vector2d::Zero();  // planar, world frame [m/s]
  // Map regions changed since the previous plan() call (e.g. the map task's MapChangeDetector
  // boxes, merged over the versions in between). nullptr: unknown; then every hypothesis within
  // hyp_check_radius_m is re-checked on each new map version (correct, slower).
  const std::vector<graph::Aabb>* changed_regions = nullptr;
};

// Guidance (Sec. IV-C): which clusters the local layer serves (1 per cluster). Those with a node in
// one of first_zones, and (near_m > 0) those with a node within near_m of robot_node along
// G_real: PlanOptions::guidance_zones, guidance_near_m. robot_node is a node of hg.
std::vector<uint8_t> guided_clusters(const HybridGraph& hg, std::span<const int32_t> first_zones,
                                     uint32_t robot_node, double near_m,
                                     const std::vector<graph::FrontierCluster>& clusters,
                                     GraphSearch& search);

enum class ExplorationStatus : uint8_t {
  kNewTrajectory = 0,  // publish `trajectory`
  kKeep,               // the current trajectory stays valid
  kExploring,          // no target this cycle (map still growing); `reason` says why
  kComplete,           // exploration finished; `reason` says why
  kFailed,             // bad input or an internal failure; `reason` says what
};
const char* to_string(ExplorationStatus s);

struct ZoneSummary {
  int32_t id = -1;
  ZoneState state = ZoneState::kHypothetical;
  Eigen::Vector3d centre_m = Eigen::Vector3d::Zero();
  int nodes = 0, real_nodes = 0, hyp_nodes = 0, frontier_nodes = 0;
};

struct ExplorationResult {
  ExplorationStatus status = ExplorationStatus::kFailed;
  const char* reason = "";
  BsplineTrajectory trajectory;  // for kNewTrajectory
  double real_until_s = 0;       // drive only up to here (real prefix, Sec. IV-C)
  Eigen::Vector3d target_m = Eigen::Vector3d::Zero();
  double target_yaw_rad = 0;
  int32_t target_cluster = -1;  // -1: a real-prefix goal toward a zone, or none
  // Floors.
  int32_t floor = -1, reference_floor = -1;
  bool floor_changed = false, prior_built = false;
  double dz_m = 0;
  // Debug (pictures): zones, global sequence, local order. Hybrid nodes/edges: hybrid().
  std::vector<ZoneSummary> zones;
  std::vector<int32_t> zone_sequence;  // global TSP order (zone ids), nearest zones only
  int zones_deferred = 0;              // reachable uncompleted zones left out of this cycle's TSP
  std::vector<int32_t> cluster_order;  // Stage 1 order (cluster ids)
  bool guided = false;                 // macro guidance was used this cycle
  MaintenanceStats maintenance;
};

class ExplorationPlanner {
 public:
  ExplorationPlanner(const RobotModel& robot, const PlanOptions& options, double voxel_size_m,
                     const LocalPlannerOptions& local = {});
  ExplorationResult plan(const ExplorationInput& in);

  const HybridGraph& hybrid() const { return hybrid_; }
  const FloorTracker& floors() const { return floors_; }
  LocalPlanner& local() { return local_; }
  // Forget the local target and the zone-centre drive (the control task asked for a replan).
  void drop_target() {
    local_.drop_target();
    drive_end_s_ = -1.0;
  }
  // Per-stage profiling (stage_probe.hpp); nullptr: none. Passed on to the hybrid graph and the
  // local layer. The probe must outlive the planner or be reset to nullptr.
  void set_stage_probe(StageProbe* probe);

 private:
  ExplorationResult plan_cycle(const ExplorationInput& in);
  void build_prior(const ExplorationInput& in, int32_t ref, int32_t target, ExplorationResult& r);
  void update_floor_progress(const graph::ReachableGraph& g);
  bool drive_to(const ExplorationInput& in, const Eigen::Vector3d& goal, ExplorationResult& r);

  RobotModel robot_;
  PlanOptions opt_;
  FloorTracker floors_;
  TaskZonePartitioner partitioner_;
  ObstacleClearance clearance_;
  HybridGraph hybrid_;
  GlobalPlanner global_;
  LocalPlanner local_;
  VoxelAStar astar_;
  TrajectoryBuilder builder_;
  CollisionChecker checker_;
  StageProbe* probe_ = nullptr;
  bool hybrid_updated_last_ = false;  // the previous cycle ran the hybrid-graph maintenance
  // The drive toward a zone centre last published (drive_to): its goal and its end on the
  // trajectory's clock (-1: none).
  Eigen::Vector3d drive_goal_m_ = Eigen::Vector3d::Zero();
  double drive_end_s_ = -1.0;
  bool drove_ = false;  // this cycle published a drive
  std::vector<int32_t> set_aside_zones_;
  // Scratch.
  GraphSearch near_search_;  // guidance_near_m: G_real around the robot
  std::vector<graph::FrontierCluster> sel_clusters_;
  std::vector<graph::ClusterViewpoints> sel_viewpoints_;
  std::vector<float> node_z_;
  std::vector<int> floor_nodes_, floor_frontiers_;
};

}  // namespace storey::core::plan

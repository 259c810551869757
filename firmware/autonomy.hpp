#pragma once
// The exploration stack as one task table (DESIGN §2-3): ingest, map + graph, plan, control,
// watchdog, telemetry, wired to a Platform (robot + sensors). Independent of the simulator: the
// `sim` verb drives it in lockstep (run_until with a VirtualClock, the simulator stepped between
// slices), `storey run` will start() it in real time against the live platform.
//
// Data between tasks, only through rt/ primitives (one writer each):
//   ingest  -> map      scans: pool of ScanBuffer + SpscQueue (filled), SpscQueue (free) back
//   ingest  -> control  last scan stamp: Mailbox<double>
//   control -> map/plan pose: Mailbox<PoseSample>
//   map     -> plan     world model (map snapshot, graph copy, clusters, viewpoints): Snapshot
//   plan    -> control  trajectory: Snapshot; planner heartbeat: Mailbox<double>
//   control -> plan     reference lag of the trajectory followed: Mailbox<TrajectoryProgress>
//   control -> *        command: Mailbox<VelocityCommand>; stop events: SpscQueue -> telemetry
//   watchdog-> control  overrun flag: atomic
//   plan    -> *        exploration status: Mailbox<ExplorationStatus>
//   plan    -> telemetry plan events (floor, prior, failure, completion): SpscQueue
//   plan    -> map      last world cycle whose changed regions the planner consumed: atomic
// The map task is the only owner of the world model; everybody else reads immutable snapshots.
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "config/parameters.hpp"
#include "core/graph/frontier_clusters.hpp"
#include "core/graph/reachable_graph.hpp"
#include "core/graph/topological_frontiers.hpp"
#include "core/graph/viewpoint_generator.hpp"
#include "core/map/traversability_map.hpp"
#include "core/plan/collision_checker.hpp"
#include "core/plan/local_planner.hpp"
#include "firmware/blind_support.hpp"
#include "firmware/control_law.hpp"
#include "firmware/exploration_policy.hpp"
#include "firmware/platform.hpp"
#include "firmware/safety_monitor.hpp"
#include "firmware/world_model.hpp"
#include "rt/mailbox.hpp"
#include "rt/scheduler.hpp"
#include "rt/snapshot.hpp"
#include "rt/spsc_queue.hpp"
#include "rt/trace.hpp"

namespace storey::firmware {

// What the plan task publishes: the trajectory to track (empty = hold still).
struct PlannedTrajectory {
  uint64_t id = 0;
  double stamp_s = 0;
  core::plan::BsplineTrajectory trajectory;
  double real_until_s = 0;  // follow only up to here (real prefix toward hypotheses, Sec. IV-C)
  int32_t target_cluster = -1;
  Eigen::Vector3d target_m = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> path_m;
};

// control -> plan: the reference waits for the robot (a turn onto the trajectory, a safety
// stop), so the trajectory's own clock trails the planner's; a climb judged "done" at its
// planned end stopped 0.7 m short of the landing (house seed 1 re-timed, session 21).
struct TrajectoryProgress {
  uint64_t id = 0;   // PlannedTrajectory::id followed (0: none)
  double lag_s = 0;  // how far its reference trails the clock [s]
  double tau_s = 0;  // the reference's time now, on the trajectory's clock [s]
};

// kStranded: nothing left the robot can reach, but frontiers unreachable from a robot cut off in
// a small part of its graph (Autonomy::kStrandedShare): the run ends, and says so, instead of
// claiming the building explored.
enum class ExplorationState : uint8_t { kStarting = 0, kExploring, kComplete, kStranded };

// Plain status (Mailbox): for progress lines, the run record, and ending the run.
struct ExplorationStatus {
  double stamp_s = 0;
  ExplorationState state = ExplorationState::kStarting;
  const char* method = "";  // the policy's name (exploration_policy.hpp)
  // The policy's last answer and why (string literals of core/: safe to copy).
  core::plan::ExplorationStatus last_plan = core::plan::ExplorationStatus::kExploring;
  const char* plan_reason = "";
  uint32_t nodes = 0, edges = 0, frontier_nodes = 0, clusters = 0;
  // Clusters whose every node the local layer set aside (or left on a flight climbed blind) / with
  // no node connected to the robot through G_real (computed by the plan task when the policy has
  // nothing to do).
  uint32_t clusters_set_aside = 0, clusters_unreachable = 0;
  uint32_t robot_component_nodes = 0;  // nodes connected to the robot's through G_real
  // A baseline's own set-aside goals (GoalDriver::SetAsideCounts; all -1 for the storey method).
  int32_t goals_stood_at = -1, goals_overdue = -1, goals_no_trajectory = -1, goals_no_progress = -1;
  uint64_t trajectories = 0, plan_cycles = 0;
  int floor_hint = 0;  // round(robot z / floor_height_hint_m)
  // Macro layer (storey method; -1 / 0 for the baselines): the robot's floor and its reference
  // floor (FloorTracker indices, in order of arrival), floors known, the prior (built once per
  // new floor, dz = target - reference), its task zones (total, uncompleted, left out of the
  // last global TSP) and whether global guidance chose this cycle's clusters or goal.
  int32_t floor = -1, reference_floor = -1;
  uint32_t floors_known = 0;
  bool prior = false;
  double prior_dz_m = 0;
  uint32_t zones = 0, zones_left = 0, zones_deferred = 0;
  bool guided = false;
  // The published trajectory's goal (what the robot is heading for; -1: none or a zone drive).
  bool has_target = false;
  int32_t target_cluster = -1;
  float target_x_m = 0, target_y_m = 0, target_z_m = 0;  // Mailbox: trivially copyable
};
const char* to_string(ExplorationState s);
// "  -> cluster 12 at 3.0, 4.5, 0.0" (or "" without a target): for progress lines.
std::string describe_target(const ExplorationStatus& s);

// Plan task -> telemetry (non-RT log): floor changes, prior built, failures, completion; and
// every new trajectory (kTrajectory: to AutonomyOptions::plan_log only).
struct PlanEvent {
  enum Kind : uint8_t {
    kFloor = 0,
    kPrior,
    kFailed,
    kComplete,
    kStranded,
    kTrajectory
  } kind = kFloor;
  double t_s = 0;
  int32_t floor = -1, reference_floor = -1;
  double dz_m = 0;
  const char* reason = "";          // string literal
  float x_m = 0, y_m = 0, z_m = 0;  // kFloor: where the robot stood; kTrajectory: its target
  int32_t cluster = -1;             // kTrajectory: the target's cluster (-1: a goal, an escape)
};

struct StopEvent {
  double t_s = 0;
  StopReason reason = StopReason::kCount;
  bool raised = true;  // false: cleared
};

struct AutonomyOptions {
  config::Parameters params;
  uint64_t seed = 1;           // graph expansion sampling (Eq. 4)
  core::graph::SensorFov fov;  // for viewpoint visibility
  // Budget overruns stop the robot (DESIGN §3). Off in lockstep: there the virtual clock does
  // not wait for a slow task, and wall-time overruns would make the run non-deterministic.
  bool stop_on_overruns = true;
  // Exploration policy (exploration_policy.hpp): storey | nearest-frontier | fael-like |
  // tare-like. Unknown names throw std::invalid_argument from the constructor.
  std::string method = "storey";
  double complete_after_s = 3.0;  // no target for this long with a settled graph = complete
  double complete_unsettled_after_s = 10.0;  // ... or this long while the graph still churns
  // Ground under the robot at start-up, which the LiDAR cannot see, entered as support up to
  // this radius (capped at the blind radius + 0.3 m; 0 = off). See insert_startup_support().
  double startup_support_radius_m = 3.0;
  size_t scan_pool = 4;  // scan buffers in flight (ingest -> map)
  size_t scan_reserve_points = 65536;
  size_t trace_events = 1 << 16;
  // Real time: the LiDAR socket (the ingest task runs when it is readable); lockstep: unused.
  int ingest_fd = -1;
  double lockstep_event_hz = 100;               // how often the ingest row is polled in lockstep
  std::function<void(const std::string&)> log;  // non-RT log sink (telemetry task); default stderr
  // One CSV row per new trajectory (kPlanLogHeader's columns; telemetry task; none if unset):
  // why the planner changed course, and toward what (run record plan.csv).
  std::function<void(const std::string&)> plan_log;
};
inline constexpr const char* kPlanLogHeader = "t_s,reason,cluster,target_x_m,target_y_m,target_z_m";

class Autonomy {
 public:
  // Stranded: frontier clusters unreachable and the robot's node in a component holding fewer
  // than this share of the graph's nodes. A floor climbed blind is a component of its own (house:
  // half the graph), so the share is small.
  static constexpr double kStrandedShare = 0.1;
  // Whether an exhausted status (no target left) is stranded rather than complete.
  static bool stranded(const ExplorationStatus& s) {
    return s.clusters_unreachable > 0 &&
           double(s.robot_component_nodes) < kStrandedShare * double(s.nodes);
  }
  Autonomy(Platform& platform, const rt::Clock& clock, AutonomyOptions options);
  ~Autonomy();
  Autonomy(const Autonomy&) = delete;
  Autonomy& operator=(const Autonomy&) = delete;

  // Lockstep: runs every release in [clock.now_ns(), t_ns), ending with the clock at t_ns.
  void run_until(rt::VirtualClock& clock, std::int64_t t_ns) { sched_->run_until(clock, t_ns); }
  rt::Scheduler& scheduler() { return *sched_; }
  const rt::TraceRing& trace() const { return trace_; }

  // Any thread.
  void set_operator_stop(bool on) { operator_stop_.store(on, std::memory_order_release); }
  // Fault injection (tests, HIL fault drills): a suspended task's body returns at once.
  // Names as in the task table; false if there is no such task.
  bool suspend_task(const char* name, bool suspended);
  ExplorationStatus status() const;
  std::shared_ptr<const WorldModel> world() const { return world_.read().ptr; }
  std::shared_ptr<const PlannedTrajectory> trajectory() const { return traj_.read().ptr; }
  // The trajectory the control task follows and how far its reference trails the clock.
  TrajectoryProgress trajectory_progress() const {
    TrajectoryProgress p;
    progress_mb_.read(p);
    return p;
  }
  VelocityCommand last_command() const;
  uint64_t safety_stops() const { return safety_stops_.load(std::memory_order_acquire); }
  uint64_t stop_events(StopReason r) const {
    return reason_events_[int(r)].load(std::memory_order_acquire);
  }
  uint32_t active_stop_mask() const { return stop_mask_.load(std::memory_order_acquire); }
  uint64_t scans_dropped() const { return scans_dropped_.load(std::memory_order_relaxed); }

  // Owner-side views for the run record, only while no task runs (after the lockstep loop or
  // stop()): the live map (PLY export, coverage).
  const core::map::TraversabilityMap& map_for_record() const { return map_; }
  // The storey method's local layer (set-aside frontier nodes and their reasons, for the run
  // record); for a baseline policy an idle local planner (nothing set aside).
  const core::plan::LocalPlanner& planner_for_record() const {
    return policy_->local_layer() ? *policy_->local_layer() : *idle_local_;
  }
  const ExplorationPolicy& policy() const { return *policy_; }
  const config::Parameters& params() const { return opt_.params; }

 private:
  enum Task { kIngest = 0, kMap, kPlan, kControl, kWatchdog, kTelemetry, kTaskCount };
  std::vector<rt::TaskSpec> task_table();
  bool suspended(Task t) const { return suspended_[t].load(std::memory_order_acquire); }
  double now_s() const { return double(clock_.now_ns()) * 1e-9; }
  void ingest_step();
  void map_step();
  size_t insert_startup_support(const Eigen::Vector3f& foot);  // points entered
  void plan_step();
  void count_exhausted(const WorldModel& w, ExplorationStatus& s);
  void control_step();
  void watchdog_step();
  void telemetry_step();
  void log(const std::string& line) const;

  Platform& platform_;
  const rt::Clock& clock_;
  AutonomyOptions opt_;
  rt::TraceRing trace_;

  // ingest -> map
  std::vector<ScanBuffer> pool_;
  rt::SpscQueue<ScanBuffer*> filled_q_, free_q_;
  ScanBuffer* ingest_buf_ = nullptr;
  ScanBuffer drop_buf_;
  std::atomic<uint64_t> scans_dropped_{0};
  rt::Mailbox<double> scan_stamp_mb_;
  rt::Mailbox<PoseSample> pose_mb_;

  // map task (owner of the world model)
  core::map::TraversabilityMap map_;
  core::graph::ReachableGraph graph_;
  core::graph::TopologicalFrontiers frontiers_;
  core::graph::FrontierClusters clusters_;
  core::graph::ViewpointGenerator viewpoints_;
  std::mt19937_64 rng_;
  std::vector<core::graph::Aabb> changed_;
  std::vector<std::pair<uint64_t, core::graph::Aabb>> pending_changes_;  // not yet seen by plan
  uint64_t map_cycle_ = 0, scans_inserted_ = 0;
  bool startup_support_done_ = false;
  Eigen::Vector3f last_support_foot_ = Eigen::Vector3f::Constant(1e9f);  // last insertion
  LevelTracker level_;  // with plan.flight_foot, blind-ring support only where it walks level
  size_t startup_points_ = 0;
  rt::Snapshot<WorldModel> world_;

  // plan task
  std::unique_ptr<ExplorationPolicy> policy_;
  std::unique_ptr<core::plan::LocalPlanner> idle_local_;  // planner_for_record() for baselines
  std::atomic<uint64_t> plan_seen_cycle_{0};  // plan -> map: changes up to here were consumed
  uint64_t plan_last_cycle_ = 0;
  std::vector<core::graph::Aabb> plan_changes_;
  rt::SpscQueue<PlanEvent> plan_q_;
  const char* last_failure_ = nullptr;
  double prior_dz_m_ = 0;
  int32_t prior_reference_ = -1;
  std::vector<uint32_t> uf_scratch_;
  rt::Snapshot<PlannedTrajectory> traj_;
  rt::Mailbox<double> plan_alive_mb_;
  rt::Mailbox<ExplorationStatus> status_mb_;
  std::atomic<bool> replan_request_{false};  // control -> plan: drop the current target
  std::atomic<bool> landed_request_{false};  // plan -> map: a climb ended on its landing
  uint64_t landings_seen_ = 0;               // plan task: LocalPlanner::landings() last seen
  uint64_t traj_id_ = 0, plan_cycles_ = 0, trajectories_ = 0;
  double idle_since_s_ = -1;
  bool complete_ = false;
  bool stranded_ = false;  // complete_ with the robot cut off (ExplorationState::kStranded)

  // control task
  ControlLaw law_;
  SafetyMonitor safety_;
  core::plan::CollisionChecker lookahead_;
  std::vector<core::plan::BodyPose> turn_poses_;  // safety.check_body_turn (ControlLaw::turn_poses)
  uint64_t ctl_traj_version_ = 0, ctl_checked_traj_ = 0, ctl_checked_map_ = 0;
  std::shared_ptr<const PlannedTrajectory> ctl_traj_;
  double tau_ = 0;        // progress along the trajectory [s] (advances while tracking well)
  double entry_tau_ = 0;  // where tracking entered it (ControlLaw::entry_time) [s]
  double lag_s_ = 0;      // now - tau_ while tau_ runs (TrajectoryProgress)
  rt::Mailbox<TrajectoryProgress> progress_mb_;
  bool hold_turn_ = false;  // safety.check_body_turn: slide onto the reference, then turn
  bool entering_ = false;   // a new trajectory the robot has not yet been on (turn_on_reference)
  // plan.brake_start: a new trajectory waits while the robot brakes on the one it follows; the
  // old one's progress and feedforward scaled by brake_k_, falling 1 -> 0 at a_max from brake_v0_.
  std::shared_ptr<const PlannedTrajectory> pending_;
  double brake_k_ = 1.0, brake_v0_ = 0;
  bool collision_predicted_ = false;
  VelocityCommand prev_cmd_;
  PoseSample last_pose_;
  rt::Mailbox<VelocityCommand> cmd_mb_;
  rt::SpscQueue<StopEvent> stop_q_;
  std::atomic<uint64_t> safety_stops_{0};
  std::atomic<uint64_t> reason_events_[int(StopReason::kCount)] = {};
  std::atomic<uint32_t> stop_mask_{0};
  std::atomic<bool> operator_stop_{false};

  // watchdog
  std::atomic<bool> overrun_flag_{false};
  uint64_t wd_overruns_ = 0;

  std::atomic<bool> suspended_[kTaskCount] = {};
  std::unique_ptr<rt::Scheduler> sched_;
};

}  // namespace storey::firmware

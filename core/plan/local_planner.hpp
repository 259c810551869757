#pragma once
// The local layer of the exploration planner (paper Sec. IV-D), on its own: what the robot runs
// on the initial floor, where "the local layer directly schedules the observed TF clusters"
// (Sec. IV, no macro guidance). One call per planning cycle:
//   Stage 1  TSP over the TF cluster representatives (graph path costs from Dijkstra on G_real),
//            open tour from the robot, optionally ending at the macro layer's anchor c_anc;
//   Stage 2  heading-aware DP (Eq. 6) choosing one viewpoint per cluster in the first W;
//   Stage 3  voxel A* to the first viewpoint, then the collision-checked B-spline.
// Between cycles it keeps its target (no dithering): it replans when the target cluster is gone
// (its frontier observed; a cluster that only changed its id is followed, track_radius_m),
// the target is reached, the rest of the trajectory collides on the new map, or replan_period_s
// passed. Frontier nodes that stay frontiers after the robot stood at their viewpoint, or whose
// cluster repeatedly fails Stage 3, are set aside (they are not observable from where the robot
// can stand), so exploration ends when no reachable, observable frontier is left. A set-aside
// node expires when the map near it changes (its frontier flags or position differ, or it is
// gone) or, after set_aside_expiry_s, once the robot stands set_aside_expiry_move_m away from
// where it was then (a new vantage point); see expire_set_aside().
//
// Single-threaded: the firmware's plan task owns it. The macro layer (ExplorationPlanner) can
// replace or wrap it: the interface is the one plan(input) -> result call.
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "core/graph/frontier_clusters.hpp"
#include "core/graph/reachable_graph.hpp"
#include "core/graph/viewpoint_generator.hpp"
#include "core/map/map_view.hpp"
#include "core/plan/bspline_trajectory.hpp"
#include "core/plan/collision_checker.hpp"
#include "core/plan/escape.hpp"
#include "core/plan/graph_search.hpp"
#include "core/plan/path_centring.hpp"
#include "core/plan/plan_options.hpp"
#include "core/plan/stage_probe.hpp"
#include "core/plan/tsp.hpp"
#include "core/plan/viewpoint_dp.hpp"
#include "core/plan/voxel_astar.hpp"
#include "core/robot_model.hpp"

namespace storey::core::plan {

struct LocalPlanInput {
  const map::MapView* view = nullptr;
  const graph::ReachableGraph* graph = nullptr;
  const std::vector<graph::FrontierCluster>* clusters = nullptr;
  // Every cluster, when `clusters` is the guided zones' subset (PlanOptions::keep_guided_target).
  const std::vector<graph::FrontierCluster>* all_clusters = nullptr;
  const std::vector<graph::ClusterViewpoints>* viewpoints = nullptr;
  Eigen::Vector3d robot_foot_m = Eigen::Vector3d::Zero();  // ground point under the robot [m]
  double robot_yaw_rad = 0;
  double t_s = 0;  // now, on the trajectory's time base [s]
  // How long the control task has held the reference of the trajectory it follows (the last one
  // planned) back while the robot caught up (a turn onto it, a safety stop) [s]: that
  // trajectory's own clock reads t_s - trajectory_lag_s.
  double trajectory_lag_s = 0;
  Eigen::Vector2d robot_velocity_mps = Eigen::Vector2d::Zero();  // planar, world frame [m/s]
  std::optional<Eigen::Vector3d> anchor_m;  // c_anc from the macro layer (Stage 1 terminal)
  // The last call of a cycle, over every cluster: with nothing else left, clusters set aside for
  // a path failure may be retried from a new vantage point (PlanOptions::path_retries).
  bool last_resort = false;
};

enum class LocalPlanStatus : uint8_t {
  kNewTrajectory = 0,  // `trajectory` replaces the current one
  kKeep,               // the current trajectory stays valid
  kNoFrontiers,        // no TF cluster left
  kNoReachableTarget,  // clusters left, but none reachable / observable (see counts)
  kNoRobotNode,        // the robot has no node in G_real yet (map still growing)
  kStartBlocked,       // no collision-free pose near the robot to start a trajectory from
  kBadInput,
  kSearching,  // targets left that this cycle's bounded work did not reach: try again next cycle
  kSettling,   // no target yet just after a climb: the new floor's graph is still growing
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
  int set_aside_expired = 0;  // set-aside nodes that expired this cycle
  uint32_t astar_calls = 0;
  uint32_t graph_fallbacks = 0;  // Stage 3 paths taken along G_real (voxel A* failed)
};

// Why frontier nodes were set aside (diagnostics: the run record lists them).
enum class SetAsideReason : uint8_t {
  kStillFrontierAtTarget = 0,  // stood at the viewpoint and on the frontier, still a frontier
  kOverdue,                    // trajectory ended long ago without reaching the viewpoint
  kAstarFailed,                // Stage 3: no voxel A* path (and none along G_real)
  kTrajectoryFailed,           // Stage 3: a path, but no collision-free B-spline
};
const char* to_string(SetAsideReason r);

// The order in which clusters with no path along G_real are tried on the map
// (PlanOptions::reach_off_graph), given their representatives' positions: those on the robot's
// level (|dz| <= band_m) first, nearest first within each group.
std::vector<size_t> off_graph_order(const std::vector<Eigen::Vector3f>& reps_m,
                                    const Eigen::Vector3f& robot_m, float band_m);

// "No collision point": NaN (SetAsideEntry::hit_m and LocalPlanner's last Stage 3 hit).
inline const Eigen::Vector3f kNoHitM =
    Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN());

struct SetAsideEntry {
  Eigen::Vector3f p_m = Eigen::Vector3f::Zero();  // frontier node position when set aside
  double t_s = 0;                                 // when
  int32_t cluster_id = -1;
  SetAsideReason reason = SetAsideReason::kStillFrontierAtTarget;
  Eigen::Vector3f robot_m = Eigen::Vector3f::Zero();  // robot foot point then
  uint16_t frontier_sig = 0;  // the node's frontier flags then (frontier_signature())
  // kTrajectoryFailed: a voxel the body hit on the last try (NaN otherwise): diagnostics.
  Eigen::Vector3f hit_m = kNoHitM;
  int retries = 0;             // path-failure retries from a new vantage point so far (here)
  bool retry_pending = false;  // released when the retry move ends
  // Rule 2 of expire_set_aside: the time after which a move away releases it (set_aside_expiry_s,
  // doubled per earlier set-aside here with PlanOptions::set_aside_backoff).
  double expiry_s = 30.0;
};
// C_sur, C_exp, boundary and |Theta_open| of a node packed: what TopologicalFrontiers
// recomputes when the map near the node changes.
uint16_t frontier_signature(const graph::GraphNode& n);

struct LocalPlannerOptions {
  double replan_period_s = 4.0;  // re-optimise a kept target this often
  // A cluster's id changes with its nodes (the frontier recedes as the robot comes near: new
  // nodes, old ones no longer frontiers). A cluster with a frontier node this close to one of
  // the target's is the same frontier: the target is kept, not "observed" and replanned (on
  // test_ramp's landing ids churned every cycle and the robot turned between two targets).
  double track_radius_m = 1.0;
  double reached_radius_m = 0.5;      // robot this close to the viewpoint = reached
  double set_aside_radius_m = 0.3;    // a frontier node this close to a set-aside one is ignored
  int max_failures = 2;               // Stage 3 failures before a cluster is set aside
  int max_stage3_attempts = 6;        // viewpoints tried per cycle (bounded work)
  int max_off_graph_cycles = 20;      // cycles to_off_graph may take to try every viewpoint
  double escape_radius_m = 0.3;       // start pose in collision: free start searched this far
  double escape_turn_radius_m = 0.8;  // cannot turn on the spot: a turning place this far
  double start_blame_radius_m = 0.7;  // every try hits an obstacle this close to the start:
                                      // the start is boxed in, not the clusters (escape)
  int max_start_escapes = 3;          // ... at most this many escapes in a row
  double landing_step_m = 0.6;        // climb_on: past the last support seen on a flight
  double min_landing_m = 0.2;    // ... shortened to fit before a wall, not below this past the top
  int max_climbs = 3;            // climb_on moves in a row without a new target
  double climb_settle_s = 15.0;  // after a climb: wait this long for the landing's graph
  // A climb deferred this many times is taken the next time it is found: the floor's last
  // clusters, set aside at their viewpoints, came back whenever the map near them changed (the
  // office, seed 2: deferred at least 4 times in 600 s, the upper floor never reached).
  int max_climb_deferrals = 2;
  // PlanOptions::stale_floor_s: the graph grew by fewer nodes than this past its largest size
  // (sensor noise and pruning add and remove a few; a walk into unseen rooms adds hundreds).
  int stale_floor_nodes = 30;
  // With PlanOptions::flight_foot a deferral counts only with at most this many other clusters.
  int climb_deferral_max_others = 2;
  // With PlanOptions::flight_foot: cycles without a way back to a climb left for last before it
  // is given up (one B-spline failure gave up house seed 7's flight, session 14; else 1).
  int max_climb_return_failures = 6;
  double keep_target_margin_m = 2.0;     // periodic replan: the current target stays first
  double keep_target_margin_frac = 0.1;  // unless another tour is shorter by max(m, frac * tour)
  double set_aside_expiry_s = 30.0;      // a set-aside node may expire after this [s] ...
  double set_aside_expiry_move_m = 2.0;  // ... once the robot is this far from where it was
  // Path-failure retry (PlanOptions::path_retries): a vantage point at least this far away.
  double retry_move_m = 2.0;
  double retry_near_m = 1.5;   // ... first along G_real toward the frontier, this short of it
  int max_retry_vantages = 8;  // vantage points tried per cycle (bounded work)
};

// Target momentum (periodic replans): `order` (indices into a tour's clusters; cost matrix
// index + 1, robot at 0, an end anchor at n - 1 if with_anchor) is changed to start at `kept`
// unless the tour as solved is shorter than that by max(margin_m, margin_frac * its cost).
void keep_first_in_tour(size_t kept, const std::vector<double>& cost, int n, bool with_anchor,
                        double margin_m, double margin_frac, std::vector<size_t>& order);

class LocalPlanner {
 public:
  // LocalPlanInput::trajectory_lag_s counts at most this much: a robot that cannot follow at all
  // (its body wedged against a wall, the reference waiting for ever) still gets its target
  // overdue.
  static constexpr double kMaxReferenceLagS = 10.0;
  LocalPlanner(const RobotModel& robot, const PlanOptions& plan, double voxel_size_m,
               const LocalPlannerOptions& options = {});
  LocalPlanResult plan(const LocalPlanInput& in);
  // Forget the current target (after a safety stop the robot may be far from its trajectory).
  void drop_target() { has_target_ = committed_ = false; }
  bool has_target() const { return has_target_; }
  bool committed() const { return has_target_ && committed_; }  // an escape or climb under way
  uint64_t no_progress_events() const { return no_progress_events_; }  // PlanOptions::no_progress_s
  size_t set_aside_nodes() const { return set_aside_.size(); }
  uint64_t set_aside_expired() const { return expired_total_; }  // since construction
  // Blind climbs that ended with the robot on their landing, within half a step of its planned
  // height (not partial, not dropped on the flight); since construction. The LiDAR never saw
  // that ground: the firmware enters it as support under the legs (firmware/blind_support.hpp).
  uint64_t landings() const { return landings_; }
  // Diagnostics: foot stands at the end of a partial climb (climbing goes on from there).
  bool at_partial_climb_end(const Eigen::Vector3d& foot) const {
    return partial_climb_end(foot) != nullptr;
  }
  // Diagnostics: the set-aside frontier nodes with their reasons; the entry of the set-aside
  // node nearest p (within set_aside_radius_m), or nullptr.
  const std::vector<SetAsideEntry>& set_aside() const { return set_aside_; }
  const SetAsideEntry* set_aside_at(const Eigen::Vector3f& p) const;
  // A frontier node the planner no longer targets: set aside, or on a flight climbed blind.
  bool ignored(const Eigen::Vector3f& p) const {
    return set_aside_at(p) != nullptr || on_climbed_flight(p) || on_deferred_flight(p);
  }
  // A viewpoint that may be a target (PlanOptions::no_views_on_climbed_flights: not on a flight
  // the robot climbed).
  bool view_allowed(const Eigen::Vector3f& p) const {
    return !plan_opt_.no_views_on_climbed_flights || !on_climbed_flight(p);
  }
  void set_stage_probe(StageProbe* probe) { probe_ = probe; }

 private:
  struct Candidate {
    int32_t cluster_id;
    size_t cluster_index;
    uint32_t rep;  // representative node (nearest the centroid)
  };
  // Over a flight climbed blind (within 0.8 m of the climb's path below the landing), no
  // higher than its landing.
  bool on_climbed_flight(const Eigen::Vector3f& p) const;
  // Over the flight of the climb left for last (within 0.8 m of its axis, from half a step over
  // its foot to a step over its end, or over the flight's slope past a partial climb's end):
  // what the climb will see.
  bool on_deferred_flight(const Eigen::Vector3f& p) const;
  // Still on a flight climbed blind: its landing more than a step above (a climb dropped
  // mid-flight, its treads below never seen from above).
  bool below_climbed_landing(const Eigen::Vector3d& foot) const;
  struct ClimbedFlight;
  // The partial climb that ended where the robot stands (within 0.5 m, a step), or nullptr.
  const ClimbedFlight* partial_climb_end(const Eigen::Vector3d& foot) const;
  void set_aside_cluster(const LocalPlanInput& in, const graph::FrontierCluster& c,
                         SetAsideReason reason, const Eigen::Vector3f& hit_m = kNoHitM);
  int expire_set_aside(const LocalPlanInput& in);
  std::vector<Viewpoint> viewpoints_of(const LocalPlanInput& in, const Candidate& c) const;
  // PlanOptions::reach_off_graph: clusters without a path along G_real tried on the map.
  bool to_off_graph(const LocalPlanInput& in, std::vector<Candidate>& off, LocalPlanResult& out);
  // to_off_graph's progress across cycles: viewpoints of a cluster (by id, or its representative
  // within 0.5 m) already tried, so that each cycle's bounded attempts take up the next ones.
  struct OffGraphTried {
    int32_t cluster_id;
    Eigen::Vector3f rep_m;
    size_t tried;
  };
  std::vector<OffGraphTried> off_graph_tried_;
  int off_graph_cycles_ = 0;  // consecutive cycles that ended kSearching
  // Nothing else left: move to a new vantage point before the path failures end the run.
  bool retry_from_elsewhere(const LocalPlanInput& in, LocalPlanResult& out);
  void release_retry();
  void remember_retried(const SetAsideEntry& e);
  // out's trajectory (Stage 3's, to cluster c's viewpoint or its flight's foot) becomes the
  // current one, with c as the target.
  void adopt_target(const LocalPlanInput& in, const graph::FrontierCluster& c,
                    LocalPlanResult& out);
  // out becomes a kKeep of the trajectory followed, to the current target (no trajectory or
  // path of its own: a Stage 3 try may have left one there). The caller owns the state.
  LocalPlanResult& keep_current(LocalPlanResult& out, const char* reason) const;
  // Distance from the Stage 3 start to a body hit (infinite for kNoHitM) [m].
  double from_start_m(const Eigen::Vector3f& hit_m) const;
  // out's trajectory (an escape, a climb, a walk: to a pose, not to a cluster) becomes the
  // current one; committed: driven to its end.
  void adopt_move(const LocalPlanInput& in, LocalPlanResult& out, const char* reason,
                  bool committed);
  const graph::FrontierCluster* find_cluster(const LocalPlanInput& in, int32_t id) const;
  // The target cluster, under a new id if its nodes changed (see track_radius_m).
  const graph::FrontierCluster* track_target(const LocalPlanInput& in);
  void remember_target(const LocalPlanInput& in, const graph::FrontierCluster& c);
  void build_search_graph(const graph::ReachableGraph& g);
  // sg_ and robot_node_ for this cycle, if Stage 1 has not built them yet (a flight's foot is
  // walked to before it, to_foot_of).
  void ensure_search_graph(const LocalPlanInput& in);
  // The nearest alive node with an edge within r (dz vertically) of p, else kNoId.
  graph::NodeId linked_node_near(const graph::ReachableGraph& g, const Eigen::Vector3f& p, float r,
                                 float dz);
  // Stage 3 to one viewpoint; on failure *why says A* or trajectory.
  bool free_start(const LocalPlanInput& in);
  // PlanOptions::no_progress_s: true once the robot stood that long with a target (then the
  // clock starts again).
  bool no_progress(const LocalPlanInput& in);
  // Now on the followed trajectory's own clock (LocalPlanInput::trajectory_lag_s): its end
  // passed means the reference reached its end, not that its planned duration has elapsed. At
  // most kMaxReferenceLagS behind the clock.
  static double on_trajectory_s(const LocalPlanInput& in) {
    return in.t_s - std::clamp(in.trajectory_lag_s, 0.0, kMaxReferenceLagS);
  }
  // PlanOptions::stale_floor_s: true once the graph has not grown for that long.
  bool floor_stale(const LocalPlanInput& in);
  void brake_start(const LocalPlanInput& in);  // PlanOptions::brake_start: moves start_foot_m_
  // away_from: the start is boxed in by this obstacle: move away from it even if the body can
  // turn where it stands.
  bool escape(const LocalPlanInput& in, LocalPlanResult& out,
              const Eigen::Vector3f* away_from = nullptr);
  // What a try_target goal is: a frontier cluster's viewpoint (its yaw left free with
  // PlanOptions::face_cluster off), a pose (a retry's vantage point), or a flight's foot (the
  // path ends on it, not within the voxel A*'s goal tolerance of it: a climb starts there).
  enum class Goal { kClusterView, kPose, kFlightFoot };
  bool try_target(const LocalPlanInput& in, const Viewpoint& vp, LocalPlanResult& out,
                  SetAsideReason* why, Goal goal = Goal::kPose);
  // Clusters other than except_id with a frontier node not set aside.
  int other_targets(const LocalPlanInput& in, int32_t except_id) const;
  // Facing up a flight: straight up the flight's axis to the last support seen and
  // landing_step_m beyond (see local_planner.cpp). on_flight_only: only if the robot stands on
  // the flight already (a lower tread behind it).
  // given: the flight from to_flight_foot (the robot stands at its foot). stored_axis: at a
  // partial climb's end, that climb's axis (else the axis the robot faces, found anew).
  bool climb_on(const LocalPlanInput& in, LocalPlanResult& out, bool on_flight_only,
                const FlightFoot* given = nullptr, bool stored_axis = true);
  // PlanOptions::flight_foot: cluster c, about to be set aside, has a flight's first riser near:
  // a new target at the flight's foot (flight_foot()), once per foot; false if none.
  // The floor has no other target, or its graph stopped growing (stale): to the foot of a flight
  // that rises out of C_reach (a node's GraphNode::flight_lead on this floor, its foot not tried
  // yet); false if none.
  bool to_flight_lead(const LocalPlanInput& in, LocalPlanResult& out, bool stale = false);
  bool to_flight_foot(const LocalPlanInput& in, const graph::FrontierCluster& c,
                      LocalPlanResult& out);
  // A climb ended on a landing: to the foot of a flight rising from it within 2 m (the return
  // flight of a U-shaped stair), climbed from there whatever else is left; false if none. A foot
  // found with no way to it yet starts a wait on the landing (next_flight_wait_until_s_).
  bool to_next_flight(const LocalPlanInput& in, LocalPlanResult& out);
  // The planned walk (out) leads to flight f's foot: f becomes the target, with no frontier.
  void adopt_foot(const LocalPlanInput& in, const FlightFoot& f, const char* reason,
                  LocalPlanResult& out);
  // Stage 3 to f's stand point, else up to 0.75 m farther back on the axis (room to turn).
  bool to_foot_of(const LocalPlanInput& in, const FlightFoot& f, LocalPlanResult& out);
  // Boxed in on a flight (every Stage 3 body hit next to the start): straight down the flight's
  // axis over the support the map holds to the floor below, facing whichever way along the axis
  // the robot faces (see local_planner.cpp).
  bool descend_flight(const LocalPlanInput& in, LocalPlanResult& out);
  // A straight walk at constant yaw through `pts` (foot points), checked against the map.
  bool straight_walk(const LocalPlanInput& in, const std::vector<Eigen::Vector3d>& pts, double yaw,
                     LocalPlanResult& out);
  void take_walk(StraightWalk&& w, double yaw, LocalPlanResult& out);

  RobotModel robot_;
  PlanOptions plan_opt_;
  LocalPlannerOptions opt_;
  TspSolver tsp_;
  ViewpointDp dp_;
  VoxelAStar astar_;
  TrajectoryBuilder builder_;
  CollisionChecker checker_;
  StageProbe* probe_ = nullptr;
  GraphSearch search_, pair_search_;
  SearchGraph sg_;
  bool sg_fresh_ = false;  // sg_ was built from this cycle's graph
  std::vector<SearchGraph::Edge> edges_scratch_;
  std::vector<Eigen::Vector3d> pos_scratch_;

  uint32_t robot_node_ = 0xFFFFFFFFu;
  Eigen::Vector3d start_foot_m_ = Eigen::Vector3d::Zero();  // Stage 3 start (free_start())
  double start_yaw_ = 0;
  // PlanOptions::start_at_speed: the robot's planar velocity when free_start() found it clear
  // and moving (the curve may leave its foot at that speed), else none.
  std::optional<Eigen::Vector2d> start_velocity_;
  std::vector<Eigen::Vector3d> start_nodes_m_;  // nearest confirmed nodes (blind-ring starts)
  // Current target.
  bool has_target_ = false;
  bool periodic_ = false;  // this plan() is a periodic replan (PlanOptions::replan_only_if_faster)
  // PlanOptions::start_at_speed: slower robots start at rest; an at-speed curve must keep this
  // share of the robot's speed at its start (else it starts at rest).
  static constexpr double kAtSpeedMinMps = 0.2, kAtSpeedShare = 0.8;
  static constexpr double kFasterMarginS = 1.0;  // a new trajectory must arrive this much earlier
  int32_t target_cluster_ = -1;
  std::vector<Eigen::Vector3f> target_nodes_m_;  // the target cluster's frontier nodes
  Eigen::Vector3d target_m_ = Eigen::Vector3d::Zero();
  BsplineTrajectory current_;
  double planned_at_s_ = 0;
  // Frontier nodes set aside (positions: node ids are recycled) and Stage 3 failures per cluster.
  std::vector<SetAsideEntry> set_aside_;
  uint64_t expired_total_ = 0;
  std::vector<graph::NodeId> near_scratch_;
  // Path-failure set-asides released for a retry, with their count (a node set aside again near
  // one inherits it, so the retries stay bounded); retrying_: a retry move is under way.
  struct Retried {
    Eigen::Vector3f p_m;
    int retries;
  };
  std::vector<Retried> retried_;
  // PlanOptions::set_aside_backoff: places where frontier nodes were set aside unresolved (still
  // frontiers at their target, or overdue), with how often (Retried::retries counts them here).
  std::vector<Retried> unresolved_, unresolved_new_;
  bool retrying_ = false;
  std::vector<std::pair<int32_t, int>> failures_;
  Eigen::Vector3f last_hit_m_ = kNoHitM;  // try_target: where the last B-spline collided
  int start_escapes_ = 0;                 // escapes from a boxed-in start since the last target
  int climbs_ = 0;                        // climb_on moves since the last target
  bool committed_ = false;  // an escape or climb (PlanOptions::climb_blind): kept to its end
  // A blind climb is one way (the flight it crosses blind is not in G_real to come back down):
  // one found while other frontiers were left waits here (where the robot stood, facing the
  // flight) until the floor has no other reachable target; climb_start_: walking back to it.
  struct DeferredClimb {
    Eigen::Vector3d foot_m;
    double yaw_rad;
    std::optional<FlightFoot> flight;  // found by to_flight_foot: climbed from its foot
    Eigen::Vector3d end_m;             // where the climb found then ended
    bool partial;                      // ... at the last tread seen (climb_partial_)
    int failures = 0;                  // cycles in which no way back to it was found
    int misses = 0;                    // climbs tried near it that found no flight (flight_foot)
  };
  std::optional<DeferredClimb> deferred_climb_;
  std::vector<Eigen::Vector3f> leads_tried_;  // flight leads looked at by to_flight_lead
  struct LeadTrip {
    FlightFoot foot;
    int trips = 0;
  };
  static constexpr int kMaxLeadTrips = 3;
  std::optional<LeadTrip> lead_trip_;  // to_flight_lead's last trip, until its foot is reached
  int climb_deferrals_ = 0;            // climbs deferred since the last climb
  int descents_ = 0;                   // descend_flight walks since the last target
  bool climb_start_ = false;
  bool climbing_ = false;                 // the committed move is a climb
  double climb_done_s_ = -1;              // when the last climb ended
  double next_flight_wait_until_s_ = -1;  // to_next_flight found a foot but no way to it yet
  uint64_t landings_ = 0;                 // see landings()
  FlightAxis climb_axis_;                 // climb_on's last axis (origin: the walk's foot on it)
  FlightAxis climbing_axis_;              // the committed climb's axis
  // No-progress watchdog: where and when the robot last moved (PlanOptions::no_progress_s).
  NoProgressWatchdog progress_;
  uint64_t no_progress_events_ = 0;
  // PlanOptions::stale_floor_s: the graph's largest size and when it last grew past it.
  size_t growth_mark_nodes_ = 0;
  double growth_mark_t_s_ = 0;
  // Flights climbed blind: the climb's foot points and its landing height. Their frontiers stay
  // (the treads are edge-on from on the flight) and nothing resolves them from below; once the
  // landing's graph links to the flight's they would send the robot back down.
  struct ClimbedFlight {
    std::vector<Eigen::Vector3f> path_m;
    float top_z_m;
    Eigen::Vector3f end_m;  // where the climb's walk ended
    bool partial;           // it ended at the last tread seen, mid-flight
    FlightAxis axis;        // the climb's axis
  };
  bool climb_partial_ = false;  // climb_on's last walk ends mid-flight (nothing seen past it)
  std::vector<ClimbedFlight> climbed_;
  std::vector<int32_t>
      approached_;              // clusters whose viewpoint was reached once (walk onto them next)
  bool flight_target_ = false;  // the target is a flight's foot (to_flight_foot) ...
  FlightFoot flight_foot_;      // ... this one
  bool next_flight_ = false;    // ... from a landing, its next flight's (to_next_flight)
  std::vector<Eigen::Vector3f> flight_feet_tried_;  // each foot is a target once
  // Flights found (to_flight_foot, to_next_flight) and whether the robot has since stood
  // kFlightLedUpM above their foot: one that never led up is gone to before "no target".
  struct FoundFlight {
    FlightFoot foot;
    bool led_up = false;
    int trips = 0;
  };
  static constexpr double kFlightLedUpM = 2.0;  // above a landing (half a storey), below a floor
  static constexpr int kMaxFoundFlightTrips = 2;
  std::vector<FoundFlight> flights_found_;
  void remember_flight(const FlightFoot& f);
  bool to_found_flight(const LocalPlanInput& in, LocalPlanResult& out);
};

}  // namespace storey::core::plan

#pragma once
// Parameters of hierarchical planning with cross-floor priors (paper Sec. IV).
namespace storey::core::plan {

struct PlanOptions {
  double r_z_m = 6.0;        // r_z, bounded Dijkstra radius of a task zone
  int min_zone_nodes = 4;    // zones smaller than this are absorbed into neighbours
  int zone_capacity = 60;    // node capacity when merging unassigned components
  int window_w = 4;          // W, DP window (Eq. 6)
  int max_candidates_k = 8;  // K, viewpoints per cluster in the DP
  double lambda_psi = 0.5;   // lambda_psi, Eq. 6 heading-change penalty [m/rad]
  double lambda_a = 0.5;     // lambda_a, Eq. 6 anchor-distance weight
  int guidance_zones = 2;    // clusters from the first few zones of the global sequence
  // ... and every cluster within this distance of the robot along G_real (0: none). A prior that
  // misleads (the maze's upper floor) orders zones the robot then passes on its way.
  double guidance_near_m = 0.0;
  double floor_change_dz_m = 1.5;     // support height change that means another floor
  int hyp_discard_observations = 3;   // repeated empty observations before discarding S_hyp
  double hyp_promote_radius_m = 0.5;  // support found this close to a hypothetical column
  // Stage 1 / global order: open-tour TSP (tsp.hpp).
  int tsp_exact_max_n = 12;  // Held-Karp up to this many nodes, heuristic beyond
  // Stage 1 schedules the nearest this many clusters (graph distance), the rest wait for later
  // cycles (bounded work: one Dijkstra per cluster). The paper's TSP takes every cluster on a
  // floor without guidance (Sec. IV-D): a tour over the nearest few leaves dead ends behind.
  int tsp_max_clusters = 12;
  // Stage 2: dpsi_m through the viewpoint's own yaw psi_m instead of travel direction only.
  bool heading_via_viewpoint_yaw = false;
  // Stage 3: voxel A* (voxel_astar.hpp).
  int astar_max_expansions = 200000;     // bounded search
  bool astar_reachable_only = true;      // states in C_reach only
  double astar_cost_weight = 1.0;        // step cost * (1 + w * c(v)), c(v) of Eq. 2
  double astar_clearance_weight = 1.0;   // extra cost per metre near obstacles (long body)
  double astar_goal_tolerance_m = 0.25;  // reaching this close to the viewpoint is enough
  // Stage 3: B-spline (bspline_trajectory.hpp).
  double traj_control_spacing_m = 0.5;  // control point spacing along the pruned path
  int traj_max_repairs = 8;             // pinned vertices before the polyline fallback
  bool traj_grade_corners = false;      // spacing halved into sharp corners (one dt per curve)
  bool traj_retime = false;             // time-optimal speed profile along the curve
  double traj_retime_yaw_share = 0.97;  // ... using this share of the yaw-rate and -accel limits
  // FCL look-ahead of the control task (collision_checker.hpp).
  double lookahead_s = 1.0;  // T: check the next T seconds of the trajectory
  // Macro layer (Sec. IV-A..C; exploration_planner.hpp).
  double floor_stable_s = 2.0;           // new support height must hold this long (floor change)
  double floor_stable_band_m = 0.08;     // ... within this band
  double floor_stable_travel_m = 2.0;    // ... while the robot walks this far in it
  double floor_node_band_m = 0.6;        // nodes within this of a floor's height belong to it
  double zone_clearance_radius_m = 3.0;  // bounded obstacle search for zone seeds (IV-A)
  double hyp_height_window_m = 0.5;      // |z - projected z| for promotion / merge (dz error)
  double hyp_check_radius_m = 20.0;      // hypotheses re-checked within this of the robot
  double hyp_bridge_radius_m = 1.6;      // hypothetical links from real nodes to S_hyp nodes
  int zone_merge_cross_edges = 2;        // "sufficient cross-zone edges" for a merge (IV-B 3)
  double zone_merge_distance_m = 3.0;    // ... or centroids this close
  double zone_visit_radius_m = 1.5;      // robot this close to c_k: zone visited (state C test)
  // Ablation switches (paper Table IV).
  bool use_prior = true;
  // Beyond the paper, on in config/default.yaml (issue #9): a frontier on a flight of stairs is not
  // seen from on it (the body pitches with the flight, the LiDAR looks over the treads); climb on
  // up the flight's axis onto the landing, blind past the last support seen, and drive escapes to
  // their end. Off here (the paper's method, what unit tests construct); docs/RESULTS.md
  // session 11.
  bool climb_blind = false;
  // Beyond the paper, on in config/default.yaml (issue #9): at a periodic replan the current target
  // stays first unless another tour is clearly shorter (LocalPlannerOptions::keep_target_margin_m /
  // _frac).
  bool target_momentum = false;
  // Beyond the paper, on in config/default.yaml (issue #9): before "complete", frontiers set aside
  // for a path failure (no A* path, no collision-free trajectory: often the robot could not turn
  // where it stood) are retried up to this many times, each after a move to a new vantage point. 0:
  // off.
  int path_retries = 0;
  // Beyond the paper, on in config/default.yaml (session 26): a viewpoint whose heading the body
  // cannot turn to where it stands (a collision within a body length of it: on a 1.5 m ramp,
  // test_ramp) is reached facing along the path instead. The heading is a preference (Eq. 6 prices
  // the turn); the LiDAR sees all round, so the frontier is observed from the viewpoint either way.
  bool arrive_along_path = false;
  // Paper (Sec. III-C): a viewpoint's yaw faces its cluster's centroid and the robot arrives
  // turned to it. Off (session 30): every viewpoint is reached facing along the path (the curve's
  // own end yaw; a flight's axis on a flight): the LiDAR sees all round, so the turn at the end
  // observes nothing more, and the next leg often turns back.
  bool face_cluster = true;
  // Beyond the paper, off (session 30): Stage 1 schedules the clusters at the robot's level
  // (representative within floor_node_band_m of its support height) first; the others (up a
  // ramp, on a landing, seen through a stairwell) once none is left, and first once the graph
  // stopped growing (stale_floor_s: what is left does not resolve). The paper explores floor by
  // floor (Table II), its prior projected from an explored reference floor; a ramp, unlike a
  // flight, is no climb left for last, and the maze's robot walked up it with the ground floor
  // half seen.
  bool floor_first = false;
  // Beyond the paper, on in config/default.yaml (session 26): before "complete", clusters with no
  // path along G_real are tried with Stage 3 on the map (voxel A*), which needs no graph (a graph
  // split at a door it did not link through: office seed 1). One that no trajectory reaches is set
  // aside.
  bool reach_off_graph = false;
  // Beyond the paper, off (session 27): a periodic replan in which Stage 3 finds no trajectory to
  // the target's cluster (or to any cluster) keeps the trajectory followed, still collision-free on
  // this cycle's map, instead of an escape or a turn back to another cluster. From a pose on a walk
  // through a narrow passage a new B-spline (from rest, at the robot's heading) may find no room to
  // turn that the walk itself never needed: maze seed 1 (session 26) turned back at the same corner
  // eight times and never reached the cluster beyond it.
  bool keep_on_failed_replan = false;
  // Beyond the paper, off (session 13): at a frontier the blind climb also looks for the flight
  // from up to this far ahead on level ground (flight_axis needs treads 0.6 and 0.9 m ahead; a
  // viewpoint 0.83 m before the first riser ended the office, seed 2, unclimbed). 0: from the
  // foot only. On, it moved which seeds end with a floor unreached (docs/RESULTS.md session 13).
  double climb_axis_ahead_m = 0.0;
  // Beyond the paper, on in config/default.yaml (session 15; inert in every default run of
  // docs/RESULTS.md): the robot stood still (moved < 0.15 m, turned < 0.3 rad) with a
  // target for this long: the body meets something the plan did not expect, and every replan
  // from there is the same (office seed 1 with session 14's deferred-flight change: 255 s against
  // a table leg). The target's cluster is set aside and the robot steps away from the nearest
  // obstacle. 0: off.
  double no_progress_s = 0.0;
  // Beyond the paper, with climb_blind (session 19): a climb left for last is taken once the
  // reachable graph has not grown (LocalPlannerOptions::stale_floor_nodes past its largest size)
  // for this long, though frontiers remain: they are ones the robot cannot resolve from this
  // floor. In the teaching building's stair hub ten such clusters came back whenever the map
  // near them changed, the climb deferred at 1020 s was never retaken, and the upper floor stayed
  // at 0 % at 1800 s. 0: off (a deferred climb waits until no target is left).
  double stale_floor_s = 0.0;
  // Session 20: a periodic replan to the same cluster publishes its trajectory only if it arrives
  // at least LocalPlanner::kFasterMarginS earlier than the one followed (every new trajectory
  // starts at rest: the robot slowed down at every replan).
  bool replan_only_if_faster = false;
  // Beyond the paper (session 14, with climb_blind): a frontier cluster about to be set aside (its
  // viewpoint reached and still a frontier, or Stage 3 failing) with a flight's first riser within
  // 1.5 m is first approached at the flight's foot (flight_foot: on its axis, facing up, 0.45 m
  // before the riser), where the blind climb can start; the stair-foot "complete" of house seeds
  // 6 and 7 (docs/RESULTS.md session 13).
  bool flight_foot = false;
  // Beyond the paper (session 16): a robot moving when Stage 3 plans comes to rest |v|^2 / (2
  // a_max) further on (the control task's acceleration limit), on the trajectory it follows; the
  // new trajectory starts there, where the braking path is clear, and the control task brakes on
  // the old one before entering a new one that turns away (house seed 3: a new target behind the
  // robot, the body turned while overshooting its start into the stairwell's railing).
  bool brake_start = false;
  // The planner judges the followed trajectory's end on its reference's own clock
  // (LocalPlanInput::trajectory_lag_s, from the control task), not on its planned duration.
  bool reference_clock = false;
  // Beyond the paper (session 28): the reference never trails a robot that is ahead of it on
  // the trajectory; it moves on to the trajectory's point nearest the robot
  // (ControlLaw::catch_up_time). Held back, it pulled the body off the checked path.
  bool reference_catch_up = false;
  // Beyond the paper (session 29): a new trajectory for a moving robot leaves the robot's
  // position at plan time along its velocity, at its speed (TrajectoryBuilder::build's
  // start_velocity_mps), where the curve allows at least 0.8 of that speed and is clear; else
  // it starts at rest as before (brake_start). Started at rest, every replan left the robot
  // ahead of its reference (0.47 m in office seed 2's table-leg collision, session 28).
  bool start_at_speed = false;
  // Beyond the paper (session 32): a straight walk (a climb, a descent) from a robot facing
  // elsewhere first turns the body on the spot, and that turn is collision-checked
  // (straight_walk's from_yaw); else the body turned there unchecked.
  bool turn_before_walk = false;
  // brake_start predicts the rest point along the last published trajectory only where that
  // point lies within 60 deg of the robot's velocity, else straight along the velocity
  // (session 32).
  bool brake_along_motion = false;
  // Beyond the paper (session 32), the control task: a new trajectory that turns away from a
  // moving robot is entered once braked to rest on the one followed, wherever it starts (not
  // only one starting on it ahead). Entered at walking speed from behind, the body overshot
  // 0.3 m past the new reference into a wall (office seed 3 with
  // safety.reference_speed_lead_mps).
  bool enter_at_rest = false;
  // Beyond the paper (session 32): the drive toward a zone centre (ExplorationPlanner::drive_to)
  // is kept while its reference has more than a second to go, not planned anew each cycle.
  bool keep_zone_drive = false;
  // Beyond the paper, on in config/default.yaml (session 33): before "complete", frontiers on a
  // flight (two steps or more above the robot's floor, or where flight_foot finds a flight's foot)
  // set aside as still frontiers at their target are retried like path failures (path_retries): a
  // walk to a new vantage point, then their flight's foot again. With
  // graph.close_probes_at_wall_faces the floor runs out of phantom frontiers, and a climb that
  // failed once from the foot ended the run below its upper floor (house seed 5).
  bool retry_flight_frontiers = false;
  // Beyond the paper, on in config/default.yaml (session 33): a climb going on from a partial
  // climb's end that fails along that climb's axis is tried up the axis the robot faces, found anew
  // (LocalPlanner::climb_on).
  bool climb_axis_anew = false;
  // Beyond the paper, on in config/default.yaml since session 35 (added in 34): a frontier set
  // aside unresolved (still a frontier with the robot at its viewpoint, or overdue) where one was
  // set aside before waits twice as long (up to 16x) before a move away releases it. A hole by a
  // wall end that the robot's blind ring covers from every viewpoint drew the robot back every
  // 30 s for the maze's last 350 s (seed 1, ground floor 75.9 %; 94.1 % with it). Off in session
  // 34: office seed 2's path with it went back onto the flight from its landing and wedged the
  // body; on with no_views_on_climbed_flights, which keeps it off the flight (docs/RESULTS.md).
  bool set_aside_backoff = false;
  // Beyond the paper, on in config/default.yaml (session 35): a cluster's viewpoints on a flight
  // the robot climbed are not targets (its nodes there already are not,
  // LocalPlanner::on_climbed_flight). Right after its climb office seed 2 (with
  // set_aside_backoff) went back down to a viewpoint on the top tread, turned on the treads and
  // wedged the body crossing the landing's edge diagonally.
  bool no_views_on_climbed_flights = false;
  // Beyond the paper, off here (session 40; on in config/default.yaml since 41): the target's
  // cluster, gone from the guided zones' clusters (Sec. IV-C: the tour's first zones change as the
  // robot moves) but still a frontier cluster, is kept as the target until it is observed or
  // reached, not dropped as "observed". Maze seed 1 at 8263464: the first zone flipped between a
  // corridor's two ends and the robot turned back and forth there for 500 s (393 "target cluster
  // observed" replans over the run, ~130 in the others).
  bool keep_guided_target = false;
  bool incremental_maintenance = true;
};

}  // namespace storey::core::plan

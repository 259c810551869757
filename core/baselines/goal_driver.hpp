#pragma once
// What every baseline shares with the paper's method and with each other (issue 10: "same map,
// speed limits, sensor and statistics"): the Stage-3 machinery of core/plan used as a library
// (voxel A* or a given support polyline -> path centring -> collision-checked, speed-limited
// B-spline), plus the target bookkeeping every frontier planner needs: keep a target until it
// is reached, gone or due for a replan; set aside goals that stay frontiers after the robot
// stood there or whose Stage 3 fails repeatedly (so exploration ends when nothing reachable
// and observable is left). Single-threaded; owned by one baseline planner.
#include <cmath>
#include <functional>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "core/plan/bspline_trajectory.hpp"
#include "core/plan/collision_checker.hpp"
#include "core/plan/escape.hpp"
#include "core/plan/exploration_planner.hpp"
#include "core/plan/plan_options.hpp"
#include "core/plan/voxel_astar.hpp"
#include "core/robot_model.hpp"

namespace storey::core::baselines {

struct BaselineOptions {
  double replan_period_s = 4.0;       // re-choose a kept target this often [s]
  double reached_radius_m = 0.5;      // robot this close (horizontally) to the goal = reached
  double set_aside_radius_m = 0.5;    // goals this close to a set-aside one are ignored [m]
  int max_failures = 2;               // Stage 3 failures before a goal is set aside
  int max_attempts = 6;               // Stage 3 attempts per cycle (bounded work)
  double overdue_s = 10.0;            // trajectory ended this long ago without arrival: set aside
  double escape_turn_radius_m = 0.8;  // cannot turn on the spot: a turning place this far
                                      // (LocalPlannerOptions::escape_turn_radius_m)
  double start_blame_radius_m = 0.7;  // every attempt's body hits an obstacle this close to the
  int max_start_escapes = 3;          // start: step away from it, at most this many times in a row
                                      // (LocalPlannerOptions, same names)
  int min_cluster_cells = 4;          // smaller frontier clusters are noise (nearest-frontier,
                                      // fael-like)
  double height_threshold_m = 0.3;    // tare-like: largest height difference of a link [m] ...
  double link_spacing_m = 1.0;        // ... per this much horizontal distance (viewpoint spacing)
  double global_cell_m = 8.0;         // tare-like: horizontal size of a global subspace [m]
  double fael_band_m = 0.15;          // fael-like: support within this of the floor height is free
  double fael_obstacle_from_m = 0.1;  // fael-like: anything occupied above floor + this, below
                                      // the body top, is an obstacle (steps, ramps past the band)
};

// A goal candidate of one baseline: where to stand, which way to face, and a key position for
// the set-aside list (the frontier it serves).
struct Goal {
  Eigen::Vector3d p_m = Eigen::Vector3d::Zero();    // support point to drive to
  double yaw_rad = 0;                               // facing the unknown
  Eigen::Vector3d key_m = Eigen::Vector3d::Zero();  // the frontier's position (set-aside key)
  double cost = 0;                                  // the method's ordering cost (lower first)
  std::vector<Eigen::Vector3d> path_m;  // support polyline from the robot (empty: voxel A*)
  uint32_t node = UINT32_MAX;           // its graph node, if the method has one (fallback paths)
};

class GoalDriver {
 public:
  GoalDriver(const RobotModel& robot, const plan::PlanOptions& plan, double voxel_size_m,
             const BaselineOptions& options);

  // Keep the current target? Call first each cycle with the goals of this cycle. Returns true
  // (and fills r as kKeep) if the target is still a goal (a goal key within set_aside_radius_m),
  // not reached, not overdue, younger than replan_period_s and its trajectory still free on this
  // map. Reaching a target whose frontier is still a goal sets it aside (not observable from
  // where the robot can stand), after walking onto the frontier with set_approach_frontier (then
  // r is kNewTrajectory and true is returned).
  bool keep(const plan::ExplorationInput& in, const std::vector<Goal>& goals,
            plan::ExplorationResult& r);
  // Goals in cost order minus set-aside ones; tries Stage 3 on them (at most max_attempts) and
  // fills r: kNewTrajectory, or kComplete when none is left, or kExploring when all attempts
  // failed this cycle (failing goals are set aside after max_failures cycles).
  void choose(const plan::ExplorationInput& in, std::vector<Goal>& goals,
              plan::ExplorationResult& r);
  // Stage 3 to one goal: voxel A* (or the goal's own polyline), centring, B-spline. From a rest
  // start away from the robot, the voxel A* first, else the goal's own polyline from its point
  // nearest that start (path_from_nearest), else the fallback path.
  bool drive(const plan::ExplorationInput& in, const Goal& g, plan::ExplorationResult& r);

  // start, then path's points after the one nearest start (horizontally); at least two points.
  static std::vector<Eigen::Vector3d> path_from_nearest(const std::vector<Eigen::Vector3d>& path,
                                                        const Eigen::Vector3d& start);

  bool set_aside(const Eigen::Vector3d& key_m) const;
  bool set_aside(const Goal& g) const;  // its key or its standing point
  // Set aside the goals within set_aside_radius_m of p_m, as choose() does after max_failures
  // (the planners' own goal filters see it at once).
  void set_aside_at(const Eigen::Vector3d& p_m) { add_set_aside(p_m); }
  void drop_target() { has_target_ = escaping_ = false; }
  bool has_target() const { return has_target_; }
  // Goals set aside, by why: stood there and still a goal / never arrived (overdue_s) / Stage 3
  // failed max_failures times / the robot stood still with it for plan.no_progress_s. The run
  // record's end reason names them.
  struct SetAsideCounts {
    uint32_t stood_at = 0, overdue = 0, no_trajectory = 0, no_progress = 0;
  };
  const SetAsideCounts& set_aside_counts() const { return counts_; }
  plan::VoxelAStar& astar() { return astar_; }
  // Optional path filter (tare-like: no climbs steeper than its link rule); false rejects.
  void set_path_filter(std::function<bool(const std::vector<Eigen::Vector3d>&)> filter) {
    filter_ = std::move(filter);
  }
  // Optional path where the voxel A* finds none (tare-like: along its own viewpoint graph, as
  // TARE plans; on a sparsely seen ramp the voxel A* fails where the graph still connects).
  // Returns support points from near the robot to the goal, or none.
  // Walk onto the frontier itself when its viewpoint was reached and it is still a goal, before
  // setting it aside (as the local layer does: the LiDAR's blind ring moves with the robot, so
  // ground beyond a frontier is often seen only from on it). Needs goals whose key_m is a place
  // to stand (tare-like's frontier node, nearest-frontier's member voxel).
  void set_approach_frontier(bool on) { approach_frontier_ = on; }
  void set_fallback_path(
      std::function<std::vector<Eigen::Vector3d>(const plan::ExplorationInput&, const Goal&)> f) {
    fallback_ = std::move(f);
  }

 private:
  void add_set_aside(const Eigen::Vector3d& key_m) { set_aside_.push_back(key_m); }
  // Where on the trajectory followed the control task's reference is (its clock, lag included).
  static double followed_s(const plan::ExplorationInput& in);
  void adopt(const plan::ExplorationInput& in, const Goal& g, const plan::ExplorationResult& r);
  // r: the escape walk w as a new trajectory with no target kept (the goals are not blamed);
  // keep() keeps it until it ends.
  void publish_escape(plan::StraightWalk w, const plan::ExplorationInput& in,
                      plan::ExplorationResult& r);
  // The escape walk (publish_escape) from the nearest free pose away from hit, with reason;
  // false if there is none.
  bool escape_away_from(const plan::ExplorationInput& in, const Eigen::Vector3f& hit,
                        const char* reason, plan::ExplorationResult& r);
  // Up to max_n points within radius_m (horizontally) of p_m over support voxels the voxel A* may
  // stand on, nearest first, at least 0.25 m apart.
  std::vector<Eigen::Vector3d> passable_supports_near(const map::MapView& view,
                                                      const Eigen::Vector3d& p_m, double radius_m,
                                                      size_t max_n) const;

  RobotModel robot_;
  BaselineOptions opt_;
  plan::VoxelAStar astar_;
  plan::TrajectoryBuilder builder_;
  plan::CollisionChecker checker_;
  std::function<bool(const std::vector<Eigen::Vector3d>&)> filter_;
  std::function<std::vector<Eigen::Vector3d>(const plan::ExplorationInput&, const Goal&)> fallback_;
  // Current target.
  bool has_target_ = false;
  Goal target_;
  double planned_at_s_ = 0, traj_end_s_ = 0;
  plan::BsplineTrajectory traj_;  // the trajectory last published (re-checked in keep() while it
                                  // leads to the target; a new start brakes along it)
  bool approach_frontier_ = false;
  double no_progress_s_ = 0;        // PlanOptions::no_progress_s (0: off)
  bool arrive_along_path_ = false;  // PlanOptions::arrive_along_path
  bool escaping_ = false;  // an escape walk (publish_escape) runs until it ends at escape_to_m_
  double escape_end_s_ = 0;
  Eigen::Vector3d escape_to_m_ = Eigen::Vector3d::Zero();
  plan::NoProgressWatchdog progress_;  // the local layer's no-progress watchdog
  // Where drive()'s last Stage 3 attempt hit an obstacle (NaN: it did not collide).
  Eigen::Vector3f last_hit_m_ = Eigen::Vector3f::Constant(NAN);
  int start_escapes_ = 0;                    // boxed-in escapes since the last trajectory to a goal
  bool ever_moved_ = false;                  // a trajectory was published (start-up is over)
  std::vector<Eigen::Vector3d> approached_;  // frontier keys walked onto (set_approach_frontier)
  std::vector<Eigen::Vector3d> set_aside_;
  SetAsideCounts counts_;
  std::vector<std::pair<Eigen::Vector3d, int>> failures_;
};

}  // namespace storey::core::baselines

#pragma once
// Getting a long body out of a place it cannot turn in: a straight step at constant yaw (the
// legs walk sideways or backwards as well) to the nearest pose where the body turns on the spot.
// Stage-3 machinery shared by the paper's local layer (LocalPlanner) and the baselines
// (GoalDriver): in a corridor narrower than the body's turning circle every path that starts
// with a turn collides, however good the target.
#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "core/map/map_view.hpp"
#include "core/plan/bspline_trajectory.hpp"
#include "core/plan/collision_checker.hpp"
#include "core/robot_model.hpp"

namespace storey::core::plan {

// The body turns on the spot at foot: 24 yaws (15 deg apart) from yaw, none colliding.
bool can_turn_at(CollisionChecker& checker, const map::MapView& view, const Eigen::Vector3d& foot,
                 double yaw);

// A straight walk: its trajectory and its end points (the first and last of the points given).
struct StraightWalk {
  BsplineTrajectory trajectory;
  Eigen::Vector3d from_m = Eigen::Vector3d::Zero(), to_m = Eigen::Vector3d::Zero();
};

// A B-spline through pts at constant yaw, starting at t0 (knots at half the speed limit and the
// acceleration limit at the ends), collision-checked; nullopt if it collides. With a finite
// from_yaw (the robot's yaw) further than 0.5 rad from yaw, the walk first turns the body on the
// spot at pts.front() to yaw, the shorter way round, within half the yaw-rate and
// yaw-acceleration limits: that turn is checked too. Without it the body turned on the spot
// where the walk started, behind a reference that held still for it, through poses no check saw
// (house seed 5, session 31: a climb started 0.3 m beside a flight's axis, 2 rad off it).
std::optional<StraightWalk> straight_walk(CollisionChecker& checker, const map::MapView& view,
                                          const RobotModel& robot,
                                          const std::vector<Eigen::Vector3d>& pts, double yaw,
                                          double t0, double from_yaw = NAN);

// Where a robot at foot moving at v (planar, world) comes to rest braking straight at the
// acceleration limit (|v|^2 / (2 a_max) on), if the body is clear every 0.05 m on the way (at
// yaw and 0.6 rad either side) over no untraversable support; the support's height where seen
// (the LiDAR's blind ring is unseen: the robot goes there anyway). nullopt: under 0.05 m to rest,
// or not clear.
std::optional<Eigen::Vector3d> straight_rest_point(CollisionChecker& checker,
                                                   const map::MapView& view,
                                                   const RobotModel& robot,
                                                   const Eigen::Vector3d& foot, double yaw,
                                                   const Eigen::Vector2d& v, double t_s);

// Where a robot at foot moving at v comes to rest braking along traj, the trajectory it follows
// (the control task brakes on it before it enters a new one): from traj's point nearest foot
// (within 0.3 m, t_on +- 2 s), |v|^2 / (2 a_max) of arc on, its poses checked every 0.05 m.
// kNotOn: under 0.05 m to rest, the robot not on traj, or (along_motion) the rest point not
// ahead along v; kBlocked: a pose on the way collides (start where the robot is).
struct RestOnTrajectory {
  enum class Kind : uint8_t { kNotOn, kBlocked, kRest } kind = Kind::kNotOn;
  BodyPose pose;  // kRest: the rest pose (at t_s)
};
RestOnTrajectory rest_on_trajectory(CollisionChecker& checker, const map::MapView& view,
                                    const RobotModel& robot, const BsplineTrajectory& traj,
                                    const Eigen::Vector3d& foot, const Eigen::Vector2d& v,
                                    double t_on, double t_s, bool along_motion);

// The straight step from start (yaw kept) to the nearest reachable pose within radius_m where
// the body can turn, nearest first (0.1 m rings, 16 directions); with away_from, only poses that
// gain distance from that point (at least half the step). nullopt: none.
std::optional<StraightWalk> escape_to_turn(CollisionChecker& checker, const map::MapView& view,
                                           const RobotModel& robot, const Eigen::Vector3d& start,
                                           double yaw, double t0, double radius_m,
                                           const Eigen::Vector3f* away_from = nullptr);

// PlanOptions::no_progress_s, shared by LocalPlanner and GoalDriver: stalled() is true once the
// robot stood still (within 0.15 m and 0.3 rad) for period_s with a target, replans to the same
// target included; then the clock starts again. Off (never true) for period_s <= 0.
class NoProgressWatchdog {
 public:
  bool stalled(const Eigen::Vector3d& foot, double yaw, double t_s, bool has_target,
               double period_s);

 private:
  Eigen::Vector3d foot_m_ = Eigen::Vector3d::Constant(NAN);
  double yaw_ = 0, t_s_ = 0;
};

// The occupied voxel nearest foot horizontally (within 0.6 m, from step height to body height
// above it): what a body that stopped making progress is pressed against. None seen: a point
// 0.45 m ahead at yaw, half the body's height up.
Eigen::Vector3f blocking_point(const map::MapView& view, const RobotModel& robot,
                               const Eigen::Vector3d& foot, double yaw);

// The pose itself if the body there is collision-free, else the nearest collision-free one at the
// same yaw within radius_m (0.05 m rings, 16 directions, height kept); nullopt: none.
std::optional<Eigen::Vector3d> nearest_free_foot(CollisionChecker& checker,
                                                 const map::MapView& view, const BodyPose& pose,
                                                 double radius_m);

}  // namespace storey::core::plan

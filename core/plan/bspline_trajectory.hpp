#pragma once
// Stage 3 of local planning (paper Sec. IV-D): the discrete voxel A* path becomes a smooth,
// collision-free, dynamically feasible uniform cubic B-spline for the control task.
//
// 1. Shortcut: greedy pruning of the path, keeping a jump a -> b only where the straight segment
//    has support under it (a traversable surface within step height of the interpolated height,
//    every half voxel) and the body box swept along it is collision-free (FCL).
// 2. Control points: the pruned polyline densified to control_spacing_m, first and last point
//    tripled (the curve starts and ends on them at rest; or, given the robot's velocity, the
//    start is P_1 with P_0, P_2 = P_1 -/+ h v / |v|: the curve leaves along v). Yaw has its own
//    control points (the travel direction around each point, unwrapped; start = robot yaw, end =
//    goal yaw if given).
// 3. Timing: one knot interval dt for the whole spline, the smallest with
//      |P_{i+1} - P_i|_xy / dt <= v_max,  |P_{i+2} - 2 P_{i+1} + P_i|_xy / dt^2 <= a_max,
//    and the same for yaw with the yaw-rate / yaw-acceleration limits. By the convex-hull
//    property of B-spline derivatives this bounds speed and acceleration everywhere on the curve.
//    Or (TrajectoryOptions::retime) the same curve re-timed: the fastest speed profile along it
//    within the same four limits, at rest at both ends (BsplineTrajectory::retime).
// 4. Collision repair: the curve is sampled at the checker's spacing; where the body hits, the
//    nearest polyline vertex is pinned (tripled control point: the curve passes through it and
//    follows the polyline there); after max_repairs, every vertex is pinned (the polyline itself).
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "core/map/map_view.hpp"
#include "core/plan/collision_checker.hpp"
#include "core/robot_model.hpp"

namespace storey::core::plan {

struct TrajectorySample {
  Eigen::Vector3d p_m = Eigen::Vector3d::Zero();     // support point [m]
  Eigen::Vector3d v_mps = Eigen::Vector3d::Zero();   // velocity [m/s]
  Eigen::Vector3d a_mps2 = Eigen::Vector3d::Zero();  // acceleration [m/s^2]
  double yaw_rad = 0;
  double yaw_rate_rps = 0;
  double pitch_rad = 0;  // terrain pitch along the heading (for the body box)
};

// A uniform cubic B-spline in time: control points P_0..P_{n-1} (n >= 4), knot interval dt,
// segment i covers [t0 + i dt, t0 + (i+1) dt]. Plain data: copyable into a mailbox.
class BsplineTrajectory {
 public:
  BsplineTrajectory() = default;
  BsplineTrajectory(std::vector<Eigen::Vector3d> ctrl, std::vector<double> yaw_ctrl, double dt_s,
                    double t0_s);

  bool empty() const { return ctrl_.size() < 4; }
  double t_start() const { return t0_; }
  double t_end() const { return t0_ + duration(); }
  double duration() const {
    return empty() ? 0.0 : retimed() ? w_t_.back() : double(ctrl_.size() - 3) * dt_;
  }
  double knot_interval() const { return dt_; }
  // Position, velocity, yaw at time t (clamped to [t_start, t_end]).
  TrajectorySample sample(double t_s) const;
  BodyPose pose(double t_s) const;
  const std::vector<Eigen::Vector3d>& control_points() const { return ctrl_; }
  const std::vector<double>& yaw_control_points() const { return yaw_; }
  // Convex-hull bounds of |v|_xy and |a|_xy over the whole curve (re-timed: the largest |v|_xy
  // at the re-timing's samples, the largest |a|_xy sampled every 10 ms).
  double speed_bound_mps() const;
  double accel_bound_mps2() const;

  // Re-times the same curve: one knot interval for the whole curve lets its sharpest corner set
  // the speed of every straight metre (a right angle at 0.5 m spacing: 0.59 m/s under a 1 m/s
  // limit). The curve's shape, and so every collision check of it, is unchanged; only how fast
  // it is walked: the time-optimal profile along its length (forward-backward integration of
  // the path acceleration under the planar speed and acceleration limits and the yaw-rate and
  // yaw-acceleration limits, on samples_per_knot samples per knot interval), at rest at both
  // ends and wherever the curve stops (a pinned vertex). Limits are used at `margin` of their
  // value (the profile is exact at the samples only).
  // yaw_margin: the same for the yaw-rate and yaw-acceleration limits.
  // start_speed_mps: the speed the profile starts at (a curve leaving along the robot's velocity,
  // TrajectoryBuilder::build), capped by what the curve and the limits allow there.
  void retime(const RobotModel& robot, int samples_per_knot = 16, double margin = 0.97,
              double yaw_margin = 0.97, double start_speed_mps = 0.0);
  bool retimed() const { return !w_t_.empty(); }

 private:
  // The curve's position and yaw and their derivatives in the knot parameter u at u.
  struct Geometry {
    Eigen::Vector3d p, p_u, p_uu;
    double yaw, yaw_u, yaw_uu;
    int segment;
  };
  Geometry geometry(double u) const;
  // The same derivatives with respect to the re-timing's path parameter sigma (planar length
  // and yaw at kYawLength metres per radian); false where the curve stands still (d sigma / du
  // = 0: the direction is undefined, the curve is at rest there).
  struct PathDerivs {
    Eigen::Vector3d p_s, p_ss;
    double yaw_s, yaw_ss, sigma_u;
  };
  bool path_derivs(const Geometry& g, PathDerivs& d) const;

  std::vector<Eigen::Vector3d> ctrl_;
  std::vector<double> yaw_;
  double dt_ = 1.0;
  double t0_ = 0;
  // Re-timing (empty: uniform time, u = (t - t0) / dt): per sample, the time since t0, the knot
  // parameter u, the path parameter sigma and its rate d sigma / dt.
  std::vector<double> w_t_, w_u_, w_s_, w_sd_;
};

struct TrajectoryOptions {
  double control_spacing_m = 0.5;  // densification of the polyline (larger: faster corners)
  bool shortcut = true;
  bool reachable_only = true;  // shortcut support must be in C_reach (else S_trav suffices)
  int max_repairs = 8;         // pinned vertices before falling back to the whole polyline
  // The spacing is halved into every sharp corner (up to three times), so one corner does not
  // slow the whole curve (one knot interval) below what its straight parts allow.
  bool grade_corners = false;
  // The curve re-timed (BsplineTrajectory::retime): each part as fast as the limits allow there.
  bool retime = false;
  // Share of the yaw-rate and yaw-acceleration limits the re-timed profile uses (the planar ones
  // at 0.97). The tracking law adds a correction to the reference's yaw rate: at the limit, a
  // robot behind its reference's yaw stays behind through the whole turn and its 0.7 m body
  // sweeps beside the poses checked (maze seed 1, session 22).
  double retime_yaw_share = 0.97;
};

enum class TrajectoryStatus : uint8_t {
  kOk = 0,
  kPolyline,   // smooth curve kept colliding: the pinned polyline (stops at every vertex)
  kBadInput,   // fewer than 1 point, non-finite points or yaw
  kCollision,  // even the polyline collides (the input path is not body-safe)
};
const char* to_string(TrajectoryStatus s);

struct TrajectoryResult {
  TrajectoryStatus status = TrajectoryStatus::kBadInput;
  BsplineTrajectory trajectory;
  std::vector<Eigen::Vector3d> waypoints_m;  // the pruned polyline
  CollisionHit hit;                          // the last collision check
  int repairs = 0;
  uint32_t segment_checks = 0;  // shortcut segment tests
  double start_speed_mps = 0;   // planar speed at t_start (0 unless started at speed)
};

class TrajectoryBuilder {
 public:
  TrajectoryBuilder(const RobotModel& robot, const TrajectoryOptions& options = {})
      : robot_(robot), opt_(options) {}

  // path_m: support points from the voxel A* (start = the robot). yaw_goal: the viewpoint's yaw.
  // start_velocity_mps (planar, world; with TrajectoryOptions::retime only): the curve leaves
  // path_m[0] along it at its speed, or as near it as the curve's first bend allows
  // (TrajectoryResult::start_speed_mps), instead of at rest.
  TrajectoryResult build(const map::MapView& view, CollisionChecker& checker,
                         std::span<const Eigen::Vector3d> path_m, double yaw_start_rad,
                         std::optional<double> yaw_goal_rad, double t0_s,
                         std::optional<Eigen::Vector2d> start_velocity_mps = std::nullopt);

  // Shortcut test of one segment (support under it + body sweep), exposed for tests.
  bool segment_ok(const map::MapView& view, CollisionChecker& checker, const Eigen::Vector3d& a,
                  const Eigen::Vector3d& b) const;

 private:
  BsplineTrajectory fit(std::span<const Eigen::Vector3d> wp, std::span<const uint8_t> pinned,
                        double yaw_start, std::optional<double> yaw_goal, double t0,
                        const Eigen::Vector2d& v0) const;

  RobotModel robot_;
  TrajectoryOptions opt_;
};

}  // namespace storey::core::plan

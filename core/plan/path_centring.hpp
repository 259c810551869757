#pragma once
// Stage 3 (paper Sec. IV-D) post-processing of a voxel path before the B-spline: each interior
// point closer than half the body length to an obstacle moves (at most max_shift_m) to where its
// clearance is largest, onto observed support: the middle of a door, a stair flight, a corridor.
// The voxel A* clears a point robot by the body's half width; the Go2's 0.8 m long box that follows
// the path at an angle still clips a door jamb or a stair's side-wall end, and then the FCL check
// rejects the trajectory and the frontier behind the passage is set aside for good. Centring first
// lets the body pass straight through passages that are wide enough for it.
#include <cmath>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "core/map/map_view.hpp"

namespace storey::core::plan {

struct PathCentringOptions {
  double max_shift_m = 0.3;  // largest move of one point [m]
  double keep_clear_m = -1;  // clearance that is enough; < 0: half body length + margin [m]
  double sample_m = 0.05;    // candidate grid spacing [m]
};

struct PathCentringStats {
  int moved = 0;  // points moved
  double max_shift_m = 0;
};

// Centres `points` (surface points: x, y, support height) in place; the first and last points
// stay. Obstacles are occupied voxels between one step above the local surface and the body top
// (the FCL checker's ground rule). A moved point must land on support that is traversable,
// under-observed or in C_reach, within a step of its height; otherwise it stays.
PathCentringStats centre_path(const map::MapView& view, std::vector<Eigen::Vector3d>& points,
                              const PathCentringOptions& opt = {});

// A stair flight's axis: the line the body should walk, origin on it near the flight's foot.
struct FlightAxis {
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();
  Eigen::Vector2d dir = Eigen::Vector2d::UnitX();  // unit, direction of travel
  double width_m = INFINITY;                       // between the side walls (inf: open side)
};
// The axis of the flight whose foot is `foot` (support point), travelled within 60 deg of
// `hint` (unit), rising (sign +1) or falling (-1): from the support heights the map holds ahead.
std::optional<FlightAxis> flight_axis(const map::MapView& view, const Eigen::Vector3d& foot,
                                      const Eigen::Vector2d& hint, double sign);

struct FlightShaping {
  int flights = 0;                 // flights re-laid on their axis
  int no_axis = 0, no_run_up = 0;  // flights left as they were, and why
  bool end_on_flight = false;      // the path ends on a flight: hold its axis yaw there
  double end_yaw_rad = 0;
};

// Stairs: the body must meet a flight head-on and stay aligned on it. Where the path changes
// level by more than half a step, the approach within a run-up (half the body length + margin)
// of the flight's foot and the flight itself are replaced by a straight line on the flight's
// axis (flight_axis), starting a run-up before the foot on the lower level: the robot turns on
// flat ground and walks straight up (or down); a turn at the foot swings the 0.8 m box over the
// treads or into the side walls, and an A* path hugging one side wall clips it.
FlightShaping shape_flights(const map::MapView& view, std::vector<Eigen::Vector3d>& points);

// Former name of shape_flights (kept for callers): the number of flights re-laid.
inline int align_before_climbs(const map::MapView& view, std::vector<Eigen::Vector3d>& points) {
  return shape_flights(view, points).flights;
}

// Stage 3's path shaping before the B-spline: shape_flights, then centre_path. Returns the goal
// yaw to use: the flight's axis yaw if the path ends on a flight (turning on a flight swings the
// body into its side walls), else `goal_yaw`.
double shape_path(const map::MapView& view, std::vector<Eigen::Vector3d>& points, double goal_yaw);

}  // namespace storey::core::plan

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

// Where to stand to climb a flight seen from its foot: on its axis, facing up, `back_m` before
// its first riser (or up to run_up_m farther back, where the floor is walkable: the floor just
// before a flight is often unseen), on the level of `floor_z`. The first riser is found from the
// support heights (the first tread a step above floor_z, the floor behind it, a higher tread
// ahead) nearest to one of `near` (a frontier cluster's nodes) within `radius_m`; the axis then
// comes from flight_axis (centred between the side walls), or is the riser's own normal where
// flight_axis disagrees by more than 25 deg. A climb from a frontier's own
// viewpoint fails when it stands 0.8 m or more before the first riser (flight_axis needs treads
// 0.6 and 0.9 m ahead) or off the axis; an A* path onto the first tread meets it diagonally.
struct FlightFoot {
  Eigen::Vector3d foot_m = Eigen::Vector3d::Zero();  // support point to stand on
  double yaw_rad = 0;                                // up the axis
  FlightAxis axis;
  Eigen::Vector3d riser_m = Eigen::Vector3d::Zero();  // middle of the first riser, at the floor
};
// sparse: a riser line whose points' normal is nearer another search direction than the one it
// was found in is found again with each direction's neighbours counted in (a flight seen
// sparsely, as the return flight of a U-shaped stair from its landing; off elsewhere: more
// feet found on the office's floors cost it 57-158 s, session 24).
std::optional<FlightFoot> flight_foot(const map::MapView& view,
                                      const std::vector<Eigen::Vector3d>& near, double floor_z,
                                      double back_m = 0.45, double radius_m = 1.5,
                                      double run_up_m = 1.0, bool sparse = false);

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

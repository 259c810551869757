#pragma once
// Stage 3 (paper Sec. IV-D) post-processing of a voxel path before the B-spline: each interior
// point closer than half the body length to an obstacle moves (at most max_shift_m) to where its
// clearance is largest, onto observed support: the middle of a door, a stair flight, a corridor.
// The voxel A* clears a point robot by the body's half width; the Go2's 0.8 m long box that follows
// the path at an angle still clips a door jamb or a stair's side-wall end, and then the FCL check
// rejects the trajectory and the frontier behind the passage is set aside for good. Centring first
// lets the body pass straight through passages that are wide enough for it.
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

// Stairs: the body must meet a flight head-on. Before the first point where the path starts to
// climb or descend (a height change of more than half a step within the next climb_look_m), the
// path gets a straight run-up of half the body length + margin along the flight's direction:
// the points within that distance before the flight are replaced by one point on its axis, so
// the robot turns on flat ground and walks straight onto the first tread (a turn at the foot of
// the flight swings the 0.8 m box over the treads or into the side walls). Returns the number of
// run-ups inserted; a run-up point without support or with an obstacle within half the body
// width is not inserted.
int align_before_climbs(const map::MapView& view, std::vector<Eigen::Vector3d>& points,
                        double climb_look_m = 0.6);

}  // namespace storey::core::plan

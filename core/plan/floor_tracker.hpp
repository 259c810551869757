#pragma once
// Floors of the building as the macro layer sees them (paper Sec. IV, IV-A): which floor the
// robot stands on, each floor's height, the inter-floor height dz and the reference floor.
//
// Floor change: the robot's support height leaves the current floor by more than
// floor_change_dz_m (a stair or ramp transition) and then stays within stable_band_m of one
// height for stable_s while it walks stable_travel_m away (horizontally) from where it came
// within that band; the robot is then on the known floor within floor_change_dz_m / 2 of that
// height, or on a new floor. Heights between floors never start a floor: on stairs the height
// does not stay put, and on a ramp it cannot stay in the band over stable_travel_m (slopes
// steeper than atan(stable_band_m / stable_travel_m), 2.3 deg by default; zigzagging across a
// 1.5 m wide 5 deg ramp got through a 0.12 m / 1.5 m window), even where the robot stands still
// mid-ramp for a while (it used to start a floor there).
// Nodes are labelled by the floor whose height is nearest their support height, within
// node_band_m (else -1: stairs, ramps, unknown floors). A floor's height is refined from its
// nodes within max_refine_shift_m of the robot's height on that floor: the mode of their
// support heights (histogram of mode_bin_m), mean of that bin (without the anchor the band
// followed the mode up a ramp once most of a floor's nodes were gone: Maze's floor 0 drifted to
// 1.41 m and the prior for floor 1 was built with dz 1.59 m).
// dz(ref, target) = difference of the two modes. The reference floor for a target floor is the
// most completely explored adjacent floor (nearest below or above).
#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

namespace storey::core::plan {

struct FloorTrackerOptions {
  double floor_change_dz_m = 1.5;    // support height change that means another floor
  double stable_s = 2.0;             // the new height must hold this long
  double stable_band_m = 0.08;       // ... within this band
  double stable_travel_m = 2.0;      // ... while the robot walks this far (horizontal) in it
  double node_band_m = 0.6;          // nodes within this of a floor's height belong to it
  double mode_bin_m = 0.1;           // histogram bin of the height mode
  int min_mode_nodes = 10;           // fewer nodes: keep the robot-derived height
  double max_refine_shift_m = 0.25;  // the mode moves a floor at most this far from where the
                                     // robot stood on it
};

struct Floor {
  int32_t id = -1;
  double z_m = 0;           // support height (robot's when created, then the node mode)
  double entered_s = 0;     // first time the robot was on it
  bool explored = false;    // no work left on it when last checked (set by the planner)
  double open_ratio = 1.0;  // frontier nodes / nodes when last checked (0 = fully explored)
  int nodes = 0;            // nodes labelled with this floor when last refined
  double anchor_z_m = 0;    // the robot's support height when the floor was created
};

class FloorTracker {
 public:
  explicit FloorTracker(const FloorTrackerOptions& opt = {}) : opt_(opt) {}

  // One planning cycle. Returns true if the robot's floor changed in this call (the first call
  // creates floor 0 and returns true). Non-finite input is ignored (counted).
  bool update(const Eigen::Vector3d& foot_m, double t_s);
  int32_t current() const { return current_; }
  const std::vector<Floor>& floors() const { return floors_; }
  Floor& floor(int32_t id) { return floors_[size_t(id)]; }
  const Floor& floor(int32_t id) const { return floors_[size_t(id)]; }
  bool is_new_floor() const { return changed_to_new_; }  // the last change created a floor
  uint32_t bad_input() const { return bad_input_; }

  // Floor of a support height (-1 if none within node_band_m).
  int32_t floor_of(double z_m) const;
  // Refines every floor's height from the support heights of all nodes (mode per floor).
  void refine(std::span<const float> node_z_m);
  // Estimated inter-floor height target - ref [m].
  double dz(int32_t ref, int32_t target) const {
    return floors_[size_t(target)].z_m - floors_[size_t(ref)].z_m;
  }
  // Reference floor for `target`: among the nearest floors below and above, the explored one,
  // else the one with the lowest open ratio (ties: more nodes, lower id); -1 if none.
  int32_t choose_reference(int32_t target) const;

 private:
  FloorTrackerOptions opt_;
  std::vector<Floor> floors_;
  int32_t current_ = -1;
  bool changed_to_new_ = false;
  bool candidate_ = false;
  double cand_z_ = 0, cand_since_ = 0;
  Eigen::Vector2d cand_xy_ = Eigen::Vector2d::Zero();
  uint32_t bad_input_ = 0;
  std::vector<int> hist_;
};

}  // namespace storey::core::plan

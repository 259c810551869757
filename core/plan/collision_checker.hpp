#pragma once
// Collision checks of the robot body against the map with FCL (paper Sec. IV-D Stage 3; DESIGN
// §3 control look-ahead). FCL is used as a broad-phase manager of voxel boxes
// (fcl::DynamicAABBTreeCollisionManagerd, one fcl::Boxd per occupied voxel, all sharing one
// geometry) queried with the body box; FCL's OcTree is not used (it would need octomap in core).
//
// Body: an oriented box (RobotModel length x width + 2 * margin, height body_height + margin),
// rotated by yaw and by the pitch of the terrain along the path (nose up when climbing), its
// bottom face centred on the support point of the pose (support height h).
// Ground rule: an occupied voxel whose surface point (voxel centre x, y at the mean height of its
// points; the centre for voxel lists without statistics) lies less than step_height_m above the
// body's bottom face (body frame; on flat ground: z < h + step_height_m) is
// ground the legs stand on or step over (floor, stair treads, curbs), not an obstacle; every
// other occupied voxel overlapping the box is a collision. Pitching with the slope is what lets
// stairs pass: a 30 deg flight rises 0.23 m within the body's half length.
// Sweeps are sampled at a spacing <= max_sample_spacing_m() = half the box's smallest dimension,
// so consecutive boxes overlap by at least half and no voxel fits between two samples.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "core/map/map_view.hpp"
#include "core/robot_model.hpp"

namespace storey::core::plan {

// A pose of the body: the point on the support surface under the body centre, and the yaw.
struct BodyPose {
  Eigen::Vector3d foot_m = Eigen::Vector3d::Zero();  // support point (z = support height h) [m]
  double yaw_rad = 0;
  double pitch_rad = 0;  // terrain pitch along the heading, nose up > 0 (atan(dz / ds))
  double t_s = 0;        // time along the trajectory [s] (reported back on a hit)
};

struct CollisionOptions {
  double sample_spacing_m = 0;  // 0 = max_sample_spacing_m(); larger values are clamped to it
  double chunk_extent_m = 3.0;  // samples are grouped so each group's voxel box stays this small
  // Map surface heights are point means in 0.1 m voxels: a 0.167 m stair riser reads up to a
  // few cm higher at a nosing. Obstacles start this far above the step height (the graph's
  // surface_tolerance_m plays the same role for its edges).
  double ground_tolerance_m = 0.03;
};

struct CollisionHit {
  bool collides = false;
  size_t sample = 0;                                  // index of the first colliding pose
  double t_s = 0;                                     // its time
  Eigen::Vector3d voxel_m = Eigen::Vector3d::Zero();  // centre of a voxel it hits
  uint32_t poses_checked = 0;
  uint32_t voxels_loaded = 0;  // obstacle voxels registered in the broad phase (all chunks)
  bool bad_input = false;      // a non-finite pose: reported as a collision (never "safe")
};

class CollisionChecker {
 public:
  CollisionChecker(const RobotModel& robot, double voxel_size_m,
                   const CollisionOptions& options = {});
  ~CollisionChecker();
  CollisionChecker(const CollisionChecker&) = delete;
  CollisionChecker& operator=(const CollisionChecker&) = delete;

  // Poses against occupied voxels given as centres (tests, callers with their own voxel sets).
  CollisionHit check_poses(std::span<const BodyPose> poses,
                           std::span<const Eigen::Vector3f> voxel_centres_m);
  // Poses against the map: loads the occupied voxels near each chunk of poses from the view.
  // The body's pitch follows the terrain where the map has support under both ends of the body
  // (a legged body stands on a stair flight at the flight's slope, whatever the trajectory's
  // own slope there is, e.g. at rest), its bottom centre no lower than the mean of the two
  // supports (with the front feet on a tread, the rear of the box would otherwise dip into the
  // floor); elsewhere the pose's pitch is kept.
  CollisionHit check_poses(const map::MapView& view, std::span<const BodyPose> poses);
  // Terrain pitch under a pose: support heights half a body length ahead and behind (nearest
  // to the foot height within the slope window; an end without support is taken at the foot's
  // height if the other end is higher); nullopt if neither end has support, or one has and lies
  // no higher than the foot (the pose's own pitch stands), unless that pitch would put the seen
  // end's legs below its support: then the pitch that keeps them on it.
  // `mid_z`: their mean, the height the body's bottom centre rests at on that slope.
  std::optional<double> terrain_pitch(const map::MapView& view, const BodyPose& p,
                                      double* mid_z = nullptr) const;

  // Control look-ahead: the trajectory pose_at(t) sampled over [t_from, t_from + horizon_s] at
  // dt_s (clamped so the body moves at most the sample spacing between samples, at the robot's
  // speed and yaw-rate limits), first hit reported. pose_at: BodyPose(double t).
  template <class PoseAt>
  CollisionHit check_ahead(const map::MapView& view, PoseAt&& pose_at, double t_from,
                           double horizon_s, double dt_s) {
    const double dt = std::min(dt_s > 0 ? dt_s : max_dt_s(), max_dt_s());
    samples_.clear();
    const int n = std::max(1, int(std::ceil(horizon_s / dt - 1e-9)));
    for (int i = 0; i <= n; ++i) {
      const double t = t_from + std::min(horizon_s, i * dt);
      BodyPose p = pose_at(t);
      p.t_s = t;
      samples_.push_back(p);
    }
    return check_poses(view, samples_);
  }
  // The same, on the poses the plan-time check of a trajectory over [t_start, t_end] sampled
  // (t_start + k * max_dt_s(), and t_end): from the last of them at or before t_from to the
  // first at or after t_from + horizon_s. An unchanged map then gives the plan-time answer
  // wherever along the trajectory the check starts (a pose grazing a stair nosing at the ground
  // tolerance passed at plan time and failed half a sample later: the planner kept a trajectory
  // the control look-ahead stopped the robot on, over and over).
  template <class PoseAt>
  CollisionHit check_on_grid(const map::MapView& view, PoseAt&& pose_at, double t_start,
                             double t_end, double t_from, double horizon_s) {
    const double dt = max_dt_s();
    const double span = std::max(0.0, t_end - t_start);
    const double a = std::clamp(t_from - t_start, 0.0, span);
    const double b = std::clamp(a + std::max(0.0, horizon_s), 0.0, span);
    const int k0 = int(std::floor(a / dt + 1e-9));
    const int k1 = int(std::ceil(b / dt - 1e-9));
    samples_.clear();
    for (int k = k0; k <= k1; ++k) {
      const double t = t_start + std::min(span, k * dt);
      BodyPose p = pose_at(t);
      p.t_s = t;
      samples_.push_back(p);
    }
    return check_poses(view, samples_);
  }

  // The straight segment a -> b (support points, z interpolated, pitch of the segment along
  // travel) at the given yaw, or the horizontal direction of travel if yaw_rad is NaN: for path
  // shortcutting. First hit.
  CollisionHit check_segment(const map::MapView& view, const Eigen::Vector3d& a_m,
                             const Eigen::Vector3d& b_m, double yaw_rad);

  double max_sample_spacing_m() const { return max_spacing_m_; }
  // Largest time step keeping samples within the spacing at the robot's limits [s].
  double max_dt_s() const;
  const Eigen::Vector3d& box_size_m() const { return box_m_; }
  const RobotModel& robot() const { return robot_; }

 private:
  struct Impl;
  bool collide_one(const BodyPose& p, Eigen::Vector3d* voxel);
  void load_voxels(std::span<const map::MapView::VoxelExtent> voxels, double ground_below_z);
  // World z below which a voxel centre is ground for pose p wherever it is under the body.
  double ground_floor_z(const BodyPose& p) const;

  RobotModel robot_;
  CollisionOptions opt_;
  double voxel_m_;
  Eigen::Vector3d box_m_;
  double max_spacing_m_;
  std::unique_ptr<Impl> impl_;
  std::vector<BodyPose> samples_;
  std::vector<BodyPose> adjusted_;
  std::vector<map::MapView::VoxelExtent> extents_;
};

}  // namespace storey::core::plan

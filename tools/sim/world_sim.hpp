// In-process lockstep simulation (DESIGN §5): a world, a Go2-like robot and a LiDAR on a
// virtual clock. step(dt, cmd) advances time; take_scan() hands over the latest complete sweep.
// Deterministic: the same scene, options and command sequence give the same bytes.
#pragma once

#include <deque>
#include <memory>
#include <optional>

#include "tools/sim/lidar_model.hpp"
#include "tools/sim/ray_caster.hpp"
#include "tools/sim/robot_model.hpp"
#include "tools/sim/scene.hpp"

namespace storey::tools::sim {

struct SimOptions {
  LidarOptions lidar;  // lidar.seed is derived from `seed`
  RobotOptions robot;  // robot.seed is derived from `seed`
  uint64_t seed = 1;
  std::optional<StartPose> start;  // default: the scene's start pose (required then)
};

class WorldSim {
 public:
  // Throws std::runtime_error when no start pose is known or the options are invalid.
  WorldSim(const Scene& scene, const SimOptions& options);
  // Advance virtual time by dt [s] with the command held constant. Completed sweeps become
  // available to take_scan(); a sweep not taken before the next completes is counted dropped.
  void step(double dt, const VelocityCommand& cmd);
  // The latest complete sweep, once (empty when none completed since the last call).
  std::optional<LidarScan> take_scan();
  const RobotState& robot_state() const { return robot_->state(); }
  const Odometry& odometry() const { return robot_->odometry(); }
  double time() const { return robot_->state().t; }
  std::size_t scans_completed() const { return scans_completed_; }
  std::size_t scans_dropped() const { return scans_dropped_; }
  const RayCaster& ray_caster() const { return *caster_; }
  const LidarModel& lidar() const { return *lidar_; }

 private:
  Eigen::Isometry3d pose_at(double t) const;  // interpolated body pose history

  std::unique_ptr<RayCaster> caster_;
  std::unique_ptr<RobotModel> robot_;
  std::unique_ptr<LidarModel> lidar_;
  struct Stamped {
    double t;
    Eigen::Vector3d p;
    Eigen::Quaterniond q;
  };
  std::deque<Stamped> history_;
  double next_scan_start_ = 0.0;
  std::optional<LidarScan> ready_;
  LidarScan spare_;
  std::size_t scans_completed_ = 0, scans_dropped_ = 0;
};

}  // namespace storey::tools::sim

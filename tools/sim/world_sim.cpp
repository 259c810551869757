#include "tools/sim/world_sim.hpp"

#include <stdexcept>

namespace storey::tools::sim {

WorldSim::WorldSim(const Scene& scene, const SimOptions& options) {
  const std::optional<StartPose> start = options.start ? options.start : scene.start;
  if (!start) throw std::runtime_error("world sim: scene '" + scene.name + "' has no start pose");
  caster_ = std::make_unique<RayCaster>(scene.mesh);
  RobotOptions ro = options.robot;
  ro.seed = options.seed * 0x9E3779B97F4A7C15ULL + 1;
  LidarOptions lo = options.lidar;
  lo.seed = options.seed * 0x9E3779B97F4A7C15ULL + 2;
  robot_ = std::make_unique<RobotModel>(*caster_, *start, ro);
  lidar_ = std::make_unique<LidarModel>(*caster_, lo);
  const auto& s = robot_->state();
  const Eigen::Isometry3d T = s.body_pose();
  history_.push_back({s.t, T.translation(), Eigen::Quaterniond(T.linear())});
}

Eigen::Isometry3d WorldSim::pose_at(double t) const {
  // History is sorted by time; interpolate linearly (slerp for attitude), clamp at the ends.
  auto it = std::lower_bound(history_.begin(), history_.end(), t,
                             [](const Stamped& a, double v) { return a.t < v; });
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (it == history_.begin() || it == history_.end()) {
    const Stamped& e = it == history_.end() ? history_.back() : history_.front();
    T.translation() = e.p;
    T.linear() = e.q.toRotationMatrix();
    return T;
  }
  const Stamped& b = *it;
  const Stamped& a = *(it - 1);
  const double u = b.t > a.t ? (t - a.t) / (b.t - a.t) : 0.0;
  T.translation() = a.p + u * (b.p - a.p);
  T.linear() = a.q.slerp(u, b.q).toRotationMatrix();
  return T;
}

void WorldSim::step(double dt, const VelocityCommand& cmd) {
  if (!(dt >= 0.0) || !std::isfinite(dt)) return;
  const double h = robot_->physics_step();
  const double period = lidar_->options().scan_period;
  double remaining = dt;
  while (remaining >= h - 1e-9) {
    robot_->step(h, cmd);
    remaining -= h;
    const auto& s = robot_->state();
    const Eigen::Isometry3d T = s.body_pose();
    history_.push_back({s.t, T.translation(), Eigen::Quaterniond(T.linear())});
    // A sweep is cast once the robot has moved through all of it.
    if (s.t >= next_scan_start_ + period - 1e-9) {
      LidarScan scan = std::move(spare_);
      lidar_->scan(
          next_scan_start_, [this](double tt) { return pose_at(tt); }, scan);
      if (ready_) {
        ++scans_dropped_;
        spare_ = std::move(*ready_);
      }
      ready_ = std::move(scan);
      ++scans_completed_;
      next_scan_start_ += period;
      while (history_.size() > 2 && history_[1].t <= next_scan_start_) history_.pop_front();
    }
  }
  if (remaining > 1e-9) robot_->step(remaining, cmd);  // carried inside the robot model
}

std::optional<LidarScan> WorldSim::take_scan() {
  std::optional<LidarScan> out = std::move(ready_);
  ready_.reset();
  return out;
}

}  // namespace storey::tools::sim

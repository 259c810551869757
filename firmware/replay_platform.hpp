#pragma once
// The platform `storey replay` drives the firmware with: sweeps assembled from recorded packets,
// placed in the world by a fixed sensor pose (a LiDAR-only capture has no odometry: the robot is
// taken to stand at the origin with the configured mounting), and a robot that hears no
// commands. The map, graph and frontier tasks then run exactly as on the robot.
#include <deque>

#include "drivers/lidar/scan_assembler.hpp"
#include "firmware/platform.hpp"

namespace storey::firmware {

class ReplayPlatform final : public Platform, public drivers::lidar::ScanSink {
 public:
  // `sensor_in_world`: sensor pose (sensor frame -> world), `foot_m`: ground under the robot.
  ReplayPlatform(const drivers::lidar::RigidTransform& sensor_in_world,
                 const Eigen::Vector3d& foot_m)
      : sensor_(sensor_in_world), foot_(foot_m) {}

  void set_time(double t_s) { now_s_ = t_s; }
  std::size_t pending() const { return pending_.size(); }

  // ScanSink (the assembler): one sweep, sensor frame -> world frame.
  void on_scan(const drivers::lidar::Scan& scan) override {
    ScanBuffer b;
    b.stamp_s = now_s_;
    b.origin_m = Eigen::Vector3f(sensor_.tx, sensor_.ty, sensor_.tz);
    b.points_m.reserve(scan.points.size());
    for (const drivers::lidar::LidarPoint& p : scan.points) {
      float x = p.x, y = p.y, z = p.z;
      sensor_.apply(x, y, z);
      b.points_m.emplace_back(x, y, z);
    }
    pending_.push_back(std::move(b));
  }

  // Platform (the firmware's tasks).
  bool take_scan(ScanBuffer& out) override {
    if (pending_.empty()) return false;
    out.stamp_s = pending_.front().stamp_s;
    out.origin_m = pending_.front().origin_m;
    out.points_m.assign(pending_.front().points_m.begin(), pending_.front().points_m.end());
    pending_.pop_front();
    return true;
  }
  bool latest_pose(PoseSample& out) override {
    out = PoseSample{};
    out.stamp_s = now_s_;
    out.x_m = foot_.x(), out.y_m = foot_.y(), out.z_m = foot_.z();
    return true;
  }
  void send_command(const VelocityCommand&) override {}
  LinkHealth link() override { return {true, now_s_}; }

 private:
  drivers::lidar::RigidTransform sensor_;
  Eigen::Vector3d foot_;
  double now_s_ = 0;
  std::deque<ScanBuffer> pending_;
};

}  // namespace storey::firmware

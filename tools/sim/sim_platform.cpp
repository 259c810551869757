#include "tools/sim/sim_platform.hpp"

namespace storey::tools::sim {

bool SimPlatform::take_scan(firmware::ScanBuffer& out) {
  std::optional<LidarScan> s = sim_.take_scan();
  if (!s || lidar_silent_) return false;
  out.stamp_s = s->t_end;
  // The map takes one origin per sweep: the sensor at the end of the sweep (the robot moves
  // at most ~0.1 m during a 10 Hz sweep; the points themselves are exact in the world frame).
  out.origin_m = s->origins_world.empty() ? s->sensor_pose_start.translation().cast<float>()
                                          : s->origins_world.back();
  out.points_m.assign(s->points_world.begin(), s->points_world.end());
  return true;
}

bool SimPlatform::latest_pose(firmware::PoseSample& out) {
  if (pose_frozen_) {
    if (frozen_.stamp_s < 0) return false;
    out = frozen_;
    return true;
  }
  const Odometry& o = sim_.odometry();
  out.stamp_s = o.t;
  out.x_m = o.position.x();
  out.y_m = o.position.y();
  out.z_m = o.position.z();
  out.yaw_rad = o.yaw;
  out.vx_mps = o.velocity.x();
  out.vy_mps = o.velocity.y();
  out.yaw_rate_rps = o.velocity.z();
  frozen_ = out;
  return true;
}

void SimPlatform::send_command(const firmware::VelocityCommand& cmd) {
  if (link_down_) return;
  fw_cmd_ = cmd;
  cmd_.vx = cmd.vx_mps;
  cmd_.vy = cmd.vy_mps;
  cmd_.yaw_rate = cmd.yaw_rate_rps;
  ++commands_;
}

firmware::LinkHealth SimPlatform::link() {
  firmware::LinkHealth h;
  h.connected = !link_down_;
  h.last_state_s = link_down_ ? frozen_link_s_ : sim_.time();
  if (!link_down_) frozen_link_s_ = sim_.time();
  return h;
}

}  // namespace storey::tools::sim

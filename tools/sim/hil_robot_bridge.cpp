#include "tools/sim/hil_robot_bridge.hpp"

#include <cmath>

namespace storey::tools::sim {

namespace go2 = storey::drivers::go2;

HilRobotBridge::HilRobotBridge(const HilRobotBridgeOptions& options, int64_t now_ns)
    : opt_(options) {
  opt_.standin.integrate = false;  // the world sim moves the robot, not the stand-in
  standin_ = std::make_unique<go2::RobotStandin>(opt_.standin, now_ns);
  standin_->set_integrate(false);
  standin_->on_command = [this](const go2::StandinCommand& c) { on_command(c); };
}

void HilRobotBridge::on_command(const go2::StandinCommand& c) {
  switch (c.kind) {
    case go2::StandinCommand::Kind::velocity: {
      const auto& v = c.velocity;
      if (!std::isfinite(v.vx) || !std::isfinite(v.vy) || !std::isfinite(v.yaw_rate)) return;
      velocity_ = v;
      velocity_rx_ns_ = c.rx_ns;
      have_velocity_ = true;
      break;
    }
    case go2::StandinCommand::Kind::mode:
      have_velocity_ = false;  // every mode request ends the current motion (sport API)
      switch (c.mode.mode) {
        case go2::ModeRequest::stop:
          break;
        case go2::ModeRequest::balance_stand:
        case go2::ModeRequest::stand_up:
          posture_ = Posture::standing;
          break;
        case go2::ModeRequest::stand_down:
          posture_ = Posture::lying;
          break;
        case go2::ModeRequest::damp:
          posture_ = Posture::damping;
          break;
      }
      break;
    case go2::StandinCommand::Kind::heartbeat:
      break;
  }
}

go2::RobotState HilRobotBridge::to_link_state(const RobotState& s, const Odometry& odom) const {
  go2::RobotState m;
  // Attitude: yaw from odometry (it drifts with it), pitch/roll from the IMU (true).
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(odom.yaw, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(s.pitch, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(s.roll, Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
  const Eigen::Vector3d centre = odom.position + R * Eigen::Vector3d(0, 0, opt_.body_height);
  const Eigen::Quaterniond q(R);
  const double c = std::cos(odom.yaw), sn = std::sin(odom.yaw);
  for (int i = 0; i < 3; ++i) m.position[i] = float(centre[i]);
  // Velocity in the odometry frame, as the Go2's sport state reports it.
  m.velocity = {float(c * odom.velocity.x() - sn * odom.velocity.y()),
                float(sn * odom.velocity.x() + c * odom.velocity.y()), 0.0f};
  m.yaw_speed = float(odom.velocity.z());
  m.body_height = float(opt_.body_height);
  m.quaternion = {float(q.w()), float(q.x()), float(q.y()), float(q.z())};
  m.rpy = {float(s.roll), float(s.pitch), float(odom.yaw)};
  m.gyro = {0.0f, 0.0f, float(s.velocity.z())};
  // Specific force of a body at rest: gravity seen in the body frame.
  const Eigen::Vector3d g = R.transpose() * Eigen::Vector3d(0, 0, 9.81);
  m.accel = {float(g.x()), float(g.y()), float(g.z())};
  switch (posture_) {
    case Posture::standing:
      m.mode = uint8_t(moving_ ? go2::RobotModeId::locomotion : go2::RobotModeId::balance_stand);
      m.gait = uint8_t(moving_ ? go2::GaitId::trot : go2::GaitId::idle);
      m.foot_force = {120, 120, 120, 120};
      break;
    case Posture::lying:
      m.mode = uint8_t(go2::RobotModeId::lie_down);
      break;
    case Posture::damping:
      m.mode = uint8_t(go2::RobotModeId::damping);
      break;
  }
  m.battery_voltage = 28.8f;
  m.battery_current = moving_ ? 4.0f : 1.5f;
  m.battery_soc = 90;
  return m;
}

VelocityCommand HilRobotBridge::step(const RobotState& s, const Odometry& odom, int64_t now_ns) {
  standin_->set_state(to_link_state(s, odom));
  standin_->step(now_ns);  // publishes when due, then calls on_command for each arrival
  VelocityCommand cmd;
  if (have_velocity_ && now_ns - velocity_rx_ns_ > opt_.command_timeout_ns) {
    have_velocity_ = false;  // the commander went quiet: stop, as the Go2 does
    ++timeouts_;
  }
  if (have_velocity_ && posture_ == Posture::standing) {
    cmd.vx = velocity_.vx;
    cmd.vy = velocity_.vy;
    cmd.yaw_rate = velocity_.yaw_rate;
  }
  moving_ = cmd.vx != 0.0 || cmd.vy != 0.0 || cmd.yaw_rate != 0.0 ||
            s.velocity.head<2>().norm() > 0.02 || std::abs(s.velocity.z()) > 0.02;
  return cmd;
}

}  // namespace storey::tools::sim

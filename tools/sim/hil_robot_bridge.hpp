// The robot's side of the Go2 link for hardware-in-the-loop: drivers/go2's RobotStandin (the
// very codecs and channels the firmware's links use, in the robot role) publishes the simulated
// robot's state and hands over the commands it receives; this bridge turns them into the sim
// robot's velocity command. As on the real Go2, a velocity command holds until the next one or
// until `command_timeout_ns` passes without one (then the robot stops); StopMove / BalanceStand /
// StandUp end the motion, StandDown and Damp lay the robot down until it is stood up again.
// Single-threaded: the HIL loop calls step() once per loop step.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "drivers/go2/robot_standin.hpp"
#include "tools/sim/robot_model.hpp"

namespace storey::tools::sim {

struct HilRobotBridgeOptions {
  drivers::go2::StandinOptions standin;  // transport, addresses, state period; integrate unused
  int64_t command_timeout_ns = 500'000'000;
  // Published body frame = the Go2's: origin at the body centre, this far above the sim robot's
  // ground point [m] (also reported as body_height).
  double body_height = 0.32;
};

class HilRobotBridge {
 public:
  HilRobotBridge(const HilRobotBridgeOptions& options, int64_t now_ns);
  bool ok() const { return standin_->ok(); }
  const char* error() const { return standin_->error(); }
  uint16_t local_port() const { return standin_->local_port(); }

  // Publishes (when due) the state of `s`/`odom` stamped now_ns on the robot's clock, drains the
  // received commands and returns the body velocity the robot must follow from now on.
  VelocityCommand step(const RobotState& s, const Odometry& odom, int64_t now_ns);

  // The link message for a sim state (exposed for tests).
  drivers::go2::RobotState to_link_state(const RobotState& s, const Odometry& odom) const;

  uint64_t velocity_commands() const { return standin_->velocity_commands(); }
  uint64_t mode_commands() const { return standin_->mode_commands(); }
  uint64_t heartbeats() const { return standin_->heartbeats(); }
  uint64_t dropped() const { return standin_->dropped(); }
  uint64_t timeouts() const { return timeouts_; }  // motion stopped for lack of commands

 private:
  enum class Posture : uint8_t { standing, lying, damping };
  void on_command(const drivers::go2::StandinCommand& c);

  HilRobotBridgeOptions opt_;
  std::unique_ptr<drivers::go2::RobotStandin> standin_;
  Posture posture_ = Posture::standing;
  bool have_velocity_ = false;
  drivers::go2::VelocityCommand velocity_;
  int64_t velocity_rx_ns_ = 0;
  bool moving_ = false;
  uint64_t timeouts_ = 0;
};

}  // namespace storey::tools::sim

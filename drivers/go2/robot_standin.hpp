// Robot stand-in: the robot's side of every Go2 link transport (DDS, UDP, CAN-over-UDP), for
// tests, benchmarks and hardware-in-the-loop (storey-sim drives it). It publishes a state it is
// given (set_state) or integrates the commanded body velocity itself (a kinematic unicycle on a
// plane), and receives and records velocity and mode commands. Single-threaded: the owner calls
// step(now) periodically; nothing blocks.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "drivers/go2/can_channel.hpp"
#include "drivers/go2/dds_config.hpp"
#include "drivers/go2/dds_link.hpp"
#include "drivers/go2/robot_messages.hpp"
#include "drivers/go2/udp_channel.hpp"

namespace storey::drivers::go2 {

enum class StandinTransport : uint8_t { dds, udp, can_over_udp };

struct StandinOptions {
  StandinTransport transport = StandinTransport::udp;
  // DDS: network configuration and topic names (as the real robot: domain 0, rt/...).
  DdsNetworkOptions dds;
  DdsTopics topics;
  // UDP and CAN-over-UDP: where the stand-in listens, and where the host is (port 0: answer
  // whoever sent the last valid frame).
  UdpEndpoint local{"127.0.0.1", 17001};
  UdpEndpoint host{"127.0.0.1", 0};
  CanChannelOptions can;
  int64_t state_period_ns = 10'000'000;       // publish state at 100 Hz
  int64_t heartbeat_period_ns = 100'000'000;  // UDP/CAN heartbeat
  // Integrating mode: a velocity command older than this (by receipt) is replaced by zero, as
  // a robot must stop when its commander goes quiet.
  int64_t command_timeout_ns = 500'000'000;
  bool integrate = true;  // false: publish the state given by set_state()
};

// One received command, as the robot saw it.
struct StandinCommand {
  enum class Kind : uint8_t { velocity, mode, heartbeat } kind = Kind::velocity;
  VelocityCommand velocity;
  ModeCommand mode;
  Heartbeat heartbeat;
  uint32_t sequence = 0;  // framed transports; 0 for DDS
  int64_t rx_ns = 0;      // receipt time, caller's clock
};

// Transport-specific part of the stand-in.
class StandinEndpoint {
 public:
  virtual ~StandinEndpoint() = default;
  virtual bool ok() const = 0;
  virtual const char* error() const = 0;
  // Next received command; false when none is pending. Malformed input is counted in `dropped`.
  virtual bool receive(StandinCommand& out, uint64_t& dropped) = 0;
  virtual bool publish_state(const RobotState& s, int64_t now_ns) = 0;
  virtual bool publish_heartbeat(const Heartbeat& h, int64_t now_ns) { return true; }
  virtual uint16_t local_port() const { return 0; }
};

class RobotStandin {
 public:
  RobotStandin(const StandinOptions& options, int64_t now_ns);
  ~RobotStandin();

  bool ok() const;
  const char* error() const;
  // UDP port the stand-in listens on (UDP transports; useful with local.port = 0).
  uint16_t local_port() const { return endpoint_ ? endpoint_->local_port() : 0; }

  // Switches to publishing `s` (integration off); its stamp is replaced by the publish time.
  void set_state(const RobotState& s);
  void set_integrate(bool on) { options_.integrate = on; }

  // Drains commands, integrates, publishes state/heartbeat when due. Returns commands received.
  int step(int64_t now_ns);
  // Publishes the current state now, regardless of the period.
  bool publish_now(int64_t now_ns);

  const RobotState& state() const { return state_; }
  uint64_t velocity_commands() const { return velocity_commands_; }
  uint64_t mode_commands() const { return mode_commands_; }
  uint64_t heartbeats() const { return heartbeats_; }
  uint64_t dropped() const { return dropped_; }
  const StandinCommand& last_velocity() const { return last_velocity_; }
  const StandinCommand& last_mode() const { return last_mode_; }

  // Called for every received command (tests, benchmarks, simulator bridge).
  std::function<void(const StandinCommand&)> on_command;

 private:
  void apply(const StandinCommand& c);
  void integrate(int64_t now_ns);

  StandinOptions options_;
  std::unique_ptr<StandinEndpoint> endpoint_;
  RobotState state_;
  StandinCommand last_velocity_;
  StandinCommand last_mode_;
  bool have_velocity_ = false;
  float yaw_ = 0.0f;
  int64_t last_integrate_ns_ = 0;
  int64_t next_state_ns_ = 0;
  int64_t next_heartbeat_ns_ = 0;
  uint32_t heartbeat_counter_ = 0;
  uint64_t velocity_commands_ = 0;
  uint64_t mode_commands_ = 0;
  uint64_t heartbeats_ = 0;
  uint64_t dropped_ = 0;
};

}  // namespace storey::drivers::go2

// RobotLink over a MessageChannel: the firmware side of the UDP, CAN and CAN-over-UDP links.
// State frames update latest_state(); commands are stamped with a per-type sequence number and
// the publish time; a host heartbeat goes out from poll() every heartbeat_period_ns.
#pragma once

#include <memory>
#include <string>

#include "drivers/can/can_transport.hpp"
#include "drivers/go2/can_channel.hpp"
#include "drivers/go2/link_monitor.hpp"
#include "drivers/go2/message_channel.hpp"
#include "drivers/go2/udp_channel.hpp"

namespace storey::drivers::go2 {

class FramedLink : public RobotLink {
 public:
  FramedLink(const char* name, std::unique_ptr<MessageChannel> channel, const LinkOptions& options,
             int64_t now_ns);

  bool ok() const override { return channel_->ok(); }
  const char* error() const override { return channel_->error(); }
  const char* name() const override { return name_.c_str(); }
  int poll(int64_t now_ns) override;
  const RobotState& latest_state() const override { return state_; }
  bool has_state() const override { return have_state_; }
  LinkStatus send_velocity(const VelocityCommand& cmd, int64_t now_ns) override;
  LinkStatus send_mode(const ModeCommand& cmd, int64_t now_ns) override;
  LinkHealth health(int64_t now_ns) override;

  const Heartbeat& last_robot_heartbeat() const { return robot_heartbeat_; }
  MessageChannel& channel() { return *channel_; }

 private:
  LinkStatus send_message(MsgType type, const uint8_t* payload, size_t len, int64_t now_ns);

  std::string name_;
  std::unique_ptr<MessageChannel> channel_;
  LinkMonitor monitor_;
  RobotState state_;
  bool have_state_ = false;
  Heartbeat robot_heartbeat_;
  uint32_t tx_seq_[8] = {};
  uint32_t heartbeat_counter_ = 0;
  int64_t next_heartbeat_ns_ = 0;
};

// Go2 UDP link (framing in udp_frame.hpp, README "UDP wire format").
class UdpLink final : public FramedLink {
 public:
  UdpLink(const UdpEndpoint& local, const UdpEndpoint& robot, const LinkOptions& options,
          int64_t now_ns);
};

// Go2 CAN link over any CAN transport (SocketCanTransport on the robot).
class CanLink : public FramedLink {
 public:
  CanLink(std::unique_ptr<can::CanTransport> transport, const CanChannelOptions& can_options,
          const LinkOptions& options, int64_t now_ns, const char* name = "can");
};

// The CAN link's framing carried over UDP (can/can_over_udp_transport.hpp).
class CanOverUdpLink final : public CanLink {
 public:
  CanOverUdpLink(const UdpEndpoint& local, const UdpEndpoint& robot,
                 const CanChannelOptions& can_options, const LinkOptions& options, int64_t now_ns);
};

}  // namespace storey::drivers::go2

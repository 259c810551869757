#include "drivers/go2/framed_link.hpp"

#include <cmath>

#include "drivers/can/can_over_udp_transport.hpp"

namespace storey::drivers::go2 {

FramedLink::FramedLink(const char* name, std::unique_ptr<MessageChannel> channel,
                       const LinkOptions& options, int64_t now_ns)
    : name_(name),
      channel_(std::move(channel)),
      monitor_(options, now_ns),
      next_heartbeat_ns_(now_ns) {}

int FramedLink::poll(int64_t now_ns) {
  int states = 0;
  ChannelMessage m;
  LinkHealth& h = monitor_.counters();
  // Bounded drain: a flood cannot keep the control task here forever.
  for (int i = 0; i < 256; ++i) {
    const RxStatus r = channel_->receive(m);
    if (r == RxStatus::empty || r == RxStatus::transport_error) break;
    if (r == RxStatus::crc_error) {
      ++h.crc_failures;
      continue;
    }
    if (r == RxStatus::decode_error || r == RxStatus::wrong_direction) {
      ++h.decode_errors;
      continue;
    }
    const MsgType type = static_cast<MsgType>(m.header.type);
    if (type == MsgType::state) {
      RobotState s;
      if (decode_state(m.payload, m.payload_len, s) != PayloadError::ok) {
        ++h.decode_errors;
        continue;
      }
      if (!monitor_.accept_sequence(LinkMonitor::Stream::state, m.header.sequence)) continue;
      s.rx_stamp_ns = now_ns;
      state_ = s;
      have_state_ = true;
      monitor_.on_state(now_ns);
      ++states;
    } else if (type == MsgType::heartbeat) {
      Heartbeat hb;
      if (decode_heartbeat(m.payload, m.payload_len, hb) != PayloadError::ok) {
        ++h.decode_errors;
        continue;
      }
      if (!monitor_.accept_sequence(LinkMonitor::Stream::heartbeat, m.header.sequence)) continue;
      robot_heartbeat_ = hb;
      monitor_.on_heartbeat(now_ns);
    } else {
      ++h.decode_errors;  // a command type arriving at the host
    }
  }
  if (now_ns >= next_heartbeat_ns_) {
    next_heartbeat_ns_ = now_ns + monitor_.options().heartbeat_period_ns;
    Heartbeat hb;
    hb.stamp_ns = now_ns;
    hb.counter = heartbeat_counter_++;
    hb.status = monitor_.update(now_ns).link_lost ? 1 : 0;
    uint8_t p[kHeartbeatPayloadSize];
    encode_heartbeat(hb, p);
    if (send_message(MsgType::heartbeat, p, sizeof(p), now_ns) != LinkStatus::ok) {
      ++h.send_errors;
    }
  }
  monitor_.update(now_ns);
  return states;
}

LinkStatus FramedLink::send_message(MsgType type, const uint8_t* payload, size_t len,
                                    int64_t now_ns) {
  FrameHeader fh;
  fh.type = static_cast<uint8_t>(type);
  fh.sequence = tx_seq_[fh.type & 7u]++;
  fh.timestamp_ns = now_ns;
  return channel_->send(fh, payload, len);
}

LinkStatus FramedLink::send_velocity(const VelocityCommand& cmd, int64_t now_ns) {
  if (!ok()) return LinkStatus::not_open;
  const bool finite = std::isfinite(cmd.vx) && std::isfinite(cmd.vy) && std::isfinite(cmd.yaw_rate);
  const LinkStatus c = monitor_.check_command(cmd.stamp_ns, now_ns, finite);
  if (c != LinkStatus::ok) return c;
  uint8_t p[kVelocityPayloadSize];
  encode_velocity(cmd, p);
  const LinkStatus s = send_message(MsgType::velocity_command, p, sizeof(p), now_ns);
  LinkHealth& h = monitor_.counters();
  s == LinkStatus::ok ? ++h.commands_sent : ++h.send_errors;
  return s;
}

LinkStatus FramedLink::send_mode(const ModeCommand& cmd, int64_t now_ns) {
  if (!ok()) return LinkStatus::not_open;
  const bool valid = static_cast<uint8_t>(cmd.mode) < kModeRequestCount;
  const LinkStatus c = monitor_.check_command(cmd.stamp_ns, now_ns, valid);
  if (c != LinkStatus::ok) return c;
  uint8_t p[kModePayloadSize];
  encode_mode(cmd, p);
  const LinkStatus s = send_message(MsgType::mode_command, p, sizeof(p), now_ns);
  LinkHealth& h = monitor_.counters();
  s == LinkStatus::ok ? ++h.commands_sent : ++h.send_errors;
  return s;
}

LinkHealth FramedLink::health(int64_t now_ns) {
  LinkHealth h = monitor_.update(now_ns);
  channel_->add_transport_health(h);
  return h;
}

UdpLink::UdpLink(const UdpEndpoint& local, const UdpEndpoint& robot, const LinkOptions& options,
                 int64_t now_ns)
    : FramedLink("udp", std::make_unique<UdpChannel>(Role::host, local, robot), options, now_ns) {}

CanLink::CanLink(std::unique_ptr<can::CanTransport> transport, const CanChannelOptions& can_options,
                 const LinkOptions& options, int64_t now_ns, const char* name)
    : FramedLink(name, std::make_unique<CanChannel>(Role::host, std::move(transport), can_options),
                 options, now_ns) {}

CanOverUdpLink::CanOverUdpLink(const UdpEndpoint& local, const UdpEndpoint& robot,
                               const CanChannelOptions& can_options, const LinkOptions& options,
                               int64_t now_ns)
    : CanLink(std::make_unique<can::CanOverUdpTransport>(local, robot), can_options, options,
              now_ns, "can-over-udp") {}

}  // namespace storey::drivers::go2

#include "drivers/go2/can_channel.hpp"

#include <cstring>

namespace storey::drivers::go2 {

namespace {
constexpr MsgType kTypes[] = {MsgType::state, MsgType::velocity_command, MsgType::mode_command,
                              MsgType::heartbeat};
}

uint32_t can_id_for(const CanChannelOptions& o, Role sender, MsgType type) {
  return o.base_id + (sender == Role::robot ? 0x10u : 0x00u) + static_cast<uint32_t>(type);
}

CanChannel::CanChannel(Role role, std::unique_ptr<can::CanTransport> transport,
                       const CanChannelOptions& options)
    : role_(role), transport_(std::move(transport)), options_(options) {
  const Role peer = role == Role::host ? Role::robot : Role::host;
  can::CanFilter filters[4];
  int n = 0;
  for (MsgType t : kTypes) {
    // Register what the peer sends: commands+heartbeat to the robot, state+heartbeat to us.
    const bool peer_sends = peer == Role::robot ? (t == MsgType::state || t == MsgType::heartbeat)
                                                : (t != MsgType::state);
    if (!peer_sends) continue;
    const uint32_t id = can_id_for(options_, peer, t);
    reassembler_.add_stream(id, kCanBodyHeader + payload_size(static_cast<uint8_t>(t)));
    filters[n++] = can::CanFilter{id, can::kCanSffMask | can::kCanEffFlag | can::kCanRtrFlag};
  }
  if (transport_ && transport_->ok()) transport_->set_filters(filters, n);
}

const char* CanChannel::error() const {
  return transport_ ? transport_->error() : "no CAN transport";
}

LinkStatus CanChannel::send(const FrameHeader& h, const uint8_t* payload, size_t len) {
  if (!ok()) return LinkStatus::not_open;
  uint8_t body[kCanBodyHeader + kMaxPayloadSize];
  put_u32(body, h.sequence);
  put_u64(body + 4, static_cast<uint64_t>(h.timestamp_ns));
  std::memcpy(body + kCanBodyHeader, payload, len);
  can::CanFrame frames[can::kMaxFramesPerTransfer];
  const uint32_t id = can_id_for(options_, role_, static_cast<MsgType>(h.type));
  uint8_t& counter = counter_[h.type & 7u];
  const size_t n = can::encode_transfer(id, body, kCanBodyHeader + len, counter++, options_.fd,
                                        frames, can::kMaxFramesPerTransfer);
  if (n == 0) return LinkStatus::invalid_command;
  for (size_t i = 0; i < n; ++i) {
    switch (transport_->send(frames[i])) {
      case can::CanIoStatus::ok:
        break;
      case can::CanIoStatus::would_block:
        return LinkStatus::would_block;
      default:
        return LinkStatus::send_failed;
    }
  }
  return LinkStatus::ok;
}

RxStatus CanChannel::receive(ChannelMessage& out) {
  can::CanFrame f;
  for (;;) {
    switch (transport_->receive(f)) {
      case can::CanIoStatus::ok:
        break;
      case can::CanIoStatus::empty:
        return RxStatus::empty;
      case can::CanIoStatus::malformed:
        return RxStatus::decode_error;
      default:
        return RxStatus::transport_error;
    }
    switch (reassembler_.push(f)) {
      case can::CanReassembler::Result::in_progress:
        continue;
      case can::CanReassembler::Result::unknown_id:
        return RxStatus::wrong_direction;
      case can::CanReassembler::Result::bad_frame:
        return RxStatus::decode_error;
      case can::CanReassembler::Result::bad_crc:
        return RxStatus::crc_error;
      case can::CanReassembler::Result::complete:
        break;
    }
    const uint8_t* b = reassembler_.body();
    const uint32_t type = (reassembler_.last_id() - options_.base_id) & 0x0Fu;
    out.header.type = static_cast<uint8_t>(type);
    out.header.flags = role_ == Role::host ? kFlagFromRobot : 0;
    out.header.sequence = get_u32(b);
    out.header.timestamp_ns = static_cast<int64_t>(get_u64(b + 4));
    out.payload_len = reassembler_.body_len() - kCanBodyHeader;
    std::memcpy(out.payload, b + kCanBodyHeader, out.payload_len);
    return RxStatus::message;
  }
}

void CanChannel::add_transport_health(LinkHealth& h) const {
  if (!transport_) return;
  const can::CanTransportStats s = transport_->stats();
  h.rx_overflow_drops += s.rx_overflow_drops;
  h.bus_errors += s.error_frames;
  h.bus_off_events += s.bus_off_events;
  h.transport_reopens += s.reopens;
}

}  // namespace storey::drivers::go2

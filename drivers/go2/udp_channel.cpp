#include "drivers/go2/udp_channel.hpp"

#include <cstring>

namespace storey::drivers::go2 {

UdpChannel::UdpChannel(Role role, const UdpEndpoint& local, const UdpEndpoint& remote)
    : role_(role) {
  socket_.open(local, remote);
}

LinkStatus UdpChannel::send(const FrameHeader& h, const uint8_t* payload, size_t len) {
  if (!socket_.is_open()) return LinkStatus::not_open;
  FrameHeader hh = h;
  hh.flags = role_ == Role::robot ? kFlagFromRobot : 0;
  uint8_t buf[kUdpMaxFrameSize];
  const size_t n = encode_udp_frame(hh, payload, len, buf);
  switch (socket_.send(buf, n)) {
    case can::UdpSocket::Io::ok:
      return LinkStatus::ok;
    case can::UdpSocket::Io::would_block:
      return LinkStatus::would_block;
    default:
      return LinkStatus::send_failed;
  }
}

RxStatus UdpChannel::receive(ChannelMessage& out) {
  uint8_t buf[kUdpMaxFrameSize + 1];
  size_t n = 0;
  switch (socket_.receive(buf, kUdpMaxFrameSize, n)) {
    case can::UdpSocket::Io::ok:
      break;
    case can::UdpSocket::Io::empty:
      return RxStatus::empty;
    default:
      return RxStatus::transport_error;
  }
  const uint8_t* payload = nullptr;
  size_t len = 0;
  const FrameError e = decode_udp_frame(buf, n, out.header, payload, len);
  if (e == FrameError::bad_crc) return RxStatus::crc_error;
  if (e != FrameError::ok) return RxStatus::decode_error;
  const bool from_robot = (out.header.flags & kFlagFromRobot) != 0;
  if (from_robot == (role_ == Role::robot)) return RxStatus::wrong_direction;
  std::memcpy(out.payload, payload, len);
  out.payload_len = len;
  socket_.adopt_last_sender();
  return RxStatus::message;
}

}  // namespace storey::drivers::go2

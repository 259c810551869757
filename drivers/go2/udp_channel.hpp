// MessageChannel over UDP: one frame (udp_frame.hpp) per datagram, non-blocking socket.
#pragma once

#include "drivers/can/udp_socket.hpp"
#include "drivers/go2/message_channel.hpp"

namespace storey::drivers::go2 {

using can::UdpEndpoint;

class UdpChannel final : public MessageChannel {
 public:
  // remote.port 0: send to the sender of the last valid frame (robot side).
  UdpChannel(Role role, const UdpEndpoint& local, const UdpEndpoint& remote);
  bool ok() const override { return socket_.is_open(); }
  const char* error() const override { return socket_.error().c_str(); }
  LinkStatus send(const FrameHeader& h, const uint8_t* payload, size_t len) override;
  RxStatus receive(ChannelMessage& out) override;
  uint16_t local_port() const override { return socket_.local_port(); }

 private:
  Role role_;
  can::UdpSocket socket_;
};

}  // namespace storey::drivers::go2

// CAN over UDP: each datagram carries one frame in its SocketCAN byte layout (16 bytes for a
// classic frame, 72 for FD; see can_frame.hpp). Lets the CAN framing run end to end where the
// kernel has no CAN (this machine) and in hardware-in-the-loop with storey-sim.
#pragma once

#include <array>

#include "drivers/can/can_transport.hpp"
#include "drivers/can/udp_socket.hpp"

namespace storey::drivers::can {

class CanOverUdpTransport final : public CanTransport {
 public:
  // remote.port 0: reply to whoever sent the last valid frame (robot side).
  CanOverUdpTransport(const UdpEndpoint& local, const UdpEndpoint& remote);

  bool ok() const override { return socket_.is_open(); }
  const char* error() const override { return socket_.error().c_str(); }
  bool set_filters(const CanFilter* filters, int n) override;
  CanIoStatus send(const CanFrame& f) override;
  CanIoStatus receive(CanFrame& f) override;
  CanTransportStats stats() const override { return stats_; }
  uint16_t local_port() const override { return socket_.local_port(); }

  static constexpr int kMaxFilters = 16;

 private:
  bool passes(uint32_t id) const;

  UdpSocket socket_;
  std::array<CanFilter, kMaxFilters> filters_{};
  int n_filters_ = 0;
  CanTransportStats stats_;
};

}  // namespace storey::drivers::can

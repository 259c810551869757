// A CAN bus as seen by a link: send and receive frames without blocking. Implementations:
// SocketCanTransport (Linux AF_CAN raw socket) and CanOverUdpTransport (one frame per UDP
// datagram, for tests and hardware-in-the-loop without a kernel CAN module).
#pragma once

#include <cstdint>

#include "drivers/can/can_frame.hpp"

namespace storey::drivers::can {

enum class CanIoStatus : uint8_t {
  ok = 0,       // a frame was sent / received
  empty,        // nothing to receive
  would_block,  // transmit queue full
  bus_off,      // controller is bus-off; waiting for restart / reopen
  error,        // socket error (see error())
  malformed,    // received something that is not a frame (counted, dropped)
};

struct CanTransportStats {
  uint64_t frames_sent = 0;
  uint64_t frames_received = 0;
  uint64_t rx_overflow_drops = 0;  // SO_RXQ_OVFL: frames the kernel dropped for us
  uint64_t error_frames = 0;       // CAN_ERR_FLAG frames
  uint64_t bus_off_events = 0;
  uint64_t reopens = 0;    // socket re-created during bus-off recovery
  uint64_t malformed = 0;  // datagrams / reads that were not a frame
  uint64_t send_errors = 0;
};

// One id filter: a frame passes if (frame.id & mask) == (id & mask), as CAN_RAW_FILTER.
struct CanFilter {
  uint32_t id = 0;
  uint32_t mask = 0;
};

class CanTransport {
 public:
  virtual ~CanTransport() = default;
  virtual bool ok() const = 0;
  virtual const char* error() const = 0;
  // Accept only frames matching one of the filters (max 16); an empty list accepts all.
  virtual bool set_filters(const CanFilter* filters, int n) = 0;
  virtual CanIoStatus send(const CanFrame& f) = 0;
  // Non-blocking: ok (frame filled), empty, bus_off, error or malformed.
  virtual CanIoStatus receive(CanFrame& f) = 0;
  virtual CanTransportStats stats() const = 0;
  // Bound UDP port for UDP-based transports (tests bind port 0); 0 otherwise.
  virtual uint16_t local_port() const { return 0; }
};

}  // namespace storey::drivers::can

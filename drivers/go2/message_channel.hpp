// A framed message pipe carrying the Go2 link's messages (header + payload, see
// message_codec.hpp) over one transport: UDP datagrams (UdpChannel) or CAN multi-frame transfers
// (CanChannel). Both the firmware side (FramedLink) and the robot stand-in use it, each in its
// role, so encoder and decoder are the same code (ArduPilot SITL habit).
#pragma once

#include <cstddef>
#include <cstdint>

#include "drivers/go2/message_codec.hpp"
#include "drivers/go2/robot_link.hpp"
#include "drivers/go2/udp_frame.hpp"

namespace storey::drivers::go2 {

enum class Role : uint8_t { host, robot };

struct ChannelMessage {
  FrameHeader header;
  uint8_t payload[kMaxPayloadSize];
  size_t payload_len = 0;
};

enum class RxStatus : uint8_t {
  message,          // `out` holds a message whose payload length matches its type
  empty,            // nothing more to read now
  crc_error,        // dropped: CRC mismatch
  decode_error,     // dropped: malformed frame / transfer / datagram
  wrong_direction,  // dropped: a message our own role sends (looped back or misrouted)
  transport_error,
};

class MessageChannel {
 public:
  virtual ~MessageChannel() = default;
  virtual bool ok() const = 0;
  virtual const char* error() const = 0;
  // Sends one message; the channel stamps direction from its role.
  virtual LinkStatus send(const FrameHeader& h, const uint8_t* payload, size_t len) = 0;
  // Non-blocking; call until `empty`.
  virtual RxStatus receive(ChannelMessage& out) = 0;
  // Adds transport counters (kernel drops, bus errors, reopens) into `h`.
  virtual void add_transport_health(LinkHealth& h) const { (void)h; }
  // Bound UDP port where the transport is UDP-based (tests bind port 0); 0 otherwise.
  virtual uint16_t local_port() const { return 0; }
};

}  // namespace storey::drivers::go2

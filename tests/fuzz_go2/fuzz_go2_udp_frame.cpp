// libFuzzer target: the Go2 UDP-link frame decoder and payload decoders (drivers/go2/udp_frame,
// message_codec). Raw input is decoded as a datagram; the same bytes also drive a valid frame
// (type and payload from the input) with one mutated byte, to reach past the CRC check.
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "drivers/go2/message_codec.hpp"
#include "drivers/go2/udp_frame.hpp"

using namespace storey::drivers::go2;

namespace {
void decode_payload(uint8_t type, const uint8_t* p, size_t n) {
  RobotState s;
  VelocityCommand v;
  ModeCommand m;
  Heartbeat h;
  switch (static_cast<MsgType>(type)) {
    case MsgType::state:
      decode_state(p, n, s);
      break;
    case MsgType::velocity_command:
      decode_velocity(p, n, v);
      break;
    case MsgType::mode_command:
      decode_mode(p, n, m);
      break;
    case MsgType::heartbeat:
      decode_heartbeat(p, n, h);
      break;
  }
}

void decode(const uint8_t* data, size_t size) {
  FrameHeader h;
  const uint8_t* payload = nullptr;
  size_t len = 0;
  if (decode_udp_frame(data, size, h, payload, len) == FrameError::ok) {
    if (len != payload_size(h.type)) __builtin_trap();  // decoder contract
    decode_payload(h.type, payload, len);
  }
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  decode(data, size);
  if (size < 3) return 0;
  // Structure-aware half: a valid frame built from the input, then one byte changed.
  FrameHeader h;
  h.type = static_cast<uint8_t>(1 + data[0] % 4);
  h.sequence = data[1];
  const size_t n = payload_size(h.type);
  uint8_t payload[kMaxPayloadSize] = {};
  std::memcpy(payload, data + 3, size - 3 < n ? size - 3 : n);
  uint8_t frame[kUdpMaxFrameSize];
  const size_t fn = encode_udp_frame(h, payload, n, frame);
  FrameHeader d;
  const uint8_t* p = nullptr;
  size_t len = 0;
  if (decode_udp_frame(frame, fn, d, p, len) != FrameError::ok) __builtin_trap();  // round trip
  decode_payload(d.type, p, len);
  frame[data[2] % fn] ^= static_cast<uint8_t>(data[1] | 1);
  decode(frame, fn);
  decode(frame, data[2] % (fn + 1));  // truncated
  return 0;
}

// Byte layout of the Go2 link's message payloads, shared by the UDP and CAN links (the same
// payload bytes travel in a UDP frame or in a CAN multi-frame transfer). Little endian, packed,
// fixed size per type; the layouts are documented byte by byte in drivers/go2/README.md.
// Dependency-free (std only): the fuzz targets compile this file standalone.
#pragma once

#include <cstddef>
#include <cstdint>

#include "drivers/go2/robot_messages.hpp"

namespace storey::drivers::go2 {

enum class MsgType : uint8_t {
  state = 1,             // robot -> host
  velocity_command = 2,  // host -> robot
  mode_command = 3,      // host -> robot
  heartbeat = 4,         // both ways
};

inline constexpr size_t kStatePayloadSize = 116;
inline constexpr size_t kVelocityPayloadSize = 20;
inline constexpr size_t kModePayloadSize = 9;
inline constexpr size_t kHeartbeatPayloadSize = 13;
inline constexpr size_t kMaxPayloadSize = kStatePayloadSize;

// Payload size for a message type; 0 for an unknown type.
size_t payload_size(uint8_t type);

enum class PayloadError : uint8_t {
  ok = 0,
  wrong_size,  // payload length does not match the type
  non_finite,  // NaN/Inf in a float field
  bad_enum,    // mode request out of range
  unknown_type,
};
const char* to_string(PayloadError e);

// Encoders write exactly the type's payload size into `out` (caller provides the room).
void encode_state(const RobotState& s, uint8_t* out);
void encode_velocity(const VelocityCommand& c, uint8_t* out);
void encode_mode(const ModeCommand& c, uint8_t* out);
void encode_heartbeat(const Heartbeat& h, uint8_t* out);

// Decoders validate length, finiteness and ranges; on error `out` is left unspecified.
PayloadError decode_state(const uint8_t* in, size_t len, RobotState& out);
PayloadError decode_velocity(const uint8_t* in, size_t len, VelocityCommand& out);
PayloadError decode_mode(const uint8_t* in, size_t len, ModeCommand& out);
PayloadError decode_heartbeat(const uint8_t* in, size_t len, Heartbeat& out);

// Little-endian helpers (the host may be either endianness; the wire is little endian).
inline void put_u16(uint8_t* p, uint16_t v) {
  p[0] = static_cast<uint8_t>(v);
  p[1] = static_cast<uint8_t>(v >> 8);
}
inline void put_u32(uint8_t* p, uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<uint8_t>(v >> (8 * i));
}
inline void put_u64(uint8_t* p, uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = static_cast<uint8_t>(v >> (8 * i));
}
inline uint16_t get_u16(const uint8_t* p) {
  return static_cast<uint16_t>(p[0] | (static_cast<uint16_t>(p[1]) << 8));
}
inline uint32_t get_u32(const uint8_t* p) {
  uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= static_cast<uint32_t>(p[i]) << (8 * i);
  return v;
}
inline uint64_t get_u64(const uint8_t* p) {
  uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= static_cast<uint64_t>(p[i]) << (8 * i);
  return v;
}

}  // namespace storey::drivers::go2

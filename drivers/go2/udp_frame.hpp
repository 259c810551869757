// Framing of the Go2 UDP link: one message per datagram.
//   [0]  magic 0x53 'S'   [1] magic 0x47 'G'   [2] version (1)   [3] msg type
//   [4]  flags (bit 0: sent by the robot)      [5] reserved (0)   [6..7] payload length u16
//   [8..11] sequence u32 (per sender and type)  [12..19] publish timestamp u64 ns
//   [20..20+n) payload   [20+n..24+n) CRC-32 (zlib) over bytes [0, 20+n)
// Little endian. Dependency-free (std only) so that the fuzz target compiles it standalone.
#pragma once

#include <cstddef>
#include <cstdint>

#include "drivers/go2/message_codec.hpp"

namespace storey::drivers::go2 {

inline constexpr uint8_t kUdpMagic0 = 0x53;
inline constexpr uint8_t kUdpMagic1 = 0x47;
inline constexpr uint8_t kUdpVersion = 1;
inline constexpr size_t kUdpHeaderSize = 20;
inline constexpr size_t kUdpCrcSize = 4;
inline constexpr size_t kUdpMaxFrameSize = kUdpHeaderSize + kMaxPayloadSize + kUdpCrcSize;
inline constexpr uint8_t kFlagFromRobot = 0x01;

struct FrameHeader {
  uint8_t type = 0;
  uint8_t flags = 0;
  uint32_t sequence = 0;
  int64_t timestamp_ns = 0;  // when the frame was published, sender's clock
};

enum class FrameError : uint8_t {
  ok = 0,
  too_short,  // fewer bytes than header + CRC
  bad_magic,
  bad_version,
  bad_length,  // payload length field disagrees with the datagram size or the type
  bad_crc,
  unknown_type,
};
const char* to_string(FrameError e);

// Writes header + payload + CRC into out (room for kUdpMaxFrameSize). Returns the frame size.
size_t encode_udp_frame(const FrameHeader& h, const uint8_t* payload, size_t payload_len,
                        uint8_t* out);

// Validates a datagram; on ok, `payload` points into `data` and `payload_len` is set. The
// payload itself is not decoded here (see message_codec.hpp).
FrameError decode_udp_frame(const uint8_t* data, size_t len, FrameHeader& h,
                            const uint8_t*& payload, size_t& payload_len);

}  // namespace storey::drivers::go2

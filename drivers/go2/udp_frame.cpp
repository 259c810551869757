#include "drivers/go2/udp_frame.hpp"

#include <cstring>

#include "drivers/crc.hpp"

namespace storey::drivers::go2 {

const char* to_string(FrameError e) {
  switch (e) {
    case FrameError::ok:
      return "ok";
    case FrameError::too_short:
      return "frame shorter than header + CRC";
    case FrameError::bad_magic:
      return "bad magic";
    case FrameError::bad_version:
      return "unsupported version";
    case FrameError::bad_length:
      return "payload length field does not match";
    case FrameError::bad_crc:
      return "CRC-32 mismatch";
    case FrameError::unknown_type:
      return "unknown message type";
  }
  return "unknown";
}

size_t encode_udp_frame(const FrameHeader& h, const uint8_t* payload, size_t payload_len,
                        uint8_t* out) {
  out[0] = kUdpMagic0;
  out[1] = kUdpMagic1;
  out[2] = kUdpVersion;
  out[3] = h.type;
  out[4] = h.flags;
  out[5] = 0;
  put_u16(out + 6, static_cast<uint16_t>(payload_len));
  put_u32(out + 8, h.sequence);
  put_u64(out + 12, static_cast<uint64_t>(h.timestamp_ns));
  if (payload_len > 0) std::memcpy(out + kUdpHeaderSize, payload, payload_len);
  const size_t n = kUdpHeaderSize + payload_len;
  put_u32(out + n, crc32_zlib({out, n}));
  return n + kUdpCrcSize;
}

FrameError decode_udp_frame(const uint8_t* data, size_t len, FrameHeader& h,
                            const uint8_t*& payload, size_t& payload_len) {
  if (len < kUdpHeaderSize + kUdpCrcSize) return FrameError::too_short;
  if (data[0] != kUdpMagic0 || data[1] != kUdpMagic1) return FrameError::bad_magic;
  if (data[2] != kUdpVersion) return FrameError::bad_version;
  const size_t n = get_u16(data + 6);
  if (kUdpHeaderSize + n + kUdpCrcSize != len) return FrameError::bad_length;
  // CRC before interpreting the type: a corrupted type byte is a CRC failure, not a decode error.
  if (crc32_zlib({data, kUdpHeaderSize + n}) != get_u32(data + kUdpHeaderSize + n)) {
    return FrameError::bad_crc;
  }
  const size_t expected = payload_size(data[3]);
  if (expected == 0) return FrameError::unknown_type;
  if (expected != n) return FrameError::bad_length;
  h.type = data[3];
  h.flags = data[4];
  h.sequence = get_u32(data + 8);
  h.timestamp_ns = static_cast<int64_t>(get_u64(data + 12));
  payload = data + kUdpHeaderSize;
  payload_len = n;
  return FrameError::ok;
}

}  // namespace storey::drivers::go2

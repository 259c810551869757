#include "drivers/can/can_frame.hpp"

#include <cstring>

namespace storey::drivers::can {
namespace {
constexpr uint8_t kFdSizes[] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 16, 20, 24, 32, 48, 64};
}

size_t canfd_round_len(size_t n) {
  for (uint8_t s : kFdSizes) {
    if (s >= n) return s;
  }
  return 64;
}

bool canfd_valid_len(size_t n) {
  for (uint8_t s : kFdSizes) {
    if (s == n) return true;
  }
  return false;
}

size_t encode_can_datagram(const CanFrame& f, uint8_t* out) {
  const size_t size = f.fd ? kCanFdDatagram : kCanClassicDatagram;
  std::memset(out, 0, size);
  for (int i = 0; i < 4; ++i) out[i] = static_cast<uint8_t>(f.id >> (8 * i));
  out[4] = f.len;
  if (f.fd) out[5] = f.flags;
  const size_t cap = f.fd ? 64 : 8;
  std::memcpy(out + 8, f.data.data(), f.len <= cap ? f.len : cap);
  return size;
}

CanDatagramError decode_can_datagram(const uint8_t* data, size_t n, CanFrame& f) {
  if (n != kCanClassicDatagram && n != kCanFdDatagram) return CanDatagramError::bad_size;
  f.fd = n == kCanFdDatagram;
  f.id = static_cast<uint32_t>(data[0]) | (static_cast<uint32_t>(data[1]) << 8) |
         (static_cast<uint32_t>(data[2]) << 16) | (static_cast<uint32_t>(data[3]) << 24);
  f.len = data[4];
  f.flags = f.fd ? data[5] : 0;
  if (f.fd ? !canfd_valid_len(f.len) : f.len > 8) return CanDatagramError::bad_len;
  std::memcpy(f.data.data(), data + 8, f.len);
  return CanDatagramError::ok;
}

}  // namespace storey::drivers::can

// CAN frame value type and its CAN-over-UDP byte form. Dependency-free (std only): the fuzz
// target compiles it standalone. Layout of the datagram mirrors Linux <linux/can.h>:
//   classic: struct can_frame,    16 bytes: id u32 | len u8 | pad | res0 | len8_dlc | data[8]
//   FD:      struct canfd_frame,  72 bytes: id u32 | len u8 | flags u8 | res0 | res1 | data[64]
// with the id little endian on the wire (Linux uses host order; x86/ARM hosts are LE anyway).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace storey::drivers::can {

inline constexpr uint32_t kCanEffFlag = 0x80000000u;  // 29-bit extended id
inline constexpr uint32_t kCanRtrFlag = 0x40000000u;  // remote request
inline constexpr uint32_t kCanErrFlag = 0x20000000u;  // error frame (SocketCAN only)
inline constexpr uint32_t kCanSffMask = 0x000007FFu;
inline constexpr uint32_t kCanEffMask = 0x1FFFFFFFu;
inline constexpr uint8_t kCanFdBrs = 0x01;  // bit-rate switch
inline constexpr uint8_t kCanFdEsi = 0x02;  // error state indicator
inline constexpr size_t kCanClassicDatagram = 16;
inline constexpr size_t kCanFdDatagram = 72;

struct CanFrame {
  uint32_t id = 0;    // with kCanEffFlag / kCanRtrFlag / kCanErrFlag as in SocketCAN
  uint8_t len = 0;    // payload bytes: 0..8 classic, one of 0..8,12,16,20,24,32,48,64 FD
  uint8_t flags = 0;  // FD flags (BRS, ESI)
  bool fd = false;
  std::array<uint8_t, 64> data{};
};

// Smallest valid CAN FD payload size >= n (n <= 64).
size_t canfd_round_len(size_t n);
bool canfd_valid_len(size_t n);

// Writes the datagram form of f (16 or 72 bytes) into out; returns its size.
size_t encode_can_datagram(const CanFrame& f, uint8_t* out);

enum class CanDatagramError : uint8_t { ok = 0, bad_size, bad_len };
// Parses a CAN-over-UDP datagram; the size tells classic (16) from FD (72).
CanDatagramError decode_can_datagram(const uint8_t* data, size_t n, CanFrame& f);

}  // namespace storey::drivers::can

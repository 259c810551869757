#pragma once
// Common output types of the LiDAR decoders: one point layout for every sensor, and the reasons a
// packet can be refused. Decoders write into caller-provided buffers (no allocation).
#include <array>
#include <cstddef>
#include <cstdint>

namespace storey::drivers::lidar {

// One return in the sensor frame. 24 bytes so a packet's worth (384 VLP-16 returns) is 9 KiB.
struct LidarPoint {
  float x = 0.f, y = 0.f, z = 0.f;  // [m] sensor frame (Velodyne: x right, y forward, z up)
  float intensity = 0.f;            // reflectivity byte as a float (0..255)
  int32_t time_offset_ns = 0;       // [ns] after the packet's timestamp
  uint16_t ring = 0;                // VLP-16: laser index sorted by elevation (0 = -15 deg)
  uint8_t return_index = 0;         // 0 single/last, 1 strongest (dual return)
  uint8_t tag = 0;                  // Livox tag bits (confidence classes), 0 for Velodyne
};
static_assert(sizeof(LidarPoint) == 24);

// Why a packet was refused. Every refusal is counted; a refused packet yields no points.
enum class DropReason : uint8_t {
  none = 0,
  short_packet,      // fewer bytes than the header/format needs
  bad_size,          // size not what the format fixes (VLP-16: 1206/512) or longer than declared
  bad_flag,          // VLP-16 block flag is not 0xFFEE
  bad_azimuth,       // azimuth >= 360.00 deg or an impossible jump between blocks
  bad_return_mode,   // VLP-16 factory byte not 0x37/0x38/0x39
  bad_dual_pair,     // dual-return blocks of a pair with different azimuths
  bad_version,       // Livox header version != 0
  bad_length,        // Livox length field disagrees with the datagram or the dot count
  unknown_type,      // Livox data type not 0..3, or unexpected port/size
  bad_crc,           // Livox CRC-32 present and wrong
  buffer_too_small,  // caller's point buffer cannot hold a whole packet
  wrong_source,      // datagram from an address other than the configured sensor
  queue_full,        // consumer queue full, chunk dropped
  count_
};
inline constexpr std::size_t kDropReasonCount = static_cast<std::size_t>(DropReason::count_);

const char* to_string(DropReason r);

// Plain counters owned by one thread (the ingesting one); read by others only via snapshots.
struct DropCounters {
  std::array<uint64_t, kDropReasonCount> by_reason{};
  void add(DropReason r) { ++by_reason[static_cast<std::size_t>(r)]; }
  uint64_t operator[](DropReason r) const { return by_reason[static_cast<std::size_t>(r)]; }
  uint64_t total() const {
    uint64_t t = 0;
    for (std::size_t i = 1; i < kDropReasonCount; ++i) t += by_reason[i];
    return t;
  }
};

}  // namespace storey::drivers::lidar

#pragma once
// Livox Mid-360 point and IMU packets (Livox SDK2 protocol, `LivoxLidarEthernetPacket` of
// include/livox_lidar_def.h). One set of packed structs serves the decoder and the encoder.
// Depends on the standard library only (the fuzz targets build this file alone).
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <span>

#include "drivers/lidar/point.hpp"

namespace storey::drivers::lidar {

static_assert(std::endian::native == std::endian::little,
              "wire structs assume a little-endian host");

inline constexpr uint16_t kMid360PointPort = 56300;  // on the sensor
inline constexpr uint16_t kMid360ImuPort = 56400;
inline constexpr uint16_t kMid360HostPointPort = 56301;  // conventional host side
inline constexpr uint16_t kMid360HostImuPort = 56401;
inline constexpr std::size_t kMid360HeaderSize = 36;
inline constexpr std::size_t kMid360MaxPointsPerPacket = 96;
// Offset of the timestamp: the CRC-32 covers timestamp + data.
inline constexpr std::size_t kMid360CrcStart = 28;

enum class Mid360DataType : uint8_t {
  imu = 0,
  cartesian_high = 1,
  cartesian_low = 2,
  spherical = 3
};
enum class Mid360TimeType : uint8_t { none = 0, ptp = 1, gps = 2 };

#pragma pack(push, 1)
struct Mid360Header {
  uint8_t version;         // 0
  uint16_t length;         // whole datagram, header included
  uint16_t time_interval;  // 0.1 us, first to last point of the packet
  uint16_t dot_num;
  uint16_t udp_cnt;  // per stream, restarts at a frame start
  uint8_t frame_cnt;
  uint8_t data_type;  // Mid360DataType
  uint8_t time_type;  // Mid360TimeType
  uint8_t reserved[12];
  uint32_t crc32;      // zlib CRC-32 of timestamp + data; 0 = not filled
  uint64_t timestamp;  // ns, first point
};
struct Mid360CartesianHigh {
  int32_t x, y, z;  // mm
  uint8_t reflectivity, tag;
};
struct Mid360CartesianLow {
  int16_t x, y, z;  // cm
  uint8_t reflectivity, tag;
};
struct Mid360Spherical {
  uint32_t depth;    // mm
  uint16_t zenith;   // 0.01 deg from +z ("theta")
  uint16_t azimuth;  // 0.01 deg from +x toward +y ("phi")
  uint8_t reflectivity, tag;
};
struct Mid360Imu {
  float gyro_x, gyro_y, gyro_z;  // rad/s
  float acc_x, acc_y, acc_z;     // g
};
#pragma pack(pop)
static_assert(sizeof(Mid360Header) == kMid360HeaderSize);
static_assert(offsetof(Mid360Header, crc32) == 24);
static_assert(offsetof(Mid360Header, timestamp) == kMid360CrcStart);
static_assert(sizeof(Mid360CartesianHigh) == 14);
static_assert(sizeof(Mid360CartesianLow) == 8);
static_assert(sizeof(Mid360Spherical) == 10);
static_assert(sizeof(Mid360Imu) == 24);

// Bytes per item of a data type; 0 for types this decoder does not know.
constexpr std::size_t mid360_item_size(uint8_t data_type) {
  switch (data_type) {
    case 0:
      return sizeof(Mid360Imu);
    case 1:
      return sizeof(Mid360CartesianHigh);
    case 2:
      return sizeof(Mid360CartesianLow);
    case 3:
      return sizeof(Mid360Spherical);
    default:
      return 0;
  }
}

struct ImuSample {
  uint64_t timestamp_ns = 0;
  float gyro[3]{};  // rad/s
  float acc[3]{};   // g
  uint8_t time_type = 0;
};

struct Mid360PacketInfo {
  DropReason reason = DropReason::none;
  uint8_t data_type = 0;
  uint8_t time_type = 0;
  uint8_t frame_cnt = 0;
  uint16_t udp_cnt = 0;
  uint64_t timestamp_ns = 0;  // first point
  uint32_t points = 0;        // points written (all-zero returns left out)
  uint32_t lost_before = 0;   // packets missing right before this one (udp_cnt gap)
  bool imu = false;           // an IMU sample was written instead of points
};

// Decoder with per-stream loss accounting. One instance per UDP stream (points, IMU), called by
// one thread; never allocates.
class Mid360Decoder {
 public:
  struct Options {
    bool verify_crc = true;  // check the CRC-32 when the sensor filled it (nonzero)
  };
  Mid360Decoder();
  explicit Mid360Decoder(Options opt);

  // Decodes one datagram. Points go to `out` (needs dot_num capacity, 96 for the Mid-360); an IMU
  // packet fills `imu` if given. A refused packet writes nothing and its reason is counted.
  Mid360PacketInfo decode(std::span<const uint8_t> payload, std::span<LidarPoint> out,
                          ImuSample* imu = nullptr);

  const DropCounters& drops() const { return drops_; }
  uint64_t packets_ok() const { return packets_ok_; }
  uint64_t lost_packets() const { return lost_; }          // inferred from udp_cnt gaps
  uint64_t out_of_order() const { return out_of_order_; }  // udp_cnt went backwards in a frame
  void reset_sequence() { have_last_ = false; }

 private:
  Options opt_;
  DropCounters drops_;
  uint64_t packets_ok_ = 0;
  uint64_t lost_ = 0;
  uint64_t out_of_order_ = 0;
  bool have_last_ = false;
  uint16_t last_udp_cnt_ = 0;
  uint8_t last_frame_cnt_ = 0;
};

// Checks the header and length of a datagram (no CRC, no state). On success fills `hdr`.
DropReason mid360_validate(std::span<const uint8_t> payload, Mid360Header& hdr);
// CRC-32 the packet should carry.
uint32_t mid360_compute_crc(std::span<const uint8_t> packet);

// ---- Encoder (storey-sim, tests) ----
struct Mid360PacketMeta {
  uint64_t timestamp_ns = 0;
  uint16_t time_interval = 0;  // 0.1 us, first to last point
  uint16_t udp_cnt = 0;
  uint8_t frame_cnt = 0;
  uint8_t time_type = 0;
  bool fill_crc = true;
};
// Bytes a packet of `n` items takes.
constexpr std::size_t mid360_packet_size(Mid360DataType t, std::size_t n) {
  return kMid360HeaderSize + n * mid360_item_size(static_cast<uint8_t>(t));
}
// Encodes points (x,y,z [m], intensity -> reflectivity, tag) as the given data type. Returns the
// bytes written, or 0 if `out` is too small, `type` is imu, or there are more than 65535 points.
std::size_t mid360_encode_points(const Mid360PacketMeta& meta, Mid360DataType type,
                                 std::span<const LidarPoint> points, std::span<uint8_t> out);
std::size_t mid360_encode_imu(const Mid360PacketMeta& meta, const ImuSample& imu,
                              std::span<uint8_t> out);

}  // namespace storey::drivers::lidar

#pragma once
// Velodyne VLP-16 wire format: data packets (UDP 2368, 1206 bytes) and position packets (UDP 8308,
// 512 bytes). One set of packed structs serves the decoder and the encoder (storey-sim emits the
// real packets with it). Sources and what was checked against a real capture: README.md here.
// Depends on the standard library only (the fuzz targets build this file alone).
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>

#include "drivers/lidar/point.hpp"

namespace storey::drivers::lidar {

static_assert(std::endian::native == std::endian::little,
              "wire structs assume a little-endian host");

inline constexpr uint16_t kVlp16DataPort = 2368;
inline constexpr uint16_t kVlp16PositionPort = 8308;
inline constexpr std::size_t kVlp16DataPacketSize = 1206;
inline constexpr std::size_t kVlp16PositionPacketSize = 512;
inline constexpr int kVlp16Blocks = 12;
inline constexpr int kVlp16ReturnsPerBlock = 32;  // two firing sequences of 16 lasers
inline constexpr int kVlp16Lasers = 16;
inline constexpr std::size_t kVlp16MaxPointsPerPacket = kVlp16Blocks * kVlp16ReturnsPerBlock;
inline constexpr uint16_t kVlp16BlockFlag = 0xEEFF;    // bytes FF EE on the wire
inline constexpr uint16_t kVlp16AzimuthUnits = 36000;  // 0.01 deg
// Firing timing (VLP-16 manual, section 9.5): lasers every 2.304 us, a 16-laser sequence every
// 55.296 us, so a 2-sequence block spans 110.592 us.
inline constexpr uint32_t kVlp16LaserNs = 2304;
inline constexpr uint32_t kVlp16FiringNs = 55296;
inline constexpr uint32_t kVlp16BlockNs = 2 * kVlp16FiringNs;
inline constexpr float kVlp16DistanceUnitM = 0.002f;
// Largest plausible azimuth step between consecutive blocks: 1200 rpm (the fastest setting) turns
// 79.6 centidegrees per block; anything far beyond that is a corrupt packet, not motion.
inline constexpr uint16_t kVlp16MaxBlockGap = 1000;
// Elevation of laser i in firing order [deg].
inline constexpr std::array<int8_t, 16> kVlp16ElevationDeg{-15, 1, -13, 3,  -11, 5,  -9, 7,
                                                           -7,  9, -5,  11, -3,  13, -1, 15};
// Ring = index by increasing elevation (ring 0 = -15 deg, ring 15 = +15 deg).
constexpr uint16_t vlp16_ring(int laser) {
  return static_cast<uint16_t>((laser % 2 == 0) ? laser / 2 : 8 + laser / 2);
}

enum class Vlp16ReturnMode : uint8_t { strongest = 0x37, last = 0x38, dual = 0x39 };
inline constexpr uint8_t kVlp16ProductVlp16 = 0x22;
inline constexpr uint8_t kVlp16ProductHdl32 = 0x21;  // also sent by some real VLP-16 units

#pragma pack(push, 1)
struct Vlp16Return {
  uint16_t distance;  // 2 mm units, 0 = no return
  uint8_t reflectivity;
};
struct Vlp16Block {
  uint16_t flag;     // 0xEEFF
  uint16_t azimuth;  // 0.01 deg of the block's first firing
  Vlp16Return returns[kVlp16ReturnsPerBlock];
};
struct Vlp16DataPacket {
  Vlp16Block blocks[kVlp16Blocks];
  uint32_t timestamp_us;  // microseconds past the hour, first firing of the packet
  uint8_t return_mode;    // Vlp16ReturnMode
  uint8_t product;        // factory byte; the model comes from the configuration, not from here
};
struct Vlp16PositionPacket {
  uint8_t unused0[198];
  uint32_t timestamp_us;  // microseconds past the hour
  uint8_t pps_status;     // 0 absent, 1 synchronising, 2 locked, 3 error
  uint8_t reserved[3];
  char nmea[128];  // $GPRMC sentence, NUL padded
  uint8_t unused1[178];
};
#pragma pack(pop)
static_assert(sizeof(Vlp16Return) == 3);
static_assert(sizeof(Vlp16Block) == 100);
static_assert(sizeof(Vlp16DataPacket) == kVlp16DataPacketSize);
static_assert(offsetof(Vlp16DataPacket, timestamp_us) == 1200);
static_assert(sizeof(Vlp16PositionPacket) == kVlp16PositionPacketSize);
static_assert(offsetof(Vlp16PositionPacket, timestamp_us) == 198);
static_assert(offsetof(Vlp16PositionPacket, pps_status) == 202);
static_assert(offsetof(Vlp16PositionPacket, nmea) == 206);

// What a decoded data packet said about itself.
struct Vlp16PacketInfo {
  DropReason reason = DropReason::none;
  uint32_t timestamp_us = 0;  // past the hour
  uint8_t return_mode = 0;
  uint8_t product = 0;
  uint32_t points = 0;  // points written (zero-distance returns left out)
};

// One return before conversion to Cartesian, for tests and tools that need the polar values.
struct Vlp16RawReturn {
  uint8_t block, firing, laser;
  uint16_t ring;
  uint16_t azimuth_cdeg;  // interpolated to this firing/laser, 0..35999
  uint16_t distance;      // 2 mm units, nonzero
  uint8_t reflectivity;
  uint8_t return_index;    // 0 single or last, 1 strongest (dual mode, odd block)
  int32_t time_offset_ns;  // from the packet's first firing
};

// Checks a payload and copies it into `pkt`. Returns the reason it is refused, or none.
// `gaps` receives each block's azimuth step to the next firing group [0.01 deg].
DropReason vlp16_validate(std::span<const uint8_t> payload, Vlp16DataPacket& pkt,
                          std::array<uint16_t, kVlp16Blocks>& gaps);

// Visits every nonzero return of a valid packet in packet order (block, firing, laser).
template <class F>
Vlp16PacketInfo vlp16_for_each_return(std::span<const uint8_t> payload, F&& visit) {
  Vlp16DataPacket pkt;
  std::array<uint16_t, kVlp16Blocks> gaps{};
  Vlp16PacketInfo info;
  info.reason = vlp16_validate(payload, pkt, gaps);
  if (info.reason != DropReason::none) return info;
  info.timestamp_us = pkt.timestamp_us;
  info.return_mode = pkt.return_mode;
  info.product = pkt.product;
  const bool dual = pkt.return_mode == static_cast<uint8_t>(Vlp16ReturnMode::dual);
  for (int b = 0; b < kVlp16Blocks; ++b) {
    const Vlp16Block& blk = pkt.blocks[b];
    // Dual mode: blocks 2k and 2k+1 hold the two returns of the same firings.
    const uint32_t slot = static_cast<uint32_t>(dual ? b / 2 : b);
    const uint8_t ret_idx = dual ? static_cast<uint8_t>(b % 2) : 0;
    const uint32_t gap = gaps[b];
    for (int f = 0; f < 2; ++f) {
      for (int l = 0; l < kVlp16Lasers; ++l) {
        const Vlp16Return& r = blk.returns[f * kVlp16Lasers + l];
        if (r.distance == 0) continue;  // no return
        const uint32_t dt = kVlp16FiringNs * f + kVlp16LaserNs * l;
        // Azimuth interpolated over the block's rotation, rounded to 0.01 deg.
        const uint32_t daz = (2 * gap * dt + kVlp16BlockNs) / (2 * kVlp16BlockNs);
        Vlp16RawReturn rr;
        rr.block = static_cast<uint8_t>(b);
        rr.firing = static_cast<uint8_t>(f);
        rr.laser = static_cast<uint8_t>(l);
        rr.ring = vlp16_ring(l);
        rr.azimuth_cdeg = static_cast<uint16_t>((blk.azimuth + daz) % kVlp16AzimuthUnits);
        rr.distance = r.distance;
        rr.reflectivity = r.reflectivity;
        rr.return_index = ret_idx;
        rr.time_offset_ns = static_cast<int32_t>(kVlp16BlockNs * slot + dt);
        visit(rr);
        ++info.points;
      }
    }
  }
  return info;
}

// Decoder of data packets into Cartesian points; keeps packet and drop counters.
// Called by one thread (the ingest task or a replay loop); never allocates.
class Vlp16Decoder {
 public:
  struct Options {
    float min_range_m = 0.0f;  // returns closer than this are left out (0 keeps all nonzero)
  };
  Vlp16Decoder();
  explicit Vlp16Decoder(Options opt);

  // Decodes one 1206-byte payload into `out` (needs kVlp16MaxPointsPerPacket capacity).
  // A refused packet writes no points, and its reason is counted.
  Vlp16PacketInfo decode(std::span<const uint8_t> payload, std::span<LidarPoint> out);

  const DropCounters& drops() const { return drops_; }
  uint64_t packets_ok() const { return packets_ok_; }

 private:
  Options opt_;
  uint32_t min_range_raw_ = 0;
  DropCounters drops_;
  uint64_t packets_ok_ = 0;
};

// Converts polar to the Velodyne convention: x = R cos(w) sin(a), y = R cos(w) cos(a), z = R
// sin(w).
LidarPoint vlp16_to_point(const Vlp16RawReturn& r);

// Position packet (UDP 8308): timestamp, PPS state and the NMEA RMC sentence.
struct NmeaRmc {
  bool present = false;         // a $GPRMC/$GNRMC sentence was found
  bool checksum_ok = false;     // '*hh' present and correct
  bool valid = false;           // status 'A'
  uint32_t time_of_day_ms = 0;  // UTC since midnight
  uint8_t day = 0, month = 0;
  uint16_t year = 0;  // 4 digits, 0 when absent
};
struct Vlp16Position {
  uint32_t timestamp_us = 0;
  uint8_t pps_status = 0;
  NmeaRmc rmc;
};
DropReason vlp16_decode_position(std::span<const uint8_t> payload, Vlp16Position& out);
// Parses an RMC sentence from a NUL-padded buffer (never reads past `text`).
NmeaRmc parse_nmea_rmc(std::span<const char> text);

// Absolute time [ns] of a "microseconds past the hour" stamp: the hour is taken from `reference_ns`
// (host or GNSS time), choosing the candidate nearest to it so that stamps near the hour's turn
// land on the right side.
uint64_t vlp16_absolute_time_ns(uint64_t reference_ns, uint32_t us_past_hour);

// ---- Encoder (storey-sim, tests) ----
// One firing sequence: 16 lasers in firing order.
struct Vlp16Firing {
  uint16_t azimuth_cdeg = 0;        // azimuth of the sequence's first laser, 0..35999
  std::array<float, 16> range_m{};  // <= 0, NaN or beyond 131 m: no return
  std::array<uint8_t, 16> reflectivity{};
};
inline constexpr int kVlp16FiringsPerPacket = 2 * kVlp16Blocks;
// Distance in 2 mm units, 0 (no return) when not representable.
uint16_t vlp16_range_to_raw(float range_m);
// Writes a filled struct; returns bytes written (1206) or 0 if `out` is too small.
std::size_t vlp16_encode(const Vlp16DataPacket& pkt, std::span<uint8_t> out);
// Single-return packet from 24 consecutive firing sequences (block b = sequences 2b, 2b+1; the
// block carries sequence 2b's azimuth, the decoder interpolates the second).
std::size_t vlp16_encode_firings(std::span<const Vlp16Firing, kVlp16FiringsPerPacket> firings,
                                 uint32_t timestamp_us, Vlp16ReturnMode mode, uint8_t product,
                                 std::span<uint8_t> out);
std::size_t vlp16_encode_position(const Vlp16Position& pos, const char* nmea,
                                  std::span<uint8_t> out);

}  // namespace storey::drivers::lidar

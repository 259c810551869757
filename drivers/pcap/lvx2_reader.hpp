#pragma once
// Livox Viewer 2 recordings (.lvx2, "LVX2 Specifications" v1.0 from Livox): a public header
// ("livox_tech", version, magic 0xAC0EA767), a private header (frame duration, device count),
// 63-byte device records, then frames (24-byte header: this frame's offset, the next frame's
// offset, index) of packages (27-byte header + points). Parsed from memory with the standard
// library only (fuzzed alone). Packages convert to SDK2 point datagrams so that replay drives the
// very same Mid360Decoder as live traffic.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace storey::drivers::pcap {

inline constexpr uint32_t kLvx2Magic = 0xAC0EA767;

#pragma pack(push, 1)
struct Lvx2PublicHeader {
  char signature[16];  // "livox_tech", NUL padded
  uint8_t version[4];  // 2.0.0.0
  uint32_t magic;
};
struct Lvx2PrivateHeader {
  uint32_t frame_duration_ms;  // 50
  uint8_t device_count;
};
struct Lvx2DeviceInfo {
  char lidar_sn[16];
  char hub_sn[16];
  uint32_t lidar_id;
  uint8_t lidar_type;   // reserved
  uint8_t device_type;  // 9 = Mid-360
  uint8_t extrinsic_enable;
  float roll, pitch, yaw;  // deg
  float x, y, z;           // m
};
struct Lvx2FrameHeader {
  uint64_t current_offset;  // absolute file offset of this header
  uint64_t next_offset;     // absolute file offset of the next frame
  uint64_t frame_index;
};
struct Lvx2PackageHeader {
  uint8_t version;
  uint32_t lidar_id;
  uint8_t lidar_type;
  uint8_t timestamp_type;
  uint64_t timestamp;  // ns
  uint16_t udp_counter;
  uint8_t data_type;  // 1 cartesian high, 2 cartesian low (SDK2 numbering)
  uint32_t length;    // bytes of point data after this header
  uint8_t frame_counter;
  uint8_t reserved[4];
};
#pragma pack(pop)
static_assert(sizeof(Lvx2PublicHeader) == 24);
static_assert(sizeof(Lvx2PrivateHeader) == 5);
static_assert(sizeof(Lvx2DeviceInfo) == 63);
static_assert(sizeof(Lvx2FrameHeader) == 24);
static_assert(sizeof(Lvx2PackageHeader) == 27);

struct Lvx2Package {
  Lvx2PackageHeader header;
  std::span<const uint8_t> data;  // header.length bytes, points only
  uint64_t frame_index;
};

class Lvx2Reader {
 public:
  // Takes a view of the whole file (see load_file); false with a reason naming the offset.
  bool open(std::span<const uint8_t> file, std::string* error);
  // Next package in file order; false at the end or on a structural error (error() says where).
  bool next(Lvx2Package& out);

  uint32_t frame_duration_ms() const { return priv_.frame_duration_ms; }
  const std::vector<Lvx2DeviceInfo>& devices() const { return devices_; }
  const std::string& error() const { return error_; }
  uint64_t frames() const { return frames_; }

 private:
  bool fail(const std::string& what, std::size_t at);
  std::span<const uint8_t> file_;
  Lvx2PrivateHeader priv_{};
  std::vector<Lvx2DeviceInfo> devices_;
  std::size_t frame_at_ = 0;   // current frame header offset
  std::size_t frame_end_ = 0;  // end of the current frame's packages
  std::size_t pos_ = 0;        // next package
  uint64_t frame_index_ = 0;
  uint64_t frames_ = 0;
  bool in_frame_ = false;
  std::string error_;
};

// Builds the Livox SDK2 datagram a Mid-360 would have sent for this package (header + the same
// point bytes, CRC not filled). `time_interval` [0.1 us] is not recorded in .lvx2; pass the
// sensor's nominal value (Mid-360: 96 points at 200 kHz = 4800). Returns bytes written or 0.
std::size_t lvx2_to_sdk_packet(const Lvx2Package& pkg, uint16_t time_interval,
                               std::span<uint8_t> out);

// Writer for tests and tools: appends to a byte vector.
class Lvx2Writer {
 public:
  explicit Lvx2Writer(std::vector<uint8_t>& out, uint32_t frame_duration_ms = 50);
  void add_device(const Lvx2DeviceInfo& d);  // all devices before the first frame
  void begin_frame();
  // `sdk_packet` is a Mid-360 point datagram (header + points); its header fields are copied.
  bool add_sdk_packet(std::span<const uint8_t> sdk_packet, uint32_t lidar_id);
  void end_frame();

 private:
  void finish_headers();
  std::vector<uint8_t>& out_;
  uint32_t frame_duration_ms_;
  std::vector<Lvx2DeviceInfo> devices_;
  bool headers_done_ = false;
  std::size_t frame_at_ = 0;
  uint64_t frame_index_ = 0;
};

// Reads a whole file into memory (tools/replay only). False with a reason on error.
bool load_file(const std::string& path, std::vector<uint8_t>& out, std::string* error);

}  // namespace storey::drivers::pcap

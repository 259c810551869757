#include "drivers/lidar/mid360.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "drivers/crc.hpp"

namespace storey::drivers::lidar {

namespace {
constexpr double kCdegToRad = 3.14159265358979323846 / 18000.0;

template <class T>
T load(const uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return v;
}
}  // namespace

uint32_t mid360_compute_crc(std::span<const uint8_t> packet) {
  if (packet.size() < kMid360HeaderSize) return 0;
  return crc32_zlib(packet.subspan(kMid360CrcStart));
}

DropReason mid360_validate(std::span<const uint8_t> payload, Mid360Header& hdr) {
  if (payload.size() < kMid360HeaderSize) return DropReason::short_packet;
  std::memcpy(&hdr, payload.data(), kMid360HeaderSize);
  if (hdr.version != 0) return DropReason::bad_version;
  if (hdr.length > payload.size()) return DropReason::short_packet;  // truncated datagram
  if (hdr.length < payload.size()) return DropReason::bad_size;      // trailing bytes
  const std::size_t item = mid360_item_size(hdr.data_type);
  if (item == 0) return DropReason::unknown_type;
  const std::size_t n = hdr.data_type == 0 ? 1 : hdr.dot_num;
  if (kMid360HeaderSize + n * item != hdr.length) return DropReason::bad_length;
  return DropReason::none;
}

Mid360Decoder::Mid360Decoder() : Mid360Decoder(Options{}) {}
Mid360Decoder::Mid360Decoder(Options opt) : opt_(opt) {}

Mid360PacketInfo Mid360Decoder::decode(std::span<const uint8_t> payload, std::span<LidarPoint> out,
                                       ImuSample* imu) {
  Mid360PacketInfo info;
  Mid360Header hdr;
  info.reason = mid360_validate(payload, hdr);
  if (info.reason == DropReason::none && opt_.verify_crc && hdr.crc32 != 0 &&
      mid360_compute_crc(payload) != hdr.crc32) {
    info.reason = DropReason::bad_crc;
  }
  if (info.reason == DropReason::none && hdr.data_type != 0 && hdr.dot_num > out.size()) {
    info.reason = DropReason::buffer_too_small;
  }
  if (info.reason != DropReason::none) {
    drops_.add(info.reason);
    return info;
  }
  info.data_type = hdr.data_type;
  info.time_type = hdr.time_type;
  info.frame_cnt = hdr.frame_cnt;
  info.udp_cnt = hdr.udp_cnt;
  info.timestamp_ns = hdr.timestamp;

  // Loss from udp_cnt: consecutive within a frame; at a new frame it restarts at 0, so the
  // packets missed are those numbered below the first one seen (a sensor whose counter keeps
  // running across frames, i.e. continues with last + 1, is also accepted as no loss).
  if (have_last_) {
    const uint16_t expected = static_cast<uint16_t>(last_udp_cnt_ + 1);
    const uint16_t gap = static_cast<uint16_t>(hdr.udp_cnt - expected);
    if (hdr.frame_cnt == last_frame_cnt_) {
      if (gap < 0x8000) {
        info.lost_before = gap;
      } else {
        ++out_of_order_;
      }
    } else {
      info.lost_before = gap == 0 ? 0u : hdr.udp_cnt;
    }
    lost_ += info.lost_before;
  }
  have_last_ = true;
  last_udp_cnt_ = hdr.udp_cnt;
  last_frame_cnt_ = hdr.frame_cnt;

  const uint8_t* data = payload.data() + kMid360HeaderSize;
  if (hdr.data_type == static_cast<uint8_t>(Mid360DataType::imu)) {
    info.imu = true;
    if (imu != nullptr) {
      const Mid360Imu m = load<Mid360Imu>(data);
      imu->timestamp_ns = hdr.timestamp;
      imu->gyro[0] = m.gyro_x;
      imu->gyro[1] = m.gyro_y;
      imu->gyro[2] = m.gyro_z;
      imu->acc[0] = m.acc_x;
      imu->acc[1] = m.acc_y;
      imu->acc[2] = m.acc_z;
      imu->time_type = hdr.time_type;
    }
    ++packets_ok_;
    return info;
  }

  // Point i is sampled at timestamp + i * time_interval * 100 / dot_num ns (PROTOCOLS.md).
  const uint64_t interval_ns = static_cast<uint64_t>(hdr.time_interval) * 100u;
  const uint32_t n = hdr.dot_num;
  LidarPoint* dst = out.data();
  uint32_t k = 0;
  for (uint32_t i = 0; i < n; ++i) {
    LidarPoint p;
    p.time_offset_ns = static_cast<int32_t>(interval_ns * i / n);
    switch (hdr.data_type) {
      case 1: {
        const auto r = load<Mid360CartesianHigh>(data + i * sizeof(Mid360CartesianHigh));
        if (r.x == 0 && r.y == 0 && r.z == 0) continue;  // no return
        p.x = r.x * 0.001f;
        p.y = r.y * 0.001f;
        p.z = r.z * 0.001f;
        p.intensity = r.reflectivity;
        p.tag = r.tag;
        break;
      }
      case 2: {
        const auto r = load<Mid360CartesianLow>(data + i * sizeof(Mid360CartesianLow));
        if (r.x == 0 && r.y == 0 && r.z == 0) continue;
        p.x = r.x * 0.01f;
        p.y = r.y * 0.01f;
        p.z = r.z * 0.01f;
        p.intensity = r.reflectivity;
        p.tag = r.tag;
        break;
      }
      default: {  // 3, spherical
        const auto r = load<Mid360Spherical>(data + i * sizeof(Mid360Spherical));
        if (r.depth == 0) continue;
        const double d = r.depth * 0.001;
        const double th = r.zenith * kCdegToRad, ph = r.azimuth * kCdegToRad;
        p.x = static_cast<float>(d * std::sin(th) * std::cos(ph));
        p.y = static_cast<float>(d * std::sin(th) * std::sin(ph));
        p.z = static_cast<float>(d * std::cos(th));
        p.intensity = r.reflectivity;
        p.tag = r.tag;
        break;
      }
    }
    dst[k++] = p;
  }
  info.points = k;
  ++packets_ok_;
  return info;
}

// ---- encoder ----

namespace {

Mid360Header make_header(const Mid360PacketMeta& meta, uint8_t type, std::size_t n,
                         std::size_t length) {
  Mid360Header h{};
  h.version = 0;
  h.length = static_cast<uint16_t>(length);
  h.time_interval = meta.time_interval;
  h.dot_num = static_cast<uint16_t>(n);
  h.udp_cnt = meta.udp_cnt;
  h.frame_cnt = meta.frame_cnt;
  h.data_type = type;
  h.time_type = meta.time_type;
  h.crc32 = 0;
  h.timestamp = meta.timestamp_ns;
  return h;
}

template <class T>
T clamp_round(double v) {
  const double lo = static_cast<double>(std::numeric_limits<T>::min());
  const double hi = static_cast<double>(std::numeric_limits<T>::max());
  if (!(v == v)) return 0;  // NaN
  return static_cast<T>(std::clamp(std::round(v), lo, hi));
}

uint8_t refl(float intensity) {
  return clamp_round<uint8_t>(intensity);
}

void finish(const Mid360PacketMeta& meta, std::span<uint8_t> pkt) {
  if (!meta.fill_crc) return;
  uint32_t crc = mid360_compute_crc(pkt);
  if (crc == 0) return;  // 0 means "not filled"; leave it so (one in 2^32)
  std::memcpy(pkt.data() + offsetof(Mid360Header, crc32), &crc, sizeof(crc));
}

}  // namespace

std::size_t mid360_encode_points(const Mid360PacketMeta& meta, Mid360DataType type,
                                 std::span<const LidarPoint> points, std::span<uint8_t> out) {
  if (type == Mid360DataType::imu || points.size() > 65535) return 0;
  const std::size_t len = mid360_packet_size(type, points.size());
  if (len > 65535 || out.size() < len) return 0;
  const Mid360Header h = make_header(meta, static_cast<uint8_t>(type), points.size(), len);
  std::memcpy(out.data(), &h, sizeof(h));
  uint8_t* d = out.data() + kMid360HeaderSize;
  for (const LidarPoint& p : points) {
    switch (type) {
      case Mid360DataType::cartesian_high: {
        Mid360CartesianHigh r{clamp_round<int32_t>(p.x * 1000.0),
                              clamp_round<int32_t>(p.y * 1000.0),
                              clamp_round<int32_t>(p.z * 1000.0), refl(p.intensity), p.tag};
        std::memcpy(d, &r, sizeof(r));
        d += sizeof(r);
        break;
      }
      case Mid360DataType::cartesian_low: {
        Mid360CartesianLow r{clamp_round<int16_t>(p.x * 100.0), clamp_round<int16_t>(p.y * 100.0),
                             clamp_round<int16_t>(p.z * 100.0), refl(p.intensity), p.tag};
        std::memcpy(d, &r, sizeof(r));
        d += sizeof(r);
        break;
      }
      default: {
        const double x = p.x, y = p.y, z = p.z;
        const double r3 = std::sqrt(x * x + y * y + z * z);
        double th = r3 > 0 ? std::acos(std::clamp(z / r3, -1.0, 1.0)) / kCdegToRad : 0.0;
        double ph = std::atan2(y, x) / kCdegToRad;
        if (ph < 0) ph += 36000.0;
        Mid360Spherical r{clamp_round<uint32_t>(r3 * 1000.0), clamp_round<uint16_t>(th),
                          static_cast<uint16_t>(clamp_round<uint32_t>(ph) % 36000u),
                          refl(p.intensity), p.tag};
        std::memcpy(d, &r, sizeof(r));
        d += sizeof(r);
        break;
      }
    }
  }
  finish(meta, out.first(len));
  return len;
}

std::size_t mid360_encode_imu(const Mid360PacketMeta& meta, const ImuSample& imu,
                              std::span<uint8_t> out) {
  const std::size_t len = mid360_packet_size(Mid360DataType::imu, 1);
  if (out.size() < len) return 0;
  const Mid360Header h = make_header(meta, 0, 1, len);
  std::memcpy(out.data(), &h, sizeof(h));
  const Mid360Imu m{imu.gyro[0], imu.gyro[1], imu.gyro[2], imu.acc[0], imu.acc[1], imu.acc[2]};
  std::memcpy(out.data() + kMid360HeaderSize, &m, sizeof(m));
  finish(meta, out.first(len));
  return len;
}

}  // namespace storey::drivers::lidar

#include "drivers/lidar/vlp16.hpp"

#include <cmath>

namespace storey::drivers::lidar {

namespace {

constexpr double kPi = 3.14159265358979323846;

// sin/cos for every 0.01 deg azimuth: built once (first use), read-only afterwards.
struct TrigTable {
  std::array<float, kVlp16AzimuthUnits> sin_a;
  std::array<float, kVlp16AzimuthUnits> cos_a;
  std::array<float, 16> sin_w;
  std::array<float, 16> cos_w;
  TrigTable() {
    for (uint32_t i = 0; i < kVlp16AzimuthUnits; ++i) {
      const double a = i * (kPi / 18000.0);
      sin_a[i] = static_cast<float>(std::sin(a));
      cos_a[i] = static_cast<float>(std::cos(a));
    }
    for (int l = 0; l < 16; ++l) {
      const double w = kVlp16ElevationDeg[l] * (kPi / 180.0);
      sin_w[l] = static_cast<float>(std::sin(w));
      cos_w[l] = static_cast<float>(std::cos(w));
    }
  }
};

const TrigTable& trig() {
  static const TrigTable table;
  return table;
}

uint16_t azimuth_step(uint16_t from, uint16_t to) {
  return static_cast<uint16_t>((to + kVlp16AzimuthUnits - from) % kVlp16AzimuthUnits);
}

}  // namespace

DropReason vlp16_validate(std::span<const uint8_t> payload, Vlp16DataPacket& pkt,
                          std::array<uint16_t, kVlp16Blocks>& gaps) {
  if (payload.size() < kVlp16DataPacketSize) return DropReason::short_packet;
  if (payload.size() > kVlp16DataPacketSize) return DropReason::bad_size;
  std::memcpy(&pkt, payload.data(), kVlp16DataPacketSize);
  const uint8_t mode = pkt.return_mode;
  if (mode != static_cast<uint8_t>(Vlp16ReturnMode::strongest) &&
      mode != static_cast<uint8_t>(Vlp16ReturnMode::last) &&
      mode != static_cast<uint8_t>(Vlp16ReturnMode::dual)) {
    return DropReason::bad_return_mode;
  }
  for (const Vlp16Block& b : pkt.blocks) {
    if (b.flag != kVlp16BlockFlag) return DropReason::bad_flag;
    if (b.azimuth >= kVlp16AzimuthUnits) return DropReason::bad_azimuth;
  }
  const bool dual = mode == static_cast<uint8_t>(Vlp16ReturnMode::dual);
  const int step = dual ? 2 : 1;
  if (dual) {
    for (int b = 0; b < kVlp16Blocks; b += 2) {
      if (pkt.blocks[b].azimuth != pkt.blocks[b + 1].azimuth) return DropReason::bad_dual_pair;
    }
  }
  // Step to the next firing group; the last group reuses the previous step (rawdata.cc does the
  // same: the next packet's azimuth is not known yet).
  for (int b = 0; b < kVlp16Blocks; ++b) {
    const int g = (b / step) * step;  // first block of this group
    uint16_t gap;
    if (g + step < kVlp16Blocks) {
      gap = azimuth_step(pkt.blocks[g].azimuth, pkt.blocks[g + step].azimuth);
    } else {
      gap = azimuth_step(pkt.blocks[g - step].azimuth, pkt.blocks[g].azimuth);
    }
    if (gap > kVlp16MaxBlockGap) return DropReason::bad_azimuth;
    gaps[b] = gap;
  }
  return DropReason::none;
}

LidarPoint vlp16_to_point(const Vlp16RawReturn& r) {
  const TrigTable& t = trig();
  const float range = r.distance * kVlp16DistanceUnitM;
  const float xy = range * t.cos_w[r.laser];
  LidarPoint p;
  p.x = xy * t.sin_a[r.azimuth_cdeg];
  p.y = xy * t.cos_a[r.azimuth_cdeg];
  p.z = range * t.sin_w[r.laser];
  p.intensity = r.reflectivity;
  p.time_offset_ns = r.time_offset_ns;
  p.ring = r.ring;
  p.return_index = r.return_index;
  p.tag = 0;
  return p;
}

Vlp16Decoder::Vlp16Decoder() : Vlp16Decoder(Options{}) {}

Vlp16Decoder::Vlp16Decoder(Options opt) : opt_(opt) {
  min_range_raw_ = opt.min_range_m > 0.f
                       ? static_cast<uint32_t>(std::ceil(opt.min_range_m / kVlp16DistanceUnitM))
                       : 0u;
  (void)trig();  // build the table here, not on the first packet
}

Vlp16PacketInfo Vlp16Decoder::decode(std::span<const uint8_t> payload, std::span<LidarPoint> out) {
  if (out.size() < kVlp16MaxPointsPerPacket) {
    drops_.add(DropReason::buffer_too_small);
    return Vlp16PacketInfo{DropReason::buffer_too_small};
  }
  LidarPoint* dst = out.data();
  std::size_t n = 0;
  const uint32_t min_raw = min_range_raw_;
  Vlp16PacketInfo info = vlp16_for_each_return(payload, [&](const Vlp16RawReturn& r) {
    if (r.distance < min_raw) return;
    dst[n++] = vlp16_to_point(r);
  });
  if (info.reason != DropReason::none) {
    drops_.add(info.reason);
    return info;
  }
  info.points = static_cast<uint32_t>(n);
  ++packets_ok_;
  return info;
}

// ---- position packet ----

namespace {

int digit(char c) {
  return (c >= '0' && c <= '9') ? c - '0' : -1;
}

int hexval(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

// Reads `n` decimal digits at s[i..]; -1 if any is missing.
int read_digits(std::span<const char> s, std::size_t i, int n) {
  int v = 0;
  for (int k = 0; k < n; ++k) {
    if (i + k >= s.size()) return -1;
    const int d = digit(s[i + k]);
    if (d < 0) return -1;
    v = v * 10 + d;
  }
  return v;
}

}  // namespace

NmeaRmc parse_nmea_rmc(std::span<const char> text) {
  NmeaRmc rmc;
  // Effective length: up to the first NUL, CR or LF.
  std::size_t len = 0;
  while (len < text.size() && text[len] != '\0' && text[len] != '\r' && text[len] != '\n') ++len;
  std::span<const char> s = text.first(len);
  // Find "$??RMC".
  std::size_t start = len;
  for (std::size_t i = 0; i + 6 <= len; ++i) {
    if (s[i] == '$' && s[i + 3] == 'R' && s[i + 4] == 'M' && s[i + 5] == 'C') {
      start = i;
      break;
    }
  }
  if (start == len) return rmc;
  rmc.present = true;
  // Checksum: XOR of the characters between '$' and '*'.
  uint8_t x = 0;
  std::size_t star = len;
  for (std::size_t i = start + 1; i < len; ++i) {
    if (s[i] == '*') {
      star = i;
      break;
    }
    x ^= static_cast<uint8_t>(s[i]);
  }
  if (star < len) {
    const int h = star + 1 < len ? hexval(s[star + 1]) : -1;
    const int l = star + 2 < len ? hexval(s[star + 2]) : -1;
    rmc.checksum_ok = h >= 0 && l >= 0 && static_cast<uint8_t>(h * 16 + l) == x;
  }
  // Fields: 1 time hhmmss(.sss), 2 status, ..., 9 date ddmmyy.
  int field = 0;
  std::size_t fstart = start;
  const std::size_t end = star < len ? star : len;
  for (std::size_t i = start; i <= end; ++i) {
    if (i == end || s[i] == ',') {
      const std::size_t flen = i - fstart;
      if (field == 1 && flen >= 6) {
        const int hh = read_digits(s, fstart, 2), mm = read_digits(s, fstart + 2, 2),
                  ss = read_digits(s, fstart + 4, 2);
        int ms = 0;
        if (flen >= 8 && s[fstart + 6] == '.') {
          int scale = 100;
          for (std::size_t k = fstart + 7; k < i && scale > 0; ++k, scale /= 10) {
            const int d = digit(s[k]);
            if (d < 0) break;
            ms += d * scale;
          }
        }
        if (hh >= 0 && hh < 24 && mm >= 0 && mm < 60 && ss >= 0 && ss < 61) {
          rmc.time_of_day_ms = static_cast<uint32_t>(((hh * 60 + mm) * 60 + ss) * 1000 + ms);
        }
      } else if (field == 2 && flen >= 1) {
        rmc.valid = s[fstart] == 'A';
      } else if (field == 9 && flen >= 6) {
        const int dd = read_digits(s, fstart, 2), mo = read_digits(s, fstart + 2, 2),
                  yy = read_digits(s, fstart + 4, 2);
        if (dd >= 1 && dd <= 31 && mo >= 1 && mo <= 12 && yy >= 0) {
          rmc.day = static_cast<uint8_t>(dd);
          rmc.month = static_cast<uint8_t>(mo);
          rmc.year = static_cast<uint16_t>(2000 + yy);
        }
      }
      ++field;
      fstart = i + 1;
    }
  }
  return rmc;
}

DropReason vlp16_decode_position(std::span<const uint8_t> payload, Vlp16Position& out) {
  if (payload.size() < kVlp16PositionPacketSize) return DropReason::short_packet;
  if (payload.size() > kVlp16PositionPacketSize) return DropReason::bad_size;
  Vlp16PositionPacket pkt;
  std::memcpy(&pkt, payload.data(), kVlp16PositionPacketSize);
  out.timestamp_us = pkt.timestamp_us;
  out.pps_status = pkt.pps_status;
  out.rmc = parse_nmea_rmc(std::span<const char>(pkt.nmea, sizeof(pkt.nmea)));
  return DropReason::none;
}

uint64_t vlp16_absolute_time_ns(uint64_t reference_ns, uint32_t us_past_hour) {
  constexpr uint64_t kHourNs = 3600ull * 1000000000ull;
  const uint64_t offset = static_cast<uint64_t>(us_past_hour % 3600000000u) * 1000u;
  const uint64_t hour = reference_ns / kHourNs;
  uint64_t best = hour * kHourNs + offset;
  auto dist = [&](uint64_t t) { return t > reference_ns ? t - reference_ns : reference_ns - t; };
  if (hour > 0 && dist((hour - 1) * kHourNs + offset) < dist(best))
    best = (hour - 1) * kHourNs + offset;
  if (dist((hour + 1) * kHourNs + offset) < dist(best)) best = (hour + 1) * kHourNs + offset;
  return best;
}

// ---- encoder ----

uint16_t vlp16_range_to_raw(float range_m) {
  if (!(range_m > 0.f)) return 0;  // also NaN
  const float raw = std::round(range_m / kVlp16DistanceUnitM);
  if (raw < 1.f || raw > 65535.f) return 0;
  return static_cast<uint16_t>(raw);
}

std::size_t vlp16_encode(const Vlp16DataPacket& pkt, std::span<uint8_t> out) {
  if (out.size() < kVlp16DataPacketSize) return 0;
  std::memcpy(out.data(), &pkt, kVlp16DataPacketSize);
  return kVlp16DataPacketSize;
}

std::size_t vlp16_encode_firings(std::span<const Vlp16Firing, kVlp16FiringsPerPacket> firings,
                                 uint32_t timestamp_us, Vlp16ReturnMode mode, uint8_t product,
                                 std::span<uint8_t> out) {
  Vlp16DataPacket pkt{};
  for (int b = 0; b < kVlp16Blocks; ++b) {
    Vlp16Block& blk = pkt.blocks[b];
    blk.flag = kVlp16BlockFlag;
    blk.azimuth = static_cast<uint16_t>(firings[2 * b].azimuth_cdeg % kVlp16AzimuthUnits);
    for (int f = 0; f < 2; ++f) {
      const Vlp16Firing& fs = firings[2 * b + f];
      for (int l = 0; l < kVlp16Lasers; ++l) {
        blk.returns[f * kVlp16Lasers + l].distance = vlp16_range_to_raw(fs.range_m[l]);
        blk.returns[f * kVlp16Lasers + l].reflectivity = fs.reflectivity[l];
      }
    }
  }
  pkt.timestamp_us = timestamp_us;
  pkt.return_mode = static_cast<uint8_t>(mode);
  pkt.product = product;
  return vlp16_encode(pkt, out);
}

std::size_t vlp16_encode_position(const Vlp16Position& pos, const char* nmea,
                                  std::span<uint8_t> out) {
  if (out.size() < kVlp16PositionPacketSize) return 0;
  Vlp16PositionPacket pkt{};
  pkt.timestamp_us = pos.timestamp_us;
  pkt.pps_status = pos.pps_status;
  if (nmea != nullptr) {
    for (std::size_t i = 0; i + 1 < sizeof(pkt.nmea) && nmea[i] != '\0'; ++i) pkt.nmea[i] = nmea[i];
  }
  std::memcpy(out.data(), &pkt, kVlp16PositionPacketSize);
  return kVlp16PositionPacketSize;
}

}  // namespace storey::drivers::lidar

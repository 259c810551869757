// VLP-16 decoder/encoder tests on packets built by hand to the published format.
#include "drivers/lidar/vlp16.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace storey::drivers::lidar {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Writes a little-endian u16 at `p`.
void put16(std::vector<uint8_t>& b, std::size_t at, uint16_t v) {
  b[at] = static_cast<uint8_t>(v & 0xFF);
  b[at + 1] = static_cast<uint8_t>(v >> 8);
}

// A packet built byte by byte (not through our structs): every block flag FF EE, azimuths
// az0 + b*step, distances 0 except the (block, channel) pairs set by the caller.
std::vector<uint8_t> raw_packet(uint16_t az0, uint16_t step, uint8_t mode = 0x37) {
  std::vector<uint8_t> b(1206, 0);
  for (int k = 0; k < 12; ++k) {
    b[k * 100] = 0xFF;
    b[k * 100 + 1] = 0xEE;
    put16(b, k * 100 + 2, static_cast<uint16_t>((az0 + k * step) % 36000));
  }
  // timestamp 0x11223344 us
  b[1200] = 0x44;
  b[1201] = 0x33;
  b[1202] = 0x22;
  b[1203] = 0x11;
  b[1204] = mode;
  b[1205] = 0x21;  // what real units send
  return b;
}
void set_return(std::vector<uint8_t>& b, int block, int channel, uint16_t dist, uint8_t refl) {
  const std::size_t at = block * 100 + 4 + channel * 3;
  put16(b, at, dist);
  b[at + 2] = refl;
}

TEST(Vlp16, SinglePointBitExact) {
  auto pkt = raw_packet(1000, 40);
  // block 3, firing 1, laser 5 (elevation +5 deg, ring 10): 10.000 m, reflectivity 77
  set_return(pkt, 3, 16 + 5, 5000, 77);
  Vlp16Decoder dec;
  std::array<LidarPoint, kVlp16MaxPointsPerPacket> out;
  const auto info = dec.decode(pkt, out);
  ASSERT_EQ(info.reason, DropReason::none);
  EXPECT_EQ(info.timestamp_us, 0x11223344u);
  EXPECT_EQ(info.return_mode, 0x37);
  EXPECT_EQ(info.product, 0x21);
  ASSERT_EQ(info.points, 1u);
  const LidarPoint& p = out[0];
  EXPECT_EQ(p.ring, 10);
  EXPECT_EQ(p.return_index, 0);
  EXPECT_EQ(p.intensity, 77.f);
  // t = 55.296 * (2*3 + 1) + 2.304 * 5 us
  EXPECT_EQ(p.time_offset_ns, 55296 * 7 + 2304 * 5);
  // azimuth = 1120 + 40 * (55.296 + 11.52) / 110.592 = 1120 + 24.17 -> 1144 (0.01 deg)
  const double a = 1144 * kPi / 18000.0, w = 5 * kPi / 180.0;
  EXPECT_NEAR(p.x, 10.0 * std::cos(w) * std::sin(a), 1e-5);
  EXPECT_NEAR(p.y, 10.0 * std::cos(w) * std::cos(a), 1e-5);
  EXPECT_NEAR(p.z, 10.0 * std::sin(w), 1e-5);
  EXPECT_EQ(dec.packets_ok(), 1u);
  EXPECT_EQ(dec.drops().total(), 0u);
}

TEST(Vlp16, RawVisitorInterpolatesAzimuthAndRing) {
  auto pkt = raw_packet(0, 80);
  for (int ch = 0; ch < 32; ++ch) set_return(pkt, 0, ch, 1000, static_cast<uint8_t>(ch));
  std::vector<Vlp16RawReturn> rr;
  const auto info = vlp16_for_each_return(pkt, [&](const Vlp16RawReturn& r) { rr.push_back(r); });
  ASSERT_EQ(info.reason, DropReason::none);
  ASSERT_EQ(rr.size(), 32u);
  const int rings[16] = {0, 8, 1, 9, 2, 10, 3, 11, 4, 12, 5, 13, 6, 14, 7, 15};
  for (int ch = 0; ch < 32; ++ch) {
    const int f = ch / 16, l = ch % 16;
    EXPECT_EQ(rr[ch].ring, rings[l]);
    const double daz = 80.0 * (55.296 * f + 2.304 * l) / 110.592;
    EXPECT_EQ(rr[ch].azimuth_cdeg, static_cast<uint16_t>(std::lround(daz))) << ch;
    EXPECT_EQ(rr[ch].time_offset_ns, 55296 * f + 2304 * l);
  }
}

TEST(Vlp16, AzimuthWrapAround) {
  // Blocks at 35960, 36000->0 (35960+40 = 36000 = 0), 40, ... and the last block's gap is reused.
  auto pkt = raw_packet(35960, 40);
  set_return(pkt, 0, 16 + 15, 500, 1);  // block 0, second firing, last laser: past 36000
  set_return(pkt, 11, 16 + 15, 500, 1);
  std::vector<Vlp16RawReturn> rr;
  const auto info = vlp16_for_each_return(pkt, [&](const Vlp16RawReturn& r) { rr.push_back(r); });
  ASSERT_EQ(info.reason, DropReason::none);
  ASSERT_EQ(rr.size(), 2u);
  // 35960 + 40 * (55.296 + 34.56) / 110.592 = 35960 + 32.5 -> 35993 (half up)
  EXPECT_EQ(rr[0].azimuth_cdeg, 35993);
  // block 11 at (35960 + 440) % 36000 = 400, + 32.5 -> 433
  EXPECT_EQ(rr[1].azimuth_cdeg, 433);
  // wraps inside the interpolation: block at 35990, gap 40 -> 35990 + 33 = 36023 -> 23
  auto pkt2 = raw_packet(35990, 40);
  set_return(pkt2, 0, 16 + 15, 500, 1);
  rr.clear();
  vlp16_for_each_return(pkt2, [&](const Vlp16RawReturn& r) { rr.push_back(r); });
  ASSERT_EQ(rr.size(), 1u);
  EXPECT_EQ(rr[0].azimuth_cdeg, 23);
}

TEST(Vlp16, DualReturnPairs) {
  std::vector<uint8_t> pkt(1206, 0);
  for (int k = 0; k < 12; ++k) {
    pkt[k * 100] = 0xFF;
    pkt[k * 100 + 1] = 0xEE;
    put16(pkt, k * 100 + 2, static_cast<uint16_t>(2000 + (k / 2) * 40));
  }
  pkt[1204] = 0x39;
  pkt[1205] = 0x22;
  set_return(pkt, 4, 3, 2500, 10);  // pair 2, last return, firing 0 laser 3
  set_return(pkt, 5, 3, 3000, 90);  // pair 2, strongest return
  Vlp16Decoder dec;
  std::array<LidarPoint, kVlp16MaxPointsPerPacket> out;
  const auto info = dec.decode(pkt, out);
  ASSERT_EQ(info.reason, DropReason::none);
  ASSERT_EQ(info.points, 2u);
  EXPECT_EQ(out[0].return_index, 0);
  EXPECT_EQ(out[1].return_index, 1);
  // both returns from the same firing: pair 2 starts 2 * 110.592 us in
  EXPECT_EQ(out[0].time_offset_ns, 2 * 110592 + 3 * 2304);
  EXPECT_EQ(out[1].time_offset_ns, out[0].time_offset_ns);
  EXPECT_NEAR(std::hypot(out[0].x, out[0].y, out[0].z), 5.0, 1e-5);
  EXPECT_NEAR(std::hypot(out[1].x, out[1].y, out[1].z), 6.0, 1e-5);
  // same direction
  EXPECT_NEAR(out[0].x / 5.0, out[1].x / 6.0, 1e-6);
  // a pair with different azimuths is refused
  put16(pkt, 5 * 100 + 2, 2081);
  const auto bad = dec.decode(pkt, out);
  EXPECT_EQ(bad.reason, DropReason::bad_dual_pair);
  EXPECT_EQ(dec.drops()[DropReason::bad_dual_pair], 1u);
}

TEST(Vlp16, ZeroDistanceIsNoReturn) {
  auto pkt = raw_packet(0, 40);
  Vlp16Decoder dec;
  std::array<LidarPoint, kVlp16MaxPointsPerPacket> out;
  const auto info = dec.decode(pkt, out);
  EXPECT_EQ(info.reason, DropReason::none);
  EXPECT_EQ(info.points, 0u);
}

TEST(Vlp16, MalformedPacketsCountedNeverDecoded) {
  auto good = raw_packet(100, 40);
  for (int b = 0; b < 12; ++b)
    for (int c = 0; c < 32; ++c) set_return(good, b, c, 1000, 5);
  Vlp16Decoder dec;
  std::array<LidarPoint, kVlp16MaxPointsPerPacket> out;
  auto expect_refused = [&](const std::vector<uint8_t>& pkt, DropReason why) {
    out.fill(LidarPoint{});
    const auto info = dec.decode(pkt, out);
    EXPECT_EQ(info.reason, why) << to_string(why);
    EXPECT_EQ(info.points, 0u);
    for (const auto& p : out) ASSERT_EQ(p.x, 0.f);  // nothing written
  };
  std::vector<uint8_t> shortp(good.begin(), good.begin() + 1205);
  expect_refused(shortp, DropReason::short_packet);
  expect_refused(std::vector<uint8_t>(), DropReason::short_packet);
  auto longp = good;
  longp.push_back(0);
  expect_refused(longp, DropReason::bad_size);
  auto flag = good;
  flag[7 * 100 + 1] = 0xDD;  // block 7 flag FF DD
  expect_refused(flag, DropReason::bad_flag);
  auto az = good;
  put16(az, 4 * 100 + 2, 36000);
  expect_refused(az, DropReason::bad_azimuth);
  auto jump = good;
  put16(jump, 4 * 100 + 2, 20000);  // 200 deg jump between blocks
  expect_refused(jump, DropReason::bad_azimuth);
  auto mode = good;
  mode[1204] = 0x40;
  expect_refused(mode, DropReason::bad_return_mode);
  EXPECT_EQ(dec.drops()[DropReason::short_packet], 2u);
  EXPECT_EQ(dec.drops()[DropReason::bad_size], 1u);
  EXPECT_EQ(dec.drops()[DropReason::bad_flag], 1u);
  EXPECT_EQ(dec.drops()[DropReason::bad_azimuth], 2u);
  EXPECT_EQ(dec.drops()[DropReason::bad_return_mode], 1u);
  EXPECT_EQ(dec.packets_ok(), 0u);
  // the good one decodes fully
  EXPECT_EQ(dec.decode(good, out).points, 384u);
  // too small a buffer is refused, not overrun
  std::array<LidarPoint, 10> small;
  EXPECT_EQ(dec.decode(good, small).reason, DropReason::buffer_too_small);
}

TEST(Vlp16, EncoderDecoderRoundTrip) {
  std::array<Vlp16Firing, kVlp16FiringsPerPacket> firings{};
  for (int f = 0; f < kVlp16FiringsPerPacket; ++f) {
    firings[f].azimuth_cdeg = static_cast<uint16_t>((35800 + f * 20) % 36000);
    for (int l = 0; l < 16; ++l) {
      firings[f].range_m[l] = (l == 3) ? 0.f : 1.0f + 0.37f * l + 0.011f * f;
      firings[f].reflectivity[l] = static_cast<uint8_t>(f * 16 + l);
    }
  }
  firings[5].range_m[7] = std::nanf("");
  firings[6].range_m[7] = 500.f;  // beyond 131 m: not representable, no return
  std::array<uint8_t, kVlp16DataPacketSize> buf;
  ASSERT_EQ(vlp16_encode_firings(firings, 1234567, Vlp16ReturnMode::strongest, 0x22, buf),
            kVlp16DataPacketSize);
  std::vector<Vlp16RawReturn> rr;
  const auto info = vlp16_for_each_return(buf, [&](const Vlp16RawReturn& r) { rr.push_back(r); });
  ASSERT_EQ(info.reason, DropReason::none);
  EXPECT_EQ(info.timestamp_us, 1234567u);
  EXPECT_EQ(info.product, 0x22);
  ASSERT_EQ(rr.size(), 24u * 15 - 2);
  for (const auto& r : rr) {
    const int f = r.block * 2 + r.firing;
    EXPECT_EQ(r.distance, vlp16_range_to_raw(firings[f].range_m[r.laser]));
    EXPECT_NEAR(r.distance * 0.002, firings[f].range_m[r.laser], 0.001 + 1e-5);
    EXPECT_EQ(r.reflectivity, static_cast<uint8_t>(f * 16 + r.laser));
    // first laser of a sequence sits at the sequence's azimuth (the second sequence's azimuth is
    // interpolated from the block gap of 40, which matches 2 x 20 exactly)
    if (r.laser == 0) {
      EXPECT_EQ(r.azimuth_cdeg, firings[f].azimuth_cdeg);
    }
  }
}

TEST(Vlp16, PositionPacketAndNmea) {
  const char* nmea = "$GPRMC,123519.25,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6A";
  Vlp16Position pos;
  pos.timestamp_us = 2999999999u;
  pos.pps_status = 2;
  std::array<uint8_t, 512> buf;
  ASSERT_EQ(vlp16_encode_position(pos, nmea, buf), 512u);
  EXPECT_EQ(buf[198], 0xFF);  // 2999999999 = 0xB2D05DFF, little endian at 198
  EXPECT_EQ(buf[201], 0xB2);
  EXPECT_EQ(buf[202], 2);
  EXPECT_EQ(buf[206], '$');
  Vlp16Position got;
  ASSERT_EQ(vlp16_decode_position(buf, got), DropReason::none);
  EXPECT_EQ(got.timestamp_us, 2999999999u);
  EXPECT_EQ(got.pps_status, 2);
  EXPECT_TRUE(got.rmc.present);
  EXPECT_TRUE(got.rmc.valid);
  EXPECT_EQ(got.rmc.time_of_day_ms, ((12u * 60 + 35) * 60 + 19) * 1000 + 250);
  EXPECT_EQ(got.rmc.day, 23);
  EXPECT_EQ(got.rmc.month, 3);
  EXPECT_EQ(got.rmc.year, 2094);  // two-digit year taken as 20yy
  // checksum computed by hand for the sentence body
  uint8_t x = 0;
  const std::string s(nmea);
  for (std::size_t i = 1; i < s.find('*'); ++i) x ^= static_cast<uint8_t>(s[i]);
  EXPECT_EQ(got.rmc.checksum_ok, x == 0x6A);
  // void sentence, no checksum
  const auto v = parse_nmea_rmc(std::string_view("$GPRMC,000001,V,,,,,,,010100,,"));
  EXPECT_TRUE(v.present);
  EXPECT_FALSE(v.valid);
  EXPECT_FALSE(v.checksum_ok);
  EXPECT_EQ(v.time_of_day_ms, 1000u);
  // nothing there
  std::array<uint8_t, 512> zero{};
  ASSERT_EQ(vlp16_decode_position(zero, got), DropReason::none);
  EXPECT_FALSE(got.rmc.present);
  EXPECT_EQ(vlp16_decode_position(std::span<const uint8_t>(zero).first(300), got),
            DropReason::short_packet);
}

TEST(Vlp16, AbsoluteTimeNearestHour) {
  constexpr uint64_t H = 3600ull * 1000000000ull;
  // reference just after 10:00, stamp from 09:59:59.9 -> previous hour
  EXPECT_EQ(vlp16_absolute_time_ns(10 * H + 50'000'000, 3599'900'000u), 10 * H - 100'000'000);
  EXPECT_EQ(vlp16_absolute_time_ns(10 * H + 50'000'000, 1000u), 10 * H + 1'000'000);
  EXPECT_EQ(vlp16_absolute_time_ns(11 * H - 1'000'000, 500u), 11 * H + 500'000);
}

}  // namespace
}  // namespace storey::drivers::lidar

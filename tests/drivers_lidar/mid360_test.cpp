// Mid-360 decoder/encoder tests on packets built by hand to the published Livox SDK2 format.
#include "drivers/lidar/mid360.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "drivers/crc.hpp"

namespace storey::drivers::lidar {
namespace {

template <class T>
void put(std::vector<uint8_t>& b, std::size_t at, T v) {
  std::memcpy(b.data() + at, &v, sizeof(T));
}

// Header written field by field at the documented offsets.
std::vector<uint8_t> header(uint8_t type, uint16_t dots, std::size_t item) {
  std::vector<uint8_t> b(36 + dots * item, 0);
  b[0] = 0;                                              // version
  put<uint16_t>(b, 1, static_cast<uint16_t>(b.size()));  // length
  put<uint16_t>(b, 3, 4800);                             // time interval: 480 us
  put<uint16_t>(b, 5, dots);
  put<uint16_t>(b, 7, 7);  // udp_cnt
  b[9] = 3;                // frame_cnt
  b[10] = type;
  b[11] = 1;                                           // PTP
  put<uint64_t>(b, 28, 1'700'000'000'000'000'000ull);  // timestamp ns
  return b;
}

TEST(Crc, CheckValues) {
  const char* s = "123456789";
  std::span<const uint8_t> d(reinterpret_cast<const uint8_t*>(s), 9);
  EXPECT_EQ(crc16_ccitt_false(d), 0x29B1);
  EXPECT_EQ(crc32_zlib(d), 0xCBF43926u);
  // chaining like zlib
  EXPECT_EQ(crc32_zlib(d.subspan(4), crc32_zlib(d.first(4))), 0xCBF43926u);
  static_assert(crc32_zlib(std::span<const uint8_t>()) == 0u);
}

TEST(Mid360, CartesianHighBitExact) {
  auto b = header(1, 96, 14);
  for (int i = 0; i < 96; ++i) {
    const std::size_t at = 36 + i * 14;
    put<int32_t>(b, at, 1000 + i);
    put<int32_t>(b, at + 4, -2000 - i);
    put<int32_t>(b, at + 8, i == 5 ? 0 : 300);
    b[at + 12] = static_cast<uint8_t>(i);
    b[at + 13] = static_cast<uint8_t>(i & 0x3F);  // tag bits
  }
  // point 10 is a non-return (all zero)
  put<int32_t>(b, 36 + 10 * 14, 0);
  put<int32_t>(b, 36 + 10 * 14 + 4, 0);
  put<int32_t>(b, 36 + 10 * 14 + 8, 0);
  ASSERT_EQ(b.size(), 1380u);
  Mid360Decoder dec;
  std::array<LidarPoint, 96> out;
  const auto info = dec.decode(b, out);
  ASSERT_EQ(info.reason, DropReason::none);
  EXPECT_EQ(info.points, 95u);
  EXPECT_EQ(info.timestamp_ns, 1'700'000'000'000'000'000ull);
  EXPECT_EQ(info.time_type, 1);
  EXPECT_EQ(info.frame_cnt, 3);
  EXPECT_EQ(info.udp_cnt, 7);
  EXPECT_FLOAT_EQ(out[0].x, 1.0f);
  EXPECT_FLOAT_EQ(out[0].y, -2.0f);
  EXPECT_FLOAT_EQ(out[0].z, 0.3f);
  EXPECT_FLOAT_EQ(out[5].z, 0.0f);  // one zero coordinate is still a point
  // point 11 lands at index 10 (point 10 skipped); time i * 480 us / 96 = i * 5 us
  EXPECT_FLOAT_EQ(out[10].x, 1.011f);
  EXPECT_EQ(out[10].time_offset_ns, 11 * 5000);
  EXPECT_EQ(out[10].intensity, 11.f);
  EXPECT_EQ(out[10].tag, 11);
  EXPECT_EQ(out[94].time_offset_ns, 95 * 5000);
}

TEST(Mid360, CartesianLowAndSpherical) {
  auto lo = header(2, 2, 8);
  put<int16_t>(lo, 36, -150);
  put<int16_t>(lo, 38, 250);
  put<int16_t>(lo, 40, 5);
  lo[42] = 200;
  lo[43] = 0b00010110;
  put<int16_t>(lo, 44, 1);
  Mid360Decoder dec;
  std::array<LidarPoint, 96> out;
  auto info = dec.decode(lo, out);
  ASSERT_EQ(info.reason, DropReason::none);
  ASSERT_EQ(info.points, 2u);
  EXPECT_FLOAT_EQ(out[0].x, -1.5f);
  EXPECT_FLOAT_EQ(out[0].y, 2.5f);
  EXPECT_FLOAT_EQ(out[0].z, 0.05f);
  EXPECT_EQ(out[0].tag, 0b00010110);
  EXPECT_EQ(out[1].time_offset_ns, 1 * 480000 / 2);

  auto sp = header(3, 1, 10);
  put<uint32_t>(sp, 36, 10000);  // 10 m
  put<uint16_t>(sp, 40, 6000);   // zenith 60 deg
  put<uint16_t>(sp, 42, 9000);   // azimuth 90 deg
  sp[44] = 9;
  Mid360Decoder dec2;
  info = dec2.decode(sp, out);
  ASSERT_EQ(info.reason, DropReason::none);
  ASSERT_EQ(info.points, 1u);
  EXPECT_NEAR(out[0].x, 0.0, 1e-5);
  EXPECT_NEAR(out[0].y, 10.0 * std::sin(60 * M_PI / 180), 1e-5);
  EXPECT_NEAR(out[0].z, 5.0, 1e-5);
}

TEST(Mid360, Imu) {
  auto b = header(0, 1, 24);
  const float v[6] = {0.1f, -0.2f, 0.3f, 0.01f, 0.02f, -1.0f};
  std::memcpy(b.data() + 36, v, 24);
  ASSERT_EQ(b.size(), 60u);
  Mid360Decoder dec;
  ImuSample imu;
  std::array<LidarPoint, 96> out;
  const auto info = dec.decode(b, out, &imu);
  ASSERT_EQ(info.reason, DropReason::none);
  EXPECT_TRUE(info.imu);
  EXPECT_EQ(info.points, 0u);
  EXPECT_EQ(imu.timestamp_ns, 1'700'000'000'000'000'000ull);
  EXPECT_EQ(imu.gyro[1], -0.2f);
  EXPECT_EQ(imu.acc[2], -1.0f);
}

TEST(Mid360, CrcCheckedWhenPresent) {
  auto b = header(1, 1, 14);
  put<int32_t>(b, 36, 1234);
  const uint32_t crc = crc32_zlib(std::span<const uint8_t>(b).subspan(28));
  put<uint32_t>(b, 24, crc);
  Mid360Decoder dec;
  std::array<LidarPoint, 96> out;
  EXPECT_EQ(dec.decode(b, out).reason, DropReason::none);
  b[40] ^= 0x01;  // corrupt one data byte
  EXPECT_EQ(dec.decode(b, out).reason, DropReason::bad_crc);
  b[28] ^= 0x80;  // and the timestamp (covered too)
  b[40] ^= 0x01;
  EXPECT_EQ(dec.decode(b, out).reason, DropReason::bad_crc);
  EXPECT_EQ(dec.drops()[DropReason::bad_crc], 2u);
  put<uint32_t>(b, 24, 0);  // not filled: accepted
  EXPECT_EQ(dec.decode(b, out).reason, DropReason::none);
  Mid360Decoder lax(Mid360Decoder::Options{.verify_crc = false});
  put<uint32_t>(b, 24, 0xDEADBEEF);
  EXPECT_EQ(lax.decode(b, out).reason, DropReason::none);
}

TEST(Mid360, MalformedCountedNeverDecoded) {
  auto good = header(1, 96, 14);
  for (int i = 0; i < 96; ++i) put<int32_t>(good, 36 + i * 14, 1000);
  Mid360Decoder dec;
  std::array<LidarPoint, 96> out;
  auto refused = [&](const std::vector<uint8_t>& b, DropReason why) {
    out.fill(LidarPoint{});
    const auto info = dec.decode(b, out);
    EXPECT_EQ(info.reason, why) << to_string(why);
    EXPECT_EQ(info.points, 0u);
    for (const auto& p : out) ASSERT_EQ(p.x, 0.f);
  };
  refused(std::vector<uint8_t>(good.begin(), good.begin() + 20), DropReason::short_packet);
  refused(std::vector<uint8_t>(good.begin(), good.end() - 1), DropReason::short_packet);
  auto longer = good;
  longer.push_back(0);
  refused(longer, DropReason::bad_size);
  auto ver = good;
  ver[0] = 1;
  refused(ver, DropReason::bad_version);
  auto type = good;
  type[10] = 0x11;  // dual-echo type: not supported by this decoder
  refused(type, DropReason::unknown_type);
  auto dots = good;
  put<uint16_t>(dots, 5, 95);
  refused(dots, DropReason::bad_length);
  std::array<LidarPoint, 10> small;
  EXPECT_EQ(dec.decode(good, small).reason, DropReason::buffer_too_small);
  EXPECT_EQ(dec.drops().total(), 7u);
  EXPECT_EQ(dec.packets_ok(), 0u);
}

TEST(Mid360, UdpCounterGapsAreLoss) {
  Mid360Decoder dec;
  std::array<LidarPoint, 96> out;
  std::vector<LidarPoint> pts(96, LidarPoint{1.f, 2.f, 3.f});
  std::array<uint8_t, 1500> buf;
  auto send = [&](uint8_t frame, uint16_t cnt) {
    Mid360PacketMeta m;
    m.frame_cnt = frame;
    m.udp_cnt = cnt;
    const std::size_t n = mid360_encode_points(m, Mid360DataType::cartesian_high, pts, buf);
    return dec.decode(std::span<const uint8_t>(buf).first(n), out);
  };
  EXPECT_EQ(send(0, 0).lost_before, 0u);
  EXPECT_EQ(send(0, 1).lost_before, 0u);
  EXPECT_EQ(send(0, 4).lost_before, 2u);  // 2, 3 missing
  EXPECT_EQ(send(0, 5).lost_before, 0u);
  EXPECT_EQ(send(1, 0).lost_before, 0u);  // new frame restarts at 0
  EXPECT_EQ(send(2, 3).lost_before, 3u);  // new frame, 0..2 missing
  EXPECT_EQ(send(2, 2).lost_before, 0u);  // went backwards: reordered, not loss
  EXPECT_EQ(dec.lost_packets(), 5u);
  EXPECT_EQ(dec.out_of_order(), 1u);
  EXPECT_EQ(send(2, 1000).lost_before, 997u);  // large forward jump is loss
}

TEST(Mid360, EncoderDecoderRoundTripAllTypes) {
  std::vector<LidarPoint> pts;
  for (int i = 0; i < 96; ++i) {
    LidarPoint p;
    p.x = 0.5f + 0.113f * i;
    p.y = -3.0f + 0.07f * i;
    p.z = (i % 7) * 0.31f - 1.0f;
    p.intensity = static_cast<float>(i * 2);
    p.tag = static_cast<uint8_t>(i % 64);
    pts.push_back(p);
  }
  std::array<uint8_t, 1500> buf;
  const struct {
    Mid360DataType t;
    double tol;
    std::size_t size;
  } cases[] = {{Mid360DataType::cartesian_high, 0.0006, 1380},
               {Mid360DataType::cartesian_low, 0.006, 36 + 96 * 8},
               {Mid360DataType::spherical, 0.002, 36 + 96 * 10}};
  for (const auto& c : cases) {
    Mid360PacketMeta m;
    m.timestamp_ns = 42;
    m.time_interval = 4800;
    const std::size_t n = mid360_encode_points(m, c.t, pts, buf);
    ASSERT_EQ(n, c.size);
    Mid360Decoder dec;
    std::array<LidarPoint, 96> out;
    const auto info = dec.decode(std::span<const uint8_t>(buf).first(n), out);
    ASSERT_EQ(info.reason, DropReason::none);
    ASSERT_EQ(info.points, 96u);
    for (int i = 0; i < 96; ++i) {
      EXPECT_NEAR(out[i].x, pts[i].x, c.tol);
      EXPECT_NEAR(out[i].y, pts[i].y, c.tol);
      EXPECT_NEAR(out[i].z, pts[i].z, c.tol);
      EXPECT_EQ(out[i].intensity, pts[i].intensity);
      EXPECT_EQ(out[i].tag, pts[i].tag);
      EXPECT_EQ(out[i].time_offset_ns, i * 5000);
    }
  }
  ImuSample imu{7, {1, 2, 3}, {4, 5, 6}, 0};
  const std::size_t n = mid360_encode_imu(Mid360PacketMeta{.timestamp_ns = 7}, imu, buf);
  ASSERT_EQ(n, 60u);
  Mid360Decoder dec;
  ImuSample got;
  std::array<LidarPoint, 96> out;
  ASSERT_EQ(dec.decode(std::span<const uint8_t>(buf).first(n), out, &got).reason, DropReason::none);
  EXPECT_EQ(got.timestamp_ns, 7u);
  EXPECT_EQ(got.acc[2], 6.f);
}

}  // namespace
}  // namespace storey::drivers::lidar

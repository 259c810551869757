#include "drivers/go2/message_codec.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "drivers/crc.hpp"
#include "drivers/go2/udp_frame.hpp"

namespace storey::drivers::go2 {
namespace {

RobotState sample_state() {
  RobotState s;
  s.stamp_ns = 1234567890123;
  s.position = {1.5f, -2.25f, 0.3f};
  s.velocity = {0.5f, 0.1f, -0.01f};
  s.yaw_speed = 0.7f;
  s.body_height = 0.31f;
  s.quaternion = {0.9f, 0.1f, -0.2f, 0.3f};
  s.gyro = {0.01f, 0.02f, 0.7f};
  s.accel = {0.1f, -0.2f, 9.8f};
  s.rpy = {0.05f, -0.04f, 1.2f};
  s.mode = 3;
  s.gait = 1;
  s.foot_force = {120, -5, 300, 32767};
  s.battery_voltage = 28.4f;
  s.battery_current = -3.5f;
  s.battery_soc = 77;
  s.error_code = 0xDEADBEEF;
  return s;
}

TEST(Crc32, ZlibCheckValue) {
  const char* s = "123456789";
  EXPECT_EQ(crc32_zlib({reinterpret_cast<const uint8_t*>(s), 9}), 0xCBF43926u);
  // Incremental == one shot.
  const uint32_t a = crc32_zlib({reinterpret_cast<const uint8_t*>(s), 4});
  EXPECT_EQ(crc32_zlib({reinterpret_cast<const uint8_t*>(s) + 4, 5}, a), 0xCBF43926u);
}

TEST(MessageCodec, StateRoundTripIsExact) {
  const RobotState s = sample_state();
  uint8_t buf[kStatePayloadSize];
  encode_state(s, buf);
  RobotState d;
  ASSERT_EQ(decode_state(buf, sizeof(buf), d), PayloadError::ok);
  EXPECT_EQ(d.stamp_ns, s.stamp_ns);
  EXPECT_EQ(d.position, s.position);
  EXPECT_EQ(d.velocity, s.velocity);
  EXPECT_EQ(d.yaw_speed, s.yaw_speed);
  EXPECT_EQ(d.body_height, s.body_height);
  EXPECT_EQ(d.quaternion, s.quaternion);
  EXPECT_EQ(d.gyro, s.gyro);
  EXPECT_EQ(d.accel, s.accel);
  EXPECT_EQ(d.rpy, s.rpy);
  EXPECT_EQ(d.mode, s.mode);
  EXPECT_EQ(d.gait, s.gait);
  EXPECT_EQ(d.foot_force, s.foot_force);
  EXPECT_EQ(d.battery_voltage, s.battery_voltage);
  EXPECT_EQ(d.battery_current, s.battery_current);
  EXPECT_EQ(d.battery_soc, s.battery_soc);
  EXPECT_EQ(d.error_code, s.error_code);
}

TEST(MessageCodec, StateLayoutMatchesReadme) {
  // Spot-check documented offsets (README "State payload") so doc and code cannot drift.
  RobotState s;
  s.stamp_ns = 0x0102030405060708;
  s.mode = 0xAB;
  s.gait = 0xCD;
  s.battery_soc = 0x42;
  s.error_code = 0x11223344;
  s.foot_force = {0x0102, 0, 0, 0};
  uint8_t b[kStatePayloadSize];
  encode_state(s, b);
  EXPECT_EQ(b[0], 0x08);  // little endian
  EXPECT_EQ(b[7], 0x01);
  EXPECT_EQ(b[92], 0xAB);
  EXPECT_EQ(b[93], 0xCD);
  EXPECT_EQ(b[94], 0x02);
  EXPECT_EQ(b[95], 0x01);
  EXPECT_EQ(b[110], 0x42);
  EXPECT_EQ(get_u32(b + 112), 0x11223344u);
  float w;
  std::memcpy(&w, b + 40, 4);  // quaternion w (default 1)
  EXPECT_EQ(w, 1.0f);
}

TEST(MessageCodec, CommandsRoundTrip) {
  VelocityCommand v{42, 0.4f, -0.2f, 0.9f};
  uint8_t vb[kVelocityPayloadSize];
  encode_velocity(v, vb);
  VelocityCommand vd;
  ASSERT_EQ(decode_velocity(vb, sizeof(vb), vd), PayloadError::ok);
  EXPECT_EQ(vd.stamp_ns, 42);
  EXPECT_EQ(vd.vx, 0.4f);
  EXPECT_EQ(vd.vy, -0.2f);
  EXPECT_EQ(vd.yaw_rate, 0.9f);

  for (uint8_t m = 0; m < kModeRequestCount; ++m) {
    ModeCommand c{7, static_cast<ModeRequest>(m)};
    uint8_t mb[kModePayloadSize];
    encode_mode(c, mb);
    ModeCommand cd;
    ASSERT_EQ(decode_mode(mb, sizeof(mb), cd), PayloadError::ok);
    EXPECT_EQ(cd.mode, c.mode);
  }
  Heartbeat h{99, 123456, 1};
  uint8_t hb[kHeartbeatPayloadSize];
  encode_heartbeat(h, hb);
  Heartbeat hd;
  ASSERT_EQ(decode_heartbeat(hb, sizeof(hb), hd), PayloadError::ok);
  EXPECT_EQ(hd.counter, 123456u);
  EXPECT_EQ(hd.status, 1);
}

TEST(MessageCodec, RejectsNonFiniteWrongSizeAndBadEnum) {
  RobotState s = sample_state();
  s.position[1] = std::numeric_limits<float>::quiet_NaN();
  uint8_t b[kStatePayloadSize];
  encode_state(s, b);
  RobotState d;
  EXPECT_EQ(decode_state(b, sizeof(b), d), PayloadError::non_finite);
  EXPECT_EQ(decode_state(b, sizeof(b) - 1, d), PayloadError::wrong_size);

  VelocityCommand v{1, std::numeric_limits<float>::infinity(), 0, 0};
  uint8_t vb[kVelocityPayloadSize];
  encode_velocity(v, vb);
  VelocityCommand vd;
  EXPECT_EQ(decode_velocity(vb, sizeof(vb), vd), PayloadError::non_finite);

  uint8_t mb[kModePayloadSize] = {};
  mb[8] = kModeRequestCount;
  ModeCommand md;
  EXPECT_EQ(decode_mode(mb, sizeof(mb), md), PayloadError::bad_enum);
}

TEST(UdpFrame, RoundTripAndHeaderFields) {
  VelocityCommand v{5, 1.0f, 2.0f, 3.0f};
  uint8_t p[kVelocityPayloadSize];
  encode_velocity(v, p);
  FrameHeader h;
  h.type = static_cast<uint8_t>(MsgType::velocity_command);
  h.sequence = 0xA1B2C3D4;
  h.timestamp_ns = 987654321;
  uint8_t f[kUdpMaxFrameSize];
  const size_t n = encode_udp_frame(h, p, sizeof(p), f);
  ASSERT_EQ(n, kUdpHeaderSize + kVelocityPayloadSize + kUdpCrcSize);
  EXPECT_EQ(f[0], 0x53);
  EXPECT_EQ(f[1], 0x47);
  EXPECT_EQ(f[2], 1);
  EXPECT_EQ(f[3], 2);
  EXPECT_EQ(get_u16(f + 6), kVelocityPayloadSize);
  EXPECT_EQ(get_u32(f + 8), 0xA1B2C3D4u);
  EXPECT_EQ(get_u32(f + n - 4), crc32_zlib({f, n - 4}));
  FrameHeader d;
  const uint8_t* payload = nullptr;
  size_t len = 0;
  ASSERT_EQ(decode_udp_frame(f, n, d, payload, len), FrameError::ok);
  EXPECT_EQ(d.sequence, h.sequence);
  EXPECT_EQ(d.timestamp_ns, h.timestamp_ns);
  EXPECT_EQ(len, kVelocityPayloadSize);
  EXPECT_EQ(std::memcmp(payload, p, len), 0);
}

TEST(UdpFrame, ReadmeExampleBytes) {
  // drivers/go2/README.md "Wire format" example, byte for byte.
  const uint8_t expected[] = {0x53, 0x47, 0x01, 0x02, 0x00, 0x00, 0x14, 0x00, 0x07, 0x00, 0x00,
                              0x00, 0xd0, 0x07, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xe8, 0x03,
                              0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x3f, 0x00,
                              0x00, 0x00, 0x00, 0xcd, 0xcc, 0xcc, 0x3d, 0x9b, 0xa3, 0xa0, 0x20};
  uint8_t p[kVelocityPayloadSize];
  encode_velocity(VelocityCommand{1000, 0.5f, 0.0f, 0.1f}, p);
  FrameHeader h;
  h.type = static_cast<uint8_t>(MsgType::velocity_command);
  h.sequence = 7;
  h.timestamp_ns = 2000;
  uint8_t f[kUdpMaxFrameSize];
  ASSERT_EQ(encode_udp_frame(h, p, sizeof(p), f), sizeof(expected));
  EXPECT_EQ(std::memcmp(f, expected, sizeof(expected)), 0);
}

TEST(UdpFrame, EveryBitFlipIsDetected) {
  RobotState s = sample_state();
  uint8_t p[kStatePayloadSize];
  encode_state(s, p);
  FrameHeader h;
  h.type = static_cast<uint8_t>(MsgType::state);
  uint8_t f[kUdpMaxFrameSize];
  const size_t n = encode_udp_frame(h, p, sizeof(p), f);
  int crc_failures = 0;
  for (size_t byte = 0; byte < n; ++byte) {
    for (int bit = 0; bit < 8; ++bit) {
      uint8_t g[kUdpMaxFrameSize];
      std::memcpy(g, f, n);
      g[byte] ^= static_cast<uint8_t>(1u << bit);
      FrameHeader d;
      const uint8_t* pl;
      size_t len;
      const FrameError e = decode_udp_frame(g, n, d, pl, len);
      ASSERT_NE(e, FrameError::ok) << "flip at byte " << byte << " bit " << bit;
      crc_failures += e == FrameError::bad_crc;
    }
  }
  // Flips outside magic/version/length are CRC failures.
  EXPECT_GE(crc_failures, static_cast<int>((n - 5) * 8) - 16);
}

TEST(UdpFrame, RejectsTruncatedAndWrongLength) {
  uint8_t p[kModePayloadSize] = {};
  FrameHeader h;
  h.type = static_cast<uint8_t>(MsgType::mode_command);
  uint8_t f[kUdpMaxFrameSize];
  const size_t n = encode_udp_frame(h, p, sizeof(p), f);
  FrameHeader d;
  const uint8_t* pl;
  size_t len;
  for (size_t k = 0; k < n; ++k) EXPECT_NE(decode_udp_frame(f, k, d, pl, len), FrameError::ok);
  // A valid CRC over a payload of the wrong size for the type is still rejected.
  uint8_t q[kVelocityPayloadSize] = {};
  const size_t m = encode_udp_frame(h, q, sizeof(q), f);
  EXPECT_EQ(decode_udp_frame(f, m, d, pl, len), FrameError::bad_length);
  h.type = 77;
  const size_t u = encode_udp_frame(h, p, sizeof(p), f);
  EXPECT_EQ(decode_udp_frame(f, u, d, pl, len), FrameError::unknown_type);
}

}  // namespace
}  // namespace storey::drivers::go2

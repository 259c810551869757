#include "drivers/go2/message_codec.hpp"

#include <cmath>
#include <cstring>

namespace storey::drivers::go2 {
namespace {

void put_f32(uint8_t* p, float v) {
  uint32_t u;
  std::memcpy(&u, &v, 4);
  put_u32(p, u);
}
float get_f32(const uint8_t* p) {
  const uint32_t u = get_u32(p);
  float v;
  std::memcpy(&v, &u, 4);
  return v;
}

// Reads n floats at p into out; false if any is NaN/Inf.
bool get_f32s(const uint8_t* p, float* out, int n) {
  bool finite = true;
  for (int i = 0; i < n; ++i) {
    out[i] = get_f32(p + 4 * i);
    finite = finite && std::isfinite(out[i]);
  }
  return finite;
}
void put_f32s(uint8_t* p, const float* in, int n) {
  for (int i = 0; i < n; ++i) put_f32(p + 4 * i, in[i]);
}

}  // namespace

size_t payload_size(uint8_t type) {
  switch (static_cast<MsgType>(type)) {
    case MsgType::state:
      return kStatePayloadSize;
    case MsgType::velocity_command:
      return kVelocityPayloadSize;
    case MsgType::mode_command:
      return kModePayloadSize;
    case MsgType::heartbeat:
      return kHeartbeatPayloadSize;
  }
  return 0;
}

const char* to_string(PayloadError e) {
  switch (e) {
    case PayloadError::ok:
      return "ok";
    case PayloadError::wrong_size:
      return "payload size does not match message type";
    case PayloadError::non_finite:
      return "non-finite float in payload";
    case PayloadError::bad_enum:
      return "enum value out of range";
    case PayloadError::unknown_type:
      return "unknown message type";
  }
  return "unknown";
}

// State payload, 116 bytes (offsets in README.md "State payload").
void encode_state(const RobotState& s, uint8_t* out) {
  put_u64(out + 0, static_cast<uint64_t>(s.stamp_ns));
  put_f32s(out + 8, s.position.data(), 3);
  put_f32s(out + 20, s.velocity.data(), 3);
  put_f32(out + 32, s.yaw_speed);
  put_f32(out + 36, s.body_height);
  put_f32s(out + 40, s.quaternion.data(), 4);
  put_f32s(out + 56, s.gyro.data(), 3);
  put_f32s(out + 68, s.accel.data(), 3);
  put_f32s(out + 80, s.rpy.data(), 3);
  out[92] = s.mode;
  out[93] = s.gait;
  for (int i = 0; i < 4; ++i) put_u16(out + 94 + 2 * i, static_cast<uint16_t>(s.foot_force[i]));
  put_f32(out + 102, s.battery_voltage);
  put_f32(out + 106, s.battery_current);
  out[110] = s.battery_soc;
  out[111] = 0;
  put_u32(out + 112, s.error_code);
}

PayloadError decode_state(const uint8_t* in, size_t len, RobotState& s) {
  if (len != kStatePayloadSize) return PayloadError::wrong_size;
  bool finite = true;
  s.stamp_ns = static_cast<int64_t>(get_u64(in + 0));
  finite &= get_f32s(in + 8, s.position.data(), 3);
  finite &= get_f32s(in + 20, s.velocity.data(), 3);
  finite &= get_f32s(in + 32, &s.yaw_speed, 1);
  finite &= get_f32s(in + 36, &s.body_height, 1);
  finite &= get_f32s(in + 40, s.quaternion.data(), 4);
  finite &= get_f32s(in + 56, s.gyro.data(), 3);
  finite &= get_f32s(in + 68, s.accel.data(), 3);
  finite &= get_f32s(in + 80, s.rpy.data(), 3);
  s.mode = in[92];
  s.gait = in[93];
  for (int i = 0; i < 4; ++i) s.foot_force[i] = static_cast<int16_t>(get_u16(in + 94 + 2 * i));
  finite &= get_f32s(in + 102, &s.battery_voltage, 1);
  finite &= get_f32s(in + 106, &s.battery_current, 1);
  s.battery_soc = in[110];
  s.error_code = get_u32(in + 112);
  return finite ? PayloadError::ok : PayloadError::non_finite;
}

void encode_velocity(const VelocityCommand& c, uint8_t* out) {
  put_u64(out + 0, static_cast<uint64_t>(c.stamp_ns));
  put_f32(out + 8, c.vx);
  put_f32(out + 12, c.vy);
  put_f32(out + 16, c.yaw_rate);
}

PayloadError decode_velocity(const uint8_t* in, size_t len, VelocityCommand& c) {
  if (len != kVelocityPayloadSize) return PayloadError::wrong_size;
  c.stamp_ns = static_cast<int64_t>(get_u64(in + 0));
  bool finite = get_f32s(in + 8, &c.vx, 1);
  finite &= get_f32s(in + 12, &c.vy, 1);
  finite &= get_f32s(in + 16, &c.yaw_rate, 1);
  return finite ? PayloadError::ok : PayloadError::non_finite;
}

void encode_mode(const ModeCommand& c, uint8_t* out) {
  put_u64(out + 0, static_cast<uint64_t>(c.stamp_ns));
  out[8] = static_cast<uint8_t>(c.mode);
}

PayloadError decode_mode(const uint8_t* in, size_t len, ModeCommand& c) {
  if (len != kModePayloadSize) return PayloadError::wrong_size;
  c.stamp_ns = static_cast<int64_t>(get_u64(in + 0));
  if (in[8] >= kModeRequestCount) return PayloadError::bad_enum;
  c.mode = static_cast<ModeRequest>(in[8]);
  return PayloadError::ok;
}

void encode_heartbeat(const Heartbeat& h, uint8_t* out) {
  put_u64(out + 0, static_cast<uint64_t>(h.stamp_ns));
  put_u32(out + 8, h.counter);
  out[12] = h.status;
}

PayloadError decode_heartbeat(const uint8_t* in, size_t len, Heartbeat& h) {
  if (len != kHeartbeatPayloadSize) return PayloadError::wrong_size;
  h.stamp_ns = static_cast<int64_t>(get_u64(in + 0));
  h.counter = get_u32(in + 8);
  h.status = in[12];
  return PayloadError::ok;
}

}  // namespace storey::drivers::go2

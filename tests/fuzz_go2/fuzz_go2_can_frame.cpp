// libFuzzer target: the CAN-over-UDP datagram decoder, the multi-frame transfer reassembler and
// the Go2 payload decoders (drivers/can/can_frame, can_transfer; drivers/go2/message_codec), fed
// as the host side of the Go2 CAN link is. Input: records of [kind byte][16 or 72 bytes].
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "drivers/can/can_frame.hpp"
#include "drivers/can/can_transfer.hpp"
#include "drivers/go2/message_codec.hpp"

using namespace storey::drivers;

namespace {
constexpr uint32_t kBase = 0x200;
constexpr size_t kBodyHeader = 12;

void setup(can::CanReassembler& r) {
  // Host side: state and heartbeat from the robot (ids base + 0x10 + type).
  r.add_stream(kBase + 0x10 + 1, kBodyHeader + go2::kStatePayloadSize);
  r.add_stream(kBase + 0x10 + 4, kBodyHeader + go2::kHeartbeatPayloadSize);
  // Robot side: commands and heartbeat from the host.
  r.add_stream(kBase + 2, kBodyHeader + go2::kVelocityPayloadSize);
  r.add_stream(kBase + 3, kBodyHeader + go2::kModePayloadSize);
  r.add_stream(kBase + 4, kBodyHeader + go2::kHeartbeatPayloadSize);
}

void deliver(const can::CanReassembler& r) {
  const uint8_t type = static_cast<uint8_t>((r.last_id() - kBase) & 0x0F);
  const uint8_t* p = r.body() + kBodyHeader;
  const size_t n = r.body_len() - kBodyHeader;
  if (n != go2::payload_size(type)) __builtin_trap();  // reassembler contract
  go2::RobotState s;
  go2::VelocityCommand v;
  go2::ModeCommand m;
  go2::Heartbeat h;
  switch (static_cast<go2::MsgType>(type)) {
    case go2::MsgType::state:
      go2::decode_state(p, n, s);
      break;
    case go2::MsgType::velocity_command:
      go2::decode_velocity(p, n, v);
      break;
    case go2::MsgType::mode_command:
      go2::decode_mode(p, n, m);
      break;
    case go2::MsgType::heartbeat:
      go2::decode_heartbeat(p, n, h);
      break;
  }
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  can::CanReassembler r;
  setup(r);
  size_t i = 0;
  while (i < size) {
    const bool fd = data[i] & 1;
    const size_t n = fd ? can::kCanFdDatagram : can::kCanClassicDatagram;
    ++i;
    uint8_t rec[can::kCanFdDatagram] = {};
    const size_t take = size - i < n ? size - i : n;
    std::memcpy(rec, data + i, take);
    i += take;
    can::CanFrame f;
    // Ids are mostly steered onto registered streams so that the reassembler is reached.
    if (can::decode_can_datagram(rec, (data[i - take - 1] & 2) ? take : n, f) !=
        can::CanDatagramError::ok) {
      continue;
    }
    if (!(data[i - take - 1] & 4)) f.id = kBase + ((data[i - take - 1] >> 3) & 0x1F);
    if (r.push(f) == can::CanReassembler::Result::complete) deliver(r);
  }
  // Structure-aware half: a valid transfer from the input, then one frame byte changed.
  if (size >= 4) {
    const uint8_t type = static_cast<uint8_t>(1 + data[0] % 4);
    const uint32_t id = kBase + (type == 1 ? 0x10u : 0u) + type;
    const size_t body_len = kBodyHeader + go2::payload_size(type);
    uint8_t body[kBodyHeader + go2::kMaxPayloadSize] = {};
    std::memcpy(body, data, size < body_len ? size : body_len);
    can::CanFrame frames[can::kMaxFramesPerTransfer];
    const bool fd = data[1] & 1;
    const size_t nf =
        can::encode_transfer(id, body, body_len, data[2], fd, frames, can::kMaxFramesPerTransfer);
    can::CanReassembler r2;
    setup(r2);
    const size_t victim = data[3] % (nf + 1);  // nf: no mutation, must complete
    if (victim < nf) frames[victim].data[data[2] % frames[victim].len] ^= 0x5A;
    can::CanReassembler::Result last{};
    for (size_t k = 0; k < nf; ++k) last = r2.push(frames[k]);
    if (victim == nf && last != can::CanReassembler::Result::complete) __builtin_trap();
    if (last == can::CanReassembler::Result::complete) deliver(r2);
  }
  return 0;
}

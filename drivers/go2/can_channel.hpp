// MessageChannel over CAN: each message is one multi-frame transfer (drivers/can/can_transfer.hpp)
// on an id that encodes direction and type:
//   id = base_id + 0x00 + type   host -> robot (commands win arbitration: lower id)
//   id = base_id + 0x10 + type   robot -> host
// transfer body = sequence u32 | timestamp u64 | payload (message_codec.hpp), then CRC-32.
// Classic 8-byte frames or CAN FD 64-byte frames (CanChannelOptions::fd).
#pragma once

#include <memory>

#include "drivers/can/can_transfer.hpp"
#include "drivers/can/can_transport.hpp"
#include "drivers/go2/message_channel.hpp"

namespace storey::drivers::go2 {

struct CanChannelOptions {
  uint32_t base_id = 0x200;  // 11-bit standard ids base..base+0x1F
  bool fd = false;           // send CAN FD frames (receive accepts both)
};

inline constexpr size_t kCanBodyHeader = 12;  // sequence u32 + timestamp u64

uint32_t can_id_for(const CanChannelOptions& o, Role sender, MsgType type);

class CanChannel final : public MessageChannel {
 public:
  CanChannel(Role role, std::unique_ptr<can::CanTransport> transport,
             const CanChannelOptions& options);
  bool ok() const override { return transport_ && transport_->ok(); }
  const char* error() const override;
  LinkStatus send(const FrameHeader& h, const uint8_t* payload, size_t len) override;
  RxStatus receive(ChannelMessage& out) override;
  void add_transport_health(LinkHealth& h) const override;
  can::CanTransport& transport() { return *transport_; }
  uint16_t local_port() const override { return transport_ ? transport_->local_port() : 0; }

 private:
  Role role_;
  std::unique_ptr<can::CanTransport> transport_;
  CanChannelOptions options_;
  can::CanReassembler reassembler_;
  uint8_t counter_[8] = {};  // per message type transfer counters
};

}  // namespace storey::drivers::go2

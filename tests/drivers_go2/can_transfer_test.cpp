#include "drivers/can/can_transfer.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "drivers/can/can_frame.hpp"

namespace storey::drivers::can {
namespace {

std::vector<uint8_t> body(size_t n) {
  std::vector<uint8_t> b(n);
  for (size_t i = 0; i < n; ++i) b[i] = static_cast<uint8_t>(i * 7 + 3);
  return b;
}

class CanTransferTest : public ::testing::TestWithParam<bool> {};

TEST_P(CanTransferTest, RoundTripThroughDatagrams) {
  const bool fd = GetParam();
  const auto b = body(128);  // Go2 state: 12-byte header + 116-byte payload
  CanFrame frames[kMaxFramesPerTransfer];
  const size_t n = encode_transfer(0x211, b.data(), b.size(), 5, fd, frames, kMaxFramesPerTransfer);
  ASSERT_EQ(n, fd ? 3u : 19u);
  CanReassembler r;
  ASSERT_TRUE(r.add_stream(0x211, b.size()));
  for (size_t i = 0; i < n; ++i) {
    EXPECT_LE(frames[i].len, fd ? 64 : 8);
    EXPECT_TRUE(fd ? canfd_valid_len(frames[i].len) : true);
    // Through the CAN-over-UDP byte form, as the transport carries it.
    uint8_t d[kCanFdDatagram];
    const size_t dn = encode_can_datagram(frames[i], d);
    EXPECT_EQ(dn, fd ? kCanFdDatagram : kCanClassicDatagram);
    CanFrame g;
    ASSERT_EQ(decode_can_datagram(d, dn, g), CanDatagramError::ok);
    const auto res = r.push(g);
    EXPECT_EQ(res,
              i + 1 == n ? CanReassembler::Result::complete : CanReassembler::Result::in_progress);
  }
  ASSERT_EQ(r.body_len(), b.size());
  EXPECT_EQ(std::memcmp(r.body(), b.data(), b.size()), 0);
}

TEST_P(CanTransferTest, LostFrameDropsTransferAndNextOneRecovers) {
  const bool fd = GetParam();
  const auto b = body(128);
  CanFrame a[kMaxFramesPerTransfer], c[kMaxFramesPerTransfer];
  const size_t n = encode_transfer(0x211, b.data(), b.size(), 0, fd, a, kMaxFramesPerTransfer);
  encode_transfer(0x211, b.data(), b.size(), 1, fd, c, kMaxFramesPerTransfer);
  CanReassembler r;
  r.add_stream(0x211, b.size());
  for (size_t i = 0; i < n; ++i) {
    if (i == 1) continue;  // lost on the bus
    const auto res = r.push(a[i]);
    if (i > 1) {
      EXPECT_NE(res, CanReassembler::Result::complete);
    }
  }
  CanReassembler::Result last{};
  for (size_t i = 0; i < n; ++i) last = r.push(c[i]);
  EXPECT_EQ(last, CanReassembler::Result::complete);
}

TEST_P(CanTransferTest, CorruptedDataIsACrcFailure) {
  const bool fd = GetParam();
  const auto b = body(24);
  CanFrame a[kMaxFramesPerTransfer];
  const size_t n = encode_transfer(0x202, b.data(), b.size(), 0, fd, a, kMaxFramesPerTransfer);
  a[0].data[3] ^= 0x10;
  CanReassembler r;
  r.add_stream(0x202, b.size());
  CanReassembler::Result last{};
  for (size_t i = 0; i < n; ++i) last = r.push(a[i]);
  EXPECT_EQ(last, CanReassembler::Result::bad_crc);
}

INSTANTIATE_TEST_SUITE_P(ClassicAndFd, CanTransferTest, ::testing::Values(false, true),
                         [](const auto& info) { return info.param ? "fd" : "classic"; });

TEST(CanTransfer, MixedCountersAreNotSpliced) {
  const auto b = body(40);
  CanFrame a[kMaxFramesPerTransfer], c[kMaxFramesPerTransfer];
  const size_t n = encode_transfer(0x202, b.data(), b.size(), 2, false, a, kMaxFramesPerTransfer);
  encode_transfer(0x202, b.data(), b.size(), 3, false, c, kMaxFramesPerTransfer);
  CanReassembler r;
  r.add_stream(0x202, b.size());
  r.push(a[0]);
  r.push(a[1]);
  EXPECT_EQ(r.push(c[2]), CanReassembler::Result::bad_frame);  // tail of another transfer
  for (size_t i = 3; i < n; ++i) EXPECT_NE(r.push(c[i]), CanReassembler::Result::complete);
  EXPECT_GE(r.incomplete_transfers(), 1u);
}

TEST(CanFrame, DatagramValidation) {
  CanFrame f;
  uint8_t d[kCanFdDatagram] = {};
  EXPECT_EQ(decode_can_datagram(d, 15, f), CanDatagramError::bad_size);
  d[4] = 9;  // classic frame with 9 data bytes
  EXPECT_EQ(decode_can_datagram(d, kCanClassicDatagram, f), CanDatagramError::bad_len);
  d[4] = 13;  // not an FD size
  EXPECT_EQ(decode_can_datagram(d, kCanFdDatagram, f), CanDatagramError::bad_len);
  d[4] = 12;
  EXPECT_EQ(decode_can_datagram(d, kCanFdDatagram, f), CanDatagramError::ok);
  EXPECT_TRUE(f.fd);
  EXPECT_EQ(canfd_round_len(9), 12u);
  EXPECT_EQ(canfd_round_len(49), 64u);
}

}  // namespace
}  // namespace storey::drivers::can

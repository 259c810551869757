// SocketCAN on a virtual CAN bus. Needs AF_CAN and a vcan interface:
//   sudo modprobe vcan && sudo ip link add dev vcan0 type vcan && sudo ip link set up vcan0
// (STOREY_VCAN=name picks another interface). Where the kernel has no CAN (EAFNOSUPPORT, as on
// this project's CI machine) or no vcan0 exists, the tests skip and say what was not tested.
#include "drivers/can/socket_can_transport.hpp"

#include <errno.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <memory>

#include "drivers/go2/framed_link.hpp"
#include "test_helpers.hpp"

namespace storey::drivers::can {
namespace {

using go2::testing::spin_until;

std::string vcan_name() {
  const char* e = std::getenv("STOREY_VCAN");
  return e ? e : "vcan0";
}

// Skips unless a SocketCAN transport opens on the vcan interface.
#define REQUIRE_VCAN(transport)                                                              \
  if (!(transport).ok()) {                                                                   \
    if ((transport).errno_value() == EAFNOSUPPORT) {                                         \
      GTEST_SKIP() << "SocketCAN not tested: kernel has no AF_CAN (" << (transport).error()  \
                   << "). Run on a kernel with CAN: modprobe vcan && ip link add dev vcan0 " \
                      "type vcan && ip link set up vcan0";                                   \
    }                                                                                        \
    GTEST_SKIP() << "SocketCAN not tested: " << (transport).error()                          \
                 << ". Create the bus: ip link add dev " << vcan_name()                      \
                 << " type vcan && ip link set up " << vcan_name();                          \
  }

SocketCanOptions options() {
  SocketCanOptions o;
  o.interface = vcan_name();
  return o;
}

TEST(SocketCan, ClassicAndFdFramesCrossTheBusWithFilters) {
  SocketCanTransport a(options());
  REQUIRE_VCAN(a);
  SocketCanTransport b(options());
  ASSERT_TRUE(b.ok()) << b.error();
  const CanFilter only_0x123{0x123, kCanSffMask | kCanEffFlag | kCanRtrFlag};
  ASSERT_TRUE(b.set_filters(&only_0x123, 1));
  CanFrame other;
  other.id = 0x124;
  other.len = 1;
  ASSERT_EQ(a.send(other), CanIoStatus::ok);
  CanFrame f;
  f.id = 0x123;
  f.len = 8;
  for (int i = 0; i < 8; ++i) f.data[i] = static_cast<uint8_t>(i + 1);
  ASSERT_EQ(a.send(f), CanIoStatus::ok);
  CanFrame fd;
  fd.id = 0x123;
  fd.fd = true;
  fd.len = 64;
  fd.data[63] = 0xAA;
  const CanIoStatus fd_sent = a.send(fd);  // vcan with MTU 16 refuses FD frames
  CanFrame g;
  ASSERT_TRUE(spin_until([] {}, [&] { return b.receive(g) == CanIoStatus::ok; }, 1000));
  EXPECT_EQ(g.id, 0x123u) << "filter let 0x124 through";
  EXPECT_EQ(g.len, 8);
  EXPECT_EQ(g.data[7], 8);
  if (fd_sent == CanIoStatus::ok) {
    ASSERT_TRUE(spin_until([] {}, [&] { return b.receive(g) == CanIoStatus::ok; }, 1000));
    EXPECT_TRUE(g.fd);
    EXPECT_EQ(g.data[63], 0xAA);
  }
  EXPECT_EQ(b.stats().bus_off_events, 0u);
}

TEST(SocketCan, Go2LinkOverVcan) {
  SocketCanTransport probe(options());
  REQUIRE_VCAN(probe);
  const int64_t t0 = go2::testing::mono_ns();
  go2::CanLink link(std::make_unique<SocketCanTransport>(options()), go2::CanChannelOptions{},
                    go2::LinkOptions{}, t0);
  ASSERT_TRUE(link.ok()) << link.error();
  go2::CanChannel robot(go2::Role::robot, std::make_unique<SocketCanTransport>(options()),
                        go2::CanChannelOptions{});
  ASSERT_TRUE(robot.ok());
  uint8_t p[go2::kStatePayloadSize];
  go2::RobotState s;
  s.position = {1, 2, 3};
  go2::encode_state(s, p);
  go2::FrameHeader h;
  h.type = static_cast<uint8_t>(go2::MsgType::state);
  ASSERT_EQ(robot.send(h, p, sizeof(p)), go2::LinkStatus::ok);
  ASSERT_TRUE(spin_until([&] { link.poll(go2::testing::mono_ns()); },
                         [&] { return link.has_state(); }, 1000));
  EXPECT_EQ(link.latest_state().position, s.position);
}

}  // namespace
}  // namespace storey::drivers::can

// UDP and CAN-over-UDP links against the robot stand-in over loopback (ephemeral ports).
#include "drivers/go2/framed_link.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <memory>
#include <random>

#include "drivers/can/can_over_udp_transport.hpp"
#include "drivers/go2/robot_standin.hpp"
#include "test_helpers.hpp"

namespace storey::drivers::go2 {
namespace {

using testing::mono_ns;
using testing::spin_until;
constexpr int64_t kMs = 1'000'000;

enum class Kind { udp, can_classic, can_fd };

struct Pair {
  std::unique_ptr<RobotStandin> robot;
  std::unique_ptr<FramedLink> link;
};

Pair make_pair(Kind kind, const LinkOptions& lo = LinkOptions{}) {
  StandinOptions so;
  so.transport = kind == Kind::udp ? StandinTransport::udp : StandinTransport::can_over_udp;
  so.local = {"127.0.0.1", 0};
  so.host = {"127.0.0.1", 0};  // learn the host from its first valid frame
  so.can.fd = kind == Kind::can_fd;
  so.state_period_ns = 0;  // publish on every step
  Pair p;
  const int64_t now = mono_ns();
  p.robot = std::make_unique<RobotStandin>(so, now);
  EXPECT_TRUE(p.robot->ok()) << p.robot->error();
  const UdpEndpoint robot{"127.0.0.1", p.robot->local_port()};
  const UdpEndpoint local{"127.0.0.1", 0};
  if (kind == Kind::udp) {
    p.link = std::make_unique<UdpLink>(local, robot, lo, now);
  } else {
    CanChannelOptions co;
    co.fd = kind == Kind::can_fd;
    p.link = std::make_unique<CanOverUdpLink>(local, robot, co, lo, now);
  }
  EXPECT_TRUE(p.link->ok()) << p.link->error();
  return p;
}

class FramedLinkTest : public ::testing::TestWithParam<Kind> {};

TEST_P(FramedLinkTest, StateReachesLinkAndCommandsReachRobot) {
  Pair p = make_pair(GetParam());
  RobotState given;
  given.position = {3.0f, -1.0f, 0.25f};
  given.mode = 3;
  given.battery_soc = 55;
  given.foot_force = {10, 20, 30, 40};
  p.robot->set_state(given);
  // The host's first poll sends a heartbeat: the stand-in learns where to publish.
  ASSERT_TRUE(spin_until(
      [&] {
        const int64_t t = mono_ns();
        p.link->poll(t);
        p.robot->step(t);
      },
      [&] { return p.link->has_state(); }));
  const RobotState& s = p.link->latest_state();
  EXPECT_EQ(s.position, given.position);
  EXPECT_EQ(s.mode, 3);
  EXPECT_EQ(s.battery_soc, 55);
  EXPECT_EQ(s.foot_force, given.foot_force);
  EXPECT_GT(s.rx_stamp_ns, 0);

  const int64_t t = mono_ns();
  VelocityCommand v{t, 0.5f, -0.25f, 0.75f};
  ASSERT_EQ(p.link->send_velocity(v, t), LinkStatus::ok);
  ASSERT_EQ(p.link->send_mode(ModeCommand{t, ModeRequest::stand_down}, t), LinkStatus::ok);
  ASSERT_TRUE(
      spin_until([&] { p.robot->step(mono_ns()); }, [&] { return p.robot->mode_commands() == 1; }));
  EXPECT_EQ(p.robot->velocity_commands(), 1u);
  const VelocityCommand& got = p.robot->last_velocity().velocity;
  EXPECT_EQ(got.stamp_ns, t);
  EXPECT_EQ(got.vx, 0.5f);
  EXPECT_EQ(got.vy, -0.25f);
  EXPECT_EQ(got.yaw_rate, 0.75f);
  EXPECT_EQ(p.robot->last_mode().mode.mode, ModeRequest::stand_down);
  EXPECT_GE(p.robot->heartbeats(), 1u);
  const LinkHealth h = p.link->health(mono_ns());
  EXPECT_EQ(h.crc_failures, 0u);
  EXPECT_EQ(h.decode_errors, 0u);
  EXPECT_EQ(h.commands_sent, 2u);
}

TEST_P(FramedLinkTest, IntegratingStandinMovesWhenCommanded) {
  Pair p = make_pair(GetParam());
  const int64_t t = mono_ns();  // injected from here on, on the links' own time base
  p.link->poll(t);              // heartbeat out
  ASSERT_TRUE(spin_until([&] { p.robot->step(t); }, [&] { return p.robot->heartbeats() > 0; }));
  ASSERT_EQ(p.link->send_velocity(VelocityCommand{t, 1.0f, 0.0f, 0.0f}, t), LinkStatus::ok);
  ASSERT_TRUE(
      spin_until([&] { p.robot->step(t); }, [&] { return p.robot->velocity_commands() == 1; }));
  // Injected times: 0.2 s at 1 m/s forward.
  for (int i = 1; i <= 20; ++i) p.robot->step(t + i * 10 * kMs);
  EXPECT_NEAR(p.robot->state().position[0], 0.2f, 1e-4f);
  EXPECT_EQ(p.robot->state().mode, static_cast<uint8_t>(RobotModeId::locomotion));
  // Commander goes quiet for longer than the command timeout: the robot stops.
  p.robot->step(t + 900 * kMs);
  const float x = p.robot->state().position[0];
  p.robot->step(t + 1000 * kMs);
  EXPECT_EQ(p.robot->state().position[0], x);
}

TEST_P(FramedLinkTest, StaleCommandIsRefusedAndNeverSent) {
  LinkOptions lo;
  lo.max_command_age_ns = 40 * kMs;
  Pair p = make_pair(GetParam(), lo);
  const int64_t t = mono_ns();
  EXPECT_EQ(p.link->send_velocity(VelocityCommand{t - 41 * kMs, 1, 0, 0}, t),
            LinkStatus::stale_command);
  EXPECT_EQ(p.link->send_velocity(VelocityCommand{t, NAN, 0, 0}, t), LinkStatus::invalid_command);
  EXPECT_EQ(p.link->send_mode(ModeCommand{t - 100 * kMs, ModeRequest::stop}, t),
            LinkStatus::stale_command);
  ASSERT_EQ(p.link->send_mode(ModeCommand{t, ModeRequest::stop}, t), LinkStatus::ok);
  ASSERT_TRUE(
      spin_until([&] { p.robot->step(mono_ns()); }, [&] { return p.robot->mode_commands() == 1; }));
  EXPECT_EQ(p.robot->velocity_commands(), 0u);
  const LinkHealth h = p.link->health(t);
  EXPECT_EQ(h.stale_commands_refused, 2u);
  EXPECT_EQ(h.invalid_commands_refused, 1u);
}

TEST_P(FramedLinkTest, LinkLossDetectedWithinTimeoutAndReconnect) {
  LinkOptions lo;
  lo.state_timeout_ns = 100 * kMs;
  Pair p = make_pair(GetParam(), lo);
  const int64_t t = mono_ns();
  ASSERT_TRUE(spin_until(
      [&] {
        p.link->poll(t);
        p.robot->step(t);
      },
      [&] { return p.link->has_state(); }));
  // The robot goes silent; the control task polls every 20 ms (injected times).
  const int64_t last = p.link->latest_state().rx_stamp_ns;
  int64_t detected = -1;
  for (int64_t now = last; now <= last + 200 * kMs; now += 20 * kMs) {
    p.link->poll(now);
    if (p.link->health(now).link_lost) {
      detected = now;
      break;
    }
  }
  ASSERT_GE(detected, 0);
  EXPECT_GT(detected - last, lo.state_timeout_ns);
  EXPECT_LE(detected - last, lo.state_timeout_ns + 20 * kMs);  // within one control period
  EXPECT_EQ(p.link->health(detected).link_lost_events, 1u);
  // State flows again: reconnect counted.
  const int64_t later = detected + 50 * kMs;
  ASSERT_TRUE(spin_until(
      [&] {
        p.robot->step(later);
        p.link->poll(later);
      },
      [&] { return !p.link->health(later).link_lost; }));
  EXPECT_EQ(p.link->health(later).reconnects, 1u);
}

INSTANTIATE_TEST_SUITE_P(Transports, FramedLinkTest,
                         ::testing::Values(Kind::udp, Kind::can_classic, Kind::can_fd),
                         [](const auto& info) {
                           switch (info.param) {
                             case Kind::udp:
                               return "udp";
                             case Kind::can_classic:
                               return "can_classic";
                             default:
                               return "can_fd";
                           }
                         });

// A hand-driven robot side: raw frames with chosen sequence numbers and corruption.
TEST(UdpLink, SequenceGapsAndCrcFailuresAreCounted) {
  UdpChannel robot(Role::robot, {"127.0.0.1", 0}, {"127.0.0.1", 0});
  ASSERT_TRUE(robot.ok());
  const int64_t t0 = mono_ns();
  UdpLink link({"127.0.0.1", 0}, {"127.0.0.1", robot.local_port()}, LinkOptions{}, t0);
  link.poll(t0);  // heartbeat: robot learns the host
  ChannelMessage m;
  ASSERT_TRUE(spin_until([] {}, [&] { return robot.receive(m) == RxStatus::message; }));

  uint8_t p[kStatePayloadSize];
  encode_state(RobotState{}, p);
  for (uint32_t seq : {0u, 1u, 2u, 6u, 7u}) {  // 3, 4, 5 lost
    FrameHeader h;
    h.type = static_cast<uint8_t>(MsgType::state);
    h.sequence = seq;
    ASSERT_EQ(robot.send(h, p, sizeof(p)), LinkStatus::ok);
  }
  // A corrupted frame and some garbage, sent from a raw socket to the link's port.
  can::UdpSocket raw;
  ASSERT_TRUE(raw.open({"127.0.0.1", 0}, {"127.0.0.1", link.channel().local_port()}));
  FrameHeader h;
  h.type = static_cast<uint8_t>(MsgType::state);
  h.sequence = 8;
  h.flags = kFlagFromRobot;
  uint8_t f[kUdpMaxFrameSize];
  const size_t n = encode_udp_frame(h, p, sizeof(p), f);
  f[40] ^= 0x01;
  ASSERT_EQ(raw.send(f, n), can::UdpSocket::Io::ok);
  const uint8_t junk[] = {1, 2, 3};
  ASSERT_EQ(raw.send(junk, sizeof(junk)), can::UdpSocket::Io::ok);
  ASSERT_TRUE(spin_until([&] { link.poll(mono_ns()); },
                         [&] {
                           const LinkHealth hh = link.health(mono_ns());
                           return hh.states_received == 5 && hh.crc_failures == 1 &&
                                  hh.decode_errors == 1;
                         }));
  EXPECT_EQ(link.health(mono_ns()).sequence_gaps, 3u);
}

TEST(CanOverUdpLink, CorruptedTransferIsACrcFailure) {
  can::CanOverUdpTransport robot({"127.0.0.1", 0}, {"127.0.0.1", 0});
  ASSERT_TRUE(robot.ok());
  const int64_t t0 = mono_ns();
  CanOverUdpLink link({"127.0.0.1", 0}, {"127.0.0.1", robot.local_port()}, CanChannelOptions{},
                      LinkOptions{}, t0);
  link.poll(t0);
  can::CanFrame f;
  ASSERT_TRUE(spin_until([] {}, [&] { return robot.receive(f) == can::CanIoStatus::ok; }));
  // Build a state transfer by hand and flip one payload bit.
  uint8_t body[kCanBodyHeader + kStatePayloadSize] = {};
  encode_state(RobotState{}, body + kCanBodyHeader);
  can::CanFrame frames[can::kMaxFramesPerTransfer];
  const uint32_t id = can_id_for(CanChannelOptions{}, Role::robot, MsgType::state);
  const size_t n =
      can::encode_transfer(id, body, sizeof(body), 0, false, frames, can::kMaxFramesPerTransfer);
  frames[4].data[2] ^= 0x80;
  for (size_t i = 0; i < n; ++i) ASSERT_EQ(robot.send(frames[i]), can::CanIoStatus::ok);
  // And a good one after it.
  const size_t n2 =
      can::encode_transfer(id, body, sizeof(body), 1, false, frames, can::kMaxFramesPerTransfer);
  for (size_t i = 0; i < n2; ++i) ASSERT_EQ(robot.send(frames[i]), can::CanIoStatus::ok);
  ASSERT_TRUE(spin_until([&] { link.poll(mono_ns()); }, [&] { return link.has_state(); }));
  EXPECT_EQ(link.health(mono_ns()).crc_failures, 1u);
}

// Random datagrams at the link (and at the stand-in): counted, never a crash, never a state.
TEST(FramedLinks, RandomGarbageNeverCrashesNorYieldsState) {
  std::mt19937 rng(1234);
  for (Kind kind : {Kind::udp, Kind::can_classic, Kind::can_fd}) {
    Pair p = make_pair(kind);
    can::UdpSocket raw_to_link, raw_to_robot;
    ASSERT_TRUE(raw_to_link.open({"127.0.0.1", 0}, {"127.0.0.1", p.link->channel().local_port()}));
    ASSERT_TRUE(raw_to_robot.open({"127.0.0.1", 0}, {"127.0.0.1", p.robot->local_port()}));
    uint8_t buf[200];
    for (int i = 0; i < 2000; ++i) {
      // Mostly plausible sizes (frame and CAN datagram sizes) with random content.
      const size_t sizes[] = {16, 72, 24 + kStatePayloadSize, 44, 3, 0, 199};
      const size_t n = sizes[rng() % 7];
      for (size_t k = 0; k < n; ++k) buf[k] = static_cast<uint8_t>(rng());
      if (n >= 2 && (rng() & 1)) {  // valid magic to reach deeper checks
        buf[0] = kUdpMagic0;
        buf[1] = kUdpMagic1;
      }
      raw_to_link.send(buf, n);
      raw_to_robot.send(buf, n);
      // The link polls (its heartbeats reach the stand-in's socket, but the stand-in only
      // drains on step(), so every state the link could see would come from garbage); the
      // stand-in drains after, and then must not have learnt a host from garbage either.
      if (i % 64 == 0) p.link->poll(mono_ns());
    }
    for (int k = 0; k < 50; ++k) {
      p.link->poll(mono_ns());
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    p.robot->step(mono_ns());
    const LinkHealth h = p.link->health(mono_ns());
    EXPECT_EQ(h.states_received, 0u);
    EXPECT_GT(h.decode_errors + h.crc_failures, 0u);
    EXPECT_EQ(p.robot->velocity_commands(), 0u);
    EXPECT_EQ(p.robot->mode_commands(), 0u);
    EXPECT_GT(p.robot->dropped(), 0u);
  }
}

}  // namespace
}  // namespace storey::drivers::go2

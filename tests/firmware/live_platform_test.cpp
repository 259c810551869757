// LivePlatform (firmware/live_platform.hpp): VLP-16 packets over loopback UDP into deskewed
// world-frame scans, the robot link's state into odometry and the pose history, commands out,
// and the faults it must report rather than hide (no pose, frozen pose, link loss, garbage).
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <thread>
#include <vector>

#include "drivers/lidar/vlp16.hpp"
#include "firmware/live_platform.hpp"

namespace storey::firmware {
namespace {

namespace go2 = drivers::go2;
namespace lidar = drivers::lidar;

// A robot link under the test's control: poll() "receives" `next` (sample stamp = now unless
// frozen), health reports loss after 100 ms without a state, stale commands are refused as the
// real links do.
class FakeLink final : public go2::RobotLink {
 public:
  go2::RobotState next;
  bool deliver = true, freeze_stamp = false;
  std::vector<go2::VelocityCommand> sent;
  std::vector<go2::ModeCommand> modes;

  bool ok() const override { return true; }
  const char* error() const override { return ""; }
  const char* name() const override { return "fake"; }
  int poll(int64_t now) override {
    if (!deliver) return 0;
    state_ = next;
    if (!freeze_stamp) sample_ = now;
    state_.stamp_ns = sample_;
    state_.rx_stamp_ns = now;
    have_ = true;
    last_rx_ = now;
    return 1;
  }
  const go2::RobotState& latest_state() const override { return state_; }
  bool has_state() const override { return have_; }
  go2::LinkStatus send_velocity(const go2::VelocityCommand& c, int64_t now) override {
    if (now - c.stamp_ns > 40'000'000) return go2::LinkStatus::stale_command;
    sent.push_back(c);
    return go2::LinkStatus::ok;
  }
  go2::LinkStatus send_mode(const go2::ModeCommand& c, int64_t) override {
    modes.push_back(c);
    return go2::LinkStatus::ok;
  }
  go2::LinkHealth health(int64_t now) override {
    go2::LinkHealth h;
    h.last_state_age_ns = have_ ? now - last_rx_ : -1;
    h.link_lost = !have_ || now - last_rx_ > 100'000'000;
    return h;
  }

 private:
  go2::RobotState state_;
  bool have_ = false;
  int64_t last_rx_ = 0, sample_ = 0;
};

go2::RobotState body_at(double x, double y, double yaw) {
  go2::RobotState s;
  s.position = {float(x), float(y), 0.32f};
  s.body_height = 0.32f;
  s.quaternion = {float(std::cos(yaw / 2)), 0.f, 0.f, float(std::sin(yaw / 2))};
  return s;
}

struct Rig {
  rt::MonotonicClock clock;
  FakeLink* link = nullptr;
  std::unique_ptr<LivePlatform> platform;
  int tx = -1;
  sockaddr_in dst{};
  uint32_t us = 0;
  int azimuth = 0;  // cdeg of the next firing

  Rig() {
    LivePlatformOptions o;
    o.params.sensor.sensor_address = "127.0.0.1";
    o.params.sensor.host_address = "127.0.0.1";
    o.params.sensor.mounting_xyz_m = {0.28, 0.0, 0.12};
    o.data_port = 0;
    auto l = std::make_unique<FakeLink>();
    link = l.get();
    platform = std::make_unique<LivePlatform>(o, std::move(l), clock);
    const auto st = platform->open();
    EXPECT_TRUE(st.ok) << st.error;
    EXPECT_GE(platform->lidar_fd(), 0);
    tx = socket(AF_INET, SOCK_DGRAM, 0);
    dst.sin_family = AF_INET;
    dst.sin_port = htons(platform->lidar_port());
    dst.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  }
  ~Rig() { close(tx); }
  void send(const uint8_t* b, size_t n) {
    ASSERT_EQ(sendto(tx, b, n, 0, reinterpret_cast<const sockaddr*>(&dst), sizeof dst), ssize_t(n));
  }
  // One packet of 24 firings, every laser returning at `range_m`, azimuth advancing 0.2 deg.
  void send_packet(float range_m) {
    std::array<lidar::Vlp16Firing, lidar::kVlp16FiringsPerPacket> f{};
    for (auto& x : f) {
      x.azimuth_cdeg = uint16_t(azimuth);
      x.range_m.fill(range_m);
      x.reflectivity.fill(100);
      azimuth = (azimuth + 20) % 36000;
    }
    uint8_t buf[1206];
    ASSERT_EQ(lidar::vlp16_encode_firings(f, us, lidar::Vlp16ReturnMode::strongest, 0x22, buf),
              1206u);
    us += 1327;
    send(buf, sizeof buf);
  }
  // Sends `rotations` turns (75 packets each) while polling the link every 10 packets, and
  // collects every scan delivered.
  std::vector<ScanBuffer> run(double rotations, float range_m) {
    std::vector<ScanBuffer> scans;
    ScanBuffer b;
    b.points_m.reserve(70000);
    PoseSample p;
    for (int i = 0; i < int(rotations * 75); ++i) {
      if (i % 10 == 0) platform->latest_pose(p);
      send_packet(range_m);
      std::this_thread::sleep_for(std::chrono::microseconds(300));
      while (platform->take_scan(b)) scans.push_back(b);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    while (platform->take_scan(b)) scans.push_back(b);
    return scans;
  }
};

TEST(LivePlatform, PoseSampleIsTheGroundPointYawAndBodyVelocity) {
  go2::RobotState s = body_at(1.0, 2.0, M_PI / 2);
  s.velocity = {0.f, 0.5f, 0.f};  // odometry frame: moving +y = body forward
  s.yaw_speed = 0.2f;
  const PoseSample p = LivePlatform::to_pose_sample(s, 0.32, 7.0);
  EXPECT_NEAR(p.x_m, 1.0, 1e-6);
  EXPECT_NEAR(p.y_m, 2.0, 1e-6);
  EXPECT_NEAR(p.z_m, 0.0, 1e-6);
  EXPECT_NEAR(p.yaw_rad, M_PI / 2, 1e-6);
  EXPECT_NEAR(p.vx_mps, 0.5, 1e-6);
  EXPECT_NEAR(p.vy_mps, 0.0, 1e-6);
  EXPECT_NEAR(p.yaw_rate_rps, 0.2, 1e-6);
  EXPECT_EQ(p.stamp_s, 7.0);
}

TEST(LivePlatform, ScansAreDeskewedIntoTheWorldFrame) {
  Rig rig;
  const double yaw = M_PI / 2;
  rig.link->next = body_at(2.0, 1.0, yaw);
  const auto scans = rig.run(3.2, 5.0f);
  ASSERT_GE(scans.size(), 2u);
  // Sensor = body centre (2, 1, 0.32) + R(yaw) * mount (0.28, 0, 0.12) = (2, 1.28, 0.44).
  const Eigen::Vector3f origin(2.0f, 1.28f, 0.44f);
  const ScanBuffer& s = scans[1];  // a whole rotation
  EXPECT_NEAR((s.origin_m - origin).norm(), 0.0f, 1e-4f);
  EXPECT_GT(s.points_m.size(), 1800u * 16u * 9 / 10);
  bool forward = false;
  for (const auto& p : s.points_m) {
    ASSERT_NEAR((p - origin).norm(), 5.0f, 0.01f);  // every return is 5 m from the sensor
    // Velodyne azimuth 0 is the sensor's +y, which the body's yaw of 90 deg turns to world -x.
    if ((p - (origin + Eigen::Vector3f(-5.0f, 0.0f, 0.0f))).norm() < 0.1f) forward = true;
  }
  EXPECT_TRUE(forward);
  const LiveCounters c = rig.platform->counters();
  EXPECT_EQ(c.scans_without_pose, 0u);
  EXPECT_EQ(rig.platform->lidar_counters().drops[size_t(lidar::DropReason::queue_full)], 0u);
}

TEST(LivePlatform, WithoutARobotStateScansAreDroppedAndCounted) {
  Rig rig;
  rig.link->deliver = false;
  const auto scans = rig.run(2.5, 5.0f);
  EXPECT_TRUE(scans.empty());
  EXPECT_GE(rig.platform->counters().scans_without_pose, 1u);
  PoseSample p;
  EXPECT_FALSE(rig.platform->latest_pose(p));
  EXPECT_FALSE(rig.platform->link().connected);
}

TEST(LivePlatform, GarbageFloodIsCountedAndScansStillArrive) {
  Rig rig;
  rig.link->next = body_at(0, 0, 0);
  std::vector<ScanBuffer> scans;
  ScanBuffer b;
  PoseSample p;
  uint32_t seed = 12345;
  for (int i = 0; i < 3 * 75; ++i) {
    if (i % 10 == 0) rig.platform->latest_pose(p);
    rig.send_packet(5.0f);
    for (int g = 0; g < 4; ++g) {  // four garbage datagrams per real one
      uint8_t junk[1300];          // up to 1300 bytes are sent below
      for (auto& x : junk) x = uint8_t((seed = seed * 1664525u + 1013904223u) >> 24);
      rig.send(junk, g == 0 ? 1206 : 1 + (seed >> 8) % 1300);  // 1206: a VLP-16-sized packet
    }
    std::this_thread::sleep_for(std::chrono::microseconds(300));
    while (rig.platform->take_scan(b)) scans.push_back(b);
  }
  EXPECT_GE(scans.size(), 2u);
  const auto c = rig.platform->lidar_counters();
  uint64_t dropped = 0;
  for (size_t i = 1; i < c.drops.size(); ++i) dropped += c.drops[i];
  EXPECT_EQ(dropped, 4u * 3 * 75);  // every garbage datagram refused, by some reason
  EXPECT_EQ(c.accepted, 3u * 75);
  EXPECT_EQ(c.drops[size_t(lidar::DropReason::queue_full)], 0u);
}

TEST(LivePlatform, FrozenPoseKeepsItsStampAndLinkLossIsReported) {
  Rig rig;
  rig.link->next = body_at(0, 0, 0);
  PoseSample first, later;
  ASSERT_TRUE(rig.platform->latest_pose(first));
  EXPECT_TRUE(rig.platform->link().connected);
  rig.link->freeze_stamp = true;  // states keep coming, the odometry does not advance
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ASSERT_TRUE(rig.platform->latest_pose(later));
  EXPECT_EQ(later.stamp_s, first.stamp_s);
  EXPECT_EQ(rig.platform->counters().frozen_states, 1u);
  EXPECT_TRUE(rig.platform->link().connected);
  rig.link->deliver = false;  // cable cut
  std::this_thread::sleep_for(std::chrono::milliseconds(150));
  EXPECT_FALSE(rig.platform->link().connected);
  rig.link->deliver = true;  // back
  rig.link->freeze_stamp = false;
  ASSERT_TRUE(rig.platform->latest_pose(later));
  EXPECT_GT(later.stamp_s, first.stamp_s);
  EXPECT_TRUE(rig.platform->link().connected);
}

TEST(LivePlatform, StaleCommandsAreRefusedAndTheFinalStopIsSent) {
  Rig rig;
  VelocityCommand c;
  c.vx_mps = 0.5;
  c.stamp_s = double(rig.clock.now_ns()) * 1e-9;
  rig.platform->send_command(c);
  c.stamp_s -= 1.0;  // a second old
  rig.platform->send_command(c);
  ASSERT_EQ(rig.link->sent.size(), 1u);
  EXPECT_FLOAT_EQ(rig.link->sent[0].vx, 0.5f);
  EXPECT_EQ(rig.platform->counters().commands_sent, 1u);
  EXPECT_EQ(rig.platform->counters().commands_refused, 1u);
  EXPECT_TRUE(rig.platform->command_stop());
  ASSERT_EQ(rig.link->sent.size(), 2u);
  EXPECT_EQ(rig.link->sent[1].vx, 0.f);
  ASSERT_EQ(rig.link->modes.size(), 1u);
  EXPECT_EQ(rig.link->modes[0].mode, go2::ModeRequest::stop);
}

}  // namespace
}  // namespace storey::firmware

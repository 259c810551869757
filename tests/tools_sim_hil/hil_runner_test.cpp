// HilRunner in real time on a thread, against the firmware's own receiving code on loopback:
// drivers/lidar UdpReceiver (source filter on, ephemeral port) and drivers/go2 UdpLink.
// Rates are only sanity-checked with generous bounds (no wall-clock thresholds).
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <thread>

#include "drivers/go2/dds_link.hpp"
#include "drivers/go2/framed_link.hpp"
#include "drivers/lidar/udp_receiver.hpp"
#include "rt/spsc_queue.hpp"
#include "tests/tools_sim_hil/hil_test_util.hpp"
#include "tools/sim/hil_runner.hpp"
#include "tools/sim/scene.hpp"

namespace sim = storey::tools::sim;
namespace lidar = storey::drivers::lidar;
namespace go2 = storey::drivers::go2;
namespace config = storey::config;
using storey::rt::SpscQueue;

namespace {

int64_t mono_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

struct Ingest {
  std::size_t points = 0, bad = 0, chunks = 0;
  double worst = 0.0;
};

// Receives until the runner thread is done and the socket is quiet; checks every point against
// the box room seen from the (unmoving) robot's sensor.
void ingest_until_done(lidar::UdpReceiver& rx, SpscQueue<lidar::PointChunk>& q,
                       const std::atomic<bool>& done, Ingest& out) {
  const Eigen::Isometry3d ws = sim::test::box_room_sensor_pose();
  auto drain = [&] {
    static lidar::PointChunk c;
    while (q.try_pop(c)) {
      ++out.chunks;
      for (uint32_t i = 0; i < c.count; ++i) {
        const auto& p = c.points[i];
        // Range noise is 0.02 m in these runs: 5 sigma + units.
        const double e = std::abs(sim::test::box_room_error(ws, Eigen::Vector3d(p.x, p.y, p.z)));
        out.worst = std::max(out.worst, e);
        if (e > 0.105) ++out.bad;
        ++out.points;
      }
    }
  };
  while (!done.load()) {
    rx.poll(20);
    drain();
  }
  while (rx.poll(100) > 0) drain();
  drain();
}

}  // namespace

TEST(HilRunner, Vlp16PacketsReachTheFirmwareReceiverIntact) {
  SpscQueue<lidar::PointChunk> q(256);
  lidar::UdpReceiver::Options ro;
  ro.sensor = lidar::SensorModel::vlp16;
  ro.bind_address = "127.0.0.1";
  ro.port = 0;
  ro.source_address = 0x7F000001;  // only 127.0.0.1 is accepted, as in config/hil.yaml
  lidar::UdpReceiver rx(ro, q);
  ASSERT_TRUE(rx.open().ok);

  const sim::Scene scene = sim::load_scene("test_box_room");
  sim::HilOptions ho;
  ho.duration = 1.5;
  sim::HilRunner runner(
      scene, sim::test::loopback_params(config::SensorType::kVlp16, rx.bound_port()), ho);
  std::atomic<bool> stop{false}, done{false};
  std::thread t([&] {
    runner.run(stop);
    done = true;
  });
  Ingest in;
  ingest_until_done(rx, q, done, in);
  t.join();

  const sim::HilStats& s = runner.stats();
  const auto c = rx.counters();
  EXPECT_NEAR(s.sim_time_s, 1.5, 1e-6);
  // 754 packets per simulated second (generous: the count follows simulated, not wall, time).
  EXPECT_GE(s.lidar_packets, 1120u);
  EXPECT_LE(s.lidar_packets, 1132u);
  EXPECT_EQ(s.send_errors, 0u);
  EXPECT_EQ(c.datagrams, s.lidar_packets);  // zero loss on loopback
  EXPECT_EQ(c.accepted, s.lidar_packets);
  uint64_t drops = 0;
  for (auto d : c.drops) drops += d;
  EXPECT_EQ(drops, 0u);
  EXPECT_EQ(in.points, s.lidar_returns);
  EXPECT_EQ(in.bad, 0u) << "worst range error " << in.worst;
  EXPECT_EQ(s.collisions, 0u);
  EXPECT_EQ(s.falls, 0u);
  EXPECT_NEAR(runner.robot_state().position.x(), 3.0, 1e-9);  // no command, no motion
}

TEST(HilRunner, Mid360PointsAndImuReachTheFirmwareReceivers) {
  SpscQueue<lidar::PointChunk> q(512);
  SpscQueue<lidar::ImuSample> imu_q(1024);
  SpscQueue<lidar::PointChunk> imu_chunks(16);
  lidar::UdpReceiver::Options ro;
  ro.sensor = lidar::SensorModel::mid360;
  ro.bind_address = "127.0.0.1";
  ro.port = 0;
  ro.source_address = 0x7F000001;
  lidar::UdpReceiver rx(ro, q), rx_imu(ro, imu_chunks);
  rx_imu.set_imu_queue(&imu_q);
  ASSERT_TRUE(rx.open().ok);
  ASSERT_TRUE(rx_imu.open().ok);

  config::Parameters p = sim::test::loopback_params(config::SensorType::kMid360, rx.bound_port());
  p.sensor.imu_port = rx_imu.bound_port();
  sim::HilOptions ho;
  ho.duration = 1.0;
  ho.rate = 2.0;  // scaled: 1 simulated second in ~0.5 s
  sim::HilRunner runner(sim::load_scene("test_box_room"), p, ho);
  std::atomic<bool> stop{false}, done{false};
  std::thread t([&] {
    runner.run(stop);
    done = true;
  });
  std::thread imu_thread([&] {
    while (!done.load()) rx_imu.poll(20);
    while (rx_imu.poll(100) > 0) {
    }
  });
  Ingest in;
  ingest_until_done(rx, q, done, in);
  t.join();
  imu_thread.join();

  const sim::HilStats& s = runner.stats();
  const auto c = rx.counters();
  // 200k shots/s / 96 = 2083 packets per simulated second; IMU at 200 Hz.
  EXPECT_GE(s.lidar_packets, 2080u);
  EXPECT_LE(s.lidar_packets, 2085u);
  EXPECT_EQ(c.accepted, s.lidar_packets);
  EXPECT_EQ(c.lost_udp_cnt, 0u);
  uint64_t drops = 0;
  for (auto d : c.drops) drops += d;
  EXPECT_EQ(drops, 0u);
  EXPECT_EQ(in.bad, 0u) << "worst range error " << in.worst;
  EXPECT_GT(in.points, 0u);
  EXPECT_GE(s.imu_packets, 199u);
  EXPECT_LE(s.imu_packets, 202u);
  EXPECT_EQ(rx_imu.counters().imu, s.imu_packets);
  lidar::ImuSample imu;
  ASSERT_TRUE(imu_q.try_pop(imu));
  EXPECT_NEAR(imu.acc[2], 1.0, 1e-3);  // standing still on a level floor: 1 g up
  EXPECT_NEAR(imu.gyro[2], 0.0, 1e-6);
}

TEST(HilRunner, VelocityCommandsMoveTheRobotAndSilenceStopsIt) {
  SpscQueue<lidar::PointChunk> q(64);  // LiDAR packets go to a receiver nobody reads
  lidar::UdpReceiver::Options ro;
  ro.bind_address = "127.0.0.1";
  ro.port = 0;
  lidar::UdpReceiver rx(ro, q);
  ASSERT_TRUE(rx.open().ok);
  sim::HilOptions ho;
  ho.duration = 30.0;  // stopped by the test
  ho.command_timeout_s = 0.3;
  sim::HilRunner runner(sim::load_scene("test_box_room"),
                        sim::test::loopback_params(config::SensorType::kVlp16, rx.bound_port()),
                        ho);
  go2::LinkOptions lo;
  go2::UdpLink link({"127.0.0.1", 0}, {"127.0.0.1", runner.link_port()}, lo, mono_ns());
  ASSERT_TRUE(link.ok()) << link.error();
  std::atomic<bool> stop{false}, done{false};
  std::thread t([&] {
    runner.run(stop);
    done = true;
  });
  auto run_for = [&](double seconds, bool command) {
    const int64_t end = mono_ns() + int64_t(seconds * 1e9);
    while (mono_ns() < end) {
      const int64_t now = mono_ns();
      link.poll(now);
      if (command) {
        go2::VelocityCommand v;
        v.stamp_ns = now;
        v.vx = 0.5f;
        EXPECT_EQ(link.send_velocity(v, now), go2::LinkStatus::ok);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  };
  run_for(0.5, false);  // heartbeats tell the stand-in where to publish; no motion yet
  ASSERT_TRUE(link.has_state());
  const go2::RobotState at_rest = link.latest_state();
  EXPECT_NEAR(at_rest.position[0], 3.0f, 1e-3f);
  EXPECT_NEAR(at_rest.position[2], 0.32f, 1e-3f);  // body centre above the floor
  EXPECT_EQ(at_rest.mode, uint8_t(go2::RobotModeId::balance_stand));

  run_for(1.0, true);  // 0.5 m/s forward (+x at yaw 0)
  const go2::RobotState moving = link.latest_state();
  EXPECT_GT(moving.position[0], 3.2f);
  EXPECT_GT(moving.velocity[0], 0.3f);
  EXPECT_EQ(moving.mode, uint8_t(go2::RobotModeId::locomotion));

  run_for(1.0, false);  // silence > command timeout: the robot stops by itself
  const go2::RobotState stopped = link.latest_state();
  EXPECT_NEAR(stopped.velocity[0], 0.0f, 1e-3f);
  run_for(0.3, false);
  EXPECT_NEAR(link.latest_state().position[0], stopped.position[0], 1e-4f);
  EXPECT_LT(stopped.position[0], 4.5f);

  // StandDown lays the robot down: velocity commands no longer move it until it stands up.
  {
    const int64_t now = mono_ns();
    ASSERT_EQ(link.send_mode({now, go2::ModeRequest::stand_down}, now), go2::LinkStatus::ok);
  }
  run_for(0.2, false);
  run_for(0.5, true);
  EXPECT_EQ(link.latest_state().mode, uint8_t(go2::RobotModeId::lie_down));
  EXPECT_NEAR(link.latest_state().position[0], stopped.position[0], 1e-4f);

  stop = true;
  t.join();
  const sim::HilStats& s = runner.stats();
  EXPECT_GE(s.velocity_commands, 20u);
  EXPECT_GE(s.command_timeouts, 1u);
  EXPECT_EQ(s.mode_commands, 1u);
  EXPECT_GT(s.heartbeats, 0u);
  EXPECT_EQ(s.link_dropped, 0u);
  EXPECT_EQ(s.collisions, 0u);
  EXPECT_NEAR(runner.robot_state().position.x(), stopped.position[0], 1e-3);  // odometry = truth
  const auto h = link.health(mono_ns());
  EXPECT_EQ(h.decode_errors, 0u);
  EXPECT_EQ(h.crc_failures, 0u);
}

TEST(HilRunner, RefusesLinksItCannotServeAndForeignSensorAddresses) {
  const sim::Scene scene = sim::load_scene("test_box_room");
  config::Parameters p = sim::test::loopback_params(config::SensorType::kVlp16, 40000);
  p.link.transport = config::LinkTransport::kSim;
  EXPECT_THROW(sim::HilRunner(scene, p, {}), std::runtime_error);
  p.link.transport = config::LinkTransport::kCan;
  EXPECT_THROW(sim::HilRunner(scene, p, {}), std::runtime_error);
  p = sim::test::loopback_params(config::SensorType::kVlp16, 40000);
  p.sensor.sensor_address = "192.0.2.1";  // TEST-NET: not this machine
  try {
    sim::HilRunner r(scene, p, {});
    ADD_FAILURE() << "expected a refusal";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("sensor.sensor_address"), std::string::npos) << e.what();
  }
  sim::HilOptions bad;
  bad.rate = 0.0;
  EXPECT_THROW(
      sim::HilRunner(scene, sim::test::loopback_params(config::SensorType::kVlp16, 40000), bad),
      std::runtime_error);
}

// The Go2's own interface: sport state over DDS, Move requests served by the stand-in in the
// runner (one CycloneDDS domain instance shared by both sides of this process, on lo).
TEST(HilRunner, DdsMoveRequestsMoveTheRobot) {
  SpscQueue<lidar::PointChunk> q(64);
  lidar::UdpReceiver::Options ro;
  ro.bind_address = "127.0.0.1";
  ro.port = 0;
  lidar::UdpReceiver rx(ro, q);
  ASSERT_TRUE(rx.open().ok);
  config::Parameters p = sim::test::loopback_params(config::SensorType::kVlp16, rx.bound_port());
  p.link.transport = config::LinkTransport::kDds;
  p.link.dds.domain_id = 47;  // apart from other tests' domains
  p.link.dds.interface = "lo";
  p.link.dds.allow_multicast = false;
  p.link.dds.peers = {"127.0.0.1"};
  sim::HilOptions ho;
  ho.duration = 30.0;
  sim::HilRunner runner(sim::load_scene("test_box_room"), p, ho);
  go2::DdsLinkOptions lo;
  lo.network = go2::dds_loopback(47);
  lo.network.interface = "lo";
  go2::DdsLink link(lo, mono_ns());
  ASSERT_TRUE(link.ok()) << link.error();
  std::atomic<bool> stop{false}, done{false};
  std::thread t([&] {
    runner.run(stop);
    done = true;
  });
  const int64_t give_up = mono_ns() + 5'000'000'000;
  while ((!link.has_state() || link.matched_request_readers() == 0) && mono_ns() < give_up) {
    link.poll(mono_ns());
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_TRUE(link.has_state()) << "no sport state over DDS";
  const int64_t end = mono_ns() + 1'000'000'000;
  while (mono_ns() < end) {
    const int64_t now = mono_ns();
    link.poll(now);
    go2::VelocityCommand v;
    v.stamp_ns = now;
    v.vx = 0.5f;
    link.send_velocity(v, now);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  link.poll(mono_ns());
  stop = true;
  t.join();
  EXPECT_GT(runner.stats().velocity_commands, 10u);
  EXPECT_GT(runner.robot_state().position.x(), 3.2);
  EXPECT_GT(link.latest_state().position[0], 3.2f);
}

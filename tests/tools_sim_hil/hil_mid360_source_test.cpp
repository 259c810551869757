// HilMid360Source: Livox SDK2 packets (96 shots, cartesian high) of the sim's non-repetitive
// pattern decode with the firmware's decoder: CRC, no udp_cnt loss, frames at 10 Hz, geometry.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "drivers/lidar/mid360.hpp"
#include "tests/tools_sim_hil/hil_test_util.hpp"
#include "tools/sim/hil_mid360_source.hpp"
#include "tools/sim/scene.hpp"

namespace sim = storey::tools::sim;
namespace lidar = storey::drivers::lidar;

TEST(HilMid360Source, BoxRoomPacketsDecodeWithoutLoss) {
  const sim::Scene scene = sim::load_scene("test_box_room");
  const sim::RayCaster rc(scene.mesh);
  sim::HilLidarOptions o;
  o.range_noise_sigma = 0.0;
  o.mount = Eigen::Translation3d(0.28, 0.0, 0.44) * Eigen::Quaterniond::Identity();
  o.clock_epoch_ns = 1'000'000'000;
  const Eigen::Isometry3d body(Eigen::Translation3d(3.0, 2.0, 0.0));
  const Eigen::Isometry3d ws = body * o.mount;
  sim::HilMid360Source src(rc, o, 0.001);
  std::vector<std::vector<uint8_t>> packets;
  const sim::HilEmit emit = [&](std::span<const uint8_t> d) {
    packets.emplace_back(d.begin(), d.end());
  };
  const sim::PoseAtTime pose = [&](double) { return body; };
  for (int k = 1; k <= 250; ++k) src.produce(k * 0.001, pose, emit);
  // 0.25 s x 200k shots/s / 96 = 520.8 packets.
  ASSERT_EQ(packets.size(), 520u);

  lidar::Mid360Decoder dec;
  std::vector<lidar::LidarPoint> pts(lidar::kMid360MaxPointsPerPacket);
  std::size_t points = 0, bad = 0, frame_starts = 0;
  uint64_t prev_ts = 0;
  for (std::size_t k = 0; k < packets.size(); ++k) {
    EXPECT_EQ(packets[k].size(), 36u + 96u * 14u);
    const auto info = dec.decode(packets[k], pts);
    ASSERT_EQ(info.reason, lidar::DropReason::none) << "packet " << k;
    EXPECT_EQ(info.data_type, 1);
    if (info.udp_cnt == 0) ++frame_starts;
    if (k > 0) {
      EXPECT_EQ(info.timestamp_ns - prev_ts, 480'000u);  // 96 shots at 200 kHz
    }
    prev_ts = info.timestamp_ns;
    for (uint32_t i = 0; i < info.points; ++i) {
      const double e =
          std::abs(sim::test::box_room_error(ws, Eigen::Vector3d(pts[i].x, pts[i].y, pts[i].z)));
      if (e > 3e-3) ++bad;  // 1 mm units
      ++points;
    }
  }
  EXPECT_EQ(dec.lost_packets(), 0u);
  EXPECT_EQ(dec.out_of_order(), 0u);
  EXPECT_EQ(dec.drops().total(), 0u);
  EXPECT_EQ(frame_starts, 3u);  // frames at 0, 0.1 and 0.2 s
  EXPECT_EQ(bad, 0u);
  // Shots of the unfinished packet 520 are cast but not sent yet.
  EXPECT_LE(points, src.returns());
  EXPECT_LE(src.returns() - points, 96u);
  EXPECT_GT(points, 520u * 96u * 9 / 10);  // a closed room returns (almost) every shot
}

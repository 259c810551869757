// HilVlp16Source: real VLP-16 packets cast against the box room decode with the firmware's own
// decoder into the scene's geometry, at the real packet timing.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "drivers/lidar/vlp16.hpp"
#include "tests/tools_sim_hil/hil_test_util.hpp"
#include "tools/sim/hil_vlp16_source.hpp"
#include "tools/sim/scene.hpp"

namespace sim = storey::tools::sim;
namespace lidar = storey::drivers::lidar;

namespace {

struct Captured {
  std::vector<std::vector<uint8_t>> packets;
  sim::HilEmit emit() {
    return [this](std::span<const uint8_t> d) { packets.emplace_back(d.begin(), d.end()); };
  }
};

}  // namespace

TEST(HilVlp16Source, BoxRoomPacketsDecodeToTheGeometry) {
  const sim::Scene scene = sim::load_scene("test_box_room");
  const sim::RayCaster rc(scene.mesh);
  sim::HilLidarOptions o;
  o.range_noise_sigma = 0.0;
  o.mount = Eigen::Translation3d(0.28, 0.0, 0.44) * Eigen::Quaterniond::Identity();
  // A yawed body: the check goes through the mount and the body pose.
  const Eigen::Isometry3d body =
      Eigen::Translation3d(3.0, 2.0, 0.0) * Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ());
  const Eigen::Isometry3d ws = body * o.mount;
  sim::HilVlp16Source src(rc, o);
  Captured cap;
  const sim::PoseAtTime pose = [&](double) { return body; };
  // Packet k is due once its last laser has fired: (24k + 23) x 55.296 us + 15 x 2.304 us.
  EXPECT_EQ(src.produce(0.001, pose, cap.emit()), 0);
  EXPECT_EQ(src.produce(0.0013, pose, cap.emit()), 0);  // packet 0 complete at 1.3064 ms
  EXPECT_EQ(src.produce(0.00131, pose, cap.emit()), 1);
  EXPECT_EQ(src.produce(0.2, pose, cap.emit()), 149);  // 0.2 s / 1.327 ms = 150.7
  ASSERT_EQ(cap.packets.size(), 150u);

  lidar::Vlp16Decoder dec;
  std::vector<lidar::LidarPoint> pts(lidar::kVlp16MaxPointsPerPacket);
  std::size_t points = 0, bad = 0;
  double worst = 0.0;
  uint32_t prev_stamp = 0;
  for (std::size_t k = 0; k < cap.packets.size(); ++k) {
    const auto info = dec.decode(cap.packets[k], pts);
    ASSERT_EQ(info.reason, lidar::DropReason::none) << "packet " << k;
    EXPECT_EQ(info.return_mode, 0x37);
    // A closed room: every one of the 384 shots returns.
    EXPECT_EQ(info.points, 384u);
    if (k > 0) {
      const uint32_t d = (info.timestamp_us + 3'600'000'000u - prev_stamp) % 3'600'000'000u;
      EXPECT_TRUE(d == 1327 || d == 1328) << d;  // 24 x 55.296 us
    }
    prev_stamp = info.timestamp_us;
    for (uint32_t i = 0; i < info.points; ++i) {
      const Eigen::Vector3d p(pts[i].x, pts[i].y, pts[i].z);
      const double e = std::abs(sim::test::box_room_error(ws, p));
      worst = std::max(worst, e);
      if (e > 3e-3) ++bad;  // 2 mm range unit, float trig
      ++points;
    }
  }
  EXPECT_EQ(dec.drops().total(), 0u);
  EXPECT_EQ(bad, 0u) << "worst " << worst;
  EXPECT_EQ(points, 150u * 384u);
  EXPECT_EQ(src.returns(), points);
}

TEST(HilVlp16Source, TurnsClockwiseAtTheConfiguredRate) {
  const sim::Scene scene = sim::load_scene("test_box_room");
  const sim::RayCaster rc(scene.mesh);
  sim::HilLidarOptions o;
  o.rotation_hz = 10.0;
  sim::HilVlp16Source src(rc, o);
  // Velodyne azimuth grows with time (clockwise seen from above): 0.199 deg per firing at 10 Hz,
  // a full turn after 0.1 s = 1808.5 firings.
  EXPECT_EQ(src.firing_azimuth(0), 0);
  EXPECT_EQ(src.firing_azimuth(1), 20);
  EXPECT_EQ(src.firing_azimuth(904), 17996);  // half a turn minus a little
  EXPECT_LT(src.firing_azimuth(1809), 100);   // wrapped
  // A point straight ahead of the sensor (+x) has Velodyne azimuth 90 deg and decodes to +x.
  lidar::Vlp16RawReturn r{};
  r.laser = 1;  // +1 deg
  r.azimuth_cdeg = 9000;
  r.distance = 5000;  // 10 m
  const auto p = lidar::vlp16_to_point(r);
  EXPECT_NEAR(p.x, 10.0 * std::cos(M_PI / 180), 1e-3);
  EXPECT_NEAR(p.y, 0.0, 1e-3);
  sim::HilLidarOptions bad = o;
  bad.rotation_hz = 30.0;
  EXPECT_THROW(sim::HilVlp16Source(rc, bad), std::runtime_error);
}

TEST(HilVlp16Source, SameSeedSameBytes) {
  const sim::Scene scene = sim::load_scene("test_box_room");
  const sim::RayCaster rc(scene.mesh);
  sim::HilLidarOptions o;
  o.range_noise_sigma = 0.02;
  o.dropout = 0.1;
  const sim::PoseAtTime pose = [](double t) {
    return Eigen::Isometry3d(Eigen::Translation3d(3.0 + 0.5 * t, 2.0, 0.0));
  };
  Captured a, b;
  sim::HilVlp16Source sa(rc, o), sb(rc, o);
  sa.produce(0.05, pose, a.emit());
  sb.produce(0.05, pose, b.emit());
  ASSERT_EQ(a.packets.size(), b.packets.size());
  EXPECT_EQ(a.packets, b.packets);
}

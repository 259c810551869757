// Scan assembly by rotation (on the real capture and on encoded packets), by time window and
// frame counter, deskewing through the PoseSource interface, and the CSV export.
#include "drivers/lidar/scan_assembler.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <vector>

#include "drivers/lidar/scan_csv.hpp"
#include "drivers/lidar/vlp16.hpp"
#include "drivers/pcap/pcap_reader.hpp"

namespace storey::drivers::lidar {
namespace {

struct Collect : ScanSink {
  std::vector<Scan> scans;
  void on_scan(const Scan& s) override { scans.push_back(s); }
};

// Packets of a synthetic spinning sensor, every laser at 10 m.
std::vector<std::array<uint8_t, kVlp16DataPacketSize>> spin(int packets, uint16_t az0) {
  std::vector<std::array<uint8_t, kVlp16DataPacketSize>> out(packets);
  // 0.22 deg per 55.296 us firing sequence (~663 rpm, a turn in 90.5 ms).
  uint32_t az = az0;
  for (int k = 0; k < packets; ++k) {
    std::array<Vlp16Firing, kVlp16FiringsPerPacket> f{};
    for (auto& s : f) {
      s.azimuth_cdeg = static_cast<uint16_t>(az % 36000);
      az += 22;
      s.range_m.fill(10.f);
      s.reflectivity.fill(50);
    }
    vlp16_encode_firings(f, static_cast<uint32_t>(k * 1327), Vlp16ReturnMode::strongest, 0x22,
                         out[k]);
  }
  return out;
}

TEST(ScanAssembler, RotationSplitsAtWrap) {
  Collect sink;
  ScanAssembler asmb({}, &sink);
  Vlp16Decoder dec;
  std::array<LidarPoint, kVlp16MaxPointsPerPacket> pts;
  // start at 300 deg: 60 deg of partial scan 0, then one full turn, then a bit more.
  const auto packets = spin(80, 30000);  // 80 x 24 x 0.22 deg = 422 deg
  for (std::size_t k = 0; k < packets.size(); ++k) {
    const auto info = dec.decode(packets[k], pts);
    ASSERT_EQ(info.reason, DropReason::none);
    asmb.add_packet(std::span(pts).first(info.points), k * 1'327'104ull);
  }
  asmb.flush();
  ASSERT_EQ(sink.scans.size(), 3u);
  EXPECT_EQ(sink.scans[0].index, 0u);
  EXPECT_EQ(sink.scans[1].index, 1u);
  // full turn: 36000 / 22 firing sequences x 16 lasers
  EXPECT_NEAR(static_cast<double>(sink.scans[1].points.size()), 36000.0 / 22 * 16, 32);
  // partial first scan: 60 deg
  EXPECT_NEAR(static_cast<double>(sink.scans[0].points.size()), 6000.0 / 22 * 16, 32);
  // the full scan starts right after azimuth 0 and spans ~0.1 s
  const auto& s = sink.scans[1];
  EXPECT_GE(s.points.front().x, 0.f);
  EXPECT_GT(s.points.front().y, 0.f);
  EXPECT_NEAR((s.end_ns - s.start_ns) * 1e-9, 36000.0 / 22 * 55.296e-6, 0.0002);
  EXPECT_EQ(s.points.front().time_offset_ns, 0);
  for (std::size_t i = 1; i < s.points.size(); ++i) {
    ASSERT_GE(s.points[i].time_offset_ns, s.points[i - 1].time_offset_ns);
  }
}

TEST(ScanAssembler, RealCaptureRotations) {
  pcap::PcapReader reader;
  ASSERT_TRUE(
      reader.open(std::string(STOREY_SOURCE_DIR) + "/tests/data/velodyne_vlp16.pcap", nullptr));
  reader.add_port(kVlp16DataPort);
  Collect sink;
  ScanAssembler asmb({}, &sink);
  Vlp16Decoder dec;
  std::array<LidarPoint, kVlp16MaxPointsPerPacket> pts;
  pcap::UdpDatagram d;
  uint64_t total = 0;
  while (reader.next(d)) {
    const auto info = dec.decode(d.payload, pts);
    ASSERT_EQ(info.reason, DropReason::none);
    total += info.points;
    asmb.add_packet(std::span(pts).first(info.points), info.timestamp_us * 1000ull);
  }
  asmb.flush();
  // Starts at 250 deg, wraps once: a partial scan 0 and a partial scan 1.
  ASSERT_EQ(sink.scans.size(), 2u);
  EXPECT_EQ(sink.scans[0].points.size() + sink.scans[1].points.size(), total);
  // Scan 0 covers 250..360 deg (~110 deg at ~600 rpm ~ 30 ms).
  const double dur0 = (sink.scans[0].end_ns - sink.scans[0].start_ns) * 1e-9;
  EXPECT_GT(dur0, 0.02);
  EXPECT_LT(dur0, 0.04);
}

TEST(ScanAssembler, TimeWindowAndFrameCounter) {
  Collect sink;
  ScanAssembler::Options o;
  o.mode = ScanAssembler::Mode::time_window;
  ScanAssembler a(o, &sink);
  std::vector<LidarPoint> pts(96);
  for (int i = 0; i < 96; ++i) pts[i].time_offset_ns = i * 5000;
  // 480 us packets from t = 50 ms for 300 ms: windows [0,100) (partial) [100,200) [200,300) ...
  for (uint64_t t = 50'000'000; t < 350'000'000; t += 480'000) a.add_packet(pts, t);
  a.flush();
  ASSERT_EQ(sink.scans.size(), 4u);
  for (const auto& s : sink.scans) {
    EXPECT_EQ(s.start_ns / 100'000'000, s.end_ns / 100'000'000);
  }
  EXPECT_NEAR(static_cast<double>(sink.scans[1].points.size()), 100e-3 / 5e-6, 2);

  Collect s2;
  ScanAssembler::Options o2;
  o2.mode = ScanAssembler::Mode::frame_counter;
  ScanAssembler b(o2, &s2);
  for (int k = 0; k < 10; ++k) b.add_packet(pts, k * 480'000ull, static_cast<uint32_t>(k / 4));
  b.flush();
  ASSERT_EQ(s2.scans.size(), 3u);
  EXPECT_EQ(s2.scans[0].points.size(), 4u * 96);
  EXPECT_EQ(s2.scans[2].points.size(), 2u * 96);
  EXPECT_EQ(s2.scans[2].frame_id, 2u);
}

// Sensor moving along +x at 1 m/s, yaw rate 1 rad/s about z.
struct Moving : PoseSource {
  bool pose_at(uint64_t t, RigidTransform& p) const override {
    const float s = t * 1e-9f;
    p.tx = s;
    p.ty = p.tz = 0.f;
    p.qw = std::cos(s / 2);
    p.qx = p.qy = 0.f;
    p.qz = std::sin(s / 2);
    return true;
  }
};

TEST(ScanAssembler, DeskewMovesPointsIntoEndFrame) {
  // A fixed world point W seen at different times: after deskew all copies coincide.
  Collect sink;
  ScanAssembler::Options o;
  o.mode = ScanAssembler::Mode::frame_counter;
  ScanAssembler a(o, &sink);
  Moving m;
  a.set_pose_source(&m);
  const float W[3] = {5.f, 2.f, 1.f};
  std::vector<LidarPoint> pts;
  for (int i = 0; i < 10; ++i) {
    LidarPoint p;
    p.time_offset_ns = i * 10'000'000;  // 0..90 ms
    RigidTransform pose;
    m.pose_at(p.time_offset_ns, pose);
    p.x = W[0];
    p.y = W[1];
    p.z = W[2];
    pose.inverse().apply(p.x, p.y, p.z);  // the sensor sees W in its own frame
    pts.push_back(p);
  }
  a.add_packet(pts, 0, 0);
  a.flush();
  ASSERT_EQ(sink.scans.size(), 1u);
  const auto& s = sink.scans[0];
  EXPECT_TRUE(s.deskewed);
  RigidTransform end;
  m.pose_at(s.end_ns, end);
  float ex = W[0], ey = W[1], ez = W[2];
  end.inverse().apply(ex, ey, ez);
  for (const auto& p : s.points) {
    EXPECT_NEAR(p.x, ex, 1e-4);
    EXPECT_NEAR(p.y, ey, 1e-4);
    EXPECT_NEAR(p.z, ez, 1e-4);
  }
  // and the raw points did differ (the test can fail)
  EXPECT_GT(std::abs(pts[0].x - pts[9].x) + std::abs(pts[0].y - pts[9].y), 0.3f);
}

TEST(ScanCsv, WritesPacketOrder) {
  Scan s;
  s.points.push_back(LidarPoint{1.f, 2.f, 3.f, 40.f, 0, 7, 0, 0});
  s.points.push_back(LidarPoint{-1.5f, 0.25f, -3.f, 255.f, 1200, 15, 0, 0});
  const std::string dir = STOREY_BINARY_DIR;
  const auto path = scan_csv_path(dir, 3);
  EXPECT_EQ(path, dir + "/scan_000003.csv");
  std::string err;
  ASSERT_TRUE(write_scan_csv(path, s, &err)) << err;
  std::ifstream f(path);
  std::string l1, l2, l3;
  std::getline(f, l1);
  std::getline(f, l2);
  std::getline(f, l3);
  EXPECT_EQ(l1, "x,y,z,intensity,ring,time_offset_ns");
  EXPECT_EQ(l2, "1.000000,2.000000,3.000000,40,7,0");
  EXPECT_EQ(l3, "-1.500000,0.250000,-3.000000,255,15,1200");
  EXPECT_FALSE(write_scan_csv("/nonexistent/dir/x.csv", s, &err));
}

}  // namespace
}  // namespace storey::drivers::lidar

// The real VLP-16 capture (tests/data/README.md) through PcapReader and the decoder.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "drivers/lidar/vlp16.hpp"
#include "drivers/pcap/pcap_reader.hpp"

namespace storey::drivers {
namespace {

using lidar::DropReason;

const std::string kCapture = std::string(STOREY_SOURCE_DIR) + "/tests/data/velodyne_vlp16.pcap";

TEST(RealVlp16Capture, DecodesWithZeroDrops) {
  pcap::PcapReader reader;
  std::string err;
  ASSERT_TRUE(reader.open(kCapture, &err)) << err;
  EXPECT_EQ(reader.link_type(), pcap::link::kEthernet);
  reader.add_port(lidar::kVlp16DataPort);
  reader.add_port(lidar::kVlp16PositionPort);

  lidar::Vlp16Decoder dec;
  std::array<lidar::LidarPoint, lidar::kVlp16MaxPointsPerPacket> pts;
  int data = 0, pos = 0, wraps = 0;
  uint32_t last_stamp = 0, last_pos_stamp = 0;
  uint64_t last_capture_ns = 0;
  int last_az = -1;
  uint64_t total_points = 0;
  pcap::UdpDatagram d;
  while (reader.next(d)) {
    EXPECT_GE(d.timestamp_ns, last_capture_ns);
    last_capture_ns = d.timestamp_ns;
    EXPECT_EQ(d.src_addr, 0xC0A801C8u);  // 192.168.1.200
    if (d.dst_port == lidar::kVlp16DataPort) {
      ASSERT_EQ(d.payload.size(), lidar::kVlp16DataPacketSize);
      const auto info = dec.decode(d.payload, pts);
      ASSERT_EQ(info.reason, DropReason::none) << "packet " << data;
      EXPECT_EQ(info.return_mode, 0x37);
      EXPECT_EQ(info.product, 0x21);  // real unit, HDL-32E code: model comes from config
      // A scene, not an empty room or a blocked sensor: most lasers return.
      EXPECT_GT(info.points, 100u);
      EXPECT_LE(info.points, 384u);
      total_points += info.points;
      for (uint32_t i = 0; i < info.points; ++i) {
        const auto& p = pts[i];
        const float r = std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
        EXPECT_GT(r, 0.3f);
        EXPECT_LT(r, 130.f);
        EXPECT_LT(p.ring, 16);
        EXPECT_LT(p.time_offset_ns, 1'327'104);  // 12 blocks x 110.592 us
      }
      if (data > 0) {
        const uint32_t dt = info.timestamp_us - last_stamp;  // ~1.327 ms apart
        EXPECT_GE(dt, 1326u);
        EXPECT_LE(dt, 1329u);
      }
      last_stamp = info.timestamp_us;
      // Azimuth monotonic within a rotation: each firing advances a little, one wrap per turn.
      lidar::vlp16_for_each_return(d.payload, [&](const lidar::Vlp16RawReturn& rr) {
        if (last_az >= 0) {
          const int step = (rr.azimuth_cdeg - last_az + 36000) % 36000;
          EXPECT_LT(step, 60) << "packet " << data;  // <= ~0.6 deg between consecutive returns
          if (rr.azimuth_cdeg < last_az) ++wraps;
        }
        last_az = rr.azimuth_cdeg;
      });
      ++data;
    } else {
      ASSERT_EQ(d.dst_port, lidar::kVlp16PositionPort);
      lidar::Vlp16Position p;
      ASSERT_EQ(lidar::vlp16_decode_position(d.payload, p), DropReason::none);
      EXPECT_GT(p.timestamp_us, last_pos_stamp);
      last_pos_stamp = p.timestamp_us;
      // What this unit sent: no GPS attached, so PPS absent and no NMEA sentence.
      EXPECT_EQ(p.pps_status, 0);
      EXPECT_FALSE(p.rmc.present);
      // Its timestamp runs on the same clock as the data packets'.
      EXPECT_LT(std::abs(static_cast<int64_t>(p.timestamp_us) - last_stamp), 20000);
      ++pos;
    }
  }
  EXPECT_TRUE(reader.error().empty()) << reader.error();
  EXPECT_EQ(data, 84);
  EXPECT_EQ(pos, 16);
  EXPECT_EQ(dec.drops().total(), 0u);
  EXPECT_EQ(dec.packets_ok(), 84u);
  EXPECT_EQ(wraps, 1);  // 84 packets x ~4.77 deg = ~1.1 turns
  EXPECT_EQ(reader.stats().frames, 100u);
  EXPECT_EQ(reader.stats().port_filtered, 0u);
  // Every position packet of this unit claims IP total length 1234 for a 540-byte IP datagram.
  EXPECT_EQ(reader.stats().ip_length_mismatch, 16u);
  EXPECT_GT(total_points, 84u * 100);
}

}  // namespace
}  // namespace storey::drivers

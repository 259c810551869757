// Writes the fuzz seed corpora (valid inputs from our encoders/writers) into DIR/<target>/.
#include <sys/stat.h>

#include <array>
#include <cstdio>
#include <string>
#include <vector>

#include "drivers/lidar/mid360.hpp"
#include "drivers/lidar/vlp16.hpp"
#include "drivers/pcap/lvx2_reader.hpp"
#include "drivers/pcap/pcap_reader.hpp"

using namespace storey::drivers;
using namespace storey::drivers::lidar;

static bool put(const std::string& path, std::span<const uint8_t> b) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) return false;
  std::fwrite(b.data(), 1, b.size(), f);
  return std::fclose(f) == 0;
}

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: storey_fuzz_seeds DIR\n");
    return 2;
  }
  const std::string dir = argv[1];
  for (const char* t : {"", "/vlp16", "/mid360", "/pcap", "/lvx2"}) mkdir((dir + t).c_str(), 0755);
  bool ok = true;
  // VLP-16: single and dual return data packets, a position packet with NMEA.
  std::array<Vlp16Firing, kVlp16FiringsPerPacket> f{};
  for (int i = 0; i < kVlp16FiringsPerPacket; ++i) {
    f[i].azimuth_cdeg = static_cast<uint16_t>((35900 + i * 20) % 36000);
    for (int l = 0; l < 16; ++l) f[i].range_m[l] = (l % 5 == 0) ? 0.f : 1.f + l + 0.1f * i;
  }
  std::array<uint8_t, kVlp16DataPacketSize> vp;
  vlp16_encode_firings(f, 123456, Vlp16ReturnMode::strongest, 0x22, vp);
  ok &= put(dir + "/vlp16/single", vp);
  Vlp16DataPacket dual;
  std::memcpy(&dual, vp.data(), sizeof(dual));
  for (int b = 1; b < kVlp16Blocks; b += 2) dual.blocks[b].azimuth = dual.blocks[b - 1].azimuth;
  dual.return_mode = 0x39;
  vlp16_encode(dual, vp);
  ok &= put(dir + "/vlp16/dual", vp);
  std::array<uint8_t, kVlp16PositionPacketSize> pos;
  vlp16_encode_position(Vlp16Position{1000, 2, {}},
                        "$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6A",
                        pos);
  ok &= put(dir + "/vlp16/position", pos);
  // Mid-360: every data type and IMU.
  std::vector<LidarPoint> pts(96);
  for (int i = 0; i < 96; ++i) pts[i] = LidarPoint{1.f + i * 0.01f, -2.f, 0.5f, 10.f, 0, 0, 0, 3};
  std::array<uint8_t, 1500> mp;
  Mid360PacketMeta meta{1'000'000, 4800, 5, 1, 0, true};
  for (auto t :
       {Mid360DataType::cartesian_high, Mid360DataType::cartesian_low, Mid360DataType::spherical}) {
    const std::size_t n = mid360_encode_points(meta, t, pts, mp);
    ok &= put(dir + "/mid360/type" + std::to_string(static_cast<int>(t)),
              std::span<const uint8_t>(mp).first(n));
  }
  const std::size_t ni =
      mid360_encode_imu(meta, ImuSample{1, {0.1f, 0.2f, 0.3f}, {0, 0, 1}, 0}, mp);
  ok &= put(dir + "/mid360/imu", std::span<const uint8_t>(mp).first(ni));
  // pcap: a few datagrams written by PcapWriter; lvx2: a synthetic two-frame file.
  pcap::PcapWriter w;
  ok &= w.open(dir + "/pcap/small.pcap", nullptr);
  pcap::UdpDatagram d;
  d.src_addr = 0xC0A801C8;
  d.dst_addr = 0xFFFFFFFF;
  d.src_port = d.dst_port = 2368;
  d.payload = std::span<const uint8_t>(pos);
  ok &= w.write(d);
  const std::size_t n1 = mid360_encode_points(meta, Mid360DataType::cartesian_low, pts, mp);
  d.payload = std::span<const uint8_t>(mp).first(n1);
  ok &= w.write(d);
  w.close();
  std::vector<uint8_t> lvx;
  pcap::Lvx2Writer lw(lvx);
  lw.add_device(pcap::Lvx2DeviceInfo{});
  for (int fr = 0; fr < 2; ++fr) {
    lw.begin_frame();
    ok &= lw.add_sdk_packet(std::span<const uint8_t>(mp).first(n1), 1);
    lw.end_frame();
  }
  ok &= put(dir + "/lvx2/two_frames.lvx2", lvx);
  if (!ok) {
    std::fprintf(stderr, "storey_fuzz_seeds: could not write seeds under %s\n", dir.c_str());
    return 1;
  }
  return 0;
}

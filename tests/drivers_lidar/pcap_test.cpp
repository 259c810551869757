// PcapReader/PcapWriter on generated captures (Ethernet+VLAN, SLL, SLL2, raw IP, pcapng written
// by hand) and the .lvx2 reader on a synthetic recording (no real .lvx2 file is available).
#include <gtest/gtest.h>
#include <pcap/pcap.h>

#include <cstdio>
#include <cstring>
#include <vector>

#include "drivers/lidar/mid360.hpp"
#include "drivers/pcap/lvx2_reader.hpp"
#include "drivers/pcap/pcap_reader.hpp"

namespace storey::drivers::pcap {
namespace {

std::string tmp_path(const std::string& name) {
  return std::string(STOREY_BINARY_DIR) + "/test_drivers_lidar_" + name;
}

void be16(std::vector<uint8_t>& v, uint16_t x) {
  v.push_back(static_cast<uint8_t>(x >> 8));
  v.push_back(static_cast<uint8_t>(x));
}

// IPv4 + UDP, built by hand. frag: flags/offset field.
std::vector<uint8_t> ip_udp(const std::vector<uint8_t>& payload, uint16_t sport, uint16_t dport,
                            uint16_t frag = 0x4000) {
  std::vector<uint8_t> v = {0x45, 0};
  be16(v, static_cast<uint16_t>(28 + payload.size()));
  be16(v, 1);
  be16(v, frag);
  v.push_back(64);
  v.push_back(17);
  be16(v, 0);
  for (uint8_t b : {10, 0, 0, 7, 10, 0, 0, 1}) v.push_back(b);
  be16(v, sport);
  be16(v, dport);
  be16(v, static_cast<uint16_t>(8 + payload.size()));
  be16(v, 0);
  v.insert(v.end(), payload.begin(), payload.end());
  return v;
}

std::vector<uint8_t> payload_of(uint8_t seed, std::size_t n) {
  std::vector<uint8_t> p(n);
  for (std::size_t i = 0; i < n; ++i) p[i] = static_cast<uint8_t>(seed + i * 7);
  return p;
}

void write_pcap(const std::string& path, int dlt, const std::vector<std::vector<uint8_t>>& frames) {
  pcap_t* dead = pcap_open_dead(dlt, 65535);
  ASSERT_NE(dead, nullptr);
  pcap_dumper_t* d = pcap_dump_open(dead, path.c_str());
  ASSERT_NE(d, nullptr) << pcap_geterr(dead);
  uint32_t t = 0;
  for (const auto& f : frames) {
    pcap_pkthdr h{};
    h.ts.tv_sec = 100;
    h.ts.tv_usec = ++t * 10;
    h.caplen = h.len = static_cast<bpf_u_int32>(f.size());
    pcap_dump(reinterpret_cast<u_char*>(d), &h, f.data());
  }
  pcap_dump_close(d);
  pcap_close(dead);
}

// Reads every datagram on port 2368 and checks payloads against payload_of(seed i).
void expect_payloads(const std::string& path, const std::vector<uint8_t>& seeds,
                     std::size_t n = 100) {
  PcapReader r;
  std::string err;
  ASSERT_TRUE(r.open(path, &err)) << err;
  r.add_port(2368);
  UdpDatagram d;
  std::size_t i = 0;
  while (r.next(d)) {
    ASSERT_LT(i, seeds.size());
    EXPECT_EQ(d.src_addr, 0x0A000007u);
    EXPECT_EQ(d.dst_port, 2368);
    const auto want = payload_of(seeds[i], n);
    ASSERT_EQ(d.payload.size(), want.size());
    EXPECT_TRUE(std::equal(want.begin(), want.end(), d.payload.begin()));
    ++i;
  }
  EXPECT_EQ(i, seeds.size()) << path;
}

TEST(PcapReader, EthernetWithVlanTagsAndFilters) {
  std::vector<std::vector<uint8_t>> frames;
  auto eth = [](uint16_t type, std::vector<uint8_t> rest, int vlans) {
    std::vector<uint8_t> f(12, 0xAB);
    for (int i = 0; i < vlans; ++i) {
      be16(f, i == 0 && vlans == 2 ? 0x88A8 : 0x8100);
      be16(f, 42);  // TCI
    }
    be16(f, type);
    f.insert(f.end(), rest.begin(), rest.end());
    return f;
  };
  frames.push_back(eth(0x0800, ip_udp(payload_of(1, 100), 2368, 2368), 0));
  frames.push_back(eth(0x0800, ip_udp(payload_of(2, 100), 2368, 2368), 1));          // 802.1Q
  frames.push_back(eth(0x0800, ip_udp(payload_of(3, 100), 2368, 2368), 2));          // QinQ
  frames.push_back(eth(0x0800, ip_udp(payload_of(4, 100), 9999, 9999), 0));          // filtered out
  frames.push_back(eth(0x0806, std::vector<uint8_t>(28, 0), 0));                     // ARP
  frames.push_back(eth(0x0800, ip_udp(payload_of(5, 100), 2368, 2368, 0x2000), 0));  // MF
  auto cut = eth(0x0800, ip_udp(payload_of(6, 100), 2368, 2368), 0);
  cut.resize(cut.size() - 10);  // snaplen-truncated
  frames.push_back(cut);
  const auto path = tmp_path("vlan.pcap");
  write_pcap(path, DLT_EN10MB, frames);
  expect_payloads(path, {1, 2, 3});
  PcapReader r;
  ASSERT_TRUE(r.open(path, nullptr));
  r.add_port(2368);
  UdpDatagram d;
  while (r.next(d)) {
  }
  EXPECT_EQ(r.stats().frames, 7u);
  EXPECT_EQ(r.stats().port_filtered, 1u);
  EXPECT_EQ(r.stats().not_ipv4, 1u);
  EXPECT_EQ(r.stats().ip_fragments, 1u);
  EXPECT_EQ(r.stats().truncated, 1u);
}

TEST(PcapReader, LinuxCookedSllAndSll2AndRawIp) {
  // SLL: pkttype, arphrd, addr len, addr[8], protocol (16 bytes)
  std::vector<std::vector<uint8_t>> sll;
  for (uint8_t s : {11, 12}) {
    std::vector<uint8_t> f = {0, 0, 0, 1, 0, 6, 1, 2, 3, 4, 5, 6, 0, 0};
    be16(f, 0x0800);
    auto ip = ip_udp(payload_of(s, 100), 2368, 2368);
    f.insert(f.end(), ip.begin(), ip.end());
    sll.push_back(f);
  }
  write_pcap(tmp_path("sll.pcap"), DLT_LINUX_SLL, sll);
  expect_payloads(tmp_path("sll.pcap"), {11, 12});
  // SLL2: protocol, reserved, ifindex, arphrd, pkttype, addr len, addr[8] (20 bytes)
  std::vector<std::vector<uint8_t>> sll2;
  for (uint8_t s : {21, 22, 23}) {
    std::vector<uint8_t> f;
    be16(f, 0x0800);
    for (uint8_t b : {0, 0, 0, 0, 0, 3, 0, 1, 0, 6, 1, 2, 3, 4, 5, 6, 0, 0}) f.push_back(b);
    auto ip = ip_udp(payload_of(s, 100), 2368, 2368);
    f.insert(f.end(), ip.begin(), ip.end());
    sll2.push_back(f);
  }
  write_pcap(tmp_path("sll2.pcap"), DLT_LINUX_SLL2, sll2);
  expect_payloads(tmp_path("sll2.pcap"), {21, 22, 23});
  write_pcap(tmp_path("raw.pcap"), DLT_RAW, {ip_udp(payload_of(31, 100), 2368, 2368)});
  expect_payloads(tmp_path("raw.pcap"), {31});
}

// pcapng written block by block (libpcap reads it but cannot write it).
TEST(PcapReader, PcapngWithNanosecondResolution) {
  std::vector<uint8_t> f;
  auto u32 = [&](uint32_t x) {
    for (int i = 0; i < 4; ++i) f.push_back(static_cast<uint8_t>(x >> (8 * i)));
  };
  auto u16 = [&](uint16_t x) {
    f.push_back(static_cast<uint8_t>(x));
    f.push_back(static_cast<uint8_t>(x >> 8));
  };
  // Section header block
  u32(0x0A0D0D0A);
  u32(28);
  u32(0x1A2B3C4D);
  u16(1);
  u16(0);
  u32(0xFFFFFFFF);
  u32(0xFFFFFFFF);
  u32(28);
  // Interface description block: Ethernet, if_tsresol = 9 (ns)
  u32(1);
  u32(32);
  u16(1);
  u16(0);
  u32(65535);
  u16(9);
  u16(1);
  f.push_back(9);
  f.push_back(0);
  f.push_back(0);
  f.push_back(0);
  u32(0);  // opt_endofopt
  u32(32);
  // Two enhanced packet blocks
  const uint64_t t0 = 1'700'000'000'123'456'789ull;
  for (uint8_t s : {41, 42}) {
    std::vector<uint8_t> frame(12, 0);
    be16(frame, 0x0800);
    auto ip = ip_udp(payload_of(s, 100), 2368, 2368);
    frame.insert(frame.end(), ip.begin(), ip.end());
    const uint32_t padded = static_cast<uint32_t>((frame.size() + 3) / 4 * 4);
    const uint64_t t = t0 + s;
    u32(6);
    u32(32 + padded);
    u32(0);
    u32(static_cast<uint32_t>(t >> 32));
    u32(static_cast<uint32_t>(t));
    u32(static_cast<uint32_t>(frame.size()));
    u32(static_cast<uint32_t>(frame.size()));
    f.insert(f.end(), frame.begin(), frame.end());
    f.resize(f.size() + (padded - frame.size()), 0);
    u32(32 + padded);
  }
  const auto path = tmp_path("capture.pcapng");
  FILE* fp = std::fopen(path.c_str(), "wb");
  ASSERT_NE(fp, nullptr);
  std::fwrite(f.data(), 1, f.size(), fp);
  std::fclose(fp);
  expect_payloads(path, {41, 42});
  PcapReader r;
  ASSERT_TRUE(r.open(path, nullptr));
  UdpDatagram d;
  ASSERT_TRUE(r.next(d));
  EXPECT_EQ(d.timestamp_ns, t0 + 41);
}

TEST(PcapReader, ErrorsNameTheFile) {
  PcapReader r;
  std::string err;
  EXPECT_FALSE(r.open("/nonexistent/x.pcap", &err));
  EXPECT_NE(err.find("/nonexistent/x.pcap"), std::string::npos);
  const auto path = tmp_path("garbage.pcap");
  FILE* fp = std::fopen(path.c_str(), "wb");
  std::fputs("this is not a capture file at all", fp);
  std::fclose(fp);
  EXPECT_FALSE(r.open(path, &err));
  EXPECT_NE(err.find("garbage.pcap"), std::string::npos);
}

TEST(PcapWriter, RoundTripThroughReader) {
  const auto path = tmp_path("written.pcap");
  PcapWriter w;
  std::string err;
  ASSERT_TRUE(w.open(path, &err)) << err;
  std::vector<std::vector<uint8_t>> payloads;
  for (int i = 0; i < 50; ++i) {
    payloads.push_back(payload_of(static_cast<uint8_t>(i), 1206));
    UdpDatagram d;
    d.timestamp_ns = 5'000'000'000ull + i * 1'327'000ull + 1;  // ns precision kept
    d.src_addr = 0xC0A801C8;
    d.dst_addr = 0xFFFFFFFF;
    d.src_port = 2368;
    d.dst_port = 2368;
    d.payload = payloads.back();
    ASSERT_TRUE(w.write(d));
  }
  w.close();
  PcapReader r;
  ASSERT_TRUE(r.open(path, &err)) << err;
  UdpDatagram d;
  int i = 0;
  while (r.next(d)) {
    EXPECT_EQ(d.timestamp_ns, 5'000'000'000ull + i * 1'327'000ull + 1);
    EXPECT_EQ(d.src_addr, 0xC0A801C8u);
    EXPECT_EQ(d.dst_addr, 0xFFFFFFFFu);
    EXPECT_FALSE(d.ip_length_mismatch);
    ASSERT_EQ(d.payload.size(), 1206u);
    EXPECT_TRUE(std::equal(payloads[i].begin(), payloads[i].end(), d.payload.begin()));
    ++i;
  }
  EXPECT_EQ(i, 50);
}

TEST(Lvx2, SyntheticRoundTripIntoMid360Decoder) {
  std::vector<uint8_t> file;
  Lvx2Writer w(file);
  Lvx2DeviceInfo dev{};
  std::memcpy(dev.lidar_sn, "47MDL9T0020193", 14);
  dev.lidar_id = 0xC0A8017B;
  dev.device_type = 9;
  w.add_device(dev);
  std::vector<std::vector<lidar::LidarPoint>> sent;
  std::array<uint8_t, 1500> buf;
  uint16_t cnt = 0;
  for (int frame = 0; frame < 3; ++frame) {
    w.begin_frame();
    for (int k = 0; k < 4; ++k) {
      std::vector<lidar::LidarPoint> pts(96);
      for (int i = 0; i < 96; ++i) {
        pts[i].x = 1.f + 0.001f * (frame * 1000 + k * 100 + i);
        pts[i].y = -2.f;
        pts[i].z = 0.5f;
        pts[i].intensity = static_cast<float>(i);
        pts[i].tag = static_cast<uint8_t>(k);
      }
      lidar::Mid360PacketMeta m;
      m.timestamp_ns = 1'000'000'000ull + (frame * 4 + k) * 480'000ull;
      m.time_interval = 4800;
      m.udp_cnt = cnt++;
      m.frame_cnt = static_cast<uint8_t>(frame);
      const auto type =
          k % 2 ? lidar::Mid360DataType::cartesian_low : lidar::Mid360DataType::cartesian_high;
      const std::size_t n = lidar::mid360_encode_points(m, type, pts, buf);
      ASSERT_TRUE(w.add_sdk_packet(std::span<const uint8_t>(buf).first(n), dev.lidar_id));
      sent.push_back(pts);
    }
    w.end_frame();
  }
  Lvx2Reader r;
  std::string err;
  ASSERT_TRUE(r.open(file, &err)) << err;
  ASSERT_EQ(r.devices().size(), 1u);
  EXPECT_EQ(r.devices()[0].device_type, 9);
  EXPECT_EQ(r.frame_duration_ms(), 50u);
  lidar::Mid360Decoder dec;
  Lvx2Package pkg;
  std::size_t idx = 0;
  std::array<lidar::LidarPoint, 96> out;
  while (r.next(pkg)) {
    ASSERT_LT(idx, sent.size());
    EXPECT_EQ(pkg.frame_index, idx / 4);
    const uint32_t lidar_id = pkg.header.lidar_id;  // packed field: copy, do not bind
    EXPECT_EQ(lidar_id, uint32_t(dev.lidar_id));
    const std::size_t n = lvx2_to_sdk_packet(pkg, 4800, buf);
    ASSERT_GT(n, 0u);
    const auto info = dec.decode(std::span<const uint8_t>(buf).first(n), out);
    ASSERT_EQ(info.reason, lidar::DropReason::none);
    ASSERT_EQ(info.points, 96u);
    EXPECT_EQ(info.timestamp_ns, 1'000'000'000ull + idx * 480'000ull);
    const double tol = (idx % 2) ? 0.006 : 0.0006;
    for (int i = 0; i < 96; ++i) {
      EXPECT_NEAR(out[i].x, sent[idx][i].x, tol);
      EXPECT_EQ(out[i].tag, sent[idx][i].tag);
      EXPECT_EQ(out[i].time_offset_ns, i * 5000);
    }
    ++idx;
  }
  EXPECT_TRUE(r.error().empty()) << r.error();
  EXPECT_EQ(idx, 12u);
  EXPECT_EQ(r.frames(), 3u);
  EXPECT_EQ(dec.lost_packets(), 0u);

  // Damage: bad magic, truncation inside a package, a frame offset that lies.
  auto bad = file;
  bad[20] ^= 0xFF;
  EXPECT_FALSE(Lvx2Reader().open(bad, &err));
  EXPECT_NE(err.find("magic"), std::string::npos);
  Lvx2Reader r2;
  std::vector<uint8_t> cut(file.begin(), file.end() - 50);
  ASSERT_TRUE(r2.open(cut, &err));
  std::size_t got = 0;
  while (r2.next(pkg)) ++got;
  EXPECT_EQ(got, 11u);
  EXPECT_NE(r2.error().find("package"), std::string::npos) << r2.error();
}

}  // namespace
}  // namespace storey::drivers::pcap

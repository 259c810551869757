// UDP ingestion on loopback: 2x the sensors' packet rates for 2 s (the 10 s version is in slow/),
// source filtering and drop reasons, and the pcap record -> replay round trip.
#include "drivers/lidar/udp_receiver.hpp"

#include <cstring>

#include "drivers/pcap/pcap_reader.hpp"
#include "loopback_harness.hpp"

namespace storey::drivers::lidar {
namespace {

using testing::LoopbackResult;

TEST(UdpReceiver, LoopbackVlp16TwiceRate2s) {
  LoopbackResult r;
  testing::run_loopback(SensorModel::vlp16, 2 * 754.0, 2.0, r);
  testing::expect_lossless(r);
  EXPECT_EQ(r.counters.points, r.sent * 384);
}

TEST(UdpReceiver, LoopbackMid360TwiceRate2s) {
  LoopbackResult r;
  testing::run_loopback(SensorModel::mid360, 2 * 2083.0, 2.0, r);
  testing::expect_lossless(r);
  EXPECT_EQ(r.counters.points, r.sent * 96);
}

TEST(UdpReceiver, WrongSourceAndMalformedCounted) {
  rt::SpscQueue<PointChunk> q(16);
  UdpReceiver::Options o;
  o.sensor = SensorModel::mid360;
  o.source_address = 0x0A010203;  // 10.1.2.3, not us
  UdpReceiver rx(o, q);
  std::array<uint8_t, 1500> buf;
  const std::size_t n = testing::make_packet(SensorModel::mid360, 1, buf);
  rx.process_datagram(std::span<const uint8_t>(buf).first(n), 0x7F000001, 56300, 1);
  rx.process_datagram(std::span<const uint8_t>(buf).first(n), 0x0A010203, 56300, 2);
  rx.process_datagram(std::span<const uint8_t>(buf).first(20), 0x0A010203, 56300, 3);
  buf[40] ^= 0xFF;  // CRC now wrong
  rx.process_datagram(std::span<const uint8_t>(buf).first(n), 0x0A010203, 56300, 4);
  buf[10] = 9;  // unknown data type
  rx.process_datagram(std::span<const uint8_t>(buf).first(n), 0x0A010203, 56300, 5);
  const auto c = rx.counters();
  EXPECT_EQ(c.datagrams, 5u);
  EXPECT_EQ(c.accepted, 1u);
  EXPECT_EQ(c.drops[static_cast<int>(DropReason::wrong_source)], 1u);
  EXPECT_EQ(c.drops[static_cast<int>(DropReason::short_packet)], 1u);
  EXPECT_EQ(c.drops[static_cast<int>(DropReason::bad_crc)], 1u);
  EXPECT_EQ(c.drops[static_cast<int>(DropReason::unknown_type)], 1u);
  EXPECT_EQ(q.size_approx(), 1u);
  // queue full: 16 slots, then counted
  buf[10] = 1;
  buf[40] ^= 0xFF;
  for (int i = 0; i < 20; ++i) {
    rx.process_datagram(std::span<const uint8_t>(buf).first(n), 0x0A010203, 56300, 10 + i);
  }
  EXPECT_EQ(rx.counters().drops[static_cast<int>(DropReason::queue_full)], 5u);
}

TEST(UdpReceiver, OpenReportsBufferAndErrors) {
  rt::SpscQueue<PointChunk> q(4);
  UdpReceiver::Options o;
  o.bind_address = "127.0.0.1";
  o.port = 0;
  o.receive_buffer_bytes = 1 << 30;  // more than any rmem_max: must warn, not fail
  UdpReceiver rx(o, q);
  const auto st = rx.open();
  ASSERT_TRUE(st.ok) << st.error;
  EXPECT_GT(st.receive_buffer, 0);
  if (st.receive_buffer / 2 < (1 << 30)) {
    EXPECT_NE(st.warning.find("rmem_max"), std::string::npos) << st.warning;
  }
  UdpReceiver::Options bad = o;
  bad.bind_address = "not-an-address";
  UdpReceiver rx2(bad, q);
  const auto st2 = rx2.open();
  EXPECT_FALSE(st2.ok);
  EXPECT_NE(st2.error.find("not-an-address"), std::string::npos);
}

// Live loopback traffic recorded with PcapWriter, replayed through process_datagram: identical
// points, chunk for chunk.
TEST(UdpReceiver, PcapRecordReplayIdentical) {
  rt::SpscQueue<PointChunk> live_q(512);
  rt::SpscQueue<RawDatagram> rec_q(512);
  UdpReceiver::Options o;
  o.bind_address = "127.0.0.1";
  o.port = 0;
  UdpReceiver rx(o, live_q);
  ASSERT_TRUE(rx.open().ok);
  rx.set_record_queue(&rec_q);
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(rx.bound_port());
  to.sin_addr.s_addr = htonl(0x7F000001);
  std::array<uint8_t, 1500> buf;
  constexpr int kPackets = 200;
  std::vector<PointChunk> live;
  const std::string path = std::string(STOREY_BINARY_DIR) + "/test_drivers_lidar_record.pcap";
  pcap::PcapWriter w;
  ASSERT_TRUE(w.open(path, nullptr));
  int sent = 0;
  while (static_cast<int>(live.size()) < kPackets) {
    if (sent < kPackets) {
      const std::size_t n = testing::make_packet(SensorModel::vlp16, sent++, buf);
      ::sendto(fd, buf.data(), n, 0, reinterpret_cast<sockaddr*>(&to), sizeof(to));
    }
    rx.poll(sent < kPackets ? 0 : 100);
    PointChunk c;
    while (live_q.try_pop(c)) live.push_back(c);
    RawDatagram* r;
    while ((r = rec_q.front()) != nullptr) {  // the recording thread's job in the firmware
      pcap::UdpDatagram d;
      d.timestamp_ns = r->receive_time_ns;
      d.src_addr = r->src_addr;
      d.dst_addr = r->dst_addr;
      d.src_port = r->src_port;
      d.dst_port = r->dst_port;
      d.payload = std::span<const uint8_t>(r->data.data(), r->size);
      ASSERT_TRUE(w.write(d));
      rec_q.pop();
    }
    if (sent == kPackets && rx.counters().datagrams == static_cast<uint64_t>(kPackets) &&
        live_q.size_approx() == 0 && static_cast<int>(live.size()) < kPackets) {
      break;  // lost something: fail below rather than spin
    }
  }
  ::close(fd);
  w.close();
  ASSERT_EQ(static_cast<int>(live.size()), kPackets);

  pcap::PcapReader reader;
  ASSERT_TRUE(reader.open(path, nullptr));
  reader.add_port(rx.bound_port());
  rt::SpscQueue<PointChunk> replay_q(512);
  UdpReceiver replay(o, replay_q);  // not opened: replay feeds it directly
  pcap::UdpDatagram d;
  while (reader.next(d)) replay.process_datagram(d.payload, d.src_addr, d.src_port, d.timestamp_ns);
  ASSERT_EQ(replay.counters().accepted, static_cast<uint64_t>(kPackets));
  for (int i = 0; i < kPackets; ++i) {
    PointChunk c;
    ASSERT_TRUE(replay_q.try_pop(c));
    EXPECT_EQ(c.receive_time_ns, live[i].receive_time_ns);  // capture time = kernel stamp
    EXPECT_EQ(c.sensor_stamp_ns, live[i].sensor_stamp_ns);
    ASSERT_EQ(c.count, live[i].count);
    EXPECT_EQ(std::memcmp(c.points.data(), live[i].points.data(), c.count * sizeof(LidarPoint)), 0)
        << "chunk " << i;
  }
}

}  // namespace
}  // namespace storey::drivers::lidar

#pragma once
// Loopback harness: a sender thread at a fixed packet rate, the receiver on its own thread
// (epoll + recvmmsg), a consumer checking every chunk in order. Shared by the 2 s test (default
// run) and the 10 s test (label "slow").
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <ctime>
#include <thread>
#include <vector>

#include "drivers/lidar/mid360.hpp"
#include "drivers/lidar/udp_receiver.hpp"
#include "drivers/lidar/vlp16.hpp"

namespace storey::drivers::lidar::testing {

// Packet k of a stream: a distinct stamp (k) and all returns present.
inline std::size_t make_packet(SensorModel s, uint32_t k, std::span<uint8_t> out) {
  if (s == SensorModel::vlp16) {
    std::array<Vlp16Firing, kVlp16FiringsPerPacket> f{};
    for (int i = 0; i < kVlp16FiringsPerPacket; ++i) {
      f[i].azimuth_cdeg = static_cast<uint16_t>((k * 24 * 20 + i * 20) % 36000);
      for (int l = 0; l < 16; ++l) f[i].range_m[l] = 2.f + 0.01f * ((k + i + l) % 1000);
      f[i].reflectivity.fill(static_cast<uint8_t>(k));
    }
    return vlp16_encode_firings(f, k, Vlp16ReturnMode::strongest, 0x22, out);
  }
  std::array<LidarPoint, 96> pts;
  for (int i = 0; i < 96; ++i) {
    pts[i].x = 1.f + 0.001f * ((k + i) % 1000);
    pts[i].y = -1.f;
    pts[i].z = 0.25f;
    pts[i].intensity = static_cast<float>(k % 256);
  }
  Mid360PacketMeta m;
  m.timestamp_ns = k;
  m.time_interval = 4800;
  m.udp_cnt = static_cast<uint16_t>(k % 210);  // ~210 packets per 100 ms frame
  m.frame_cnt = static_cast<uint8_t>(k / 210);
  return mid360_encode_points(m, Mid360DataType::cartesian_high, pts, out);
}

struct LoopbackResult {
  uint64_t sent = 0, received_chunks = 0, out_of_order = 0, bad_content = 0;
  UdpReceiver::Counters counters;
  std::vector<int64_t> latency_ns;  // kernel receive -> enqueue
};

inline void run_loopback(SensorModel sensor, double rate_hz, double seconds, LoopbackResult& res,
                         bool keep_latency = false) {
  rt::SpscQueue<PointChunk> queue(1024);
  UdpReceiver::Options opt;
  opt.sensor = sensor;
  opt.bind_address = "127.0.0.1";
  opt.port = 0;
  opt.source_address = 0x7F000001;
  UdpReceiver rx(opt, queue);
  const auto st = rx.open();
  ASSERT_TRUE(st.ok) << st.error;
  if (!st.warning.empty()) std::fprintf(stderr, "warning: %s\n", st.warning.c_str());

  std::atomic<bool> sending{true}, stop{false};
  const uint64_t total = static_cast<uint64_t>(rate_hz * seconds);
  std::thread receiver([&] {
    while (!stop.load(std::memory_order_acquire)) rx.poll(5);
  });
  std::thread sender([&] {
    const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_port = htons(rx.bound_port());
    to.sin_addr.s_addr = htonl(0x7F000001);
    std::array<uint8_t, 1500> buf;
    timespec t0;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    timespec next = t0;
    uint64_t k = 0;
    while (k < total) {
      next.tv_nsec += 1'000'000;  // 1 ms ticks, as many packets as the rate owes
      if (next.tv_nsec >= 1'000'000'000) {
        next.tv_nsec -= 1'000'000'000;
        ++next.tv_sec;
      }
      clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, nullptr);
      const double el = (next.tv_sec - t0.tv_sec) + (next.tv_nsec - t0.tv_nsec) * 1e-9;
      const uint64_t owed = std::min<uint64_t>(total, static_cast<uint64_t>(el * rate_hz));
      for (; k < owed; ++k) {
        const std::size_t n = make_packet(sensor, static_cast<uint32_t>(k), buf);
        ::sendto(fd, buf.data(), n, 0, reinterpret_cast<sockaddr*>(&to), sizeof(to));
      }
    }
    ::close(fd);
    sending.store(false, std::memory_order_release);
  });
  // Consumer: every chunk in order with the expected content.
  uint64_t expect = 0;
  timespec idle_since{};
  bool idle = false;
  for (;;) {
    PointChunk* c = queue.front();
    if (c == nullptr) {
      if (!sending.load(std::memory_order_acquire)) {
        timespec now;
        clock_gettime(CLOCK_MONOTONIC, &now);
        if (!idle) {
          idle = true;
          idle_since = now;
        } else if (now.tv_sec - idle_since.tv_sec >= 1) {
          break;  // 1 s with nothing more after the sender finished
        }
      }
      std::this_thread::sleep_for(std::chrono::microseconds(200));
      continue;
    }
    idle = false;
    if (c->sensor_stamp_ns != (sensor == SensorModel::vlp16 ? expect * 1000 : expect)) {
      ++res.out_of_order;
    }
    const uint32_t want = sensor == SensorModel::vlp16 ? 384u : 96u;
    if (c->count != want) ++res.bad_content;
    if (keep_latency) {
      res.latency_ns.push_back(static_cast<int64_t>(c->enqueue_time_ns - c->receive_time_ns));
    }
    ++expect;
    ++res.received_chunks;
    queue.pop();
  }
  stop.store(true, std::memory_order_release);
  sender.join();
  receiver.join();
  res.sent = total;
  res.counters = rx.counters();
}

inline void expect_lossless(const LoopbackResult& r) {
  EXPECT_EQ(r.received_chunks, r.sent);
  EXPECT_EQ(r.counters.accepted, r.sent);
  EXPECT_EQ(r.out_of_order, 0u);
  EXPECT_EQ(r.bad_content, 0u);
  EXPECT_EQ(r.counters.lost_udp_cnt, 0u);
  for (std::size_t i = 1; i < kDropReasonCount; ++i) {
    EXPECT_EQ(r.counters.drops[i], 0u) << to_string(static_cast<DropReason>(i));
  }
}

}  // namespace storey::drivers::lidar::testing

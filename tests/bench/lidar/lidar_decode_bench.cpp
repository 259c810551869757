// LiDAR decode throughput (points/s on one core) and packet-to-queue latency on loopback.
// decode_vlp16/naive is the same decode with per-point std::sin/std::cos instead of the tables:
// the baseline the table buys against.
#include <arpa/inet.h>
#include <benchmark/benchmark.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <thread>
#include <vector>

#include "drivers/lidar/mid360.hpp"
#include "drivers/lidar/udp_receiver.hpp"
#include "drivers/lidar/vlp16.hpp"

namespace {

using namespace storey::drivers::lidar;

std::vector<std::array<uint8_t, kVlp16DataPacketSize>> vlp16_packets(int n) {
  std::vector<std::array<uint8_t, kVlp16DataPacketSize>> v(n);
  for (int k = 0; k < n; ++k) {
    std::array<Vlp16Firing, kVlp16FiringsPerPacket> f{};
    for (int i = 0; i < kVlp16FiringsPerPacket; ++i) {
      f[i].azimuth_cdeg = static_cast<uint16_t>((k * 480 + i * 20) % 36000);
      for (int l = 0; l < 16; ++l) f[i].range_m[l] = 1.f + 0.05f * ((k * 7 + i * 3 + l) % 600);
    }
    vlp16_encode_firings(f, static_cast<uint32_t>(k), Vlp16ReturnMode::strongest, 0x22, v[k]);
  }
  return v;
}

void BM_DecodeVlp16(benchmark::State& state) {
  const auto pkts = vlp16_packets(256);
  Vlp16Decoder dec;
  std::array<LidarPoint, kVlp16MaxPointsPerPacket> out;
  uint64_t points = 0;
  std::size_t i = 0;
  for (auto _ : state) {
    const auto info = dec.decode(pkts[i++ & 255], out);
    benchmark::DoNotOptimize(out.data());
    points += info.points;
  }
  state.SetItemsProcessed(static_cast<int64_t>(points));
}
BENCHMARK(BM_DecodeVlp16)->Name("decode_vlp16/storey");

void BM_DecodeVlp16Naive(benchmark::State& state) {
  const auto pkts = vlp16_packets(256);
  std::array<LidarPoint, kVlp16MaxPointsPerPacket> out;
  uint64_t points = 0;
  std::size_t i = 0;
  for (auto _ : state) {
    std::size_t n = 0;
    vlp16_for_each_return(pkts[i++ & 255], [&](const Vlp16RawReturn& r) {
      const double a = r.azimuth_cdeg * (M_PI / 18000.0);
      const double w = kVlp16ElevationDeg[r.laser] * (M_PI / 180.0);
      const double range = r.distance * 0.002;
      LidarPoint& p = out[n++];
      p.x = static_cast<float>(range * std::cos(w) * std::sin(a));
      p.y = static_cast<float>(range * std::cos(w) * std::cos(a));
      p.z = static_cast<float>(range * std::sin(w));
      p.intensity = r.reflectivity;
      p.ring = r.ring;
      p.time_offset_ns = r.time_offset_ns;
    });
    benchmark::DoNotOptimize(out.data());
    points += n;
  }
  state.SetItemsProcessed(static_cast<int64_t>(points));
}
BENCHMARK(BM_DecodeVlp16Naive)->Name("decode_vlp16/naive");

void BM_DecodeMid360(benchmark::State& state) {
  const auto type = static_cast<Mid360DataType>(state.range(0));
  std::vector<std::vector<uint8_t>> pkts;
  std::vector<LidarPoint> pts(96);
  for (int k = 0; k < 64; ++k) {
    for (int i = 0; i < 96; ++i) {
      pts[i] = LidarPoint{0.5f + 0.01f * (i + k), -3.f + 0.02f * i, 0.1f * (i % 9), 30.f};
    }
    std::vector<uint8_t> b(1500);
    Mid360PacketMeta m{
        static_cast<uint64_t>(k) * 480000, 4800, static_cast<uint16_t>(k), 0, 0, true};
    b.resize(mid360_encode_points(m, type, pts, b));
    pkts.push_back(std::move(b));
  }
  Mid360Decoder dec;  // CRC verified (the sensor fills it): part of the cost
  std::array<LidarPoint, 96> out;
  uint64_t points = 0;
  std::size_t i = 0;
  for (auto _ : state) {
    const auto info = dec.decode(pkts[i++ & 63], out);
    benchmark::DoNotOptimize(out.data());
    points += info.points;
  }
  state.SetItemsProcessed(static_cast<int64_t>(points));
}
BENCHMARK(BM_DecodeMid360)->Name("decode_mid360/storey")->Arg(1)->Arg(2)->Arg(3);

// Kernel receive stamp (SO_TIMESTAMPNS) -> chunk pushed into the SPSC queue, on loopback at the
// VLP-16's doubled rate, receiver on its own thread. Percentiles as counters [us].
void BM_PacketToQueueLatency(benchmark::State& state) {
  for (auto _ : state) {
    storey::rt::SpscQueue<PointChunk> q(1024);
    UdpReceiver::Options o;
    o.bind_address = "127.0.0.1";
    o.port = 0;
    UdpReceiver rx(o, q);
    if (!rx.open().ok) {
      state.SkipWithError("cannot open loopback socket");
      return;
    }
    std::atomic<bool> stop{false};
    std::thread t([&] {
      while (!stop.load()) rx.poll(5);
    });
    const auto pkts = vlp16_packets(64);
    const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_port = htons(rx.bound_port());
    to.sin_addr.s_addr = htonl(0x7F000001);
    std::vector<double> lat;
    const int n = 3000;  // ~2 s at 1508 packets/s
    for (int k = 0; k < n; ++k) {
      ::sendto(fd, pkts[k & 63].data(), kVlp16DataPacketSize, 0, reinterpret_cast<sockaddr*>(&to),
               sizeof(to));
      std::this_thread::sleep_for(std::chrono::microseconds(663));
      PointChunk* c;
      while ((c = q.front()) != nullptr) {
        lat.push_back((c->enqueue_time_ns - c->receive_time_ns) * 1e-3);
        q.pop();
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    PointChunk* c;
    while ((c = q.front()) != nullptr) {
      lat.push_back((c->enqueue_time_ns - c->receive_time_ns) * 1e-3);
      q.pop();
    }
    stop = true;
    t.join();
    ::close(fd);
    std::sort(lat.begin(), lat.end());
    if (lat.empty()) {
      state.SkipWithError("nothing received");
      return;
    }
    auto pct = [&](double p) {
      return lat[std::min(lat.size() - 1, static_cast<std::size_t>(p * lat.size()))];
    };
    state.counters["p50_us"] = pct(0.50);
    state.counters["p99_us"] = pct(0.99);
    state.counters["max_us"] = lat.back();
    state.counters["received"] = static_cast<double>(lat.size());
  }
}
BENCHMARK(BM_PacketToQueueLatency)
    ->Name("lidar_packet_to_queue_latency")
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

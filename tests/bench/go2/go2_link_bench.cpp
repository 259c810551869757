// Go2 link command latency: from the firmware's send_velocity() call to the robot stand-in's
// receipt of the decoded command, per transport, over loopback. The stand-in runs on its own
// thread, busy-polling; each command is sent after the previous one arrived (no queueing), so
// the figure is the one-way latency of one command. Counters: p50_us, p90_us, p99_us, max_us.
// Baseline in the same run: a bare 20-byte UDP datagram between two loopback sockets.
#include <benchmark/benchmark.h>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <memory>
#include <thread>
#include <vector>

#include "drivers/can/udp_socket.hpp"
#include "drivers/go2/dds_link.hpp"
#include "drivers/go2/framed_link.hpp"
#include "drivers/go2/robot_standin.hpp"

namespace storey::drivers::go2 {
namespace {

int64_t mono_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

void report(benchmark::State& state, std::vector<int64_t>& lat, int64_t lost) {
  if (lat.empty()) {
    state.SkipWithError("no command arrived");
    return;
  }
  std::sort(lat.begin(), lat.end());
  auto pct = [&](double p) {
    return static_cast<double>(lat[static_cast<size_t>(p * (lat.size() - 1))]) / 1e3;
  };
  state.counters["p50_us"] = pct(0.50);
  state.counters["p90_us"] = pct(0.90);
  state.counters["p99_us"] = pct(0.99);
  state.counters["max_us"] = static_cast<double>(lat.back()) / 1e3;
  state.counters["lost"] = static_cast<double>(lost);
  state.SetItemsProcessed(static_cast<int64_t>(lat.size()));
}

enum class Transport { udp, can_classic, can_fd, dds };

void BM_CommandLatency(benchmark::State& state, Transport transport) {
  StandinOptions so;
  so.local = {"127.0.0.1", 0};
  so.host = {"127.0.0.1", 0};
  so.state_period_ns = 20'000'000;  // 50 Hz state, as background traffic
  so.transport = transport == Transport::udp   ? StandinTransport::udp
                 : transport == Transport::dds ? StandinTransport::dds
                                               : StandinTransport::can_over_udp;
  so.can.fd = transport == Transport::can_fd;
  so.dds = dds_loopback(77);
  const int64_t t0 = mono_ns();
  RobotStandin robot(so, t0);
  if (!robot.ok()) {
    state.SkipWithError(robot.error());
    return;
  }
  LinkOptions lo;
  lo.max_command_age_ns = 1'000'000'000;
  std::unique_ptr<RobotLink> link;
  const UdpEndpoint robot_ep{"127.0.0.1", robot.local_port()};
  if (transport == Transport::udp) {
    link = std::make_unique<UdpLink>(UdpEndpoint{"127.0.0.1", 0}, robot_ep, lo, t0);
  } else if (transport == Transport::dds) {
    DdsLinkOptions d;
    d.network = so.dds;
    d.link = lo;
    link = std::make_unique<DdsLink>(d, t0);
  } else {
    CanChannelOptions co;
    co.fd = transport == Transport::can_fd;
    link = std::make_unique<CanOverUdpLink>(UdpEndpoint{"127.0.0.1", 0}, robot_ep, co, lo, t0);
  }
  if (!link->ok()) {
    state.SkipWithError(link->error());
    return;
  }
  std::atomic<int64_t> received{0};
  std::atomic<int64_t> last_latency{0};
  robot.on_command = [&](const StandinCommand& c) {
    if (c.kind != StandinCommand::Kind::velocity) return;
    last_latency.store(mono_ns() - c.velocity.stamp_ns, std::memory_order_relaxed);
    received.fetch_add(1, std::memory_order_release);
  };
  std::atomic<bool> stop{false};
  std::thread robot_thread([&] {
    while (!stop.load(std::memory_order_relaxed)) robot.step(mono_ns());
  });
  // Let discovery / peer learning settle: the host heartbeat reaches the stand-in.
  for (int i = 0; i < 200; ++i) {
    link->poll(mono_ns());
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  std::vector<int64_t> lat;
  lat.reserve(100000);
  int64_t lost = 0;
  for (auto _ : state) {
    const int64_t before = received.load(std::memory_order_acquire);
    const int64_t t = mono_ns();
    link->send_velocity(VelocityCommand{t, 0.5f, 0.0f, 0.1f}, t);
    const int64_t deadline = t + 100'000'000;
    while (received.load(std::memory_order_acquire) == before && mono_ns() < deadline) {
    }
    if (received.load(std::memory_order_acquire) == before) {
      ++lost;
      continue;
    }
    lat.push_back(last_latency.load(std::memory_order_relaxed));
    link->poll(mono_ns());  // drain state as the control task would
  }
  stop = true;
  robot_thread.join();
  report(state, lat, lost);
}

void BM_RawUdpBaseline(benchmark::State& state) {
  can::UdpSocket rx, tx;
  if (!rx.open({"127.0.0.1", 0}, {"127.0.0.1", 1}) ||
      !tx.open({"127.0.0.1", 0}, {"127.0.0.1", rx.local_port()})) {
    state.SkipWithError("socket setup failed");
    return;
  }
  std::atomic<int64_t> received{0}, last_latency{0};
  std::atomic<bool> stop{false};
  std::thread t([&] {
    uint8_t buf[64];
    while (!stop.load(std::memory_order_relaxed)) {
      size_t n = 0;
      if (rx.receive(buf, sizeof(buf), n) == can::UdpSocket::Io::ok && n == 20) {
        int64_t sent;
        std::memcpy(&sent, buf, 8);
        last_latency.store(mono_ns() - sent, std::memory_order_relaxed);
        received.fetch_add(1, std::memory_order_release);
      }
    }
  });
  std::vector<int64_t> lat;
  lat.reserve(100000);
  int64_t lost = 0;
  uint8_t msg[20] = {};
  for (auto _ : state) {
    const int64_t before = received.load(std::memory_order_acquire);
    const int64_t s = mono_ns();
    std::memcpy(msg, &s, 8);
    tx.send(msg, sizeof(msg));
    const int64_t deadline = s + 100'000'000;
    while (received.load(std::memory_order_acquire) == before && mono_ns() < deadline) {
    }
    if (received.load(std::memory_order_acquire) == before) {
      ++lost;
      continue;
    }
    lat.push_back(last_latency.load(std::memory_order_relaxed));
  }
  stop = true;
  t.join();
  report(state, lat, lost);
}

BENCHMARK_CAPTURE(BM_CommandLatency, udp, Transport::udp)
    ->Name("go2_command_latency/udp")
    ->Iterations(5000)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_CommandLatency, can_classic, Transport::can_classic)
    ->Name("go2_command_latency/can_over_udp_classic")
    ->Iterations(5000)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_CommandLatency, can_fd, Transport::can_fd)
    ->Name("go2_command_latency/can_over_udp_fd")
    ->Iterations(5000)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_CommandLatency, dds, Transport::dds)
    ->Name("go2_command_latency/dds_in_process")
    ->Iterations(5000)
    ->UseRealTime();
BENCHMARK(BM_RawUdpBaseline)
    ->Name("go2_command_latency/raw_udp_baseline")
    ->Iterations(5000)
    ->UseRealTime();

}  // namespace
}  // namespace storey::drivers::go2

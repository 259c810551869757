// SPSC queue vs a mutex-protected std::deque: throughput (two threads) and ping-pong latency.
// Both run through the same template with the same capacity, pinning and spin policy.
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdint>
#include <deque>
#include <mutex>
#include <thread>

#include <time.h>

#include "rt/rt_setup.hpp"
#include "rt/spsc_queue.hpp"

namespace {

using storey::rt::SpscQueue;

// The baseline: the queue people write first. Bounded like ours, so the comparison is fair.
template <typename T>
class MutexDequeQueue {
 public:
  explicit MutexDequeQueue(std::size_t capacity) : capacity_(capacity) {}
  bool try_push(const T& v) {
    std::lock_guard<std::mutex> lock(m_);
    if (d_.size() >= capacity_) return false;
    d_.push_back(v);
    return true;
  }
  bool try_pop(T& v) {
    std::lock_guard<std::mutex> lock(m_);
    if (d_.empty()) return false;
    v = d_.front();
    d_.pop_front();
    return true;
  }

 private:
  std::mutex m_;
  std::deque<T> d_;
  std::size_t capacity_;
};

constexpr std::size_t kCapacity = 1 << 14;
constexpr std::uint64_t kBatch = 1 << 16;
constexpr std::uint64_t kStop = ~std::uint64_t{0};

// Spin briefly, then yield: the machine is shared (2 cores, other jobs), and a thread spinning
// through its whole time slice while its peer is descheduled measures the OS, not the queue.
struct Backoff {
  int spins = 0;
  void operator()() {
    if (++spins > 1024) {
      spins = 0;
      std::this_thread::yield();
    }
  }
};

// items_per_second on the wall clock (two threads work; the main thread's CPU time would
// flatter whichever queue sleeps more). Set as a plain counter so the names stay exactly
// <what>/storey and <what>/mutex_deque (UseRealTime() would append "/real_time").
double thread_cpu_s() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

void set_rate(benchmark::State& state, double items, std::chrono::steady_clock::time_point t0) {
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  state.counters["items_per_second"] = items / s;
  state.counters["wall_ns_per_item"] = s * 1e9 / items;
}

// Producer on CPU 0 (the benchmark thread), consumer on CPU 1 (best effort: pinning may fail).
template <class Q>
void spsc_throughput(benchmark::State& state) {
  Q q(kCapacity);
  storey::rt::pin_cpu(0);
  std::uint64_t received = 0;
  double consumer_cpu = 0;
  std::thread consumer([&] {
    storey::rt::pin_cpu(1);
    const double c0 = thread_cpu_s();
    std::uint64_t v = 0;
    Backoff wait;
    for (;;) {
      if (!q.try_pop(v)) {
        wait();
        continue;
      }
      if (v == kStop) break;
      benchmark::DoNotOptimize(v);
      ++received;
    }
    consumer_cpu = thread_cpu_s() - c0;
  });
  Backoff wait;
  const auto t0 = std::chrono::steady_clock::now();
  const double p0 = thread_cpu_s();
  for (auto _ : state) {
    for (std::uint64_t i = 0; i < kBatch; ++i) {
      while (!q.try_push(i)) wait();
    }
  }
  while (!q.try_push(kStop)) wait();
  const double producer_cpu = thread_cpu_s() - p0;
  consumer.join();
  if (received != state.iterations() * kBatch) state.SkipWithError("items lost");
  const double items = static_cast<double>(state.iterations() * kBatch);
  set_rate(state, items, t0);
  // CPU spent by both threads per item (including waiting): the cost of the queue, much less
  // sensitive than the wall-clock rate to whether the OS runs both threads at once.
  state.counters["cpu_ns_per_item"] = (producer_cpu + consumer_cpu) * 1e9 / items;
}

// One item to the echo thread and back per iteration: Time is the round-trip latency.
template <class Q>
void spsc_roundtrip(benchmark::State& state) {
  Q ping(kCapacity), pong(kCapacity);
  storey::rt::pin_cpu(0);
  std::thread echo([&] {
    storey::rt::pin_cpu(1);
    std::uint64_t v = 0;
    Backoff wait;
    for (;;) {
      if (!ping.try_pop(v)) {
        wait();
        continue;
      }
      while (!pong.try_push(v)) wait();
      if (v == kStop) break;
    }
  });
  std::uint64_t i = 0, v = 0;
  Backoff wait;
  const auto t0 = std::chrono::steady_clock::now();
  for (auto _ : state) {
    while (!ping.try_push(i)) wait();
    while (!pong.try_pop(v)) wait();
    ++i;
  }
  set_rate(state, static_cast<double>(state.iterations()), t0);  // round trips per second
  while (!ping.try_push(kStop)) wait();
  echo.join();
}

BENCHMARK_TEMPLATE(spsc_throughput, SpscQueue<std::uint64_t>)->Name("spsc_throughput/storey");
BENCHMARK_TEMPLATE(spsc_throughput, MutexDequeQueue<std::uint64_t>)
    ->Name("spsc_throughput/mutex_deque");
BENCHMARK_TEMPLATE(spsc_roundtrip, SpscQueue<std::uint64_t>)->Name("spsc_roundtrip/storey");
BENCHMARK_TEMPLATE(spsc_roundtrip, MutexDequeQueue<std::uint64_t>)
    ->Name("spsc_roundtrip/mutex_deque");

}  // namespace

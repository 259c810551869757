// SPSC queue vs a mutex-protected std::deque: throughput (two threads) and ping-pong latency.
// Both run through the same template with the same capacity, pinning and spin policy.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <deque>
#include <mutex>
#include <thread>

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

constexpr std::size_t kCapacity = 1024;
constexpr std::uint64_t kBatch = 1 << 16;
constexpr std::uint64_t kStop = ~std::uint64_t{0};

// Producer on CPU 0 (the benchmark thread), consumer on CPU 1 (best effort: pinning may fail).
template <class Q>
void spsc_throughput(benchmark::State& state) {
  Q q(kCapacity);
  storey::rt::pin_cpu(0);
  std::uint64_t received = 0;
  std::thread consumer([&] {
    storey::rt::pin_cpu(1);
    std::uint64_t v = 0;
    for (;;) {
      if (!q.try_pop(v)) continue;
      if (v == kStop) break;
      benchmark::DoNotOptimize(v);
      ++received;
    }
  });
  for (auto _ : state) {
    for (std::uint64_t i = 0; i < kBatch; ++i) {
      while (!q.try_push(i)) {
      }
    }
  }
  while (!q.try_push(kStop)) {
  }
  consumer.join();
  if (received != state.iterations() * kBatch) state.SkipWithError("items lost");
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kBatch));
}

// One item to the echo thread and back per iteration: Time is the round-trip latency.
template <class Q>
void spsc_roundtrip(benchmark::State& state) {
  Q ping(kCapacity), pong(kCapacity);
  storey::rt::pin_cpu(0);
  std::thread echo([&] {
    storey::rt::pin_cpu(1);
    std::uint64_t v = 0;
    for (;;) {
      if (!ping.try_pop(v)) continue;
      while (!pong.try_push(v)) {
      }
      if (v == kStop) break;
    }
  });
  std::uint64_t i = 0, v = 0;
  for (auto _ : state) {
    while (!ping.try_push(i)) {
    }
    while (!pong.try_pop(v)) {
    }
    ++i;
  }
  while (!ping.try_push(kStop)) {
  }
  echo.join();
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
}

BENCHMARK_TEMPLATE(spsc_throughput, SpscQueue<std::uint64_t>)
    ->Name("spsc_throughput/storey")
    ->UseRealTime()
    ->MinTime(1.0);
BENCHMARK_TEMPLATE(spsc_throughput, MutexDequeQueue<std::uint64_t>)
    ->Name("spsc_throughput/mutex_deque")
    ->UseRealTime()
    ->MinTime(1.0);
BENCHMARK_TEMPLATE(spsc_roundtrip, SpscQueue<std::uint64_t>)
    ->Name("spsc_roundtrip/storey")
    ->UseRealTime()
    ->MinTime(1.0);
BENCHMARK_TEMPLATE(spsc_roundtrip, MutexDequeQueue<std::uint64_t>)
    ->Name("spsc_roundtrip/mutex_deque")
    ->UseRealTime()
    ->MinTime(1.0);

}  // namespace

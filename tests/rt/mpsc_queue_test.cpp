#include "rt/mpsc_queue.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <thread>
#include <vector>

namespace storey::rt {
namespace {

TEST(MpscQueue, CapacityRoundsUpAndFullEmpty) {
  MpscQueue<int> q(3);
  EXPECT_EQ(q.capacity(), 4u);
  for (int i = 0; i < 4; ++i) EXPECT_TRUE(q.try_push(i));
  EXPECT_FALSE(q.try_push(99));
  int v;
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(q.try_pop(v));
    EXPECT_EQ(v, i);
  }
  EXPECT_FALSE(q.try_pop(v));
}

TEST(MpscQueue, DestroysRemainingElements) {
  auto counted = std::make_shared<int>(0);
  {
    MpscQueue<std::shared_ptr<int>> q(8);
    for (int i = 0; i < 3; ++i) ASSERT_TRUE(q.try_push(counted));
  }
  EXPECT_EQ(counted.use_count(), 1);
}

// Several producers, millions of items: per-producer order kept, nothing lost or duplicated.
TEST(MpscQueue, ProducersKeepOrderNoLossNoDuplication) {
  constexpr int kProducers = 4;
#if defined(__SANITIZE_THREAD__)
  constexpr std::uint64_t kPerProducer = 250'000;
#else
  constexpr std::uint64_t kPerProducer = 1'000'000;
#endif
  MpscQueue<std::uint64_t> q(256);  // value = producer << 32 | sequence
  std::vector<std::thread> producers;
  for (std::uint64_t p = 0; p < kProducers; ++p) {
    producers.emplace_back([&q, p] {
      for (std::uint64_t i = 0; i < kPerProducer; ++i) {
        while (!q.try_push((p << 32) | i)) std::this_thread::yield();
      }
    });
  }
  std::vector<std::uint64_t> next(kProducers, 0);
  bool ok = true;
  std::uint64_t received = 0;
  while (received < kProducers * kPerProducer) {
    std::uint64_t v;
    if (!q.try_pop(v)) continue;
    const std::uint64_t p = v >> 32, i = v & 0xffffffffu;
    ok &= p < kProducers && i == next[p];
    if (p < kProducers) next[p] = i + 1;
    ++received;
  }
  for (auto& t : producers) t.join();
  EXPECT_TRUE(ok);
  for (int p = 0; p < kProducers; ++p) EXPECT_EQ(next[p], kPerProducer) << "producer " << p;
  std::uint64_t v;
  EXPECT_FALSE(q.try_pop(v));
}

}  // namespace
}  // namespace storey::rt

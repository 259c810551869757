#include "rt/spsc_queue.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <string>
#include <thread>

namespace storey::rt {
namespace {

TEST(SpscQueue, FifoAndFullEmpty) {
  SpscQueue<int> q(3);
  EXPECT_EQ(q.capacity(), 3u);
  EXPECT_EQ(q.front(), nullptr);
  EXPECT_TRUE(q.try_push(1));
  EXPECT_TRUE(q.try_push(2));
  EXPECT_TRUE(q.try_emplace(3));
  EXPECT_FALSE(q.try_push(4));  // full: nothing constructed, nothing blocks
  EXPECT_EQ(q.size_approx(), 3u);
  int v = 0;
  ASSERT_TRUE(q.try_pop(v));
  EXPECT_EQ(v, 1);
  EXPECT_TRUE(q.try_push(4));  // wraps around
  for (int want : {2, 3, 4}) {
    ASSERT_NE(q.front(), nullptr);
    EXPECT_EQ(*q.front(), want);
    q.pop();
  }
  EXPECT_FALSE(q.try_pop(v));
  EXPECT_TRUE(q.empty_approx());
}

TEST(SpscQueue, RejectsZeroCapacity) {
  EXPECT_THROW(SpscQueue<int>(0), std::invalid_argument);
}

TEST(SpscQueue, DestroysRemainingElements) {
  auto counted = std::make_shared<int>(0);
  {
    SpscQueue<std::shared_ptr<int>> q(8);
    for (int i = 0; i < 5; ++i) ASSERT_TRUE(q.try_push(counted));
    EXPECT_EQ(counted.use_count(), 6);
  }
  EXPECT_EQ(counted.use_count(), 1);
}

TEST(SpscQueue, MoveOnlyType) {
  SpscQueue<std::unique_ptr<std::string>> q(2);
  ASSERT_TRUE(q.try_emplace(std::make_unique<std::string>("a")));
  std::unique_ptr<std::string> out;
  ASSERT_TRUE(q.try_pop(out));
  EXPECT_EQ(*out, "a");
}

// Millions of items across two threads: every value arrives once, in order.
TEST(SpscQueue, TwoThreadsOrderNoLossNoDuplication) {
#if defined(__SANITIZE_THREAD__)
  constexpr std::uint64_t kItems = 1'000'000;  // TSan is ~10x slower; still wraps 10^4 times
#else
  constexpr std::uint64_t kItems = 5'000'000;
#endif
  SpscQueue<std::uint64_t> q(100);
  std::thread producer([&] {
    for (std::uint64_t i = 0; i < kItems; ++i) {
      while (!q.try_push(i)) std::this_thread::yield();
    }
  });
  std::uint64_t expected = 0, sum = 0;
  bool in_order = true;
  while (expected < kItems) {
    std::uint64_t v;
    if (!q.try_pop(v)) continue;
    in_order &= (v == expected);
    sum += v;
    ++expected;
  }
  producer.join();
  EXPECT_TRUE(in_order);
  EXPECT_EQ(sum, kItems * (kItems - 1) / 2);
  EXPECT_TRUE(q.empty_approx());
}

}  // namespace
}  // namespace storey::rt

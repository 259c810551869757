#include "rt/clock.hpp"

#include <gtest/gtest.h>

namespace storey::rt {
namespace {

TEST(VirtualClock, MovesOnlyForwardWhenTold) {
  VirtualClock c(100);
  EXPECT_EQ(c.now_ns(), 100);
  c.advance_by(50);
  EXPECT_EQ(c.now_ns(), 150);
  c.advance_to(120);  // the past: ignored
  EXPECT_EQ(c.now_ns(), 150);
  Clock& base = c;
  base.sleep_until(1'000);
  EXPECT_EQ(c.now_ns(), 1'000);
}

TEST(MonotonicClock, NonDecreasingAndSleepReachesDeadline) {
  MonotonicClock c;
  const auto t0 = c.now_ns();
  EXPECT_GE(c.now_ns(), t0);
  const auto deadline = t0 + 2'000'000;  // 2 ms
  c.sleep_until(deadline);
  EXPECT_GE(c.now_ns(), deadline);  // never early (no upper bound: the machine may be loaded)
  c.sleep_until(t0);                // past deadline returns at once
  EXPECT_GT(monotonic_now_ns(), 0);
}

}  // namespace
}  // namespace storey::rt

#include "rt/mailbox.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <thread>

namespace storey::rt {
namespace {

// 13 words whose values all derive from one counter: a torn read breaks the relation.
struct Pose {
  std::uint64_t stamp;
  double v[12];
};
Pose make_pose(std::uint64_t n) {
  Pose p{n, {}};
  for (int i = 0; i < 12; ++i) p.v[i] = static_cast<double>(n) * (i + 1);
  return p;
}
bool consistent(const Pose& p) {
  for (int i = 0; i < 12; ++i) {
    if (p.v[i] != static_cast<double>(p.stamp) * (i + 1)) return false;
  }
  return true;
}

TEST(Mailbox, EmptyThenLatestValue) {
  Mailbox<Pose> m;
  Pose out = make_pose(7);
  EXPECT_EQ(m.read(out), 0u);
  EXPECT_EQ(out.stamp, 7u);  // untouched
  m.write(make_pose(1));
  m.write(make_pose(2));
  EXPECT_EQ(m.read(out), 2u);
  EXPECT_EQ(out.stamp, 2u);
  EXPECT_EQ(m.version(), 2u);
}

TEST(Mailbox, ReadersNeverSeeTornValues) {
  Mailbox<Pose> m;
#if defined(__SANITIZE_THREAD__)
  constexpr std::uint64_t kWrites = 100'000;
#else
  constexpr std::uint64_t kWrites = 2'000'000;
#endif
  std::atomic<bool> done{false};
  std::atomic<std::uint64_t> torn{0}, backwards{0}, reads{0};
  auto reader = [&] {
    std::uint64_t last = 0;
    Pose p;
    while (!done.load(std::memory_order_acquire)) {
      if (m.read(p) == 0) continue;
      if (!consistent(p)) torn.fetch_add(1);
      if (p.stamp < last) backwards.fetch_add(1);
      last = p.stamp;
      reads.fetch_add(1, std::memory_order_relaxed);
    }
  };
  std::thread r1(reader), r2(reader);
  for (std::uint64_t i = 1; i <= kWrites; ++i) m.write(make_pose(i));
  done.store(true, std::memory_order_release);
  r1.join();
  r2.join();
  EXPECT_EQ(torn.load(), 0u);
  EXPECT_EQ(backwards.load(), 0u);
  Pose last;
  EXPECT_EQ(m.read(last), kWrites);
  EXPECT_EQ(last.stamp, kWrites);
}

}  // namespace
}  // namespace storey::rt

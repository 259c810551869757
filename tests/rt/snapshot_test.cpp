#include "rt/snapshot.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <thread>
#include <vector>

namespace storey::rt {
namespace {

struct World {
  std::uint64_t id;
  std::vector<std::uint64_t> cells;  // all equal to id: a half-built world breaks this
};

std::shared_ptr<const World> make_world(std::uint64_t id) {
  return std::make_shared<const World>(World{id, std::vector<std::uint64_t>(64, id)});
}

TEST(Snapshot, VersionsAndDeferredRelease) {
  Snapshot<World> s(8);
  EXPECT_EQ(s.read().ptr, nullptr);
  EXPECT_EQ(s.version(), 0u);
  std::weak_ptr<const World> first;
  {
    auto w = make_world(1);
    first = w;
    EXPECT_EQ(s.publish(std::move(w)), 1u);
  }
  auto v = s.read();
  ASSERT_NE(v.ptr, nullptr);
  EXPECT_EQ(v.version, 1u);
  EXPECT_EQ(v.ptr->id, 1u);
  v = {};
  // Publishing more replaces slots; replaced pointers wait in the retire queue.
  for (std::uint64_t i = 2; i <= 6; ++i) EXPECT_EQ(s.publish(make_world(i)), i);
  EXPECT_FALSE(first.expired()) << "the owner must not have freed the old snapshot itself";
  EXPECT_GT(s.collect(), 0u);
  EXPECT_TRUE(first.expired());
  EXPECT_EQ(s.read().ptr->id, 6u);
  EXPECT_EQ(s.released_in_place(), 0u);
}

TEST(Snapshot, RetireQueueFullIsCounted) {
  Snapshot<World> s(1);  // retire capacity rounds to 2
  for (std::uint64_t i = 1; i <= 10; ++i) s.publish(make_world(i));
  EXPECT_GT(s.released_in_place(), 0u);
}

// One owner publishes fast, readers read concurrently: every view is complete and versions
// never go backwards.
TEST(Snapshot, ConcurrentReadersSeeWholeSnapshots) {
#if defined(__SANITIZE_THREAD__)
  constexpr std::uint64_t kPublishes = 20'000;
#else
  constexpr std::uint64_t kPublishes = 200'000;
#endif
  Snapshot<World> s(1024);
  std::atomic<bool> done{false};
  std::atomic<std::uint64_t> bad{0}, backwards{0};
  auto reader = [&] {
    std::uint64_t last = 0;
    while (!done.load(std::memory_order_acquire)) {
      auto v = s.read();
      if (!v.ptr) continue;
      if (v.ptr->id != v.version || v.ptr->cells.size() != 64) bad.fetch_add(1);
      for (auto c : v.ptr->cells) {
        if (c != v.version) bad.fetch_add(1);
      }
      if (v.version < last) backwards.fetch_add(1);
      last = v.version;
      s.retire(std::move(v.ptr));
    }
  };
  std::thread r1(reader), r2(reader);
  std::thread collector([&] {
    while (!done.load(std::memory_order_acquire)) s.collect();
  });
  std::uint64_t published = 0;
  while (published < kPublishes) {
    if (s.publish(make_world(published + 1)) != 0) ++published;
  }
  done.store(true, std::memory_order_release);
  r1.join();
  r2.join();
  collector.join();
  EXPECT_EQ(bad.load(), 0u);
  EXPECT_EQ(backwards.load(), 0u);
  EXPECT_EQ(s.version(), kPublishes);
}

}  // namespace
}  // namespace storey::rt

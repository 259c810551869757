// Helpers for the Go2 link tests: monotonic time and bounded waiting for loopback delivery.
#pragma once

#include <time.h>

#include <cstdint>
#include <functional>
#include <thread>

namespace storey::drivers::go2::testing {

inline int64_t mono_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

// Calls `step` until `done` holds, up to `max_iterations` x 1 ms. Loopback delivery is fast but
// asynchronous; the bound only keeps a broken test from hanging (no timing is asserted).
inline bool spin_until(const std::function<void()>& step, const std::function<bool()>& done,
                       int max_iterations = 3000) {
  for (int i = 0; i < max_iterations; ++i) {
    step();
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return false;
}

}  // namespace storey::drivers::go2::testing

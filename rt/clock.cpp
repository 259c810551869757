#include "rt/clock.hpp"

#include <cerrno>
#include <ctime>

namespace storey::rt {

namespace {
constexpr std::int64_t kNsPerS = 1'000'000'000;
}

std::int64_t monotonic_now_ns() noexcept {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * kNsPerS + ts.tv_nsec;
}

std::int64_t MonotonicClock::now_ns() const noexcept {
  return monotonic_now_ns();
}

void MonotonicClock::sleep_until(std::int64_t deadline_ns) noexcept {
  if (deadline_ns < 0) return;
  timespec ts;
  ts.tv_sec = static_cast<time_t>(deadline_ns / kNsPerS);
  ts.tv_nsec = static_cast<long>(deadline_ns % kNsPerS);
  // Absolute deadline: an interrupted sleep resumes with the same target.
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

}  // namespace storey::rt

// One clock interface: the real monotonic clock and a virtual clock for lockstep simulation.
#pragma once

#include <atomic>
#include <cstdint>

namespace storey::rt {

// Times are int64 nanoseconds on a monotonic timeline (never wall/calendar time).
class Clock {
 public:
  virtual ~Clock() = default;
  // Any thread; never blocks.
  virtual std::int64_t now_ns() const noexcept = 0;
  // Blocks the calling thread until now_ns() >= deadline_ns (returns at once if already past).
  virtual void sleep_until(std::int64_t deadline_ns) noexcept = 0;
};

// CLOCK_MONOTONIC; sleep_until is clock_nanosleep(TIMER_ABSTIME), retried on EINTR, so the
// deadline never drifts the way a relative sleep does (cyclictest's loop).
class MonotonicClock final : public Clock {
 public:
  std::int64_t now_ns() const noexcept override;
  void sleep_until(std::int64_t deadline_ns) noexcept override;
};

// Time that moves only when the lockstep driver says so: same inputs, same outputs, bit for
// bit. One driver thread advances it; any thread may read it. sleep_until(t) just jumps to t
// (a lockstep task that "sleeps" simply lets virtual time pass), never backwards.
class VirtualClock final : public Clock {
 public:
  explicit VirtualClock(std::int64_t start_ns = 0) : now_(start_ns) {}
  std::int64_t now_ns() const noexcept override { return now_.load(std::memory_order_acquire); }
  void sleep_until(std::int64_t deadline_ns) noexcept override { advance_to(deadline_ns); }
  // Driver only. Moves time forward to t (no-op if t is in the past).
  void advance_to(std::int64_t t_ns) noexcept {
    if (t_ns > now_.load(std::memory_order_relaxed)) now_.store(t_ns, std::memory_order_release);
  }
  void advance_by(std::int64_t dt_ns) noexcept { advance_to(now_ns() + dt_ns); }

 private:
  std::atomic<std::int64_t> now_;
};

// The process-wide monotonic time, for code that has no Clock& (statistics, trace stamps).
std::int64_t monotonic_now_ns() noexcept;

}  // namespace storey::rt

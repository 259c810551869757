// Bounded trace ring of complete events, exported as Chrome trace-event JSON (Perfetto).
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

namespace storey::rt {

struct TraceEvent {
  const char* name;  // must point to a string that outlives the ring (a literal, a task name)
  std::uint32_t tid;
  std::int64_t start_ns;
  std::int64_t dur_ns;
};

// Contract: any thread may call record() (lock-free, never allocates, overwrites the oldest
// event when full); one non-RT thread at a time calls events()/write_chrome_json(), which copy
// out whatever is consistent at that moment. Allocation happens only in the constructor.
//
// Each slot carries a sequence number (odd while being written, 2*i+2 once event i is in),
// so the exporter skips slots that are mid-write or already overwritten. Two writers a whole
// ring apart on one slot (only if a writer stalls for `capacity` events): the later one drops
// its event and counts it (dropped()), nothing is torn.
class TraceRing {
 public:
  static constexpr std::uint32_t kMaxThreadNames = 64;

  explicit TraceRing(std::size_t capacity);

  void record(const char* name, std::uint32_t tid, std::int64_t start_ns,
              std::int64_t dur_ns) noexcept {
    const std::uint64_t i = head_.fetch_add(1, std::memory_order_relaxed);
    Slot& s = slots_[i % capacity_];
    // Claim the slot; a writer that lapped a slower one (slot odd or newer) drops its event.
    std::uint64_t cur = s.seq.load(std::memory_order_relaxed);
    if ((cur & 1) || cur > 2 * i ||
        !s.seq.compare_exchange_strong(cur, 2 * i + 1, std::memory_order_relaxed)) {
      dropped_.fetch_add(1, std::memory_order_relaxed);
      return;
    }
    std::atomic_thread_fence(std::memory_order_release);
    s.name.store(name, std::memory_order_relaxed);
    s.tid.store(tid, std::memory_order_relaxed);
    s.start.store(start_ns, std::memory_order_relaxed);
    s.dur.store(dur_ns, std::memory_order_relaxed);
    s.seq.store(2 * i + 2, std::memory_order_release);
  }

  // Setup time (any thread): a label for tid in the viewer. tid >= kMaxThreadNames is ignored.
  void set_thread_name(std::uint32_t tid, const char* name) noexcept {
    if (tid < kMaxThreadNames) thread_names_[tid].store(name, std::memory_order_release);
  }

  std::size_t capacity() const noexcept { return capacity_; }
  std::uint64_t recorded() const noexcept { return head_.load(std::memory_order_relaxed); }
  std::uint64_t dropped() const noexcept { return dropped_.load(std::memory_order_relaxed); }
  std::uint64_t overwritten() const noexcept {
    const auto n = recorded();
    return n > capacity_ ? n - capacity_ : 0;
  }

  // Non-RT. Retained events, oldest start first.
  std::vector<TraceEvent> events() const;
  // Non-RT. {"traceEvents":[...]} with complete ("X") events, ts/dur in microseconds.
  void write_chrome_json(std::ostream& out) const;
  // Non-RT. Returns false (and sets *error when given) if the file cannot be written.
  bool write_chrome_json(const std::string& path, std::string* error = nullptr) const;

 private:
  struct Slot {
    std::atomic<std::uint64_t> seq{0};
    std::atomic<const char*> name{nullptr};
    std::atomic<std::uint32_t> tid{0};
    std::atomic<std::int64_t> start{0};
    std::atomic<std::int64_t> dur{0};
  };
  std::size_t capacity_;
  std::unique_ptr<Slot[]> slots_;
  std::atomic<std::uint64_t> head_{0};
  std::atomic<std::uint64_t> dropped_{0};
  std::atomic<const char*> thread_names_[kMaxThreadNames] = {};
};

// Records [construction, destruction) of a scope as one event; null ring = no-op.
class TraceScope {
 public:
  TraceScope(TraceRing* ring, const char* name, std::uint32_t tid) noexcept;
  ~TraceScope();
  TraceScope(const TraceScope&) = delete;
  TraceScope& operator=(const TraceScope&) = delete;

 private:
  TraceRing* ring_;
  const char* name_;
  std::uint32_t tid_;
  std::int64_t start_;
};

}  // namespace storey::rt

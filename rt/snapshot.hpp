// Immutable versioned snapshots published by one owner thread to any number of readers.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>

#include "rt/mpsc_queue.hpp"

namespace storey::rt {

// Contract: one owner thread calls publish(); any thread calls read(), retire() and version();
// one non-real-time thread calls collect(). publish() and read() never block and never free.
//
// Why not std::atomic<std::shared_ptr>: in libstdc++ 12 it takes a spin lock. Here the owner
// rotates kSlots shared_ptr slots; `current_` packs (version << 8 | slot). A reader announces
// itself on a slot (readers counter), re-checks that the slot is still current, then copies the
// shared_ptr (an atomic increment). The owner only overwrites a slot that is not current and
// has no announced reader (seq_cst on both sides, the Dekker pattern), so nobody ever reads a
// shared_ptr while it is being written.
//
// Deferred release: a real-time thread must never drop the LAST reference to a snapshot (that
// runs ~T and free). The owner hands each replaced pointer to an MPSC retire queue; readers on
// real-time threads do the same with retire(std::move(ptr)) instead of letting a copy go out of
// scope. A non-RT thread calls collect() to drop retired references. If the retire queue is
// full the reference is dropped in place and counted (released_in_place()).
template <typename T>
class Snapshot {
 public:
  static constexpr std::size_t kSlots = 4;
  struct View {
    std::shared_ptr<const T> ptr;  // nullptr before the first publish
    std::uint64_t version = 0;     // 1 for the first publish
  };

  explicit Snapshot(std::size_t retire_capacity = 64) : retired_(retire_capacity) {}
  ~Snapshot() { collect(); }
  Snapshot(const Snapshot&) = delete;
  Snapshot& operator=(const Snapshot&) = delete;

  // Owner only. Makes p the current snapshot and returns its version, or returns 0 (and
  // leaves p untouched) in the rare case every other slot has a reader mid-copy; the owner
  // simply tries again on its next cycle.
  std::uint64_t publish(std::shared_ptr<const T>&& p) noexcept {
    const std::uint64_t cur = current_.load(std::memory_order_relaxed);
    const std::size_t cur_slot = cur == 0 ? kSlots : static_cast<std::size_t>(cur & 0xff);
    for (std::size_t i = 0; i < kSlots; ++i) {
      if (i == cur_slot || slots_[i].readers.load(std::memory_order_seq_cst) != 0) continue;
      std::shared_ptr<const T> old = std::move(slots_[i].ptr);
      slots_[i].ptr = std::move(p);
      const std::uint64_t version = (cur >> 8) + 1;
      current_.store((version << 8) | i, std::memory_order_seq_cst);
      if (old) retire(std::move(old));
      return version;
    }
    busy_.fetch_add(1, std::memory_order_relaxed);
    return 0;
  }
  std::uint64_t publish(const std::shared_ptr<const T>& p) noexcept {
    auto copy = p;
    return publish(std::move(copy));
  }

  // Any thread. The current snapshot and its version ({nullptr, 0} before the first publish).
  View read() const noexcept {
    for (;;) {
      const std::uint64_t c = current_.load(std::memory_order_seq_cst);
      if (c == 0) return {};
      const Slot& s = slots_[c & 0xff];
      s.readers.fetch_add(1, std::memory_order_seq_cst);
      if (current_.load(std::memory_order_seq_cst) == c) {
        View v{s.ptr, c >> 8};
        s.readers.fetch_sub(1, std::memory_order_release);
        return v;
      }
      s.readers.fetch_sub(1, std::memory_order_release);  // owner moved on; retry
    }
  }

  // Any thread. Version of the current snapshot (0 = none yet).
  std::uint64_t version() const noexcept { return current_.load(std::memory_order_acquire) >> 8; }

  // Any thread: hand over a reference for release by collect() on a non-RT thread.
  void retire(std::shared_ptr<const T>&& p) noexcept {
    if (!p) return;
    if (!retired_.try_push(std::move(p))) {
      released_in_place_.fetch_add(1, std::memory_order_relaxed);
      p.reset();
    }
  }

  // One non-RT thread. Drops retired references; returns how many.
  std::size_t collect() noexcept {
    std::size_t n = 0;
    std::shared_ptr<const T> p;
    while (retired_.try_pop(p)) {
      p.reset();
      ++n;
    }
    return n;
  }

  std::uint64_t busy_publishes() const noexcept { return busy_.load(std::memory_order_relaxed); }
  std::uint64_t released_in_place() const noexcept {
    return released_in_place_.load(std::memory_order_relaxed);
  }

 private:
  struct alignas(kCacheLine) Slot {
    std::shared_ptr<const T> ptr;
    mutable std::atomic<std::uint32_t> readers{0};
  };
  std::array<Slot, kSlots> slots_;
  alignas(kCacheLine) std::atomic<std::uint64_t> current_{0};
  std::atomic<std::uint64_t> busy_{0};
  std::atomic<std::uint64_t> released_in_place_{0};
  MpscQueue<std::shared_ptr<const T>> retired_;
};

}  // namespace storey::rt

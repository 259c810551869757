// Latest-value mailbox: a seqlock over a trivially copyable value.
#pragma once

#include <atomic>
#include <cstdint>
#include <cstring>
#include <type_traits>

#include "rt/spsc_queue.hpp"  // kCacheLine

namespace storey::rt {

// Contract: one writer thread calls write(); any number of reader threads call read(). write()
// never waits; read() never sees a torn value and retries only while a write is in progress.
//
// The payload is stored as relaxed atomic 64-bit words bracketed by fences (Boehm, "Can
// seqlocks get along with programming language memory models?", 2012): this is race-free by
// the C++ memory model, so ThreadSanitizer can check it, and costs nothing extra on x86/ARM.
template <typename T>
class Mailbox {
  static_assert(std::is_trivially_copyable_v<T>, "Mailbox<T> needs a trivially copyable T");

 public:
  // Writer only.
  void write(const T& v) noexcept {
    std::uint64_t buf[kWords] = {};
    std::memcpy(buf, &v, sizeof(T));
    const std::uint64_t s = seq_.load(std::memory_order_relaxed);
    seq_.store(s + 1, std::memory_order_relaxed);  // odd: write in progress
    std::atomic_thread_fence(std::memory_order_release);
    for (std::size_t i = 0; i < kWords; ++i) words_[i].store(buf[i], std::memory_order_relaxed);
    seq_.store(s + 2, std::memory_order_release);
  }

  // Any thread. Copies the latest value into out and returns its version (number of writes so
  // far, 1 for the first); returns 0 and leaves out untouched when nothing was written yet.
  std::uint64_t read(T& out) const noexcept {
    std::uint64_t buf[kWords];
    std::uint64_t s1, s2;
    do {
      s1 = seq_.load(std::memory_order_acquire);
      if (s1 & 1) continue;  // writer mid-way: its two stores are a few ns apart
      for (std::size_t i = 0; i < kWords; ++i) buf[i] = words_[i].load(std::memory_order_relaxed);
      std::atomic_thread_fence(std::memory_order_acquire);
      s2 = seq_.load(std::memory_order_relaxed);
      if (s1 == s2) break;
    } while (true);
    if (s1 == 0) return 0;
    std::memcpy(&out, buf, sizeof(T));
    return s1 / 2;
  }

  // Any thread. Version of the latest completed write (0 = never written).
  std::uint64_t version() const noexcept { return seq_.load(std::memory_order_acquire) / 2; }

 private:
  static constexpr std::size_t kWords = (sizeof(T) + 7) / 8;
  alignas(kCacheLine) std::atomic<std::uint64_t> seq_{0};
  std::atomic<std::uint64_t> words_[kWords] = {};
};

}  // namespace storey::rt

// Lock-free bounded multi-producer single-consumer queue (D. Vyukov's bounded queue: one
// sequence number per slot tells whose turn it is, so producers only contend on one CAS).
#pragma once

#include <atomic>
#include <cstddef>
#include <memory>
#include <new>
#include <stdexcept>
#include <type_traits>
#include <utility>

#include "rt/spsc_queue.hpp"  // kCacheLine

namespace storey::rt {

// Contract: any number of threads may call try_push/try_emplace, exactly one thread calls
// try_pop; none of them blocks or allocates (a producer only retries a lost CAS).
template <typename T>
class MpscQueue {
 public:
  // The only allocation. Capacity is rounded up to a power of two (>= 2).
  explicit MpscQueue(std::size_t capacity) {
    if (capacity < 1) throw std::invalid_argument("MpscQueue: capacity must be >= 1");
    if (capacity > (std::size_t{1} << 40)) throw std::length_error("MpscQueue: capacity");
    std::size_t n = 2;
    while (n < capacity) n <<= 1;
    mask_ = n - 1;
    cells_ = std::allocator<Cell>().allocate(n);
    for (std::size_t i = 0; i < n; ++i) ::new (&cells_[i]) Cell(i);
  }
  ~MpscQueue() {
    for (;; ++dequeue_) {  // destroy what is left without requiring a default-constructible T
      Cell& c = cells_[dequeue_ & mask_];
      if (c.seq.load(std::memory_order_acquire) != dequeue_ + 1) break;
      std::launder(reinterpret_cast<T*>(&c.storage))->~T();
    }
    for (std::size_t i = 0; i <= mask_; ++i) cells_[i].~Cell();
    std::allocator<Cell>().deallocate(cells_, mask_ + 1);
  }
  MpscQueue(const MpscQueue&) = delete;
  MpscQueue& operator=(const MpscQueue&) = delete;

  // Any thread. False when full.
  template <typename... Args>
  bool try_emplace(Args&&... args) noexcept(std::is_nothrow_constructible_v<T, Args&&...>) {
    std::size_t pos = enqueue_.load(std::memory_order_relaxed);
    Cell* c;
    for (;;) {
      c = &cells_[pos & mask_];
      const std::size_t seq = c->seq.load(std::memory_order_acquire);
      const auto dif = static_cast<std::ptrdiff_t>(seq) - static_cast<std::ptrdiff_t>(pos);
      if (dif == 0) {
        if (enqueue_.compare_exchange_weak(pos, pos + 1, std::memory_order_relaxed)) break;
      } else if (dif < 0) {
        return false;  // the slot one lap behind is still unread: full
      } else {
        pos = enqueue_.load(std::memory_order_relaxed);  // another producer took it
      }
    }
    ::new (static_cast<void*>(&c->storage)) T(std::forward<Args>(args)...);
    c->seq.store(pos + 1, std::memory_order_release);
    return true;
  }
  bool try_push(const T& v) { return try_emplace(v); }
  bool try_push(T&& v) { return try_emplace(std::move(v)); }

  // Consumer only. False when empty (or when the next producer has claimed but not yet
  // filled its slot: items from one producer stay in order, across producers in claim order).
  bool try_pop(T& out) noexcept(std::is_nothrow_move_assignable_v<T>) {
    Cell* c = &cells_[dequeue_ & mask_];
    if (c->seq.load(std::memory_order_acquire) != dequeue_ + 1) return false;
    T* p = std::launder(reinterpret_cast<T*>(&c->storage));
    out = std::move(*p);
    p->~T();
    c->seq.store(dequeue_ + mask_ + 1, std::memory_order_release);
    ++dequeue_;
    return true;
  }

  std::size_t capacity() const noexcept { return mask_ + 1; }

 private:
  struct Cell {
    explicit Cell(std::size_t i) : seq(i) {}
    std::atomic<std::size_t> seq;
    alignas(T) unsigned char storage[sizeof(T)];
  };
  Cell* cells_ = nullptr;
  std::size_t mask_ = 0;
  alignas(kCacheLine) std::atomic<std::size_t> enqueue_{0};
  alignas(kCacheLine) std::size_t dequeue_ = 0;  // consumer-private
  char pad_[kCacheLine - sizeof(std::size_t)];
};

}  // namespace storey::rt

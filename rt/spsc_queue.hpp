// Lock-free bounded single-producer single-consumer queue (after rigtorp/SPSCQueue).
#pragma once

#include <atomic>
#include <cstddef>
#include <memory>
#include <new>
#include <stdexcept>
#include <type_traits>
#include <utility>

namespace storey::rt {

inline constexpr std::size_t kCacheLine = 64;

// Contract: exactly one thread calls the producer side (try_push/try_emplace) and exactly one
// thread calls the consumer side (front/pop/try_pop); none of them blocks or allocates.
template <typename T>
class SpscQueue {
 public:
  // The only allocation: capacity + 1 slots (one slot stays empty to tell full from empty).
  explicit SpscQueue(std::size_t capacity) : capacity_(capacity + 1) {
    if (capacity < 1) throw std::invalid_argument("SpscQueue: capacity must be >= 1");
    if (capacity > (SIZE_MAX / sizeof(T)) - 2) throw std::length_error("SpscQueue: capacity");
    slots_ = alloc_.allocate(capacity_);
  }
  ~SpscQueue() {
    while (front()) pop();
    alloc_.deallocate(slots_, capacity_);
  }
  SpscQueue(const SpscQueue&) = delete;
  SpscQueue& operator=(const SpscQueue&) = delete;

  // Producer. Returns false (and constructs nothing) when full.
  template <typename... Args>
  bool try_emplace(Args&&... args) noexcept(std::is_nothrow_constructible_v<T, Args&&...>) {
    const std::size_t w = write_.load(std::memory_order_relaxed);
    std::size_t next = w + 1;
    if (next == capacity_) next = 0;
    if (next == read_cache_) {
      // Only now pay for the cross-core load of the consumer's index.
      read_cache_ = read_.load(std::memory_order_acquire);
      if (next == read_cache_) return false;
    }
    ::new (static_cast<void*>(&slots_[w])) T(std::forward<Args>(args)...);
    write_.store(next, std::memory_order_release);
    return true;
  }
  bool try_push(const T& v) noexcept(std::is_nothrow_copy_constructible_v<T>) {
    return try_emplace(v);
  }
  bool try_push(T&& v) noexcept(std::is_nothrow_move_constructible_v<T>) {
    return try_emplace(std::move(v));
  }

  // Consumer. Pointer to the oldest element or nullptr when empty; valid until pop().
  T* front() noexcept {
    const std::size_t r = read_.load(std::memory_order_relaxed);
    if (r == write_cache_) {
      write_cache_ = write_.load(std::memory_order_acquire);
      if (r == write_cache_) return nullptr;
    }
    return &slots_[r];
  }
  // Consumer. Precondition: front() != nullptr.
  void pop() noexcept {
    const std::size_t r = read_.load(std::memory_order_relaxed);
    slots_[r].~T();
    std::size_t next = r + 1;
    if (next == capacity_) next = 0;
    read_.store(next, std::memory_order_release);
  }
  // Consumer. Moves the oldest element into out; false when empty.
  bool try_pop(T& out) noexcept(std::is_nothrow_move_assignable_v<T>) {
    T* p = front();
    if (!p) return false;
    out = std::move(*p);
    pop();
    return true;
  }

  // Either side; a snapshot that may be stale by the time it is used.
  std::size_t size_approx() const noexcept {
    const std::ptrdiff_t d = static_cast<std::ptrdiff_t>(write_.load(std::memory_order_acquire)) -
                             static_cast<std::ptrdiff_t>(read_.load(std::memory_order_acquire));
    return static_cast<std::size_t>(d < 0 ? d + static_cast<std::ptrdiff_t>(capacity_) : d);
  }
  bool empty_approx() const noexcept { return size_approx() == 0; }
  std::size_t capacity() const noexcept { return capacity_ - 1; }

 private:
  // Read-mostly fields first, then one cache line per side so that the producer and the
  // consumer never write to the same line (the cached copy of the other side's index lives
  // beside the index its owner writes).
  const std::size_t capacity_;
  [[no_unique_address]] std::allocator<T> alloc_;
  T* slots_ = nullptr;

  alignas(kCacheLine) std::atomic<std::size_t> write_{0};
  std::size_t read_cache_ = 0;  // producer's copy of read_
  alignas(kCacheLine) std::atomic<std::size_t> read_{0};
  std::size_t write_cache_ = 0;  // consumer's copy of write_
  char pad_[kCacheLine - sizeof(std::atomic<std::size_t>) - sizeof(std::size_t)];
};

}  // namespace storey::rt

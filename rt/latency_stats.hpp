// Log-linear latency histogram (HDR-like): fixed memory, no allocation, O(1) record.
#pragma once

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstdint>
#include <limits>

namespace storey::rt {

struct LatencySummary {
  std::uint64_t count = 0;
  double mean_ns = 0;
  std::int64_t min_ns = 0, p50_ns = 0, p99_ns = 0, p999_ns = 0, max_ns = 0;
};

// Contract: one thread calls record(); any thread may read (count, percentile, summary) at any
// time and gets a slightly stale but never corrupt view (relaxed atomics, no RMW on the writer
// side). Values are ns; negative values count as 0.
//
// Buckets: values below 2^(kSubBits+1) = 64 ns are exact; above, each power of two [2^e,
// 2^(e+1)) is split into 2^kSubBits equal sub-buckets, so a reported percentile is within
// 1/32 (about 3 %) of the true sample. Values >= 2^(kMaxExp+1) ns (~2.4 h) share the last bucket
// (max_ns stays exact).
class LatencyHistogram {
 public:
  static constexpr int kSubBits = 5;
  static constexpr int kSub = 1 << kSubBits;
  static constexpr int kMaxExp = 42;
  static constexpr int kBuckets = (kMaxExp - kSubBits + 2) * kSub;

  static constexpr int bucket_of(std::uint64_t v) noexcept {
    if (v < 2 * kSub) return static_cast<int>(v);
    const int e = std::bit_width(v) - 1;
    if (e > kMaxExp) return kBuckets - 1;
    return (e - kSubBits + 1) * kSub + static_cast<int>((v >> (e - kSubBits)) - kSub);
  }
  static constexpr std::int64_t bucket_low(int b) noexcept {
    if (b < 2 * kSub) return b;
    const int g = b / kSub;
    return static_cast<std::int64_t>(kSub + b % kSub) << (g - 1);
  }
  static constexpr std::int64_t bucket_width(int b) noexcept {
    return b < 2 * kSub ? 1 : std::int64_t{1} << (b / kSub - 1);
  }

  void record(std::int64_t v_ns) noexcept {
    const std::int64_t v = std::max<std::int64_t>(v_ns, 0);
    auto& b = buckets_[bucket_of(static_cast<std::uint64_t>(v))];
    b.store(b.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
    const std::uint64_t n = count_.load(std::memory_order_relaxed);
    count_.store(n + 1, std::memory_order_relaxed);
    sum_.store(sum_.load(std::memory_order_relaxed) + v, std::memory_order_relaxed);
    if (v > max_.load(std::memory_order_relaxed)) max_.store(v, std::memory_order_relaxed);
    if (n == 0 || v < min_.load(std::memory_order_relaxed)) {
      min_.store(v, std::memory_order_relaxed);
    }
  }

  std::uint64_t count() const noexcept { return count_.load(std::memory_order_relaxed); }
  std::int64_t max() const noexcept { return max_.load(std::memory_order_relaxed); }
  std::int64_t min() const noexcept { return min_.load(std::memory_order_relaxed); }
  double mean() const noexcept {
    const auto n = count();
    return n ? static_cast<double>(sum_.load(std::memory_order_relaxed)) / n : 0.0;
  }

  // Value at quantile q in [0, 1]: the sample of rank ceil(q * n) (nearest-rank definition),
  // reported as its bucket's midpoint clamped to [min, max]. 0 when empty.
  std::int64_t percentile(double q) const noexcept {
    std::uint64_t n = 0;
    for (const auto& b : buckets_) n += b.load(std::memory_order_relaxed);
    if (n == 0) return 0;
    const double want = std::clamp(q, 0.0, 1.0) * static_cast<double>(n);
    std::uint64_t rank = static_cast<std::uint64_t>(want);
    if (static_cast<double>(rank) < want) ++rank;
    rank = std::clamp<std::uint64_t>(rank, 1, n);
    std::uint64_t seen = 0;
    for (int i = 0; i < kBuckets; ++i) {
      seen += buckets_[i].load(std::memory_order_relaxed);
      if (seen >= rank) {
        const std::int64_t mid = bucket_low(i) + (bucket_width(i) - 1) / 2;
        return std::clamp(mid, min(), std::max(min(), max()));
      }
    }
    return max();
  }

  LatencySummary summary() const noexcept {
    LatencySummary s;
    s.count = count();
    if (s.count == 0) return s;
    s.mean_ns = mean();
    s.min_ns = min();
    s.p50_ns = percentile(0.50);
    s.p99_ns = percentile(0.99);
    s.p999_ns = percentile(0.999);
    s.max_ns = max();
    return s;
  }

  // Not concurrent with record().
  void reset() noexcept {
    for (auto& b : buckets_) b.store(0, std::memory_order_relaxed);
    count_.store(0, std::memory_order_relaxed);
    sum_.store(0, std::memory_order_relaxed);
    max_.store(0, std::memory_order_relaxed);
    min_.store(0, std::memory_order_relaxed);
  }

 private:
  std::atomic<std::uint64_t> buckets_[kBuckets] = {};
  std::atomic<std::uint64_t> count_{0};
  std::atomic<std::int64_t> sum_{0};
  std::atomic<std::int64_t> max_{0};
  std::atomic<std::int64_t> min_{0};
};

}  // namespace storey::rt

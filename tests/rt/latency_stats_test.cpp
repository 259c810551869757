#include "rt/latency_stats.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <random>
#include <vector>

namespace storey::rt {
namespace {

std::int64_t nearest_rank(const std::vector<std::int64_t>& sorted, double q) {
  auto rank = static_cast<std::size_t>(std::ceil(q * sorted.size()));
  rank = std::clamp<std::size_t>(rank, 1, sorted.size());
  return sorted[rank - 1];
}

TEST(LatencyHistogram, BucketsRoundTrip) {
  using H = LatencyHistogram;
  for (std::uint64_t v : {0ull, 1ull, 63ull, 64ull, 65ull, 1000ull, 123456789ull, 1ull << 40}) {
    const int b = H::bucket_of(v);
    EXPECT_LE(H::bucket_low(b), static_cast<std::int64_t>(v)) << v;
    EXPECT_GT(H::bucket_low(b) + H::bucket_width(b), static_cast<std::int64_t>(v)) << v;
  }
  // Contiguous: each bucket starts where the previous one ends.
  for (int b = 1; b < H::kBuckets; ++b) {
    ASSERT_EQ(H::bucket_low(b), H::bucket_low(b - 1) + H::bucket_width(b - 1)) << b;
  }
  EXPECT_EQ(H::bucket_of(~0ull), H::kBuckets - 1);
}

TEST(LatencyHistogram, EmptyAndSmallExact) {
  auto h = std::make_unique<LatencyHistogram>();
  EXPECT_EQ(h->summary().count, 0u);
  EXPECT_EQ(h->percentile(0.5), 0);
  for (int v : {5, 1, 3, 2, 4}) h->record(v);
  h->record(-7);  // clamps to 0
  const auto s = h->summary();
  EXPECT_EQ(s.count, 6u);
  EXPECT_EQ(s.min_ns, 0);
  EXPECT_EQ(s.max_ns, 5);
  EXPECT_EQ(s.p50_ns, 2);  // rank ceil(0.5 * 6) = 3 of {0,1,2,3,4,5}
  EXPECT_DOUBLE_EQ(s.mean_ns, 15.0 / 6);
}

// Percentiles against a sorted copy of the samples, within one sub-bucket (1/32 relative).
TEST(LatencyHistogram, PercentilesMatchSortedArray) {
  std::mt19937_64 rng(42);
  std::lognormal_distribution<double> dist(std::log(200'000.0), 1.0);  // ~0.2 ms, heavy tail
  auto h = std::make_unique<LatencyHistogram>();
  std::vector<std::int64_t> samples;
  for (int i = 0; i < 100'000; ++i) {
    const auto v = static_cast<std::int64_t>(dist(rng));
    samples.push_back(v);
    h->record(v);
  }
  std::sort(samples.begin(), samples.end());
  for (double q : {0.0, 0.1, 0.5, 0.9, 0.99, 0.999, 1.0}) {
    const double truth = static_cast<double>(nearest_rank(samples, q));
    EXPECT_NEAR(static_cast<double>(h->percentile(q)), truth, truth / 32 + 1) << "q=" << q;
  }
  EXPECT_EQ(h->max(), samples.back());
  EXPECT_EQ(h->min(), samples.front());
  double sum = 0;
  for (auto v : samples) sum += static_cast<double>(v);
  EXPECT_NEAR(h->mean(), sum / samples.size(), 1e-6 * sum / samples.size());
  h->reset();
  EXPECT_EQ(h->count(), 0u);
}

}  // namespace
}  // namespace storey::rt

#include "edm/runtime/histogram.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <random>
#include <vector>

namespace edm::rt {
namespace {

using H = LatencyHistogram;

// ~18 KiB each: keep them off the test thread's stack.
std::unique_ptr<H> make_histogram() { return std::make_unique<H>(); }

TEST(LatencyHistogram, empty_histogram_reports_zero) {
  auto h = make_histogram();
  EXPECT_EQ(h->count(), 0u);
  EXPECT_EQ(h->quantile(0.5), 0);
  EXPECT_EQ(h->quantile(1.0), 0);
  EXPECT_EQ(h->max_ns(), 0);
}

TEST(LatencyHistogram, uniform_distribution_quantiles_within_bucket_error) {
  auto h = make_histogram();
  for (std::int64_t ns = 1; ns <= 100'000; ++ns) {
    h->record(ns);
  }
  ASSERT_EQ(h->count(), 100'000u);
  // Upper bound of the bucket: never below the true quantile, at most 1/64 above it.
  const std::int64_t p50 = h->quantile(0.5);
  EXPECT_GE(p50, 50'000);
  EXPECT_LE(static_cast<double>(p50), 50'000 * (1.0 + 1.0 / 64));
  const std::int64_t p99 = h->quantile(0.99);
  EXPECT_GE(p99, 99'000);
  EXPECT_LE(static_cast<double>(p99), 99'000 * (1.0 + 1.0 / 64));
  EXPECT_EQ(h->quantile(0.0), 1);
  EXPECT_EQ(h->quantile(1.0), 100'000);  // capped at the true max
}

TEST(LatencyHistogram, single_value_is_every_quantile) {
  auto h = make_histogram();
  h->record(12'345);
  for (const double q : {0.0, 0.01, 0.5, 0.99, 1.0}) {
    EXPECT_EQ(h->quantile(q), 12'345) << "q=" << q;
  }
}

TEST(LatencyHistogram, small_values_are_exact) {
  auto h = make_histogram();
  for (std::int64_t ns = 0; ns < 100; ++ns) {
    h->record(ns);
  }
  EXPECT_EQ(h->quantile(0.01), 0);   // rank 1
  EXPECT_EQ(h->quantile(0.07), 6);   // rank 7, although 0.07 * 100 == 7.000000000000001
  EXPECT_EQ(h->quantile(0.5), 49);   // rank 50
  EXPECT_EQ(h->quantile(0.99), 98);  // rank 99
  EXPECT_EQ(h->quantile(1.0), 99);
  for (std::uint64_t ns = 0; ns < 64; ++ns) {
    EXPECT_EQ(H::bucket_lower_ns(H::bucket_index(ns)), ns);
    EXPECT_EQ(H::bucket_upper_ns(H::bucket_index(ns)), ns);
  }
}

TEST(LatencyHistogram, buckets_tile_the_range_with_bounded_relative_width) {
  for (std::size_t i = 0; i < H::kBucketCount; ++i) {
    const std::uint64_t lower = H::bucket_lower_ns(i);
    const std::uint64_t upper = H::bucket_upper_ns(i);
    ASSERT_LE(lower, upper) << i;
    ASSERT_EQ(H::bucket_index(lower), i) << i;
    ASSERT_EQ(H::bucket_index(upper), i) << i;
    if (i > 0) {
      ASSERT_EQ(lower, H::bucket_upper_ns(i - 1) + 1) << "gap or overlap before bucket " << i;
    }
    // Width <= lower / 64, i.e. relative error of the upper bound < 1/64 (~1.6 %).
    ASSERT_LE((upper - lower + 1) * 64, std::max<std::uint64_t>(lower, 64)) << i;
  }
  EXPECT_EQ(H::bucket_upper_ns(H::kBucketCount - 1), H::kMaxTrackedNs);
}

TEST(LatencyHistogram, seeded_random_values_respect_error_bound) {
  std::mt19937_64 rng(0xED3u);
  auto h = make_histogram();
  std::vector<std::int64_t> values;
  values.reserve(200'000);
  for (int n = 0; n < 200'000; ++n) {
    // Random magnitude (log-uniform-ish) so every power of two up to 2^41 is exercised.
    const unsigned bits = static_cast<unsigned>(rng() % 42);
    const std::uint64_t v = bits == 0 ? 0 : rng() >> (64 - bits);
    const std::size_t i = H::bucket_index(v);
    ASSERT_LT(i, H::kBucketCount);
    ASSERT_LE(H::bucket_lower_ns(i), v);
    ASSERT_GE(H::bucket_upper_ns(i), v);
    ASSERT_LE((H::bucket_upper_ns(i) - v) * 64, v) << v;
    values.push_back(static_cast<std::int64_t>(v));
    h->record(static_cast<std::int64_t>(v));
  }
  std::sort(values.begin(), values.end());
  for (const double q : {0.001, 0.1, 0.25, 0.5, 0.75, 0.9, 0.99, 0.999, 1.0}) {
    const auto rank = static_cast<std::size_t>(std::ceil(q * static_cast<double>(values.size())));
    const std::int64_t truth = values[std::max<std::size_t>(rank, 1) - 1];
    const std::int64_t est = h->quantile(q);
    EXPECT_GE(est, truth) << "q=" << q;
    EXPECT_LE(est - truth, truth / 64) << "q=" << q;
  }
  EXPECT_EQ(h->quantile(1.0), values.back());
  EXPECT_EQ(h->max_ns(), values.back());
}

TEST(LatencyHistogram, huge_values_land_in_last_bucket_and_keep_true_max) {
  constexpr std::int64_t kHuge = std::int64_t{1} << 50;
  EXPECT_EQ(H::bucket_index(static_cast<std::uint64_t>(kHuge)), H::kBucketCount - 1);
  EXPECT_EQ(H::bucket_index(std::numeric_limits<std::uint64_t>::max()), H::kBucketCount - 1);
  auto h = make_histogram();
  h->record(10);
  h->record(kHuge);
  EXPECT_EQ(h->count(), 2u);
  EXPECT_EQ(h->quantile(0.5), 10);
  EXPECT_EQ(h->quantile(1.0), kHuge);
  EXPECT_EQ(h->max_ns(), kHuge);
  h->record(std::numeric_limits<std::int64_t>::max());
  EXPECT_EQ(h->quantile(1.0), std::numeric_limits<std::int64_t>::max());
}

TEST(LatencyHistogram, negative_values_count_as_zero) {
  auto h = make_histogram();
  h->record(-5);
  h->record(std::numeric_limits<std::int64_t>::min());
  EXPECT_EQ(h->count(), 2u);
  EXPECT_EQ(h->quantile(1.0), 0);
  EXPECT_EQ(h->max_ns(), 0);
}

TEST(LatencyHistogram, reset_forgets_everything) {
  auto h = make_histogram();
  h->record(1'000'000);
  h->reset();
  EXPECT_EQ(h->count(), 0u);
  EXPECT_EQ(h->quantile(1.0), 0);
  h->record(7);
  EXPECT_EQ(h->quantile(1.0), 7);
  EXPECT_EQ(h->quantile(0.0), 7);
}

}  // namespace
}  // namespace edm::rt

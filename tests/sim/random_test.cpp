#include "edm/sim/random.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace edm::sim {
namespace {

TEST(SimRandom, uniform_is_open_unit_interval_with_right_moments) {
  constexpr int kN = 200000;
  double sum = 0.0, sum2 = 0.0;
  for (int i = 0; i < kN; ++i) {
    const double u = uniform(42, Stream::kTd, static_cast<std::uint64_t>(i));
    ASSERT_GT(u, 0.0);
    ASSERT_LT(u, 1.0);
    sum += u;
    sum2 += u * u;
  }
  EXPECT_NEAR(sum / kN, 0.5, 0.003);
  EXPECT_NEAR(sum2 / kN - 0.25, 1.0 / 12.0, 0.002);
}

TEST(SimRandom, keyed_by_seed_stream_and_index_only) {
  EXPECT_EQ(uniform(7, Stream::kArc, 1000), uniform(7, Stream::kArc, 1000));
  EXPECT_NE(uniform(7, Stream::kArc, 1000), uniform(8, Stream::kArc, 1000));
  EXPECT_NE(uniform(7, Stream::kArc, 1000), uniform(7, Stream::kTd, 1000));
  EXPECT_NE(uniform(7, Stream::kArc, 1000), uniform(7, Stream::kArc, 1001));
  // Streams are not correlated with each other at the same index.
  double sxy = 0.0;
  constexpr int kN = 100000;
  for (int i = 0; i < kN; ++i) {
    const auto k = static_cast<std::uint64_t>(i);
    sxy += (uniform(1, Stream::kTd, k) - 0.5) * (uniform(1, Stream::kArc, k) - 0.5);
  }
  EXPECT_NEAR(sxy / kN * 12.0, 0.0, 0.02);
}

TEST(SimRandom, normal_has_zero_mean_unit_variance) {
  constexpr int kN = 200000;
  double sum = 0.0, sum2 = 0.0;
  for (int i = 0; i < kN; ++i) {
    const double z = normal(3, Stream::kRemovalScatter, static_cast<std::uint64_t>(i));
    ASSERT_TRUE(std::isfinite(z));
    sum += z;
    sum2 += z * z;
  }
  EXPECT_NEAR(sum / kN, 0.0, 0.01);
  EXPECT_NEAR(sum2 / kN, 1.0, 0.015);
}

TEST(SimRandom, splitmix64_reference_values) {
  // First outputs of SplitMix64 seeded with 0 (Vigna's reference implementation).
  SplitMix64 g(0);
  EXPECT_EQ(g.next(), 0xE220A8397B1DCDAFULL);
  EXPECT_EQ(g.next(), 0x6E789E6AA1B965F4ULL);
}

}  // namespace
}  // namespace edm::sim

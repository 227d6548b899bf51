#include "edm/blocks/moving_average.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <deque>
#include <limits>
#include <random>

#include "block_harness.hpp"

namespace edm::blocks {
namespace {

constexpr double kSpike = 1e12;

// Brute force: the mean of the samples in the window, summed afresh. The ±kSpike samples are
// counted as an integer (exact) and the rest summed in extended precision, so the reference stays
// exact even when +kSpike and −kSpike are in the window together (a plain long double sum would
// lose ~1e-7 there).
long double brute_mean(const std::deque<double>& window) {
  long double small = 0.0L;
  long long spikes = 0;
  for (double x : window) {
    if (std::fabs(x) == kSpike) {
      spikes += x > 0.0 ? 1 : -1;
    } else {
      small += x;
    }
  }
  const long double sum = static_cast<long double>(spikes) * kSpike + small;
  return sum / static_cast<long double>(window.size());
}

class MovingAverageRandomTest : public ::testing::TestWithParam<std::int64_t> {};

// Random samples in [-1, 1] with rare spikes of ±1e12: a plain running sum loses the low bits of
// everything added while a spike is in the window and keeps that error (~1e-4) after the spike
// has left; the brute-force mean does not, so drift shows up as a mismatch.
TEST_P(MovingAverageRandomTest, equals_brute_force_mean_without_drift) {
  const std::int64_t window = GetParam();
  BlockHarness<MovingAverage> h;
  ASSERT_TRUE(h.start({.window = window}).empty());

  std::mt19937_64 rng(0x5eed'ed11'0000'0001ULL);
  std::uniform_real_distribution<double> noise(-1.0, 1.0);
  std::uniform_int_distribution<int> spike(0, 4999);
  std::deque<double> seen;
  double worst = 0.0;
  for (int n = 0; n < 100000; ++n) {
    double x = noise(rng);
    if (spike(rng) == 0) {
      x = x < 0.0 ? -kSpike : kSpike;
    }
    seen.push_back(x);
    if (static_cast<std::int64_t>(seen.size()) > window) {
      seen.pop_front();
    }
    ASSERT_EQ(h.step(x), BlockStatus::kOk);
    const long double ref = brute_mean(seen);
    const double err = std::fabs(static_cast<double>(static_cast<long double>(h.out()) - ref));
    const double tol = 1e-12 * (1.0 + std::fabs(static_cast<double>(ref)));
    ASSERT_LE(err, tol) << "n = " << n << ", window = " << window;
    ASSERT_EQ(h.out<bool>("full"), n + 1 >= window) << "n = " << n;
    worst = std::max(worst, err / tol);
  }
  RecordProperty("worst_error_over_tolerance", std::to_string(worst));
}

INSTANTIATE_TEST_SUITE_P(Windows, MovingAverageRandomTest, ::testing::Values(1, 7, 4096));

TEST(MovingAverageTest, before_full_averages_what_has_been_seen) {
  BlockHarness<MovingAverage> h;
  ASSERT_TRUE(h.start({.window = 4}).empty());
  EXPECT_EQ(h.out(), 0.0);
  EXPECT_FALSE(h.out<bool>("full"));
  h.step(4.0);
  EXPECT_EQ(h.out(), 4.0);
  h.step(8.0);
  EXPECT_EQ(h.out(), 6.0);
  h.step(0.0);
  EXPECT_EQ(h.out(), 4.0);
  EXPECT_FALSE(h.out<bool>("full"));
  h.step(-4.0);
  EXPECT_EQ(h.out(), 2.0);
  EXPECT_TRUE(h.out<bool>("full"));
  h.step(12.0);  // 4 leaves
  EXPECT_EQ(h.out(), 4.0);
}

TEST(MovingAverageTest, non_finite_samples_are_not_stored) {
  BlockHarness<MovingAverage> h;
  ASSERT_TRUE(h.start({.window = 3}).empty());
  h.step(1.0);
  h.step(2.0);
  EXPECT_EQ(h.step(std::numeric_limits<double>::quiet_NaN()), BlockStatus::kFault);
  EXPECT_EQ(h.out(), 1.5);
  EXPECT_FALSE(h.out<bool>("full"));
  EXPECT_EQ(h.step(std::numeric_limits<double>::infinity()), BlockStatus::kFault);
  EXPECT_EQ(h.step(6.0), BlockStatus::kOk);
  EXPECT_EQ(h.out(), 3.0) << "mean of 1, 2, 6";
  EXPECT_TRUE(h.out<bool>("full"));
}

TEST(MovingAverageTest, overflowing_sum_faults_and_recovers) {
  constexpr std::int64_t kWindow = 3;
  BlockHarness<MovingAverage> h;
  ASSERT_TRUE(h.start({.window = kWindow}).empty());
  const double big = std::numeric_limits<double>::max();
  EXPECT_EQ(h.step(1.0), BlockStatus::kOk);
  EXPECT_EQ(h.step(big), BlockStatus::kOk);
  const double held = h.out();
  EXPECT_EQ(h.step(big), BlockStatus::kFault) << "big + big overflows";
  EXPECT_EQ(h.out(), held);
  // The sum is re-seeded from the samples once per pass: clean again within two windows.
  for (int k = 0; k < 2 * kWindow; ++k) {
    h.step(3.0);
  }
  EXPECT_EQ(h.step(3.0), BlockStatus::kOk);
  EXPECT_EQ(h.out(), 3.0);
}

TEST(MovingAverageTest, window_is_not_writable_at_run_time) {
  BlockHarness<MovingAverage> h;
  ASSERT_TRUE(h.start({.window = 2}).empty());
  const auto errs = h.write_param("window", rt::ParamValue::of_int(3));
  ASSERT_EQ(errs.size(), 1u);
  EXPECT_NE(errs[0].message.find("load time only"), std::string::npos) << errs[0].message;
  EXPECT_EQ(h.block().read_param(h.param_index("window")).i, 2);
  h.step(1.0);
  h.step(2.0);
  h.step(3.0);
  EXPECT_EQ(h.out(), 2.5);
}

TEST(MovingAverageTest, window_range_is_validated) {
  EXPECT_FALSE(rt::validate_params(MovingAverageParams{.window = 0}).empty());
  EXPECT_FALSE(rt::validate_params(MovingAverageParams{.window = -3}).empty());
  EXPECT_FALSE(rt::validate_params(MovingAverageParams{.window = 65537}).empty());
  EXPECT_TRUE(rt::validate_params(MovingAverageParams{.window = 1}).empty());
  BlockHarness<MovingAverage> h;
  ASSERT_TRUE(h.start({.window = 65536}).empty());
  h.step(2.0);
  EXPECT_EQ(h.out(), 2.0);
}

TEST(MovingAverageTest, activate_empties_the_window) {
  BlockHarness<MovingAverage> h;
  ASSERT_TRUE(h.start({.window = 2}).empty());
  h.step(10.0);
  h.step(20.0);
  h.block().activate();
  EXPECT_EQ(h.out(), 0.0);
  EXPECT_FALSE(h.out<bool>("full"));
  h.step(1.0);
  EXPECT_EQ(h.out(), 1.0);
}

}  // namespace
}  // namespace edm::blocks

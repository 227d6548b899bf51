#include "edm/blocks/sine_source.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>

#include "block_harness.hpp"

namespace edm::blocks {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

TEST(SineSourceTest, matches_std_sin_over_the_first_cycles) {
  BlockHarness<SineSource> h(1ms);
  const SineSourceParams p{.amplitude = 2.0, .frequency_hz = 7.3, .phase_rad = 0.3, .offset = 0.5};
  ASSERT_TRUE(h.start(p).empty());
  for (std::uint64_t n = 0; n < 5000; ++n) {
    ASSERT_EQ(h.step(), BlockStatus::kOk);
    const double t = static_cast<double>(n) * 1e-3;
    ASSERT_NEAR(h.out(), 0.5 + 2.0 * std::sin(kTwoPi * 7.3 * t + 0.3), 1e-11) << "n = " << n;
  }
}

// f·dt = 7.25 Hz · 1 ms = 29/4000 periods per sample exactly (7.25 and 1e6 ns are exact), so
// the true phase at cycle n is 2π·((29·n) mod 4000)/4000: an exact reference at any n.
TEST(SineSourceTest, matches_exact_phase_at_large_cycle_counts) {
  BlockHarness<SineSource> h(1ms);
  const SineSourceParams p{.amplitude = 3.0, .frequency_hz = 7.25, .phase_rad = -1.1, .offset = 1};
  ASSERT_TRUE(h.start(p).empty());
  const std::uint64_t cycles[] = {0,
                                  1,
                                  3999,
                                  4000,
                                  1'000'000'007ULL,
                                  1ULL << 40,
                                  1'000'000'000'123ULL,
                                  1'000'000'000'000'007ULL,
                                  (1ULL << 53) - 1};
  for (std::uint64_t n : cycles) {
    h.set_cycle(n);
    ASSERT_EQ(h.step(), BlockStatus::kOk);
    const double frac = static_cast<double>((29 * n) % 4000) / 4000.0;
    EXPECT_NEAR(h.out(), 1.0 + 3.0 * std::sin(kTwoPi * frac - 1.1), 1e-12) << "n = " << n;
    EXPECT_EQ(h.out(), h.block().value_at(n));
  }
}

TEST(SineSourceTest, quarter_period_points_land_on_the_peaks) {
  // 1 kHz at 250 us: four samples per period; n ≡ 1 (mod 4) is the positive peak.
  BlockHarness<SineSource> h(250us);
  ASSERT_TRUE(h.start({.amplitude = 1.0, .frequency_hz = 1000.0}).empty());
  for (std::uint64_t n : {1ULL, 5ULL, (1ULL << 50) + 1, 4'000'000'000'000'001ULL}) {
    EXPECT_NEAR(h.block().value_at(n), 1.0, 1e-15) << "n = " << n;
    EXPECT_NEAR(h.block().value_at(n + 2), -1.0, 1e-15) << "n = " << n;
    EXPECT_NEAR(h.block().value_at(n + 1), 0.0, 1e-14) << "n = " << n;
  }
}

TEST(SineSourceTest, runtime_write_of_frequency_applies_from_the_next_cycle) {
  BlockHarness<SineSource> h(1ms);
  ASSERT_TRUE(h.start({.amplitude = 1.0, .frequency_hz = 1.0}).empty());
  const auto errs = h.write_param("frequency_hz", rt::ParamValue::of_real(250.0));
  ASSERT_TRUE(errs.empty()) << describe(errs);
  h.set_cycle(1001);  // 250 Hz · 1.001 s = 250.25 periods
  h.step();
  EXPECT_NEAR(h.out(), 1.0, 1e-14);

  EXPECT_FALSE(h.write_param("frequency_hz", rt::ParamValue::of_real(0.0)).empty());
  EXPECT_FALSE(h.write_param("frequency_hz", rt::ParamValue::of_real(-5.0)).empty());
  h.set_cycle(1001);
  h.step();
  EXPECT_NEAR(h.out(), 1.0, 1e-14) << "refused writes left 250 Hz in place";
}

TEST(SineSourceTest, validate_refuses_bad_parameters) {
  EXPECT_TRUE(rt::validate_params(SineSourceParams{}).empty());
  auto errs = rt::validate_params(SineSourceParams{.frequency_hz = 0.0});
  ASSERT_EQ(errs.size(), 1u);
  EXPECT_EQ(errs[0].field, "frequency_hz");
  errs =
      rt::validate_params(SineSourceParams{.amplitude = std::numeric_limits<double>::infinity()});
  ASSERT_EQ(errs.size(), 1u);
  EXPECT_EQ(errs[0].field, "amplitude");
  EXPECT_FALSE(rt::validate_params(
                   SineSourceParams{.frequency_hz = std::numeric_limits<double>::quiet_NaN()})
                   .empty());
  BlockHarness<SineSource> no_task(rt::Duration{0});
  EXPECT_FALSE(no_task.start().empty());
}

}  // namespace
}  // namespace edm::blocks

#include "edm/blocks/limiter.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>

#include "block_harness.hpp"

namespace edm::blocks {
namespace {

TEST(LimiterTest, clamps_to_min_and_max) {
  BlockHarness<Limiter> h;
  ASSERT_TRUE(h.start({.min = -1.0, .max = 2.0, .rate = 0.0}).empty());
  struct Row {
    double in, out;
    bool limited;
  };
  for (const Row r : {Row{0.5, 0.5, false}, Row{3.0, 2.0, true}, Row{2.0, 2.0, false},
                      Row{-5.0, -1.0, true}, Row{-1.0, -1.0, false}, Row{1e300, 2.0, true}}) {
    EXPECT_EQ(h.step(r.in), r.limited ? BlockStatus::kSaturated : BlockStatus::kOk)
        << "in = " << r.in;
    EXPECT_EQ(h.out(), r.out) << "in = " << r.in;
    EXPECT_EQ(h.out<bool>("limited"), r.limited) << "in = " << r.in;
  }
}

TEST(LimiterTest, rate_limit_ramps_with_slope_rate_times_dt) {
  constexpr double kRate = 125.0;  // units/s: 0.125 per 1 ms cycle, so the ramp values are exact
  BlockHarness<Limiter> h(1ms);
  ASSERT_TRUE(h.start({.min = -50.0, .max = 50.0, .rate = kRate}).empty());
  const double step = kRate * h.dt_s();

  EXPECT_EQ(h.step(0.0), BlockStatus::kOk) << "first cycle starts from the input";
  EXPECT_EQ(h.out(), 0.0);

  // Rising ramp towards 10: rate·dt per cycle.
  double prev = 0.0;
  int k = 0;
  while (10.0 - prev > step) {
    ++k;
    ASSERT_EQ(h.step(10.0), BlockStatus::kSaturated) << "k = " << k;
    EXPECT_TRUE(h.out<bool>("limited"));
    EXPECT_NEAR(h.out() - prev, step, 1e-12) << "k = " << k;
    EXPECT_NEAR(h.out(), k * step, 1e-11) << "k = " << k;
    prev = h.out();
    ASSERT_LT(k, 200);
  }
  EXPECT_EQ(k, 79);
  // The last step fits within rate·dt and lands exactly on the target.
  EXPECT_EQ(h.step(10.0), BlockStatus::kOk);
  EXPECT_EQ(h.out(), 10.0);
  EXPECT_FALSE(h.out<bool>("limited"));

  // Falling ramp: same slope downwards.
  for (int j = 1; j <= 30; ++j) {
    ASSERT_EQ(h.step(-10.0), BlockStatus::kSaturated);
    EXPECT_NEAR(h.out(), 10.0 - j * step, 1e-11) << "j = " << j;
  }
}

TEST(LimiterTest, ramp_towards_a_clamped_target_stays_saturated) {
  BlockHarness<Limiter> h(2ms);
  ASSERT_TRUE(h.start({.min = 0.0, .max = 1.0, .rate = 250.0}).empty());  // 0.5 per cycle
  h.step(0.0);
  EXPECT_EQ(h.step(7.0), BlockStatus::kSaturated);
  EXPECT_NEAR(h.out(), 0.5, 1e-15);
  EXPECT_EQ(h.step(7.0), BlockStatus::kSaturated);
  EXPECT_EQ(h.out(), 1.0);
  EXPECT_EQ(h.step(7.0), BlockStatus::kSaturated) << "still clamped at max";
  EXPECT_EQ(h.out(), 1.0);
}

TEST(LimiterTest, zero_rate_means_unlimited) {
  BlockHarness<Limiter> h;
  ASSERT_TRUE(h.start({.min = -1e9, .max = 1e9, .rate = 0.0}).empty());
  h.step(0.0);
  EXPECT_EQ(h.step(1e6), BlockStatus::kOk);
  EXPECT_EQ(h.out(), 1e6);
}

TEST(LimiterTest, runtime_write_of_rate_changes_the_slope) {
  BlockHarness<Limiter> h(1ms);
  ASSERT_TRUE(h.start({.min = -100.0, .max = 100.0, .rate = 10.0}).empty());
  h.step(0.0);
  h.step(50.0);
  EXPECT_NEAR(h.out(), 0.01, 1e-15);
  const auto errs = h.write_param("rate", rt::ParamValue::of_real(1000.0));
  ASSERT_TRUE(errs.empty()) << describe(errs);
  h.step(50.0);
  EXPECT_NEAR(h.out(), 1.01, 1e-12);
  EXPECT_FALSE(h.write_param("rate", rt::ParamValue::of_real(-1.0)).empty());
  h.step(50.0);
  EXPECT_NEAR(h.out(), 2.01, 1e-12) << "refused write left the rate alone";
}

TEST(LimiterTest, narrowed_range_at_run_time_wins_over_the_slew_limit) {
  BlockHarness<Limiter> h(1ms);
  ASSERT_TRUE(h.start({.min = 0.0, .max = 10.0, .rate = 1.0}).empty());
  h.step(8.0);
  ASSERT_EQ(h.out(), 8.0);
  ASSERT_TRUE(h.write_param("max", rt::ParamValue::of_real(5.0)).empty());
  EXPECT_EQ(h.step(8.0), BlockStatus::kSaturated);
  EXPECT_EQ(h.out(), 5.0);
}

TEST(LimiterTest, non_finite_input_holds_outputs_and_faults) {
  BlockHarness<Limiter> h(1ms);
  ASSERT_TRUE(h.start({.min = -1.0, .max = 1.0, .rate = 100.0}).empty());
  h.step(0.0);
  h.step(5.0);  // rate-limited to 0.1
  const double held = h.out();
  EXPECT_EQ(h.step(std::numeric_limits<double>::quiet_NaN()), BlockStatus::kFault);
  EXPECT_EQ(h.out(), held);
  EXPECT_TRUE(h.out<bool>("limited")) << "held from the last good cycle";
  EXPECT_EQ(h.step(-std::numeric_limits<double>::infinity()), BlockStatus::kFault);
  EXPECT_EQ(h.out(), held);
  // The slew state is intact: the ramp continues from where it was.
  h.step(5.0);
  EXPECT_NEAR(h.out(), 0.2, 1e-15);
}

TEST(LimiterTest, validate_refuses_inverted_range_negative_rate_and_nan) {
  auto errs = rt::validate_params(LimiterParams{.min = 1.0, .max = 0.0, .rate = 0.0});
  ASSERT_EQ(errs.size(), 1u);
  EXPECT_EQ(errs[0].field, "max");
  errs = rt::validate_params(LimiterParams{.min = 0.0, .max = 1.0, .rate = -1.0});
  ASSERT_EQ(errs.size(), 1u);
  EXPECT_EQ(errs[0].field, "rate");
  errs = rt::validate_params(
      LimiterParams{.min = std::numeric_limits<double>::quiet_NaN(), .max = 1.0});
  ASSERT_FALSE(errs.empty());
  EXPECT_EQ(errs[0].field, "min");
  EXPECT_TRUE((rt::validate_params(LimiterParams{.min = 2.0, .max = 2.0, .rate = 0.0}).empty()));
  EXPECT_TRUE(rt::validate_params(LimiterParams{}).empty());
}

TEST(LimiterTest, activate_restarts_from_the_input) {
  BlockHarness<Limiter> h(1ms);
  ASSERT_TRUE(h.start({.min = -10.0, .max = 10.0, .rate = 1.0}).empty());
  h.step(0.0);
  h.step(5.0);
  EXPECT_NEAR(h.out(), 0.001, 1e-15);
  h.block().activate();
  EXPECT_EQ(h.step(5.0), BlockStatus::kOk);
  EXPECT_EQ(h.out(), 5.0);
}

}  // namespace
}  // namespace edm::blocks

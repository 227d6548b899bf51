#include "edm/blocks/low_pass.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>

#include "block_harness.hpp"

namespace edm::blocks {
namespace {

using rt::Duration;

// dt/τ from the integer nanosecond counts, independently of the block's code path.
double ratio(Duration dt, Duration tau) {
  return static_cast<double>(dt.count()) / static_cast<double>(tau.count());
}

struct Case {
  Duration tau;
  Duration dt;
};

class LowPassStepTest : public ::testing::TestWithParam<Case> {};

TEST_P(LowPassStepTest, step_response_is_one_minus_exp_at_the_sample_instants) {
  const auto [tau, dt] = GetParam();
  BlockHarness<LowPass> h(dt);
  ASSERT_TRUE(h.start({.tau = tau, .initial = 0.0}).empty());
  EXPECT_NEAR(h.block().alpha(), 1.0 - std::exp(-ratio(dt, tau)), 1e-15);
  EXPECT_EQ(h.out(), 0.0) << "activate() sets out = initial";
  // Out after the k-th update is the continuous response at t = k·dt (input held since t = 0).
  const int cycles = std::min<int>(20000, static_cast<int>(8.0 / ratio(dt, tau)) + 10);
  for (int k = 1; k <= cycles; ++k) {
    ASSERT_EQ(h.step(1.0), BlockStatus::kOk);
    const double t_over_tau = k * ratio(dt, tau);
    ASSERT_NEAR(h.out(), 1.0 - std::exp(-t_over_tau), 1e-12) << "k = " << k;
  }
}

INSTANTIATE_TEST_SUITE_P(TauAndPeriod, LowPassStepTest,
                         ::testing::Values(Case{10ms, 1ms}, Case{1ms, 1ms}, Case{3300us, 250us},
                                           Case{1s, 100us}, Case{50us, 1ms}, Case{7ms, 3ms}));

TEST(LowPassTest, step_from_initial_to_another_level) {
  BlockHarness<LowPass> h(500us);
  ASSERT_TRUE(h.start({.tau = 4ms, .initial = 2.0}).empty());
  EXPECT_EQ(h.out(), 2.0);
  for (int k = 1; k <= 100; ++k) {
    h.step(-3.0);
    // y(t) = x + (y0 − x)·exp(−t/τ)
    ASSERT_NEAR(h.out(), -3.0 + 5.0 * std::exp(-k * 0.125), 1e-12) << "k = " << k;
  }
}

TEST(LowPassTest, runtime_write_of_tau_changes_alpha_bumplessly) {
  BlockHarness<LowPass> h(1ms);
  ASSERT_TRUE(h.start({.tau = 10ms, .initial = 0.0}).empty());
  for (int k = 0; k < 50; ++k) {
    h.step(1.0);
  }
  const double y50 = h.out();
  ASSERT_NEAR(y50, 1.0 - std::exp(-5.0), 1e-12);

  const auto errs = h.write_param("tau", rt::ParamValue::of_duration(20ms));
  ASSERT_TRUE(errs.empty()) << describe(errs);
  EXPECT_NEAR(h.block().alpha(), 1.0 - std::exp(-1.0 / 20.0), 1e-15);
  EXPECT_EQ(h.out(), y50) << "a parameter write does not touch the state";
  EXPECT_EQ(h.block().read_param(h.param_index("tau")).i, Duration(20ms).count());
  for (int k = 1; k <= 100; ++k) {
    h.step(1.0);
    // The new time constant applies from the state reached with the old one.
    ASSERT_NEAR(h.out(), 1.0 - (1.0 - y50) * std::exp(-k / 20.0), 1e-12) << "k = " << k;
  }
}

TEST(LowPassTest, invalid_runtime_write_is_refused_and_changes_nothing) {
  BlockHarness<LowPass> h(1ms);
  ASSERT_TRUE(h.start({.tau = 10ms, .initial = 0.0}).empty());
  const double alpha = h.block().alpha();
  const std::size_t tau_index = h.param_index("tau");

  for (const Duration bad : {Duration{0}, Duration{-5'000'000}}) {
    const auto errs = h.block().stage_param(tau_index, rt::ParamValue::of_duration(bad));
    ASSERT_EQ(errs.size(), 1u) << "tau = " << bad.count() << "ns";
    EXPECT_EQ(errs[0].field, "tau");
  }
  // Wrong type: a REAL for a TIME parameter.
  EXPECT_FALSE(h.block().stage_param(tau_index, rt::ParamValue::of_real(0.02)).empty());

  EXPECT_EQ(h.block().read_param(tau_index).i, Duration(10ms).count()) << "shadow unchanged";
  EXPECT_EQ(h.block().params().tau, 10ms);
  EXPECT_EQ(h.block().alpha(), alpha);
  for (int k = 1; k <= 30; ++k) {
    h.step(1.0);
    ASSERT_NEAR(h.out(), 1.0 - std::exp(-k / 10.0), 1e-12);
  }
}

TEST(LowPassTest, non_finite_input_holds_state_and_faults) {
  BlockHarness<LowPass> h(1ms);
  ASSERT_TRUE(h.start({.tau = 10ms, .initial = 0.0}).empty());
  h.step(1.0);
  const double y1 = h.out();
  EXPECT_EQ(h.step(std::numeric_limits<double>::quiet_NaN()), BlockStatus::kFault);
  EXPECT_EQ(h.out(), y1);
  EXPECT_EQ(h.step(std::numeric_limits<double>::infinity()), BlockStatus::kFault);
  EXPECT_EQ(h.out(), y1);
  // The state was not poisoned: the next sample continues as if the bad ones never came.
  EXPECT_EQ(h.step(1.0), BlockStatus::kOk);
  EXPECT_NEAR(h.out(), 1.0 - std::exp(-0.2), 1e-12);
}

TEST(LowPassTest, validate_and_configure_refuse_bad_setups) {
  EXPECT_FALSE((rt::validate_params(LowPassParams{.tau = Duration{0}, .initial = 0.0}).empty()));
  const LowPassParams nan_initial{.tau = 1ms, .initial = std::numeric_limits<double>::quiet_NaN()};
  EXPECT_FALSE(rt::validate_params(nan_initial).empty());
  EXPECT_TRUE(rt::validate_params(LowPassParams{}).empty());
  EXPECT_EQ(LowPassParams{}.tau, 10ms);

  BlockHarness<LowPass> no_task(Duration{0});
  EXPECT_FALSE(no_task.start().empty()) << "a filter needs a task period";
}

TEST(LowPassTest, activate_restarts_from_initial) {
  BlockHarness<LowPass> h(1ms);
  ASSERT_TRUE(h.start({.tau = 1ms, .initial = 0.5}).empty());
  h.step(10.0);
  EXPECT_GT(h.out(), 5.0);
  h.block().activate();
  EXPECT_EQ(h.out(), 0.5);
}

}  // namespace
}  // namespace edm::blocks

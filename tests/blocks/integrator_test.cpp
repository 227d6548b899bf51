#include "edm/blocks/integrator.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>

#include "block_harness.hpp"

namespace edm::blocks {
namespace {

TEST(IntegratorTest, integrates_a_constant_exactly) {
  // dt = 0.125 s and k·in·dt = 0.5·4·0.125 = 0.25: every partial sum is exact in binary.
  BlockHarness<Integrator> h(125ms);
  ASSERT_TRUE(h.start({.k = 0.5, .min = -1e9, .max = 1e9, .initial = 1.0}).empty());
  EXPECT_EQ(h.out(), 1.0) << "configure() sets out = initial";
  h.in().set(4.0);
  for (int n = 1; n <= 10000; ++n) {
    ASSERT_EQ(h.step(), BlockStatus::kOk);
    ASSERT_EQ(h.out(), 1.0 + 0.25 * n) << "n = " << n;
  }
}

TEST(IntegratorTest, integrates_a_constant_at_1ms) {
  BlockHarness<Integrator> h(1ms);
  ASSERT_TRUE(h.start({.k = 2.0, .min = -1e9, .max = 1e9, .initial = 0.0}).empty());
  for (int n = 1; n <= 5000; ++n) {
    h.step(-3.0);
    ASSERT_NEAR(h.out(), -6.0 * n * 1e-3, 1e-12) << "n = " << n;  // out = k·in·t
  }
}

TEST(IntegratorTest, clamps_without_windup) {
  BlockHarness<Integrator> h(125ms);
  ASSERT_TRUE(h.start({.k = 1.0, .min = -1.0, .max = 1.0, .initial = 0.0}).empty());
  EXPECT_EQ(h.step(4.0), BlockStatus::kOk);  // 0.5
  EXPECT_EQ(h.step(4.0), BlockStatus::kOk);  // 1.0, exactly at the limit: not cut
  EXPECT_EQ(h.out(), 1.0);
  for (int n = 0; n < 100; ++n) {
    EXPECT_EQ(h.step(4.0), BlockStatus::kSaturated);
    EXPECT_EQ(h.out(), 1.0);
  }
  // Anti-windup: the first step back leaves the limit at once.
  EXPECT_EQ(h.step(-2.0), BlockStatus::kOk);
  EXPECT_EQ(h.out(), 0.75);
  for (int n = 0; n < 10; ++n) {
    h.step(-8.0);
  }
  EXPECT_EQ(h.out(), -1.0);
  EXPECT_EQ(h.step(-8.0), BlockStatus::kSaturated);
}

TEST(IntegratorTest, reset_sets_initial_and_ignores_the_input) {
  BlockHarness<Integrator> h(125ms);
  ASSERT_TRUE(h.start({.k = 1.0, .min = -10.0, .max = 10.0, .initial = 2.0}).empty());
  auto& reset = h.source<bool>("reset");
  h.step(4.0);
  h.step(4.0);
  EXPECT_EQ(h.out(), 3.0);
  reset.set(true);
  for (int n = 0; n < 3; ++n) {
    EXPECT_EQ(h.step(4.0), BlockStatus::kOk);
    EXPECT_EQ(h.out(), 2.0);
  }
  EXPECT_EQ(h.step(std::numeric_limits<double>::quiet_NaN()), BlockStatus::kOk)
      << "in is not read while reset";
  reset.set(false);
  h.step(4.0);
  EXPECT_EQ(h.out(), 2.5);
}

TEST(IntegratorTest, reset_value_is_clamped_to_the_range) {
  BlockHarness<Integrator> h(125ms);
  ASSERT_TRUE(h.start({.k = 1.0, .min = -1.0, .max = 1.0, .initial = 5.0}).empty());
  EXPECT_EQ(h.out(), 1.0);
}

TEST(IntegratorTest, continues_from_a_value_written_into_out) {
  BlockHarness<Integrator> h(125ms);
  ASSERT_TRUE(h.start({.k = 1.0, .min = -100.0, .max = 100.0, .initial = 0.0}).empty());
  rt::Output<double>* out = h.pin("out").as_output<double>();
  ASSERT_NE(out, nullptr);
  out->set(42.0);  // what the retain store does at start-up
  h.step(2.0);
  EXPECT_EQ(h.out(), 42.25);
  // Forcing: the forced value is the state; after unforce the integration continues from it.
  out->force(-7.0);
  h.step(2.0);
  EXPECT_EQ(h.out(), -7.0);
  out->unforce();
  h.step(2.0);
  EXPECT_EQ(h.out(), -6.75);
}

TEST(IntegratorTest, non_finite_input_holds_and_non_finite_state_restarts) {
  BlockHarness<Integrator> h(125ms);
  ASSERT_TRUE(h.start({.k = 1.0, .min = -100.0, .max = 100.0, .initial = 1.0}).empty());
  h.step(4.0);
  EXPECT_EQ(h.step(std::numeric_limits<double>::quiet_NaN()), BlockStatus::kFault);
  EXPECT_EQ(h.out(), 1.5);
  EXPECT_EQ(h.step(std::numeric_limits<double>::infinity()), BlockStatus::kFault);
  EXPECT_EQ(h.out(), 1.5);
  h.pin("out").as_output<double>()->set(std::numeric_limits<double>::quiet_NaN());
  EXPECT_EQ(h.step(4.0), BlockStatus::kFault);
  EXPECT_EQ(h.out(), 1.0) << "corrupt state replaced by initial";
  EXPECT_EQ(h.step(4.0), BlockStatus::kOk);
  EXPECT_EQ(h.out(), 1.5);
}

TEST(IntegratorTest, runtime_write_of_k_and_limits) {
  BlockHarness<Integrator> h(125ms);
  ASSERT_TRUE(h.start({.k = 1.0, .min = -100.0, .max = 100.0, .initial = 0.0}).empty());
  auto errs = h.write_param("k", rt::ParamValue::of_real(-2.0));
  ASSERT_TRUE(errs.empty()) << describe(errs);
  h.step(4.0);
  EXPECT_EQ(h.out(), -1.0);
  errs = h.write_param("min", rt::ParamValue::of_real(200.0));
  ASSERT_EQ(errs.size(), 1u) << "min > max is refused";
  EXPECT_EQ(errs[0].field, "max");
  h.step(4.0);
  EXPECT_EQ(h.out(), -2.0);
}

TEST(IntegratorTest, validate_refuses_bad_parameters) {
  EXPECT_TRUE(rt::validate_params(IntegratorParams{}).empty());
  EXPECT_FALSE((rt::validate_params(IntegratorParams{.min = 1.0, .max = -1.0}).empty()));
  EXPECT_FALSE(
      rt::validate_params(IntegratorParams{.k = std::numeric_limits<double>::quiet_NaN()}).empty());
  BlockHarness<Integrator> no_task(rt::Duration{0});
  EXPECT_FALSE(no_task.start().empty());
}

}  // namespace
}  // namespace edm::blocks

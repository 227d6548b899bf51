#include "edm/blocks/gain.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "block_harness.hpp"

namespace edm::blocks {
namespace {

TEST(GainTest, out_is_k_times_in_plus_offset) {
  BlockHarness<Gain> h;
  ASSERT_TRUE(h.start({.k = 2.5, .offset = -1.0}).empty());
  for (double x : {0.0, 1.0, -3.25, 1e6, 0.1}) {
    EXPECT_EQ(h.step(x), BlockStatus::kOk);
    EXPECT_DOUBLE_EQ(h.out(), 2.5 * x - 1.0) << "in = " << x;
  }
}

TEST(GainTest, defaults_pass_the_input_through) {
  BlockHarness<Gain> h;
  ASSERT_TRUE(h.start().empty());
  h.step(-7.125);
  EXPECT_EQ(h.out(), -7.125);
}

TEST(GainTest, non_finite_input_or_result_holds_out_and_faults) {
  BlockHarness<Gain> h;
  ASSERT_TRUE(h.start({.k = 1e6, .offset = 0.0}).empty());  // the largest k (its range)
  ASSERT_EQ(h.step(2.0), BlockStatus::kOk);
  EXPECT_EQ(h.step(kNaN), BlockStatus::kFault);
  EXPECT_EQ(h.out(), 2e6);
  EXPECT_EQ(h.step(-kInf), BlockStatus::kFault);
  EXPECT_EQ(h.out(), 2e6);
  EXPECT_EQ(h.step(1e303), BlockStatus::kFault) << "k·in overflows";
  EXPECT_EQ(h.out(), 2e6);
  EXPECT_EQ(h.step(1.0), BlockStatus::kOk);
  EXPECT_EQ(h.out(), 1e6);
}

TEST(GainTest, zero_gain_still_faults_on_nan) {
  BlockHarness<Gain> h;
  ASSERT_TRUE(h.start({.k = 0.0, .offset = 3.0}).empty());
  EXPECT_EQ(h.step(5.0), BlockStatus::kOk);
  EXPECT_EQ(h.out(), 3.0);
  EXPECT_EQ(h.step(kNaN), BlockStatus::kFault);
}

TEST(GainTest, validate_refuses_non_finite_parameters) {
  const auto errs = rt::validate_params(GainParams{.k = kNaN, .offset = kInf});
  ASSERT_EQ(errs.size(), 2u);
  EXPECT_EQ(errs[0].field, "k");
  EXPECT_EQ(errs[1].field, "offset");
}

TEST(GainTest, runtime_write_of_k_takes_effect_next_cycle) {
  BlockHarness<Gain> h;
  ASSERT_TRUE(h.start().empty());
  EXPECT_TRUE(h.write_param("k", rt::ParamValue::of_real(-4.0)).empty());
  h.step(0.5);
  EXPECT_EQ(h.out(), -2.0);
  EXPECT_FALSE(h.write_param("k", rt::ParamValue::of_real(kNaN)).empty());
  h.step(0.5);
  EXPECT_EQ(h.out(), -2.0);
}

}  // namespace
}  // namespace edm::blocks

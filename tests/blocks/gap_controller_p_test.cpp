#include "edm/blocks/gap_controller_p.hpp"

#include <gtest/gtest.h>

#include <limits>

#include "block_harness.hpp"

namespace edm::blocks {
namespace {

// kg 0.1 mm/s per µs, Tdr 10 µs, feed ≤ 0.5 mm/s down, ≤ 2 mm/s up, retract
// at 1.5 mm/s.
constexpr GapControllerPParams kParams{.kg = 0.1,
                                       .tdr_default_us = 10.0,
                                       .v_feed_max_mm_s = 0.5,
                                       .v_retract_max_mm_s = 2.0,
                                       .retract_speed_mm_s = 1.5,
                                       .idle_feed_mm_s = -0.2};

class GapControllerPTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto errs = h_.start(kParams);
    ASSERT_TRUE(errs.empty()) << describe(errs);
    td_ = &h_.source<double>("td_us");
    tdr_ = &h_.source<double>("tdr_us");
    valid_ = &h_.source<bool>("valid");
    enable_ = &h_.source<bool>("enable");
    hold_ = &h_.source<bool>("hold");
    retract_ = &h_.source<bool>("retract");
    valid_->set(true);
    enable_->set(true);
  }
  BlockStatus step(double td_us) {
    td_->set(td_us);
    return h_.step();
  }
  double vz() const { return h_.out("vz_mm_s"); }
  bool saturated() const { return h_.out<bool>("saturated"); }

  BlockHarness<GapControllerP> h_;
  rt::Output<double>* td_{nullptr};
  rt::Output<double>* tdr_{nullptr};
  rt::Output<bool>* valid_{nullptr};
  rt::Output<bool>* enable_{nullptr};
  rt::Output<bool>* hold_{nullptr};
  rt::Output<bool>* retract_{nullptr};
};

TEST_F(GapControllerPTest, gap_too_large_feeds_down_gap_too_small_backs_off) {
  EXPECT_EQ(step(12.0), BlockStatus::kOk);  // Td > Tdr: gap too large
  EXPECT_LT(vz(), 0.0) << "Z is positive upward: feed down is negative";
  EXPECT_DOUBLE_EQ(vz(), 0.1 * (10.0 - 12.0));
  EXPECT_EQ(step(7.0), BlockStatus::kOk);  // Td < Tdr: gap too small
  EXPECT_GT(vz(), 0.0);
  EXPECT_DOUBLE_EQ(vz(), 0.1 * (10.0 - 7.0));
  EXPECT_EQ(step(10.0), BlockStatus::kOk);
  EXPECT_EQ(vz(), 0.0) << "on the reference: hold position";
  EXPECT_FALSE(saturated());
}

TEST_F(GapControllerPTest, output_is_kg_times_error_inside_the_limits) {
  for (double td = 5.0; td <= 15.0; td += 0.25) {
    ASSERT_EQ(step(td), BlockStatus::kOk) << "td = " << td;
    ASSERT_DOUBLE_EQ(vz(), 0.1 * (10.0 - td)) << "td = " << td;
    ASSERT_FALSE(saturated());
  }
}

TEST_F(GapControllerPTest, clamps_to_feed_and_retract_limits) {
  EXPECT_EQ(step(16.0), BlockStatus::kSaturated);  // 0.1·(10 − 16) = −0.6 < −0.5
  EXPECT_DOUBLE_EQ(vz(), -0.5);
  EXPECT_TRUE(saturated());
  EXPECT_EQ(step(1e6), BlockStatus::kSaturated);
  EXPECT_DOUBLE_EQ(vz(), -0.5);
  EXPECT_EQ(step(15.0), BlockStatus::kOk) << "exactly on the limit is not clamped";
  EXPECT_DOUBLE_EQ(vz(), -0.5);
  EXPECT_FALSE(saturated());
  // The retract limit is 2 mm/s: 0.1·(10 − Td) ≤ 2 for any Td ≥ −10 µs.
  tdr_->set(40.0);
  EXPECT_EQ(step(0.0), BlockStatus::kSaturated);  // 0.1·40 = 4 > 2
  EXPECT_DOUBLE_EQ(vz(), 2.0);
  EXPECT_TRUE(saturated());
}

TEST_F(GapControllerPTest, tdr_input_overrides_the_parameter_when_positive) {
  tdr_->set(20.0);
  step(12.0);
  EXPECT_DOUBLE_EQ(vz(), 0.1 * (20.0 - 12.0));
  tdr_->set(0.0);  // what an unwired input reads
  step(12.0);
  EXPECT_DOUBLE_EQ(vz(), 0.1 * (10.0 - 12.0));
  const double last = vz();
  tdr_->set(-5.0);
  EXPECT_EQ(step(12.0), BlockStatus::kFault) << "a negative reference is a broken signal";
  EXPECT_EQ(vz(), last);
}

TEST_F(GapControllerPTest, unwired_tdr_uses_the_parameter) {
  BlockHarness<GapControllerP> h;
  ASSERT_TRUE(h.start(kParams).empty());
  h.source<double>("td_us").set(14.0);
  EXPECT_EQ(h.step(), BlockStatus::kOk);
  EXPECT_DOUBLE_EQ(h.out("vz_mm_s"), 0.1 * (10.0 - 14.0))
      << "valid and enable default to true, hold and retract to false";
}

TEST_F(GapControllerPTest, no_valid_td_feeds_at_idle_feed) {
  valid_->set(false);
  EXPECT_EQ(step(kNaN), BlockStatus::kOk) << "Td is not read without a valid window";
  EXPECT_DOUBLE_EQ(vz(), -0.2);
  EXPECT_FALSE(saturated());
  // A runtime write of the idle feed applies from the next cycle.
  ASSERT_TRUE(h_.write_param("idle_feed_mm_s", rt::ParamValue::of_real(0.0)).empty());
  step(3.0);
  EXPECT_EQ(vz(), 0.0);
  valid_->set(true);
  step(3.0);
  EXPECT_DOUBLE_EQ(vz(), 0.7);
}

TEST_F(GapControllerPTest, precedence_retract_then_enable_then_hold) {
  step(14.0);
  const double feeding = vz();
  ASSERT_LT(feeding, 0.0);

  hold_->set(true);
  EXPECT_EQ(step(14.0), BlockStatus::kOk);
  EXPECT_EQ(vz(), 0.0) << "hold";
  hold_->set(false);
  EXPECT_EQ(step(14.0), BlockStatus::kOk);
  EXPECT_DOUBLE_EQ(vz(), feeding) << "releasing hold resumes the P law at once";

  enable_->set(false);
  EXPECT_EQ(step(14.0), BlockStatus::kOk);
  EXPECT_EQ(vz(), 0.0) << "disabled";

  hold_->set(true);
  retract_->set(true);
  EXPECT_EQ(step(14.0), BlockStatus::kOk);
  EXPECT_DOUBLE_EQ(vz(), 1.5) << "retract wins over disable and hold";
  EXPECT_FALSE(saturated());
  enable_->set(true);
  hold_->set(false);
  valid_->set(false);
  step(14.0);
  EXPECT_DOUBLE_EQ(vz(), 1.5) << "retract wins over the idle feed";
  valid_->set(true);
  step(14.0);
  EXPECT_DOUBLE_EQ(vz(), 1.5) << "retract wins over the P law";

  retract_->set(false);
  step(14.0);
  EXPECT_DOUBLE_EQ(vz(), feeding);
}

TEST_F(GapControllerPTest, broken_td_faults_and_holds_but_never_blocks_a_retract) {
  EXPECT_EQ(step(16.0), BlockStatus::kSaturated);
  for (const double bad : {kNaN, kInf, -kInf}) {
    EXPECT_EQ(step(bad), BlockStatus::kFault);
    EXPECT_DOUBLE_EQ(vz(), -0.5);
    EXPECT_TRUE(saturated()) << "saturated held too";
  }
  tdr_->set(kNaN);
  EXPECT_EQ(step(12.0), BlockStatus::kFault);
  EXPECT_DOUBLE_EQ(vz(), -0.5);
  tdr_->set(0.0);

  retract_->set(true);
  EXPECT_EQ(step(kNaN), BlockStatus::kOk);
  EXPECT_DOUBLE_EQ(vz(), 1.5);
  retract_->set(false);
  hold_->set(true);
  EXPECT_EQ(step(kNaN), BlockStatus::kOk);
  EXPECT_EQ(vz(), 0.0);
  hold_->set(false);
  EXPECT_EQ(step(12.0), BlockStatus::kOk) << "the state was not poisoned";
  EXPECT_DOUBLE_EQ(vz(), -0.2);
}

TEST_F(GapControllerPTest, runtime_write_of_gain_applies_next_cycle) {
  step(12.0);
  EXPECT_DOUBLE_EQ(vz(), -0.2);
  const auto errs = h_.write_param("kg", rt::ParamValue::of_real(0.05));
  ASSERT_TRUE(errs.empty()) << describe(errs);
  step(12.0);
  EXPECT_DOUBLE_EQ(vz(), -0.1);
  EXPECT_FALSE(h_.write_param("kg", rt::ParamValue::of_real(0.0)).empty());
  EXPECT_FALSE(h_.write_param("kg", rt::ParamValue::of_real(kNaN)).empty());
  step(12.0);
  EXPECT_DOUBLE_EQ(vz(), -0.1) << "refused writes change nothing";
}

TEST(GapControllerPParamsTest, validate_refuses_bad_values) {
  EXPECT_TRUE(rt::validate_params(GapControllerPParams{}).empty());
  EXPECT_TRUE(rt::validate_params(kParams).empty());
  auto with = [](auto edit) {
    GapControllerPParams p = kParams;
    edit(p);
    return rt::validate_params(p);
  };
  EXPECT_FALSE(with([](auto& p) { p.kg = 0.0; }).empty());
  EXPECT_FALSE(with([](auto& p) { p.kg = -0.1; }).empty());
  EXPECT_FALSE(with([](auto& p) { p.tdr_default_us = 0.0; }).empty());
  EXPECT_FALSE(with([](auto& p) { p.v_feed_max_mm_s = 0.0; }).empty());
  EXPECT_FALSE(with([](auto& p) { p.v_retract_max_mm_s = -1.0; }).empty());
  EXPECT_FALSE(with([](auto& p) { p.retract_speed_mm_s = 0.0; }).empty());
  EXPECT_FALSE(with([](auto& p) { p.retract_speed_mm_s = 2.5; }).empty()) << "> retract max";
  EXPECT_FALSE(with([](auto& p) { p.idle_feed_mm_s = 0.1; }).empty()) << "idle feed upward";
  EXPECT_FALSE(with([](auto& p) { p.idle_feed_mm_s = -0.6; }).empty()) << "beyond feed max";
  EXPECT_FALSE(with([](auto& p) { p.kg = kNaN; }).empty());
  EXPECT_FALSE(with([](auto& p) { p.v_feed_max_mm_s = kInf; }).empty());
}

// The integral option (ki > 0): with a constant error the command is Kg·e + ki·e·t exactly
// (t = cycles·dt), and ki = 0 is the P law.
TEST(GapControllerPIntegral, ConstantErrorRampsTheCommandAsKgEPlusKiET) {
  BlockHarness<GapControllerP> h;  // 1 ms
  GapControllerPParams p;
  p.kg = 0.05;
  p.ki = 0.02;
  p.v_feed_max_mm_s = 100.0;
  ASSERT_TRUE(h.start(p).empty());
  h.source<double>("tdr_us").set(8.0);
  h.source<double>("td_us").set(18.0);  // e = −10 µs
  for (int n = 0; n < 500; ++n) {
    ASSERT_EQ(h.step(), BlockStatus::kOk);
    // The integral is updated after the output of cycle n: n cycles of error are in it.
    EXPECT_NEAR(h.out("vz_mm_s"), 0.05 * -10.0 + 0.02 * -10.0 * 1e-3 * n, 1e-12) << n;
  }
}

// Closed loop on a ramp: the hole bottom recedes at v_b, the gap grows with the axis' upward
// speed (gap' = Vz + v_b) and Td = Tdr0 + s·(gap − g0). The P law settles with Td − Tdr = v_b/Kg
// (seed 004's steady offset); with ki > 0 the offset goes to 0.
double settled_offset_us(double ki) {
  BlockHarness<GapControllerP> h;  // 1 ms
  GapControllerPParams p;
  p.kg = 0.05;
  p.ki = ki;
  EXPECT_TRUE(h.start(p).empty());
  const double v_b = 0.5, s_us_per_mm = 500.0, dt = 1e-3;
  double gap_mm = 0.03;
  h.source<double>("tdr_us").set(8.0);
  double td = 0.0;
  for (int n = 0; n < 60000; ++n) {
    td = 8.0 + s_us_per_mm * (gap_mm - 0.03);
    h.source<double>("td_us").set(td);
    h.step();
    gap_mm += (h.out("vz_mm_s") + v_b) * dt;
  }
  return td - 8.0;
}

TEST(GapControllerPIntegral, PLawKeepsTheRampOffsetAndTheIntegralRemovesIt) {
  EXPECT_NEAR(settled_offset_us(0.0), 0.5 / 0.05, 1e-6) << "Td − Tdr = v_b/Kg";
  EXPECT_NEAR(settled_offset_us(0.05), 0.0, 1e-3);
}

// Saturated with the error pushing further: the integral does not grow, so the command leaves the
// clamp as soon as the error reverses (no wind-up).
TEST(GapControllerPIntegral, NoWindUpWhileClamped) {
  BlockHarness<GapControllerP> h;
  GapControllerPParams p;
  p.kg = 0.05;
  p.ki = 0.5;
  p.v_feed_max_mm_s = 1.0;
  ASSERT_TRUE(h.start(p).empty());
  h.source<double>("tdr_us").set(8.0);
  h.source<double>("td_us").set(100.0);  // Kg·e = −4.6 mm/s: clamped at −1
  for (int n = 0; n < 5000; ++n) h.step();
  EXPECT_EQ(h.out("vz_mm_s"), -1.0);
  h.source<double>("td_us").set(4.0);  // e = +4 µs: back off
  EXPECT_EQ(h.step(), BlockStatus::kOk);
  EXPECT_GT(h.out("vz_mm_s"), 0.0) << "the integral did not wind up while clamped";
  // Hold freezes it, activate() clears it.
  h.source<bool>("hold").set(true);
  EXPECT_EQ(h.step(), BlockStatus::kOk);
  EXPECT_EQ(h.out("vz_mm_s"), 0.0);
  h.source<bool>("hold").set(false);
  h.block().activate();
  h.source<double>("td_us").set(8.0);
  h.step();
  EXPECT_EQ(h.out("vz_mm_s"), 0.0);
}

}  // namespace
}  // namespace edm::blocks

#include "edm/blocks/wear_compensator.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>

#include "block_harness.hpp"

namespace edm::blocks {
namespace {

// Sets the gap controller's command vz_in_mm_s, then runs one cycle.
BlockStatus step(BlockHarness<WearCompensator>& h, double vz_in_mm_s) {
  h.source<double>("vz_in_mm_s").set(vz_in_mm_s);
  return h.step();
}

TEST(WearCompensatorTest, vd_equals_eq8_for_constant_feeds) {
  BlockHarness<WearCompensator> h(1ms);
  ASSERT_TRUE(h.start(WearCompensatorParams{}).empty());
  const double a_hole = std::numbers::pi / 4.0 * 1.1 * 1.1;
  const double a_e = std::numbers::pi / 4.0 * (1.0 - 0.09);
  EXPECT_NEAR(h.block().params().hole_area_mm2, 0.950332, 1e-6);
  EXPECT_NEAR(h.block().params().electrode_area_mm2, 0.714712, 1e-6);
  auto& ratio = h.source<double>("wear_ratio");
  for (const double wr : {0.1, 0.5, 1.2}) {
    for (const double vz : {-0.001, -0.02, -0.5}) {
      ratio.set(wr);
      EXPECT_EQ(step(h, vz), BlockStatus::kOk);
      // eq. 8 from its parts: MRRw = A_hole·|vz|, MRRe = wr·MRRw, Vd = MRRe / A_e.
      const double mrr_w = a_hole * -vz;
      const double vd = wr * mrr_w / a_e;
      EXPECT_NEAR(h.out("vd_mm_s"), vd, 1e-15) << wr << " " << vz;
      EXPECT_NEAR(h.out("vz_out_mm_s"), vz - vd, 1e-15);
      EXPECT_LT(h.out("vz_out_mm_s"), vz) << "more downward";
    }
  }
}

// A loaded real-time machine may omit cycles while the axis keeps its last command: the front
// moved for the whole time since the previous release, and that new depth wears the electrode.
TEST(WearCompensatorTest, omitted_cycles_still_count_as_front_progress) {
  BlockHarness<WearCompensator> h(1ms);
  ASSERT_TRUE(h.start(WearCompensatorParams{}).empty());
  h.source<double>("wear_ratio").set(0.6);
  const double vz = -0.5;
  step(h, vz);                 // cycle 0
  h.set_cycle(h.cycle() + 2);  // cycles 1 and 2 omitted
  step(h, vz);                 // cycle 3: 3 ms of feed since cycle 0
  const auto& p = h.block().params();
  const double area_ratio = p.hole_area_mm2 / p.electrode_area_mm2;
  // eq. 8 over 4 ms of new depth (1 ms before cycle 0's own step + 3 ms since).
  EXPECT_NEAR(h.out("wear_mm"), 0.6 * area_ratio * 0.5 * 4e-3, 1e-12);
  h.set_cycle(h.cycle() + 1000);  // a long gap is a pause of the block: one period
  step(h, vz);
  EXPECT_NEAR(h.out("wear_mm"), 0.6 * area_ratio * 0.5 * 5e-3, 1e-12);
}

TEST(WearCompensatorTest, no_compensation_while_retracting_holding_or_disabled) {
  BlockHarness<WearCompensator> h(1ms);
  ASSERT_TRUE(h.start(WearCompensatorParams{}).empty());
  h.source<double>("wear_ratio").set(0.5);
  auto& enable = h.source<bool>("enable");
  enable.set(true);
  for (const double vz : {0.0, 0.3, 5.0}) {
    EXPECT_EQ(step(h, vz), BlockStatus::kOk);
    EXPECT_EQ(h.out("vz_out_mm_s"), vz);
    EXPECT_EQ(h.out("vd_mm_s"), 0.0);
  }
  enable.set(false);
  EXPECT_EQ(step(h, -0.1), BlockStatus::kOk);
  EXPECT_EQ(h.out("vz_out_mm_s"), -0.1);
  EXPECT_EQ(h.out("vd_mm_s"), 0.0);
  EXPECT_EQ(h.out("wear_mm"), 0.0);
}

TEST(WearCompensatorTest, accumulated_wear_integrates_exactly) {
  // A_hole/A_e = 2, wear ratio 0.25, dt = 0.125 s: every step and partial sum is exact in binary.
  // The feed pattern goes down, further down, then back up (a retract): only depth the front has
  // never reached before is erosion (the high-water mark), so the up-stroke and the down-stroke
  // that re-covers it add no wear.
  BlockHarness<WearCompensator> h(125ms);
  ASSERT_TRUE(h.start({.hole_area_mm2 = 2.0, .electrode_area_mm2 = 1.0}).empty());
  h.source<double>("wear_ratio").set(0.25);
  double expected = 0.0;
  double front = 0.0;
  double deepest = 0.0;
  for (int n = 1; n <= 4000; ++n) {
    const double vz = n % 3 == 0 ? 0.5 : (n % 3 == 1 ? -0.5 : -0.25);  // incl. retracting cycles
    step(h, vz);
    front += vz * 0.125;
    const double new_depth = std::max(0.0, -front - deepest);
    deepest = std::max(deepest, -front);
    const double vd = 0.25 * 2.0 * new_depth / 0.125;
    ASSERT_EQ(h.out("vd_mm_s"), vd) << "n = " << n;
    expected += vd * 0.125;
    ASSERT_EQ(h.out("wear_mm"), expected) << "n = " << n;
  }
  // Net travel 4000/3 patterns × 0.03125 mm (+ the first partial pattern): wear = θ·A_h/A_e·depth.
  EXPECT_EQ(h.out("wear_mm"), 0.25 * 2.0 * deepest);
  // reset_wear zeroes it (electrode change); a value written into the pin is continued.
  auto& reset = h.source<bool>("reset_wear");
  reset.set(true);
  step(h, -0.5);
  EXPECT_EQ(h.out("wear_mm"), 0.25 * 0.125);
  reset.set(false);
  h.pin("wear_mm").as_output<double>()->set(10.0);  // retained value restored
  step(h, -0.5);
  EXPECT_EQ(h.out("wear_mm"), 10.0 + 0.25 * 0.125);
}

TEST(WearCompensatorTest, oscillation_over_eroded_depth_adds_no_wear) {
  // A servo that swings ±A about a slowly advancing mean: the wear estimate must follow the net
  // advance, not the sum of the down-strokes (which is many times larger here).
  BlockHarness<WearCompensator> h(1ms);
  ASSERT_TRUE(h.start({.hole_area_mm2 = 1.0, .electrode_area_mm2 = 1.0}).empty());
  h.source<double>("wear_ratio").set(0.5);
  double down_strokes = 0.0;
  double front = 0.0;
  for (int n = 0; n < 20000; ++n) {
    const double vz = -0.01 + 2.0 * std::sin(2.0 * 3.141592653589793 * n / 50.0);  // mm/s
    step(h, vz);
    front += vz * 1e-3;
    if (vz < 0.0) down_strokes += -vz * 1e-3;
  }
  const double net = -front;  // 0.2 mm
  EXPECT_NEAR(h.out("wear_mm"), 0.5 * net, 0.5 * 0.02 * net + 0.5 * 2.0 * 50e-3 / 3.14159);
  EXPECT_LT(h.out("wear_mm"), 0.05 * 0.5 * down_strokes);
}

TEST(WearCompensatorTest, electrode_front_keeps_up_with_the_hole_bottom) {
  // Physical model: the holder moves at vz_out, the electrode shortens by the true wear
  // (wear_ratio·A_hole·bottom feed / A_e), the bottom advances at the front feed. The gap must
  // stay constant.
  BlockHarness<WearCompensator> h(1ms);
  ASSERT_TRUE(h.start(WearCompensatorParams{}).empty());
  const auto& p = h.block().params();
  const double wr = 0.6;
  h.source<double>("wear_ratio").set(wr);
  double holder = 10.0;
  double length = 5.0;
  double bottom = holder - length - 0.01;  // 10 µm gap
  const double vz = -0.05;                 // the gap controller's command
  for (int k = 0; k < 100000; ++k) {
    step(h, vz);
    const double dt = 1e-3;
    const double front_before = holder - length;
    const double bottom_feed = vz;  // the bottom advances with the front (steady gap)
    holder += h.out("vz_out_mm_s") * dt;
    length -= wr * p.hole_area_mm2 * -bottom_feed / p.electrode_area_mm2 * dt;
    bottom += bottom_feed * dt;
    ASSERT_NEAR((holder - length) - front_before, vz * dt, 1e-12);
  }
  EXPECT_NEAR((holder - length) - bottom, 0.01, 1e-9) << "gap unchanged after 100 s";
  EXPECT_NEAR(h.out("wear_mm"), 5.0 - length, 1e-9) << "wear_mm = length consumed";
}

TEST(WearCompensatorTest, wear_ratio_is_clamped_and_non_finite_is_a_fault) {
  BlockHarness<WearCompensator> h(1ms);
  ASSERT_TRUE(
      h.start({.hole_area_mm2 = 2.0, .electrode_area_mm2 = 1.0, .wear_ratio_max = 1.0}).empty());
  auto& ratio = h.source<double>("wear_ratio");
  ratio.set(-0.5);
  EXPECT_EQ(step(h, -1.0), BlockStatus::kSaturated);
  EXPECT_EQ(h.out("vd_mm_s"), 0.0);
  ratio.set(3.0);
  EXPECT_EQ(step(h, -1.0), BlockStatus::kSaturated);
  EXPECT_EQ(h.out("vd_mm_s"), 2.0);
  ratio.set(std::numeric_limits<double>::quiet_NaN());
  EXPECT_EQ(step(h, -1.0), BlockStatus::kFault);
  EXPECT_EQ(h.out("vz_out_mm_s"), -1.0) << "uncompensated, still driven";
  EXPECT_EQ(h.out("vd_mm_s"), 0.0);
  ratio.set(0.5);
  const double wear = h.out("wear_mm");
  EXPECT_EQ(step(h, std::numeric_limits<double>::infinity()), BlockStatus::kFault);
  EXPECT_EQ(h.out("vz_out_mm_s"), 0.0) << "a broken feed command stops the axis";
  EXPECT_EQ(h.out("wear_mm"), wear);
  EXPECT_EQ(step(h, -1.0), BlockStatus::kOk);
  EXPECT_EQ(h.out("vd_mm_s"), 1.0);
}

// An input <= 0 (unwired reads 0) is "no estimate": wear_ratio_default is θ then. With the
// default 0 that is no compensation, as for an input of 0.
TEST(WearCompensatorTest, wear_ratio_default_applies_while_the_input_is_not_positive) {
  BlockHarness<WearCompensator> h(1ms);
  ASSERT_TRUE(h.start({.hole_area_mm2 = 2.0, .electrode_area_mm2 = 1.0}).empty());
  EXPECT_EQ(step(h, -1.0), BlockStatus::kOk);
  EXPECT_EQ(h.out("vd_mm_s"), 0.0) << "unwired input, default 0: no compensation";
  ASSERT_TRUE(h.write_param("wear_ratio_default", rt::ParamValue::of_real(0.25)).empty());
  EXPECT_EQ(step(h, -2.0), BlockStatus::kOk);
  // Vd = θ·(A_hole/A_e)·|vz| for a steady downward feed.
  EXPECT_NEAR(h.out("vd_mm_s"), 0.25 * 2.0 * 2.0, 1e-12) << "unwired input: the parameter's θ";
  h.source<double>("wear_ratio").set(0.5);
  EXPECT_EQ(step(h, -3.0), BlockStatus::kOk);
  EXPECT_NEAR(h.out("vd_mm_s"), 0.5 * 2.0 * 3.0, 1e-12) << "a positive input wins";
  h.source<double>("wear_ratio").set(-0.5);
  EXPECT_EQ(step(h, -4.0), BlockStatus::kSaturated) << "a negative input is out of range";
  EXPECT_NEAR(h.out("vd_mm_s"), 0.25 * 2.0 * 4.0, 1e-12);
  EXPECT_FALSE(h.write_param("wear_ratio_default", rt::ParamValue::of_real(-0.1)).empty());
  const auto errs = h.write_param("wear_ratio_default", rt::ParamValue::of_real(6.0));
  ASSERT_EQ(errs.size(), 1u) << describe(errs);
  EXPECT_EQ(errs[0].field, "wear_ratio_max") << "must be >= wear_ratio_default";
}

TEST(WearCompensatorTest, runtime_write_of_the_areas) {
  BlockHarness<WearCompensator> h(1ms);
  ASSERT_TRUE(h.start({.hole_area_mm2 = 2.0, .electrode_area_mm2 = 1.0}).empty());
  h.source<double>("wear_ratio").set(0.5);
  auto errs = h.write_param("electrode_area_mm2", rt::ParamValue::of_real(0.5));
  ASSERT_TRUE(errs.empty()) << describe(errs);
  step(h, -1.0);
  EXPECT_EQ(h.out("vd_mm_s"), 2.0);
  EXPECT_FALSE(h.write_param("hole_area_mm2", rt::ParamValue::of_real(0.0)).empty());
}

// The active condition's A_hole/A_e (EdmJob wires it) replaces the area parameters while > 0, so
// eq. 8 and the HMI's eq. 10 use one ratio; unwired (0) or negative: the parameters' ratio.
TEST(WearCompensatorTest, area_ratio_input_replaces_the_area_parameters_while_positive) {
  BlockHarness<WearCompensator> h(1ms);
  ASSERT_TRUE(h.start({.hole_area_mm2 = 2.0, .electrode_area_mm2 = 1.0}).empty());
  h.source<double>("wear_ratio").set(0.5);
  auto& areas = h.source<double>("area_ratio");
  EXPECT_EQ(step(h, -1.0), BlockStatus::kOk);
  EXPECT_NEAR(h.out("vd_mm_s"), 0.5 * 2.0 * 1.0, 1e-12) << "unwired: the parameters' 2.0";
  areas.set(1.3297);
  EXPECT_EQ(step(h, -2.0), BlockStatus::kOk);
  EXPECT_NEAR(h.out("vd_mm_s"), 0.5 * 1.3297 * 2.0, 1e-12) << "the condition's ratio";
  areas.set(-1.0);
  EXPECT_EQ(step(h, -3.0), BlockStatus::kOk);
  EXPECT_NEAR(h.out("vd_mm_s"), 0.5 * 2.0 * 3.0, 1e-12) << "not positive: the parameters'";
  areas.set(std::numeric_limits<double>::quiet_NaN());
  EXPECT_EQ(step(h, -4.0), BlockStatus::kFault) << "a broken ratio is reported";
  EXPECT_NEAR(h.out("vd_mm_s"), 0.5 * 2.0 * 4.0, 1e-12) << "and the parameters' ratio used";
}

TEST(WearCompensatorTest, validate_refuses_bad_parameters) {
  EXPECT_TRUE(rt::validate_params(WearCompensatorParams{}).empty());
  EXPECT_FALSE(rt::validate_params(WearCompensatorParams{.hole_area_mm2 = -1.0}).empty());
  EXPECT_FALSE(
      rt::validate_params(
          WearCompensatorParams{.electrode_area_mm2 = std::numeric_limits<double>::infinity()})
          .empty());
  EXPECT_FALSE(rt::validate_params(WearCompensatorParams{.wear_ratio_default = -0.1}).empty());
  EXPECT_FALSE(
      rt::validate_params(WearCompensatorParams{.wear_ratio_max = 1.0, .wear_ratio_default = 1.5})
          .empty());
  EXPECT_TRUE(
      rt::validate_params(WearCompensatorParams{.wear_ratio_max = 1.0, .wear_ratio_default = 1.0})
          .empty());
  BlockHarness<WearCompensator> no_task(rt::Duration{0});
  EXPECT_FALSE(no_task.start().empty());
}

}  // namespace
}  // namespace edm::blocks

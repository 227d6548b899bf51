// Select: IEC SEL with a bumpless (ramped) transfer.

#include "edm/blocks/select.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <random>

#include "block_harness.hpp"

namespace edm::blocks {
namespace {

TEST(SelectTest, selects_in1_when_g_or_the_select_parameter_is_true) {
  BlockHarness<Select> h(1ms);
  ASSERT_TRUE(h.start({}).empty());
  auto& g = h.source<bool>("g");
  h.source<double>("in0").set(3.0);
  h.source<double>("in1").set(-7.5);
  EXPECT_EQ(h.step(), BlockStatus::kOk);
  EXPECT_EQ(h.out(), 3.0);
  EXPECT_TRUE(h.out<bool>("active0"));
  EXPECT_FALSE(h.out<bool>("active1"));
  g.set(true);
  h.step();
  EXPECT_EQ(h.out(), -7.5) << "ramp_time 0 switches at once";
  EXPECT_TRUE(h.out<bool>("active1"));
  EXPECT_FALSE(h.out<bool>("transferring"));
  g.set(false);
  h.step();
  EXPECT_EQ(h.out(), 3.0);
  // The operator's parameter, written at run time, selects in1 too (OR with g).
  ASSERT_TRUE(h.write_param("select", rt::ParamValue::of_bool(true)).empty());
  h.step();
  EXPECT_EQ(h.out(), -7.5);
  EXPECT_FALSE(h.out<bool>("active0"));
}

// Blocks ahead in the program and readers in another task may run before the first update:
// activate() already gives them the input g OR select picks, never 0.
TEST(SelectTest, activate_outputs_the_input_g_or_the_select_parameter_picks) {
  for (const bool select : {false, true}) {
    for (const bool g : {false, true}) {
      BlockHarness<Select> h(1ms);
      SelectParams p;
      p.select = select;
      ASSERT_TRUE(h.start(p).empty());
      h.source<bool>("g").set(g);
      h.source<double>("in0").set(3.0);
      h.source<double>("in1").set(-7.5);
      h.block().activate();
      const bool s = g || select;
      EXPECT_EQ(h.out(), s ? -7.5 : 3.0) << "select " << select << ", g " << g;
      EXPECT_EQ(h.out<bool>("active1"), s);
      EXPECT_EQ(h.out<bool>("active0"), !s);
    }
  }
}

// With a ramp, the switch makes no step: the bump b = out(k−1) − src(k) decays linearly to 0
// over ramp_time while the selected source moves on (here a random walk).
TEST(SelectTest, ramped_transfer_starts_at_the_previous_output_and_decays_linearly) {
  constexpr int kRampCycles = 40;
  BlockHarness<Select> h(1ms);
  SelectParams p;
  p.ramp_time = 40ms;
  ASSERT_TRUE(h.start(p).empty());
  auto& g = h.source<bool>("g");
  auto& in0 = h.source<double>("in0");
  auto& in1 = h.source<double>("in1");
  std::mt19937_64 rng(7);
  std::normal_distribution<double> walk(0.0, 0.3);
  double x0 = 10.0, x1 = 50.0;
  for (int k = 0; k < 5; ++k) {
    in0.set(x0 += walk(rng));
    in1.set(x1 += walk(rng));
    h.step();
  }
  const double before = h.out();
  EXPECT_EQ(before, x0);
  g.set(true);
  in1.set(x1 += walk(rng));
  h.step();
  EXPECT_DOUBLE_EQ(h.out(), before) << "no step at the switch";
  const double bump = before - x1;
  EXPECT_TRUE(h.out<bool>("transferring"));
  for (int n = 1; n <= kRampCycles + 5; ++n) {
    in1.set(x1 += walk(rng));
    h.step();
    const double w = std::max(0.0, 1.0 - static_cast<double>(n) / kRampCycles);
    EXPECT_NEAR(h.out(), x1 + bump * w, 1e-9) << "n = " << n;
    EXPECT_EQ(h.out<bool>("transferring"), w > 0.0) << "n = " << n;
  }
}

TEST(SelectTest, a_switch_back_during_a_ramp_starts_from_the_current_output) {
  BlockHarness<Select> h(1ms);
  SelectParams p;
  p.ramp_time = 10ms;
  ASSERT_TRUE(h.start(p).empty());
  auto& g = h.source<bool>("g");
  h.source<double>("in0").set(0.0);
  h.source<double>("in1").set(100.0);
  h.step();
  g.set(true);
  h.step();  // out = 0, bump −100
  for (int k = 0; k < 4; ++k) h.step();
  const double mid = h.out();
  EXPECT_NEAR(mid, 40.0, 1e-9);  // 100 − 100·(1 − 4/10)
  g.set(false);
  h.step();
  EXPECT_NEAR(h.out(), mid, 1e-9) << "no step at the second switch either";
  for (int k = 0; k < 10; ++k) h.step();
  EXPECT_EQ(h.out(), 0.0);
}

TEST(SelectTest, rejects_a_negative_ramp_and_faults_on_a_non_finite_selected_input) {
  BlockHarness<Select> h(1ms);
  SelectParams bad;
  bad.ramp_time = -1ms;
  EXPECT_FALSE(h.start(bad).empty());
  BlockHarness<Select> h2(1ms);
  ASSERT_TRUE(h2.start({}).empty());
  auto& in0 = h2.source<double>("in0");
  auto& in1 = h2.source<double>("in1");
  in0.set(1.0);
  in1.set(std::numeric_limits<double>::quiet_NaN());
  EXPECT_EQ(h2.step(), BlockStatus::kOk) << "the unselected input may be anything";
  in0.set(std::numeric_limits<double>::infinity());
  EXPECT_EQ(h2.step(), BlockStatus::kFault);
  EXPECT_EQ(h2.out(), 1.0) << "outputs held";
}

}  // namespace
}  // namespace edm::blocks

// JumpCycle: the periodic electrode jump of die sinking, and the cycle edges seed 002's ILC needs.

#include "edm/blocks/jump_cycle.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "block_harness.hpp"

namespace edm::blocks {
namespace {

JumpCycleParams small() {
  JumpCycleParams p;
  p.period = 100ms;
  p.up_time = 4ms;
  p.down_time = 5ms;
  p.up_speed_mm_s = 30.0;
  p.down_speed_mm_s = 20.0;
  return p;
}

// The schedule of the header, written out: the k-th update (k = 1, 2, …) starts a jump when k is
// a multiple of the period (100 cycles); 4 cycles up, 5 down, the servo otherwise.
TEST(JumpCycleTest, jumps_every_period_up_then_down_then_passes_the_servo) {
  BlockHarness<JumpCycle> h(1ms);
  ASSERT_TRUE(h.start(small()).empty());
  h.source<double>("vz_in_mm_s").set(-0.2);
  int starts = 0;
  for (int k = 1; k <= 350; ++k) {
    ASSERT_EQ(h.step(), BlockStatus::kOk);
    const int since = k >= 100 ? (k - 100) % 100 : -1;  // cycles since the last jump's start
    const bool up = since >= 0 && since < 4;
    const bool down = since >= 4 && since < 9;
    const double want = up ? 30.0 : down ? -20.0 : -0.2;
    ASSERT_EQ(h.out<double>("vz_out_mm_s"), want) << "cycle " << k;
    ASSERT_EQ(h.out<bool>("jumping"), up || down) << "cycle " << k;
    ASSERT_EQ(h.out<bool>("cycle_start"), since == 0) << "cycle " << k;
    starts += since == 0 ? 1 : 0;
    ASSERT_EQ(h.out<std::int64_t>("jumps"), starts);
  }
  EXPECT_EQ(starts, 3);
}

// settling = jumping, then S = settle_time cycles more (the approach); 0 → settling = jumping.
// A safe state ends it at once.
TEST(JumpCycleTest, settling_covers_the_jump_and_the_approach_after_it) {
  for (const int settle : {0, 20}) {
    SCOPED_TRACE(settle);
    JumpCycleParams p = small();
    p.settle_time = std::chrono::milliseconds(settle);
    BlockHarness<JumpCycle> h(1ms);
    ASSERT_TRUE(h.start(p).empty());
    for (int k = 1; k <= 250; ++k) {
      ASSERT_EQ(h.step(), BlockStatus::kOk);
      const int since = k >= 100 ? (k - 100) % 100 : -1;
      const bool jumping = since >= 0 && since < 9;
      ASSERT_EQ(h.out<bool>("jumping"), jumping) << "cycle " << k;
      ASSERT_EQ(h.out<bool>("settling"), since >= 0 && since < 9 + settle) << "cycle " << k;
      ASSERT_EQ(h.out<bool>("servo_part"), !h.out<bool>("settling")) << "cycle " << k;
    }
    // Inside the approach of the third jump (k = 300 starts it; 300 + 9 + 5 is mid-approach):
    for (int k = 251; k <= 314; ++k) h.step();
    EXPECT_EQ(h.out<bool>("settling"), settle > 0);
    h.block().enter_safe_state({rt::MachineState::kFault, rt::AlarmCode::kNone});
    EXPECT_FALSE(h.out<bool>("settling"));
    EXPECT_TRUE(h.out<bool>("servo_part"));
  }
}

TEST(JumpCycleTest, z_hold_follows_z_and_holds_the_jump_start_through_the_jump) {
  BlockHarness<JumpCycle> h(1ms);
  ASSERT_TRUE(h.start(small()).empty());
  auto& z = h.source<double>("z_mm");
  double z_at_start = std::numeric_limits<double>::quiet_NaN();
  for (int k = 1; k <= 230; ++k) {
    z.set(0.5 - 0.001 * k);
    h.step();
    if (h.out<bool>("cycle_start")) z_at_start = z.get();
    if (h.out<bool>("jumping")) {
      ASSERT_EQ(h.out<double>("z_hold_mm"), z_at_start) << "cycle " << k;
    } else {
      ASSERT_EQ(h.out<double>("z_hold_mm"), z.get()) << "cycle " << k;
    }
  }
  EXPECT_FALSE(std::isnan(z_at_start));
}

TEST(JumpCycleTest, disabled_it_starts_no_jump_and_re_enabled_waits_a_whole_period) {
  BlockHarness<JumpCycle> h(1ms);
  ASSERT_TRUE(h.start(small()).empty());
  auto& enable = h.source<bool>("enable");
  enable.set(false);
  for (int k = 0; k < 250; ++k) {
    h.step();
    ASSERT_FALSE(h.out<bool>("jumping"));
  }
  enable.set(true);
  for (int k = 1; k <= 100; ++k) {
    h.step();
    ASSERT_EQ(h.out<bool>("cycle_start"), k == 100) << "cycle " << k << " after enabling";
  }
  enable.set(false);  // a running jump finishes
  for (int k = 0; k < 8; ++k) {
    h.step();
    EXPECT_TRUE(h.out<bool>("jumping"));
  }
  h.step();
  EXPECT_FALSE(h.out<bool>("jumping"));
}

TEST(JumpCycleTest, a_safe_state_aborts_the_jump_and_restarts_the_period_after_it) {
  BlockHarness<JumpCycle> h(1ms);
  ASSERT_TRUE(h.start(small()).empty());
  h.source<double>("vz_in_mm_s").set(-0.1);
  for (int k = 0; k < 101; ++k) h.step();
  ASSERT_TRUE(h.out<bool>("jumping"));
  h.block().enter_safe_state({rt::MachineState::kFault, rt::AlarmCode::kNone});
  EXPECT_EQ(h.out<double>("vz_out_mm_s"), 0.0);
  EXPECT_FALSE(h.out<bool>("jumping"));
  rt::CycleContext fault;
  fault.period = 1ms;
  fault.dt_s = 0.001;
  fault.state = rt::MachineState::kFault;
  for (int k = 0; k < 300; ++k) {
    EXPECT_EQ(h.block().update(fault), BlockStatus::kOk);
    ASSERT_FALSE(h.out<bool>("jumping")) << "no jump in a safe state";
    ASSERT_EQ(h.out<double>("vz_out_mm_s"), -0.1);
  }
  for (int k = 1; k <= 100; ++k) {
    h.step();
    ASSERT_EQ(h.out<bool>("cycle_start"), k == 100) << "cycle " << k << " after the safe state";
  }
}

TEST(JumpCycleTest, a_broken_servo_signal_stops_the_axis_but_not_a_running_jump) {
  BlockHarness<JumpCycle> h(1ms);
  ASSERT_TRUE(h.start(small()).empty());
  auto& v = h.source<double>("vz_in_mm_s");
  v.set(std::numeric_limits<double>::quiet_NaN());
  EXPECT_EQ(h.step(), BlockStatus::kFault);
  EXPECT_EQ(h.out<double>("vz_out_mm_s"), 0.0);
  for (int k = 2; k < 100; ++k) h.step();
  EXPECT_EQ(h.step(), BlockStatus::kOk) << "the jump does not read the servo";
  EXPECT_EQ(h.out<double>("vz_out_mm_s"), 30.0);
  h.source<double>("z_mm").set(std::numeric_limits<double>::infinity());
  const double held = h.out<double>("z_hold_mm");
  EXPECT_EQ(h.step(), BlockStatus::kFault);
  EXPECT_EQ(h.out<double>("z_hold_mm"), held);
}

TEST(JumpCycleTest, bad_parameters_are_refused) {
  auto p = small();
  p.period = 9ms;  // = up + down: no time for the servo
  EXPECT_FALSE(rt::validate_params(p).empty());
  p = small();
  p.up_time = 0ms;
  EXPECT_FALSE(rt::validate_params(p).empty());
  p = small();
  p.down_speed_mm_s = 0.0;
  EXPECT_FALSE(rt::validate_params(p).empty());
  p = small();
  p.up_speed_mm_s = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(rt::validate_params(p).empty());
  p = small();
  p.settle_time = -1ms;
  EXPECT_FALSE(rt::validate_params(p).empty());
  p = small();
  p.settle_time = 91ms;  // up + down + settle = period: no time for the servo
  EXPECT_FALSE(rt::validate_params(p).empty());
  p.settle_time = 90ms;
  EXPECT_TRUE(rt::validate_params(p).empty());
  EXPECT_TRUE(rt::validate_params(small()).empty());
}

}  // namespace
}  // namespace edm::blocks

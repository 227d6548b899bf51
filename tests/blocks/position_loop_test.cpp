#include "edm/blocks/position_loop.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>

#include "block_harness.hpp"

namespace edm::blocks {
namespace {

// A position loop closed over a simulated axis that integrates the velocity command:
// x ← x + v_cmd·dt (+ an optional velocity disturbance).
struct Loop {
  explicit Loop(const PositionLoopParams& p) { h.start_ok(p); }
  BlockStatus step(double disturbance_mm_s = 0.0) {
    x_mm.set(x);
    const BlockStatus s = h.step();
    x += (h.out("v_cmd_mm_s") + disturbance_mm_s) * h.dt_s();
    return s;
  }
  BlockHarness<PositionLoop> h{1ms};
  rt::Output<double>& x_ref = h.source<double>("x_ref_mm");
  rt::Output<double>& v_ff = h.source<double>("v_ff_mm_s");
  rt::Output<double>& x_mm = h.source<double>("x_mm");
  rt::Output<bool>& reset = h.source<bool>("reset");
  rt::Output<bool>& enable = h.source<bool>("enable");
  double x{0.0};
};

PositionLoopParams p_loop() {
  return {.kv = 50.0,
          .ki = 0.0,
          .kff = 1.0,
          .v_max_mm_s = 1000.0,
          .f_err_max_mm = 1.0,
          .in_pos_tol_mm = 0.001,
          .in_pos_cycles = 3};
}

TEST(PositionLoopTest, p_step_follows_the_first_order_response) {
  Loop l(p_loop());
  l.enable.set(true);
  l.x_ref.set(0.5);
  const double a = 1.0 - 50.0 * 1e-3;  // 1 − kv·dt
  for (int k = 0; k < 400; ++k) {
    ASSERT_EQ(l.step(), BlockStatus::kOk) << "k = " << k;
    ASSERT_NEAR(l.h.out("error_mm"), 0.5 * std::pow(a, k), 1e-12) << "k = " << k;
    ASSERT_NEAR(l.h.out("v_cmd_mm_s"), 50.0 * 0.5 * std::pow(a, k), 1e-9) << "k = " << k;
  }
}

TEST(PositionLoopTest, feed_forward_tracks_a_ramp_with_zero_steady_error) {
  for (const double kff : {1.0, 0.0}) {
    auto p = p_loop();
    p.kff = kff;
    Loop l(p);
    l.enable.set(true);
    l.x = -0.05;  // start 0.05 mm behind
    const double v = 10.0;
    l.v_ff.set(v);
    for (int k = 0; k < 2000; ++k) {
      l.x_ref.set(v * k * 1e-3);
      ASSERT_NE(l.step(), BlockStatus::kFault);
    }
    if (kff == 1.0) {
      EXPECT_NEAR(l.h.out("error_mm"), 0.0, 1e-12) << "feed-forward: no lag";
    } else {
      EXPECT_NEAR(l.h.out("error_mm"), v / 50.0, 1e-9) << "P only: the classic lag v/kv";
    }
  }
}

TEST(PositionLoopTest, pi_removes_the_error_of_a_constant_disturbance) {
  auto p = p_loop();
  p.ki = 400.0;  // s² + 50 s + 400: real poles at −10 and −40
  Loop l(p);
  l.enable.set(true);
  l.x_ref.set(0.2);
  for (int k = 0; k < 5000; ++k) {
    ASSERT_NE(l.step(-2.0), BlockStatus::kFault);
  }
  EXPECT_NEAR(l.h.out("error_mm"), 0.0, 1e-9);
  EXPECT_NEAR(l.h.out("v_cmd_mm_s"), 2.0, 1e-6) << "the integral cancels the disturbance";
}

TEST(PositionLoopTest, clamps_at_v_max_without_windup) {
  auto p = p_loop();
  p.ki = 100.0;
  p.v_max_mm_s = 2.0;
  Loop l(p);
  l.enable.set(true);
  l.x_ref.set(0.5);  // kv·e = 25 mm/s > v_max
  for (int k = 0; k < 1000; ++k) {
    l.x_mm.set(0.0);  // blocked axis: the error stays
    ASSERT_EQ(l.h.step(), BlockStatus::kSaturated);
    ASSERT_EQ(l.h.out("v_cmd_mm_s"), 2.0);
    ASSERT_TRUE(l.h.out<bool>("saturated"));
  }
  // With windup the integral would be 0.5 mm·s and v = ki·0.5 = 50 mm/s here.
  l.x_ref.set(0.0);
  EXPECT_EQ(l.h.step(), BlockStatus::kOk);
  EXPECT_EQ(l.h.out("v_cmd_mm_s"), 0.0);
  EXPECT_FALSE(l.h.out<bool>("saturated"));
  l.x_ref.set(-0.5);
  EXPECT_EQ(l.h.step(), BlockStatus::kSaturated);
  EXPECT_EQ(l.h.out("v_cmd_mm_s"), -2.0);
}

TEST(PositionLoopTest, following_error_fault_latches_until_reset) {
  Loop l(p_loop());
  l.enable.set(true);
  l.x_ref.set(0.9);
  EXPECT_EQ(l.step(), BlockStatus::kOk);
  EXPECT_FALSE(l.h.out<bool>("following_error_fault"));
  l.x_ref.set(1.5);  // beyond f_err_max = 1 mm
  EXPECT_EQ(l.step(), BlockStatus::kFault);
  EXPECT_TRUE(l.h.out<bool>("following_error_fault"));
  EXPECT_EQ(l.h.out("v_cmd_mm_s"), 0.0) << "the axis is stopped";
  l.x_ref.set(l.x);  // the error is gone, the latch stays
  for (int k = 0; k < 10; ++k) {
    EXPECT_EQ(l.step(), BlockStatus::kFault);
    EXPECT_TRUE(l.h.out<bool>("following_error_fault"));
    EXPECT_EQ(l.h.out("v_cmd_mm_s"), 0.0);
  }
  l.x_ref.set(l.x + 2.0);  // reset while still beyond the limit: latches again
  l.reset.set(true);
  EXPECT_EQ(l.step(), BlockStatus::kFault);
  l.x_ref.set(l.x + 0.1);
  EXPECT_EQ(l.step(), BlockStatus::kOk);
  EXPECT_FALSE(l.h.out<bool>("following_error_fault"));
  l.reset.set(false);
  EXPECT_EQ(l.step(), BlockStatus::kOk);
  EXPECT_GT(l.h.out("v_cmd_mm_s"), 0.0);
}

TEST(PositionLoopTest, no_following_error_check_while_disabled) {
  Loop l(p_loop());
  l.enable.set(false);
  l.x_ref.set(5.0);
  EXPECT_EQ(l.step(), BlockStatus::kOk);
  EXPECT_EQ(l.h.out("v_cmd_mm_s"), 0.0);
  EXPECT_EQ(l.h.out("error_mm"), 5.0);
  EXPECT_FALSE(l.h.out<bool>("following_error_fault"));
  l.enable.set(true);
  EXPECT_EQ(l.step(), BlockStatus::kFault);
}

TEST(PositionLoopTest, in_position_after_in_pos_cycles_in_the_window) {
  Loop l(p_loop());  // tol 0.001 mm, 3 cycles
  l.enable.set(true);
  auto at = [&](double e) {
    l.x_ref.set(e);
    l.x_mm.set(0.0);
    l.h.step();
    return l.h.out<bool>("in_position");
  };
  EXPECT_FALSE(at(0.0005));
  EXPECT_FALSE(at(-0.001));
  EXPECT_TRUE(at(0.0)) << "third cycle in the window";
  EXPECT_TRUE(at(0.0009));
  EXPECT_FALSE(at(0.0011)) << "out of the window: at once";
  EXPECT_FALSE(at(0.0));
  EXPECT_FALSE(at(0.0));
  EXPECT_TRUE(at(0.0));
}

TEST(PositionLoopTest, non_finite_input_stops_the_axis) {
  Loop l(p_loop());
  l.enable.set(true);
  l.x_ref.set(0.5);
  l.step();
  l.x_mm.set(std::numeric_limits<double>::quiet_NaN());
  EXPECT_EQ(l.h.step(), BlockStatus::kFault);
  EXPECT_EQ(l.h.out("v_cmd_mm_s"), 0.0);
  EXPECT_EQ(l.h.out("error_mm"), 0.5) << "held";
  EXPECT_FALSE(l.h.out<bool>("in_position"));
  l.x_ref.set(std::numeric_limits<double>::infinity());
  l.x_mm.set(0.0);
  EXPECT_EQ(l.h.step(), BlockStatus::kFault);
  l.x_ref.set(0.5);
  EXPECT_EQ(l.h.step(), BlockStatus::kOk);
  EXPECT_EQ(l.h.out("v_cmd_mm_s"), 25.0);
}

TEST(PositionLoopTest, validate_refuses_bad_parameters) {
  EXPECT_TRUE(rt::validate_params(PositionLoopParams{}).empty());
  EXPECT_FALSE(rt::validate_params(PositionLoopParams{.kff = 1.6}).empty());
  EXPECT_FALSE(rt::validate_params(PositionLoopParams{.kv = -1.0}).empty());
  EXPECT_FALSE(rt::validate_params(PositionLoopParams{.v_max_mm_s = 0.0}).empty());
  EXPECT_FALSE(rt::validate_params(
                   PositionLoopParams{.f_err_max_mm = std::numeric_limits<double>::quiet_NaN()})
                   .empty());
  EXPECT_FALSE(rt::validate_params(PositionLoopParams{.in_pos_cycles = 0}).empty());
  BlockHarness<PositionLoop> no_task(rt::Duration{0});
  EXPECT_FALSE(no_task.start().empty());
}

}  // namespace
}  // namespace edm::blocks

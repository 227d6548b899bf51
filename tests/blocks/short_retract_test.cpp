#include "edm/blocks/short_retract.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>

#include "block_harness.hpp"

namespace edm::blocks {
namespace {

using State = ShortRetract::State;

ShortRetractParams test_params() {
  return {.history_capacity = 256,
          .min_spacing_mm = 0.0,
          .short_cycles = 3,
          .retract_distance_mm = 0.5,
          .retract_speed_mm_s = 10.0,  // 0.01 mm per 1 ms cycle
          .resume_speed_mm_s = 5.0,    // 0.005 mm per cycle
          .resume_ramp_ms = 20.0,
          .max_tries = 2,
          .progress_mm = 0.05};
}

struct RetractRig {
  explicit RetractRig(const ShortRetractParams& p) { EXPECT_TRUE(h.start(p).empty()); }
  BlockStatus step(double x, double y, double z, bool short_now = false) {
    xs.set(x);
    ys.set(y);
    zs.set(z);
    shorted.set(short_now);
    return h.step();
  }
  BlockStatus step(const std::array<double, 3>& q, bool short_now = false) {
    return step(q[0], q[1], q[2], short_now);
  }
  [[nodiscard]] std::array<double, 3> sp() const {
    return {h.out("x_sp_mm"), h.out("y_sp_mm"), h.out("z_sp_mm")};
  }
  [[nodiscard]] bool active() const { return h.out<bool>("active"); }
  BlockHarness<ShortRetract> h{1ms};
  rt::Output<double>& xs = h.source<double>("x_mm");
  rt::Output<double>& ys = h.source<double>("y_mm");
  rt::Output<double>& zs = h.source<double>("z_mm");
  rt::Output<bool>& shorted = h.source<bool>("short_detected");
  rt::Output<bool>& reset = h.source<bool>("reset");
};

// An L-shaped path: 0.3 mm along +X, then 0.4 mm down in Z; s is the distance along it.
std::array<double, 3> l_path(double s) {
  return s <= 0.3 ? std::array<double, 3>{s, 0.0, 0.0}
                  : std::array<double, 3>{0.3, 0.0, -(s - 0.3)};
}

void drive_l_path(RetractRig& r) {
  for (int k = 0; k <= 70; ++k) {
    ASSERT_EQ(r.step(l_path(0.01 * k)), BlockStatus::kOk);
    ASSERT_FALSE(r.active());
    ASSERT_EQ(r.sp(), l_path(0.01 * k)) << "pass-through while idle";
  }
}

void expect_on_path(const std::array<double, 3>& got, double s, int k) {
  const auto want = l_path(s);
  for (std::size_t i = 0; i < 3; ++i) {
    ASSERT_NEAR(got[i], want[i], 1e-12) << "k = " << k << " axis " << i << " s = " << s;
  }
}

TEST(ShortRetractTest, retract_walks_back_along_the_path_and_resumes_to_the_start_point) {
  auto p = test_params();
  p.retract_distance_mm = 0.495;  // not a whole number of steps: the last one is cut
  p.resume_speed_mm_s = 4.0;      // 0.004 mm per cycle, 123.75 steps
  RetractRig r(p);
  drive_l_path(r);
  const auto head = l_path(0.7);
  EXPECT_EQ(r.step(head, true), BlockStatus::kOk);
  EXPECT_EQ(r.step(head, true), BlockStatus::kOk);
  EXPECT_FALSE(r.active()) << "two short cycles are not sustained";
  // Third short cycle: the retract starts and takes its first step at once.
  EXPECT_EQ(r.step(head, true), BlockStatus::kOk);
  EXPECT_TRUE(r.active());
  EXPECT_EQ(r.h.out<std::int64_t>("tries"), 1);
  expect_on_path(r.sp(), 0.69, 1);
  // 0.495 mm back at 0.01 mm per cycle: around the corner, the last step cut to s = 0.205.
  for (int k = 2; k <= 50; ++k) {
    ASSERT_EQ(r.step(9.0, 9.0, 9.0), BlockStatus::kOk) << "inputs are not read while active";
    ASSERT_TRUE(r.active());
    ASSERT_EQ(r.h.out("v_scale"), 0.0);
    expect_on_path(r.sp(), std::max(0.7 - 0.01 * k, 0.205), k);
  }
  EXPECT_EQ(r.h.block().state(), State::kResume);
  // Forward again at 0.004 mm per cycle to the point where the short was confirmed.
  for (int k = 1; k < 124; ++k) {
    ASSERT_EQ(r.step(9.0, 9.0, 9.0), BlockStatus::kOk);
    ASSERT_TRUE(r.active()) << "k = " << k;
    ASSERT_EQ(r.h.out("v_scale"), 0.0);
    expect_on_path(r.sp(), 0.205 + 0.004 * k, k);
  }
  EXPECT_EQ(r.step(head), BlockStatus::kOk);
  EXPECT_FALSE(r.active()) << "control handed back";
  EXPECT_EQ(r.sp(), head) << "exactly at the start point";
  EXPECT_EQ(r.h.out("v_scale"), 0.0);
}

TEST(ShortRetractTest, reacceleration_reaches_full_feed_within_resume_ramp) {
  for (const double ramp_ms : {0.0, 0.5, 20.0, 37.5}) {
    auto p = test_params();
    p.resume_ramp_ms = ramp_ms;
    p.retract_distance_mm = 0.05;
    RetractRig r(p);
    drive_l_path(r);
    for (int k = 0; k < 3; ++k) {
      r.step(l_path(0.7), true);
    }
    ASSERT_TRUE(r.active());
    int guard = 0;
    while (r.active() && ++guard < 1000) {
      r.step(l_path(0.7));
    }
    ASSERT_FALSE(r.active());
    // Cycles after hand-back until v_scale = 1; the ramp is monotone and bounded.
    int cycles = 0;
    double last = r.h.out("v_scale");
    while (r.h.out("v_scale") < 1.0 && cycles < 1000) {
      r.step(l_path(0.7));
      ++cycles;
      ASSERT_GE(r.h.out("v_scale"), last);
      ASSERT_LE(r.h.out("v_scale"), 1.0);
      last = r.h.out("v_scale");
    }
    EXPECT_LE(cycles * 1.0, ramp_ms) << "full feed within resume_ramp_ms = " << ramp_ms;
    EXPECT_GE(cycles * 1.0, std::floor(ramp_ms)) << "and not a step";
    EXPECT_EQ(r.h.block().state(), State::kIdle);
  }
}

TEST(ShortRetractTest, max_tries_without_progress_raise_alarm_and_hold) {
  auto p = test_params();
  p.retract_distance_mm = 0.05;
  RetractRig r(p);
  drive_l_path(r);
  const auto head = l_path(0.7);
  // The short never clears: retract, and a sustained short while walking forward retracts again.
  std::int64_t max_seen = 0;
  int k = 0;
  for (; k < 2000; ++k) {
    const BlockStatus s = r.step(head, true);
    max_seen = std::max(max_seen, r.h.out<std::int64_t>("tries"));
    if (r.h.out<bool>("alarm")) {
      EXPECT_EQ(s, BlockStatus::kFault) << "from the alarm cycle on";
      break;
    }
    ASSERT_EQ(s, BlockStatus::kOk) << k;
  }
  EXPECT_TRUE(r.h.out<bool>("alarm"));
  EXPECT_EQ(max_seen, 2);
  EXPECT_EQ(r.h.out<std::int64_t>("tries"), 2);
  // The last retract runs, then the block holds.
  for (int n = 0; n < 100; ++n) {
    ASSERT_EQ(r.step(head, true), BlockStatus::kFault);
    ASSERT_TRUE(r.h.out<bool>("hold"));
    ASSERT_TRUE(r.active());
  }
  EXPECT_EQ(r.h.block().state(), State::kHold);
  const auto held = r.sp();
  EXPECT_EQ(r.step(head, true), BlockStatus::kFault);
  EXPECT_EQ(r.sp(), held);
  EXPECT_GT(held[2], head[2]) << "backed off along the path";
  // reset: alarm and tries cleared, walk forward to the start point, hand back.
  r.reset.set(true);
  EXPECT_EQ(r.step(head), BlockStatus::kOk);
  r.reset.set(false);
  EXPECT_FALSE(r.h.out<bool>("alarm"));
  EXPECT_FALSE(r.h.out<bool>("hold"));
  EXPECT_EQ(r.h.out<std::int64_t>("tries"), 0);
  for (int n = 0; n < 1000 && r.active(); ++n) {
    ASSERT_EQ(r.step(head), BlockStatus::kOk);
  }
  EXPECT_EQ(r.sp(), head);
}

TEST(ShortRetractTest, progress_along_the_path_resets_tries) {
  auto p = test_params();
  p.retract_distance_mm = 0.02;
  p.resume_ramp_ms = 0.0;
  RetractRig r(p);
  drive_l_path(r);
  auto short_and_recover = [&](double s) {
    for (int k = 0; k < 3; ++k) {
      r.step(l_path(s), true);
    }
    for (int n = 0; n < 1000 && r.active(); ++n) {
      r.step(l_path(s));
    }
  };
  short_and_recover(0.7);
  short_and_recover(0.7);
  EXPECT_EQ(r.h.out<std::int64_t>("tries"), 2);
  r.step(l_path(0.74));  // 0.04 mm: not yet progress
  EXPECT_EQ(r.h.out<std::int64_t>("tries"), 2);
  r.step(l_path(0.76));
  EXPECT_EQ(r.h.out<std::int64_t>("tries"), 0) << "0.06 mm past the last short";
  short_and_recover(0.76);
  EXPECT_EQ(r.h.out<std::int64_t>("tries"), 1);
  EXPECT_FALSE(r.h.out<bool>("alarm"));
}

TEST(ShortRetractTest, history_is_bounded_and_the_retract_stops_at_its_oldest_point) {
  auto p = test_params();
  p.history_capacity = 8;
  RetractRig r(p);
  for (int k = 0; k < 20; ++k) {
    r.step(0.01 * k, 0.0, 0.0);
    ASSERT_LE(r.h.block().history_size(), 8u);
  }
  EXPECT_EQ(r.h.block().history_size(), 8u);
  for (int k = 0; k < 3; ++k) {
    r.step(0.19, 0.0, 0.0, true);
  }
  int n = 0;
  while (r.h.block().state() == State::kRetract && ++n < 1000) {
    r.step(0.19, 0.0, 0.0);
  }
  // Points x = 0.12 … 0.19 are kept: the retract ends 0.07 mm back, not 0.5 mm.
  EXPECT_NEAR(r.h.out("x_sp_mm"), 0.12, 1e-12);
  EXPECT_GE(n, 6) << "7 steps of 0.01 mm, the first in the confirming cycle";
  EXPECT_LE(n, 7) << "(one more if rounding leaves the 7th a hair short)";
  EXPECT_EQ(r.h.block().state(), State::kResume);
}

TEST(ShortRetractTest, a_servo_back_off_unwinds_the_recorded_path) {
  RetractRig r(test_params());
  auto z_at = [&](int k) { r.step(0.0, 0.0, -0.01 * k); };
  for (int k = 0; k <= 20; ++k) {
    z_at(k);  // down to −0.20
  }
  for (int k = 19; k >= 10; --k) {
    z_at(k);  // the gap servo backs off to −0.10
  }
  for (int k = 11; k <= 15; ++k) {
    z_at(k);  // and re-advances to −0.15
  }
  EXPECT_EQ(r.h.block().history_size(), 16u) << "0 … −0.15, no doubled segments";
  for (int k = 0; k < 3; ++k) {
    r.step(0.0, 0.0, -0.15, true);
  }
  for (int n = 0; n < 1000 && r.h.block().state() == State::kRetract; ++n) {
    r.step(0.0, 0.0, -0.15);
  }
  EXPECT_NEAR(r.h.out("z_sp_mm"), 0.0, 1e-12) << "0.5 mm back is beyond the start: z = 0";
}

TEST(ShortRetractTest, retract_distance_after_a_back_off_is_net_path_length) {
  auto p = test_params();
  p.retract_distance_mm = 0.1;
  RetractRig r(p);
  for (int k = 0; k <= 20; ++k) {
    r.step(0.0, 0.0, -0.01 * k);
  }
  for (int k = 19; k >= 10; --k) {
    r.step(0.0, 0.0, -0.01 * k);
  }
  for (int k = 11; k <= 15; ++k) {
    r.step(0.0, 0.0, -0.01 * k);
  }
  for (int k = 0; k < 3; ++k) {
    r.step(0.0, 0.0, -0.15, true);
  }
  for (int n = 0; n < 1000 && r.h.block().state() == State::kRetract; ++n) {
    r.step(0.0, 0.0, -0.15);
  }
  EXPECT_NEAR(r.h.out("z_sp_mm"), -0.05, 1e-12) << "a time-reversed walk would end at −0.15";
}

TEST(ShortRetractTest, min_spacing_thins_the_history) {
  auto p = test_params();
  p.min_spacing_mm = 0.0495;
  RetractRig r(p);
  for (int k = 0; k <= 100; ++k) {
    r.step(0.001 * k, 0.0, 0.0);  // 0.1 mm in 1 µm steps
  }
  EXPECT_EQ(r.h.block().history_size(), 3u) << "0, 0.05, 0.1";
}

TEST(ShortRetractTest, disable_clears_the_history_and_passes_through) {
  RetractRig r(test_params());
  auto& enable = r.h.source<bool>("enable");
  enable.set(true);
  drive_l_path(r);
  enable.set(false);
  for (int k = 0; k < 5; ++k) {
    EXPECT_EQ(r.step(1.0, 2.0, 3.0, true), BlockStatus::kOk);
    EXPECT_FALSE(r.active());
  }
  EXPECT_EQ(r.h.block().history_size(), 0u);
  EXPECT_EQ(r.sp(), (std::array<double, 3>{1.0, 2.0, 3.0}));
  EXPECT_EQ(r.h.out("v_scale"), 1.0);
}

TEST(ShortRetractTest, non_finite_position_is_a_fault_and_not_recorded) {
  RetractRig r(test_params());
  r.step(0.0, 0.0, 0.0);
  r.step(0.01, 0.0, 0.0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(r.step(nan, 0.0, 0.0), BlockStatus::kFault);
  EXPECT_EQ(r.h.block().history_size(), 2u);
  EXPECT_EQ(r.h.out("x_sp_mm"), 0.01) << "held";
  EXPECT_EQ(r.step(0.02, 0.0, 0.0), BlockStatus::kOk);
  EXPECT_EQ(r.h.block().history_size(), 3u);
}

TEST(ShortRetractTest, validate_and_load_time_only_capacity) {
  EXPECT_TRUE(rt::validate_params(ShortRetractParams{}).empty());
  EXPECT_FALSE(rt::validate_params(ShortRetractParams{.history_capacity = 1}).empty());
  EXPECT_FALSE(rt::validate_params(ShortRetractParams{.short_cycles = 0}).empty());
  EXPECT_FALSE(rt::validate_params(ShortRetractParams{.retract_speed_mm_s = 0.0}).empty());
  EXPECT_FALSE(rt::validate_params(
                   ShortRetractParams{.resume_ramp_ms = std::numeric_limits<double>::quiet_NaN()})
                   .empty());
  RetractRig r(test_params());
  EXPECT_FALSE(r.h.write_param("history_capacity", rt::ParamValue::of_int(16)).empty());
  EXPECT_TRUE(r.h.write_param("max_tries", rt::ParamValue::of_int(5)).empty());
  BlockHarness<ShortRetract> no_task(rt::Duration{0});
  EXPECT_FALSE(no_task.start().empty());
}

}  // namespace
}  // namespace edm::blocks

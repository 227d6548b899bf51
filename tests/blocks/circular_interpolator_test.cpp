#include "edm/blocks/circular_interpolator.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <random>

#include "block_harness.hpp"
#include "interpolator_rig.hpp"

namespace edm::blocks {
namespace {

constexpr double kPi = std::numbers::pi;

struct Rig : InterpolatorRig<CircularInterpolator> {
  explicit Rig(rt::Duration period = 1ms, CircularInterpolatorParams p = {})
      : InterpolatorRig(period) {
    h.start_ok(p);
    ov.set(1.0);
    turns.set(1);
  }
  /// Latches an arc to the end increment (ex, ey), or full circles when full > 0 turns.
  BlockStatus arc(double i_mm, double j_mm, bool clockwise, double ex_mm, double ey_mm,
                  double feed_mm_min) {
    i.set(i_mm);
    j.set(j_mm);
    cw.set(clockwise);
    ex.set(ex_mm);
    ey.set(ey_mm);
    full.set(false);
    feed.set(feed_mm_min);
    return edge();
  }
  BlockStatus circle(double i_mm, double j_mm, bool clockwise, std::int64_t n, double feed_mm_min) {
    i.set(i_mm);
    j.set(j_mm);
    cw.set(clockwise);
    full.set(true);
    turns.set(n);
    feed.set(feed_mm_min);
    return edge();
  }
  BlockStatus edge() { return h.rising_edge("start"); }
  [[nodiscard]] double x() const { return h.out("rx_mm"); }
  [[nodiscard]] double y() const { return h.out("ry_mm"); }

  rt::Output<bool>& cw = h.source<bool>("cw");
  rt::Output<double>& i = h.source<double>("i_mm");
  rt::Output<double>& j = h.source<double>("j_mm");
  rt::Output<bool>& full = h.source<bool>("full_circle");
  rt::Output<std::int64_t>& turns = h.source<std::int64_t>("turns");
  rt::Output<double>& ex = h.source<double>("ex_mm");
  rt::Output<double>& ey = h.source<double>("ey_mm");
};

TEST(CircularInterpolatorTest, matches_the_seeds_recurrence_eq_14_19) {
  // Iterate eq. 14–19 as written for a few hundred samples (error still tiny) and compare.
  for (const bool clockwise : {false, true}) {
    Rig r(1ms, {.x0_mm = 2.0, .y0_mm = -1.0});
    const double i0 = -0.6;
    const double j0 = 0.8;      // R = 1 mm
    const double feed = 600.0;  // fr = 0.01 mm → Δθ = 0.01 rad
    ASSERT_EQ(r.circle(i0, j0, clockwise, 1, feed), BlockStatus::kOk);
    const double dth = feed / 60.0 * 1e-3 / 1.0;
    const double pa = 1.0 - std::cos(dth);
    const double pb = (clockwise ? -1.0 : 1.0) * std::sin(dth);
    double rx = 2.0;
    double ry = -1.0;
    double i = i0;
    double j = j0;
    for (int k = 0; k < 300; ++k) {
      const double vx = pa * i + pb * j;
      const double vy = -pb * i + pa * j;
      rx += vx;
      ry += vy;
      i -= vx;
      j -= vy;
      if (k > 0) {
        r.h.step();
      }
      ASSERT_NEAR(r.x(), rx, 1e-12) << "k = " << k << " cw = " << clockwise;
      ASSERT_NEAR(r.y(), ry, 1e-12) << "k = " << k;
      ASSERT_NEAR(r.h.out("vx_mm_s"), vx / 1e-3, 1e-8);
      ASSERT_NEAR(r.h.out("vy_mm_s"), vy / 1e-3, 1e-8);
    }
  }
}

TEST(CircularInterpolatorTest, g03_is_counter_clockwise_and_g02_clockwise) {
  // Start at (1, 0) with the centre at the origin: i = −1, j = 0.
  Rig ccw(1ms, {.x0_mm = 1.0, .y0_mm = 0.0});
  ccw.arc(-1.0, 0.0, false, -1.0, 1.0, 60.0);  // quarter to (0, 1)
  EXPECT_GT(ccw.y(), 0.0);
  EXPECT_GT(ccw.h.out("angle_rad"), 0.0);
  const int n = ccw.run_to_end(100000);
  EXPECT_EQ(ccw.x(), 0.0);
  EXPECT_EQ(ccw.y(), 1.0);
  EXPECT_NEAR(ccw.h.out("swept_rad"), kPi / 2, 1e-12);
  EXPECT_NEAR(ccw.h.out("angle_rad"), kPi / 2, 1e-12);
  EXPECT_NEAR(n + 1, kPi / 2 / 1e-3, 1.0) << "fr = 1e-3 mm, R = 1 mm";

  Rig cw(1ms, {.x0_mm = 1.0, .y0_mm = 0.0});
  cw.arc(-1.0, 0.0, true, -1.0, 1.0, 60.0);  // clockwise to (0, 1): three quarters
  EXPECT_LT(cw.y(), 0.0);
  EXPECT_LT(cw.h.out("angle_rad"), 0.0);
  cw.run_to_end(100000);
  EXPECT_EQ(cw.x(), 0.0);
  EXPECT_EQ(cw.y(), 1.0);
  EXPECT_NEAR(cw.h.out("swept_rad"), 1.5 * kPi, 1e-12);
}

// Radius error every sample and closure after every revolution, R = 0.01 … 100 mm, both
// directions, several turns, seeded random start angle and feed.
TEST(CircularInterpolatorTest, radius_and_closure_error_stay_below_1e9_of_r) {
  std::mt19937_64 rng(4242);
  std::uniform_real_distribution<double> angle(-kPi, kPi);
  for (const double radius : {0.01, 0.1, 1.0, 10.0, 100.0}) {
    for (const bool clockwise : {false, true}) {
      const double a = angle(rng);
      const double x0 = std::uniform_real_distribution<double>(-50.0, 50.0)(rng);
      const double y0 = std::uniform_real_distribution<double>(-50.0, 50.0)(rng);
      Rig r(1ms, {.x0_mm = x0, .y0_mm = y0});
      const double i = radius * std::cos(a);
      const double j = radius * std::sin(a);
      const double cx = x0 + i;
      const double cy = y0 + j;
      // ~2000…4000 samples per revolution.
      const double fr =
          2.0 * kPi * radius / std::uniform_real_distribution<double>(2000.0, 4000.0)(rng);
      const double feed = fr / 1e-3 * 60.0;
      const std::int64_t turns = 3;
      ASSERT_EQ(r.circle(i, j, clockwise, turns, feed), BlockStatus::kOk);
      double worst = 0.0;
      double prev_swept = 0.0;
      int revs_seen = 0;
      double prev_x = x0;
      double prev_y = y0;
      int n = 0;
      for (;;) {
        const double err = std::abs(std::hypot(r.x() - cx, r.y() - cy) - radius);
        worst = std::max(worst, err);
        ASSERT_LE(err, 1e-9 * radius) << "R = " << radius << " sample " << n;
        const double step = std::hypot(r.x() - prev_x, r.y() - prev_y);
        if (r.busy()) {
          // Chord of an arc fr: 2R·sin(fr/2R).
          ASSERT_NEAR(step, 2.0 * radius * std::sin(fr / (2.0 * radius)), 1e-9 * fr + 1e-13);
        } else {
          ASSERT_LE(step, fr * (1.0 + 1e-9));
        }
        const double swept = r.h.out("swept_rad");
        if (std::floor(swept / (2.0 * kPi)) > std::floor(prev_swept / (2.0 * kPi)) && r.busy()) {
          // Just after crossing a full revolution: the point is within one step of the start.
          ++revs_seen;
          const double past = swept - 2.0 * kPi * std::floor(swept / (2.0 * kPi));
          const double ex = cx + radius * std::cos(std::atan2(-j, -i) + (clockwise ? -past : past));
          const double ey = cy + radius * std::sin(std::atan2(-j, -i) + (clockwise ? -past : past));
          EXPECT_LE(std::hypot(r.x() - ex, r.y() - ey), 1e-9 * radius) << "closure";
        }
        if (!r.busy()) {
          break;
        }
        prev_swept = swept;
        prev_x = r.x();
        prev_y = r.y();
        r.h.step();
        ASSERT_LT(++n, 20000);
      }
      EXPECT_EQ(revs_seen, turns - 1);
      EXPECT_TRUE(r.done());
      EXPECT_EQ(r.x(), x0) << "end snapped exactly to the start point";
      EXPECT_EQ(r.y(), y0);
      EXPECT_NEAR(r.h.out("swept_rad"), 2.0 * kPi * static_cast<double>(turns), 1e-9);
      RecordProperty("worst_radius_error_R_" + std::to_string(radius), std::to_string(worst));
    }
  }
}

TEST(CircularInterpolatorTest, random_arcs_end_exactly_on_the_programmed_point) {
  std::mt19937_64 rng(77);
  std::uniform_real_distribution<double> angle(-kPi, kPi);
  std::uniform_real_distribution<double> rad(0.01, 20.0);
  Rig r(500us);
  for (int m = 0; m < 200; ++m) {
    const double radius = rad(rng);
    const double a0 = angle(rng);
    const double a1 = angle(rng);
    const double i = -radius * std::cos(a0);  // start at angle a0 about the centre
    const double j = -radius * std::sin(a0);
    const double ex = i + radius * std::cos(a1);  // end at angle a1
    const double ey = j + radius * std::sin(a1);
    const double x0 = r.x();
    const double y0 = r.y();
    const double fr = radius * std::uniform_real_distribution<double>(1e-3, 2e-2)(rng);
    ASSERT_EQ(r.arc(i, j, m % 2 == 0, ex, ey, fr / 5e-4 * 60.0), BlockStatus::kOk) << m;
    int n = 0;
    while (r.busy()) {
      r.h.step();
      ASSERT_LT(++n, 100000);
    }
    EXPECT_TRUE(r.done());
    EXPECT_EQ(r.x(), x0 + ex) << m;
    EXPECT_EQ(r.y(), y0 + ey) << m;
  }
}

TEST(CircularInterpolatorTest, hold_and_override) {
  Rig r(1ms, {.x0_mm = 1.0, .y0_mm = 0.0});
  r.circle(-1.0, 0.0, false, 1, 60.0);  // Δθ = 1e-3 rad
  EXPECT_NEAR(r.h.out("swept_rad"), 1e-3, 1e-15);
  r.ov.set(2.0);
  r.h.step();
  EXPECT_NEAR(r.h.out("swept_rad"), 3e-3, 1e-15);
  r.ov.set(5.0);
  EXPECT_EQ(r.h.step(), BlockStatus::kSaturated);
  EXPECT_NEAR(r.h.out("swept_rad"), 5e-3, 1e-15);
  r.ov.set(1.0);
  r.hold.set(true);
  const double hx = r.x();
  const double hy = r.y();
  for (int n = 0; n < 50; ++n) {
    EXPECT_EQ(r.h.step(), BlockStatus::kOk);
    EXPECT_EQ(r.x(), hx);
    EXPECT_EQ(r.y(), hy);
    EXPECT_EQ(r.h.out("vx_mm_s"), 0.0);
    EXPECT_TRUE(r.busy());
  }
  r.hold.set(false);
  r.h.step();
  EXPECT_NEAR(r.h.out("swept_rad"), 6e-3, 1e-15);
  r.run_to_end(100000);
  EXPECT_EQ(r.x(), 1.0);
  EXPECT_EQ(r.y(), 0.0);
}

TEST(CircularInterpolatorTest, zero_end_increment_is_one_full_circle) {
  Rig r(1ms, {.x0_mm = 0.0, .y0_mm = 0.0});
  r.arc(0.0, 0.5, true, 0.0, 0.0, 600.0);
  r.run_to_end(100000);
  EXPECT_NEAR(r.h.out("swept_rad"), 2.0 * kPi, 1e-12);
  EXPECT_EQ(r.x(), 0.0);
  EXPECT_EQ(r.y(), 0.0);
}

TEST(CircularInterpolatorTest, refuses_bad_moves) {
  Rig r(1ms, {.x0_mm = 0.0, .y0_mm = 0.0, .end_tol_mm = 1e-3});
  EXPECT_EQ(r.arc(0.0, 0.0, false, 1.0, 0.0, 60.0), BlockStatus::kFault) << "R = 0";
  EXPECT_EQ(r.arc(kNaN, 1.0, false, 1.0, 0.0, 60.0), BlockStatus::kFault);
  EXPECT_EQ(r.arc(1.0, 0.0, false, kNaN, 0.0, 60.0), BlockStatus::kFault);
  EXPECT_EQ(r.arc(1.0, 0.0, false, 2.0, 0.0, 0.0), BlockStatus::kFault) << "feed 0";
  EXPECT_EQ(r.arc(1.0, 0.0, false, 2.0, 0.0, kNaN), BlockStatus::kFault);
  EXPECT_EQ(r.arc(1.0, 0.0, false, 2.01, 0.0, 60.0), BlockStatus::kFault) << "end off circle";
  EXPECT_EQ(r.circle(1.0, 0.0, false, 0, 60.0), BlockStatus::kFault) << "turns < 1";
  EXPECT_EQ(r.circle(1.0, 0.0, false, CircularInterpolator::kMaxTurns + 1, 60.0),
            BlockStatus::kFault);
  EXPECT_FALSE(r.busy());
  EXPECT_EQ(r.x(), 0.0);
  EXPECT_EQ(r.y(), 0.0);
  // Within the tolerance: accepted, and the last step lands on the programmed point.
  EXPECT_EQ(r.arc(1.0, 0.0, false, 2.0005, 0.0, 600.0), BlockStatus::kOk);
  r.run_to_end(100000);
  EXPECT_EQ(r.x(), 2.0005);
  EXPECT_EQ(r.y(), 0.0);
}

TEST(CircularInterpolatorTest, non_finite_override_holds_and_faults) {
  Rig r(1ms, {.x0_mm = 1.0, .y0_mm = 0.0});
  r.circle(-1.0, 0.0, false, 1, 60.0);
  const double x = r.x();
  const double y = r.y();
  r.ov.set(kNaN);
  EXPECT_EQ(r.h.step(), BlockStatus::kFault);
  EXPECT_EQ(r.x(), x);
  EXPECT_EQ(r.y(), y);
  EXPECT_EQ(r.h.out("vy_mm_s"), 0.0);
  EXPECT_TRUE(r.busy());
  r.ov.set(1.0);
  EXPECT_EQ(r.h.step(), BlockStatus::kOk);
  EXPECT_NEAR(r.h.out("swept_rad"), 2e-3, 1e-15);
}

TEST(CircularInterpolatorTest, load_sets_the_position_and_cancels) {
  Rig r;
  r.circle(1.0, 0.0, false, 1, 60.0);
  r.load_x.set(3.0);
  r.load_y.set(4.0);
  r.load.set(true);
  EXPECT_EQ(r.h.step(), BlockStatus::kOk);
  EXPECT_FALSE(r.busy());
  EXPECT_EQ(r.x(), 3.0);
  EXPECT_EQ(r.y(), 4.0);
  r.load_x.set(kNaN);
  EXPECT_EQ(r.h.step(), BlockStatus::kFault);
  EXPECT_EQ(r.x(), 3.0);
}

TEST(CircularInterpolatorTest, validate_and_configure_refuse_bad_setups) {
  EXPECT_TRUE(rt::validate_params(CircularInterpolatorParams{}).empty());
  EXPECT_FALSE(rt::validate_params(CircularInterpolatorParams{.end_tol_mm = -1.0}).empty());
  EXPECT_FALSE(rt::validate_params(CircularInterpolatorParams{.x0_mm = kNaN}).empty());
  BlockHarness<CircularInterpolator> no_task(rt::Duration{0});
  EXPECT_FALSE(no_task.start().empty());
}

}  // namespace
}  // namespace edm::blocks

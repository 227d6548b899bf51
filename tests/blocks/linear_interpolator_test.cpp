#include "edm/blocks/linear_interpolator.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

#include "block_harness.hpp"
#include "interpolator_rig.hpp"

namespace edm::blocks {
namespace {

using Vec3 = std::array<double, 3>;

// The block with every input wired to a test-owned output.
struct LinearRig : InterpolatorRig<LinearInterpolator> {
  explicit LinearRig(rt::Duration period = 1ms, LinearInterpolatorParams p = {})
      : InterpolatorRig(period) {
    h.start_ok(p);
    ov.set(1.0);
  }
  /// Latches a move: start low for one cycle (if it was high), then a rising edge. Returns the
  /// status of the edge cycle (the first step of the move).
  BlockStatus move(const Vec3& l, double feed_mm_min) {
    lx.set(l[0]);
    ly.set(l[1]);
    lz.set(l[2]);
    feed.set(feed_mm_min);
    return h.rising_edge("start");
  }
  [[nodiscard]] Vec3 pos() const { return {h.out("rx_mm"), h.out("ry_mm"), h.out("rz_mm")}; }
  [[nodiscard]] Vec3 vel() const { return {h.out("vx_mm_s"), h.out("vy_mm_s"), h.out("vz_mm_s")}; }

  rt::Output<double>& lx = h.source<double>("lx_mm");
  rt::Output<double>& ly = h.source<double>("ly_mm");
  rt::Output<double>& lz = h.source<double>("lz_mm");
  rt::Output<double>& load_z = h.source<double>("load_z_mm");
};

double dist(const Vec3& a, const Vec3& b) {
  return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
}

TEST(LinearInterpolatorTest, starts_at_the_parameter_position_idle) {
  LinearRig r(1ms, {.x0_mm = 1.5, .y0_mm = -2.0, .z0_mm = 10.0});
  EXPECT_EQ(r.h.step(), BlockStatus::kOk);
  EXPECT_EQ(r.pos(), (Vec3{1.5, -2.0, 10.0}));
  EXPECT_EQ(r.vel(), (Vec3{0.0, 0.0, 0.0}));
  EXPECT_FALSE(r.busy());
  EXPECT_FALSE(r.done());
}

TEST(LinearInterpolatorTest, follows_eq_12_13_and_ends_exactly) {
  // 3-4-0 triangle: l = 5 mm; feed 600 mm/min at 1 ms → fr = 0.01 mm per sample, 500 samples.
  LinearRig r;
  ASSERT_EQ(r.move({3.0, 4.0, 0.0}, 600.0), BlockStatus::kOk);
  EXPECT_TRUE(r.busy());
  EXPECT_NEAR(r.pos()[0], 0.01 * 3.0 / 5.0, 1e-15);
  EXPECT_NEAR(r.pos()[1], 0.01 * 4.0 / 5.0, 1e-15);
  EXPECT_NEAR(r.vel()[0], 6.0, 1e-9) << "v = fr·lx/l / dt = 10 mm/s · 0.6";
  EXPECT_NEAR(r.vel()[1], 8.0, 1e-9);
  EXPECT_EQ(r.vel()[2], 0.0);
  for (int k = 2; k < 500; ++k) {
    r.h.step();
    ASSERT_TRUE(r.busy()) << k;
    ASSERT_NEAR(r.pos()[0], 0.01 * k * 0.6, 1e-12) << k;
    ASSERT_NEAR(r.pos()[1], 0.01 * k * 0.8, 1e-12) << k;
  }
  r.h.step();  // sample 500 (rounding of s may put it at 499 or 500)
  if (r.busy()) {
    r.h.step();
  }
  EXPECT_FALSE(r.busy());
  EXPECT_TRUE(r.done());
  EXPECT_EQ(r.pos(), (Vec3{3.0, 4.0, 0.0}));
  // done is a level; once stopped, v = 0 and the position stays.
  for (int k = 0; k < 3; ++k) {
    r.h.step();
    EXPECT_TRUE(r.done());
    EXPECT_EQ(r.vel(), (Vec3{0.0, 0.0, 0.0}));
    EXPECT_EQ(r.pos(), (Vec3{3.0, 4.0, 0.0}));
  }
}

TEST(LinearInterpolatorTest, random_moves_end_exactly_and_step_fr_every_sample_but_the_last) {
  std::mt19937_64 rng(20240611);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_real_distribution<double> feed_dist(5.0, 6000.0);
  std::uniform_real_distribution<double> ov_dist(0.1, 2.0);
  LinearRig r(250us);
  const double dt = r.h.dt_s();
  double worst_rel = 0.0;
  for (int m = 0; m < 300; ++m) {
    Vec3 l{unit(rng), unit(rng), unit(rng)};
    if (m % 5 == 1) {
      l[m % 3] = 0.0;  // single-axis and planar moves too
    }
    const double feed = feed_dist(rng);
    const double ov = m % 3 == 0 ? ov_dist(rng) : 1.0;
    const double fr = feed / 60.0 * ov * dt;
    // At most ~20000 samples per move.
    const double len_target = fr * std::uniform_real_distribution<double>(0.3, 20000.0)(rng);
    const double n0 = std::hypot(l[0], l[1], l[2]);
    for (double& c : l) {
      c *= len_target / n0;
    }
    const Vec3 p0 = r.pos();
    const Vec3 end{p0[0] + l[0], p0[1] + l[1], p0[2] + l[2]};
    r.ov.set(ov);
    Vec3 prev = p0;
    ASSERT_EQ(r.move(l, feed), BlockStatus::kOk);
    int samples = 1;
    for (;;) {
      const Vec3 p = r.pos();
      const double step = dist(p, prev);
      const Vec3 v = r.vel();
      ASSERT_NEAR(std::hypot(v[0], v[1], v[2]) * dt, step, 1e-9 * fr) << "v = step/dt";
      if (!r.busy()) {
        ASSERT_LE(step, fr * (1.0 + 1e-9)) << "last step clipped, move " << m;
        break;
      }
      // The step is a difference of two rounded positions: allow their last bits too.
      const double ulps = 4.0 * std::numeric_limits<double>::epsilon() *
                          std::max({std::abs(p[0]), std::abs(p[1]), std::abs(p[2]), 1.0});
      const double rel = std::abs(step - fr) / fr;
      worst_rel = std::max(worst_rel, rel);
      ASSERT_LE(std::abs(step - fr), 1e-12 * fr + ulps) << "move " << m << " sample " << samples;
      prev = p;
      r.h.step();
      ++samples;
      ASSERT_LT(samples, 30000);
    }
    ASSERT_TRUE(r.done());
    EXPECT_EQ(r.pos()[0], end[0]) << "move " << m;
    EXPECT_EQ(r.pos()[1], end[1]) << "move " << m;
    EXPECT_EQ(r.pos()[2], end[2]) << "move " << m;
    EXPECT_LE(std::abs(samples - std::ceil(len_target / fr)), 1.0)
        << "one sample per fr, the last one partial; move " << m;
  }
  RecordProperty("worst_step_rel_error", std::to_string(worst_rel));
}

TEST(LinearInterpolatorTest, hold_keeps_the_position_and_resumes_without_loss) {
  // Reference run without hold, then the same move with a hold of 137 samples in the middle:
  // the sequence of positions is the same, only delayed.
  LinearRig ref;
  ASSERT_EQ(ref.move({-7.25, 2.5, 1.0}, 1234.5), BlockStatus::kOk);
  std::vector<Vec3> path{ref.pos()};
  while (ref.busy()) {
    ref.h.step();
    path.push_back(ref.pos());
  }
  ASSERT_GT(path.size(), 300u);

  LinearRig r;
  ASSERT_EQ(r.move({-7.25, 2.5, 1.0}, 1234.5), BlockStatus::kOk);
  std::size_t k = 0;
  EXPECT_EQ(r.pos(), path[k]);
  for (; k + 1 < 200; ++k) {
    r.h.step();
    ASSERT_EQ(r.pos(), path[k + 1]);
  }
  r.hold.set(true);
  for (int n = 0; n < 137; ++n) {
    ASSERT_EQ(r.h.step(), BlockStatus::kOk);
    ASSERT_EQ(r.pos(), path[k]) << "held";
    ASSERT_EQ(r.vel(), (Vec3{0.0, 0.0, 0.0}));
    ASSERT_TRUE(r.busy());
    ASSERT_FALSE(r.done());
  }
  r.hold.set(false);
  while (r.busy()) {
    r.h.step();
    ++k;
    ASSERT_LT(k, path.size());
    ASSERT_EQ(r.pos(), path[k]);
  }
  EXPECT_EQ(k + 1, path.size());
  EXPECT_EQ(r.pos(), (Vec3{-7.25, 2.5, 1.0}));
}

TEST(LinearInterpolatorTest, override_scales_the_feed_live_and_is_clamped) {
  // 10 mm at 600 mm/min, 1 ms: fr = 0.01 mm at 100 %.
  LinearRig r;
  r.ov.set(2.0);
  ASSERT_EQ(r.move({10.0, 0.0, 0.0}, 600.0), BlockStatus::kOk);
  EXPECT_NEAR(r.pos()[0], 0.02, 1e-15);
  EXPECT_NEAR(r.vel()[0], 20.0, 1e-9);
  r.ov.set(0.5);
  r.h.step();
  EXPECT_NEAR(r.pos()[0], 0.025, 1e-15);
  EXPECT_NEAR(r.vel()[0], 5.0, 1e-9);
  r.ov.set(3.0);
  EXPECT_EQ(r.h.step(), BlockStatus::kSaturated);
  EXPECT_NEAR(r.pos()[0], 0.045, 1e-15) << "clamped to 200 %";
  r.ov.set(-1.0);
  EXPECT_EQ(r.h.step(), BlockStatus::kSaturated);
  EXPECT_NEAR(r.pos()[0], 0.045, 1e-15) << "clamped to 0 %: no advance";
  EXPECT_EQ(r.vel()[0], 0.0);
  r.ov.set(0.0);
  EXPECT_EQ(r.h.step(), BlockStatus::kOk);
  EXPECT_TRUE(r.busy());
  r.ov.set(1.0);
  const int n = r.run_to_end();
  EXPECT_EQ(r.pos()[0], 10.0);
  EXPECT_NEAR(n, (10.0 - 0.045) / 0.01, 1.0);
}

TEST(LinearInterpolatorTest, zero_length_move_is_done_at_once) {
  LinearRig r(1ms, {.x0_mm = 1.0, .y0_mm = 2.0, .z0_mm = 3.0});
  EXPECT_EQ(r.move({0.0, 0.0, 0.0}, 0.0), BlockStatus::kOk) << "feed not needed";
  EXPECT_FALSE(r.busy());
  EXPECT_TRUE(r.done());
  EXPECT_EQ(r.pos(), (Vec3{1.0, 2.0, 3.0}));
  EXPECT_EQ(r.vel(), (Vec3{0.0, 0.0, 0.0}));
}

TEST(LinearInterpolatorTest, consecutive_moves_chain_from_the_end_point) {
  LinearRig r;
  const Vec3 a{1.0, 0.1, -0.3};
  const Vec3 b{-0.7, 2.0, 0.05};
  r.move(a, 900.0);
  r.run_to_end();
  EXPECT_EQ(r.pos(), a);
  r.move(b, 450.0);
  EXPECT_FALSE(r.done()) << "done drops when the next move is latched";
  r.run_to_end();
  EXPECT_EQ(r.pos(), (Vec3{a[0] + b[0], a[1] + b[1], a[2] + b[2]}));
}

TEST(LinearInterpolatorTest, start_edge_while_busy_is_ignored_and_level_does_not_restart) {
  LinearRig r;
  r.move({1.0, 0.0, 0.0}, 600.0);  // 100 samples
  for (int n = 0; n < 10; ++n) {
    r.h.step();
  }
  r.lx.set(50.0);
  r.start.set(false);
  r.h.step();
  r.start.set(true);
  r.h.step();
  r.run_to_end();
  EXPECT_EQ(r.pos()[0], 1.0) << "the second edge came while busy";
  for (int n = 0; n < 10; ++n) {
    r.h.step();
  }
  EXPECT_EQ(r.pos()[0], 1.0) << "a start held high does not relatch";
}

TEST(LinearInterpolatorTest, load_sets_the_position_and_cancels_a_move) {
  LinearRig r;
  r.move({5.0, 5.0, 5.0}, 600.0);
  r.h.step();
  r.load_x.set(-1.0);
  r.load_y.set(-2.0);
  r.load_z.set(-3.0);
  r.load.set(true);
  EXPECT_EQ(r.h.step(), BlockStatus::kOk);
  EXPECT_EQ(r.pos(), (Vec3{-1.0, -2.0, -3.0}));
  EXPECT_FALSE(r.busy());
  EXPECT_FALSE(r.done());
  r.load.set(false);
  r.move({0.5, 0.0, 0.0}, 600.0);
  r.run_to_end();
  EXPECT_EQ(r.pos(), (Vec3{-0.5, -2.0, -3.0}));
  r.load_y.set(kNaN);
  r.load.set(true);
  EXPECT_EQ(r.h.step(), BlockStatus::kFault);
  EXPECT_EQ(r.pos(), (Vec3{-0.5, -2.0, -3.0})) << "non-finite load refused";
}

TEST(LinearInterpolatorTest, non_finite_inputs_fault_without_moving) {
  LinearRig r;
  EXPECT_EQ(r.move({kNaN, 1.0, 0.0}, 600.0), BlockStatus::kFault);
  EXPECT_FALSE(r.busy());
  EXPECT_EQ(r.pos(), (Vec3{0.0, 0.0, 0.0}));
  EXPECT_EQ(r.move({1.0, 1.0, 0.0}, kNaN), BlockStatus::kFault);
  EXPECT_EQ(r.move({1.0, 1.0, 0.0}, 0.0), BlockStatus::kFault) << "feed 0";
  EXPECT_EQ(r.move({1.0, 1.0, 0.0}, -5.0), BlockStatus::kFault) << "negative feed";
  EXPECT_EQ(r.move({1.5e308, 1.5e308, 0.0}, 600.0), BlockStatus::kFault) << "length overflows";
  EXPECT_FALSE(r.busy());
  EXPECT_EQ(r.pos(), (Vec3{0.0, 0.0, 0.0}));

  ASSERT_EQ(r.move({1.0, 0.0, 0.0}, 600.0), BlockStatus::kOk);
  const Vec3 p = r.pos();
  r.ov.set(kNaN);
  EXPECT_EQ(r.h.step(), BlockStatus::kFault);
  EXPECT_EQ(r.pos(), p) << "held";
  EXPECT_EQ(r.vel(), (Vec3{0.0, 0.0, 0.0}));
  EXPECT_TRUE(r.busy());
  r.ov.set(1.0);
  EXPECT_EQ(r.h.step(), BlockStatus::kOk);
  r.run_to_end();
  EXPECT_EQ(r.pos(), (Vec3{1.0, 0.0, 0.0}));
  for (double x : {r.pos()[0], r.vel()[0]}) {
    EXPECT_TRUE(std::isfinite(x));
  }
}

TEST(LinearInterpolatorTest, safe_state_cancels_the_move) {
  LinearRig r;
  r.move({1.0, 0.0, 0.0}, 600.0);
  r.h.step();
  const Vec3 p = r.pos();
  r.h.block().enter_safe_state({});
  EXPECT_FALSE(r.busy());
  EXPECT_EQ(r.vel(), (Vec3{0.0, 0.0, 0.0}));
  r.h.step();
  EXPECT_EQ(r.pos(), p);
}

TEST(LinearInterpolatorTest, validate_and_configure_refuse_bad_setups) {
  EXPECT_TRUE(rt::validate_params(LinearInterpolatorParams{}).empty());
  EXPECT_FALSE(rt::validate_params(LinearInterpolatorParams{.x0_mm = kNaN}).empty());
  BlockHarness<LinearInterpolator> no_task(rt::Duration{0});
  EXPECT_FALSE(no_task.start().empty());
}

}  // namespace
}  // namespace edm::blocks

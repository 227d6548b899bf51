#include "edm/sim/monitors.hpp"

#include <gtest/gtest.h>

#include "edm/sim/axis.hpp"

namespace edm::sim {
namespace {

constexpr std::int64_t kMs = 1'000'000;

TEST(SimWire, thickness_profile_steps) {
  std::string why;
  const auto p = ThicknessProfile::make("0:10,20:60,40:10", &why);
  ASSERT_TRUE(p.has_value()) << why;
  EXPECT_DOUBLE_EQ(p->thickness_mm(0.0), 10.0);
  EXPECT_DOUBLE_EQ(p->thickness_mm(19.99), 10.0);
  EXPECT_DOUBLE_EQ(p->thickness_mm(20.0), 60.0);
  EXPECT_DOUBLE_EQ(p->thickness_mm(39.0), 60.0);
  EXPECT_DOUBLE_EQ(p->thickness_mm(100.0), 10.0);
  EXPECT_FALSE(ThicknessProfile::make("0:10,x:2", &why).has_value());
}

TEST(SimWire, break_current_law) {
  EXPECT_DOUBLE_EQ(wire_break_current_a(3.0, 10.0, 1.0), 3.0);
  EXPECT_NEAR(wire_break_current_a(3.0, 40.0, 1.0), 6.0, 1e-12);
  EXPECT_NEAR(wire_break_current_a(3.0, 10.0, 0.3), 0.9, 1e-12);
}

TEST(SimWire, breaks_after_5ms_over_current_not_4ms) {
  WireBreakMonitor m(5 * kMs, 0.5, 100 * kMs);
  for (int i = 0; i < 40; ++i) m.update(kMs / 10, 3.5, 3.0, 0.0);  // 4 ms over
  EXPECT_FALSE(m.broken());
  m.update(kMs / 10, 2.9, 3.0, 0.0);  // below: the timer restarts
  for (int i = 0; i < 45; ++i) m.update(kMs / 10, 3.5, 3.0, 0.0);
  EXPECT_FALSE(m.broken());
  for (int i = 0; i < 15; ++i) m.update(kMs / 10, 3.5, 3.0, 0.0);  // 6 ms in a row
  EXPECT_TRUE(m.broken());
  m.update(kMs, 0.0, 3.0, 0.0);
  EXPECT_TRUE(m.broken());  // latched
}

TEST(SimWire, breaks_after_100ms_of_high_rab) {
  WireBreakMonitor m(5 * kMs, 0.5, 100 * kMs);
  for (int i = 0; i < 99; ++i) m.update(kMs, 0.0, 3.0, 0.6);
  EXPECT_FALSE(m.broken());
  m.update(kMs, 0.0, 3.0, 0.5);  // not above: restart
  for (int i = 0; i < 99; ++i) m.update(kMs, 0.0, 3.0, 0.6);
  EXPECT_FALSE(m.broken());
  m.update(kMs, 0.0, 3.0, 0.6);
  EXPECT_TRUE(m.broken());
}

TEST(SimRab, window_slides) {
  RabWindow r(40 * kMs);
  for (int i = 0; i < 40; ++i) r.add(i * kMs, i % 4 == 0);  // 25 % abnormal
  EXPECT_NEAR(r.rab(40 * kMs - 1), 0.25, 1e-12);
  for (int i = 40; i < 80; ++i) r.add(i * kMs, false);
  EXPECT_NEAR(r.rab(80 * kMs - 1), 0.0, 0.03);  // the old abnormal ones have left
  EXPECT_DOUBLE_EQ(r.rab(500 * kMs), 0.0);      // empty window
}

TEST(SimAxis, tracks_velocity_and_respects_limits) {
  Axis a(AxisLimits{200.0, 0.55, 30.0, 150.0, 2000.0});
  a.reset(0.0);
  const double dt = 25e-6;
  for (int i = 0; i < 4000; ++i) a.step(-10.0, dt);  // 0.1 s at -10 mm/s
  EXPECT_NEAR(a.velocity_mm_s(), -10.0, 0.01);
  EXPECT_NEAR(a.position_mm(), a.reference_mm(), 1e-3);  // feed-forward: (almost) no lag
  for (int i = 0; i < 8000; ++i) a.step(-1000.0, dt);    // clipped to v_max
  EXPECT_NEAR(a.velocity_mm_s(), -30.0, 0.05);
  for (int i = 0; i < 8000; ++i) a.step(1000.0, dt);  // retract: v_jump
  EXPECT_NEAR(a.velocity_mm_s(), 150.0, 0.2);
  // acceleration limit: from rest to 30 mm/s takes 15 ms at 2 m/s²; after 5 ms < 12 mm/s.
  a.reset(0.0);
  for (int i = 0; i < 200; ++i) a.step(-30.0, dt);
  EXPECT_GT(a.velocity_mm_s(), -12.0);
  // stop: settles at the reference with overshoot below 20 %, within ~50 ms.
  a.reset(0.0);
  for (int i = 0; i < 2000; ++i) a.step(-30.0, dt);
  const double stop_ref = a.reference_mm();
  double worst = 0.0;
  for (int i = 0; i < 4000; ++i) {
    a.step(0.0, dt);
    worst = std::max(worst, std::abs(a.position_mm() - a.reference_mm()));
  }
  EXPECT_LT(std::abs(a.position_mm() - a.reference_mm()), 1e-3);
  EXPECT_LT(worst, 0.06);  // ≈ a_max / ω_n² = 50 µm while the reference decelerates
  EXPECT_LT(a.position_mm(), stop_ref);  // it kept moving while decelerating
}

}  // namespace
}  // namespace edm::sim

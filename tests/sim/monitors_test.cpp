#include "edm/sim/monitors.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "edm/sim/axis.hpp"
#include "edm/sim/random.hpp"

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

// A monitor whose Rab hazard never fires within these tests (mean time 1e9 s at Rab = 1).
WireBreakMonitor current_only() {
  return WireBreakMonitor(5 * kMs, 1.0, std::int64_t{1'000'000'000} * 1'000 * kMs, 0.02, kMs, 1.0);
}

TEST(SimWire, breaks_after_5ms_over_current_not_4ms) {
  WireBreakMonitor m = current_only();
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

// Constant Rab r, lag settled (tau 1 µs): λ = e^((r − ref)/w) / T, so the wire breaks at
// t = threshold / λ — whatever the update step.
TEST(SimWire, rab_hazard_breaks_at_threshold_over_rate_for_any_step) {
  const double ref = 0.75, w = 0.02, mean_s = 10.0, threshold = 0.8;
  for (const double r : {0.70, 0.75, 0.79, 0.85}) {
    const double expected_s = threshold * mean_s * std::exp(-(r - ref) / w);
    for (const std::int64_t step : {kMs / 10, kMs, 7 * kMs}) {
      WireBreakMonitor m(5 * kMs, ref, static_cast<std::int64_t>(mean_s * 1e3) * kMs, w, 1000,
                         threshold);
      EXPECT_NEAR(m.rate_per_s(r), std::exp((r - ref) / w) / mean_s, 1e-12);
      std::int64_t t = 0;
      while (!m.update(step, 0.0, 3.0, r) && t < 1000'000 * kMs) t += step;
      t += step;
      const double t_s = static_cast<double>(t) * 1e-9;
      EXPECT_GE(t_s, expected_s - 1e-6) << "r " << r << " step " << step;
      EXPECT_LT(t_s, expected_s + static_cast<double>(step) * 1e-9 + 1e-6)
          << "r " << r << " step " << step;
    }
  }
}

// The hazard acts on Rab lagged by tau: a 40 ms burst of Rab = 1 (one bad window) does not
// break a wire that would break in microseconds on the raw value; the same Rab held does.
TEST(SimWire, rab_hazard_acts_on_the_lagged_rab) {
  WireBreakMonitor m(5 * kMs, 0.75, 10'000 * kMs, 0.02, 200 * kMs, 1.0);
  EXPECT_GT(m.rate_per_s(1.0), 1e4);  // on the raw value: mean time to break < 0.1 ms
  for (int i = 0; i < 40; ++i) m.update(kMs, 0.0, 3.0, 1.0);
  EXPECT_NEAR(m.rab_lagged(), 1.0 - std::exp(-40.0 / 200.0), 1e-9);
  for (int i = 0; i < 1000; ++i) m.update(kMs, 0.0, 3.0, 0.3);
  EXPECT_FALSE(m.broken());
  for (int i = 0; i < 1000 && !m.broken(); ++i) m.update(kMs, 0.0, 3.0, 1.0);
  EXPECT_TRUE(m.broken());
  EXPECT_GE(m.hazard(), m.threshold());
}

// The tolerated damage: shape 1 is the Exp(1) variate at index 0 of the wire-break stream
// (the draw before the shape existed, so shape-1 runs are unchanged); shape k is Gamma(k, 1/k):
// mean 1, CV 1/√k, and a lower tail that vanishes as (k x)^k / k! — checked over 20 000 seeds
// against the Gamma distribution's own figures.
TEST(SimWire, break_threshold_is_gamma_of_the_shape) {
  for (std::uint64_t seed = 1; seed <= 50; ++seed) {
    EXPECT_DOUBLE_EQ(wire_break_threshold(seed, 1),
                     -std::log1p(-uniform(seed, Stream::kWireBreak, 0)));
  }
  constexpr int kSeeds = 20000;
  for (const int k : {1, 4, 9}) {
    double sum = 0.0, ss = 0.0;
    int below = 0;  // thresholds under 0.05
    for (std::uint64_t seed = 1; seed <= kSeeds; ++seed) {
      const double x = wire_break_threshold(seed, k);
      ASSERT_GT(x, 0.0);
      sum += x;
      ss += x * x;
      below += x < 0.05 ? 1 : 0;
    }
    const double mean = sum / kSeeds;
    const double sd = std::sqrt(ss / kSeeds - mean * mean);
    const double cv = 1.0 / std::sqrt(static_cast<double>(k));
    EXPECT_NEAR(mean, 1.0, 4.0 * cv / std::sqrt(static_cast<double>(kSeeds))) << "k " << k;
    EXPECT_NEAR(sd, cv, 0.03 * cv) << "k " << k;
    // P(X < 0.05) = 1 − e^(−0.05 k) Σ_{i<k} (0.05 k)^i / i!
    double term = 1.0, cdf_sum = 0.0;
    for (int i = 0; i < k; ++i) {
      cdf_sum += term;
      term *= 0.05 * k / (i + 1);
    }
    const double p = 1.0 - std::exp(-0.05 * k) * cdf_sum;
    const double tol = 4.0 * std::sqrt(p * (1.0 - p) / kSeeds) + 1.0 / kSeeds;
    EXPECT_NEAR(static_cast<double>(below) / kSeeds, p, tol) << "k " << k;
  }
  EXPECT_DOUBLE_EQ(wire_break_threshold(3, 0), wire_break_threshold(3, 1));  // clamped
  EXPECT_DOUBLE_EQ(wire_break_threshold(3, 1000), wire_break_threshold(3, kMaxWireBreakShape));
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

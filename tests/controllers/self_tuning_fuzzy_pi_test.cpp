// Seed 000 controller: self-tuning PI-type fuzzy control of the abnormal ratio Rab.

#include "edm/blocks/self_tuning_fuzzy_pi.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "blocks/block_harness.hpp"
#include "edm/blocks/butterworth_low_pass.hpp"
#include "edm/blocks/grey_predictor_gm11.hpp"

namespace edm::blocks {
namespace {

// Table 3 of the paper, rows CE = PB…NB, columns E = NB…PB, as printed (the extracted text lost
// one cell of column PS; it is restored from the neighbouring cells' pattern: NM).
constexpr int kTable3[7][7] = {
    {0, -1, -2, -3, -3, -3, -3},  // CE = PB
    {1, 0, -1, -2, -3, -3, -3},   // CE = PM
    {2, 1, 0, -1, -2, -3, -3},    // CE = PS
    {3, 2, 1, 0, -1, -2, -3},     // CE = ZE
    {3, 3, 2, 1, 0, -1, -2},      // CE = NS
    {3, 3, 3, 2, 1, 0, -1},       // CE = NM
    {3, 3, 3, 3, 2, 1, 0},        // CE = NB
};

class Pi {
 public:
  explicit Pi(const SelfTuningFuzzyPIParams& p = {}) {
    const auto errs = h_.start(p);
    EXPECT_TRUE(errs.empty()) << test::describe(errs);
    rab_p_ = &h_.source<double>("rab_p");
    rab_f_ = &h_.source<double>("rab_f");
    enable_ = &h_.source<bool>("enable");
    enable_->set(true);
  }
  BlockStatus step(double rab_p, double rab_f) {
    rab_p_->set(rab_p);
    rab_f_->set(rab_f);
    return h_.step();
  }
  BlockStatus step(double rab) { return step(rab, rab); }
  double u() const { return h_.out("arc_off_time_us"); }
  double v() const { return h_.out("servo_ref_v"); }
  double du() const { return h_.out("du"); }
  double phi() const { return h_.out("phi"); }
  double psi() const { return h_.out("psi"); }
  void enable(bool on) { enable_->set(on); }

 private:
  BlockHarness<SelfTuningFuzzyPI> h_;
  rt::Output<double>* rab_p_{nullptr};
  rt::Output<double>* rab_f_{nullptr};
  rt::Output<bool>* enable_{nullptr};
};

TEST(SelfTuningFuzzyPI, rule_base_at_term_peaks_reproduces_table_3) {
  // Ge = 10 (not 5) keeps every Rab of the 49 cases inside [0, 1]; the peaks do not depend on Ge.
  SelfTuningFuzzyPIParams p;
  p.ge = 10.0;
  p.rab_ref_default = 0.5;
  for (int row = 0; row < 7; ++row) {
    const int j = 3 - row;  // CE index
    for (int col = 0; col < 7; ++col) {
      const int i = col - 3;  // E index
      // Two samples: Rab_p(k−1) = x0, Rab_p(k) = x1 with e = ref − x1 = i/Ge, ce = x0 − x1 = j/Gce.
      Pi pi(p);
      const double x1 = p.rab_ref_default - i / p.ge;
      const double x0 = x1 + j / p.gce;
      pi.step(x0);
      pi.step(x1);
      EXPECT_NEAR(pi.du(), kTable3[row][col], 1e-9) << "E index " << i << ", CE index " << j;
    }
  }
}

TEST(SelfTuningFuzzyPI, rule_output_between_peaks_and_saturation_by_hand) {
  // Between peaks: two terms per input fire; height defuzzification averages the table values.
  EXPECT_DOUBLE_EQ(SelfTuningFuzzyPI::rule_output(0.5, 0.0), -0.5);  // ZE .5 → 0, PS .5 → −1
  EXPECT_DOUBLE_EQ(SelfTuningFuzzyPI::rule_output(0.5, 0.5), -1.0);  // 0, −1, −1, −2 at .5 each
  // E = −0.25: NS .25 → +1 and ZE .75 → 0 ⇒ (0.25·1)/(0.25 + 0.75).
  EXPECT_DOUBLE_EQ(SelfTuningFuzzyPI::rule_output(-0.25, 0.0), 0.25);
  // E = 2.5, CE = 1: PM .5 and PB .5 with PS 1 → −3 and −4 clamped to −3.
  EXPECT_DOUBLE_EQ(SelfTuningFuzzyPI::rule_output(2.5, 1.0), -3.0);
  // The clamp: E = PB, CE = PB gives NB, not −6; beyond the universe the outer terms hold.
  EXPECT_DOUBLE_EQ(SelfTuningFuzzyPI::rule_output(3.0, 3.0), -3.0);
  EXPECT_DOUBLE_EQ(SelfTuningFuzzyPI::rule_output(50.0, 0.0), -3.0);
  EXPECT_DOUBLE_EQ(SelfTuningFuzzyPI::rule_output(-50.0, -50.0), 3.0);
  EXPECT_DOUBLE_EQ(SelfTuningFuzzyPI::rule_output(-1.0, 1.0), 0.0);
}

TEST(SelfTuningFuzzyPI, rule_output_is_continuous_and_monotone_decreasing) {
  double prev = SelfTuningFuzzyPI::rule_output(-4.0, 0.3);
  for (int k = 1; k <= 800; ++k) {
    const double e = -4.0 + k * 0.01;
    const double y = SelfTuningFuzzyPI::rule_output(e, 0.3);
    ASSERT_LE(y, prev + 1e-12) << "E = " << e;
    // No jumps. (min-AND with height defuzzification is not bilinear: the local slope reaches
    // ≈2.4 where one weight overtakes another, so the bound is loose.)
    ASSERT_LE(prev - y, 0.01 * 4.0) << "E = " << e;
    prev = y;
  }
}

TEST(SelfTuningFuzzyPI, increment_is_du_times_ku_abs_e_phi_psi) {
  // eq. 4-8, with Φ and Ψ from their definitions and dU from the rule base.
  const SelfTuningFuzzyPIParams p;
  struct Case {
    double x0, x1, f1;
  };
  for (const Case c : {Case{0.70, 0.72, 0.70}, Case{0.74, 0.71, 0.71}, Case{0.50, 0.55, 0.55},
                       Case{0.62, 0.58, 0.58}, Case{0.90, 0.95, 0.93}, Case{0.66, 0.64, 0.66}}) {
    Pi pi(p);
    pi.step(c.x0);
    const double u0 = pi.u();
    const double v0 = pi.v();
    pi.step(c.x1, c.f1);
    const double e = p.rab_ref_default - c.x1;
    const double big_e = p.ge * e;
    const double big_ce = p.gce * (c.x0 - c.x1);
    const double f =
        (1.0 - std::exp(-5.0 * big_e * big_ce)) / (1.0 + std::exp(-5.0 * big_e * big_ce));
    const double phi = (1.0 + p.alpha) / 2.0 + (1.0 - p.alpha) / 2.0 * f;
    const double psi =
        e < p.overload_error ? std::max(0.0, p.ol * (1.0 + 100.0 * (c.x1 - c.f1))) : 1.0;
    const double du = SelfTuningFuzzyPI::rule_output(big_e, big_ce);
    EXPECT_NEAR(pi.phi(), phi, 1e-12);
    EXPECT_NEAR(pi.psi(), psi, 1e-12);
    EXPECT_NEAR(pi.u() - u0, du * p.ku * std::fabs(e) * phi * psi, 1e-12);
    EXPECT_NEAR(pi.v() - v0, du * p.kv * std::fabs(e) * phi * psi, 1e-12);
    // Direction: Rab above the set point raises both actuators, below lowers them.
    if (e < -1e-9 && big_ce <= 0.0) {
      EXPECT_GT(pi.u(), u0);
      EXPECT_GT(pi.v(), v0);
    }
  }
}

TEST(SelfTuningFuzzyPI, phi_attenuates_when_approaching_the_set_point) {
  // Same error, opposite change of error: moving away (E·CE > 0) keeps the full gain (Φ → 1),
  // approaching (E·CE < 0) scales it by α.
  SelfTuningFuzzyPIParams p;
  p.alpha = 0.4;
  Pi away(p);
  away.step(0.70);
  const double u_away = away.u();
  away.step(0.80);  // e = −0.2 and Rab rising: E < 0, CE < 0
  Pi toward(p);
  toward.step(0.90);
  const double u_toward = toward.u();
  toward.step(0.80);  // e = −0.2 and Rab falling: E < 0, CE > 0
  EXPECT_NEAR(away.phi(), 1.0, 1e-6);
  EXPECT_NEAR(toward.phi(), 0.4, 1e-6);
  // Gain ratio seen in the actuator steps, per unit of dU.
  const double g_away = (away.u() - u_away) / away.du();
  const double g_toward = (toward.u() - u_toward) / toward.du();
  EXPECT_NEAR(g_toward / g_away, 0.4, 1e-6);
}

TEST(SelfTuningFuzzyPI, psi_boosts_the_action_in_overload_by_the_prediction_lead) {
  const SelfTuningFuzzyPIParams p;  // ol = 2
  // Not overloaded (e ≥ 0.01, eq. 8): Ψ = 1 whatever d_pf is.
  Pi under(p);
  under.step(0.55, 0.50);
  under.step(0.55, 0.50);
  EXPECT_EQ(under.psi(), 1.0);
  // Overloaded with the prediction 0.004 ahead of the filtered value: Ψ = 2·(1 + 0.4) = 2.8.
  Pi lead(p);
  lead.step(0.70, 0.696);
  lead.step(0.70, 0.696);
  EXPECT_NEAR(lead.psi(), 2.8, 1e-9);
  Pi same(p);
  same.step(0.70);
  same.step(0.70);
  EXPECT_NEAR(same.psi(), 2.0, 1e-12);
  EXPECT_NEAR((lead.u() - p.u_initial_us) / (same.u() - p.u_initial_us), 1.4, 1e-9);
  // Prediction far below the filtered value: the floor keeps the action from reversing.
  Pi behind(p);
  behind.step(0.70, 0.75);
  behind.step(0.70, 0.75);
  EXPECT_EQ(behind.psi(), 0.0);
  EXPECT_EQ(behind.u(), p.u_initial_us);
}

TEST(SelfTuningFuzzyPI, actuators_clamp_to_table_1_ranges_and_report_saturation) {
  SelfTuningFuzzyPIParams p;
  p.ku = 5.0;
  p.kv = 5.0;
  Pi pi(p);
  BlockStatus last = BlockStatus::kOk;
  for (int k = 0; k < 200; ++k) {
    last = pi.step(0.95);
  }
  EXPECT_EQ(pi.u(), 50.0);
  EXPECT_EQ(pi.v(), 70.0);
  EXPECT_EQ(last, BlockStatus::kSaturated);
  for (int k = 0; k < 400; ++k) {
    pi.step(0.05);
  }
  EXPECT_EQ(pi.u(), 9.0);
  EXPECT_EQ(pi.v(), 30.0);
}

TEST(SelfTuningFuzzyPI, disabled_holds_and_faults_on_non_finite_inputs) {
  Pi pi;
  pi.step(0.9);
  pi.step(0.9);
  const double u = pi.u();
  pi.enable(false);
  for (int k = 0; k < 10; ++k) {
    EXPECT_EQ(pi.step(0.95), BlockStatus::kOk);
  }
  EXPECT_EQ(pi.u(), u);
  pi.enable(true);
  pi.step(0.95);
  EXPECT_NEAR(pi.phi(), 0.85, 1e-12) << "ce = 0 after the pause (Rab_p tracked while disabled)";
  const double u2 = pi.u();
  EXPECT_EQ(pi.step(std::numeric_limits<double>::quiet_NaN()), BlockStatus::kFault);
  EXPECT_EQ(pi.u(), u2);
}

// Bumpless transfer: while disabled the outputs follow the tracked commands (clamped to Table 1's
// ranges); on enabling, the incremental law (eq. 4-5) starts from the last tracked values, so
// the first step differs from them by one increment of eq. 4-5 and no more.
TEST(SelfTuningFuzzyPI, disabled_block_tracks_the_applied_commands_and_takes_over_bumplessly) {
  SelfTuningFuzzyPIParams p;  // case 1 of Table 5: u 9 … 50 µs, v 30 … 70 V, starts at 20 / 40
  BlockHarness<SelfTuningFuzzyPI> h;
  ASSERT_TRUE(h.start(p).empty());
  auto& rab_p = h.source<double>("rab_p");
  auto& rab_f = h.source<double>("rab_f");
  auto& enable = h.source<bool>("enable");
  auto& track_u = h.source<double>("track_arc_off_time_us");
  auto& track_v = h.source<double>("track_servo_ref_v");
  enable.set(false);
  rab_p.set(0.5);
  rab_f.set(0.5);
  const double us[] = {12.0, 33.3, 80.0, 4.0, 27.5};
  const double vs[] = {41.7, 55.0, 90.0, 10.0, 48.25};
  for (int k = 0; k < 5; ++k) {
    track_u.set(us[k]);
    track_v.set(vs[k]);
    EXPECT_EQ(h.step(), BlockStatus::kOk);
    EXPECT_EQ(h.out("arc_off_time_us"), std::clamp(us[k], p.u_min_us, p.u_max_us)) << k;
    EXPECT_EQ(h.out("servo_ref_v"), std::clamp(vs[k], p.v_min_v, p.v_max_v)) << k;
  }
  enable.set(true);
  rab_p.set(0.55);  // e = 0.05 below the set point: no overload, Ψ = 1
  rab_f.set(0.55);
  h.step();
  const double e = p.rab_ref_default - 0.55;
  const double du = h.out("du");
  const double scale = std::fabs(e) * h.out("phi") * 1.0;
  EXPECT_NEAR(h.out("arc_off_time_us"), 27.5 + du * p.ku * scale, 1e-12);
  EXPECT_NEAR(h.out("servo_ref_v"), 48.25 + du * p.kv * scale, 1e-12);
  EXPECT_LE(std::fabs(h.out("arc_off_time_us") - 27.5), 3.0 * p.ku * std::fabs(e));
  EXPECT_LE(std::fabs(h.out("servo_ref_v") - 48.25), 3.0 * p.kv * std::fabs(e));
  // Unwired (0) tracking inputs leave the hold behaviour unchanged.
  enable.set(false);
  track_u.set(0.0);
  track_v.set(0.0);
  const double u_held = h.out("arc_off_time_us");
  h.step();
  EXPECT_EQ(h.out("arc_off_time_us"), u_held);
}

// A first-order plant: Rab relaxes toward a level that falls as the arc-off time u and the servo
// reference v rise (paper, Figs. 2-3).
struct Plant {
  double rab{0.9};
  double level(double u, double v) const {
    return std::clamp(1.05 - 0.012 * (u - 9.0) - 0.006 * (v - 30.0), 0.0, 1.0);
  }
  void step(double u, double v) { rab += 0.1 * (level(u, v) - rab); }
};

TEST(SelfTuningFuzzyPI, closed_loop_on_a_first_order_plant_drives_the_error_down) {
  SelfTuningFuzzyPIParams p;  // case 1 of Table 5
  p.u_initial_us = 12.0;
  p.v_initial_v = 35.0;
  Pi pi(p);
  Plant plant;
  const double e0 = std::fabs(p.rab_ref_default - plant.rab);
  double worst_late = 0.0;
  const int steps = 20000;  // 800 s at 40 ms
  for (int k = 0; k < steps; ++k) {
    pi.step(plant.rab);
    plant.step(pi.u(), pi.v());
    if (k > steps / 2) {
      worst_late = std::max(worst_late, std::fabs(p.rab_ref_default - plant.rab));
    }
  }
  EXPECT_LT(std::fabs(p.rab_ref_default - plant.rab), 0.1 * e0);
  EXPECT_LT(worst_late, 0.2 * e0) << "no sustained oscillation";
  EXPECT_GT(pi.u(), p.u_initial_us) << "Rab started too high: the arc-off time went up";
  EXPECT_GT(pi.v(), p.v_initial_v);
}

TEST(SelfTuningFuzzyPI, closed_loop_with_the_butterworth_and_grey_predictor_chain) {
  // The paper's chain: Rab (noisy) → Butterworth (Wn 0.012) → GM(1,1) (p = 37) → fuzzy PI.
  BlockHarness<ButterworthLowPass> lp;
  ASSERT_TRUE(lp.start(ButterworthLowPassParams{}).empty());
  BlockHarness<GreyPredictorGM11> gm;
  ASSERT_TRUE(gm.start(GreyPredictorGM11Params{}).empty());
  SelfTuningFuzzyPIParams p;
  p.u_initial_us = 12.0;
  p.v_initial_v = 35.0;
  Pi pi(p);
  Plant plant;
  std::uint64_t lcg = 12345;  // deterministic noise, ±0.1
  double sum_late = 0.0;
  int n_late = 0;
  const int steps = 20000;
  for (int k = 0; k < steps; ++k) {
    lcg = lcg * 6364136223846793005ULL + 1442695040888963407ULL;
    const double noise = 0.2 * (static_cast<double>(lcg >> 11) / 9007199254740992.0 - 0.5);
    lp.step(plant.rab + noise);
    gm.step(lp.out());
    ASSERT_EQ(std::isfinite(gm.out()), true);
    pi.step(gm.out(), lp.out());
    plant.step(pi.u(), pi.v());
    if (k > steps / 2) {
      sum_late += std::fabs(p.rab_ref_default - plant.rab);
      ++n_late;
    }
  }
  EXPECT_LT(sum_late / n_late, 0.1) << "mean |e| over the second half (started at 0.3)";
}

TEST(SelfTuningFuzzyPI, rab_inputs_are_clamped_to_the_unit_interval) {
  // A grey prediction of 3066 (seen on a start-up transient) acts like Rab = 1, not like e = −3066.
  const SelfTuningFuzzyPIParams p;
  Pi wild(p);
  wild.step(1.0, 0.2);
  wild.step(3066.0, 0.2);
  Pi one(p);
  one.step(1.0, 0.2);
  one.step(1.0, 0.2);
  EXPECT_EQ(wild.u(), one.u());
  EXPECT_EQ(wild.psi(), one.psi());
  EXPECT_NEAR(wild.psi(), p.ol * (1.0 + 100.0 * 0.8), 1e-9);
  Pi negative(p);
  negative.step(-0.5);
  EXPECT_NEAR(negative.du(), SelfTuningFuzzyPI::rule_output(p.ge * p.rab_ref_default, 0.0), 1e-12);
}

TEST(SelfTuningFuzzyPI, settle_samples_hold_the_actuators_after_activation) {
  SelfTuningFuzzyPIParams p;
  p.settle_samples = 10;
  Pi pi(p);
  for (int k = 0; k < 10; ++k) {
    pi.step(0.9 + 0.001 * k);
    ASSERT_EQ(pi.u(), p.u_initial_us) << "k = " << k;
    ASSERT_EQ(pi.v(), p.v_initial_v);
  }
  pi.step(0.9 + 0.01);  // ce from the tracked previous sample: −0.001
  EXPECT_GT(pi.u(), p.u_initial_us);
  EXPECT_NEAR(pi.du(), SelfTuningFuzzyPI::rule_output(p.ge * (0.6 - 0.91), p.gce * (0.909 - 0.91)),
              1e-12);
}

TEST(SelfTuningFuzzyPI, validate_refuses_bad_ranges) {
  EXPECT_TRUE(rt::validate_params(SelfTuningFuzzyPIParams{}).empty());
  EXPECT_FALSE(rt::validate_params(SelfTuningFuzzyPIParams{.u_min_us = 60.0}).empty());
  EXPECT_FALSE(rt::validate_params(SelfTuningFuzzyPIParams{.alpha = 1.5}).empty());
  EXPECT_FALSE(rt::validate_params(SelfTuningFuzzyPIParams{.v_initial_v = 80.0}).empty());
  EXPECT_FALSE(
      rt::validate_params(SelfTuningFuzzyPIParams{.ge = std::numeric_limits<double>::quiet_NaN()})
          .empty());
}

}  // namespace
}  // namespace edm::blocks

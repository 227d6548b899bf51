// Seed 001 controller: two decoupled minimum-variance self-tuning loops on the gap-state ratios.

#include "edm/blocks/self_tuning_regulator.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <deque>
#include <random>

#include "blocks/block_harness.hpp"

namespace edm::blocks {
namespace {

class Str {
 public:
  explicit Str(const SelfTuningRegulatorParams& p = {}) {
    const auto errs = h_.start(p);
    EXPECT_TRUE(errs.empty()) << test::describe(errs);
    normal_ = &h_.source<double>("ratio_normal");
    transient_ = &h_.source<double>("ratio_transient_arc");
    stable_ = &h_.source<double>("ratio_stable_arc");
    short_ = &h_.source<double>("ratio_short");
    y_rv_ref_ = &h_.source<double>("y_rv_ref");
    y_rt_ref_ = &h_.source<double>("y_rt_ref");
  }
  BlockStatus step(double normal, double transient = 0.0, double stable = 0.0,
                   double shorts = 0.0) {
    normal_->set(normal);
    transient_->set(transient);
    stable_->set(stable);
    short_->set(shorts);
    return h_.step();
  }
  void refs(double rv, double rt) {
    y_rv_ref_->set(rv);
    y_rt_ref_->set(rt);
  }
  double out(const char* name) const { return h_.out(name); }

 private:
  BlockHarness<SelfTuningRegulator> h_;
  rt::Output<double>* normal_{nullptr};
  rt::Output<double>* transient_{nullptr};
  rt::Output<double>* stable_{nullptr};
  rt::Output<double>* short_{nullptr};
  rt::Output<double>* y_rv_ref_{nullptr};
  rt::Output<double>* y_rt_ref_{nullptr};
};

// The paper's main model as the plant: y_v(k) = β00·u(k−d−1) + β01·u(k−d−2) + β0c + ε(k), with
// ε white N(0, σ²). Fed to the block through ratio_normal alone (y_v = φe when the other ratios
// are 0). Returns the mean and variance of y_v over the last `measure` samples.
struct MvResult {
  double mean{0.0};
  double var{0.0};
};
MvResult run_main_loop(std::int64_t d, double beta01, double beta0c, double sigma, double y_ref,
                       unsigned seed) {
  SelfTuningRegulatorParams p;
  p.delay_v = d;
  Str str(p);
  str.refs(y_ref, 0.0);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  std::deque<double> u(static_cast<std::size_t>(d + 2), p.u_v_initial);  // u[0] = u(k−1), …
  const int total = 6000;
  const int measure = 4000;
  double sum = 0.0;
  double sum2 = 0.0;
  for (int k = 0; k < total; ++k) {
    const double y = p.beta00 * u[static_cast<std::size_t>(d)] +
                     beta01 * u[static_cast<std::size_t>(d + 1)] + beta0c + noise(rng);
    str.step(y);
    u.push_front(str.out("u_v"));
    u.pop_back();
    if (k >= total - measure) {
      sum += y;
      sum2 += y * y;
    }
  }
  MvResult r;
  r.mean = sum / measure;
  r.var = sum2 / measure - r.mean * r.mean;
  return r;
}

TEST(SelfTuningRegulator, minimum_variance_main_loop_reaches_the_noise_floor_and_tracks) {
  // For this model (no autoregressive terms) the minimum-variance law puts the d+1-step
  // prediction on y_r, so the output error is the noise alone: E[y] = y_r, Var[y] = σ².
  const double sigma = 0.05;
  for (std::int64_t d : {0, 1}) {
    const MvResult r = run_main_loop(d, 0.3, 1.8, sigma, 0.95, 11U + static_cast<unsigned>(d));
    EXPECT_NEAR(r.mean, 0.95, 4.0 * sigma / std::sqrt(4000.0) + 0.005) << "d = " << d;
    // Var of a 4000-sample variance estimate: ±2.2 % (1 SD); the RLS adds O(1/window) on top.
    EXPECT_NEAR(r.var / (sigma * sigma), 1.0, 0.15) << "d = " << d;
  }
}

TEST(SelfTuningRegulator, steady_control_solves_the_model_for_the_reference) {
  // Noise-free: the loop settles where β00·u + β01·u + β0c = y_r, u* = (y_r − β0c)/(β00 + β01).
  SelfTuningRegulatorParams p;
  p.delay_v = 1;
  Str str(p);
  str.refs(0.95, 0.0);
  const double beta01 = 0.3;
  const double beta0c = 1.8;
  std::deque<double> u(3, p.u_v_initial);
  for (int k = 0; k < 3000; ++k) {
    str.step(p.beta00 * u[1] + beta01 * u[2] + beta0c);
    u.push_front(str.out("u_v"));
    u.pop_back();
  }
  const double u_star = (0.95 - beta0c) / (p.beta00 + beta01);
  EXPECT_NEAR(str.out("u_v"), u_star, 1e-6);
  EXPECT_NEAR(str.out("servo_ref_v"), p.us_per_unit_v * u_star, 1e-4);
  EXPECT_NEAR(str.out("y_v"), 0.95, 1e-6);
  // The last command is the seed's law on the current estimates (u(k−1) = u(k) at rest).
  EXPECT_NEAR(str.out("u_v"),
              (0.95 - str.out("beta01") * str.out("u_v") - str.out("beta0c")) / p.beta00, 1e-6);
}

TEST(SelfTuningRegulator, off_time_loop_tracks_y_rt_on_the_good_gap_model) {
  // Good gap (all sparks): y_t = K1·φe = ti/(ti + t_o), the paper's §4.4 model. β10 = −1/ti is
  // only its tangent, yet the loop's fixed point is exact: y_t = y_rt ⇒ t_o = ti·(1/y_rt − 1).
  SelfTuningRegulatorParams p;
  p.ti_us = 100.0;
  Str str(p);
  for (int k = 0; k < 300; ++k) {
    str.step(1.0);
  }
  EXPECT_NEAR(str.out("y_rt"), 0.9, 1e-9);
  EXPECT_NEAR(str.out("off_time_us"), p.ti_us * (1.0 / 0.9 - 1.0), 1e-3);
  str.step(1.0);
  EXPECT_NEAR(str.out("y_t"), 0.9, 1e-5);
  EXPECT_NEAR(str.out("k1"), 0.9, 1e-5);
}

TEST(SelfTuningRegulator, reference_decision_lowers_on_stable_arcs_and_returns_when_good) {
  SelfTuningRegulatorParams p;
  Str str(p);
  // A stable arc: both references fall by ref_step per sample.
  for (int k = 1; k <= 4; ++k) {
    str.step(0.8, 0.0, 0.05);
    EXPECT_NEAR(str.out("y_rv"), 0.95 - k * p.ref_step, 1e-12);
    EXPECT_NEAR(str.out("y_rt"), 0.9 - k * p.ref_step, 1e-12);
  }
  // Transient arcs above the limit without a stable arc: hold.
  const double held = str.out("y_rv");
  str.step(0.8, 0.2, 0.0);
  EXPECT_DOUBLE_EQ(str.out("y_rv"), held);
  // Good gap: geometric approach, y_r(n) = good − (good − y_r(0))·(1 − ref_rise)^n.
  for (int n = 1; n <= 10; ++n) {
    str.step(0.9);
    EXPECT_NEAR(str.out("y_rv"), 0.95 - (0.95 - held) * std::pow(1.0 - p.ref_rise, n), 1e-12);
  }
  // Floors hold during a long arc.
  for (int k = 0; k < 100; ++k) {
    str.step(0.5, 0.0, 0.3);
  }
  EXPECT_DOUBLE_EQ(str.out("y_rv"), p.y_rv_min);
  EXPECT_DOUBLE_EQ(str.out("y_rt"), p.y_rt_min);
}

TEST(SelfTuningRegulator, a_stable_arc_raises_servo_voltage_and_off_time) {
  // Lowering y_rv and y_rt with β00, β10 < 0 raises Us and t_o: the gap opens and deionises.
  SelfTuningRegulatorParams p;
  Str str(p);
  for (int k = 0; k < 50; ++k) {
    str.step(0.95);
  }
  const double us_before = str.out("servo_ref_v");
  const double to_before = str.out("off_time_us");
  for (int k = 0; k < 5; ++k) {
    str.step(0.6, 0.1, 0.1, 0.1);
  }
  EXPECT_GT(str.out("servo_ref_v"), us_before);
  EXPECT_GT(str.out("off_time_us"), to_before);
}

TEST(SelfTuningRegulator, clamps_and_faults) {
  SelfTuningRegulatorParams p;
  Str str(p);
  str.refs(0.05, 0.0);  // far below what the model allows at u_v_max
  BlockStatus s = BlockStatus::kOk;
  for (int k = 0; k < 20; ++k) {
    s = str.step(1.0);
  }
  EXPECT_EQ(s, BlockStatus::kSaturated);
  EXPECT_DOUBLE_EQ(str.out("u_v"), p.u_v_max);
  EXPECT_EQ(str.step(std::nan("")), BlockStatus::kFault);
  EXPECT_FALSE(rt::validate_params(SelfTuningRegulatorParams{.beta00 = 0.0}).empty());
  EXPECT_FALSE(rt::validate_params(SelfTuningRegulatorParams{.u_v_initial = 5.0}).empty());
}

}  // namespace
}  // namespace edm::blocks

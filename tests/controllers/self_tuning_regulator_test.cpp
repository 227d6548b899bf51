// Seed 001 controller: two decoupled minimum-variance self-tuning loops on the gap-state ratios.

#include "edm/blocks/self_tuning_regulator.hpp"

#include <gtest/gtest.h>

#include <algorithm>
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

// The per-loop equations are tested with both loops computed every sample and Us = us·u_v; the
// paper's structure (K1 on Us, loops in turn: the defaults) has its own tests at the end.
SelfTuningRegulatorParams both_loops_every_sample() {
  SelfTuningRegulatorParams p;
  p.k1_on_us = false;
  p.alternate = false;
  return p;
}

// The paper's main model as the plant: y_v(k) = β00·u(k−d−1) + β01·u(k−d−2) + β0c + ε(k), with
// ε white N(0, σ²). Fed to the block through ratio_normal alone (y_v = φe when the other ratios
// are 0). Returns the mean and variance of y_v over the last `measure` samples.
struct MvResult {
  double mean{0.0};
  double var{0.0};
};
MvResult run_main_loop(std::int64_t d, double beta01, double beta0c, double sigma, double y_ref,
                       unsigned seed) {
  SelfTuningRegulatorParams p = both_loops_every_sample();
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
  SelfTuningRegulatorParams p = both_loops_every_sample();
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
  SelfTuningRegulatorParams p = both_loops_every_sample();
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
  SelfTuningRegulatorParams p = both_loops_every_sample();
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

// §3: "an automatic gain K1 = ti/tp on the Us input". Over seeded random gap states, in both
// loop schedules, Us = ti/(ti + t_o)·us_per_unit_v·u_v with the t_o output with it (and
// us_per_unit_v·u_v without K1).
TEST(SelfTuningRegulator, k1_scales_us_by_ti_over_tp_of_the_off_time_output_with_it) {
  for (const bool k1 : {true, false}) {
    for (const bool alternate : {true, false}) {
      SelfTuningRegulatorParams p;
      p.k1_on_us = k1;
      p.alternate = alternate;
      p.us_per_unit_v = 60.0;
      Str str(p);
      std::mt19937_64 rng(41U + (k1 ? 2U : 0U) + (alternate ? 1U : 0U));
      std::uniform_real_distribution<double> u01(0.0, 1.0);
      for (int k = 0; k < 400; ++k) {
        const double e = u01(rng), t = 0.2 * u01(rng), a = 0.02 * u01(rng) * (k % 7 == 0);
        const double sh = 0.3 * u01(rng) * (1.0 - e);
        str.step(e, t, a, sh);
        const double gain = k1 ? p.ti_us / (p.ti_us + str.out("off_time_us")) : 1.0;
        ASSERT_NEAR(str.out("servo_ref_v"), gain * p.us_per_unit_v * str.out("u_v"), 1e-12)
            << "k1 " << k1 << " alternate " << alternate << " sample " << k;
      }
    }
  }
}

// The decoupling K1 is there for: the gap-voltage servo balances the period-mean voltage
// Ūg = K1·U_p (U_p the mean voltage over the pulse width, which sets the gap state) against Us,
// so U_p = Us/K1. With K1 on Us, U_p = us_per_unit_v·u_v whatever t_o is: a step of the
// auxiliary loop's reference moves t_o and leaves y_v and u_v exactly where they were; without
// it, the same step disturbs the main loop. Plant: y_v = 2 − U_p/40 (1 at 40 V), fed as φe = y_v
// below 1 and φe = 2 − y_v, φs = y_v − 1 above (so that φe + 2φs = y_v); y_t = K1·φe.
struct DecouplingRun {
  double to_before{0.0}, to_after{0.0};
  double max_yv_dev{0.0};  // max |y_v − y_v before the step| after it
  double max_uv_dev{0.0};
};
DecouplingRun run_off_time_step(bool k1, bool alternate) {
  SelfTuningRegulatorParams p;
  p.k1_on_us = k1;
  p.alternate = alternate;
  p.us_per_unit_v = k1 ? 60.0 : 40.0;
  p.delay_v = 0;  // the plant below answers within one sample
  Str str(p);
  auto plant_step = [&](double y_rt) {
    str.refs(0.0, y_rt);
    const double to = str.out("off_time_us");
    const double k1_actual = p.ti_us / (p.ti_us + to);
    const double u_p = str.out("servo_ref_v") / k1_actual;
    const double y_v = std::clamp(2.0 - u_p / 40.0, 0.0, 2.0);
    if (y_v <= 1.0) {
      str.step(y_v);
    } else {
      str.step(2.0 - y_v, 0.0, 0.0, y_v - 1.0);
    }
  };
  for (int k = 0; k < 3000; ++k) {
    plant_step(0.6);
  }
  DecouplingRun r;
  r.to_before = str.out("off_time_us");
  const double yv0 = str.out("y_v"), uv0 = str.out("u_v");
  for (int k = 0; k < 600; ++k) {
    plant_step(0.75);
    r.max_yv_dev = std::max(r.max_yv_dev, std::fabs(str.out("y_v") - yv0));
    r.max_uv_dev = std::max(r.max_uv_dev, std::fabs(str.out("u_v") - uv0));
  }
  r.to_after = str.out("off_time_us");
  return r;
}

TEST(SelfTuningRegulator, with_k1_on_us_an_off_time_step_leaves_the_main_loop_undisturbed) {
  for (const bool alternate : {true, false}) {
    const DecouplingRun with = run_off_time_step(true, alternate);
    const DecouplingRun without = run_off_time_step(false, alternate);
    for (const DecouplingRun& r : {with, without}) {
      // y_t = K1·0.95 → 0.6, 0.75: t_o = ti·(0.95/y_rt − 1) = 58.3 µs, then 26.7 µs.
      EXPECT_NEAR(r.to_before, 100.0 * (0.95 / 0.6 - 1.0), 0.5) << "alternate " << alternate;
      EXPECT_NEAR(r.to_after, 100.0 * (0.95 / 0.75 - 1.0), 0.5) << "alternate " << alternate;
    }
    // (1e-6: what is left of the main loop's own settling after 3000 samples)
    EXPECT_LT(with.max_yv_dev, 1e-6) << "alternate " << alternate;
    EXPECT_LT(with.max_uv_dev, 1e-6) << "alternate " << alternate;
    EXPECT_GT(without.max_yv_dev, 0.05) << "alternate " << alternate;
    EXPECT_GT(without.max_uv_dev, 0.05) << "alternate " << alternate;
  }
}

// §4: "本系统分时交替对两个模型进行计算和控制" — the two models are computed and controlled in
// turn. With `alternate`, sample 0, 2, 4 … after activation runs the main loop alone (u_v and its
// estimates β01, β0c may change; t_o and β1c are held) and sample 1, 3, 5 … the auxiliary loop
// alone; without it both change every sample (seeded random gap states).
TEST(SelfTuningRegulator, alternate_computes_one_loop_per_sample) {
  for (const bool alternate : {true, false}) {
    SelfTuningRegulatorParams p;
    p.alternate = alternate;
    Str str(p);
    std::mt19937_64 rng(5U);
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    double uv = str.out("u_v"), to = str.out("off_time_us"), b01 = str.out("beta01"),
           b0c = str.out("beta0c"), b1c = str.out("beta1c");
    for (int k = 0; k < 200; ++k) {
      // A stable arc every fifth sample moves both reference decisions as well.
      const double arc = k % 5 == 0 ? 0.02 : 0.0;
      const double rv = str.out("y_rv"), rt = str.out("y_rt");
      str.step(0.6 + 0.35 * u01(rng), 0.05 * u01(rng), arc, 0.05 * u01(rng));
      const bool main_ran = str.out("beta0c") != b0c || str.out("beta01") != b01;
      const bool aux_ran = str.out("beta1c") != b1c;
      if (alternate) {
        // Each reference decision on its own loop's samples.
        EXPECT_EQ(str.out("y_rv") != rv, k % 2 == 0 && (arc > 0.0 || rv != 0.95)) << k;
        EXPECT_EQ(str.out("y_rt") != rt, k % 2 == 1 && (arc > 0.0 || rt != 0.9)) << k;
      }
      if (alternate) {
        EXPECT_EQ(main_ran, k % 2 == 0) << "sample " << k;
        EXPECT_EQ(aux_ran, k % 2 == 1) << "sample " << k;
        if (k % 2 == 0) {
          EXPECT_EQ(str.out("off_time_us"), to) << "t_o held on the main loop's sample " << k;
        } else {
          EXPECT_EQ(str.out("u_v"), uv) << "u_v held on the auxiliary loop's sample " << k;
        }
      } else {
        EXPECT_TRUE(main_ran && aux_ran) << "sample " << k;
      }
      uv = str.out("u_v"), to = str.out("off_time_us"), b01 = str.out("beta01");
      b0c = str.out("beta0c"), b1c = str.out("beta1c");
    }
  }
}

// In turn, the main model's k counts the main loop's own samples: on the paper's model
// y_v(m) = β00·u(m−d−1) + β01·u(m−d−2) + β0c in main-loop samples m (the plant's y_v held over
// the auxiliary loop's samples), the loop settles at u* = (y_r − β0c)/(β00 + β01) as with both
// loops every sample.
TEST(SelfTuningRegulator, in_turn_the_main_model_counts_main_loop_samples) {
  SelfTuningRegulatorParams p;  // alternate, K1 on Us
  p.delay_v = 1;
  Str str(p);
  str.refs(0.95, 0.0);
  const double beta01 = 0.3, beta0c = 1.8;
  std::deque<double> u(3, p.u_v_initial);  // u[0] = u(m−1), …
  double y = 0.0;
  for (int k = 0; k < 6000; ++k) {
    if (k % 2 == 0) {
      y = p.beta00 * u[1] + beta01 * u[2] + beta0c;
    }
    str.step(y);
    if (k % 2 == 0) {
      u.push_front(str.out("u_v"));
      u.pop_back();
    }
  }
  const double u_star = (0.95 - beta0c) / (p.beta00 + beta01);
  EXPECT_NEAR(str.out("u_v"), u_star, 1e-6);
  EXPECT_NEAR(y, 0.95, 1e-6);
}

}  // namespace
}  // namespace edm::blocks

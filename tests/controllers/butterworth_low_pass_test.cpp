// Seed 000 pre-filter: 2nd-order Butterworth low-pass, bilinear transform with pre-warping.

#include "edm/blocks/butterworth_low_pass.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <limits>
#include <numbers>

#include "blocks/block_harness.hpp"

namespace edm::blocks {
namespace {

using std::numbers::pi;

BlockHarness<ButterworthLowPass>* started(BlockHarness<ButterworthLowPass>& h, double wn,
                                          bool prime = false) {
  EXPECT_TRUE(h.start({.cutoff = wn, .initial = 0.0, .prime = prime}).empty());
  return &h;
}

// Steady-state amplitude of the block's response to sin(ω·k), measured by correlating the
// output with sin and cos over a whole number of periods after the transient has died out.
double measured_gain(double wn, double omega, int periods_settle, int samples) {
  BlockHarness<ButterworthLowPass> h;
  started(h, wn);
  const int settle = periods_settle;
  for (int k = 0; k < settle; ++k) {
    h.step(std::sin(omega * k));
  }
  double s = 0.0;
  double c = 0.0;
  for (int k = settle; k < settle + samples; ++k) {
    h.step(std::sin(omega * k));
    s += h.out() * std::sin(omega * k);
    c += h.out() * std::cos(omega * k);
  }
  return 2.0 * std::hypot(s, c) / samples;
}

// |H|² of the digital Butterworth from its defining property (not from the coefficients).
double analytic_gain(double wn, double omega) {
  const double ratio = std::tan(omega / 2.0) / std::tan(pi * wn / 2.0);
  return 1.0 / std::sqrt(1.0 + std::pow(ratio, 4));
}

TEST(ButterworthLowPass, dc_gain_is_one) {
  for (const double wn : {0.012, 0.05, 0.3, 0.9}) {
    BlockHarness<ButterworthLowPass> h;
    started(h, wn);
    for (int k = 0; k < 20000; ++k) {
      h.step(0.42);
    }
    EXPECT_NEAR(h.out(), 0.42, 1e-12) << "Wn = " << wn;
  }
}

TEST(ButterworthLowPass, minus_3_db_at_the_cut_off_measured_through_the_block) {
  // Wn chosen so that a whole number of periods fits: period = 2/Wn samples.
  struct Case {
    double wn;
    int period;
  };
  for (const Case c :
       {Case{0.012, 500 / 3}, Case{0.0125, 160}, Case{0.05, 40}, Case{0.1, 20}, Case{0.4, 5}}) {
    const double omega = pi * c.wn;  // rad/sample
    // For 0.012 the period is 166.67 samples: 3 periods = 500 samples.
    const int samples = c.wn == 0.012 ? 5000 : c.period * 50;
    const double gain = measured_gain(c.wn, omega, 20000, samples);
    EXPECT_NEAR(gain, 1.0 / std::sqrt(2.0), 1e-6) << "Wn = " << c.wn;
    EXPECT_NEAR(20.0 * std::log10(gain), -3.0103, 1e-3) << "Wn = " << c.wn;
  }
}

TEST(ButterworthLowPass, magnitude_follows_the_butterworth_law_off_the_cut_off) {
  const double wn = 0.05;
  for (const double f : {0.25, 0.5, 2.0, 4.0}) {
    const double omega = pi * wn * f;
    const int period = static_cast<int>(std::lround(2.0 / (wn * f)));  // 160, 80, 20, 10
    EXPECT_NEAR(measured_gain(wn, omega, 20000, period * 40), analytic_gain(wn, omega), 1e-6)
        << "f/fc = " << f;
  }
}

TEST(ButterworthLowPass, poles_are_the_bilinear_images_of_the_analogue_butterworth_poles) {
  for (const double wn : {0.012, 0.1, 0.5}) {
    const auto c = ButterworthLowPass::design(wn);
    // Analogue poles (pre-warped, time unit 2/fs): s = K·e^{±j3π/4}; bilinear z = (1+s)/(1−s).
    const double k = std::tan(pi * wn / 2.0);
    const std::complex<double> s = k * std::polar(1.0, 3.0 * pi / 4.0);
    const std::complex<double> z = (1.0 + s) / (1.0 - s);
    // z² + a1·z + a2 = (z − p)(z − p̄) ⇒ a1 = −2·Re p, a2 = |p|².
    EXPECT_NEAR(c.a1, -2.0 * z.real(), 1e-14) << wn;
    EXPECT_NEAR(c.a2, std::norm(z), 1e-14) << wn;
    EXPECT_LT(std::abs(z), 1.0);
    // Both zeros at z = −1 (numerator b0·(1 + z⁻¹)²).
    EXPECT_DOUBLE_EQ(c.b1, 2.0 * c.b0);
    EXPECT_DOUBLE_EQ(c.b2, c.b0);
  }
}

TEST(ButterworthLowPass, impulse_response_energy_matches_parseval) {
  // Σ h² = (1/π)∫₀^π |H(e^{jω})|² dω with |H|² = 1/(1 + (tan(ω/2)/K)⁴), integrated numerically.
  for (const double wn : {0.012, 0.1, 0.3}) {
    BlockHarness<ButterworthLowPass> h;
    started(h, wn);
    double energy = 0.0;
    for (int k = 0; k < 200000; ++k) {
      h.step(k == 0 ? 1.0 : 0.0);
      energy += h.out() * h.out();
    }
    // Substitute t = tan(ω/2)/K: (2K/π)∫₀^∞ dt / ((1 + t⁴)(1 + K²t²)); Simpson on t = u/(1−u).
    const double k = std::tan(pi * wn / 2.0);
    const int n = 200000;
    double integral = 0.0;
    for (int i = 0; i <= n; ++i) {
      const double u = static_cast<double>(i) / n;
      double f = 0.0;
      if (i < n) {
        const double t = u / (1.0 - u);
        const double dt_du = 1.0 / ((1.0 - u) * (1.0 - u));
        f = dt_du / ((1.0 + std::pow(t, 4)) * (1.0 + k * k * t * t));
      }
      const double w = (i == 0 || i == n) ? 1.0 : (i % 2 == 1 ? 4.0 : 2.0);
      integral += w * f;
    }
    integral *= 1.0 / (3.0 * n);
    EXPECT_NEAR(energy, 2.0 * k / pi * integral, 1e-9 + 1e-7 * energy) << "Wn = " << wn;
  }
}

TEST(ButterworthLowPass, prime_starts_in_steady_state_at_the_first_sample) {
  BlockHarness<ButterworthLowPass> h;
  started(h, 0.012, /*prime=*/true);
  for (int k = 0; k < 100; ++k) {
    ASSERT_EQ(h.step(0.55), BlockStatus::kOk);
    ASSERT_NEAR(h.out(), 0.55, 1e-12);
  }
  BlockHarness<ButterworthLowPass> cold;
  started(cold, 0.012, /*prime=*/false);
  cold.step(0.55);
  EXPECT_LT(cold.out(), 0.01) << "without priming the output rises slowly from 0";
}

TEST(ButterworthLowPass, non_finite_input_faults_and_keeps_the_state) {
  BlockHarness<ButterworthLowPass> a;
  BlockHarness<ButterworthLowPass> b;
  started(a, 0.1);
  started(b, 0.1);
  for (int k = 0; k < 30; ++k) {
    const double x = std::sin(0.3 * k);
    a.step(x);
    if (k == 10) {
      EXPECT_EQ(b.step(std::numeric_limits<double>::quiet_NaN()), BlockStatus::kFault);
    }
    b.step(x);
    ASSERT_EQ(a.out(), b.out()) << "k = " << k;
  }
}

TEST(ButterworthLowPass, validate_refuses_cutoffs_outside_the_open_unit_interval) {
  for (const double wn : {0.0, 1.0, -0.1, 1.5, std::numeric_limits<double>::quiet_NaN()}) {
    EXPECT_FALSE(rt::validate_params(ButterworthLowPassParams{.cutoff = wn}).empty()) << wn;
  }
  EXPECT_TRUE(rt::validate_params(ButterworthLowPassParams{}).empty());
  EXPECT_EQ(ButterworthLowPassParams{}.cutoff, 0.012);
}

}  // namespace
}  // namespace edm::blocks

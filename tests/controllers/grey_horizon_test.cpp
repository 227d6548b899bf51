// The offline horizon choice of seed 000 (apps/greyhorizon/horizon.hpp) on synthetic signals
// whose answer is known analytically.

#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <vector>

#include "edm/blocks/butterworth_low_pass.hpp"
#include "horizon.hpp"

namespace gh = edm::greyhorizon;

namespace {

constexpr double kPaperWn[] = {0.010, 0.012, 0.015, 0.020, 0.030, 0.050};

std::vector<double> ramp(std::size_t n, double a, double s) {
  std::vector<double> x(n);
  for (std::size_t k = 0; k < n; ++k) x[k] = a + s * static_cast<double>(k);
  return x;
}

}  // namespace

TEST(GreyHorizon, DcDelayFormulaMatchesTheDesignedCoefficients) {
  // τ = Σn·b_n/Σb_n − Σn·a_n/Σa_n for the designed H(z), against 1/(√2·tan(πWn/2)).
  for (double wn : kPaperWn) {
    const auto c = edm::blocks::ButterworthLowPass::design(wn);
    const double num = (c.b1 + 2 * c.b2) / (c.b0 + c.b1 + c.b2);
    const double den = (c.a1 + 2 * c.a2) / (1 + c.a1 + c.a2);
    EXPECT_NEAR(num - den, gh::butterworth_dc_delay(wn), 1e-6 * gh::butterworth_dc_delay(wn))
        << "Wn " << wn;
  }
  EXPECT_NEAR(gh::butterworth_dc_delay(0.012), 37.5, 0.1);  // the paper's p = 37 at 0.012
}

TEST(GreyHorizon, FilterLagsARampByItsDcDelay) {
  const auto x = ramp(3000, 0.3, 1e-4);
  for (double wn : kPaperWn) {
    const auto f = gh::butterworth_filter(x, wn);
    const double lag = (x[2999] - f[2999]) / 1e-4;
    EXPECT_NEAR(lag, gh::butterworth_dc_delay(wn), 1e-3) << "Wn " << wn;
  }
}

TEST(GreyHorizon, ShiftedMovingAverageIsCentred) {
  const auto x = ramp(200, 0.0, 1.0);
  const auto o = gh::shifted_moving_average(x, 50, 25);
  EXPECT_TRUE(std::isnan(o[23]));   // needs x(−1)
  EXPECT_DOUBLE_EQ(o[24], 24.5);    // mean of x(0 … 49)
  EXPECT_DOUBLE_EQ(o[100], 100.5);  // centre k + 0.5
  EXPECT_DOUBLE_EQ(o[174], 174.5);  // last: x(150 … 199)
  EXPECT_TRUE(std::isnan(o[175]));
}

TEST(GreyHorizon, ChosenHorizonOnARampIsTheFilterDelay) {
  // Filter lag τ, objective centred on k + 0.5, GM(1,1) extrapolates a slow ramp ≈ linearly:
  // the error is ≈ s·(p − τ − 0.5), so the best p is the integer nearest τ + 0.5.
  const auto x = ramp(3000, 0.3, 1e-4);
  gh::HorizonOptions opt;
  opt.warmup = 600;
  for (double wn : kPaperWn) {
    const auto r = gh::choose_horizon(x, wn, opt);
    const double expected = gh::butterworth_dc_delay(wn) + 0.5;
    EXPECT_LE(std::fabs(static_cast<double>(r.best_p) - expected), 1.0)
        << "Wn " << wn << " expected ≈ " << expected;
    EXPECT_LT(r.best_rms, 1e-4 * 1.0);  // within one step of slope
    EXPECT_GT(r.rms[0], 1e-4 * 8.0);    // no prediction: the whole lag remains
  }
}

TEST(GreyHorizon, NoiseShortensTheHorizonAtHighCutOff) {
  // On a ramp plus white noise, extrapolating 5 filtered samples p steps ahead amplifies the
  // noise the filter lets through, so the best p falls below the noise-free choice τ + ½ (which
  // the ramp alone gives, test above), and further the more noise the filter passes: at
  // Wn = 0.05 (τ ≈ 9) it is below τ and below the p chosen at Wn = 0.010 (τ ≈ 45).
  std::vector<double> x = ramp(6000, 0.3, 5e-5);
  unsigned s = 12345u;
  for (double& v : x) {
    s = s * 1664525u + 1013904223u;
    v += 0.1 * (static_cast<double>(s >> 8) / 16777216.0 - 0.5);
  }
  gh::HorizonOptions opt;
  opt.warmup = 600;
  const auto lo = gh::choose_horizon(x, 0.010, opt);
  const auto hi = gh::choose_horizon(x, 0.050, opt);
  EXPECT_LT(static_cast<double>(hi.best_p), gh::butterworth_dc_delay(0.050));
  EXPECT_LT(static_cast<double>(lo.best_p), gh::butterworth_dc_delay(0.010));
  EXPECT_GT(lo.best_p, hi.best_p);
}

TEST(GreyHorizon, TooShortARecordIsRefused) {
  const auto x = ramp(100, 0.3, 1e-4);
  gh::HorizonOptions opt;
  EXPECT_THROW(gh::choose_horizon(x, 0.012, opt), std::invalid_argument);
}

TEST(GreyHorizon, PoolingTwoRecordsIsScoringTheirConcatenatedErrors) {
  // Pooled RMS² = (Σ over both records of the squared errors) / (samples of both): the same as
  // one record scored twice when the records are equal, and the weighted mean of RMS² otherwise.
  gh::HorizonOptions opt;
  opt.max_horizon = 20;
  const auto a = ramp(1200, 0.3, 2e-4);
  auto b = ramp(1600, 0.5, -1e-4);
  for (std::size_t k = 0; k < b.size(); ++k) b[k] += 0.01 * std::sin(0.05 * static_cast<double>(k));
  const auto ra = gh::choose_horizon(a, 0.012, opt);
  const auto rb = gh::choose_horizon(b, 0.012, opt);
  const auto same = gh::pool_horizons({ra, ra});
  EXPECT_EQ(same.best_p, ra.best_p);
  EXPECT_EQ(same.scored, 2 * ra.scored);
  const auto both = gh::pool_horizons({ra, rb});
  ASSERT_EQ(both.rms.size(), ra.rms.size());
  for (std::size_t p = 0; p < both.rms.size(); ++p) {
    EXPECT_NEAR(same.rms[p], ra.rms[p], 1e-15);
    const double want = (ra.rms[p] * ra.rms[p] * static_cast<double>(ra.scored) +
                         rb.rms[p] * rb.rms[p] * static_cast<double>(rb.scored)) /
                        static_cast<double>(ra.scored + rb.scored);
    EXPECT_NEAR(both.rms[p] * both.rms[p], want, 1e-15);
    EXPECT_GE(both.rms[p], both.best_rms);
  }
  EXPECT_THROW(gh::pool_horizons({}), std::invalid_argument);
}

TEST(GreyHorizon, PaperFormAndRhoChooseTheSameHorizonOnASlowSignal) {
  // |c| ≪ 1 on a slowly drifting filtered signal: e^(−c) and ρ differ by O(c³) per step.
  gh::HorizonOptions paper;
  paper.max_horizon = 60;
  gh::HorizonOptions rho = paper;
  rho.paper_exp = false;
  const auto x = ramp(3000, 0.3, 5e-5);
  for (double wn : kPaperWn) {
    const auto rp = gh::choose_horizon(x, wn, paper);
    const auto rr = gh::choose_horizon(x, wn, rho);
    EXPECT_EQ(rp.best_p, rr.best_p) << "Wn " << wn;
    EXPECT_NEAR(rp.best_rms, rr.best_rms, 1e-9) << "Wn " << wn;
  }
}

// Seed 000 (Lee & Liao 2003) as printed: the defaults of the chain are the paper's equations,
// checked against the paper's formulas computed here independently of the blocks (issue 20).

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "blocks/block_harness.hpp"
#include "edm/blocks/grey_predictor_gm11.hpp"
#include "edm/blocks/self_tuning_fuzzy_pi.hpp"

namespace edm::blocks {
namespace {

// GM(1,1) as in Deng (the paper's ref. 14): AGO y¹, background z(k) = (y¹(k−1) + y¹(k))/2,
// [c b]ᵀ = (BᵀB)⁻¹BᵀY with B = [−z(k) 1], Y = y⁰(k), k = 1 … n−1 (0-based), solved by the 2 × 2
// inverse (not the block's centred sums); then eq. (1) literally, with b/c:
//   ŷ⁰(m) = (1 − e^c)·(y⁰(0) − b/c)·e^(−c·m),   m = (n − 1) + p.
double eq1(const std::vector<double>& y, std::int64_t p) {
  const std::size_t n = y.size();
  double s_zz = 0, s_z = 0, s_zy = 0, s_y = 0;
  double y1 = y[0];
  for (std::size_t k = 1; k < n; ++k) {
    const double z = 0.5 * (y1 + (y1 + y[k]));
    y1 += y[k];
    s_zz += z * z;
    s_z += z;
    s_zy += z * y[k];
    s_y += y[k];
  }
  const auto m = static_cast<double>(n - 1);
  // BᵀB = [[Σz², −Σz], [−Σz, m]],  BᵀY = [−Σzy, Σy]
  const double det = s_zz * m - s_z * s_z;
  const double c = (m * (-s_zy) + s_z * s_y) / det;
  const double b = (s_z * (-s_zy) + s_zz * s_y) / det;
  const double k_ahead = static_cast<double>(n - 1) + static_cast<double>(p);
  return (1.0 - std::exp(c)) * (y[0] - b / c) * std::exp(-c * k_ahead);
}

TEST(Seed000, default_grey_prediction_is_eq_1_with_the_matrix_least_squares) {
  // Seeded random windows of a filtered-Rab-like signal (slow drift plus small noise), the
  // paper's n-independent horizons; the block with its default params against eq. (1).
  std::mt19937_64 rng(2003);
  std::uniform_real_distribution<double> level(0.2, 0.8);
  std::uniform_real_distribution<double> slope(-0.01, 0.01);
  std::normal_distribution<double> noise(0.0, 0.002);
  int compared = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const std::int64_t n = 4 + trial % 9;
    const std::int64_t p = std::int64_t{1} + trial % 47;  // Table 2's range: 1 … 46 (and 47)
    GreyPredictorGM11Params params;                       // the defaults: eq. (1)
    params.window = n;
    params.horizon = p;
    BlockHarness<GreyPredictorGM11> h;
    ASSERT_TRUE(h.start(params).empty());
    std::vector<double> y;
    const double a = level(rng);
    const double s = slope(rng);
    for (std::int64_t k = 0; k < n; ++k) {
      y.push_back(a + s * static_cast<double>(k) + noise(rng));
      ASSERT_EQ(h.step(y.back()), BlockStatus::kOk);
    }
    ASSERT_TRUE(h.out<bool>("valid")) << trial;
    const double want = eq1(y, p);
    if (!std::isfinite(want) || std::fabs(h.out("c")) < 1e-6) {
      continue;  // eq. (1)'s b/c is ill-conditioned there; the block's form has no b/c
    }
    ++compared;
    EXPECT_NEAR(h.out(), want, 1e-9 * std::max(1.0, std::fabs(want))) << "trial " << trial;
  }
  EXPECT_GT(compared, 250);
}

// One controller step from a settled Rab_p: Ψ of eq. (8) for an error e and a lead d_pf.
double psi_after(double e, double d_pf, const SelfTuningFuzzyPIParams& p) {
  BlockHarness<SelfTuningFuzzyPI> h;
  EXPECT_TRUE(h.start(p).empty());
  auto& rab_p = h.source<double>("rab_p");
  auto& rab_f = h.source<double>("rab_f");
  const double x = p.rab_ref_default - e;
  for (int k = 0; k < 2; ++k) {
    rab_p.set(x);
    rab_f.set(x - d_pf);
    h.step();
  }
  return h.out("psi");
}

TEST(Seed000, psi_threshold_is_eq_8_as_printed) {
  // Eq. (8): Ψ = ol·(1 + 100·d_pf) for e < 0.01, else 1. Around the set point, where the printed
  // 0.01 and the digest's −0.01 differ, the default follows the print.
  const SelfTuningFuzzyPIParams p;  // ol = 2, Rab_ref = 0.6
  EXPECT_EQ(p.overload_error, 0.01);
  const double d_pf = 0.003;
  for (const double e : {-0.3, -0.05, -0.0099, 0.0, 0.004, 0.0099}) {
    EXPECT_NEAR(psi_after(e, d_pf, p), p.ol * (1.0 + 100.0 * d_pf), 1e-9) << "e = " << e;
  }
  for (const double e : {0.0101, 0.02, 0.3}) {
    EXPECT_EQ(psi_after(e, d_pf, p), 1.0) << "e = " << e;
  }
  // The digest's reading stays a setting: then the band −0.01 ≤ e < 0.01 has Ψ = 1.
  SelfTuningFuzzyPIParams digest = p;
  digest.overload_error = -0.01;
  EXPECT_EQ(psi_after(0.004, d_pf, digest), 1.0);
  EXPECT_EQ(psi_after(-0.0099, d_pf, digest), 1.0);
  EXPECT_NEAR(psi_after(-0.0101, d_pf, digest), p.ol * (1.0 + 100.0 * d_pf), 1e-9);
}

TEST(Seed000, psi_unfloored_is_eq_8_as_printed_and_reverses_the_action) {
  // Overloaded (e < 0.01) with the prediction 0.02 below the filtered value: eq. 8 gives
  // Ψ = ol·(1 − 2) = −ol, so the step has the sign of −dU. The default floor (psi_min 0) stops
  // the action instead; psi_min = −1e9 leaves eq. 8 as printed.
  SelfTuningFuzzyPIParams p;
  EXPECT_EQ(psi_after(-0.1, -0.02, p), 0.0);
  p.psi_min = -1e9;
  EXPECT_NEAR(psi_after(-0.1, -0.02, p), -p.ol, 1e-9);
  BlockHarness<SelfTuningFuzzyPI> h;
  ASSERT_TRUE(h.start(p).empty());
  auto& rab_p = h.source<double>("rab_p");
  auto& rab_f = h.source<double>("rab_f");
  for (int k = 0; k < 2; ++k) {
    rab_p.set(0.7);  // e = −0.1: dU > 0 (lengthen the arc-off time) …
    rab_f.set(0.72);
    h.step();
  }
  EXPECT_GT(h.out("du"), 0.0);
  EXPECT_LT(h.out("arc_off_time_us"), p.u_initial_us) << "… but Ψ < 0 shortens it";
}

}  // namespace
}  // namespace edm::blocks
